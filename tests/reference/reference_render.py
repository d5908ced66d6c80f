#!/usr/bin/env python3
"""Independent reference renderer for streamrt scenes (float64, NumPy).

Written from the course handout (TD Infographie n°4) and docs/scene-format.md only: it
shares no code with engine/ so that a mistake in the engines' shared shape math, shading,
camera or samplers shows up as a difference. Meshes and spp > 1 are not supported.

Usage: reference_render.py SCENE.cfg -o OUT.pfm [--width W --height H --degree D --depth N]
"""
import argparse
import math
import os
import re
import sys

import numpy as np


class SceneError(Exception):
    pass


# ----------------------------------------------------------------------------- parsing
def _num(text):
    v = float(text)
    if not math.isfinite(v):
        raise SceneError(f"bad number {text!r}")
    return v


def _vec(text):
    parts = text.split(",")
    if len(parts) != 3:
        raise SceneError(f"expected x,y,z, got {text!r}")
    return np.array([_num(p) for p in parts])


def _rot(axis, deg):
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    m = np.eye(4)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    # Right-handed: rotate_z=90 maps +x to +y, rotate_x=90 maps +y to +z, rotate_y=90 +z to +x.
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _transform_step(key, val):
    m = np.eye(4)
    if key == "scale":
        s = _vec(val) if "," in val else np.full(3, _num(val))
        m[0, 0], m[1, 1], m[2, 2] = s
    elif key == "translate":
        m[:3, 3] = _vec(val)
    else:
        m = _rot(key[-1], _num(val))
    return m


TRANSFORM_KEYS = ("scale", "rotate_x", "rotate_y", "rotate_z", "translate")
MATERIAL_DEFAULT = dict(color=np.ones(3), ambi=1.0, diff=1.0, spec=0.0, shininess=32.0,
                        refl=0.0, trans=0.0, ior=1.0, checker=None, cell=1.0, fresnel=False,
                        emission=np.zeros(3))
SHAPES = ("sphere", "cube", "cylinder", "cone", "torus", "plane", "disk")


def _kv(args):
    out = []
    for a in args:
        if "=" not in a:
            raise SceneError(f"token without '=': {a!r}")
        k, v = a.split("=", 1)
        out.append((k, v))
    return out


def _material_keys(mat, pairs):
    for k, v in pairs:
        if k in ("color", "checker", "emission"):
            mat[k] = _vec(v)
        elif k == "fresnel":
            if v not in ("true", "false"):
                raise SceneError(f"fresnel must be true or false, got {v!r}")
            mat[k] = v == "true"
        elif k in MATERIAL_DEFAULT:
            mat[k] = _num(v)


class Scene:
    def __init__(self):
        self.image = dict(width=640, height=480, spp=1, depth=5, degree=5)
        self.ambient = 0.1
        self.background = np.zeros(3)
        self.camera = ("lookat", dict(eye=np.array([0, 0, 5.0]), look=np.zeros(3),
                                      up=np.array([0, 1.0, 0]), fov=45.0))
        self.lights = []      # dicts: kind, pos, dir, cos_angle, color
        self.materials = {}
        self.objects = []     # dicts: shape, Md, Mi, Mn, mat, minor


def parse_scene(path, scene=None, depth=0):
    scene = scene or Scene()
    if depth > 32:
        raise SceneError("include nesting too deep")
    with open(path, encoding="utf-8-sig") as f:
        lines = f.read().splitlines()
    for line in lines:
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split()
        st, args = words[0], words[1:]
        if st == "image":
            for k, v in _kv(args):
                if k in ("width", "height", "spp", "depth", "degree"):
                    scene.image[k] = int(_num(v))
        elif st == "ambient":
            scene.ambient = _num(args[0])
        elif st == "background":
            scene.background = _vec(args[0])
        elif st == "camera":
            pairs = _kv(args)
            keys = {k for k, _ in pairs}
            if keys & {"eye", "look", "up", "fov"}:
                p = dict(eye=np.array([0, 0, 5.0]), look=np.zeros(3), up=np.array([0, 1.0, 0]),
                         fov=45.0)
                for k, v in pairs:
                    p[k] = _num(v) if k == "fov" else _vec(v)
                scene.camera = ("lookat", p)
            else:
                p = dict(rx=1.0, ry=1.0, df=1.0, steps=[])
                for k, v in pairs:
                    if k in ("rx", "ry", "df"):
                        p[k] = _num(v)
                    else:
                        p["steps"].append(_transform_step(k, v))
                scene.camera = ("explicit", p)
        elif st == "light":
            kind = args[0]
            p = dict(_kv(args[1:]))
            light = dict(kind=kind, color=_vec(p.get("color", "1,1,1")))
            if "pos" in p:
                light["pos"] = _vec(p["pos"])
            if "dir" in p:
                d = _vec(p["dir"])
                light["dir"] = d / np.linalg.norm(d)
            light["cos_angle"] = math.cos(math.radians(_num(p.get("angle", "30"))))
            scene.lights.append(light)
        elif st == "material":
            name = args[0]
            pairs = _kv(args[1:])
            mat = dict(MATERIAL_DEFAULT)
            for k, v in pairs:
                if k == "material":
                    mat = dict(scene.materials[v])
            _material_keys(mat, pairs)
            scene.materials[name] = mat
        elif st in SHAPES:
            pairs = _kv(args)
            mat = dict(MATERIAL_DEFAULT)
            for k, v in pairs:
                if k == "material":
                    mat = dict(scene.materials[v])
            _material_keys(mat, pairs)  # after material=, whatever its position
            md = np.eye(4)
            minor = 0.25
            for k, v in pairs:
                if k in TRANSFORM_KEYS:
                    md = _transform_step(k, v) @ md  # first written applies first
                elif k == "minor":
                    minor = _num(v)
            mi = np.linalg.inv(md)
            # Secondary-ray offset: a millionth of the object's thinnest dimension.
            eps = 1e-6 * np.linalg.svd(md[:3, :3], compute_uv=False).min()
            scene.objects.append(dict(shape=st, Md=md, Mi=mi, Mn=mi[:3, :3].T, mat=mat,
                                      minor=minor, eps=eps))
        elif st == "include":
            parse_scene(os.path.join(os.path.dirname(path), args[0]), scene, depth + 1)
        elif st == "mesh":
            raise SceneError("mesh statements are not supported by the reference renderer")
        else:
            raise SceneError(f"unknown statement {st!r}")
    return scene


def camera_matrix(scene):
    kind, p = scene.camera
    w, h = scene.image["width"], scene.image["height"]
    if kind == "explicit":
        md = np.diag([p["rx"], p["ry"], p["df"], 1.0])
        for step in p["steps"]:
            md = step @ md
        return md
    f = p["look"] - p["eye"]
    f = f / np.linalg.norm(f)
    r = np.cross(f, p["up"])
    r = r / np.linalg.norm(r)
    u = np.cross(r, f)
    ry = math.tan(math.radians(p["fov"]) / 2)
    rx = ry * w / h
    rot = np.eye(4)
    rot[:3, 0], rot[:3, 1], rot[:3, 2] = r, u, -f
    tr = np.eye(4)
    tr[:3, 3] = p["eye"] + f  # canonical eye (0,0,1) lands on `eye`
    return tr @ rot @ np.diag([rx, ry, 1.0, 1.0])


def primary_rays(scene):
    w, h = scene.image["width"], scene.image["height"]
    md = camera_matrix(scene)
    jj, ii = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    x = -1 + (2 * ii + 1) / w   # pixel centres (spp = 1)
    y = 1 - (2 * jj + 1) / h
    pts = np.stack([x.ravel(), y.ravel(), np.zeros(x.size), np.ones(x.size)], axis=1)
    screen = pts @ md.T
    eye = md @ np.array([0, 0, 1.0, 1.0])
    d = screen[:, :3] - eye[:3]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.broadcast_to(eye[:3], d.shape).copy()
    # Angle between neighbouring samples at the image centre, for the checker footprint.
    c0 = md @ np.array([0, 0, 0, 1.0])
    c1 = md @ np.array([0, 2.0 / h, 0, 1.0])
    spread = np.linalg.norm(c1[:3] - c0[:3]) / np.linalg.norm(c0[:3] - eye[:3])
    return o, d, spread


# ------------------------------------------------------------------------ intersections
# Each returns (t, n) in canonical space for rays o + t d (d not unit: t is then the world
# distance because the world direction is unit); t = inf where there is no hit with t > tmin.
def _quadratic(a, b, c):
    """Roots of a t^2 + 2 b t + c = 0 (numerically stable form); nan where none."""
    disc = b * b - a * c
    ok = disc >= 0
    sq = np.sqrt(np.where(ok, disc, 0))
    q = -(b + np.copysign(sq, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = np.where(q != 0, c / q, np.nan)
        t2 = np.where(a != 0, q / a, np.where(b != 0, -c / (2 * b), np.nan))
    t1 = np.where(ok, t1, np.nan)
    t2 = np.where(ok, t2, np.nan)
    return np.minimum(t1, t2), np.maximum(t1, t2)


def _pick(cands, tmin):
    """cands: list of (t, valid). Nearest valid t > tmin, and its index."""
    ts = np.stack([np.where(v & (t > tmin), t, np.inf) for t, v in cands])
    k = np.argmin(ts, axis=0)
    return ts[k, np.arange(ts.shape[1])], k


def hit_sphere(o, d, tmin, obj):
    a = np.einsum("ij,ij->i", d, d)
    # Solve from the ray's point nearest the centre: c is then free of the cancellation that
    # loses the root for far origins or very flat spheres (scale 1e-6 along one axis).
    t0 = -np.einsum("ij,ij->i", o, d) / a
    q = o + t0[:, None] * d
    b = np.einsum("ij,ij->i", q, d)
    c = np.einsum("ij,ij->i", q, q) - 1
    t1, t2 = _quadratic(a, b, c)
    t1, t2 = t1 + t0, t2 + t0
    t, _ = _pick([(t1, ~np.isnan(t1)), (t2, ~np.isnan(t2))], tmin)
    return t, o + np.where(np.isfinite(t), t, 0)[:, None] * d


def normal_sphere(p, obj):
    return p


def hit_cube(o, d, tmin, obj):
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t0 = (-1 - o) * inv
        t1 = (1 - o) * inv
    lo = np.nanmax(np.minimum(t0, t1), axis=1)
    hi = np.nanmin(np.maximum(t0, t1), axis=1)
    ok = lo <= hi
    t, _ = _pick([(lo, ok), (hi, ok)], tmin)
    return t, o + np.where(np.isfinite(t), t, 0)[:, None] * d


def normal_cube(p, obj):
    k = np.argmax(np.abs(p), axis=1)
    n = np.zeros_like(p)
    n[np.arange(len(p)), k] = np.sign(p[np.arange(len(p)), k])
    return n


def _caps(o, d, ys, radius2):
    out = []
    with np.errstate(divide="ignore", invalid="ignore"):
        for y, r2 in zip(ys, radius2):
            t = (y - o[:, 1]) / d[:, 1]
            x = o[:, 0] + t * d[:, 0]
            z = o[:, 2] + t * d[:, 2]
            out.append((t, np.isfinite(t) & (x * x + z * z <= r2)))
    return out


def hit_cylinder(o, d, tmin, obj):
    a = d[:, 0] ** 2 + d[:, 2] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):  # same shift as the sphere, in xz
        t0 = np.where(a > 0, -(o[:, 0] * d[:, 0] + o[:, 2] * d[:, 2]) / a, 0)
    qx, qz = o[:, 0] + t0 * d[:, 0], o[:, 2] + t0 * d[:, 2]
    b = qx * d[:, 0] + qz * d[:, 2]
    c = qx ** 2 + qz ** 2 - 1
    t1, t2 = _quadratic(a, b, c)
    t1, t2 = t1 + t0, t2 + t0
    cands = []
    for t in (t1, t2):
        y = o[:, 1] + t * d[:, 1]
        cands.append((t, ~np.isnan(t) & (np.abs(y) <= 1)))
    cands += _caps(o, d, (-1.0, 1.0), (1.0, 1.0))
    t, _ = _pick(cands, tmin)
    return t, o + np.where(np.isfinite(t), t, 0)[:, None] * d


def normal_cylinder(p, obj):
    side = np.stack([p[:, 0], np.zeros(len(p)), p[:, 2]], axis=1)
    rad_err = np.abs(np.hypot(p[:, 0], p[:, 2]) - 1)
    cap_err = np.abs(np.abs(p[:, 1]) - 1)
    cap = np.stack([np.zeros(len(p)), np.sign(p[:, 1]), np.zeros(len(p))], axis=1)
    return np.where((cap_err < rad_err)[:, None], cap, side)


def hit_cone(o, d, tmin, obj):
    # x^2 + z^2 = ((1 - y) / 2)^2 for y in [-1, 1]
    k = 1 - o[:, 1]
    a = d[:, 0] ** 2 + d[:, 2] ** 2 - d[:, 1] ** 2 / 4
    b = o[:, 0] * d[:, 0] + o[:, 2] * d[:, 2] + k * d[:, 1] / 4
    c = o[:, 0] ** 2 + o[:, 2] ** 2 - k * k / 4
    t1, t2 = _quadratic(a, b, c)
    cands = []
    for t in (t1, t2):
        y = o[:, 1] + t * d[:, 1]
        cands.append((t, ~np.isnan(t) & (y >= -1) & (y <= 1)))
    cands += _caps(o, d, (-1.0,), (1.0,))
    t, _ = _pick(cands, tmin)
    return t, o + np.where(np.isfinite(t), t, 0)[:, None] * d


def normal_cone(p, obj):
    side = np.stack([2 * p[:, 0], (1 - p[:, 1]) / 2, 2 * p[:, 2]], axis=1)
    cap = np.tile([0.0, -1.0, 0.0], (len(p), 1))
    on_cap = np.abs(p[:, 1] + 1) < np.abs(np.hypot(p[:, 0], p[:, 2]) - (1 - p[:, 1]) / 2)
    # The apex has no gradient; docs/scene-format.md gives it the normal +y.
    apex = ~np.any(side, axis=1)
    side[apex] = [0.0, 1.0, 0.0]
    return np.where(on_cap[:, None], cap, side)


def _torus_f(p, r):
    s = np.einsum("ij,ij->i", p, p) + 1 - r * r
    return s * s - 4 * (p[:, 0] ** 2 + p[:, 2] ** 2)


def hit_torus(o, d, tmin, obj):
    r = obj["minor"]
    n = len(o)
    dl = np.linalg.norm(d, axis=1)
    u = d / dl[:, None]
    # Solve from the point of the ray nearest the torus centre: keeps the quartic's
    # coefficients small for far-away origins.
    t0 = -np.einsum("ij,ij->i", o, u)
    q = o + t0[:, None] * u
    qq = np.einsum("ij,ij->i", q, q)
    qu = np.einsum("ij,ij->i", q, u)
    k = qq + 1 - r * r
    # (s^2 + 2 qu s + k)^2 - 4((qx + s ux)^2 + (qz + s uz)^2) = 0
    a2 = u[:, 0] ** 2 + u[:, 2] ** 2
    a1 = q[:, 0] * u[:, 0] + q[:, 2] * u[:, 2]
    a0 = q[:, 0] ** 2 + q[:, 2] ** 2
    c3 = 4 * qu
    c2 = 4 * qu * qu + 2 * k - 4 * a2
    c1 = 4 * qu * k - 8 * a1
    c0 = k * k - 4 * a0
    comp = np.zeros((n, 4, 4))
    comp[:, 0, :] = -np.stack([c3, c2, c1, c0], axis=1)
    comp[:, 1, 0] = comp[:, 2, 1] = comp[:, 3, 2] = 1
    finite = np.all(np.isfinite(comp.reshape(n, -1)), axis=1)
    comp[~finite] = 0
    roots = np.linalg.eigvals(comp)
    s = roots.real.copy()
    # Newton polishing on the quartic; a root is kept if its residual is tiny afterwards.
    for _ in range(4):
        f = (((s + c3[:, None]) * s + c2[:, None]) * s + c1[:, None]) * s + c0[:, None]
        df = ((4 * s + 3 * c3[:, None]) * s + 2 * c2[:, None]) * s + c1[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(df != 0, f / df, 0)
        s = s - np.where(np.abs(step) < 1e-3 * (1 + np.abs(s)), step, 0)
    f = (((s + c3[:, None]) * s + c2[:, None]) * s + c1[:, None]) * s + c0[:, None]
    scale = np.maximum.reduce([np.abs(c0), np.abs(c1), np.abs(c2), np.abs(c3), np.ones(n)])
    real = (np.abs(roots.imag) < 1e-4 * (1 + np.abs(roots.real))) | \
           (np.abs(f) < 1e-10 * scale[:, None])
    real &= finite[:, None]
    tc = (s + t0[:, None]) / dl[:, None]
    t, _ = _pick([(tc[:, i], real[:, i]) for i in range(4)], tmin)
    return t, o + np.where(np.isfinite(t), t, 0)[:, None] * d


def normal_torus(p, obj):
    r = obj["minor"]
    s = np.einsum("ij,ij->i", p, p) + 1 - r * r
    g = 4 * s[:, None] * p
    g[:, 0] -= 8 * p[:, 0]
    g[:, 2] -= 8 * p[:, 2]
    # F is the product of the near-tube and far-tube factors; on the spindle's inner lemon
    # (the far factor vanishes) the gradient points into the lemon, while the documented
    # outward normal points away from the far tube's centre circle: flip it there.
    rho = np.hypot(p[:, 0], p[:, 2])
    near = (rho - 1) ** 2 + p[:, 1] ** 2 - r * r
    far = (rho + 1) ** 2 + p[:, 1] ** 2 - r * r
    g[np.abs(far) < np.abs(near)] *= -1
    return g


def hit_plane(o, d, tmin, obj):
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -o[:, 1] / d[:, 1]
    t = np.where(np.isfinite(t) & (t > tmin), t, np.inf)
    return t, o + np.where(np.isfinite(t), t, 0)[:, None] * d


def normal_plane(p, obj):
    return np.tile([0.0, 1.0, 0.0], (len(p), 1))


def hit_disk(o, d, tmin, obj):
    """The unit disk x^2 + z^2 <= 1 of the plane y = 0 (edge included)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t = -o[:, 1] / d[:, 1]
        x = o[:, 0] + t * d[:, 0]
        z = o[:, 2] + t * d[:, 2]
        inside = x * x + z * z <= 1
    t = np.where(np.isfinite(t) & (t > tmin) & inside, t, np.inf)
    return t, o + np.where(np.isfinite(t), t, 0)[:, None] * d


def normal_disk(p, obj):
    return np.tile([0.0, 1.0, 0.0], (len(p), 1))


HIT = dict(sphere=(hit_sphere, normal_sphere), cube=(hit_cube, normal_cube),
           cylinder=(hit_cylinder, normal_cylinder), cone=(hit_cone, normal_cone),
           torus=(hit_torus, normal_torus), plane=(hit_plane, normal_plane),
           disk=(hit_disk, normal_disk))


def closest_hit(scene, o, d, tmin=0.0):
    """Nearest hit over all objects: t, object index (-1 none), world point, outward normal."""
    n = len(o)
    best_t = np.full(n, np.inf)
    best_k = np.full(n, -1)
    best_pc = np.zeros((n, 3))
    for k, obj in enumerate(scene.objects):
        mi = obj["Mi"]
        oc = o @ mi[:3, :3].T + mi[:3, 3]
        dc = d @ mi[:3, :3].T
        t, pc = HIT[obj["shape"]][0](oc, dc, tmin, obj)
        closer = t < best_t
        best_t = np.where(closer, t, best_t)
        best_k = np.where(closer, k, best_k)
        best_pc = np.where(closer[:, None], pc, best_pc)
    normal = np.zeros((n, 3))
    for k, obj in enumerate(scene.objects):
        sel = best_k == k
        if sel.any():
            nc = HIT[obj["shape"]][1](best_pc[sel], obj)
            nw = nc @ obj["Mn"].T
            normal[sel] = nw / np.linalg.norm(nw, axis=1, keepdims=True)
    point = o + np.where(np.isfinite(best_t), best_t, 0)[:, None] * d
    return best_t, best_k, point, normal


def occluded(scene, o, d, tmax):
    t, _, _, _ = closest_hit(scene, o, d)
    return t < tmax


# ------------------------------------------------------------------------------ shading
def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def surface_colour(mat, point, normal, width, cos_inc):
    """Colour after checker, and a mask of points whose filtered checker value may differ from
    the sharp pattern (the footprint disc reaches a cell boundary)."""
    n = len(point)
    if mat["checker"] is None:
        return np.tile(mat["color"], (n, 1)), np.zeros(n, bool)
    q = point / mat["cell"] + 0.5
    parity = np.floor(q).sum(axis=1).astype(np.int64) % 2
    col = np.where((parity == 0)[:, None], mat["color"], mat["checker"])
    # Distance, within the tangent plane, to the nearest cell boundary plane: a boundary
    # x = c is |x - c| / sin(angle between N and x) away along the surface.
    frac = q - np.floor(q)
    along = np.minimum(frac, 1 - frac) * mat["cell"]
    sin_axis = np.sqrt(np.maximum(1 - normal * normal, 0))
    with np.errstate(divide="ignore"):
        dist = np.min(np.where(sin_axis > 1e-9, along / sin_axis, np.inf), axis=1)
    # The filter disc has diameter `width`, stretched by 1/|cos| along the incidence
    # direction: beyond one full (stretched) width from a boundary it sees one cell only.
    return col, dist < width / np.maximum(np.abs(cos_inc), 1e-3) + 1e-12


def trace(scene, o, d, level, width0, spread):
    """Colour of rays o + t d (d unit); returns (colour, uncertain-checker mask)."""
    n = len(o)
    deg = scene.image["degree"]
    colour = np.tile(scene.background, (n, 1)).astype(float)
    unsure = np.zeros(n, bool)
    if n == 0:
        return colour, unsure
    t, k, p, nout = closest_hit(scene, o, d)
    # Secondary rays of every object are traced together, one batch per bounce level.
    sec = dict(o=[], d=[], w=[], parent=[], width=[])
    for idx, obj in enumerate(scene.objects):
        sel = np.nonzero(k == idx)[0]
        if len(sel) == 0:
            continue
        mat = obj["mat"]
        D, P, No = d[sel], p[sel], nout[sel]
        cos_i = _dot(D, No)
        # Both faces of a surface are lit: shade with the normal facing the incoming ray.
        N = np.where((cos_i > 0)[:, None], -No, No)
        width = width0[sel] + t[sel] * spread
        C, uns = surface_colour(mat, P, No, width, cos_i)
        V = -D
        eps = 1e-9 * (1 + np.linalg.norm(P, axis=1))
        eps = np.maximum(eps, obj["eps"])
        off = P + eps[:, None] * N  # shadow / reflection origin, on the ray's side
        if deg == 0:
            colour[sel] = C
            unsure[sel] = uns
            continue
        amb = scene.ambient * (mat["ambi"] if deg >= 2 else 1.0)
        col = amb * C + mat["emission"]  # the surface's own radiance, from degree 1
        for L in scene.lights:
            if L["kind"] == "directional":
                w = np.tile(-L["dir"], (len(sel), 1))
                dist = np.full(len(sel), np.inf)
            else:
                to = L["pos"] - P
                dist = np.linalg.norm(to, axis=1)
                w = to / dist[:, None]
            ndw = _dot(N, w)
            lit = ndw > 0
            if L["kind"] == "spot":
                lit &= (-w) @ L["dir"] >= L["cos_angle"]
            if deg >= 5 and lit.any():
                li = np.nonzero(lit)[0]
                blocked = occluded(scene, off[li], w[li], dist[li] - eps[li])
                lit[li[blocked]] = False
            if deg == 1:
                col = col + np.where(lit, ndw, 0)[:, None] * C
                continue
            lc = L["color"]
            col = col + np.where(lit, ndw, 0)[:, None] * mat["diff"] * lc * C
            if mat["spec"] > 0:
                R = 2 * ndw[:, None] * N - w
                rv = np.maximum(_dot(R, V), 0)
                hl = np.where(lit, rv ** mat["shininess"], 0)
                col = col + mat["spec"] * hl[:, None] * lc
        if deg >= 3 and level < scene.image["depth"]:
            refl_dir = D - 2 * _dot(D, N)[:, None] * N
            w_refl, w_trans = mat["refl"], mat["trans"]
            if deg >= 4 and mat["trans"] > 0:
                entering = cos_i < 0
                eta = np.where(entering, 1 / mat["ior"], mat["ior"])
                ci = -_dot(D, N)
                kk = 1 - eta * eta * (1 - ci * ci)
                tir = kk < 0
                T = eta[:, None] * D + (eta * ci - np.sqrt(np.maximum(kk, 0)))[:, None] * N
                T /= np.linalg.norm(T, axis=1, keepdims=True)
                tdir = np.where(tir[:, None], refl_dir, T)
                torg = np.where(tir[:, None], off, P - eps[:, None] * N)
                if mat["fresnel"] and mat["ior"] != 1:
                    # docs/scene-format.md, "Fresnel": Schlick with the cosine on the less
                    # dense side, R = 1 under total internal reflection; trans R is
                    # reflected on top of refl, trans (1 - R) refracted.
                    r0 = ((mat["ior"] - 1) / (mat["ior"] + 1)) ** 2
                    c = np.where(eta > 1, np.sqrt(np.maximum(kk, 0)), ci)
                    R = np.where(tir, 1.0, r0 + (1 - r0) * (1 - c) ** 5)
                    w_refl = mat["refl"] + mat["trans"] * R
                    w_trans = mat["trans"] * (1 - R)
            if np.any(np.asarray(w_refl) > 0):
                _queue(sec, off, refl_dir, w_refl, sel, width)
            if deg >= 4 and mat["trans"] > 0:
                _queue(sec, torg, tdir, w_trans, sel, width)
        colour[sel] = col
        unsure[sel] = uns
    if sec["o"]:
        cat = {key: np.concatenate(val) for key, val in sec.items()}
        c2, u2 = trace(scene, cat["o"], cat["d"], level + 1, cat["width"], spread)
        np.add.at(colour, cat["parent"], cat["w"][:, None] * c2)
        unsure[cat["parent"][u2]] = True
    return colour, unsure


def _queue(sec, o, d, weight, parent, width):
    sec["o"].append(o)
    sec["d"].append(d)
    sec["w"].append(np.full(len(o), weight))
    sec["parent"].append(parent)
    sec["width"].append(width)


def render(scene):
    if scene.image["spp"] != 1:
        # The reference places one sample at each pixel centre; that is what the engines
        # do at spp = 1 whatever the sampler (docs/scene-format.md, Samplers).
        raise SceneError("the reference renderer needs spp=1")
    o, d, spread = primary_rays(scene)
    col, unsure = trace(scene, o, d, 0, np.zeros(len(o)), spread)
    h, w = scene.image["height"], scene.image["width"]
    return col.reshape(h, w, 3), unsure.reshape(h, w)


# ------------------------------------------------------------------------------- PFM I/O
def write_pfm(path, img):
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())  # bottom row first


def read_pfm(path):
    with open(path, "rb") as f:
        data = f.read()
    # Header: "PF", width, height, scale (negative: little-endian), one whitespace each.
    m = re.match(rb"PF\s+(\d+)\s+(\d+)\s+(\S+)\s", data)
    if not m:
        raise ValueError(f"{path}: not a colour PFM")
    w, h, scale = int(m.group(1)), int(m.group(2)), float(m.group(3))
    pos = m.end()
    dtype = "<f4" if scale < 0 else ">f4"
    img = np.frombuffer(data, dtype=dtype, count=w * h * 3, offset=pos).reshape(h, w, 3)
    return img[::-1].astype(np.float64)


def load(path, width=None, height=None, degree=None, depth=None):
    scene = parse_scene(path)
    for key, val in (("width", width), ("height", height), ("degree", degree),
                     ("depth", depth)):
        if val is not None:
            scene.image[key] = val
    scene.image["spp"] = 1
    return scene


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("-o", "--output", required=True, help="output .pfm (linear float)")
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--degree", type=int)
    ap.add_argument("--depth", type=int)
    a = ap.parse_args(argv)
    scene = load(a.scene, a.width, a.height, a.degree, a.depth)
    img, _ = render(scene)
    write_pfm(a.output, img)


if __name__ == "__main__":
    sys.exit(main())
