#!/usr/bin/env python3
"""Peak memory and phases of a render of one very large mesh (docs/performance.md, "A
10M-triangle mesh"; issue 19 asks that a 10M-triangle mesh render within 2 GB peak).

usage: /usr/bin/python3 scripts/big_mesh_bench.py [--build DIR] [--out DIR] [--triangles N]
                                                  [--jobs J] [--engine stream|recursive]

Writes OUT/uv_sphere_<N>.ply once (binary little-endian PLY: a unit UV sphere of 2 * S * (R - 1)
triangles, S segments and R rings chosen so that the count is N, 10,000,000 by default: 2001
rings x 2500 segments) and OUT/big_mesh.cfg (the sphere in clay with a little mirror over a
checker floor, one point light, 1280x720, depth 4), renders it with streamrt -jJ under GNU time
and prints the closing line's phases and the peak resident set (GNU time's "Maximum resident
set size"; /usr/bin/time is Debian's `time` package). OUT defaults to build/perf.
"""
import argparse
import os
import re
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402

np = pc.np
GNU_TIME = "/usr/bin/time"


def sphere_shape(triangles):
    """(rings, segments) with 2 * segments * (rings - 1) == triangles, segments near 1.25 x rings
    (bands = rings - 1 tried from sqrt(triangles / 2.5) down)."""
    if triangles % 2 == 0:
        for bands in range(int(round((triangles / 2.5) ** 0.5)), 0, -1):
            if (triangles // 2) % bands == 0:
                return bands + 1, triangles // 2 // bands
    raise SystemExit("big_mesh_bench: %d triangles is not 2 * segments * (rings - 1)" % triangles)


def write_sphere(path, triangles):
    if os.path.exists(path):
        return
    rings, seg = sphere_shape(triangles)
    v, t = pc.uv_sphere_mesh(rings, seg)
    v = v.astype("<f4")
    faces = np.empty(len(t), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"], faces["i"] = 3, t
    header = ("ply\nformat binary_little_endian 1.0\ncomment UV sphere, %d rings x %d segments "
              "(scripts/big_mesh_bench.py)\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
              % (rings, seg, len(v), len(t)))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path + ".tmp", "wb") as f:
        f.write(header.encode("ascii"))
        f.write(v.tobytes())
        f.write(faces.tobytes())
    os.replace(path + ".tmp", path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"))
    ap.add_argument("--out", default=None, help="folder for the mesh, the scene and the picture (default BUILD/perf)")
    ap.add_argument("--triangles", type=int, default=10_000_000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--engine", default="stream", choices=("stream", "recursive"))
    args = ap.parse_args()
    exe = pc.binary(args.build)
    out = args.out or os.path.join(args.build, "perf")
    if not os.access(GNU_TIME, os.X_OK):
        raise SystemExit("big_mesh_bench: %s is missing (apt-get install time)" % GNU_TIME)
    mesh = os.path.join(out, "uv_sphere_%d.ply" % args.triangles)
    write_sphere(mesh, args.triangles)
    scene = os.path.join(out, "big_mesh.cfg")
    with open(scene, "w") as f:
        f.write("# one UV sphere of %d triangles (scripts/big_mesh_bench.py)\n" % args.triangles)
        f.write("image width=1280 height=720 spp=1 depth=4 degree=5\n")
        f.write("camera eye=0,0.3,3 look=0,0,0 fov=45\nlight point pos=3,4,5\n")
        f.write("plane color=0.8,0.8,0.8 checker=0.3,0.3,0.3 translate=0,-1,0\n")
        f.write("mesh file=%s color=0.8,0.5,0.3 diff=0.8 spec=0.3 shininess=40 refl=0.2\n" % os.path.basename(mesh))
    picture = os.path.join(out, "big_mesh.png")
    p = subprocess.run([GNU_TIME, "-v", exe, "-j%d" % args.jobs, "--engine", args.engine, scene, "-o", picture],
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit("big_mesh_bench: streamrt failed (%d): %s" % (p.returncode, p.stderr.strip()[-800:]))
    text = p.stdout + p.stderr
    closing = next((ln for ln in text.splitlines() if ln.startswith(scene)), "")
    peak_kib = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([0-9:.]+)", text).group(1)
    print(closing)
    print("mesh %s: %d triangles, %.0f MB; whole process %s; peak resident %.0f MiB = %.2f GB (target <= 2 GB: %s)" % (
        os.path.relpath(mesh, pc.ROOT), args.triangles, os.path.getsize(mesh) / 1e6, wall, peak_kib / 1024,
        peak_kib * 1024 / 1e9, "met" if peak_kib * 1024 <= 2e9 else "missed"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
