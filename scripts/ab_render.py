#!/usr/bin/env python3
"""Before/after render times of two streamrt builds, measured in one run (docs/performance.md).

usage: scripts/ab_render.py OLD_BINARY NEW_BINARY [--runs N] [--jobs J] [--size WxH] [--spp S]
                             [--adaptive T] [--output EXT] [--stages [--stage-names a,b] | --whole] SCENE...

Renders each scene with the old and the new binary alternately (old, new, old, new, ...),
--runs times each, and prints the median render clock (the summary line's "render" phase:
scene reading, set-up and image writing excluded) of each, and new / old. Alternating keeps
the two series under the same load on a shared machine. Writes nothing but temporary PFMs.

With --stages, runs `--profile` instead and compares the intersect and occlusion stages'
thread CPU time (immune to time spent descheduled), median and minimum of each series: the
figures of docs/performance.md's traversal changes (use --jobs 1). --stage-names picks
other rows of that table (default intersect,occlusion; e.g. shade+spawn,intersect).

With --whole, compares the whole process instead (start to exit as the parent sees it:
reading, set-up, rendering, writing and freeing), median wall time and median peak RSS of
each series. --output picks the picture's format (pfm by default; png to time the encoder too).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time


def command(binary, scene, args, out, *extra):
    """The streamrt command line of one render with the options asked for."""
    cmd = [binary, "-j%d" % args.jobs, *extra, scene, "-o", out]
    if args.adaptive:
        cmd += ["--adaptive", str(args.adaptive)]
    if args.size:
        w, h = args.size.split("x")
        cmd += ["--width", w, "--height", h]
    if args.spp:
        cmd += ["--spp", str(args.spp)]
    return cmd


def streamrt(binary, scene, args, out, *extra):
    """Runs one render with the options asked for; its output (stdout and stderr)."""
    r = subprocess.run(command(binary, scene, args, out, *extra), capture_output=True, text=True, check=True)
    return r.stdout + r.stderr


def render_seconds(binary, scene, args, out):
    text = streamrt(binary, scene, args, out)
    m = re.search(r"render ([0-9.]+) s", text)
    if not m:
        sys.exit("no render time in: " + text)
    return float(m.group(1))


def whole_process(binary, scene, args, out):
    """Wall seconds and peak RSS (MiB) of one whole streamrt process, as its parent sees them."""
    cmd = command(binary, scene, args, out, "-q")
    with tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
        _, status, ru = os.wait4(p.pid, 0)  # this child's own rusage: its peak RSS
        wall = time.perf_counter() - t0
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            sys.exit("%s failed: %s" % (" ".join(cmd), err.read().decode().strip()))
    return wall, ru.ru_maxrss / 1024.0


def compare_whole(args, scene, out):
    runs = {"old": [], "new": []}
    whole_process(args.new, scene, args, out)  # warm the page cache
    for i in range(args.runs):
        order = ("old", "new") if i % 2 == 0 else ("new", "old")
        for which in order:
            runs[which].append(whole_process(getattr(args, which), scene, args, out))
    old_t, new_t = (statistics.median(t for t, _ in runs[w]) for w in ("old", "new"))
    old_m, new_m = (statistics.median(m for _, m in runs[w]) for w in ("old", "new"))
    print("| %s | %.4f | %.4f | %.3f | %.1f -> %.1f |" % (scene, old_t, new_t, new_t / old_t, old_m, new_m), flush=True)


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
    ap.add_argument("--adaptive", type=float, help="--adaptive T (with --spp as the cap)")
    ap.add_argument("--output", default="pfm", help="the picture's format: pfm (default), png, ppm, exr")
    ap.add_argument("--whole", action="store_true", help="compare whole-process wall time and peak RSS")
    ap.add_argument("--stages", action="store_true", help="compare stages' CPU time (--stage-names)")
    ap.add_argument("--stage-names", default="intersect,occlusion",
                    help="rows of --profile's stage table to compare (default intersect,occlusion)")
    args = ap.parse_args()
    args.stage_names = args.stage_names.split(",")
    picture = "x." + args.output
    if args.whole:
        print("| scene | old, whole process (s) | new (s) | new / old | peak RSS, MiB |")
        print("|---|---|---|---|---|")
        with tempfile.TemporaryDirectory() as tmp:
            for scene in args.scenes:
                compare_whole(args, scene, os.path.join(tmp, picture))
        return
    if args.stages:
        head = ["%s median s, old -> new (new / old)" % args.stage_names[0], "%s min" % args.stage_names[0]]
        for name in args.stage_names[1:]:
            head += ["%s median" % name, "%s min" % name]
        print("| scene | " + " | ".join(head) + " |")
        print("|---" * (1 + len(head)) + "|")
        with tempfile.TemporaryDirectory() as tmp:
            for scene in args.scenes:
                compare_stages(args, scene, os.path.join(tmp, picture))
        return
    print("| scene | old (s) | new (s) | new / old |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, picture)
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
