#!/usr/bin/env python3
"""Rays traced by adaptive sampling at uniform 16 spp's error, on the luminance the decisions
use (docs/adaptive-sampling.md, "Figures"). No timing: rays and RMSE are deterministic.

usage: /usr/bin/python3 scripts/adaptive_sweep.py SCENE T1,T2,... [--build DIR] [--ref-spp N] [--cap N]

Renders the scene (at its own size, -j2) with the stream engine uniformly at --ref-spp
(default 1024; cached in BUILD/perf/reference/) as the reference, at 16 spp, and adaptively
(--spp CAP --adaptive T) at each T; prints each run's rays (from the closing line), the RMSE
of its luminance against the reference and the closing line's estimate over it, then the
rays at uniform 16's RMSE, interpolated in log rays against log RMSE between the two runs
around it. A T list that does not bracket uniform 16's RMSE prints no interpolation.
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402
from adaptive_bench import ADAPTIVE_RE, luminance, rays_in, scene_size  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("thresholds")
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"))
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--cap", type=int, default=64)
    args = ap.parse_args(argv)
    if pc.np is None:
        sys.exit("needs NumPy: run with /usr/bin/python3")
    np = pc.np
    exe = pc.binary(args.build)
    path = args.scene if os.path.isabs(args.scene) else os.path.join(pc.ROOT, args.scene)
    w, h = scene_size(path)
    ref_dir = os.path.join(args.build, "perf", "reference")
    os.makedirs(ref_dir, exist_ok=True)
    base = os.path.splitext(os.path.basename(path))[0]
    ref_path = os.path.join(ref_dir, "%s_%dx%d_%dspp_stream.pfm" % (base, w, h, args.ref_spp))
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x.pfm")

        def render(extra, to=out):
            p = subprocess.run([exe, path, "-j2", "--width", str(w), "--height", str(h), "-o", to, *extra],
                               capture_output=True, text=True, check=True)
            return p.stdout

        if not os.path.exists(ref_path):
            render(["--spp", str(args.ref_spp), "--sampler", "stratified"], ref_path + ".tmp.pfm")
            os.replace(ref_path + ".tmp.pfm", ref_path)

        def lum(file):
            ww, hh, vals = pc.read_pfm(file)
            return luminance(np.asarray(vals, np.float64).reshape(hh, ww, 3))

        ref = lum(ref_path)
        line = render(["--spp", "16"])
        r16, e16 = rays_in(line), math.sqrt(((lum(out) - ref) ** 2).mean())
        print("%s: uniform 16 spp %.2f M rays, luminance RMSE %.5f (reference: stream engine, %d spp)" % (
            base, r16 / 1e6, e16, args.ref_spp))
        points = []
        for t in args.thresholds.split(","):
            line = render(["--spp", str(args.cap), "--adaptive", t])
            rays, err = rays_in(line), math.sqrt(((lum(out) - ref) ** 2).mean())
            m = ADAPTIVE_RE.search(line)
            est = float(m.group(3)) if m else float("nan")
            points.append((err, rays))
            print("  T %s: %.2f M rays (%.3f of uniform 16's), RMSE %.5f, estimated / measured %.2f" % (
                t, rays / 1e6, rays / r16, err, est / err))
    points.sort()
    for (e0, n0), (e1, n1) in zip(points, points[1:]):
        if e0 <= e16 <= e1 and e1 > e0:
            f = (math.log(e16) - math.log(e0)) / (math.log(e1) - math.log(e0))
            print("  at uniform 16's error: %.3f of its rays" % (math.exp(math.log(n0) + f * (math.log(n1) - math.log(n0))) / r16))
            break
    return 0


if __name__ == "__main__":
    sys.exit(main())
