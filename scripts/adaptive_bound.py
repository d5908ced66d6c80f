#!/usr/bin/env python3
"""How few camera rays any per-pixel sample allocation could spend at uniform 16 spp's error
(docs/adaptive-sampling.md, "How far per-pixel allocation can go").

usage: /usr/bin/python3 scripts/adaptive_bound.py [--scenes a.cfg,b.cfg] [--build DIR] [-j J]

For each scene (default whitted, textured, soft_shadows) at its own size: a reference (the
stream engine, --ref-spp uniform stratified samples), then uniform stratified renders at
1, 2, 4, ..., 64 spp. Each pixel's squared error e(n)^2 against the reference is one noisy
draw, so the script models it as a * n^-p: p is the image's own exponent (a least-squares fit
of log MSE against log n over the renders), and a per pixel is the mean over the renders of
e(n)^2 n^p. An oracle that knows every pixel's a then gives pixel i the n_i that minimises
a_i n_i^-p + lambda n_i (n_i = (p a_i / lambda)^(1 / (p + 1)), at least 1 and at most --cap),
with lambda chosen so that the modelled image MSE equals uniform 16's measured one. Its mean
n_i over 16 is the fewest camera rays per pixel, against uniform 16, that any allocation by
pixel could spend (camera rays only: a pixel's secondary rays are not counted, so where the
refined pixels are the dearest ones, as on whitted, the saving in time is smaller still).
Prints one line per scene.
"""
import argparse
import math
import os
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402
from adaptive_bench import luminance, scene_size  # noqa: E402


def render(exe, scene, size, spp, jobs, out):
    subprocess.run([exe, scene, "-q", "-j", str(jobs), "--spp", str(spp), "--sampler", "stratified",
                    "--width", str(size[0]), "--height", str(size[1]), "-o", out], check=True)
    w, h, vals = pc.read_pfm(out)
    return luminance(pc.np.asarray(vals, pc.np.float64).reshape(h, w, 3))


def oracle_ratio(a, p, target_mse, cap):
    """Mean n over 16 of the oracle allocation whose modelled MSE is target_mse (bisection on lambda)."""
    np = pc.np

    def alloc(lam):
        return np.clip((p * a / lam) ** (1.0 / (p + 1.0)), 1.0, cap)

    lo, hi = 1e-30, 1e30  # a larger lambda buys fewer samples: MSE decreasing in n, so bisect in log space
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        n = alloc(mid)
        if (a * n ** -p).mean() > target_mse:
            hi = mid
        else:
            lo = mid
    n = alloc(lo)
    return n.mean() / 16.0, float((a * n ** -p).mean())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="scenes/whitted.cfg,scenes/textured.cfg,scenes/soft_shadows.cfg")
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"))
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--cap", type=int, default=64)
    ap.add_argument("-j", "--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    if pc.np is None:
        sys.exit("needs NumPy: run with /usr/bin/python3")
    np = pc.np
    exe = pc.binary(args.build)
    levels = [1, 2, 4, 8, 16, 32, 64]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x.pfm")
        for name in args.scenes.split(","):
            path = name if os.path.isabs(name) else os.path.join(pc.ROOT, name)
            size = scene_size(path)
            ref = render(exe, path, size, args.ref_spp, args.jobs, out)
            err2 = {n: (render(exe, path, size, n, args.jobs, out) - ref) ** 2 for n in levels}
            mse = np.array([err2[n].mean() for n in levels])
            p = -np.polyfit(np.log(levels), np.log(mse), 1)[0]
            a = np.mean([err2[n] * n ** p for n in levels], axis=0)
            ratio, model_mse = oracle_ratio(a, p, err2[16].mean(), args.cap)
            print("%s (%dx%d): image MSE ~ n^-%.2f; uniform 16 spp RMSE %.5f (luminance, reference %d spp); "
                  "the oracle allocation reaches it (modelled RMSE %.5f) with %.2f camera rays per pixel: "
                  "%.2f of uniform 16's" % (os.path.basename(path), size[0], size[1], p, math.sqrt(err2[16].mean()),
                                            args.ref_spp, math.sqrt(model_mse), 16 * ratio, ratio), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
