#!/usr/bin/env python3
"""streamrt against POV-Ray and Embree on the same scenes (docs/performance.md, "Against
POV-Ray and Embree").

usage: /usr/bin/python3 scripts/peer_bench.py [--build DIR] [--runs N] [--scenes NAME,...]
                                              [--modes MODE,...] [--size WxH] [--no-engines]
                                              [--no-embree] [--embree-meshes NAME,...]
                                              [--povray PATH] [--dry-run] [--log FILE | --no-log]
       /usr/bin/python3 scripts/peer_bench.py --table [--log FILE]

Scenes (perf/scenes/peer/ and scenes/):
  bunny     perf/scenes/peer/bunny_glass.cfg: the Stanford bunny in glass and in clay, a mirror
            sphere, a checker floor, two point lights, depth 8 (the mesh: scripts/fetch_bunny.py,
            which needs npm; without it the scene is skipped)
  million   perf/scenes/peer/million.cfg: a lumpy icosphere of 1 310 720 triangles (generated
            here into perf/assets/lumpy_icosphere.obj), a mirror sphere, the floor, depth 8
  bunny235k perf/scenes/peer/bunny235k_glass.cfg: the bunny scene with the bunny split three
            times, 235 136 triangles (scripts/fetch_bunny.py --split 3)
  whitted   scenes/whitted.cfg, the handout's scene (at --size, 1 spp like the others)
  random_spheres  scenes/random_spheres.cfg: 50 spheres (clay, mirror, glass) on a checker
            floor, two point lights, depth 4 (not in the default set)
All at 1280x720 (--size), 1 spp.

Each scene is translated into a POV-Ray scene (BUILD/peer/NAME.pov, meshes as mesh2 in
NAME_meshes.inc): the camera (z mirrored: POV-Ray is left-handed), point lights, the handout's
shading as POV-Ray finishes (ambient, diffuse, phong, reflection, transmit and ior), the same
depth (max_trace_level = depth + 1: POV-Ray counts the camera ray), the checker in world space.
POV-Ray runs with +WT2 -A -J (2 threads, no anti-aliasing: one ray through each pixel centre),
streamrt with -j2; the time is the whole process's wall time (reading, set-up, rendering and
writing a PPM), the median of --runs runs, the two programs alternated. Modes:
  default     each program's defaults (POV-Ray's adc_bailout is 1/255; streamrt's --cutoff is 0.001)
  nopruning   nothing pruned: POV-Ray `global_settings { adc_bailout 0 }`, streamrt --cutoff 0
  matched     both prune rays worth less than 1/255: POV-Ray's default, streamrt --cutoff 1/255
Then streamrt's two engines (--engine recursive against stream, -j2, defaults) on the same
scenes, and build/perf/embree_rays (Embree 3 against streamrt's mesh kernels per ray kind, one
thread) on the two meshes when it was built (perf/CMakeLists.txt builds it when CMake finds
Embree 3).

Without POV-Ray (`povray` not on PATH, or --povray naming no program) the POV-Ray columns are
skipped with a message; without embree_rays the Embree table is. --dry-run checks the tools,
writes the .pov files of the scenes whose meshes are there, and renders nothing (the test suite
runs it). Writes BUILD/peer/results.{json,md}.

Every real run also appends to the log (--log, default perf/results/peer_runs.jsonl, committed;
--no-log: not) one JSON object per scene and benchmark: "bench" (povray, engines or embree),
"scene", "date" (UTC), "host", "cpu", "isa", "load" (the 1, 5 and 15-minute load averages
before the scene's runs), "load_after", "commit" (of the source the build folder was made from,
"-dirty" when its engine/ or perf/ differ from it), "build", "binaries" (sha256 of streamrt and
embree_rays; "binaries_changed" when a digest moved during the run), "scripts_commit",
"command" and "metrics" (ratios and seconds, each the median of the run's --runs repetitions). --table reads the log and prints the
Markdown table docs/performance.md quotes: per benchmark, scene and ratio, the lowest and the
highest over the runs logged, how many runs on how many days, the loads they ran under, and
the headline, which is the lowest.
"""
import argparse
import json
import math
import os
import platform
import re
import shutil
import struct
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import perf_common as pc  # noqa: E402

PEER_DIR = os.path.join(pc.ROOT, "perf", "scenes", "peer")
ASSETS = os.path.join(pc.ROOT, "perf", "assets")
SCENES = {
    "bunny": os.path.join(PEER_DIR, "bunny_glass.cfg"),
    "bunny235k": os.path.join(PEER_DIR, "bunny235k_glass.cfg"),
    "million": os.path.join(PEER_DIR, "million.cfg"),
    "whitted": os.path.join(pc.ROOT, "scenes", "whitted.cfg"),
    "random_spheres": os.path.join(pc.ROOT, "scenes", "random_spheres.cfg"),
    # CSG (docs/scene-format.md, "CSG"); the lens's Fresnel glass is not translated, so it is
    # in the degree-0 check (--flat) only
    "csg_lens": os.path.join(pc.ROOT, "scenes", "csg", "lens.cfg"),
    "csg_pipe": os.path.join(pc.ROOT, "scenes", "csg", "pipe.cfg"),
    "csg_die": os.path.join(pc.ROOT, "scenes", "csg", "die.cfg"),
    "csg_hollow": os.path.join(pc.ROOT, "scenes", "csg", "hollow.cfg"),
    "csg_tree": os.path.join(pc.ROOT, "scenes", "csg", "tree.cfg"),
    "csg_mesh_cut": os.path.join(pc.ROOT, "scenes", "csg", "mesh_cut.cfg"),
    "csg_glass_merge": os.path.join(pc.ROOT, "scenes", "csg", "glass_merge.cfg"),
    "csg_field": os.path.join(pc.ROOT, "scenes", "csg", "field.cfg"),
    "csg_ring": os.path.join(pc.ROOT, "scenes", "csg", "ring.cfg"),
    "csg_union_merge": os.path.join(pc.ROOT, "scenes", "csg", "union_merge.cfg"),
}
CSG_SCENES = [k for k in SCENES if k.startswith("csg_")]
MODES = {
    # name: (POV-Ray adc_bailout or None for its default, streamrt --cutoff or None for its default)
    "default": (None, None),
    "nopruning": (0.0, 0.0),
    "matched": (None, 1.0 / 255.0),
}
LUMPY_LEVEL = 8  # 20 * 4^8 = 1 310 720 triangles
LOG = os.path.join(pc.ROOT, "perf", "results", "peer_runs.jsonl")
EMBREE_MESHES = {  # --embree-meshes name: file under perf/assets
    "bunny": "bunny.ply",
    "bunny235k": "bunny_split3.ply",
    "sphere1m": "uv_sphere_1m.obj",
    "lumpy": "lumpy_icosphere.obj",
}


# ---- generated meshes -------------------------------------------------------------------------

def lumpy_icosphere(path, level=LUMPY_LEVEL):
    """An icosahedron subdivided `level` times, its vertices pushed onto a lumpy sphere of
    radius about 1: 20 * 4^level triangles, counter-clockwise seen from outside, as OBJ."""
    if os.path.exists(path):
        return path
    t = (1.0 + 5.0 ** 0.5) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(x * x + y * y + z * z) for c in (x, y, z)) for x, y, z in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    xs, ys, zs = [v[0] for v in verts], [v[1] for v in verts], [v[2] for v in verts]
    for _ in range(level):
        mid = {}
        big = 1 << 32

        def midpoint(a, b):
            key = a * big + b if a < b else b * big + a
            m = mid.get(key)
            if m is None:
                x, y, z = xs[a] + xs[b], ys[a] + ys[b], zs[a] + zs[b]
                s = 1.0 / math.sqrt(x * x + y * y + z * z)
                m = mid[key] = len(xs)
                xs.append(x * s), ys.append(y * s), zs.append(z * s)
            return m

        nf = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = nf
    sin = math.sin
    lines = ["# lumpy icosphere, level %d: %d vertices, %d triangles (scripts/peer_bench.py)" % (level, len(xs),
                                                                                             len(faces))]
    for x, y, z in zip(xs, ys, zs):
        r = 1.0 + 0.10 * sin(5 * x + 1) * sin(4 * y + 2) * sin(6 * z) + 0.03 * sin(17 * x) * sin(13 * y + z)
        lines.append("v %.6f %.6f %.6f" % (x * r, y * r, z * r))
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    return pc.write_lines(path, lines)


def uv_sphere(path, rings=501, segments=1000):
    """The unit UV sphere of issue 19's Embree table (perf_common.uv_sphere_mesh, 1 000 000
    triangles by default), as OBJ."""
    if os.path.exists(path):
        return path
    v, t = pc.uv_sphere_mesh(rings, segments)
    lines = ["# UV sphere, %d rings x %d segments: %d triangles (scripts/peer_bench.py)" % (rings, segments, len(t)),
             "v 0 1 0"]
    lines += ["v %.7f %.7f %.7f" % tuple(p) for p in v[1:-1].tolist()]
    lines.append("v 0 -1 0")
    lines += ["f %d %d %d" % tuple(f) for f in (t + 1).tolist()]
    return pc.write_lines(path, lines)


def embree_meshes(dry_run, names=tuple(EMBREE_MESHES)):
    """The meshes of the Embree table (docs/performance.md, "Ray traversal, Embree against
    streamrt") among `names`, made when missing: the bunny, the bunny split three times (235k
    triangles: the issue's ~200k-triangle scanned mesh), the 1M-triangle UV sphere and the 1.3M
    lumpy icosphere (its 1M-triangle meshes)."""
    bunny, split3, sphere, lumpy = (os.path.join(ASSETS, EMBREE_MESHES[n]) for n in EMBREE_MESHES)
    if not dry_run:
        if "bunny235k" in names and os.path.exists(bunny) and not os.path.exists(split3):
            import fetch_bunny
            fetch_bunny.main(["--split", "3"])
        if "sphere1m" in names:
            uv_sphere(sphere)
        if "lumpy" in names:
            lumpy_icosphere(lumpy)
    return [os.path.join(ASSETS, EMBREE_MESHES[n]) for n in names if os.path.exists(os.path.join(ASSETS, EMBREE_MESHES[n]))]


def ensure_assets(names, dry_run):
    """Makes the meshes the chosen scenes need; returns {scene: reason} for those to skip."""
    skip = {}
    if "bunny" in names and not os.path.exists(os.path.join(ASSETS, "bunny.ply")):
        if dry_run:
            skip["bunny"] = "perf/assets/bunny.ply is not there (scripts/fetch_bunny.py writes it)"
        else:
            import fetch_bunny
            if fetch_bunny.main([]) != 0:
                skip["bunny"] = "no bunny mesh (scripts/fetch_bunny.py could not fetch it: see above)"
    if "bunny235k" in names and not os.path.exists(os.path.join(ASSETS, "bunny_split3.ply")):
        if dry_run:
            skip["bunny235k"] = "perf/assets/bunny_split3.ply is not there (scripts/fetch_bunny.py --split 3 writes it)"
        else:
            import fetch_bunny
            if fetch_bunny.main(["--split", "3"]) != 0:
                skip["bunny235k"] = "no bunny mesh (scripts/fetch_bunny.py could not fetch it: see above)"
    lumpy = os.path.join(ASSETS, "lumpy_icosphere.obj")
    if "million" in names and not os.path.exists(lumpy):
        if dry_run:
            skip["million"] = "perf/assets/lumpy_icosphere.obj is not there (made on a real run)"
        else:
            t0 = time.time()
            lumpy_icosphere(lumpy)
            print("wrote %s in %.0f s" % (os.path.relpath(lumpy, pc.ROOT), time.time() - t0), flush=True)
    return skip


# ---- reading the .cfg subset the peer scenes use ----------------------------------------------

class Unsupported(ValueError):
    pass


def vec(s):
    v = [float(x) for x in s.split(",")]
    if len(v) != 3:
        raise ValueError("expected x,y,z: %r" % s)
    return v


def mat_mul(a, b):
    """3x4 affine matrices (rows of [r0 r1 r2 t]) composed: a after b."""
    out = []
    for i in range(3):
        row = [sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)]
        row.append(sum(a[i][k] * b[k][3] for k in range(3)) + a[i][3])
        out.append(row)
    return out


IDENTITY = [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0]]


def transform_of(key, value):
    if key == "scale":
        s = [float(x) for x in value.split(",")]
        s = s * 3 if len(s) == 1 else s
        return [[s[0], 0, 0, 0], [0, s[1], 0, 0], [0, 0, s[2], 0]]
    if key == "translate":
        t = vec(value)
        return [[1.0, 0, 0, t[0]], [0, 1.0, 0, t[1]], [0, 0, 1.0, t[2]]]
    a = math.radians(float(value))
    c, s = math.cos(a), math.sin(a)
    if key == "rotate_x":
        return [[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0]]
    if key == "rotate_y":
        return [[c, 0, s, 0], [0, 1.0, 0, 0], [-s, 0, c, 0]]
    return [[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1.0, 0]]


DEFAULT_MATERIAL = dict(color=[1.0, 1.0, 1.0], ambi=1.0, diff=1.0, spec=0.0, shininess=32.0, refl=0.0, trans=0.0,
                        ior=1.0, checker=None, cell=1.0)
MATERIAL_KEYS = set(DEFAULT_MATERIAL) | {"fresnel", "texture", "uvscale"}
TRANSFORM_KEYS = {"scale", "rotate_x", "rotate_y", "rotate_z", "translate"}


SHAPES = ("sphere", "plane", "cube", "cylinder", "cone", "torus")  # canonical shapes POV-Ray has as primitives
CSG_OPS = ("union", "intersection", "difference", "merge")


def read_cfg(path, flat=False):
    """The scene as a dict (image, ambient, background, camera, lights, objects) for the
    statements the peer scenes use; anything else raises Unsupported (file:line). `csg` blocks
    become objects of kind "csg" (op, children, md) whose leaves carry their resolved material;
    flat: a degree-0 picture is wanted, so material keys other than the colours are ignored."""
    scene = dict(image=dict(width=640, height=480, spp=1, depth=5, degree=5, cutoff=0.001), ambient=0.1,
                 background=[0.0, 0.0, 0.0], camera=dict(eye=[0.0, 0.0, 5.0], look=[0.0, 0.0, 0.0],
                                                          up=[0.0, 1.0, 0.0], fov=45.0),
                 lights=[], objects=[])
    materials = {}
    blocks = []  # the open csg blocks, outermost first
    base = os.path.dirname(os.path.abspath(path))
    with open(path) as f:
        for n, raw in enumerate(f, 1):
            words = raw.split("#", 1)[0].split()
            if not words:
                continue
            where = "%s:%d" % (path, n)
            stmt, rest = words[0], words[1:]
            if stmt == "ambient":
                scene["ambient"] = float(rest[0])
                continue
            if stmt == "background":
                scene["background"] = vec(rest[0])
                continue
            if stmt == "end":
                if not blocks:
                    raise Unsupported("%s: end with no csg block" % where)
                node = blocks.pop()
                (blocks[-1]["children"] if blocks else scene["objects"]).append(node)
                continue
            name = None
            if stmt in ("material", "csg"):
                if not rest:
                    raise Unsupported("%s: %s without a name" % (where, stmt))
                name, rest = rest[0], rest[1:]
            kv = []
            for w in rest:
                if "=" not in w:
                    if stmt == "light" and not kv:
                        kv.append(("kind", w))
                        continue
                    raise Unsupported("%s: %r is not key=value" % (where, w))
                k, v = w.split("=", 1)
                kv.append((k, v))
            if stmt == "image":
                for k, v in kv:
                    if k in ("width", "height", "spp", "depth", "degree"):
                        scene["image"][k] = int(float(v))
                    elif k == "cutoff":
                        scene["image"][k] = float(v)
                    elif k not in ("output", "sampler", "calibration", "colorspace"):
                        raise Unsupported("%s: image %s= is not translated" % (where, k))
            elif stmt == "camera":
                for k, v in kv:
                    if k in ("eye", "look", "up"):
                        scene["camera"][k] = vec(v)
                    elif k == "fov":
                        scene["camera"][k] = float(v)
                    else:
                        raise Unsupported("%s: camera %s= is not translated (look-at form only)" % (where, k))
            elif stmt == "light":
                d = dict(kv)
                if d.get("kind") != "point" or set(d) - {"kind", "pos", "color", "name"}:
                    raise Unsupported("%s: only point lights without falloff are translated" % where)
                scene["lights"].append(dict(pos=vec(d["pos"]), color=vec(d.get("color", "1,1,1"))))
            elif stmt in ("material", "mesh", "csg") + SHAPES:
                d = dict(kv)
                # a shape in a block starts from the block's appearance (docs/scene-format.md, "CSG")
                inherited = blocks[-1]["material"] if blocks else DEFAULT_MATERIAL
                mat = dict(materials[d["material"]] if "material" in d else inherited)
                md = IDENTITY
                obj = dict(kind=stmt, smooth=False)
                for k, v in kv:
                    if k in TRANSFORM_KEYS:
                        md = mat_mul(transform_of(k, v), md)
                    elif flat and k not in ("color", "checker", "cell", "material", "file", "smooth", "minor"):
                        continue
                    elif k in ("fresnel", "texture", "uvscale"):
                        if k != "fresnel" or v != "false":
                            raise Unsupported("%s: %s= is not translated" % (where, k))
                    elif k in ("color", "checker"):
                        mat[k] = vec(v)
                    elif k in DEFAULT_MATERIAL:
                        mat[k] = float(v)
                    elif k == "file" and stmt == "mesh":
                        obj["file"] = os.path.normpath(os.path.join(base, v))
                    elif k == "smooth" and stmt == "mesh":
                        obj["smooth"] = v == "true"
                    elif k == "minor" and stmt == "torus":
                        obj["minor"] = float(v)
                    elif k not in ("material", "name"):
                        raise Unsupported("%s: %s %s= is not translated" % (where, stmt, k))
                if stmt == "material":
                    materials[name] = mat
                    continue
                obj.update(material=mat, md=md)
                if stmt == "csg":
                    if name not in CSG_OPS:
                        raise Unsupported("%s: csg %s is not an operation" % (where, name))
                    obj.update(op=name, children=[])
                    blocks.append(obj)
                elif blocks:
                    blocks[-1]["children"].append(obj)
                else:
                    scene["objects"].append(obj)
            else:
                raise Unsupported("%s: statement %r is not translated" % (where, stmt))
    if blocks:
        raise Unsupported("%s: a csg block has no end" % path)
    if scene["image"]["degree"] != 5 and not flat:
        raise Unsupported("%s: only degree 5 is translated" % path)
    return scene


# ---- meshes for POV-Ray -----------------------------------------------------------------------

PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h", "ushort": "H",
             "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I", "float": "f", "float32": "f",
             "double": "d", "float64": "d"}


def read_ply(path):
    """(positions, triangles) of a binary little-endian or ASCII PLY file (vertex x y z, face
    vertex_indices lists, polygons fan-cut), enough for the files fetch_bunny.py writes."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    elements, fmt = [], None
    for line in data[:end].decode("ascii").splitlines():
        w = line.split()
        if w and w[0] == "format":
            fmt = w[1]
        elif w and w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w and w[0] == "property":
            elements[-1][2].append(w[1:])
    pos, tris = [], []
    if fmt == "ascii":
        toks, i = data[end:].split(), 0
        for name, count, props in elements:
            for _ in range(count):
                vals = {}
                for p in props:
                    if p[0] == "list":
                        k = int(toks[i])
                        vals[p[3]] = [int(x) for x in toks[i + 1:i + 1 + k]]
                        i += 1 + k
                    else:
                        vals[p[1]] = float(toks[i])
                        i += 1
                if name == "vertex":
                    pos.append((vals["x"], vals["y"], vals["z"]))
                elif name == "face":
                    ids = vals.get("vertex_indices", vals.get("vertex_index"))
                    tris += [(ids[0], ids[j], ids[j + 1]) for j in range(1, len(ids) - 1)]
        return pos, tris
    if fmt != "binary_little_endian":
        raise Unsupported("%s: PLY format %s is not read here" % (path, fmt))
    off = end
    for name, count, props in elements:
        fixed = all(p[0] != "list" for p in props)
        if fixed:
            st = struct.Struct("<" + "".join(PLY_TYPES[p[0]] for p in props))
            names = [p[1] for p in props]
            ix, iy, iz = (names.index(c) if c in names else None for c in "xyz")
            for vals in st.iter_unpack(data[off:off + st.size * count]):
                if name == "vertex":
                    pos.append((vals[ix], vals[iy], vals[iz]))
            off += st.size * count
            continue
        for _ in range(count):
            for p in props:
                if p[0] == "list":
                    cs, vs = struct.Struct("<" + PLY_TYPES[p[1]]), PLY_TYPES[p[2]]
                    k = cs.unpack_from(data, off)[0]
                    off += cs.size
                    ids = struct.unpack_from("<%d%s" % (k, vs), data, off)
                    off += struct.calcsize("<%d%s" % (k, vs))
                    if name == "face" and p[3] in ("vertex_indices", "vertex_index"):
                        tris += [(ids[0], ids[j], ids[j + 1]) for j in range(1, len(ids) - 1)]
                else:
                    off += struct.calcsize("<" + PLY_TYPES[p[0]])
    return pos, tris


def read_obj(path):
    """(positions, triangles) of an OBJ file's v and f lines (polygons fan-cut)."""
    pos, tris = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                w = line.split()
                pos.append((float(w[1]), float(w[2]), float(w[3])))
            elif line.startswith("f "):
                ids = []
                for w in line.split()[1:]:
                    i = int(w.split("/", 1)[0])
                    ids.append(i - 1 if i > 0 else len(pos) + i)
                tris += [(ids[0], ids[j], ids[j + 1]) for j in range(1, len(ids) - 1)]
    return pos, tris


def write_mesh2(name, path, out, smooth):
    """`#declare name = mesh2 {...}` with z mirrored, and the area-weighted vertex normals
    streamrt computes for smooth=true (the triangles' cross products summed per vertex)."""
    pos, tris = read_ply(path) if path.lower().endswith(".ply") else read_obj(path)
    keep = []
    normals = [[0.0, 0.0, 0.0] for _ in pos] if smooth else None
    for a, b, c in tris:
        if a == b or b == c or a == c:
            continue
        pa, pb, pc_ = pos[a], pos[b], pos[c]
        ux, uy, uz = pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]
        vx, vy, vz = pc_[0] - pa[0], pc_[1] - pa[1], pc_[2] - pa[2]
        nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        if nx == 0 and ny == 0 and nz == 0:
            continue
        keep.append((a, b, c))
        if smooth:
            for i in (a, b, c):
                n = normals[i]
                n[0] += nx
                n[1] += ny
                n[2] += nz
    parts = ["#declare %s = mesh2 {\n  vertex_vectors { %d,\n" % (name, len(pos))]
    parts.append(",\n".join("<%.7g,%.7g,%.7g>" % (x, y, -z) for x, y, z in pos))
    parts.append("\n  }\n")
    if smooth:
        parts.append("  normal_vectors { %d,\n" % len(pos))
        rows = []
        for nx, ny, nz in normals:
            ln = math.sqrt(nx * nx + ny * ny + nz * nz) or 1.0
            rows.append("<%.6g,%.6g,%.6g>" % (nx / ln, ny / ln, -nz / ln))
        parts.append(",\n".join(rows))
        parts.append("\n  }\n")
    parts.append("  face_indices { %d,\n" % len(keep))
    parts.append(",\n".join("<%d,%d,%d>" % t for t in keep))
    # inside_vector: POV-Ray's meshes have an inside (for CSG) only with it
    parts.append("\n  }\n  inside_vector <0, 0, 1>\n}\n")
    out.write("".join(parts))
    return len(keep)


# ---- POV-Ray scene ----------------------------------------------------------------------------

def f3(v, flip=True):
    return "<%.9g,%.9g,%.9g>" % (v[0], v[1], -v[2] if flip else v[2])


def pov_matrix(md):
    """POV-Ray's `matrix` (row vectors, translation last) of F md F, F = diag(1, 1, -1)."""
    flip = [1, 1, -1]
    a = [[md[i][j] * flip[i] * flip[j] for j in range(3)] for i in range(3)]
    t = [md[i][3] * flip[i] for i in range(3)]
    vals = [a[j][i] for i in range(3) for j in range(3)] + t
    return "matrix <%s>" % ",".join("%.9g" % v for v in vals)


def pov_texture(m, ambient, flat=False):
    c = m["color"]
    t = 0.0 if flat else m["trans"]
    if m["checker"] is None:
        pig = "rgbt <%.6g,%.6g,%.6g,%.6g>" % (c[0], c[1], c[2], t) if t > 0 else "rgb <%.6g,%.6g,%.6g>" % tuple(c)
        pigment = "pigment { %s }" % pig
    else:
        k = m["checker"]
        h = m["cell"] / 2
        # streamrt: color where floor(p/cell + 1/2) summed over x, y, z is even (cells centred
        # on multiples of cell); POV-Ray's checker: colour 1 where floor(q) summed is even, q
        # the point before `scale cell translate -cell/2`.
        pigment = ("pigment { checker rgbt <%.6g,%.6g,%.6g,%.6g>, rgbt <%.6g,%.6g,%.6g,%.6g> scale %.9g "
                   "translate <%.9g,%.9g,%.9g> }" % (c[0], c[1], c[2], t, k[0], k[1], k[2], t, m["cell"], -h, -h, -h))
    # POV-Ray scales a surface's ambient and diffuse terms by its opacity, 1 - transmit
    # (measured: a sphere of transmit 0.9 shows a tenth of its diffuse term; its phong and
    # reflection are not scaled), streamrt does not: divide them back.
    if flat:
        return "texture { %s finish { ambient 1 diffuse 0 } }" % pigment
    opacity = 1.0 - t if 0 < t < 1 else 1.0
    fin = ["ambient %.6g" % (ambient * m["ambi"] / opacity), "diffuse %.6g" % (m["diff"] / opacity)]
    if m["spec"] > 0:
        fin.append("phong %.6g phong_size %.6g" % (m["spec"], m["shininess"]))
    if m["refl"] > 0:
        fin.append("reflection { %.6g }" % m["refl"])
    s = "texture { %s finish { %s } }" % (pigment, " ".join(fin))
    if t > 0 and m["ior"] != 1.0:
        s += " interior { ior %.6g }" % m["ior"]
    return s


# The canonical shapes (docs/scene-format.md, "Canonical shapes") as POV-Ray primitives, less
# their closing brace; POV-Ray's cylinder and cone are closed solids, as streamrt's, and its
# plane's inside is below it, as streamrt's half-space (the torus, with its tube radius, is
# written by pov_object).
POV_PRIMITIVES = {
    "sphere": "sphere { <0,0,0>, 1",
    "plane": "plane { y, 0",
    "cube": "box { <-1,-1,-1>, <1,1,1>",
    "cylinder": "cylinder { <0,-1,0>, <0,1,0>, 1",
    "cone": "cone { <0,-1,0>, 1, <0,1,0>, 0",
}


def write_pov(scene, pov_path, width, height, adc_bailout, mesh_cache, flat=False):
    """Writes the POV-Ray scene; mesh_cache maps (file, smooth) to (include name, declared name),
    filled as meshes are written (one include per scene, reused by every mode). flat: degree 0,
    each surface its pigment alone (`finish { ambient 1 diffuse 0 }`, full ambient light)."""
    img, cam = scene["image"], scene["camera"]
    depth = img["depth"]
    hfov = 2 * math.degrees(math.atan(math.tan(math.radians(cam["fov"] / 2)) * width / height))
    glob = ["assumed_gamma 1.0", "max_trace_level %d" % (depth + 1), "ambient_light rgb <1,1,1>"]
    if adc_bailout is not None:
        glob.append("adc_bailout %.9g" % adc_bailout)
    lines = ["// Translated from %s by scripts/peer_bench.py" % os.path.relpath(scene["path"], pc.ROOT),
             "#version 3.7;",
             "global_settings { %s }" % " ".join(glob),
             "background { rgb %s }" % f3(scene["background"], False),
             "camera { perspective location %s look_at %s sky %s right x*%.9g up y angle %.9g }" % (
                 f3(cam["eye"]), f3(cam["look"]), f3(cam["up"]), width / height, hfov)]
    for li in scene["lights"]:
        lines.append("light_source { %s color rgb %s }" % (f3(li["pos"]), f3(li["color"], False)))
    includes = []

    def pov_object(o):
        if o["kind"] == "csg":
            # the leaves carry their own textures; the block's matrix applies after its children's
            return "%s { %s %s }" % (o["op"], " ".join(pov_object(c) for c in o["children"]), pov_matrix(o["md"]))
        tex = pov_texture(o["material"], scene["ambient"], flat)
        if o["kind"] == "torus":  # POV-Ray's torus is streamrt's: major radius 1 around y
            return "torus { 1, %.9g %s %s }" % (o.get("minor", 0.25), pov_matrix(o["md"]), tex)
        if o["kind"] in POV_PRIMITIVES:
            return "%s %s %s }" % (POV_PRIMITIVES[o["kind"]], pov_matrix(o["md"]), tex)
        inc, name = mesh_cache[(o["file"], o["smooth"])]
        if inc not in includes:
            includes.append(inc)
        return "object { %s %s %s }" % (name, pov_matrix(o["md"]), tex)

    lines += [pov_object(o) for o in scene["objects"]]
    lines[3:3] = ['#include "%s"' % os.path.basename(i) for i in includes]
    with open(pov_path, "w") as f:
        f.write("\n".join(lines) + "\n")


def prepare_meshes(scene, out_dir, tag):
    """Writes the include file of the scene's meshes (once); returns the mesh cache."""
    cache, todo = {}, []

    def objects(objs):  # csg blocks' children too
        for o in objs:
            yield o
            yield from objects(o.get("children", []))

    for o in objects(scene["objects"]):
        if o["kind"] == "mesh" and (o["file"], o["smooth"]) not in cache:
            name = "M_%s_%d" % (tag, len(cache))
            cache[(o["file"], o["smooth"])] = (os.path.join(out_dir, "%s_meshes.inc" % tag), name)
            todo.append((o["file"], o["smooth"], name))
    if not todo:
        return cache
    inc = os.path.join(out_dir, "%s_meshes.inc" % tag)
    stamp = "// " + repr([(os.path.relpath(f, pc.ROOT), s, os.path.getmtime(f)) for f, s, _ in todo])
    if os.path.exists(inc):
        with open(inc) as f:
            if f.readline().rstrip("\n") == stamp:
                return cache
    t0 = time.time()
    with open(inc + ".tmp", "w") as f:
        f.write(stamp + "\n")
        n = sum(write_mesh2(name, path, f, smooth) for path, smooth, name in todo)
    os.replace(inc + ".tmp", inc)
    print("wrote %s (%d triangles as mesh2) in %.0f s" % (os.path.relpath(inc, pc.ROOT), n, time.time() - t0),
          flush=True)
    return cache


# ---- running ----------------------------------------------------------------------------------

POV_TIME_RE = {k: re.compile(r"%s Time:.*\(\s*([0-9.]+) seconds\)" % k) for k in ("Parse", "Bounding", "Trace")}


def run_povray(povray, pov_path, out_ppm, width, height, threads=2):
    cmd = [povray, "+I" + os.path.basename(pov_path), "+O" + os.path.basename(out_ppm), "+FP", "+W%d" % width,
           "+H%d" % height, "-A", "-J", "+WT%d" % threads, "-D", "-P", "-V", "+GS", "+GR", "-GD", "-GW"]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=os.path.dirname(pov_path), capture_output=True, text=True)
    wall = time.perf_counter() - t0
    text = p.stdout + p.stderr
    if p.returncode != 0 or not os.path.exists(out_ppm):
        raise RuntimeError("%s failed (%d):\n%s" % (" ".join(cmd), p.returncode, text[-2000:]))
    r = {"wall": wall}
    for k, rx in POV_TIME_RE.items():
        m = rx.search(text)
        if m:
            r[k.lower()] = float(m.group(1))
    return r


def run_stream(exe, cfg, out_ppm, width, height, cutoff, engine="stream", jobs=2):
    extra = ["--cutoff", "%.9g" % cutoff] if cutoff is not None else []
    return pc.run_streamrt(exe, cfg, out_ppm, engine=engine, jobs=jobs, spp=1, width=width, height=height,
                           extra=extra)


def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    parts, pos = [], 0
    while len(parts) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":  # a comment (POV-Ray writes one) runs to the end of its line
            pos = data.index(b"\n", pos)
            continue
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        parts.append(data[start:pos])
    if parts[0] != b"P6" or parts[3] != b"255":
        raise ValueError(path + ": not an 8-bit P6 PPM")
    return int(parts[1]), int(parts[2]), data[pos + 1:]


def ppm_psnr(a_path, b_path):
    """PSNR (dB) and the share of channel values within 8/255 of two PPM files."""
    wa, ha, a = read_ppm(a_path)
    wb, hb, b = read_ppm(b_path)
    if (wa, ha) != (wb, hb):
        return None, None
    n = len(a)
    hist = [0] * 256
    for x, y in zip(a, b):
        hist[abs(x - y)] += 1
    se = sum(d * d * c for d, c in enumerate(hist))
    close = sum(hist[:9]) / n
    mse = se / n / (255.0 * 255.0)
    return (10 * math.log10(1 / mse) if mse > 0 else float("inf")), close


def side_by_side_png(left_ppm, right_ppm, png, gap=4):
    """The two PPM pictures side by side (a white gap between) as an 8-bit RGB PNG."""
    import zlib
    wl, h, a = read_ppm(left_ppm)
    wr, hr, b = read_ppm(right_ppm)
    if h != hr:
        raise ValueError("pictures of different heights")
    rows = []
    for y in range(h):
        rows.append(b"\x00" + a[3 * wl * y:3 * wl * (y + 1)] + b"\xff" * (3 * gap) + b[3 * wr * y:3 * wr * (y + 1)])

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    w = wl + gap + wr
    with open(png, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(b"".join(rows), 9)) + chunk(b"IEND", b""))



# ---- the log of runs and the table the report quotes ------------------------------------------

EMBREE_ROW_RE = re.compile(r"^(primary|shadow|mirror|glass|diffuse)\s+(\d+)\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)\s+"
                           r"([0-9.]+)x\s+([0-9.]+)")
EMBREE_MESH_RE = re.compile(r"^(\S+): (\d+) triangles;")
EMBREE_ISA_RE = re.compile(r"streamrt kernels (\w+)")


def parse_embree(text):
    """embree_rays' output as (isa, {mesh file name: {metric: value}}): per ray kind the ratio
    streamrt / Embree16 ("KIND ratio") and the three programs' Mrays/s."""
    isa, meshes, cur = None, {}, None
    for line in text.splitlines():
        m = EMBREE_ISA_RE.search(line)
        if m and isa is None:
            isa = m.group(1)
        m = EMBREE_MESH_RE.match(line)
        if m:
            cur = meshes.setdefault(os.path.basename(m.group(1)), {"triangles": int(m.group(2))})
            continue
        m = EMBREE_ROW_RE.match(line)
        if m and cur is not None:
            k = m.group(1)
            cur.update({k + " ratio": float(m.group(6)), k + " Embree16 Mrays/s": float(m.group(3)),
                        k + " Embree1 Mrays/s": float(m.group(4)), k + " streamrt Mrays/s": float(m.group(5))})
    return isa, meshes


def cpu_isa():
    """The widest vector extension the CPU reports (what streamrt's dispatch picks)."""
    try:
        flags = next((ln.split(":", 1)[1].split() for ln in open("/proc/cpuinfo") if ln.startswith("flags")), [])
    except OSError:
        flags = []
    for isa, flag in (("avx512", "avx512f"), ("avx2", "avx2"), ("sse4.2", "sse4_2")):
        if flag in flags:
            return isa
    return "sse2"


def load_now():
    return [round(x, 2) for x in os.getloadavg()]


def build_provenance(build_dir):
    """The source tree the build folder was configured from (CMakeCache.txt), its commit, and
    "-dirty" when its engine/ or perf/ sources differ from that commit: what the binaries were
    built from, as far as the tree says (the binaries' digests pin them down)."""
    source = None
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt")) as f:
            source = next((ln.split("=", 1)[1].strip() for ln in f if ln.startswith("CMAKE_HOME_DIRECTORY:")), None)
    except OSError:
        pass
    commit = "unknown"
    if source:
        try:
            commit = subprocess.run(["git", "-C", source, "rev-parse", "--short", "HEAD"], capture_output=True,
                                    text=True, check=True).stdout.strip()
            dirty = subprocess.run(["git", "-C", source, "status", "--porcelain", "--untracked-files=no", "--",
                                    "engine", "perf"], capture_output=True, text=True, check=True).stdout.strip()
            commit += "-dirty" if dirty else ""
        except (OSError, subprocess.CalledProcessError):
            pass
    return {"build": os.path.abspath(build_dir), "source": source, "commit": commit}


def binary_digests(paths):
    """sha256 (first 12 hex digits) of each program that runs, by name: a build that changes
    under a run shows as a different digest at its end."""
    import hashlib
    out = {}
    for p in paths:
        if p and os.path.exists(p):
            with open(p, "rb") as f:
                out[os.path.basename(p)] = hashlib.sha256(f.read()).hexdigest()[:12]
    return out


def log_entry(meta, bench, scene, metrics, load_before, **extra):
    e = {"bench": bench, "scene": scene, "date": meta["utc"], "host": meta["host"], "cpu": meta["cpu"],
         "cores": meta["cores"], "isa": meta["isa"], "load": load_before, "load_after": load_now(),
         "commit": meta["build_commit"], "build": meta["build"], "binaries": meta["binaries"],
         "scripts_commit": meta["revision"], "command": meta["command"], "size": meta["size"], "runs": meta["runs"]}
    e.update(extra)
    e["metrics"] = {k: (round(v, 4) if isinstance(v, float) else v) for k, v in metrics.items()}
    return e


def append_log(path, entries):
    if not entries:
        return
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "a") as f:
        for e in entries:
            f.write(json.dumps(e, sort_keys=True) + "\n")
    print("appended %d entries to %s" % (len(entries), os.path.relpath(path, pc.ROOT)))


BENCH_ORDER = {"povray": 0, "engines": 1, "embree": 2}
BENCH_TITLE = {"povray": "POV-Ray 3.7 wall time / streamrt wall time, whole process, +WT2 / -j2",
               "engines": "streamrt's recursive engine / its stream engine, whole process and render phase, -j2",
               "embree": "streamrt's packet kernel / Embree 3's rtcIntersect16 (rtcOccluded16: shadow), Mrays/s, one thread"}


def read_log(path):
    entries = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if line:
                try:
                    entries.append(json.loads(line))
                except ValueError as e:
                    raise SystemExit("%s:%d: not JSON (%s)" % (path, n, e))
    return entries


METRIC_ORDER = ["ratio default", "ratio nopruning", "ratio matched", "render ratio default", "render ratio nopruning",
                "render ratio matched", "whole ratio", "render ratio", "primary ratio", "shadow ratio", "mirror ratio",
                "glass ratio", "diffuse ratio"]
SCENE_ORDER = ["bunny", "bunny235k", "million", "whitted", "random_spheres", "sphere1m", "lumpy"]


def _order(xs, order):
    return sorted(xs, key=lambda x: (order.index(x) if x in order else len(order), x))


def table(entries, metric_filter=None):
    """The Markdown tables of the log, one per benchmark: a row per scene with the runs logged,
    their days, loads and ISAs, and per ratio the lowest value (the headline, bold) with the
    range over the runs (its spread) in brackets; "n=K" where only K of the row's runs have it."""
    by_bench = {}
    for e in entries:
        row = by_bench.setdefault(e["bench"], {}).setdefault(e["scene"], {"entries": [], "metrics": {}})
        row["entries"].append(e)
        for k, v in e["metrics"].items():
            if "ratio" not in k.split() or not isinstance(v, (int, float)) or v != v:
                continue
            if metric_filter and k not in metric_filter:
                continue
            row["metrics"].setdefault(k, []).append(v)
    lines = []
    for bench in _order(by_bench, list(BENCH_ORDER)):
        rows = by_bench[bench]
        metrics = _order({k for r in rows.values() for k in r["metrics"]}, METRIC_ORDER)
        if not metrics:
            continue
        if lines:
            lines.append("")
        lines += ["%s:" % BENCH_TITLE.get(bench, bench), "",
                  "| scene | runs | days | load (1 min) | ISA | " + " | ".join(metrics) + " |",
                  "|---|---|---|---|---|" + "---|" * len(metrics)]
        for scene in _order(rows, SCENE_ORDER):
            r = rows[scene]
            es = r["entries"]
            days = sorted({e["date"][:10] for e in es})
            loads = [e["load"][0] for e in es if e.get("load")]
            cells = []
            for k in metrics:
                vs = r["metrics"].get(k)
                if not vs:
                    cells.append("-")
                    continue
                lo, hi = min(vs), max(vs)
                cells.append("**%.2fx** (%.2f - %.2f%s)" % (lo, lo, hi, "" if len(vs) == len(es) else ", n=%d" % len(vs)))
            lines.append("| %s | %d | %d (%s) | %s | %s | %s |" % (
                scene, len(es), len(days), ", ".join(days),
                ("%.1f - %.1f" % (min(loads), max(loads))) if loads else "-",
                ", ".join(sorted({e.get("isa", "?") for e in es})), " | ".join(cells)))
    return "\n".join(lines)


def fmt(v, nd=3):
    return "-" if v is None else "%.*f" % (nd, v)


def edge_mask(w, h, *pictures):
    """Pixels with a 4-neighbour of another colour in any of the pictures: silhouettes and
    colour edges (checker cells), where a sample a hair's breadth away can change the colour."""
    mask = bytearray(w * h)
    for px in pictures:
        for y in range(h):
            row = 3 * w * y
            for x in range(w):
                i = row + 3 * x
                c = px[i:i + 3]
                if (x + 1 < w and px[i + 3:i + 6] != c) or (y + 1 < h and px[i + 3 * w:i + 3 * w + 3] != c):
                    mask[y * w + x] = 1
                    mask[y * w + x + (1 if x + 1 < w else 0)] = 1
                    if y + 1 < h:
                        mask[(y + 1) * w + x] = 1
    return mask


def flat_check(exe, povray, names, out_dir, width, height, engines):
    """Degree-0 pictures (each surface's own colour) of each scene by streamrt's engines and by
    POV-Ray (`finish { ambient 1 diffuse 0 }`), one sample at each pixel's centre: the count of
    pixels that differ (any channel by more than one step of 255), all of them and those off
    the edges (edge_mask). Returns the rows printed."""
    rows = []
    for s in names:
        # streamrt filters the checker over each sample's footprint (docs/scene-format.md,
        # "Checker") and POV-Ray does not: the check compares the scene without its checkers,
        # a copy whose mesh files are named by absolute paths
        base = os.path.dirname(os.path.abspath(SCENES[s]))
        with open(SCENES[s]) as f:
            text = f.read()
        text = re.sub(r"(?<=\s)checker=\S+", "", text)
        text = re.sub(r"(?<=\s)file=(\S+)", lambda m: "file=" + os.path.join(base, m.group(1)), text)
        cfg = os.path.join(out_dir, "%s_flat.cfg" % s)
        with open(cfg, "w") as f:
            f.write(text)
        sc = read_cfg(cfg, flat=True)
        sc["path"] = SCENES[s]
        pov_path = os.path.join(out_dir, "%s_flat.pov" % s)
        write_pov(sc, pov_path, width, height, None, prepare_meshes(sc, out_dir, s), flat=True)
        pov_img = os.path.join(out_dir, "%s_flat_povray.ppm" % s)
        run_povray(povray, pov_path, pov_img, width, height)
        _, _, pov_px = read_ppm(pov_img)
        for e in engines:
            img = os.path.join(out_dir, "%s_flat_%s.ppm" % (s, e))
            pc.run_streamrt(exe, cfg, img, engine=e, jobs=2, spp=1, width=width, height=height,
                            sampler="grid", extra=["--degree", "0"])
            _, _, px = read_ppm(img)
            edges = edge_mask(width, height, px, pov_px)
            differ = [max(abs(px[3 * i + c] - pov_px[3 * i + c]) for c in range(3)) > 1 for i in range(width * height)]
            row = dict(scene=s, engine=e, pixels=width * height, differ=sum(differ),
                       differ_off_edges=sum(d and not m for d, m in zip(differ, edges)), edge_pixels=sum(edges))
            rows.append(row)
            print("%-10s %-9s %7d pixels: %6d differ, %5d of them off the edges (%d edge pixels)" % (
                s, e, row["pixels"], row["differ"], row["differ_off_edges"], row["edge_pixels"]), flush=True)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(pc.ROOT, "build"), help="build folder (default build/)")
    ap.add_argument("--runs", type=int, default=3, help="timed runs per program and case (median; default 3)")
    ap.add_argument("--scenes", help="scenes to run (default bunny,bunny235k,million,whitted); with --table: "
                    "only these rows (the Embree table's are its meshes)")
    ap.add_argument("--modes", default="default,nopruning,matched")
    ap.add_argument("--size", default="1280x720", help="WxH of every picture (default 1280x720)")
    ap.add_argument("--povray", default=shutil.which("povray") or "/usr/bin/povray", help="the POV-Ray program")
    ap.add_argument("--no-engines", action="store_true", help="leave out streamrt's recursive-vs-stream table")
    ap.add_argument("--no-embree", action="store_true", help="leave out the Embree table")
    ap.add_argument("--embree-reps", type=int, default=5, help="embree_rays --reps (default 5)")
    ap.add_argument("--embree-meshes", default=",".join(EMBREE_MESHES),
                    help="meshes of the Embree table (default %s)" % ",".join(EMBREE_MESHES))
    ap.add_argument("--log", default=LOG, help="the log of runs to append to and --table from "
                    "(default perf/results/peer_runs.jsonl)")
    ap.add_argument("--no-log", action="store_true", help="append nothing to the log")
    ap.add_argument("--table", action="store_true", help="print the Markdown table of the log's runs "
                    "(lowest, range, runs, days per scene and ratio) and stop")
    ap.add_argument("--metrics", help="with --table: only these ratios, comma-separated names as in the "
                    "table's third column (e.g. 'ratio default,primary ratio')")
    ap.add_argument("--since", metavar="UTC", help="with --table: only the runs logged at or after this UTC time "
                    "(YYYY-MM-DD or YYYY-MM-DDTHH:MM; the runs of today's engine, not of one a change replaced)")
    ap.add_argument("--isa", help="with --table: only the runs on machines of these instruction sets, "
                    "comma-separated (avx2, avx512: the Embree ratios depend on the packet width)")
    ap.add_argument("--dry-run", action="store_true", help="check tools, write the .pov files, render nothing")
    ap.add_argument("--out", help="output folder (default BUILD/peer)")
    ap.add_argument("--flat", action="store_true", help="only the degree-0 check: each scene's flat colours by "
                    "both engines against POV-Ray's, the count of differing pixels on and off the edges "
                    "(docs/testing.md; ctest csg_against_povray: --flat --scenes %s --size 160x120)" % ",".join(CSG_SCENES))
    ap.add_argument("--engines", default="stream,recursive", help="with --flat: streamrt's engines checked")
    ap.add_argument("--picture", metavar="PNG", help="only write the first scene (nopruning) at --size by streamrt "
                    "(left) and POV-Ray (right) side by side into PNG, and stop (docs/img/peer_bunny.png: "
                    "--scenes bunny --size 400x225)")
    args = ap.parse_args(argv)
    if args.table:
        if not os.path.exists(args.log):
            print("no log at %s: run the benchmark first" % args.log)
            return 1
        entries = read_log(args.log)
        if args.since:
            entries = [e for e in entries if e.get("date", "") >= args.since]
        if args.scenes:
            wanted = set(args.scenes.split(","))
            entries = [e for e in entries if e.get("scene") in wanted]
        if args.isa:
            isas = set(args.isa.split(","))
            entries = [e for e in entries if e.get("isa") in isas]
        print(table(entries, [m for m in args.metrics.split(",") if m] if args.metrics else None))
        print("\n%d entries from %s; bold: the lowest over the runs (the headline), in brackets the range" % (
            len(entries), os.path.relpath(os.path.abspath(args.log), pc.ROOT)))
        return 0
    for m in args.embree_meshes.split(","):
        if m and m not in EMBREE_MESHES:
            ap.error("unknown Embree mesh %r (one of %s)" % (m, ", ".join(EMBREE_MESHES)))
    width, height = (int(x) for x in args.size.split("x"))
    names = [s for s in (args.scenes or "bunny,bunny235k,million,whitted").split(",") if s]
    modes = [m for m in args.modes.split(",") if m]
    for s in names:
        if s not in SCENES:
            ap.error("unknown scene %r (one of %s)" % (s, ", ".join(SCENES)))
    for m in modes:
        if m not in MODES:
            ap.error("unknown mode %r (one of %s)" % (m, ", ".join(MODES)))
    out_dir = os.path.abspath(args.out or os.path.join(args.build, "peer"))
    os.makedirs(out_dir, exist_ok=True)

    exe = os.path.join(args.build, "engine", "streamrt")
    have_streamrt = os.access(exe, os.X_OK)
    if not have_streamrt and not args.dry_run:
        exe = pc.binary(args.build)  # exits with the message
    povray = args.povray if args.povray and os.access(args.povray, os.X_OK) else None
    if povray is None:
        print("POV-Ray is not installed (%s; apt-get install povray): skipping the POV-Ray columns" % args.povray)
    embree_rays = os.path.join(args.build, "perf", "embree_rays")
    if args.no_embree:
        embree_rays = None
    elif not os.access(embree_rays, os.X_OK):
        print("%s is not built (CMake builds it when it finds Embree 3: apt-get install libembree-dev): "
              "skipping the Embree table" % os.path.relpath(embree_rays, pc.ROOT))
        embree_rays = None

    skip = ensure_assets(names, args.dry_run)
    for s, why in skip.items():
        print("skipping scene %s: %s" % (s, why))
    names = [s for s in names if s not in skip]

    if args.flat:
        if not povray:
            print("no degree-0 check: it needs POV-Ray (apt-get install povray)")
            return 77  # ctest's skip (tests/CMakeLists.txt, csg_against_povray)
        if args.dry_run:
            print("dry run: nothing rendered")
            return 0
        rows = flat_check(exe, povray, names, out_dir, width, height, [e for e in args.engines.split(",") if e])
        with open(os.path.join(out_dir, "flat.json"), "w") as f:
            json.dump(rows, f, indent=1)
        return 1 if any(r["differ_off_edges"] for r in rows) else 0
    scenes = {}
    for s in list(names):
        try:
            sc = read_cfg(SCENES[s])
        except Unsupported as e:
            print("skipping scene %s: %s" % (s, e))
            names.remove(s)
            continue
        sc["path"] = SCENES[s]
        scenes[s] = sc
        if povray or args.dry_run:
            cache = prepare_meshes(sc, out_dir, s)
            for m in modes:
                write_pov(sc, os.path.join(out_dir, "%s_%s.pov" % (s, m)), width, height, MODES[m][0], cache)
    if args.picture and not (povray and names):
        print("no picture: it needs POV-Ray and a scene whose mesh is there")
        return 0
    if args.picture:
        s = names[0]
        pov_path = os.path.join(out_dir, "%s_%s.pov" % (s, modes[0] if "nopruning" not in modes else "nopruning"))
        pov_img, srt_img = os.path.join(out_dir, "picture_povray.ppm"), os.path.join(out_dir, "picture_streamrt.ppm")
        run_povray(povray, pov_path, pov_img, width, height)
        run_stream(exe, SCENES[s], srt_img, width, height, 0.0)
        side_by_side_png(srt_img, pov_img, args.picture)
        print("wrote %s: streamrt (left), POV-Ray (right); PSNR %.1f dB" % (args.picture, ppm_psnr(pov_img, srt_img)[0]))
        return 0
    if args.dry_run:
        print("dry run: wrote %s; streamrt %s, POV-Ray %s, embree_rays %s; nothing rendered" % (
            ", ".join(os.path.relpath(os.path.join(out_dir, "%s_%s.pov" % (s, m)), pc.ROOT) for s in names
                      for m in modes) or "no .pov file",
            "found" if have_streamrt else "not built", "found" if povray else "skipped",
            "found" if embree_rays else "skipped"))
        return 0

    meta = pc.machine_info()
    meta.update(runs=args.runs, size=args.size, command=" ".join(["scripts/peer_bench.py"] + (argv or sys.argv[1:])),
                load_before=os.getloadavg()[0], utc=time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()),
                host=platform.node(), isa=cpu_isa())
    prov = build_provenance(args.build)
    meta.update(build_commit=prov["commit"], build=prov["build"], binaries=binary_digests([exe, embree_rays]))
    if prov["commit"].endswith("-dirty") or prov["commit"] == "unknown":
        print("warning: the build's source tree %s is at %s: the figures are of uncommitted code" % (
            prov["source"], prov["commit"]))
    log = []
    if povray:
        v = subprocess.run([povray, "--version"], capture_output=True, text=True)
        meta["povray"] = next((ln.strip() for ln in (v.stdout + v.stderr).splitlines() if ln.startswith("POV-Ray")),
                              "POV-Ray ?")
    rows, engine_rows = [], []
    t_start = time.time()
    for s in names:
        cfg = SCENES[s]
        scene_load, pov_metrics = load_now(), {}
        for m in modes:
            adc, cutoff = MODES[m]
            pov_path = os.path.join(out_dir, "%s_%s.pov" % (s, m))
            pov_img, srt_img = os.path.join(out_dir, "%s_%s_povray.ppm" % (s, m)), os.path.join(
                out_dir, "%s_%s_streamrt.ppm" % (s, m))
            # one untimed run of each: files in the page cache, the program's pages loaded
            if povray:
                run_povray(povray, pov_path, pov_img, width, height)
            run_stream(exe, cfg, srt_img, width, height, cutoff)
            pov_runs, srt_runs = [], []
            for _ in range(args.runs):
                if povray:
                    pov_runs.append(run_povray(povray, pov_path, pov_img, width, height))
                srt_runs.append(run_stream(exe, cfg, srt_img, width, height, cutoff))
            row = dict(scene=s, mode=m, streamrt=pc.median([r["wall"] for r in srt_runs]),
                       streamrt_runs=[r["wall"] for r in srt_runs],
                       streamrt_render=pc.median([r["seconds"] for r in srt_runs]), rays=srt_runs[0]["rays"])
            if povray:
                row.update(povray=pc.median([r["wall"] for r in pov_runs]), povray_runs=[r["wall"] for r in pov_runs],
                           povray_parse=pc.median([r.get("parse", 0.0) + r.get("bounding", 0.0) for r in pov_runs]),
                           povray_trace=pc.median([r.get("trace", float("nan")) for r in pov_runs]))
                row["ratio"] = row["povray"] / row["streamrt"]
                row["render_ratio"] = row["povray_trace"] / row["streamrt_render"]
                row["psnr"], row["close"] = ppm_psnr(pov_img, srt_img)
            rows.append(row)
            pov_metrics.update({"streamrt s " + m: row["streamrt"], "streamrt render s " + m: row["streamrt_render"]})
            if povray:
                pov_metrics.update({"ratio " + m: row["ratio"], "render ratio " + m: row["render_ratio"],
                                    "povray s " + m: row["povray"], "povray trace s " + m: row["povray_trace"],
                                    "psnr dB " + m: row["psnr"]})
            print("[%4.0fs] %-8s %-10s POV-Ray %s s (parse %s, trace %s)  streamrt %.3f s (render %.3f)  ratio %s"
                  "  PSNR %s dB" % (time.time() - t_start, s, m, fmt(row.get("povray")), fmt(row.get("povray_parse")),
                                     fmt(row.get("povray_trace")), row["streamrt"], row["streamrt_render"],
                                     fmt(row.get("ratio"), 2), fmt(row.get("psnr"), 1)), flush=True)
        if povray and pov_metrics:
            log.append(log_entry(meta, "povray", s, pov_metrics, scene_load, povray=meta.get("povray")))
        if not args.no_engines:
            scene_load = load_now()
            img = os.path.join(out_dir, "%s_engine.ppm" % s)
            times = {"stream": [], "recursive": []}
            for e in times:
                run_stream(exe, cfg, img, width, height, None, engine=e)
            for _ in range(args.runs):
                for e in times:
                    times[e].append(run_stream(exe, cfg, img, width, height, None, engine=e))
            er = dict(scene=s, **{e: pc.median([r["wall"] for r in rs]) for e, rs in times.items()},
                      **{e + "_render": pc.median([r["seconds"] for r in rs]) for e, rs in times.items()})
            er["ratio"] = er["recursive"] / er["stream"]
            engine_rows.append(er)
            log.append(log_entry(meta, "engines", s, {
                "whole ratio": er["ratio"], "render ratio": er["recursive_render"] / er["stream_render"],
                "stream s": er["stream"], "recursive s": er["recursive"]}, scene_load))
            print("[%4.0fs] %-8s engines: recursive %.3f s (render %.3f), stream %.3f s (render %.3f), %.2fx" % (
                time.time() - t_start, s, er["recursive"], er["recursive_render"], er["stream"], er["stream_render"],
                er["ratio"]), flush=True)

    embree_text = None
    if embree_rays:
        meshes = embree_meshes(False, [m for m in args.embree_meshes.split(",") if m])
        for mesh in meshes:  # one mesh a process: each its own load average in the log
            scene_load = load_now()
            p = subprocess.run([embree_rays, "--reps", str(args.embree_reps), mesh], capture_output=True, text=True)
            text = p.stdout.strip()
            if p.returncode != 0:
                text += "\n(embree_rays failed: %s)" % p.stderr.strip()
            embree_text = text if embree_text is None else embree_text + "\n\n" + text.split("\n\n", 1)[-1]
            isa, parsed = parse_embree(text)
            for name, metrics in parsed.items():
                scene = next((k for k, f in EMBREE_MESHES.items() if f == name), name)
                log.append(log_entry(meta, "embree", scene, metrics, scene_load, kernels=isa,
                                     reps=args.embree_reps))
            print("[%4.0fs] embree_rays %s: %s" % (time.time() - t_start, os.path.basename(mesh), ", ".join(
                "%s %.2fx" % (k.split()[0], v) for m in parsed.values() for k, v in m.items() if k.endswith("ratio"))),
                flush=True)

    meta["load_after"] = os.getloadavg()[0]
    meta["seconds"] = time.time() - t_start
    md = ["# streamrt against POV-Ray and Embree", "",
          "%s, %s cores, %s, revision %s, load average %.1f -> %.1f; %s; %s, 1 spp; whole-process wall time, median "
          "of %d runs; `%s`" % (meta["cpu"], meta["cores"], meta["date"], meta["revision"], meta["load_before"],
                                meta["load_after"], meta.get("povray", "no POV-Ray"), args.size, args.runs,
                                meta["command"]), "",
          "| scene | mode | POV-Ray s | streamrt s | ratio | POV-Ray parse s | POV-Ray trace s | streamrt render s "
          "| render ratio | PSNR dB | within 8/255 |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        md.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["scene"], r["mode"], fmt(r.get("povray")), fmt(r["streamrt"]), fmt(r.get("ratio"), 2) + (
                "x" if r.get("ratio") else ""), fmt(r.get("povray_parse")), fmt(r.get("povray_trace")),
            fmt(r["streamrt_render"]), fmt(r.get("render_ratio"), 2) + ("x" if r.get("render_ratio") else ""),
            fmt(r.get("psnr"), 1),
            "%.1f %%" % (100 * r["close"]) if r.get("close") is not None else "-"))
    md += ["", "ratio: POV-Ray wall / streamrt wall (above 1: streamrt is faster). render ratio: POV-Ray's trace "
           "time / streamrt's render phase (reading, parsing, set-up and writing left out). PSNR: POV-Ray's picture "
           "against streamrt's (8-bit sRGB)."]
    if engine_rows:
        md += ["", "| scene | recursive s | stream s | recursive / stream | recursive render s | stream render s |",
               "|---|---|---|---|---|---|"]
        for r in engine_rows:
            md.append("| %s | %.3f | %.3f | %.2fx | %.3f | %.3f |" % (r["scene"], r["recursive"], r["stream"],
                                                                    r["ratio"], r["recursive_render"],
                                                                    r["stream_render"]))
    if embree_text:
        md += ["", "```", embree_text, "```"]
    text = "\n".join(md) + "\n"
    with open(os.path.join(out_dir, "results.md"), "w") as f:
        f.write(text)
    with open(os.path.join(out_dir, "results.json"), "w") as f:
        json.dump({"meta": meta, "rows": rows, "engines": engine_rows, "embree": embree_text}, f, indent=1)
    print()
    print(text)
    print("wrote %s/results.{json,md}" % os.path.relpath(out_dir, pc.ROOT))
    if binary_digests([exe, embree_rays]) != meta["binaries"]:
        print("warning: %s changed during the run (rebuilt?): its entries are marked binaries_changed" % args.build)
        for e in log:
            e["binaries_changed"] = True
    if not args.no_log:
        append_log(args.log, log)
    return 0


if __name__ == "__main__":
    sys.exit(main())
