"""Shared helpers of the perf scripts (perf_suite.py, error_vs_time.py): running streamrt
with timing, peak memory and profile, generating N-sphere scenes, reading PFM images and
measuring image error exactly as engine/image/image_compare.cpp does. Standard library only
(numpy is used when the interpreter has it, for speed)."""
import json
import math
import os
import platform
import re
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from array import array

try:
    import numpy as np
except ImportError:  # pragma: no cover - the pure-Python path is slower but equal
    np = None

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PHASES_RE = re.compile(r"\(read ([0-9.]+) s, set-up ([0-9.]+) s, render ([0-9.]+) s, write ([0-9.]+) s\)")
SUMMARY_RE = re.compile(r": (\d+)x(\d+), spp (\d+), degree (\d+), (\w+) engine, -j(\d+): ([0-9.]+) s, (\d+) rays")


def binary(build_dir):
    exe = os.path.join(build_dir, "engine", "streamrt")
    if not os.access(exe, os.X_OK):
        sys.exit("%s not found: build first (cmake -S . -B build -G Ninja && ninja -C build -j2)" % exe)
    return exe


def run_streamrt(exe, scene, out_pfm, engine="stream", jobs=1, spp=None, width=None, height=None, depth=None,
                 sampler=None, profile_json=None, extra=()):
    """Renders once. Returns a dict: render seconds (streamrt's own clock, parse and build
    excluded), process wall seconds, total rays, peak RSS in MiB, per-kind ray counts (stream
    engine with a profile), and the stage figures of the profile."""
    cmd = [exe, scene, "-o", out_pfm, "--engine", engine, "-j", str(jobs)]
    for flag, v in (("--spp", spp), ("--width", width), ("--height", height), ("--depth", depth),
                    ("--sampler", sampler)):
        if v is not None:
            cmd += [flag, str(v)]
    if profile_json:
        cmd += ["--profile=json", profile_json]
    cmd += list(extra)
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=out, stderr=err)
        _, status, ru = os.wait4(p.pid, 0)  # this child's own rusage: its peak RSS
        wall = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        text, etext = out.read().decode(), err.read().decode()
    if p.returncode != 0:
        raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd), p.returncode, etext.strip()))
    m = SUMMARY_RE.search(text)
    if not m:
        raise RuntimeError("no summary line from: %s\n%s" % (" ".join(cmd), text))
    r = {"seconds": float(m.group(7)), "rays": int(m.group(8)), "wall": wall,
         "peak_rss_mib": ru.ru_maxrss / 1024.0, "width": int(m.group(1)), "height": int(m.group(2)),
         "spp": int(m.group(3))}
    phases = PHASES_RE.search(text)  # the whole process's phases (binaries before they were reported lack them)
    if phases:
        r.update(read=float(phases.group(1)), setup=float(phases.group(2)), render=float(phases.group(3)),
                 write=float(phases.group(4)))
    if profile_json:
        with open(profile_json) as f:
            prof = json.load(f)
        r["kinds"] = prof["rays"]
        r["stages"] = {s["stage"]: s for s in prof["stages"]}
        r["isa"] = prof.get("isa")
    return r


def read_pfm(path):
    """Returns (width, height, flat list/array of floats, RGB, top row first)."""
    with open(path, "rb") as f:
        data = f.read()
    parts, pos = [], 0
    while len(parts) < 4:  # "PF", width, height, scale, each ended by whitespace
        while data[pos:pos + 1].isspace():
            pos += 1
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        parts.append(data[start:pos].decode())
    pos += 1
    if parts[0] != "PF":
        raise ValueError(path + ": not an RGB PFM")
    w, h, scale = int(parts[1]), int(parts[2]), float(parts[3])
    endian = "<" if scale < 0 else ">"
    n = w * h * 3
    if np is not None:
        img = np.frombuffer(data, dtype=endian + "f4", count=n, offset=pos).reshape(h, w, 3)[::-1]
        return w, h, img
    vals = array("f")
    vals.frombytes(data[pos:pos + 4 * n])
    if (endian == "<") != (sys.byteorder == "little"):
        vals.byteswap()
    rows = [vals[(h - 1 - y) * w * 3:(h - y) * w * 3] for y in range(h)]
    return w, h, [v for row in rows for v in row]


def module(build_dir):
    """The streamrt Python module of that build (build/python, docs/python.md)."""
    path = os.path.join(build_dir, "python")
    sys.path.insert(0, path)
    try:
        import streamrt
    except ImportError as exc:
        sys.exit("the streamrt module is not in %s (%s): build first with scripts/build.sh, and run "
                 "this script with /usr/bin/python3" % (path, exc))
    return streamrt


def array_error(image, reference):
    """image_error of two height x width x 3 arrays (NumPy)."""
    a = np.clip(np.nan_to_num(np.asarray(image, np.float64), nan=0.0, posinf=0.0, neginf=0.0), 0, 1)
    b = np.clip(np.nan_to_num(np.asarray(reference, np.float64), nan=0.0, posinf=0.0, neginf=0.0), 0, 1)
    e2 = (a - b) ** 2
    mse = float(e2.mean())
    psnr = 10 * math.log10(1 / mse) if mse > 0 else float("inf")
    return {"rmse": math.sqrt(mse), "psnr": psnr, "relmse": float((e2 / (b * b + 1e-2)).mean())}


def image_error(image_path, reference_path):
    """RMSE, PSNR (dB) and relative MSE of image against reference, both clamped to [0, 1]
    (non-finite values count as 0), over every pixel component: the definitions of
    engine/image/image_compare.cpp."""
    wa, ha, a = read_pfm(image_path)
    wb, hb, b = read_pfm(reference_path)
    if (wa, ha) != (wb, hb):
        raise ValueError("images of different sizes: %s, %s" % (image_path, reference_path))
    if np is not None:
        return array_error(a, b)
    # No NumPy: the same definitions, value by value.
    def c(v):
        return min(max(v, 0.0), 1.0) if math.isfinite(v) else 0.0
    s2 = rel = 0.0
    for x, y in zip(a, b):
        x, y = c(x), c(y)
        e = (x - y) ** 2
        s2 += e
        rel += e / (y * y + 1e-2)
    mse, rel = s2 / len(a), rel / len(a)
    psnr = 10 * math.log10(1 / mse) if mse > 0 else float("inf")
    return {"rmse": math.sqrt(mse), "psnr": psnr, "relmse": rel}


_in_child = False


def sphere_scene(n, path, width=1280, height=720, spp=1, depth=4, seed=1):
    """N spheres on a jittered grid over a square field (the layout of random_spheres.py,
    without its quadratic overlap search, so that N = 1e6 takes seconds), a checkered plane,
    two point lights, a camera looking down at the whole field. Written once, then reused."""
    if os.path.exists(path):
        return path
    if not _in_child:
        # Written by a child process: a parent grown by a 1e6-line scene would pass its
        # resident size on to every streamrt it forks, and wait4's peak RSS would show it.
        subprocess.run([sys.executable, "-B", os.path.abspath(__file__), "spheres", str(n), path, str(width),
                        str(height), str(spp), str(depth), str(seed)], check=True)
        return path
    import random
    rng = random.Random(seed)
    g = max(1, math.ceil(math.sqrt(n)))
    cell = 4.0
    side = cell * g
    lines = [
        "# %d spheres on a jittered grid (scripts/perf_common.py, seed %d)" % (n, seed),
        "image width=%d height=%d spp=%d depth=%d degree=5 output=spheres.png" % (width, height, spp, depth),
        "ambient 0.1",
        "background 0.5,0.65,0.85",
        "camera eye=0,%.4f,%.4f look=0,0,%.4f up=0,1,0 fov=45" % (0.75 * side + 2, 0.85 * side + 2, -0.05 * side),
        "light point pos=%.4f,%.4f,%.4f color=0.8,0.8,0.8" % (-0.4 * side, side + 4, 0.6 * side),
        "light point pos=%.4f,%.4f,%.4f color=0.45,0.45,0.5" % (0.6 * side, 0.7 * side + 3, 0.2 * side),
        "plane color=0.9,0.9,0.9 checker=0.25,0.25,0.25 cell=%.4f diff=0.9" % (cell / 2),
    ]
    for i in range(n):
        gx, gz = i % g, i // g
        r = cell * rng.uniform(0.2, 0.45)
        x = -side / 2 + (gx + 0.5) * cell + rng.uniform(-1, 1) * (cell / 2 - r)
        z = -side / 2 + (gz + 0.5) * cell + rng.uniform(-1, 1) * (cell / 2 - r)
        kind = rng.random()
        if kind < 0.2:
            mat = "ambi=0.1 diff=0.2 spec=0.6 shininess=80 refl=0.7"
        else:
            mat = "diff=0.85 spec=0.2 shininess=40"
        lines.append("sphere color=%.2f,%.2f,%.2f %s scale=%.4f translate=%.4f,%.4f,%.4f"
                     % (rng.uniform(0.1, 1), rng.uniform(0.1, 1), rng.uniform(0.1, 1), mat, r, x, r, z))
    return write_lines(path, lines)


def uv_sphere_mesh(rings, segments):
    """The unit UV sphere of the benchmarks (issue 19's 1M-triangle mesh at 501 x 1000): the
    north pole, rings - 1 rings of `segments` vertices, the south pole (float64, N x 3), and
    2 * segments * (rings - 1) triangles (0-based, M x 3): per segment the north and the south
    fan's triangle, then per band and segment a quad's two, counter-clockwise from outside."""
    th = np.pi * np.arange(1, rings) / rings
    ph = 2 * np.pi * np.arange(segments) / segments
    v = np.empty((2 + (rings - 1) * segments, 3))
    v[0], v[-1] = (0, 1, 0), (0, -1, 0)
    v[1:-1, 0] = (np.sin(th)[:, None] * np.cos(ph)[None, :]).ravel()
    v[1:-1, 1] = np.repeat(np.cos(th), segments)
    v[1:-1, 2] = (np.sin(th)[:, None] * np.sin(ph)[None, :]).ravel()
    south = len(v) - 1

    def ring(i, j):
        return 1 + (i - 1) * segments + j % segments

    j = np.arange(segments)
    fans = np.stack([np.stack([np.zeros(segments, np.int64), ring(1, j + 1), ring(1, j)], 1),
                     np.stack([np.full(segments, south), ring(rings - 1, j), ring(rings - 1, j + 1)], 1)], 1)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(1, rings - 1), np.arange(segments), indexing="ij"))
    a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
    bands = np.stack([np.stack([a, c, b], 1), np.stack([a, d, c], 1)], 1)
    return v, np.concatenate([fans.reshape(-1, 3), bands.reshape(-1, 3)])


def write_lines(path, lines):
    """Writes the lines to path through a temporary file renamed into place (never half a
    file under the name); returns path."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, path)
    return path


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def git_revision():
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def machine_info():
    return {"cpu": cpu_model(), "cores": os.cpu_count(), "date": time.strftime("%Y-%m-%d %H:%M"),
            "revision": git_revision(), "python": sys.version.split()[0]}


def median(xs):
    return statistics.median(xs)


if __name__ == "__main__" and len(sys.argv) == 9 and sys.argv[1] == "spheres":
    _in_child = True
    a = sys.argv
    sphere_scene(int(a[2]), a[3], int(a[4]), int(a[5]), int(a[6]), int(a[7]), int(a[8]))
