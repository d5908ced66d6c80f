#!/usr/bin/env python3
"""Degree 6 against Embree's tutorial path tracer on its own Cornell box
(docs/global-illumination.md, "Against Embree").

Debian's embree-tools installs `pathtracer` and, with its documentation, the Cornell box it
renders (cornell_box.obj, cornell_box.ecs: a point light of intensity 100000 at (213, 300,
227)). perf/scenes/gi/embree_cornell.cfg is the same scene in streamrt's conventions. This
script renders:
  1. a converged reference with Embree's pathtracer (--ref-spp samples; cached in build/gi/);
  2. Embree at --embree-spp (64) samples, the figure to reach: its RMSE against the reference
     and its whole-process wall time (median of --reps runs);
  3. streamrt at 4, 8, 16, ... samples: RMSE and whole-process wall time, both engines;
and prints a table, the time streamrt needs to reach Embree's RMSE (interpolated with the
error's spp^-1/2 law between the measured sample counts), and the mean of each channel of
streamrt's picture against the reference's. pathtracer writes its PFM clamped and truncated
to 8 bits; streamrt's pictures are brought to the same values before any comparison.

    /usr/bin/python3 scripts/gi_peer.py [--size 512] [--reps 3] [--check] [--out docs/img]

--check (a ctest): a small, quick run that only asserts agreement: each channel's mean
within 1 % of the reference's plus 4 standard errors of the two estimates. Exits 77 (ctest's
skip) when pathtracer or its model is not installed.
"""
import argparse
import math
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
import perf_common  # noqa: E402
import numpy as np  # noqa: E402

MODELS = pathlib.Path("/usr/share/doc/embree3/models")
SCENE = ROOT / "perf/scenes/gi/embree_cornell.cfg"
SKIP = 77


def run_timed(cmd, cwd=None):
    """(wall seconds, CPU seconds: user + system) of one whole process (read, build, render,
    write). The CPU time is the figure to trust on a loaded machine: it is what the process
    did, not how long it waited for a core."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=cwd)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def run_embree(size, spp, out, threads):
    cmd = ["pathtracer", "-c", str(MODELS / "cornell_box.ecs"), "--size", str(size), str(size), "--spp", str(spp),
           "--max-path-length", "8", "--threads", str(threads), "-o", str(out)]
    return run_timed(cmd, cwd=MODELS)


def run_streamrt(exe, size, spp, out, threads, engine="stream"):
    cmd = [str(exe), "--quiet", "-j", str(threads), "--engine", engine, "--spp", str(spp), "--width", str(size),
           "--height", str(size), str(SCENE), "-o", str(out)]
    return run_timed(cmd)


def image(path):
    return np.asarray(perf_common.read_pfm(str(path))[2], dtype=np.float64)


def as_embree_writes(img):
    """A linear picture as pathtracer writes its PFM: each channel clamped to [0, 1] and
    truncated to 8 bits (its files hold k / 255 only; measured: truncation, not rounding, brings
    a converged streamrt picture's means within 0.2 % of its, rounding leaves them 0.2 - 0.6 %
    above)."""
    return np.floor(np.clip(img, 0.0, 1.0) * 255.0) / 255.0


def streamrt_image(path):
    return as_embree_writes(image(path))


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


def timed(fn, reps):
    """Over `reps` runs: the median wall time and its spread (min, max), then the median CPU
    time and its spread."""
    runs = [fn() for _ in range(reps)]
    wall, cpu = [r[0] for r in runs], [r[1] for r in runs]
    return statistics.median(wall), min(wall), max(wall), statistics.median(cpu), min(cpu), max(cpu)


def check_means(picture, reference, label):
    """Each channel's mean against the reference's: within 1 % plus 4 standard errors."""
    ok = True
    for c, name in enumerate("RGB"):
        m, r = picture[..., c].mean(), reference[..., c].mean()
        # The standard error of an image mean, from the spread of 8 x 8 blocks' means.
        h, w = picture.shape[0] // 8 * 8, picture.shape[1] // 8 * 8
        blocks = (picture[:h, :w, c] - reference[:h, :w, c]).reshape(h // 8, 8, w // 8, 8).mean(axis=(1, 3))
        se = blocks.std() / math.sqrt(blocks.size)
        rel = (m - r) / r
        good = abs(m - r) <= 0.01 * r + 4 * se
        ok = ok and good
        print(f"{label} {name}: mean {m:.5f}, reference {r:.5f}, {rel * 100:+.2f} % "
              f"(standard error {se / r * 100:.2f} %) {'ok' if good else 'DIFFERS'}")
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--streamrt", default=str(ROOT / "build/engine/streamrt"))
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--embree-spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--spp", default="4,8,16,32,64", help="streamrt's sample counts")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--recursive", action="store_true", help="also time the recursive engine at each count")
    ap.add_argument("--check", action="store_true", help="quick agreement check (a ctest)")
    ap.add_argument("--work", default=str(ROOT / "build/gi"))
    ap.add_argument("--out", help="folder for the pictures and the difference image (e.g. docs/img)")
    a = ap.parse_args()
    if not (MODELS / "cornell_box.obj").exists() or subprocess.run(["which", "pathtracer"], capture_output=True).returncode:
        print("gi_peer: Embree's pathtracer or its Cornell box is not installed (Debian package embree-tools): skipped")
        return SKIP
    work = pathlib.Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    if a.check:
        a.size, a.ref_spp = 96, 256
    ref_path = work / f"embree_ref_{a.size}_{a.ref_spp}.pfm"
    if not ref_path.exists():
        print(f"reference: Embree pathtracer, {a.size}x{a.size}, {a.ref_spp} spp ...", flush=True)
        run_embree(a.size, a.ref_spp, ref_path, a.threads)
    ref = image(ref_path)

    if a.check:
        out = work / "check_streamrt.pfm"
        ok = True
        for engine in ("stream", "recursive"):
            run_streamrt(a.streamrt, a.size, 256, out, a.threads, engine)
            ok = check_means(streamrt_image(out), ref, f"streamrt ({engine}, 256 spp)") and ok
        return 0 if ok else 1

    embree_path = work / f"embree_{a.size}_{a.embree_spp}.pfm"
    e_time = timed(lambda: run_embree(a.size, a.embree_spp, embree_path, a.threads), a.reps)
    e_rmse = rmse(image(embree_path), ref)
    rows = [("Embree pathtracer", a.embree_spp, e_rmse) + e_time]
    print(f"Embree pathtracer {a.embree_spp} spp: RMSE {e_rmse:.5f}, wall {e_time[0]:.3f} s "
          f"({e_time[1]:.3f} - {e_time[2]:.3f}), CPU {e_time[3]:.3f} s ({e_time[4]:.3f} - {e_time[5]:.3f})", flush=True)
    curve = []
    engines = ("stream", "recursive") if a.recursive else ("stream",)
    for spp in [int(s) for s in a.spp.split(",")]:
        for engine in engines:
            out = work / f"streamrt_{engine}_{a.size}_{spp}.pfm"
            t = timed(lambda: run_streamrt(a.streamrt, a.size, spp, out, a.threads, engine), a.reps)
            e = rmse(streamrt_image(out), ref)
            rows.append((f"streamrt {engine}", spp, e) + t)
            if engine == "stream":
                curve.append((spp, e, t[0], t[3]))
            print(f"streamrt {engine} {spp} spp: RMSE {e:.5f}, wall {t[0]:.3f} s ({t[1]:.3f} - {t[2]:.3f}), "
                  f"CPU {t[3]:.3f} s ({t[4]:.3f} - {t[5]:.3f})", flush=True)

    # The time to reach Embree's RMSE: from the count whose RMSE is nearest it, with RMSE ~
    # spp^-1/2, and time ~ a + b spp fitted on the measured counts (wall and CPU alike).
    spps = np.array([c[0] for c in curve], dtype=float)
    best = min(curve, key=lambda c: abs(math.log(c[1] / e_rmse)))
    need = best[0] * (best[1] / e_rmse) ** 2
    for label, col, embree_t in (("wall", 2, e_time[0]), ("CPU", 3, e_time[3])):
        b, a0 = np.polyfit(spps, np.array([c[col] for c in curve]), 1)
        t_need = a0 + b * need
        print(f"streamrt reaches Embree's {a.embree_spp}-spp RMSE at about {need:.1f} spp: {t_need:.3f} s {label} "
              f"({t_need / embree_t:.3f}x Embree's {embree_t:.3f} s)")
    stream64 = work / f"streamrt_stream_{a.size}_64.pfm"
    if stream64.exists():
        check_means(streamrt_image(stream64), ref, "streamrt (stream, 64 spp)")
        check_means(image(embree_path), ref, f"Embree ({a.embree_spp} spp)")
    table = work / "embree_cornell.md"
    with open(table, "w") as f:
        f.write("| renderer | spp | RMSE | wall s (median) | min | max | CPU s (median) | min | max |\n"
                "|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write(f"| {r[0]} | {r[1]} | {r[2]:.5f} | " + " | ".join(f"{v:.3f}" for v in r[3:]) + " |\n")
    print("table:", table)
    if a.out and stream64.exists():
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        out = pathlib.Path(a.out)
        diff = streamrt_image(stream64) - ref
        fig, ax = plt.subplots(1, 3, figsize=(12, 4.3))
        for axis, img, title in ((ax[0], streamrt_image(stream64), "streamrt, 64 spp"), (ax[1], ref, f"Embree, {a.ref_spp} spp"),
                                 (ax[2], None, "streamrt - Embree (mean of R, G, B)")):
            axis.set_axis_off()
            axis.set_title(title)
            if img is not None:
                axis.imshow(np.clip(img, 0, 1) ** (1 / 2.2))
        im = ax[2].imshow(diff.mean(axis=2), cmap="RdBu", vmin=-0.1, vmax=0.1)
        fig.colorbar(im, ax=ax[2], fraction=0.046)
        fig.tight_layout()
        fig.savefig(out / "gi_embree_cornell.png", dpi=80)
        print("picture:", out / "gi_embree_cornell.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
