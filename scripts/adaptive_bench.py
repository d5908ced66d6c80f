#!/usr/bin/env python3
"""Adaptive sampling against uniform sampling at equal error (docs/adaptive-sampling.md,
"Figures"; docs/performance.md).

usage: /usr/bin/python3 scripts/adaptive_bench.py [--scenes a.cfg,b.cfg] [--build DIR] [--runs N]

For each scene (default whitted, textured, soft_shadows) at its own size (the scene's `image`
statement; --width/--height override it): a reference
(the recursive engine, uniform, --ref-spp samples, stratified; cached in BUILD/perf/reference/),
then uniform renders at 4, 8, 16 and 32 spp and adaptive renders with --spp --cap as the cap
and each threshold of --thresholds, all with the streamrt command at -jJOBS, timed whole
(process start to exit, median of --runs). Each picture's RMSE against the reference is
image_compare's (every channel clamped to [0, 1]); the estimate check compares the adaptive
render's own estimated RMSE (the closing line's, luminance) with the measured RMSE of the
luminance (unclamped). Prints one table per scene, the equal-error ratio (the fastest adaptive
run whose RMSE is at most uniform 16 spp's, its time over uniform 16's), the rays traced at
equal error (every kind, from the closing lines; interpolated between the sweep's two runs
around uniform 16 spp's RMSE, in log rays against log RMSE: rays and RMSE are deterministic,
so this ratio does not move with the machine's load) and writes BUILD/perf/adaptive.csv.

It also prints what a third of uniform 16 spp's time can pay for: the process's fixed cost F
(the same scene rendered at 8 x 8 pixels: start, reading, set-up, writing, exit) taken off,
the rest spent on rays at uniform 4 spp's cost per ray ((its seconds - F) / its rays: the
same number of rays as an adaptive render at uniform 16's error, traced in the most coherent
order adaptive sampling could hope for, with no adaptive work at all). An adaptive render
that reaches uniform 16's error with more rays than that cannot take a third of its time.
"""
import argparse
import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402

ADAPTIVE_RE = re.compile(r"spp ([0-9.]+) adaptive \(at most (\d+), estimated error ([0-9.e+-]+)")
RAYS_RE = re.compile(r"s, (\d+) rays")


def rays_in(line):
    m = RAYS_RE.search(line)
    if not m:
        sys.exit("no ray count in: " + line)
    return int(m.group(1))


def rays_at_error(rows, rmse):
    """Rays of the adaptive runs interpolated to `rmse` (log-log between the two runs around it), or None."""
    import math
    pts = sorted((r["rmse"], r["rays"]) for r in rows if r["sampler"] == "adaptive")
    for (e0, r0), (e1, r1) in zip(pts, pts[1:]):
        if e0 <= rmse <= e1 and e1 > e0:
            f = (math.log(rmse) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(r0) + f * (math.log(r1) - math.log(r0)))
    return None


def scene_size(path):
    """The width and height of a scene's `image` statement (the renderer's defaults when absent)."""
    width, height = 640, 480
    with open(path) as f:
        for line in f:
            words = line.split("#")[0].split()
            if words and words[0] == "image":
                for w in words[1:]:
                    key, _, value = w.partition("=")
                    if key == "width":
                        width = int(value)
                    elif key == "height":
                        height = int(value)
    return width, height


def run(exe, scene, args, size, extra):
    """Whole-process seconds (median of args.runs), the last picture and its closing line."""
    times, line = [], ""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.pfm")
        cmd = [exe, scene, "-j", str(args.jobs), "--width", str(size[0]), "--height", str(size[1]),
               "-o", out, *extra]
        for _ in range(args.runs):
            t0 = time.perf_counter()
            p = subprocess.run(cmd, capture_output=True, text=True)
            times.append(time.perf_counter() - t0)
            if p.returncode != 0:
                sys.exit("%s failed: %s" % (" ".join(cmd), p.stderr.strip()))
            line = p.stdout
        w, h, vals = pc.read_pfm(out)
    return statistics.median(times), pc.np.asarray(vals, pc.np.float64).reshape(h, w, 3), line


def luminance(img):
    return 0.2126 * img[..., 0] + 0.7152 * img[..., 1] + 0.0722 * img[..., 2]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="scenes/whitted.cfg,scenes/textured.cfg,scenes/soft_shadows.cfg")
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"))
    ap.add_argument("--width", type=int, help="picture width (default: the scene's own)")
    ap.add_argument("--height", type=int, help="picture height (default: the scene's own)")
    ap.add_argument("--ref-spp", type=int, default=256)
    ap.add_argument("--cap", type=int, default=64)
    ap.add_argument("--thresholds", default="0.04,0.02,0.01,0.005,0.0025,0.00125")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args(argv)
    if pc.np is None:
        sys.exit("needs NumPy: run with /usr/bin/python3")
    exe = pc.binary(args.build)
    out_dir = os.path.join(args.build, "perf")
    ref_dir = os.path.join(out_dir, "reference")
    os.makedirs(ref_dir, exist_ok=True)
    rows = []
    for name in args.scenes.split(","):
        path = name if os.path.isabs(name) else os.path.join(pc.ROOT, name)
        base = os.path.splitext(os.path.basename(path))[0]
        own = scene_size(path)
        size = (args.width or own[0], args.height or own[1])
        ref_path = os.path.join(ref_dir, "%s_%dx%d_%dspp_uniform.pfm" % (base, size[0], size[1], args.ref_spp))
        if not os.path.exists(ref_path):
            print("reference: %s, recursive engine, %d spp..." % (base, args.ref_spp), flush=True)
            subprocess.run([exe, path, "-q", "-j", str(args.jobs), "--engine", "recursive", "--spp", str(args.ref_spp),
                            "--sampler", "stratified", "--width", str(size[0]), "--height", str(size[1]),
                            "-o", ref_path + ".tmp.pfm"], check=True)
            os.replace(ref_path + ".tmp.pfm", ref_path)
        w, h, vals = pc.read_pfm(ref_path)
        ref = pc.np.asarray(vals, pc.np.float64).reshape(h, w, 3)
        scene_rows = []
        for spp in (4, 8, 16, 32):
            secs, img, line = run(exe, path, args, size, ["--spp", str(spp)])
            scene_rows.append(dict(scene=base, sampler="uniform", threshold="", spp=spp, rays=rays_in(line), seconds=secs,
                                   rmse=pc.array_error(img, ref)["rmse"], estimated="", measured_luminance=""))
        for t in args.thresholds.split(","):
            secs, img, line = run(exe, path, args, size, ["--spp", str(args.cap), "--adaptive", t])
            m = ADAPTIVE_RE.search(line)
            if not m:
                sys.exit("no adaptive summary in: " + line)
            lum = float(pc.np.sqrt(((luminance(img) - luminance(ref)) ** 2).mean()))
            scene_rows.append(dict(scene=base, sampler="adaptive", threshold=float(t), spp=float(m.group(1)),
                                   rays=rays_in(line), seconds=secs, rmse=pc.array_error(img, ref)["rmse"],
                                   estimated=float(m.group(3)), measured_luminance=lum))
        print("\n%s, %dx%d, -j%d, whole process, median of %d (reference: recursive, %d spp)" % (
            base, size[0], size[1], args.jobs, args.runs, args.ref_spp))
        print("| sampling | spp | rays | seconds | RMSE | estimated / measured (luminance) |")
        print("|---|---|---|---|---|---|")
        for r in scene_rows:
            how = "uniform" if r["sampler"] == "uniform" else "adaptive T=%g" % r["threshold"]
            ratio = "" if r["sampler"] == "uniform" else "%.4f / %.4f (%.2f)" % (
                r["estimated"], r["measured_luminance"], r["estimated"] / max(r["measured_luminance"], 1e-12))
            print("| %s | %s | %.2f M | %.3f | %.5f | %s |" % (
                how, r["spp"] if r["sampler"] == "uniform" else "%.2f" % r["spp"], r["rays"] / 1e6, r["seconds"], r["rmse"],
                ratio))
        u16 = next(r for r in scene_rows if r["sampler"] == "uniform" and r["spp"] == 16)
        ok = [r for r in scene_rows if r["sampler"] == "adaptive" and r["rmse"] <= u16["rmse"]]
        if ok:
            best = min(ok, key=lambda r: r["seconds"])
            print("equal error (uniform 16 spp, RMSE %.5f, %.3f s): adaptive T=%g in %.3f s, %.2f of the time" % (
                u16["rmse"], u16["seconds"], best["threshold"], best["seconds"], best["seconds"] / u16["seconds"]))
        else:
            print("equal error: no adaptive run of the sweep reaches uniform 16 spp's RMSE %.5f" % u16["rmse"])
        rays = rays_at_error(scene_rows, u16["rmse"])
        if rays is not None:
            print("rays at equal error (interpolated): %.2f M, %.3f of uniform 16's %.2f M" % (
                rays / 1e6, rays / u16["rays"], u16["rays"] / 1e6))
        fixed = run(exe, path, args, (8, 8), ["--spp", "16"])[0]
        u4 = next(r for r in scene_rows if r["sampler"] == "uniform" and r["spp"] == 4)
        per_ray = (u4["seconds"] - fixed) / u4["rays"]
        affordable = (u16["seconds"] / 3 - fixed) / per_ray
        print("a third of uniform 16's time (%.3f s) pays, after the fixed cost %.4f s (8 x 8 pixels), for "
              "%.2f M rays at uniform 4 spp's cost per ray (%.1f ns): %.3f of uniform 16's rays" % (
                  u16["seconds"] / 3, fixed, affordable / 1e6, per_ray * 1e9, affordable / u16["rays"]))
        rows += scene_rows
    csv_path = os.path.join(out_dir, "adaptive.csv")
    with open(csv_path, "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(rows[0]))
        wr.writeheader()
        wr.writerows(rows)
    print("\nwrote", csv_path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
