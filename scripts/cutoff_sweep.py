#!/usr/bin/python3
"""The weight cut-off's effect on time and error (docs/performance.md, "Weight cut-off").

usage: /usr/bin/python3 scripts/cutoff_sweep.py [--scene scenes/whitted.cfg] [--depth 16]
           [--cutoffs 0,0.001,0.01,0.05,0.1,0.2] [--runs 5] [--jobs 2] [--build build]
           [--engines stream,recursive]

Renders the scene with each cut-off (image cutoff=, --cutoff) with both engines, and reports
each picture's error against the same engine's exact picture (cut-off 0), the render time
(streamrt's render clock, median of --runs), the rays traced (every kind), and what an 8-bit
sRGB output would show of the difference: the share of pixels off by more than one step (1/255)
in some channel and the largest difference in steps. The renders run in
this process through the streamrt Python module (build/python, docs/python.md): the pictures
stay NumPy arrays, no image files are written.
"""
import argparse
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402


def srgb8(linear):
    """The 8-bit sRGB values of a linear image (clamped to [0, 1], the sRGB curve, rounded)."""
    x = pc.np.clip(pc.np.asarray(linear, pc.np.float64), 0.0, 1.0)
    v = pc.np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    return pc.np.rint(v * 255.0).astype(pc.np.int32)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default=os.path.join(pc.ROOT, "scenes", "whitted.cfg"))
    ap.add_argument("--depth", type=int, default=16)
    ap.add_argument("--width", type=int, default=1280)
    ap.add_argument("--height", type=int, default=720)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--cutoffs", default="0,0.001,0.01,0.05,0.1,0.2")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"))
    ap.add_argument("--engines", default="stream,recursive")
    a = ap.parse_args()
    rt = pc.module(a.build)
    cutoffs = [float(c) for c in a.cutoffs.split(",")]
    print(f"{os.path.relpath(a.scene, pc.ROOT)} {a.width}x{a.height} spp {a.spp} depth {a.depth} -j{a.jobs}, "
          f"median of {a.runs}")
    print("| engine | cut-off | render s | rays | PSNR vs exact (dB) | RMSE | 8-bit: pixels off > 1/255 | largest (steps) |")
    print("|---|---|---|---|---|---|---|---|")
    for engine in a.engines.split(","):
        exact = None
        for c in cutoffs:
            runs = [rt.render(a.scene, engine=engine, threads=a.jobs, spp=a.spp, width=a.width, height=a.height,
                              depth=a.depth, cutoff=c)
                    for _ in range(a.runs if engine == "stream" else 1)]
            seconds = pc.median([r.seconds["render"] for r in runs])
            image = runs[0].image
            if c == 0:
                exact = image
            err = pc.array_error(image, exact if exact is not None else image)
            psnr = "exact" if c == 0 else f"{err['psnr']:.1f}"
            rays = runs[0].rays
            steps = abs(srgb8(image) - srgb8(exact if exact is not None else image))
            off = 100.0 * float((steps.max(axis=-1) > 1).mean())
            print(f"| {engine} | {c:g} | {seconds:.3f} | {rays['total']} | {psnr} | {err['rmse']:.2e} | {off:.3f} % "
                  f"| {int(steps.max())} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
