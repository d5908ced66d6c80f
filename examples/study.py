#!/usr/bin/env python3
"""A notebook-style study with the streamrt module (docs/python.md): render a scene, look at
its stream profile, compare the two engines, and plot error against samples per pixel.

    scripts/build.sh && PYTHONPATH=build/python /usr/bin/python3 examples/study.py [SCENE]

Writes study_image.png, study_difference.png and study_error.png in the current folder.
"""
import sys

import numpy as np

import streamrt

scene = sys.argv[1] if len(sys.argv) > 1 else "scenes/whitted.cfg"

# 1. One render: the picture is a linear float32 array, height x width x 3.
r = streamrt.render(scene, width=320, height=240, spp=4, profile=True)
print(r, "rays:", r.rays)
for stage in r.profile["stages"]:
    print("  %-12s %10d rays in  %8.2f Mrays/s" % (stage["stage"], stage["rays_in"], stage["mrays_per_s"]))
streamrt.save(r.image, "study_image.png")  # sRGB for display

# 2. Both engines at the same settings: speed-up and difference.
c = streamrt.compare(scene, width=320, height=240, spp=4)
print("stream %.3f s, recursive %.3f s: %.1fx, PSNR %.1f dB" % (
    c["stream"].seconds["render"], c["recursive"].seconds["render"], c["speedup"], c["psnr"]))
difference = np.abs(c["stream"].image - c["recursive"].image)
streamrt.save(difference * 100, "study_difference.png", colorspace="linear")

# 3. Error against samples per pixel, against a 256-spp reference of the recursive engine.
reference = streamrt.render(scene, width=160, height=120, spp=256, engine="recursive").image
spps, errors, seconds = [1, 2, 4, 8, 16, 32], [], []
for spp in spps:
    run = streamrt.render(scene, width=160, height=120, spp=spp)
    errors.append(float(np.sqrt(np.mean((np.clip(run.image, 0, 1) - np.clip(reference, 0, 1)) ** 2))))
    seconds.append(run.seconds["render"])
    print("spp %3d: RMSE %.5f in %.4f s" % (spp, errors[-1], seconds[-1]))
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit(0)
fig, ax = plt.subplots(figsize=(5, 3.5))
ax.loglog(seconds, errors, "o-")
for s, e, n in zip(seconds, errors, spps):
    ax.annotate(str(n), (s, e), textcoords="offset points", xytext=(4, 4), fontsize=8)
ax.set_xlabel("render seconds")
ax.set_ylabel("RMSE against 256 spp")
ax.set_title(scene)
fig.tight_layout()
fig.savefig("study_error.png", dpi=110)
print("wrote study_image.png, study_difference.png, study_error.png")
