#!/usr/bin/python3
"""Renders every scene of scenes/stress/ with both engines and writes docs/stability.md.

    scripts/stability_report.py [--build build] [--jobs 2] [--out docs/stability.md]

Needs a Release build (build/engine/streamrt, build/perf/bad_rays) and numpy. For each
scene: the recursive (double) and stream (float) pictures as linear PFM, compared after
clamping to [0, 1] like engine/image/image_compare.cpp; NaN/Inf values; for scenes with a
`# reference:` line, each engine against its own picture of the reference scene (acne:
pixels lit in the reference and darkened by more than 0.1); the bounds of the `# bound:`
and `# reference:` lines, which tests/stress/stress_test.cpp asserts on the same renders.
The degenerate-ray row comes from build/perf/bad_rays.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
STRESS = os.path.join(ROOT, "scenes", "stress")
ACNE_DROP = 0.1


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1].astype(np.float64)


def parse_meta(path):
    meta = {"what": "", "bound": {}, "reference": None}
    for line in open(path):
        m = re.match(r"#\s*(what|bound|reference):\s*(.*)", line)
        if not m:
            continue
        key, val = m.group(1), m.group(2).strip()
        if key == "what":
            meta["what"] = val
        else:
            words = val.split()
            if key == "reference":
                meta["reference"] = words[0]
                words = words[1:]
            d = dict(w.split("=") for w in words)
            meta[key if key == "bound" else "ref_bound"] = {k: float(x) for k, x in d.items()}
    return meta


def render(streamrt, scene, engine, out, jobs):
    t0 = time.perf_counter()
    r = subprocess.run([streamrt, "--engine", engine, "-j", str(jobs), "-o", out, scene],
                       capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"{scene}: {engine} failed: {r.stderr.strip()}")
    m = re.search(r": ([0-9.]+) s,", r.stderr + r.stdout)
    return read_pfm(out), float(m.group(1)) if m else wall


def compare(a, b):
    ca = np.clip(np.nan_to_num(a, nan=0, posinf=0, neginf=0), 0, 1)
    cb = np.clip(np.nan_to_num(b, nan=0, posinf=0, neginf=0), 0, 1)
    e = np.abs(ca - cb)
    return {"max": float(e.max()), "rmse": float(np.sqrt((e * e).mean())),
            "share": float((e > 1 / 255).any(axis=2).mean())}


def acne(img, ref):
    lum = lambda x: np.clip(np.nan_to_num(x), 0, 1).mean(axis=2)
    return int(((lum(ref) - lum(img)) > ACNE_DROP).sum())


def bad_count(img):
    return int((~np.isfinite(img)).sum())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "stability.md"))
    args = ap.parse_args()
    streamrt = os.path.join(args.build, "engine", "streamrt")
    scenes = sorted(f for f in os.listdir(STRESS) if f.endswith(".cfg"))
    tmp = tempfile.mkdtemp(prefix="stability_")
    pics, times, rows = {}, {}, []
    for name in scenes:
        path = os.path.join(STRESS, name)
        for eng in ("recursive", "stream"):
            pics[name, eng], times[name, eng] = render(streamrt, path, eng, os.path.join(tmp, f"{name}.{eng}.pfm"), args.jobs)
        print(f"{name}: rendered", file=sys.stderr)
    failures = []
    for name in scenes:
        meta = parse_meta(os.path.join(STRESS, name))
        base, strm = pics[name, "recursive"], pics[name, "stream"]
        d = compare(strm, base)
        row = {"name": name, "what": meta["what"], "diff": d, "bound": meta["bound"],
               "nan": bad_count(base) + bad_count(strm),
               "t_rec": times[name, "recursive"], "t_str": times[name, "stream"]}
        b = meta["bound"]
        ok = d["share"] <= b.get("share", 1) and d["max"] <= b.get("max", 1) and row["nan"] == 0
        if meta["reference"]:
            ref = meta["reference"]
            rb = meta["ref_bound"]
            row["ref"] = ref
            row["ref_bound"] = rb
            for eng in ("recursive", "stream"):
                rd = compare(pics[name, eng], pics[ref, eng])
                row["ref_" + eng] = rd
                row["acne_" + eng] = acne(pics[name, eng], pics[ref, eng])
                ok = ok and rd["share"] <= rb.get("share", 1) and row["acne_" + eng] <= rb.get("acne", 1e9)
        row["ok"] = ok
        if not ok:
            failures.append(name)
        rows.append(row)

    bad_rays = None
    tool = os.path.join(args.build, "perf", "bad_rays")
    if os.path.exists(tool):
        r = subprocess.run([tool, "--json"], capture_output=True, text=True)
        if r.returncode == 0:
            bad_rays = json.loads(r.stdout)

    write_doc(args.out, rows, bad_rays)
    print(f"wrote {args.out}; {len(rows)} scenes, outside their bounds: {', '.join(failures) or 'none'}", file=sys.stderr)
    return 1 if failures else 0


NOTES = """
## What the cases found, and the fixes

- **Scale (1e-4, 1e5 units).** `offset_ray_origin` (engine/render/shading.h) used Waechter & Binder's
  constants: 256 ulps per component, and below |coordinate| 1/32 a fixed step of 1/65536, i.e. 15% of a
  scene built at 1e-4 units (light leaking, lost contact shadows). It is now one scale-free template for
  double, float and batches: p + n * 2^-17 (float; 2^-36 in double) * max(|p|, |ray origin|), the size of
  the numbers the hit point was computed from. The scaled scenes now match the unit-scale picture.
- **1e6 units from the origin.** The stream engine keeps rays, hit points and lights in float, whose
  resolution at 1e6 is 0.06 units: the whole scene. `StreamScene` (engine/stream/stream_scene.cpp) now
  renders relative to the camera's eye: the translation is applied in double to Md, Mi and the lights
  before anything is rounded to float, and the checker gets (eye / cell) mod 2 through
  `MaterialT::cell_offset`, so the pattern stays put. The recursive engine (double) needed nothing.
- **Degenerate rays.** Rays with denormal components (or products that underflow) cost 4x overall (tens of times
  in single kernels) through the CPU's denormal assists; every kernel entry point now runs with
  flush-to-zero / denormals-are-zero (`simd::FlushDenormals`, restored on exit): degenerate rays now cost
  no more than ordinary ones. The torus, solved in double, returned t beyond float's range (1e45 for a
  denormal direction, 1e-40 for a 3e38 one); the flat closest-hit kernel stored them as +inf or 0 with an
  object id. Such t are now misses (14 to 19 non-definite answers per ISA level before, 0 now).
- **Coplanar faces** are not a numerical problem but a scene one: the first nested-glass scene put the
  cube's bottom face on the floor and both engines showed z-fighting; the cube now floats above it.

## Known limits (stated as the bounds above)

- `disk_sphere`: the disk is 2e-6 thick. Float keeps world positions to ~2.4e-7 at 3 units, so the
  canonical y of a stream hit (magnified 1e6 by Mi) carries an error of ~0.2: near the rim, where the
  true canonical y is that small, the stream engine's normals wobble and some shadow rays start inside
  the disk (the dark rim speckles); the double engine is clean. Normals stay unit length (Mn then
  normalize) and finite everywhere.
- `torus_far` (1e4 units): the stream keeps t in float (ulp 1e-3 at 1e4) and its offset is 2^-17 of
  1e4 = 0.08 units, so self-shadow boundaries on the 0.25 tube move by a pixel; the quartic itself is
  solved in double in both engines.

## Torus quartic accuracy

`tests/shapes/torus_math_test.cpp` checks `torus_hit_t` (engine/shapes/torus_math.h, double in both
engines) against a long-double reference on 108,000 rays (thin 1e-3, 0.25, fat 0.9, spindle 1.5; outside,
inside the tube, in the hole, tangent, near-tangent, origin at 1e4): no hit/miss disagreement outside the
tangent band; maximum relative t error 2.6e-13 for hits at |cos| >= 1e-3 and distance >= 1e-2, 5.1e-11 for
all hits at |cos| >= 1e-3, 1.1e-7 including grazing hits (|cos| down to 2e-10, where t is ill-conditioned);
SIMD and scalar identical (docs/torus.md).

## Quadratics

Sphere, cylinder and cone solve a t^2 + 2 b t + c = 0 with q = -(b + sign(b) sqrt(disc)), t = q / a and
c / q (engine/shapes/quadratic.h), the discriminant written about the ray's closest approach (sphere,
cylinder) or from a shifted origin (cone): `quadrics_far` (camera 1e4 units away) agrees to 0.02% of pixels.
"""


def pct(x):
    return f"{100 * x:.2f}%"


def write_doc(out, rows, bad_rays):
    L = []
    L.append("# Numerical stability: stiff and extreme cases")
    L.append("")
    L.append("Generated by `scripts/stability_report.py` (rerun it after a Release build; it renders every scene")
    L.append("of `scenes/stress/`, written by `scripts/make_stress_scenes.py`, with both engines at 64x64, 1 spp).")
    L.append("`tests/stress/stress_test.cpp` renders the same scenes and asserts the bounds stated here, which")
    L.append("each scene file carries in its `# bound:` and `# reference:` lines.")
    L.append("")
    L.append("Columns: **baseline vs stream** compares the recursive engine (double) with the stream engine")
    L.append("(float kernels; the torus is solved in double in both) on calibrated values in [0, 1]: largest")
    L.append("difference, RMSE and share of pixels with a component off by more than 1/255. **NaN/Inf**: non-finite")
    L.append("values in both framebuffers. **vs reference**: for the scale and ior cases, each engine against its")
    L.append(f"own picture of the reference scene (share over 1/255, recursive / stream) and **acne**: pixels the")
    L.append(f"reference lights that are darker by more than {ACNE_DROP} (recursive / stream). Times are the")
    L.append("engines' own render times (-j2, shared machine: indicative only).")
    L.append("")
    L.append("| case | what it checks | baseline vs stream: max / RMSE / >1/255 (bound) | NaN/Inf | vs reference: >1/255 (bound) | acne (bound) | time recursive / stream |")
    L.append("|---|---|---|---|---|---|---|")
    for r in rows:
        d, b = r["diff"], r["bound"]
        bound = f"share <= {pct(b.get('share', 1))}" + (f", max <= {b['max']:g}" if b.get("max", 1) < 1 else "")
        if "ref" in r:
            rb = r["ref_bound"]
            refc = (f"{pct(r['ref_recursive']['share'])} / {pct(r['ref_stream']['share'])} vs `{r['ref']}` "
                    f"(<= {pct(rb.get('share', 1))})")
            ac = f"{r['acne_recursive']} / {r['acne_stream']} (<= {int(rb.get('acne', 0))})"
        else:
            refc, ac = "", ""
        L.append(f"| `{r['name'][:-4]}` | {r['what']} | {d['max']:.3g} / {d['rmse']:.2g} / {pct(d['share'])} ({bound}) | "
                 f"{r['nan']} | {refc} | {ac} | {1e3 * r['t_rec']:.1f} / {1e3 * r['t_str']:.1f} ms |")
    if bad_rays:
        L.append(f"| degenerate rays | {bad_rays['what']} | — | {bad_rays['non_finite']} | — | — | "
                 f"normal {bad_rays['ns_normal']:.1f} ns/ray, degenerate {bad_rays['ns_bad']:.1f} ns/ray "
                 f"(x{bad_rays['ratio']:.2f}, bound x2) |")
    L.append("")
    worst = max(rows, key=lambda r: r["diff"]["share"])
    L.append(f"Outside their bounds: {', '.join(r['name'] for r in rows if not r['ok']) or 'none'}. "
             f"Worst baseline/stream agreement: `{worst['name']}` ({pct(worst['diff']['share'])} of pixels over 1/255).")
    L.append("")
    text = "\n".join(L) + "\n" + NOTES
    with open(out, "w") as f:
        f.write(text)


if __name__ == "__main__":
    sys.exit(main())
