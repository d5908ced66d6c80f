"""The meshes the benchmarks generate (scripts/fetch_bunny.py --split, peer_bench.uv_sphere,
big_mesh_bench.write_sphere), run by ctest with Debian's pytest.

Each is checked against counts worked out by hand and against the properties the benchmarks
rely on: the mesh is closed (every edge between exactly two triangles, once in each
direction, so the winding is consistent) and wound counter-clockwise seen from outside (the
enclosed volume, summed from the triangles, is positive), and the split keeps the surface (the
same volume)."""
import collections
import os
import struct
import sys
import tempfile

import pytest

SCRIPTS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "scripts")
sys.dont_write_bytecode = True
sys.path.insert(0, SCRIPTS)

import big_mesh_bench  # noqa: E402
import fetch_bunny  # noqa: E402
import peer_bench  # noqa: E402


def signed_volume(positions, cells):
    """Six times the volume enclosed by the triangles (positive: counter-clockwise from outside)."""
    v = 0.0
    for a, b, c in cells:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = positions[a], positions[b], positions[c]
        v += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    return v


def assert_closed(cells):
    directed = collections.Counter()
    for a, b, c in cells:
        for e in ((a, b), (b, c), (c, a)):
            directed[e] += 1
    assert all(n == 1 for n in directed.values()), "an edge used twice in one direction"
    assert all((b, a) in directed for (a, b) in directed), "an edge with one triangle"


def read_obj(path):
    positions, cells = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                positions.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith("f "):
                cells.append(tuple(int(x) - 1 for x in line.split()[1:4]))
    return positions, cells


TETRAHEDRON = ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)],
               [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])


def test_split_quadruples_the_triangles_and_keeps_the_surface():
    positions, cells = TETRAHEDRON
    assert signed_volume(positions, cells) == pytest.approx(1.0)  # 6 x 1/6: wound outwards
    p1, c1 = fetch_bunny.split(positions, cells)
    assert (len(p1), len(c1)) == (4 + 6, 16)  # a midpoint per edge, four triangles per triangle
    assert_closed(c1)
    assert signed_volume(p1, c1) == pytest.approx(1.0, abs=1e-12)
    assert (0.5, 0.0, 0.0) in p1 and (0.0, 0.5, 0.5) in p1
    p3, c3 = fetch_bunny.split(*fetch_bunny.split(p1, c1))
    assert len(c3) == 4 * 4 ** 3  # the benchmark's bunny: 3,674 x 64 = 235,136
    assert_closed(c3)
    assert signed_volume(p3, c3) == pytest.approx(1.0, abs=1e-12)


def test_split_ply_round_trip():
    positions, cells = TETRAHEDRON
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "t.ply")
        fetch_bunny.write_ply(path, positions, cells)
        back_p, back_c = fetch_bunny.read_ply(path)
    assert [tuple(p) for p in back_p] == positions and [tuple(c) for c in back_c] == cells


def test_uv_sphere_counts_closed_and_outwards():
    with tempfile.TemporaryDirectory() as tmp:
        path = peer_bench.uv_sphere(os.path.join(tmp, "s.obj"), rings=4, segments=6)
        positions, cells = read_obj(path)
    assert (len(positions), len(cells)) == (2 + 3 * 6, 2 * 6 * 3)
    assert_closed(cells)
    assert signed_volume(positions, cells) > 0
    assert all(abs(x * x + y * y + z * z - 1) < 1e-6 for x, y, z in positions)


def test_big_mesh_sphere_shape_and_file():
    assert big_mesh_bench.sphere_shape(10_000_000) == (2001, 2500)
    rings, seg = big_mesh_bench.sphere_shape(120)
    assert 2 * seg * (rings - 1) == 120
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "m.ply")
        big_mesh_bench.write_sphere(path, 120)
        data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    nv = int(header.split("element vertex ")[1].split()[0])
    nf = int(header.split("element face ")[1].split()[0])
    assert (nv, nf) == (2 + (rings - 1) * seg, 120)
    positions = [struct.unpack_from("<3f", data, end + 12 * k) for k in range(nv)]
    cells = []
    at = end + 12 * nv
    for _ in range(nf):
        assert data[at] == 3
        cells.append(struct.unpack_from("<3i", data, at + 1))
        at += 13
    assert at == len(data)
    assert_closed(cells)
    assert signed_volume(positions, cells) > 0
