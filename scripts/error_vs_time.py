#!/usr/bin/env python3
"""Image error against render time, both engines, three sampling patterns and adaptive
sampling (docs/performance.md, "Error against run time").

usage: /usr/bin/python3 scripts/error_vs_time.py [--quick] [--scenes a.cfg,b.cfg] [--build DIR]

For each scene, renders spp = 1, 2, 4, ... 64 with the stream and the recursive engine and
each sampler (grid, stratified, random), and measures each image against a converged
reference: the recursive (double precision) engine at --ref-spp samples per pixel,
stratified, made once and cached in BUILD/perf/reference/. Writes
  BUILD/perf/error_vs_time.csv     scene, engine, sampler, spp, seconds, rmse, psnr, relmse
  BUILD/perf/precision.csv         scene, sampler, spp, stream-vs-recursive rmse/psnr/relmse at
                                   equal spp and equal samples: what single precision costs
(BUILD/perf-quick/ with --quick) and, when matplotlib is there (/usr/bin/python3), one log-log plot per scene into --out
(build/perf/img/; --out docs/img for the docs' pictures)
(scripts/plot_perf.py --errors draws them again from the CSV).
Seconds are streamrt's render clock (-j as given, default 2), median of --runs. The renders run
in this process through the streamrt Python module (build/python, docs/python.md): the
pictures are NumPy arrays, no image file is written but the cached references.
Adaptive sampling (docs/adaptive-sampling.md) adds one curve per engine: --adaptive T for
T in --thresholds, max-spp as the cap, stratified (sampler "adaptive" in the CSV, spp = the
mean samples per pixel taken).
Scenes with area lights (scenes/soft_shadows.cfg) also get a sweep of --light-samples
1, 2, ... max-spp at 1 spp, stratified (sampler "light" in the CSV), and their reference
takes min(--ref-spp, 2 x max-spp) spp (above the sweep's, so no pixel sample is shared) with
--ref-light-samples light samples (default 64, quick 16).
"""
import argparse
import csv
import os
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402

SAMPLERS = ("grid", "stratified", "random")
ENGINES = ("stream", "recursive")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="one scene, spp up to 16, 160x90, 128 spp reference: a smoke run")
    ap.add_argument("--scenes", help="comma-separated scene files (default whitted, shapes, cornell, dof, soft_shadows)")
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"))
    ap.add_argument("--width", type=int, help="default 320 (quick 160)")
    ap.add_argument("--height", type=int, help="default 180 (quick 90)")
    ap.add_argument("--max-spp", type=int, help="default 64 (quick 16)")
    ap.add_argument("--ref-spp", type=int, help="reference spp (default 512, quick 128)")
    ap.add_argument("--ref-light-samples", type=int, help="area-light scenes: reference light samples (default 64, quick 16)")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--runs", type=int, default=1, help="timed renders per point (median)")
    ap.add_argument("--thresholds", default="0.08,0.04,0.02,0.01,0.005",
                    help="adaptive sampling's thresholds T (comma-separated; empty: no adaptive curve)")
    ap.add_argument("--out", "--img", dest="img", default=os.path.join(pc.ROOT, "build", "perf", "img"),
                    help="where the plots go (default build/perf/img; the docs' pictures: --out docs/img)")
    args = ap.parse_args(argv)
    w = args.width or (160 if args.quick else 320)
    h = args.height or (90 if args.quick else 180)
    args.ref_spp = args.ref_spp or (128 if args.quick else 512)
    args.ref_light_samples = args.ref_light_samples or (16 if args.quick else 64)
    max_spp = args.max_spp or (16 if args.quick else 64)
    names = args.scenes.split(",") if args.scenes else (
        ["scenes/whitted.cfg"] if args.quick else ["scenes/whitted.cfg", "scenes/shapes.cfg", "scenes/cornell.cfg",
                                                    "scenes/dof.cfg", "scenes/soft_shadows.cfg"])
    rt = pc.module(args.build)
    out_dir = os.path.join(args.build, "perf-quick" if args.quick else "perf")
    ref_dir = os.path.join(out_dir, "reference")
    os.makedirs(ref_dir, exist_ok=True)
    spps = []
    s = 1
    while s <= max_spp:
        spps.append(s)
        s *= 2
    t0 = time.time()
    rows, prec = [], []
    for name in names:
        path = name if os.path.isabs(name) else os.path.join(pc.ROOT, name)
        base = os.path.splitext(os.path.basename(path))[0]
        area = has_area_lights(path)
        ref_spp = min(args.ref_spp, 2 * max_spp) if area else args.ref_spp
        ref_extra = ["--light-samples", str(args.ref_light_samples)] if area else []
        ref_light = dict(light_samples=args.ref_light_samples) if area else {}
        ref = os.path.join(ref_dir, "%s_%dx%d_%dspp%s.pfm" % (base, w, h, ref_spp,
                                                             "_%dls" % args.ref_light_samples if area else ""))
        if not os.path.exists(ref):
            print("reference: %s, recursive engine, %d spp, stratified %s..." % (base, ref_spp, " ".join(ref_extra)),
                  flush=True)
            r = rt.render(path, engine="recursive", threads=args.jobs, spp=ref_spp, width=w, height=h,
                          sampler="stratified", **ref_light)
            tmp = ref + ".tmp.pfm"
            rt.save(r.image, tmp)
            os.replace(tmp, ref)
        reference = pc.read_pfm(ref)[2]
        rt.render(path, threads=args.jobs, spp=1, width=w, height=h)  # warm-up
        for sampler in SAMPLERS:
            for spp in spps:
                imgs = {}
                for engine in ENGINES:
                    runs = [rt.render(path, engine=engine, threads=args.jobs, spp=spp, width=w, height=h,
                                      sampler=sampler) for _ in range(args.runs)]
                    e = pc.array_error(runs[-1].image, reference)
                    imgs[engine] = runs[-1].image
                    rows.append(dict(scene=base, engine=engine, sampler=sampler, spp=spp,
                                     seconds=pc.median([r.seconds["render"] for r in runs]), **e))
                    print("[%5.0fs] %-8s %-9s %-10s spp %-3d %7.3f s  rmse %.5f  psnr %5.2f dB  relmse %.5f" % (
                        time.time() - t0, base, engine, sampler, spp, rows[-1]["seconds"], e["rmse"], e["psnr"],
                        e["relmse"]), flush=True)
                d = pc.array_error(imgs["stream"], imgs["recursive"])
                prec.append(dict(scene=base, sampler=sampler, spp=spp, **d))
        for t in [float(v) for v in args.thresholds.split(",") if v]:
            for engine in ENGINES:
                runs = [rt.render(path, engine=engine, threads=args.jobs, spp=max_spp, width=w, height=h,
                                  sampler="stratified", adaptive=t) for _ in range(args.runs)]
                e = pc.array_error(runs[-1].image, reference)
                mean_spp = runs[-1].adaptive["mean_spp"]
                rows.append(dict(scene=base, engine=engine, sampler="adaptive", spp=round(mean_spp, 2),
                                 seconds=pc.median([r.seconds["render"] for r in runs]), **e))
                print("[%5.0fs] %-8s %-9s adaptive T=%-7g spp %5.2f %7.3f s  rmse %.5f  psnr %5.2f dB" % (
                    time.time() - t0, base, engine, t, mean_spp, rows[-1]["seconds"], e["rmse"], e["psnr"]),
                    flush=True)
        # Area lights: the light samples grow instead (1 spp); the CSV's spp column holds them.
        for ls in spps if area else []:
            for engine in ENGINES:
                runs = [rt.render(path, engine=engine, threads=args.jobs, spp=1, width=w, height=h,
                                  sampler="stratified", light_samples=ls) for _ in range(args.runs)]
                e = pc.array_error(runs[-1].image, reference)
                rows.append(dict(scene=base, engine=engine, sampler="light", spp=ls,
                                 seconds=pc.median([r.seconds["render"] for r in runs]), **e))
                print("[%5.0fs] %-8s %-9s light samples %-3d %7.3f s  rmse %.5f  psnr %5.2f dB" % (
                    time.time() - t0, base, engine, ls, rows[-1]["seconds"], e["rmse"], e["psnr"]), flush=True)
    fields = ["scene", "engine", "sampler", "spp", "seconds", "rmse", "psnr", "relmse"]
    csv_path = os.path.join(out_dir, "error_vs_time.csv")
    with open(csv_path, "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=fields)
        wr.writeheader()
        wr.writerows(rows)
    with open(os.path.join(out_dir, "precision.csv"), "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=["scene", "sampler", "spp", "rmse", "psnr", "relmse"])
        wr.writeheader()
        wr.writerows(prec)
    print("wrote %s and precision.csv (%dx%d, reference %d spp, -j%d) in %.0f s" % (
        csv_path, w, h, args.ref_spp, args.jobs, time.time() - t0))
    try:
        import plot_perf
    except ImportError as exc:
        print("no plots (%s): run /usr/bin/python3 scripts/plot_perf.py --errors %s" % (exc, csv_path))
        return 0
    for p in plot_perf.plot_errors(csv_path, args.img, suffix="-quick" if args.quick else ""):
        print("plot:", p)
    return 0


def has_area_lights(path):
    """Whether the scene file has a sphere or rect light (a plain look at its statements)."""
    with open(path) as f:
        return any(line.split()[:2] in (["light", "sphere"], ["light", "rect"]) for line in f)


if __name__ == "__main__":
    sys.exit(main())
