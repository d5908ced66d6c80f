#!/usr/bin/env python3
"""Before/after render times of two streamrt builds, measured in one run (docs/performance.md).

usage: scripts/ab_render.py OLD_BINARY NEW_BINARY [--runs N] [--jobs J] [--size WxH] [--spp S] [--stages]
                             [--stage-names a,b] SCENE...

Renders each scene with the old and the new binary alternately (old, new, old, new, ...),
--runs times each, and prints the median render clock (the summary line's "render" phase:
scene reading, set-up and image writing excluded) of each, and new / old. Alternating keeps
the two series under the same load on a shared machine. Writes nothing but temporary PFMs.

With --stages, runs `--profile` instead and compares the intersect and occlusion stages'
thread CPU time (immune to time spent descheduled), median and minimum of each series: the
figures of docs/performance.md's traversal changes (use --jobs 1). --stage-names picks
other rows of that table (default intersect,occlusion; e.g. shade+spawn,intersect).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile


def streamrt(binary, scene, args, out, *extra):
    """Runs one render with the options asked for; its output (stdout and stderr)."""
    cmd = [binary, "-j%d" % args.jobs, *extra, scene, "-o", out]
    if args.size:
        w, h = args.size.split("x")
        cmd += ["--width", w, "--height", h]
    if args.spp:
        cmd += ["--spp", str(args.spp)]
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return r.stdout + r.stderr


def render_seconds(binary, scene, args, out):
    text = streamrt(binary, scene, args, out)
    m = re.search(r"render ([0-9.]+) s", text)
    if not m:
        sys.exit("no render time in: " + text)
    return float(m.group(1))


def stage_seconds(binary, scene, args, out):
    """Thread CPU seconds of the stages args.stage_names (--profile's table), in that order."""
    text = streamrt(binary, scene, args, out, "--profile")
    cpu = {}
    for line in text.splitlines():
        f = line.split()
        if len(f) >= 4 and f[0] in args.stage_names and f[0] not in cpu:
            cpu[f[0]] = float(f[3])
    if len(cpu) != len(args.stage_names):
        sys.exit("no %s rows in: %s" % (" and ".join(args.stage_names), text))
    return tuple(cpu[n] for n in args.stage_names)


def compare_stages(args, scene, out):
    runs = {"old": [], "new": []}
    for _ in range(args.runs):
        for which in ("old", "new"):
            runs[which].append(stage_seconds(getattr(args, which), scene, args, out))
    row = [scene]
    for k in range(len(args.stage_names)):
        for pick in (statistics.median, min):
            old, new = pick(r[k] for r in runs["old"]), pick(r[k] for r in runs["new"])
            row.append("%.4f -> %.4f (%.3f)" % (old, new, new / old))
    print("| " + " | ".join(row) + " |", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--size", help="WxH (default: the scene's)")
    ap.add_argument("--spp", type=int)
    ap.add_argument("--stages", action="store_true", help="compare stages' CPU time (--stage-names)")
    ap.add_argument("--stage-names", default="intersect,occlusion",
                    help="rows of --profile's stage table to compare (default intersect,occlusion)")
    args = ap.parse_args()
    args.stage_names = args.stage_names.split(",")
    if args.stages:
        head = ["%s median s, old -> new (new / old)" % args.stage_names[0], "%s min" % args.stage_names[0]]
        for name in args.stage_names[1:]:
            head += ["%s median" % name, "%s min" % name]
        print("| scene | " + " | ".join(head) + " |")
        print("|---" * (1 + len(head)) + "|")
        with tempfile.TemporaryDirectory() as tmp:
            for scene in args.scenes:
                compare_stages(args, scene, os.path.join(tmp, "x.pfm"))
        return
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
