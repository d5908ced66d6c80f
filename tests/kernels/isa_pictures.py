#!/usr/bin/env python3
"""Renders scenes with the stream engine at every instruction-set level the CPU has
(--isa sse2, sse4.2, avx2, avx512) and compares the PFM pictures byte for byte
(docs/architecture.md, "Kernels and instruction sets": the pictures are bit-identical).

For each scene prints the levels whose picture differs from the first level's, with the
largest absolute difference of a channel and the share of pixels with any channel different.
Exits 1 when a picture differs (or a render fails) and 0 when every scene gives the same bytes
at every level.

    python3 tests/kernels/isa_pictures.py --streamrt build/streamrt [--width 96 --height 64 --spp 2]
        [--accel auto|off|packet|single] [--shade ...] [--degree N] [SCENE.cfg ...]

Without scene arguments: every scene in scenes/ (and its sub-folders) and in
tests/reference/scenes/, except scenes/degrees/common.cfg (the shared part of degree*.cfg,
rendered through them).
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import perf_common  # noqa: E402  (read_pfm)

LEVELS = ["sse2", "sse4.2", "avx2", "avx512"]


def default_scenes():
    scenes = sorted((ROOT / "scenes").rglob("*.cfg")) + sorted((ROOT / "tests/reference/scenes").glob("*.cfg"))
    return [s for s in scenes if s.name != "common.cfg"]


def read_pfm(path):
    """(width, height, flat RGB floats, file bytes)."""
    w, h, img = perf_common.read_pfm(str(path))
    return w, h, [float(v) for v in (img.ravel() if hasattr(img, "ravel") else img)], path.read_bytes()


# The CPU flags each level needs (the same sets engine/kernels/dispatch.cpp asks xsimd for),
# read here from /proc/cpuinfo: what the machine has is not taken from the program under test.
CPU_FLAGS = {"sse2": (), "sse4.2": ("sse4_2",), "avx2": ("avx2", "fma"),
             "avx512": ("avx512f", "avx512bw", "avx512dq", "avx512cd")}


SKIPPED = 77  # ctest's SKIP_RETURN_CODE (tests/CMakeLists.txt)


def cpu_levels():
    """The levels this CPU has by its flags, or None where /proc/cpuinfo cannot say."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    flags = set(line.split(":", 1)[1].split())
                    return [level for level in LEVELS if all(flag in flags for flag in CPU_FLAGS[level])]
    except OSError:
        pass
    return None


def supported_levels(streamrt, scene):
    levels = []
    for level in LEVELS:
        r = subprocess.run([streamrt, str(scene), "--isa", level, "--check", "-q"], capture_output=True, text=True)
        if r.returncode == 0:
            levels.append(level)
    return levels


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--streamrt", required=True)
    ap.add_argument("--width", type=int, default=96)
    ap.add_argument("--height", type=int, default=64)
    ap.add_argument("--spp", type=int, default=2)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--accel", default=None, help="passed to streamrt --accel")
    ap.add_argument("--shade", default=None, help="passed to streamrt --shade")
    ap.add_argument("--degree", default=None, help="passed to streamrt --degree")
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args()
    scenes = [pathlib.Path(s) for s in args.scenes] or default_scenes()
    levels = supported_levels(args.streamrt, scenes[0])
    have = cpu_levels()
    # A level the CPU has that streamrt refuses is a failure, not fewer pictures to compare:
    # with fewer than two levels the check compared nothing and passed.
    if have is not None and levels != have:
        print(f"the CPU has {', '.join(have)} (/proc/cpuinfo), but streamrt --isa ran {', '.join(levels) or 'none'}")
        return 1
    if len(levels) < 2:
        print("fewer than two instruction-set levels on this CPU:", levels, "(skipped)")
        return SKIPPED
    print("levels:", ", ".join(levels), f"({args.width}x{args.height}, spp {args.spp})")
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            pictures = {}
            for level in levels:
                out = pathlib.Path(tmp) / f"{scene.stem}_{level}.pfm"
                cmd = [args.streamrt, str(scene), "--isa", level, "-q", "-j", str(args.jobs), "-o", str(out),
                       "--width", str(args.width), "--height", str(args.height), "--spp", str(args.spp)]
                if args.accel:
                    cmd += ["--accel", args.accel]
                if args.shade:
                    cmd += ["--shade", args.shade]
                if args.degree:
                    cmd += ["--degree", args.degree]
                r = subprocess.run(cmd, capture_output=True, text=True)
                if r.returncode != 0:
                    print(f"{scene}: --isa {level} failed: {r.stderr.strip()}")
                    failures += 1
                    break
                pictures[level] = read_pfm(out)
            if len(pictures) != len(levels):
                continue
            first = levels[0]
            w, h, ref, ref_bytes = pictures[first]
            notes = []
            for level in levels[1:]:
                _, _, img, img_bytes = pictures[level]
                if img_bytes == ref_bytes:
                    continue
                max_diff, pixels = 0.0, 0
                for p in range(w * h):
                    d = max(abs(ref[3 * p + c] - img[3 * p + c]) for c in range(3))
                    if d > 0 or any(ref[3 * p + c] != img[3 * p + c] for c in range(3)):
                        pixels += 1
                        max_diff = max(max_diff, d)
                notes.append(f"{level} differs from {first}: max abs {max_diff:.3g}, "
                             f"{100.0 * pixels / (w * h):.2f} % of pixels")
            rel = scene.resolve().relative_to(ROOT) if scene.resolve().is_relative_to(ROOT) else scene
            if notes:
                failures += 1
                print(f"{rel}: " + "; ".join(notes))
            else:
                print(f"{rel}: identical at {', '.join(levels)}")
    print(f"{failures} scene(s) with pictures that differ between levels" if failures
          else "every picture is bit-identical at every level")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
