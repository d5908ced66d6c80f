#!/usr/bin/env python3
"""The stream engine's speed-up over the recursive baseline, and their agreement, per scene.

usage: scripts/speedups.py [--build DIR] [--runs N] [--jobs J] [--size WxH] SCENE[:FRAME]...

Runs `streamrt --compare` (both engines, same settings) --runs times per scene, the scenes
taken in turn so that each sees the same load, and prints a Markdown table of the medians:
recursive and stream render clocks, their ratio, PSNR and the share of pixels off by more
than 1/255. SCENE:FRAME renders that frame of an animated scene. docs/performance.md quotes
its output.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def compare(exe, scene, args, out):
    path, _, frame = scene.partition(":")
    cmd = [exe, "-j%d" % args.jobs, "--compare", os.path.join(ROOT, path), "-o", out]
    if frame:
        cmd += ["--frames", frame]
    if args.size:
        w, h = args.size.split("x")
        cmd += ["--width", w, "--height", h]
    text = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    num = lambda pattern: float(re.search(pattern, text).group(1))
    return dict(recursive=num(r"recursive: ([0-9.]+) s"), stream=num(r"stream: +([0-9.]+) s"),
                psnr=num(r"psnr ([0-9.inf]+) dB"), off=num(r"1/255: ([0-9.]+)%"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--size", help="WxH (default: each scene's)")
    args = ap.parse_args()
    exe = os.path.join(args.build, "engine", "streamrt")
    runs = {s: [] for s in args.scenes}
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x_%d.pfm")
        for _ in range(args.runs):
            for s in args.scenes:
                runs[s].append(compare(exe, s, args, out))
    print("| scene | recursive (s) | stream (s) | speed-up | PSNR (dB) | pixels > 1/255 |")
    print("|---|---|---|---|---|---|")
    for s, rs in runs.items():
        med = lambda k: statistics.median(r[k] for r in rs)
        print("| %s | %.3f | %.3f | %.2fx | %.1f | %.4f %% |" % (
            s, med("recursive"), med("stream"), statistics.median(r["recursive"] / r["stream"] for r in rs),
            med("psnr"), med("off")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
