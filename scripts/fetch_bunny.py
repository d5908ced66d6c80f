#!/usr/bin/env python3
"""Writes the Stanford bunny as a binary PLY file for the peer benchmark (docs/performance.md,
"Against POV-Ray and Embree").

usage: /usr/bin/python3 scripts/fetch_bunny.py [-o perf/assets/bunny.ply] [--tgz FILE] [--force]
                                              [--split N]

The mesh comes from the npm package `bunny` (public domain: `exports.positions` and
`exports.cells`, two JSON arrays in a JS file, 1 839 vertices and 3 674 triangles, closed and
wound counter-clockwise seen from outside, +y up, standing on y = 0). `npm pack bunny` fetches
the package's tarball (nothing is installed); --tgz reads one fetched before. The output is
generated, not committed (perf/assets/ is ignored by git).

--split N also writes the bunny with every triangle cut into four at its edges' midpoints, N
times (the same surface, 3 674 * 4^N triangles), to perf/assets/bunny_split<N>.ply (or -o): N = 3
gives the 235 136-triangle "bunny split three times" of issue 19, its ~200k-triangle scanned mesh
for the comparison with Embree. It is made from bunny.ply (fetched first when missing).

Exit status: 0 written (or already there), 3 npm is not installed or the package could not be
fetched (the message says which; the peer benchmark then skips the bunny scene), 1 otherwise.
"""
import argparse
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tarfile
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_OUT = os.path.join(ROOT, "perf", "assets", "bunny.ply")
UNAVAILABLE = 3


def fetch_tarball(tmp):
    """`npm pack bunny` into tmp; returns the tarball's path, or None with a message."""
    npm = shutil.which("npm")
    if npm is None:
        print("fetch_bunny: npm is not installed (apt-get install npm): no bunny mesh", file=sys.stderr)
        return None
    p = subprocess.run([npm, "pack", "bunny", "--silent"], cwd=tmp, capture_output=True, text=True)
    names = [n for n in os.listdir(tmp) if n.endswith(".tgz")]
    if p.returncode != 0 or not names:
        print("fetch_bunny: `npm pack bunny` failed (%d): %s" % (p.returncode, (p.stderr or p.stdout).strip()[-400:]),
              file=sys.stderr)
        return None
    return os.path.join(tmp, names[0])


def read_package(tgz):
    """(positions, cells) from the package's index.js."""
    with tarfile.open(tgz) as tf:
        member = next((m for m in tf.getmembers() if m.name.endswith("/index.js")), None)
        if member is None:
            raise ValueError("%s: no index.js in the package" % tgz)
        text = tf.extractfile(member).read().decode("utf-8")

    def array(name):
        m = re.search(r"exports\.%s\s*=\s*" % name, text)
        if not m:
            raise ValueError("index.js: no exports.%s" % name)
        value, _ = json.JSONDecoder().raw_decode(text, m.end())
        return value

    positions, cells = array("positions"), array("cells")
    if not positions or not cells or any(len(v) != 3 for v in positions) or any(len(c) != 3 for c in cells):
        raise ValueError("index.js: positions and cells are not lists of triples")
    n = len(positions)
    if any(not 0 <= i < n for c in cells for i in c):
        raise ValueError("index.js: a cell names a vertex that is not there")
    return positions, cells


def write_ply(path, positions, cells):
    header = ("ply\nformat binary_little_endian 1.0\ncomment Stanford bunny, from the npm package 'bunny' "
              "(scripts/fetch_bunny.py)\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
              "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(positions), len(cells)))
    body = bytearray(header.encode("ascii"))
    for v in positions:
        body += struct.pack("<3f", *v)
    for c in cells:
        body += struct.pack("<B3i", 3, *c)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(body)
    os.replace(tmp, path)


def read_ply(path):
    """(positions, cells) of a PLY file as write_ply writes it."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii")
    nv = int(re.search(r"element vertex (\d+)", header).group(1))
    nf = int(re.search(r"element face (\d+)", header).group(1))
    positions = [struct.unpack_from("<3f", data, end + 12 * k) for k in range(nv)]
    at = end + 12 * nv
    cells = []
    for _ in range(nf):
        if data[at] != 3:
            raise ValueError("%s: a face that is not a triangle" % path)
        cells.append(struct.unpack_from("<3i", data, at + 1))
        at += 13
    return positions, cells


def split(positions, cells):
    """Every triangle cut into four at its edges' midpoints (shared edges share the midpoint, so
    the mesh stays closed), the winding kept."""
    positions = list(positions)
    mid = {}

    def midpoint(a, b):
        key = (a, b) if a < b else (b, a)
        if key not in mid:
            pa, pb = positions[a], positions[b]
            mid[key] = len(positions)
            positions.append(tuple((pa[k] + pb[k]) / 2 for k in range(3)))
        return mid[key]

    out = []
    for a, b, c in cells:
        ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return positions, out


def write_split(args):
    if not os.path.exists(DEFAULT_OUT) and main(["--tgz", args.tgz] if args.tgz else []) != 0:
        return UNAVAILABLE
    out = args.output if args.output != DEFAULT_OUT else os.path.join(ROOT, "perf", "assets",
                                                                      "bunny_split%d.ply" % args.split)
    if os.path.exists(out) and not args.force:
        print(out)
        return 0
    positions, cells = read_ply(DEFAULT_OUT)
    for _ in range(args.split):
        positions, cells = split(positions, cells)
    write_ply(out, positions, cells)
    print("%s: %d vertices, %d triangles" % (out, len(positions), len(cells)), file=sys.stderr)
    print(out)
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--output", default=DEFAULT_OUT)
    ap.add_argument("--tgz", help="a tarball of the package fetched before (npm pack bunny)")
    ap.add_argument("--force", action="store_true", help="write it again when it is there")
    ap.add_argument("--split", type=int, default=0, help="cut every triangle into four, N times (above)")
    args = ap.parse_args(argv)
    if args.split < 0:
        ap.error("--split must be at least 0")
    if args.split > 0:
        return write_split(args)
    if os.path.exists(args.output) and not args.force:
        print(args.output)
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        tgz = args.tgz or fetch_tarball(tmp)
        if tgz is None:
            return UNAVAILABLE
        try:
            positions, cells = read_package(tgz)
        except (OSError, ValueError, tarfile.TarError) as exc:
            print("fetch_bunny: %s" % exc, file=sys.stderr)
            return 1
    write_ply(args.output, positions, cells)
    print("%s: %d vertices, %d triangles" % (args.output, len(positions), len(cells)), file=sys.stderr)
    print(args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
