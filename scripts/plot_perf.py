#!/usr/bin/python3
"""Plots of the perf suite and of the error-against-time sweep, as small PNGs (matplotlib,
Debian's python3-matplotlib: run with /usr/bin/python3).

usage: /usr/bin/python3 scripts/plot_perf.py [--results build/perf/results.json]
                                             [--errors build/perf/error_vs_time.csv] [--out build/perf/img]
Writes scaling_resolution.png, scaling_objects.png, scaling_threads.png (from results.json)
evt_<scene>.png (from error_vs_time.csv) and kernels_sphere.png (from perf/kernel_bench's JSON,
whose summary table is printed in Markdown) into --out: build/perf/img/ unless asked otherwise,
so that a quick run never rewrites the pictures the docs show (--out docs/img does, on purpose).
Exits 1 when there is nothing to plot.
"""
import argparse
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COLORS = {"stream": "tab:blue", "recursive": "tab:red"}
MARKERS = {"grid": "s", "stratified": "o", "random": "^", "light": "D", "adaptive": "*"}
STYLES = {"grid": ":", "stratified": "-", "random": "--", "light": "-.", "adaptive": (0, (5, 1))}


def _save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def plot_errors(csv_path, img_dir, suffix=""):
    rows = list(csv.DictReader(open(csv_path)))
    os.makedirs(img_dir, exist_ok=True)
    out = []
    for scene in sorted({r["scene"] for r in rows}):
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for engine in ("stream", "recursive"):
            # "light": 1 spp, stratified, --light-samples growing (scenes with area lights)
            # "adaptive": --adaptive T at a sweep of T, cap max-spp; its spp is the mean taken
            for sampler in ("grid", "stratified", "random", "light", "adaptive"):
                pts = sorted((float(r["seconds"]), float(r["rmse"]), float(r["spp"])) for r in rows
                             if r["scene"] == scene and r["engine"] == engine and r["sampler"] == sampler)
                if not pts:
                    continue
                ax.plot([p[0] for p in pts], [p[1] for p in pts], color=COLORS[engine], marker=MARKERS[sampler],
                        linestyle=STYLES[sampler], markersize=4, label="%s, %s" % (engine, sampler))
                if sampler in ("stratified", "light", "adaptive"):
                    for x, y, spp in pts:
                        ax.annotate("%g" % round(spp, 1), (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7,
                                    color=COLORS[engine])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("render time (s)")
        ax.set_ylabel("RMSE vs converged reference")
        has_light = any(r["scene"] == scene and r["sampler"] == "light" for r in rows)
        ax.set_title("%s: error against time (labels: spp%s)" % (scene, ", light samples" if has_light else ""))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
        out.append(_save(fig, os.path.join(img_dir, "evt_%s%s.png" % (scene, suffix))))
    return out


def plot_results(json_path, img_dir, suffix=""):
    data = json.load(open(json_path))
    res = data["results"]
    os.makedirs(img_dir, exist_ok=True)
    out = []
    rs = [r for r in res if r["group"] == "resolution"]
    if rs:
        fig, ax = plt.subplots(figsize=(5.6, 3.8))
        for engine in ("stream", "recursive"):
            pts = sorted((r["width"] * r["height"], r["seconds"]) for r in rs if r["engine"] == engine)
            ax.plot([p[0] / 1e6 for p in pts], [p[1] for p in pts], "o-", color=COLORS[engine], label=engine)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("megapixels (320x180 .. 1920x1080)")
        ax.set_ylabel("render time (s)")
        ax.set_title("whitted.cfg, 1 spp, -j%d: time vs resolution" % rs[0]["jobs"])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        out.append(_save(fig, os.path.join(img_dir, "scaling_resolution%s.png" % suffix)))
    os_ = [r for r in res if r["group"] == "objects"]
    if os_:
        fig, ax = plt.subplots(figsize=(5.6, 3.8))
        for engine in ("stream", "recursive"):
            pts = sorted((r["objects"], r["seconds"]) for r in os_ if r["engine"] == engine)
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=COLORS[engine], label=engine)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("spheres N")
        ax.set_ylabel("render time (s)")
        ax.set_title("N spheres, 1280x720, 1 spp, -j%d: time vs N" % os_[0]["jobs"])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        out.append(_save(fig, os.path.join(img_dir, "scaling_objects%s.png" % suffix)))
    th = [r for r in res if r["group"] in ("matrix", "headline") and r.get("scaling_j2")]
    if th:
        # the largest spp of each scene and group: one bar per (scene, engine)
        best = {}
        for r in th:
            k = (r["group"], r["scene"], r["engine"])
            if k not in best or r["spp"] > best[k]["spp"]:
                best[k] = r
        labels = sorted({(g, s) for g, s, _ in best})
        fig, ax = plt.subplots(figsize=(7.2, 0.3 * len(labels) + 1.6))
        y = list(range(len(labels)))
        for i, engine in enumerate(("stream", "recursive")):
            vals = [best.get((g, s, engine), {}).get("scaling_j2", 0) for g, s in labels]
            ax.barh([v + (i - 0.5) * 0.4 for v in y], vals, height=0.4, color=COLORS[engine], label=engine)
        ax.axvline(2.0, color="gray", linestyle=":", label="ideal (2 cores)")
        ax.set_yticks(y)
        ax.set_yticklabels(["%s%s" % (s.replace("scenes/", ""), " (1280x720)" if g == "headline" else "")
                            for g, s in labels], fontsize=7)
        ax.set_xlabel("speedup of -j2 over -j1")
        ax.set_title("threads: time(-j1) / time(-j2)")
        ax.legend(fontsize=7, loc="lower right")
        out.append(_save(fig, os.path.join(img_dir, "scaling_threads%s.png" % suffix)))
    return out


def kernel_rows(json_path):
    """Google Benchmark JSON of perf/kernel_bench -> (kernel rows, limits per isa, context)."""
    data = json.load(open(json_path))
    rows, limits, peaks = [], {}, {}
    for b in data["benchmarks"]:
        parts = b["name"].split("/")
        if parts[0] == "BM_kernel":
            args = dict(p.split(":") for p in parts[4:])
            rows.append(dict(shape=parts[1], mode=parts[2], isa=parts[3], rays=int(args["rays"]),
                             objs=int(args["objs"]), tests=b["tests/s"], rays_s=b["rays/s"], cycles=b["cycles/test"]))
        elif parts[0] == "BM_arith_limit":
            limits[parts[1]] = (b["tests/s"], b["cycles/test"])
        elif parts[0] == "BM_fma_peak":
            peaks[parts[1]] = (b["fma/s"], b["vec_fma/cycle"])
    return rows, limits, peaks, data.get("context", {})


def kernel_markdown(json_path):
    rows, limits, peaks, ctx = kernel_rows(json_path)
    isas = [i for i in ("sse2", "sse4.2", "avx2", "avx512") if i in limits]
    out = ["TSC %.2f GHz. Arithmetic limit of the sphere test (BM_arith_limit) and FMA peak (BM_fma_peak):" %
           float(ctx.get("tsc_ghz", "0")), "",
           "| isa | FMA peak (G lane-FMA/s) | vector FMA / TSC cycle | sphere-test limit (M tests/s) | cycles/test |",
           "|---|---|---|---|---|"]
    for i in isas:
        out.append("| %s | %.1f | %.2f | %.0f | %.2f |" % (i, peaks[i][0] / 1e9, peaks[i][1], limits[i][0] / 1e6,
                                                          limits[i][1]))
    out += ["", "Closest-hit kernels, M ray-object tests/s (cycles/test), 4096 rays x 8 objects; "
            "in brackets 16 rays x 1 object:", "",
            "| shape | " + " | ".join(isas) + " |", "|---|" + "---|" * len(isas)]
    for shape in ("sphere", "cube", "cylinder", "cone", "torus", "plane"):
        cells = []
        for i in isas:
            big = [r for r in rows if r["shape"] == shape and r["isa"] == i and r["mode"] == "closest"
                   and r["rays"] == 4096 and r["objs"] == 8]
            small = [r for r in rows if r["shape"] == shape and r["isa"] == i and r["mode"] == "closest"
                     and r["rays"] == 16 and r["objs"] == 1]
            cells.append("%.0f (%.1f) [%.0f]" % (big[0]["tests"] / 1e6, big[0]["cycles"], small[0]["tests"] / 1e6)
                         if big and small else "")
        out.append("| %s | %s |" % (shape, " | ".join(cells)))
    return "\n".join(out)


def plot_kernels(json_path, img_dir, suffix=""):
    rows, limits, _, _ = kernel_rows(json_path)
    os.makedirs(img_dir, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    colors = {"sse2": "tab:gray", "sse4.2": "tab:olive", "avx2": "tab:green", "avx512": "tab:purple"}
    for isa, col in colors.items():
        for objs, style in ((8, "-"), (1, ":")):
            pts = sorted((r["rays"], r["tests"]) for r in rows if r["shape"] == "sphere" and r["mode"] == "closest"
                         and r["isa"] == isa and r["objs"] == objs)
            if pts:
                ax.plot([p[0] for p in pts], [p[1] / 1e6 for p in pts], style, marker="o", markersize=3, color=col,
                        label="%s, %d obj" % (isa, objs))
        if isa in limits:
            ax.axhline(limits[isa][0] / 1e6, color=col, linestyle="--", linewidth=0.8)
    ax.set_xscale("log", base=2)
    ax.set_xlabel("rays per call (packet stream)")
    ax.set_ylabel("M ray-sphere tests/s (one core)")
    ax.set_title("sphere closest-hit kernel; dashed: arithmetic limit")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    return [_save(fig, os.path.join(img_dir, "kernels_sphere%s.png" % suffix))]


def main(argv=None):
    ap = argparse.ArgumentParser(description="Plot perf-suite results and error-vs-time sweeps.")
    ap.add_argument("--results", default=os.path.join(ROOT, "build", "perf", "results.json"))
    ap.add_argument("--errors", default=os.path.join(ROOT, "build", "perf", "error_vs_time.csv"))
    ap.add_argument("--kernels", default=os.path.join(ROOT, "build", "perf", "kernels.json"),
                    help="perf/kernel_bench --benchmark_out JSON (a summary table is printed)")
    ap.add_argument("--out", "--img", dest="img", default=os.path.join(ROOT, "build", "perf", "img"),
                    help="where the PNGs go (default build/perf/img; the docs' pictures: --out docs/img)")
    ap.add_argument("--suffix", default="", help="appended to each PNG name")
    args = ap.parse_args(argv)
    os.makedirs(args.img, exist_ok=True)
    made = []
    if os.path.exists(args.results):
        made += plot_results(args.results, args.img, args.suffix)
    if os.path.exists(args.errors):
        made += plot_errors(args.errors, args.img, args.suffix)
    if os.path.exists(args.kernels):
        made += plot_kernels(args.kernels, args.img, args.suffix)
        print(kernel_markdown(args.kernels))
    for p in made:
        print("plot:", p)
    if not made:
        # A run that plotted nothing is a failure: a script chain (perf_suite.py && plot_perf.py)
        # must not report success with no pictures.
        print("nothing to plot: run scripts/perf_suite.py and/or scripts/error_vs_time.py first", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
