#!/usr/bin/env python3
"""The streamrt performance suite (docs/performance.md, "How to reproduce").

usage: scripts/perf_suite.py [--quick] [--build DIR] [--runs N] [--groups G,...]

Runs streamrt (build/engine/streamrt) over a fixed set of cases, each timed as the median of
--runs renders after one warm-up render, and writes to DIR/perf/ (default build/perf/):
  results.json   every case: times of each run, median, rays per kind, Mrays/s per kind,
                 peak memory, stream's speedup over the recursive baseline and its image error
                 against the baseline at the same settings
  results.csv    the same, one row per case
  results.md     the Markdown table
Groups (all by default):
  matrix      every scene in scenes/ (and scenes/degrees/) and generated N-sphere scenes
              x both engines x -j1/-j2 x spp 1 and 4, at each scene's own resolution
  headline    scenes/shapes.cfg and scenes/whitted.cfg at 1280x720, 4 spp, depth 5, both
              engines, -j1 and -j2, plus one --profile of the stream engine per scene
  resolution  whitted at 320x180 .. 1920x1080, both engines, -j2, 1 spp
  objects     N spheres (N = 1 .. 1e6), stream engine (recursive to 1e5), -j2, 1 spp, 1280x720
  endtoend    the whole process as a user runs it (not in the default set): 1e6 spheres + plane
              at 1280x720, 1 spp, -j2, to PNG; whitted at 2560x1440, 1 spp, -j2, to PNG and PPM.
              Medians of max(--runs, 5) runs of process wall time, its phases (read, set-up,
              render, write, from the summary line) and peak RSS, into
              results_endtoend.{json,md}; --before DIR also runs DIR/engine/streamrt (an older
              build) alternately with this one, for a before/after measured in one run.
--quick runs a subset of about half a minute (27 s measured; one run after the warm-up, fewer cases).
Times are streamrt's own render clock (scene parsing, hierarchy build and image writing
excluded); "wall" is the whole process. Peak memory is the process's maximum RSS (wait4).
Then: /usr/bin/python3 scripts/plot_perf.py  and  scripts/compare_results.py OLD NEW.
"""
import argparse
import csv
import glob
import json
import os
import shutil
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402

KINDS = ("primary", "shadow", "reflected", "refracted", "diffuse")


def case_key(c):
    return "%s|%s|j%d|spp%d|%dx%s|d%s" % (c["group"], c["scene"], c["jobs"], c["spp"], c.get("width") or 0,
                                          c.get("height") or 0, c.get("depth"))


def build_cases(args, gen_dir):
    quick = args.quick
    cases = []

    def add(group, scene, engines, jobs, spps, width=None, height=None, depth=None, name=None, **kw):
        for spp in spps:
            for j in jobs:
                for e in engines:
                    cases.append(dict(group=group, scene=name or os.path.relpath(scene, pc.ROOT), path=scene,
                                      engine=e, jobs=j, spp=spp, width=width, height=height, depth=depth, **kw))

    groups = args.groups
    if "matrix" in groups:
        scenes = sorted(glob.glob(os.path.join(pc.ROOT, "scenes", "*.cfg")))
        scenes += sorted(p for p in glob.glob(os.path.join(pc.ROOT, "scenes", "degrees", "degree*.cfg")))
        if quick:
            scenes = [os.path.join(pc.ROOT, "scenes", s) for s in ("whitted.cfg", "shapes.cfg")]
        for s in scenes:
            # the degree scenes are one scene with more and more effects: 1 spp is enough
            spps = (1,) if quick or "degrees" in s else (1, 4)
            add("matrix", s, ("stream", "recursive"), (1, 2), spps)
        for n in (() if quick else (100000,)):
            p = pc.sphere_scene(n, os.path.join(gen_dir, "spheres_%d.cfg" % n))
            add("matrix", p, ("stream", "recursive"), (1, 2), (1,), name="spheres N=%d" % n, objects=n)
    if "headline" in groups:
        for s in ("shapes.cfg", "whitted.cfg"):
            add("headline", os.path.join(pc.ROOT, "scenes", s), ("stream", "recursive"), (1, 2), (4,), 1280, 720, 5)
    if "resolution" in groups:
        sizes = ((320, 180), (640, 360)) if quick else ((320, 180), (640, 360), (1280, 720), (1920, 1080))
        for w, h in sizes:
            add("resolution", os.path.join(pc.ROOT, "scenes", "whitted.cfg"), ("stream", "recursive"), (2,), (1,), w, h,
                pixels=w * h)
    if "objects" in groups:
        ns = (1, 10, 100, 1000, 10000) if quick else (1, 10, 100, 1000, 10000, 100000, 1000000)
        for n in ns:
            p = pc.sphere_scene(n, os.path.join(gen_dir, "spheres_%d.cfg" % n))
            engines = ("stream", "recursive") if n <= 100000 else ("stream",)
            add("objects", p, engines, (2,), (1,), 1280, 720, name="spheres N=%d" % n, objects=n)
    return cases


def run_case(exe, c, args, tmp):
    out = os.path.join(tmp, "img_%d.pfm" % c["index"])
    prof = os.path.join(tmp, "prof.json") if c["engine"] == "stream" else None
    kw = dict(engine=c["engine"], jobs=c["jobs"], spp=c["spp"], width=c["width"], height=c["height"], depth=c["depth"])
    for _ in range(args.warmup):
        pc.run_streamrt(exe, c["path"], out, **kw)
    runs = [pc.run_streamrt(exe, c["path"], out, profile_json=prof, **kw) for _ in range(args.runs)]
    secs = [r["seconds"] for r in runs]
    med = pc.median(secs)
    r0 = runs[0]
    res = dict(c)
    res.pop("path")
    res.pop("index")
    res.update(seconds=med, seconds_runs=secs, wall=pc.median([r["wall"] for r in runs]), rays=r0["rays"],
               mrays_per_s=r0["rays"] / med / 1e6, peak_rss_mib=max(r["peak_rss_mib"] for r in runs),
               width=r0["width"], height=r0["height"], image=out)
    if "kinds" in r0:
        res["kinds"] = r0["kinds"]
        res["stages"] = r0["stages"]
        res["isa"] = r0["isa"]
    return res


def fill_pairs(results):
    """Stream rows get the speedup over the recursive row of the same case and the image error
    against it; recursive rows get per-kind counts from the stream row (the same rays)."""
    by = {}
    for r in results:
        by.setdefault(case_key(r), {})[r["engine"]] = r
    for pair in by.values():
        s, b = pair.get("stream"), pair.get("recursive")
        if s and b:
            s["speedup"] = b["seconds"] / s["seconds"]
            try:
                s.update({"err_" + k: v for k, v in pc.image_error(s["image"], b["image"]).items()})
            except (OSError, ValueError):
                pass
            if "kinds" in s and "kinds" not in b:
                b["kinds"] = s["kinds"]
    for r in results:
        if "kinds" in r:
            for k in KINDS:
                r["mrays_" + k] = r["kinds"].get(k, 0) / r["seconds"] / 1e6
    # -j2 over -j1, same engine and case
    for r in results:
        if r["jobs"] == 2:
            one = dict(r, jobs=1)
            for q in results:
                if q["engine"] == r["engine"] and q["jobs"] == 1 and case_key(q) == case_key(one):
                    r["scaling_j2"] = q["seconds"] / r["seconds"]


COLUMNS = ["group", "scene", "engine", "jobs", "spp", "width", "height", "depth", "seconds", "wall", "rays",
           "mrays_per_s"] + ["mrays_" + k for k in KINDS] + ["speedup", "scaling_j2", "err_rmse", "err_psnr",
                                                            "err_relmse", "peak_rss_mib", "objects"]


def fmt(v, nd=3):
    if v is None or v == "":
        return ""
    if isinstance(v, float):
        return "%.*f" % (nd, v)
    return str(v)


def write_outputs(results, meta, out_dir):
    with open(os.path.join(out_dir, "results.json"), "w") as f:
        json.dump({"meta": meta, "results": [{k: v for k, v in r.items() if k != "image"} for r in results]}, f,
                  indent=1)
    with open(os.path.join(out_dir, "results.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in results:
            w.writerow([r.get(k, "") if r.get(k) is not None else "" for k in COLUMNS])
    lines = ["# streamrt perf suite", "",
             "%s, %s cores, %s, revision %s; median of %d runs after %d warm-up; `%s`" %
             (meta["cpu"], meta["cores"], meta["date"], meta["revision"], meta["runs"], meta["warmup"],
              meta["command"]), "",
             "| group | scene | engine | -j | spp | size | s | Mrays/s | primary | shadow | refl. | refr. "
             "| speedup | j2/j1 | RMSE vs base | PSNR dB | peak MiB |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        lines.append("| %s |" % " | ".join([
            r["group"], r["scene"], r["engine"], str(r["jobs"]), str(r["spp"]), "%dx%d" % (r["width"], r["height"]),
            fmt(r["seconds"]), fmt(r["mrays_per_s"], 2)] + [fmt(r.get("mrays_" + k), 2) for k in KINDS] + [
            fmt(r.get("speedup"), 2) + ("x" if r.get("speedup") else ""), fmt(r.get("scaling_j2"), 2),
            fmt(r.get("err_rmse"), 5), fmt(r.get("err_psnr"), 1), fmt(r["peak_rss_mib"], 0)]))
    lines += ["", "Mrays/s per kind: rays of that kind / render time. speedup: recursive time / stream time "
              "(same case). j2/j1: -j1 time / -j2 time. RMSE, PSNR: stream image vs recursive image."]
    with open(os.path.join(out_dir, "results.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


ENDTOEND_PHASES = ("read", "setup", "render", "write")


def endtoend(exe, before_exe, args, gen_dir, out_dir):
    """The endtoend group: whole-process wall time, phases and peak RSS per case, for this
    build and optionally an older one run alternately (so both see the same machine)."""
    spheres = pc.sphere_scene(1000000, os.path.join(gen_dir, "spheres_1000000.cfg"))
    whitted = os.path.join(pc.ROOT, "scenes", "whitted.cfg")
    cases = [("1e6 spheres + plane", spheres, 1280, 720, ".png"),
             ("whitted 2560x1440", whitted, 2560, 1440, ".png"),
             ("whitted 2560x1440", whitted, 2560, 1440, ".ppm")]
    builds = [("after", exe)] + ([("before", before_exe)] if before_exe else [])
    runs = max(args.runs, 5)
    rows = []
    for name, path, w, h, ext in cases:
        samples = {b: [] for b, _ in builds}
        out = os.path.join(out_dir, "endtoend" + ext)
        for _ in range(runs):
            for b, e in builds:
                samples[b].append(pc.run_streamrt(e, path, out, jobs=2, spp=1, width=w, height=h))
        for b, _ in builds:
            rs = samples[b]
            row = dict(case=name, output=ext, build=b, runs=runs, wall=pc.median([r["wall"] for r in rs]),
                       peak_rss_mib=pc.median([r["peak_rss_mib"] for r in rs]))
            for k in ENDTOEND_PHASES:
                if all(k in r for r in rs):
                    row[k] = pc.median([r[k] for r in rs])
            if "render" not in row:
                row["render"] = pc.median([r["seconds"] for r in rs])
            row["wall_over_render"] = row["wall"] / row["render"]
            rows.append(row)
            print("%-20s %s %-6s wall %.3f s, render %.3f s, wall/render %.2f, peak %.0f MiB" % (
                name, ext, b, row["wall"], row["render"], row["wall_over_render"], row["peak_rss_mib"]), flush=True)
        if os.path.exists(out):
            os.remove(out)
    with open(os.path.join(out_dir, "results_endtoend.json"), "w") as f:
        json.dump({"meta": pc.machine_info(), "rows": rows}, f, indent=1)
    lines = ["| case | output | build | wall s | read s | set-up s | render s | write s | wall / render | peak MiB |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["case"], r["output"], r["build"], fmt(r["wall"]), fmt(r.get("read")), fmt(r.get("setup")),
            fmt(r["render"]), fmt(r.get("write")), fmt(r["wall_over_render"], 2), fmt(r["peak_rss_mib"], 0)))
    with open(os.path.join(out_dir, "results_endtoend.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="a smoke run of about half a minute")
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"), help="build folder (default build/)")
    ap.add_argument("--runs", type=int, help="timed runs per case (default 3, quick 1)")
    ap.add_argument("--warmup", type=int, default=1, help="untimed runs before (default 1)")
    ap.add_argument("--groups", default="matrix,headline,resolution,objects")
    ap.add_argument("--out", help="output folder (default BUILD/perf, quick: BUILD/perf-quick)")
    ap.add_argument("--before", help="endtoend group: an older build folder to compare with, run alternately")
    args = ap.parse_args(argv)
    args.groups = args.groups.split(",")
    args.runs = args.runs or (1 if args.quick else 3)
    exe = pc.binary(args.build)
    out_dir = args.out or os.path.join(args.build, "perf-quick" if args.quick else "perf")
    os.makedirs(out_dir, exist_ok=True)
    gen_dir = os.path.join(args.build, "perf", "scenes")
    tmp = os.path.join(out_dir, "images")
    os.makedirs(tmp, exist_ok=True)
    if "endtoend" in args.groups:
        endtoend(exe, pc.binary(args.before) if args.before else None, args, gen_dir, out_dir)
        args.groups = [g for g in args.groups if g != "endtoend"]
        if not args.groups:
            return 0
    cases = build_cases(args, gen_dir)
    meta = pc.machine_info()
    meta.update(runs=args.runs, warmup=args.warmup, command=" ".join(["scripts/perf_suite.py"] + (argv or sys.argv[1:])),
                quick=args.quick)
    t0 = time.time()
    results = []
    for i, c in enumerate(cases):
        c["index"] = i
        r = run_case(exe, c, args, tmp)
        results.append(r)
        print("[%3d/%d %5.0fs] %-10s %-26s %-9s -j%d spp %-2d %5dx%-5d %8.3f s %7.2f Mrays/s %6.0f MiB" % (
            i + 1, len(cases), time.time() - t0, r["group"], r["scene"][-26:], r["engine"], r["jobs"], r["spp"],
            r["width"], r["height"], r["seconds"], r["mrays_per_s"], r["peak_rss_mib"]), flush=True)
    # one profile (text) of the stream engine per headline scene: where the time goes
    if "headline" in args.groups:
        meta["profiles"] = {}
        for s in ("shapes.cfg", "whitted.cfg"):
            for j in (1, 2):
                p = subprocess.run([exe, os.path.join(pc.ROOT, "scenes", s), "-o", os.path.join(tmp, "p.pfm"), "-j",
                                    str(j), "--spp", "4", "--width", "1280", "--height", "720", "--depth", "5",
                                    "--profile"], capture_output=True, text=True, check=True)
                meta["profiles"]["%s -j%d" % (s, j)] = p.stdout
    meta["suite_seconds"] = time.time() - t0
    fill_pairs(results)
    write_outputs(results, meta, out_dir)
    shutil.rmtree(tmp, ignore_errors=True)  # the images were only for the error column
    print("wrote %s/results.{json,csv,md} in %.0f s" % (out_dir, time.time() - t0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
