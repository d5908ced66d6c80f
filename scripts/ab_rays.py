#!/usr/bin/env python3
"""Before/after mesh-walk throughput of two builds of perf/embree_rays, measured in one run
(docs/performance.md, "Ray traversal, Embree against streamrt").

usage: scripts/ab_rays.py OLD_EMBREE_RAYS NEW_EMBREE_RAYS [--rounds N] [--reps R]
                          [--rays primary,shadow,...] [--shuffle] MESH...

Runs the two harness binaries alternately (old then new, then new then old, ...), --rounds
times each, every mesh, and prints per mesh and ray set the median Mrays/s of streamrt's packet
walk (the `streamrt` column) and of the single-ray walk (`single`) for each build, new / old
for the medians and for the fastest runs, and the ratio to Embree16 (its median over both
builds' runs: the same library either way). Alternating keeps both series under the same load
on a shared machine.
"""
import argparse
import collections
import statistics
import subprocess
import sys

KINDS = ("primary", "shadow", "mirror", "glass", "diffuse")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--reps", type=int, default=3, help="the harness's own --reps (median of R)")
    ap.add_argument("--rays", default=",".join(KINDS))
    ap.add_argument("--shuffle", action="store_true", help="the harness's --shuffle: rays in a random order")
    args = ap.parse_args()
    runs = collections.defaultdict(list)  # (mesh, kind, build, column) -> Mrays/s
    for r in range(args.rounds):
        order = (("old", args.old), ("new", args.new))
        for build, binary in order if r % 2 == 0 else order[::-1]:
            for mesh in args.meshes:
                out = subprocess.run([binary, "--reps", str(args.reps), "--rays", args.rays, mesh] + (["--shuffle"] if args.shuffle else []),
                                     capture_output=True, text=True, check=True).stdout
                for line in out.splitlines():
                    f = line.split()
                    if f and f[0] in KINDS:
                        runs[(mesh, f[0], build, "embree16")].append(float(f[2]))
                        runs[(mesh, f[0], build, "streamrt")].append(float(f[4]))
                        runs[(mesh, f[0], build, "single")].append(float(f[6]))
    print("mesh | rays | streamrt old -> new (new/old, fastest) | / Embree16 | single old -> new (new/old, fastest)")
    for mesh in args.meshes:
        for kind in KINDS:
            if not runs[(mesh, kind, "old", "streamrt")]:
                continue
            col = lambda build, c: runs[(mesh, kind, build, c)]
            med = lambda build, c: statistics.median(col(build, c))
            e16 = statistics.median(col("old", "embree16") + col("new", "embree16"))
            so, sn = med("old", "streamrt"), med("new", "streamrt")
            fo, fn = max(col("old", "streamrt")), max(col("new", "streamrt"))
            qo, qn = med("old", "single"), med("new", "single")
            gfo, gfn = max(col("old", "single")), max(col("new", "single"))
            print(f"{mesh} | {kind} | {so:.2f} -> {sn:.2f} ({sn / so:.3f}, {fn / fo:.3f}) | "
                  f"{so / e16:.2f}x -> {sn / e16:.2f}x | {qo:.2f} -> {qn:.2f} ({qn / qo:.3f}, {gfn / gfo:.3f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
