#!/usr/bin/env python3
"""Measures streamrt across processes on this machine (docs/distributed.md, "Measured"):
one process at -j1 and -j2 against 1-4 MPI ranks, on one scene, and prints a Markdown table
of the best wall time of REPEAT runs, the CPU seconds of that run (all processes), the
rays per second, and whether the PFM bytes equal the one-process picture.

    scripts/distributed_figures.py [--streamrt build/engine/streamrt] [--scene scenes/whitted.cfg]
                                   [--size 1280x720] [--spp 1] [--repeat 3]
"""
import argparse
import os
import re
import resource
import subprocess
import tempfile
import time

MPIRUN = ["mpirun", "--oversubscribe", "--mca", "btl", "self,tcp", "--mca", "btl_tcp_if_include", "lo",
          "--mca", "oob_tcp_if_include", "lo"]


def timed(cmd, env):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    rays = int(re.search(r"(\d+) rays", r.stdout).group(1))
    render = float(re.search(r"render ([0-9.]+) s", r.stdout).group(1))
    return wall, cpu, rays, render


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--streamrt", default="build/engine/streamrt")
    ap.add_argument("--scene", default="scenes/whitted.cfg")
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--spp", default="1")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    w, h = args.size.split("x")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    common = [args.scene, "--width", w, "--height", h, "--spp", args.spp]
    with tempfile.TemporaryDirectory() as d:
        ref = os.path.join(d, "ref.pfm")
        subprocess.run([args.streamrt, "-j2", *common, "-o", ref, "-q"], check=True)
        want = open(ref, "rb").read()
        runs = [("1 process, -j1", [args.streamrt, "-j1"]), ("1 process, -j2", [args.streamrt, "-j2"])]
        for ranks in (1, 2, 3, 4):
            runs.append((f"{ranks} rank(s) x -j1, dynamic", MPIRUN + ["-np", str(ranks), args.streamrt, "--mpi", "-j1"]))
        runs.append(("2 ranks x -j1, static", MPIRUN + ["-np", "2", args.streamrt, "--mpi", "-j1",
                                                         "--mpi-schedule", "static"]))
        print(f"load average at start: {os.getloadavg()[0]:.1f}; {args.scene} {args.size}, spp {args.spp}, "
              f"best of {args.repeat}\n")
        print("| run | wall s (whole process) | render s | CPU s | Mrays/s (render) | same bytes |")
        print("|---|---|---|---|---|---|")
        for name, cmd in runs:
            best = None
            out = os.path.join(d, "out.pfm")
            for _ in range(args.repeat):
                m = timed(cmd + [*common, "-o", out], env)
                if best is None or m[0] < best[0]:
                    best = m
            same = open(out, "rb").read() == want
            wall, cpu, rays, render = best
            print(f"| {name} | {wall:.2f} | {render:.2f} | {cpu:.2f} | {rays / render / 1e6:.1f} | {'yes' if same else 'NO'} |")


if __name__ == "__main__":
    main()
