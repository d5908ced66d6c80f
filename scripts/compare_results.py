#!/usr/bin/env python3
"""Compares two perf-suite result files (scripts/perf_suite.py), e.g. before and after a change.

usage: scripts/compare_results.py OLD.json NEW.json [--threshold 0.05] [--all]

For every case present in both (same group, scene, engine, -j, spp, size, depth), prints
old and new median render time and the ratio new/old: above 1 is slower (a regression),
below 1 faster. Cases off by more than the threshold are marked; --all prints every case.
The geometric mean of all ratios ends the table. Exit status 0 always (timings are noisy;
read the numbers). Standard library only.
"""
import argparse
import json
import math
import sys


def key(r):
    return (r["group"], r["scene"], r["engine"], r["jobs"], r["spp"], r["width"], r["height"], r.get("depth"))


def main(argv=None):
    ap = argparse.ArgumentParser(description="Ratios new/old of two perf-suite results.json files.")
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--threshold", type=float, default=0.05, help="mark cases off by more (default 0.05 = 5%%)")
    ap.add_argument("--all", action="store_true", help="print unchanged cases too")
    args = ap.parse_args(argv)
    old = {key(r): r for r in json.load(open(args.old))["results"]}
    new = {key(r): r for r in json.load(open(args.new))["results"]}
    common = [k for k in new if k in old]
    if not common:
        print("no case in common")
        return 0
    print("%-10s %-28s %-9s %3s %4s %10s %9s %9s %7s  %s" % ("group", "scene", "engine", "-j", "spp", "size",
                                                           "old s", "new s", "new/old", ""))
    logs, worse, better = [], 0, 0
    for k in common:
        o, n = old[k]["seconds"], new[k]["seconds"]
        ratio = n / o if o > 0 else float("inf")
        logs.append(math.log(ratio))
        mark = ""
        if ratio > 1 + args.threshold:
            mark, worse = "SLOWER", worse + 1
        elif ratio < 1 - args.threshold:
            mark, better = "faster", better + 1
        if mark or args.all:
            print("%-10s %-28s %-9s %3d %4d %10s %9.3f %9.3f %7.3f  %s" % (
                k[0], k[1][-28:], k[2], k[3], k[4], "%dx%d" % (k[5], k[6]), o, n, ratio, mark))
        for f in ("speedup", "err_rmse"):
            if f in old[k] and f in new[k] and old[k][f] and mark:
                print("%68s %s: %.4g -> %.4g (x%.3f)" % ("", f, old[k][f], new[k][f], new[k][f] / old[k][f]))
    gm = math.exp(sum(logs) / len(logs))
    print("%d cases in common: %d slower, %d faster by more than %.0f%%; geometric mean new/old = %.3f" % (
        len(common), worse, better, 100 * args.threshold, gm))
    only = len(set(old) ^ set(new))
    if only:
        print("%d cases in only one of the files (not compared)" % only)
    return 0


if __name__ == "__main__":
    sys.exit(main())
