#!/usr/bin/env python3
"""Stream engine against the recursive baseline, whole process, runs alternated
(docs/performance.md, "The closest walk on large meshes" and the issue's 5x target).

usage: /usr/bin/python3 scripts/engine_ratio.py [--streamrt build/engine/streamrt] [--runs 9]
                                                [--jobs 2] [--size 1280x720] [SCENE]

Runs `streamrt -jJ SCENE --engine recursive` and `--engine stream` alternately, --runs times
each (recursive, stream, recursive, ...), so both series see the same load on a shared
machine, and prints the median wall time of each (process start to exit, reading and writing
included) and their ratio, then the same for the render phase alone (the summary line's
"render" figure: the process's start, the scene's reading and the picture's writing, which
both engines share, left out). SCENE defaults to perf/scenes/peer/bunny_glass.cfg (its mesh comes
from scripts/fetch_bunny.py). The picture goes to a temporary PPM, removed at the end.

--free-after G adds a third series, the stream engine at --depth G (the same picture's rays
of generations 0 .. G only), and prints the ratios the stream engine would reach if every ray
after generation G cost nothing: a bound on what faster deep rays can give, the shared
reading and writing included.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", default=os.path.join(ROOT, "perf", "scenes", "peer", "bunny_glass.cfg"))
    ap.add_argument("--streamrt", default=os.path.join(ROOT, "build", "engine", "streamrt"))
    ap.add_argument("--runs", type=int, default=9)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--size", default="1280x720", help="WxH (empty: the scene's own)")
    ap.add_argument("--free-after", type=int, metavar="G",
                    help="also time the stream engine at --depth G: the ratios if deeper rays were free")
    args = ap.parse_args()
    if args.runs < 1:
        ap.error("--runs must be at least 1")
    if not os.access(args.streamrt, os.X_OK):
        ap.error("%s is not an executable (build it with scripts/build.sh, or give --streamrt)" % args.streamrt)
    extra = []
    if args.size:
        w, _, h = args.size.partition("x")
        extra = ["--width", w, "--height", h]
    series = {"recursive": ["--engine", "recursive"], "stream": ["--engine", "stream"]}
    if args.free_after is not None:
        series["shallow"] = ["--engine", "stream", "--depth", str(args.free_after)]
    seconds = {name: [] for name in series}
    render = {name: [] for name in series}
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "engine.ppm")
        for _ in range(args.runs):
            for engine in seconds:
                cmd = [args.streamrt, "-j%d" % args.jobs, args.scene, *series[engine], "-o", out, *extra]
                start = time.perf_counter()
                r = subprocess.run(cmd, capture_output=True, text=True)
                elapsed = time.perf_counter() - start
                if r.returncode != 0:
                    sys.stderr.write("engine_ratio.py: %s failed:\n%s" % (" ".join(cmd), r.stderr))
                    return 1
                seconds[engine].append(elapsed)
                m = re.search(r"render ([0-9.]+) s", r.stdout + r.stderr)
                if m:
                    render[engine].append(float(m.group(1)))
    rec, st = statistics.median(seconds["recursive"]), statistics.median(seconds["stream"])
    print("%s, -j%d, %s: recursive %.3f s, stream %.3f s (medians of %d alternated runs): stream engine %.2fx the "
          "recursive baseline" % (os.path.relpath(args.scene), args.jobs, args.size or "scene size", rec, st,
                                  args.runs, rec / st))
    if render["recursive"] and render["stream"]:
        rr, rs = statistics.median(render["recursive"]), statistics.median(render["stream"])
        print("render phase alone: recursive %.3f s, stream %.3f s: stream engine %.2fx the recursive baseline"
              % (rr, rs, rr / rs))
    if args.free_after is not None:
        sw = statistics.median(seconds["shallow"])
        line = ("stream engine at --depth %d: %.3f s whole: with every ray after generation %d free, at most %.2fx "
                "the recursive baseline whole process" % (args.free_after, sw, args.free_after, rec / sw))
        if render["shallow"] and render["recursive"]:
            sr = statistics.median(render["shallow"])
            line += ", %.2fx on the render phase (%.3f s)" % (statistics.median(render["recursive"]) / sr, sr)
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
