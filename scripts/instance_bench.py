#!/usr/bin/env python3
"""Instanced meshes against the same triangles flattened into one mesh (docs/performance.md,
"Instances"; the targets of issue 19: 100 instances cost at most 1.5x the flattened triangles,
10,000 instances keep at least 0.5x the per-ray rate of 100, in at most 200 MB).

usage: /usr/bin/python3 scripts/instance_bench.py [--build DIR] [--out DIR] [--runs N]
                                                  [--mesh FILE] [--counts N,...] [--size WxH]
                                                  [--spp S] [--depth D] [--jobs J] [--no-floor]
                                                  [--smooth] [--seed S] [--write-only]

The mesh: by default a (2,3) torus knot tube generated here (10 240 triangles, no network
needed); --mesh FILE takes an OBJ or PLY file instead (e.g. perf/assets/bunny.ply from
scripts/fetch_bunny.py). Either is centred on its bounding box and scaled to radius 1, then
written to OUT/instances/mesh.obj.

Scenes (OUT/instances/):
  inst_N.cfg   N `mesh file=mesh.obj` statements (each an instance: the file is read once) on a
               square grid of cells 2.5 units wide, each with its own uniform scale (0.6-1.1),
               rotations about x and y and a height that keeps it above the floor; one
               material (clay with a highlight and a little mirror), two point lights, a
               checker floor (--no-floor: none), a camera looking down at the whole field.
  flat_100.cfg inst_100.cfg's instances' triangles transformed into world space by the script
               (float64) and written to ONE OBJ (flat_100.obj), used by one `mesh` statement
               with identity placement; camera, lights, floor and material the same, so its
               picture is inst_100's up to float rounding (the PSNR between them is reported).
Every count of --counts (default 100,10000) renders at the same --size (default 1280x720), so
the rate of the largest compares traversal through a bigger top level (and smaller instances
on screen, hence less coherent packets) with that of 100.

Each scene is rendered by streamrt -jJOBS (default 2) to a PFM, --runs times (default 3, the
cases alternated), timed whole (process start to exit, wall, median); the closing lines give
the render seconds (median) and the rays (per-ray rate = rays / render seconds). One further
run with --profile=json under GNU time (/usr/bin/time) gives the intersect and occlusion
stages' rates (CPU time) and streamrt's peak RSS.
Writes OUT/instances.csv (OUT defaults to build/perf) and prints a markdown table with the
ratios against the targets. --write-only writes the scenes and stops.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402

np = pc.np
CELL = 2.5          # grid spacing; an instance's radius is at most 1.1, so they never overlap
FLAT_COUNT = 100    # the instanced scene flattened for comparison
GNU_TIME = "/usr/bin/time"
MATERIAL = "color=0.85,0.55,0.35 ambi=0.15 diff=0.8 spec=0.4 shininess=50 refl=0.15"


# ---- meshes ----------------------------------------------------------------------------------

def torus_knot(segments=256, sides=20, p=2, q=3, tube=0.35):
    """(vertices, triangles) of a tube of radius `tube` around the (p, q) torus knot,
    segments x sides x 2 triangles, counter-clockwise seen from outside."""
    def curve(t):
        r = 2.0 + np.cos(q * t)
        return np.stack([r * np.cos(p * t), r * np.sin(p * t), -np.sin(q * t)], axis=-1)

    t = np.arange(segments) * (2 * math.pi / segments)
    h = 1e-4
    c, cp, cm = curve(t), curve(t + h), curve(t - h)
    tang = cp - cm
    tang /= np.linalg.norm(tang, axis=1, keepdims=True)
    bino = np.cross(tang, cp - 2 * c + cm)  # Frenet frame: the (2,3) knot's curvature never vanishes
    bino /= np.linalg.norm(bino, axis=1, keepdims=True)
    norm = np.cross(bino, tang)
    a = np.arange(sides) * (2 * math.pi / sides)
    ring = np.cos(a)[None, :, None] * norm[:, None, :] + np.sin(a)[None, :, None] * bino[:, None, :]
    verts = (c[:, None, :] + tube * ring).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(segments), np.arange(sides), indexing="ij")
    v00 = i * sides + j
    v10 = ((i + 1) % segments) * sides + j
    v11 = ((i + 1) % segments) * sides + (j + 1) % sides
    v01 = i * sides + (j + 1) % sides
    tris = np.concatenate([np.stack([v00, v10, v11], -1).reshape(-1, 3),
                           np.stack([v00, v11, v01], -1).reshape(-1, 3)])
    # Outward winding: the first face's normal must point away from the curve.
    p0, p1, p2 = verts[tris[0]]
    if np.dot(np.cross(p1 - p0, p2 - p0), p0 - c[0]) < 0:
        tris = tris[:, ::-1]
    return verts, tris


def load_mesh(path):
    import peer_bench  # its OBJ and PLY readers
    pos, tris = (peer_bench.read_ply if path.lower().endswith(".ply") else peer_bench.read_obj)(path)
    return np.asarray(pos, np.float64), np.asarray(tris, np.int64)


def normalised(verts):
    """Centred on the bounding box, farthest vertex at distance 1."""
    v = verts - (verts.min(0) + verts.max(0)) / 2
    return v / np.linalg.norm(v, axis=1).max()


def write_obj(path, verts, tris, comment):
    with open(path + ".tmp", "w") as f:
        f.write("# %s: %d vertices, %d triangles (scripts/instance_bench.py)\n" % (comment, len(verts), len(tris)))
        np.savetxt(f, verts, fmt="v %.9g %.9g %.9g")
        np.savetxt(f, tris + 1, fmt="f %d %d %d")
    os.replace(path + ".tmp", path)


# ---- scenes ----------------------------------------------------------------------------------

def placements(n, seed):
    """Per instance: scale, rotate_x, rotate_y (degrees) and translation on a square grid."""
    rng = np.random.default_rng(seed)
    g = max(1, math.ceil(math.sqrt(n)))
    k = np.arange(n)
    s = rng.uniform(0.6, 1.1, n)
    rx, ry = rng.uniform(0, 360, n), rng.uniform(0, 360, n)
    side = CELL * g
    x = -side / 2 + (k % g + 0.5) * CELL
    z = -side / 2 + (k // g + 0.5) * CELL
    y = s + 0.05  # radius s: clear of the floor
    return s, rx, ry, np.stack([x, y, z], -1), side


def matrices(s, rx, ry, t):
    """Md = translate x rotate_y x rotate_x x scale (the keys' written order), as (n, 3, 3), (n, 3)."""
    a, b = np.radians(rx), np.radians(ry)
    n = len(s)
    rot_x = np.zeros((n, 3, 3))
    rot_x[:, 0, 0] = 1
    rot_x[:, 1, 1], rot_x[:, 1, 2] = np.cos(a), -np.sin(a)
    rot_x[:, 2, 1], rot_x[:, 2, 2] = np.sin(a), np.cos(a)
    rot_y = np.zeros((n, 3, 3))
    rot_y[:, 1, 1] = 1
    rot_y[:, 0, 0], rot_y[:, 0, 2] = np.cos(b), np.sin(b)
    rot_y[:, 2, 0], rot_y[:, 2, 2] = -np.sin(b), np.cos(b)
    return rot_y @ rot_x * s[:, None, None], t


def header(side, width, height, spp, depth, floor, n):
    lines = [
        "image width=%d height=%d spp=%d depth=%d degree=5 output=instances.png" % (width, height, spp, depth),
        "ambient 0.1",
        "background 0.5,0.65,0.85",
        # The whole field in the picture, its corners at about 0.93 of the half-width and half-height.
        "camera eye=0,%.4f,%.4f look=0,0,%.4f up=0,1,0 fov=45" % (0.82 * side, 0.77 * side, 0.1 * side),
        "light point pos=%.4f,%.4f,%.4f color=0.8,0.8,0.8" % (-0.4 * side, side + 4, 0.6 * side),
        "light point pos=%.4f,%.4f,%.4f color=0.45,0.45,0.5" % (0.6 * side, 0.7 * side + 3, 0.2 * side),
    ]
    if floor:
        lines.append("plane color=0.9,0.9,0.9 checker=0.25,0.25,0.25 cell=%.4f diff=0.9" % (CELL / 2))
    return ["# %d instances of mesh.obj on a grid (scripts/instance_bench.py)" % n] + lines


def write_scenes(args, d):
    """Writes mesh.obj, inst_N.cfg for every count and flat_100.cfg/.obj."""
    os.makedirs(d, exist_ok=True)
    if args.mesh:
        verts, tris = load_mesh(args.mesh)
        what = os.path.basename(args.mesh)
    else:
        verts, tris = torus_knot()
        what = "(2,3) torus knot"
    verts = normalised(verts)
    write_obj(os.path.join(d, "mesh.obj"), verts, tris, what + ", centred, radius 1")
    smooth = "true" if args.smooth else "false"
    for n in sorted(set(args.counts) | {FLAT_COUNT}):
        s, rx, ry, t, side = placements(n, args.seed)
        lines = header(side, args.width, args.height, args.spp, args.depth, args.floor, n)
        lines += ["mesh file=mesh.obj smooth=%s %s scale=%.9g rotate_x=%.9g rotate_y=%.9g translate=%.9g,%.9g,%.9g"
                  % (smooth, MATERIAL, s[i], rx[i], ry[i], *t[i]) for i in range(n)]
        path = os.path.join(d, "inst_%d.cfg" % n)
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        if n == FLAT_COUNT:
            m, tt = matrices(s, rx, ry, t)
            world = np.einsum("nij,vj->nvi", m, verts) + tt[:, None, :]
            ftris = (np.arange(n)[:, None, None] * len(verts) + tris[None]).reshape(-1, 3)
            write_obj(os.path.join(d, "flat_%d.obj" % n), world.reshape(-1, 3), ftris,
                      "%d instances of %s in world space" % (n, what))
            lines = header(side, args.width, args.height, args.spp, args.depth, args.floor, n)
            lines[0] = "# inst_%d.cfg's instances flattened into one mesh (scripts/instance_bench.py)" % n
            lines.append("mesh file=flat_%d.obj smooth=%s %s" % (n, smooth, MATERIAL))
            path = os.path.join(d, "flat_%d.cfg" % n)
            with open(path, "w") as f:
                f.write("\n".join(lines) + "\n")


def cases_of(d, counts):
    """{case: (scene path, objects, triangles)} of the scenes write_scenes wrote into d."""
    with open(os.path.join(d, "mesh.obj")) as f:
        tris = sum(1 for line in f if line.startswith("f "))
    cases = {"flattened %d" % FLAT_COUNT: (os.path.join(d, "flat_%d.cfg" % FLAT_COUNT), 1, FLAT_COUNT * tris)}
    for n in counts:
        cases["instanced %d" % n] = (os.path.join(d, "inst_%d.cfg" % n), n, n * tris)
    return cases


# ---- measuring -------------------------------------------------------------------------------

def measure(exe, cases, args, d):
    runs = {k: [] for k in cases}
    for r in range(args.runs):  # the cases alternated, so a busy moment hits them all
        for k, (cfg, _, _) in cases.items():
            runs[k].append(pc.run_streamrt(exe, cfg, os.path.join(d, k.replace(" ", "_") + ".pfm"),
                                           jobs=args.jobs))
            print("  run %d/%d %-14s %.3f s" % (r + 1, args.runs, k, runs[k][-1]["wall"]), flush=True)
    rows = []
    for k, (cfg, inst, tris) in cases.items():
        rs = sorted(runs[k], key=lambda x: x["wall"])
        med = rs[len(rs) // 2]
        st, peak = profile_run(exe, cfg, d, args.jobs)
        rows.append(dict(
            case=k, objects=inst, triangles=tris, width=med["width"], height=med["height"], spp=med["spp"],
            wall_s=statistics.median(x["wall"] for x in rs), render_s=statistics.median(x["seconds"] for x in rs),
            read_s=med.get("read"), setup_s=med.get("setup"), rays=med["rays"],
            mrays_s=med["rays"] / statistics.median(x["seconds"] for x in rs) / 1e6,
            peak_rss_mib=peak if peak is not None else statistics.median(x["peak_rss_mib"] for x in rs),
            intersect_mrays=st["intersect"]["mrays_per_s"], intersect_cpu_s=st["intersect"]["cpu_seconds"],
            occlusion_mrays=st["occlusion"]["mrays_per_s"], occlusion_cpu_s=st["occlusion"]["cpu_seconds"],
            cpu_s=sum(s["cpu_seconds"] for s in st.values())))
    return rows


def profile_run(exe, cfg, d, jobs):
    """One more run with --profile=json, under GNU time when it is there: the profile's stages
    and streamrt's own peak RSS in MiB (None without GNU time). wait4 on a child forked by this
    script also counts the copy of the script (Python and NumPy, about 30 MiB) that the child
    was before it exec'd streamrt; GNU time's child is a copy of GNU time, about 2 MiB."""
    prof_json = os.path.join(d, "profile.json")
    cmd = [exe, cfg, "-o", os.path.join(d, "profile.pfm"), "-j", str(jobs), "-q", "--profile=json", prof_json]
    peak = None
    if os.access(GNU_TIME, os.X_OK):
        p = subprocess.run([GNU_TIME, "-f", "peak_kib %M"] + cmd, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError("%s failed: %s" % (" ".join(cmd), p.stderr.strip()))
        peak = int(p.stderr.split("peak_kib")[-1]) / 1024.0
    else:
        print("no %s: peak RSS from wait4, which counts this script's own size too" % GNU_TIME)
        subprocess.run(cmd, check=True)
    with open(prof_json) as f:
        return {s["stage"]: s for s in json.load(f)["stages"]}, peak


def fmt(v, nd=3):
    return "-" if v is None else ("%.*f" % (nd, v))


def report(rows, agree):
    by = {r["case"]: r for r in rows}
    print("\n| scene | objects | triangles | whole process s | read + set-up s | render s | rays | Mrays/s "
          "| intersect / occlusion Mrays/s (CPU) | peak RSS MiB |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %d | %s | %s | %s | %s | %s | %s | %s / %s | %s |" % (
            r["case"], r["objects"], "{:,}".format(r["triangles"]), fmt(r["wall_s"]),
            fmt((r["read_s"] or 0) + (r["setup_s"] or 0)), fmt(r["render_s"]), "{:,}".format(r["rays"]),
            fmt(r["mrays_s"], 2), fmt(r["intersect_mrays"], 2), fmt(r["occlusion_mrays"], 2),
            fmt(r["peak_rss_mib"], 1)))
    print()
    inst, flat = by.get("instanced %d" % FLAT_COUNT), by.get("flattened %d" % FLAT_COUNT)
    if inst and flat:
        for what in ("render_s", "wall_s"):
            q = inst[what] / flat[what]
            print("- instanced %d / flattened %d, %s: **%.2fx** (target <= 1.5x: %s)"
                  % (FLAT_COUNT, FLAT_COUNT, "render" if what == "render_s" else "whole process", q,
                     "met" if q <= 1.5 else "missed"))
        if agree:
            print("- pictures, instanced %d against flattened %d: PSNR %.1f dB, %.3f %% of pixels off by more "
                  "than 1/255" % (FLAT_COUNT, FLAT_COUNT, agree[0], 100 * agree[1]))
    big = max(by[k]["objects"] for k in by if k.startswith("instanced"))
    if inst and big != FLAT_COUNT:
        b = by["instanced %d" % big]
        q = b["mrays_s"] / inst["mrays_s"]
        print("- rate(%d) / rate(%d): **%.2fx** (target >= 0.5x: %s)" % (big, FLAT_COUNT, q,
                                                                          "met" if q >= 0.5 else "missed"))
        mb = b["peak_rss_mib"] * 1.048576
        print("- peak RSS at %d instances: %.1f MiB = %.1f MB (target <= 200 MB: %s)"
              % (big, b["peak_rss_mib"], mb, "met" if mb <= 200 else "missed"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"), help="build folder (default build/)")
    ap.add_argument("--out", default=None, help="output folder (default build/perf of this checkout)")
    ap.add_argument("--runs", type=int, default=3, help="timed runs per case (median; default 3)")
    ap.add_argument("--mesh", help="OBJ or PLY file to instance (default: a generated torus knot)")
    ap.add_argument("--counts", default="100,10000", help="instance counts (default 100,10000)")
    ap.add_argument("--size", default="1280x720", help="WxH of every picture (default 1280x720)")
    ap.add_argument("--spp", type=int, default=1)
    ap.add_argument("--depth", type=int, default=2)
    ap.add_argument("--jobs", type=int, default=2, help="streamrt -j (default 2)")
    ap.add_argument("--no-floor", dest="floor", action="store_false", help="no checker floor")
    ap.add_argument("--smooth", action="store_true", help="smooth=true meshes (default flat faces)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--write-only", action="store_true", help="write the scenes and stop")
    args = ap.parse_args(argv)
    if np is None:
        sys.exit("instance_bench.py needs NumPy: run it with /usr/bin/python3")
    args.counts = sorted({int(c) for c in args.counts.split(",")})
    args.width, args.height = (int(x) for x in args.size.lower().split("x"))
    out = args.out or os.path.join(pc.ROOT, "build", "perf")
    d = os.path.join(out, "instances")

    if args.write_only:
        write_scenes(args, d)
        for k, (cfg, inst, tris) in cases_of(d, args.counts).items():
            print("%-14s %s: %d object(s), %d triangles" % (k, shown(cfg), inst, tris))
        return 0

    exe = pc.binary(args.build)
    # The scenes are written by a child process, so that this one stays small: every streamrt
    # it forks starts as a copy of it (see profile_run).
    t0 = time.time()
    subprocess.run([sys.executable, "-B", os.path.abspath(__file__), "--write-only", "--out", out] +
                   list(sys.argv[1:] if argv is None else argv), check=True)
    print("scenes written in %.1f s" % (time.time() - t0), flush=True)
    cases = cases_of(d, args.counts)

    info = pc.machine_info()
    print("%s, %d cores, revision %s, %s; streamrt -j%d, %dx%d %d spp depth %d, %d runs"
          % (info["cpu"], info["cores"], info["revision"], info["date"], args.jobs, args.width, args.height,
             args.spp, args.depth, args.runs), flush=True)
    rows = measure(exe, cases, args, d)
    agree = picture_agreement(os.path.join(d, "instanced_%d.pfm" % FLAT_COUNT),
                              os.path.join(d, "flattened_%d.pfm" % FLAT_COUNT)) if FLAT_COUNT in args.counts else None
    for r in rows:
        mine = agree if r["case"] == "instanced %d" % FLAT_COUNT else (None, None)
        r["psnr_vs_flat"], r["pixels_off_vs_flat"] = mine
    with open(os.path.join(out, "instances.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    report(rows, agree)
    print("\nwrote %s" % shown(os.path.join(out, "instances.csv")))
    return 0


def shown(path):
    """A path relative to the checkout when inside it, else absolute."""
    path = os.path.abspath(path)
    return os.path.relpath(path, pc.ROOT) if path.startswith(pc.ROOT + os.sep) else path


def picture_agreement(image, reference):
    """PSNR (image_compare's definition) and the fraction of pixels whose largest channel
    difference, both clamped to [0, 1], exceeds 1/255."""
    _, _, a = pc.read_pfm(image)
    _, _, b = pc.read_pfm(reference)
    off = np.abs(np.clip(a, 0, 1) - np.clip(b, 0, 1)).max(axis=2) > 1 / 255
    return pc.array_error(a, b)["psnr"], float(off.mean())


if __name__ == "__main__":
    sys.exit(main())
