#!/usr/bin/env python3
"""What a CSG node costs over its children (issue 49's target: at most 1.5x): the stream engine's
`--profile` intersect stage (thread CPU seconds, one thread) on a difference of two spheres
(perf/scenes/csg/difference.cfg) and on the same two spheres as plain objects
(perf/scenes/csg/spheres.cfg), run in alternated pairs so that both see the same load; prints
the median of the pairs' ratios with their range, and each scene's median (docs/performance.md,
"CSG").

    /usr/bin/python3 scripts/csg_node_cost.py [--build build] [--pairs 15]
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402

SCENES = {name: os.path.join(pc.ROOT, "perf", "scenes", "csg", name + ".cfg") for name in ("difference", "spheres")}


def intersect_seconds(exe, scene, out):
    """The intersect row's CPU seconds of one `--profile` run at -j1."""
    text = subprocess.run([exe, "-j1", "--profile", scene, "-o", out], check=True, capture_output=True,
                          text=True).stdout
    for line in text.splitlines():
        fields = line.split()
        if fields and fields[0] == "intersect":
            return float(fields[3])
    raise SystemExit("no intersect row in the profile of %s" % scene)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"), help="build folder (default build/)")
    ap.add_argument("--pairs", type=int, default=15, help="alternated pairs of runs (default 15)")
    args = ap.parse_args()
    exe = pc.binary(args.build)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x.pfm")
        pairs = [(intersect_seconds(exe, SCENES["difference"], out), intersect_seconds(exe, SCENES["spheres"], out))
                 for _ in range(args.pairs)]
    ratios = sorted(a / b for a, b in pairs)
    print("difference over the two spheres, intersect CPU, -j1, %d alternated pairs: median %.2fx (%.2f - %.2f); "
          "difference %.4f s, spheres %.4f s (medians)" % (
              len(pairs), statistics.median(ratios), ratios[0], ratios[-1],
              statistics.median(a for a, _ in pairs), statistics.median(b for _, b in pairs)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
