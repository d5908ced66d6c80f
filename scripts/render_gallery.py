#!/usr/bin/env python3
"""Renders the pictures of the feature scenes shown in README.md and docs/scene-format.md.

usage: scripts/render_gallery.py [--build DIR] [--out DIR] [--only csg|stills|gi|strip]

Each scene at 320x240 with its own settings (the degree-6 scenes of scenes/gi/ at their own
samples, the square ones at 256x256, into docs/img/gi_<scene>.png) (sRGB PNG, the default display colour) into
docs/img/<scene>.png, and the strip of frames 0, 6, 12, 13, 18 and 23 of
scenes/anim/orbit.cfg (160x120 each, side by side, 4-pixel white gaps) into
docs/img/anim_orbit_strip.png; the CSG scenes of scenes/csg/ into docs/img/csg_<scene>.png. Needs /usr/bin/python3 with numpy and matplotlib (Debian's
python3-numpy, python3-matplotlib) for the strip.
"""
import argparse
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STILLS = ["soft_shadows", "dof", "fresnel", "textured", "emission"]
# Degree 6 (docs/global-illumination.md): each at its own samples, square scenes square.
GI_STILLS = [("gi/cornell", 256, 256), ("gi/sky_room", 320, 240), ("gi/glass_box", 256, 256)]
STRIP_FRAMES = [0, 6, 12, 13, 18, 23]
CSG_STILLS = ["lens", "pipe", "die", "hollow", "tree", "mesh_cut", "ring", "union_merge", "field"]


def render(exe, scene, out, *extra):
    subprocess.run([exe, "-q", "-j2", os.path.join(ROOT, scene), "-o", out, *extra], check=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "img"))
    ap.add_argument("--only", choices=["csg", "stills", "gi", "strip"], help="render one group of pictures alone")
    args = ap.parse_args()
    exe = os.path.join(args.build, "engine", "streamrt")
    want = lambda group: args.only in (None, group)  # noqa: E731
    for name in CSG_STILLS if want("csg") else []:
        out = os.path.join(args.out, "csg_%s.png" % name)
        render(exe, "scenes/csg/%s.cfg" % name, out, "--width", "320", "--height", "240")
        print(out)
    for name in STILLS if want("stills") else []:
        out = os.path.join(args.out, name + ".png")
        render(exe, "scenes/%s.cfg" % name, out, "--width", "320", "--height", "240")
        print(out)
    for name, width, height in GI_STILLS if want("gi") else []:
        out = os.path.join(args.out, name.replace("/", "_") + ".png")
        render(exe, "scenes/%s.cfg" % name, out, "--width", str(width), "--height", str(height))
        print(out)
    if not want("strip"):
        return 0
    import matplotlib.image as mpimg
    import numpy as np
    with tempfile.TemporaryDirectory() as tmp:
        frames = []
        for f in STRIP_FRAMES:
            path = os.path.join(tmp, "f_%d.png" % f)
            render(exe, "scenes/anim/orbit.cfg", path, "--frames", str(f),
                   "--width", "160", "--height", "120")
            frames.append(mpimg.imread(path)[:, :, :3])
        gap = np.ones((120, 4, 3), dtype=frames[0].dtype)
        strip = np.concatenate(sum(([f, gap] for f in frames), [])[:-1], axis=1)
        out = os.path.join(args.out, "anim_orbit_strip.png")
        mpimg.imsave(out, strip)
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
