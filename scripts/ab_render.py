#!/usr/bin/env python3
"""Before/after render times of two streamrt builds, measured in one run (docs/performance.md).

usage: scripts/ab_render.py OLD_BINARY NEW_BINARY [--runs N] [--jobs J] [--size WxH] [--spp S] SCENE...

Renders each scene with the old and the new binary alternately (old, new, old, new, ...),
--runs times each, and prints the median render clock (the summary line's "render" phase:
scene reading, set-up and image writing excluded) of each, and new / old. Alternating keeps
the two series under the same load on a shared machine. Writes nothing but temporary PFMs.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile


def render_seconds(binary, scene, args, out):
    cmd = [binary, "-j%d" % args.jobs, scene, "-o", out]
    if args.size:
        w, h = args.size.split("x")
        cmd += ["--width", w, "--height", h]
    if args.spp:
        cmd += ["--spp", str(args.spp)]
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    m = re.search(r"render ([0-9.]+) s", r.stdout + r.stderr)
    if not m:
        sys.exit("no render time in: " + r.stdout + r.stderr)
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--size", help="WxH (default: the scene's)")
    ap.add_argument("--spp", type=int)
    args = ap.parse_args()
    print("| scene | old (s) | new (s) | new / old |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x.pfm")
        for scene in args.scenes:
            times = {"old": [], "new": []}
            render_seconds(args.new, scene, args, out)  # warm the page cache
            for _ in range(args.runs):
                for which in ("old", "new"):
                    times[which].append(render_seconds(getattr(args, which), scene, args, out))
            old, new = statistics.median(times["old"]), statistics.median(times["new"])
            print("| %s | %.4f | %.4f | %.3f |" % (scene, old, new, new / old), flush=True)


if __name__ == "__main__":
    main()
