#!/usr/bin/env python3
"""Writes a streamrt scene of N random spheres resting on a checkered plane.

usage: random_spheres.py N [--seed S] [-o FILE]

The spheres sit in a square field whose side grows with sqrt(N); their radius is scaled so
that N of them fit, and each new sphere is placed where it does not overlap the earlier ones
(after a bounded number of tries it is placed anyway, hence "non-overlapping-ish"). A look-at
camera looks down at the field from the front, lit by two point lights. Standard library only.
"""
import argparse
import math
import random
import sys


def build_scene(n, seed):
    rng = random.Random(seed)
    side = 4.0 * math.sqrt(max(n, 1))   # the field is [-side/2, side/2]^2 in x and z
    cell = side / math.sqrt(max(n, 1))  # room per sphere
    rmax = 0.45 * cell
    rmin = 0.2 * cell
    spheres = []
    for _ in range(n):
        best = None
        for _attempt in range(60):
            r = rng.uniform(rmin, rmax)
            x = rng.uniform(-side / 2 + r, side / 2 - r)
            z = rng.uniform(-side / 2 + r, side / 2 - r)
            clearance = min((math.hypot(x - sx, z - sz) - r - sr for sx, sz, sr in spheres),
                            default=math.inf)
            if best is None or clearance > best[0]:
                best = (clearance, x, z, r)
            if clearance > 0.02 * cell:
                break
        spheres.append(best[1:])

    lines = [
        "# %d random spheres on a checkered plane (random_spheres.py, seed %s)" % (n, seed),
        "image width=800 height=600 spp=4 depth=4 degree=5 output=random_spheres.png",
        "ambient 0.1",
        "background 0.5,0.65,0.85",
        "camera eye=0,%.4f,%.4f look=0,0,%.4f up=0,1,0 fov=45"
        % (0.75 * side + 2, 0.85 * side + 2, -0.05 * side),
        "light point pos=%.4f,%.4f,%.4f color=0.8,0.8,0.8" % (-0.4 * side, side + 4, 0.6 * side),
        "light point pos=%.4f,%.4f,%.4f color=0.45,0.45,0.5" % (0.6 * side, 0.7 * side + 3, 0.2 * side),
        "plane color=0.9,0.9,0.9 checker=0.25,0.25,0.25 cell=%.4f diff=0.9" % (cell / 2),
    ]
    for x, z, r in spheres:
        color = ",".join("%.3f" % rng.uniform(0.1, 1.0) for _ in range(3))
        kind = rng.random()
        if kind < 0.2:
            material = "ambi=0.1 diff=0.2 spec=0.6 shininess=80 refl=0.7"
        elif kind < 0.3:
            material = "ambi=0 diff=0.05 spec=0.8 shininess=120 refl=0.05 trans=0.9 ior=1.5"
            color = "1,1,1"
        else:
            material = "diff=0.85 spec=%.2f shininess=40" % rng.uniform(0.0, 0.4)
        lines.append("sphere color=%s %s scale=%.4f translate=%.4f,%.4f,%.4f"
                     % (color, material, r, x, r, z))
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description="Write a scene of N random spheres on a checkered plane.")
    ap.add_argument("n", type=int, metavar="N", help="number of spheres (>= 1)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    ap.add_argument("-o", "--output", default="-", help="scene file to write (default: stdout)")
    args = ap.parse_args(argv)
    if args.n < 1:
        ap.error("N must be at least 1")
    text = build_scene(args.n, args.seed)
    if args.output == "-":
        sys.stdout.write(text)
    else:
        with open(args.output, "w", encoding="utf-8") as f:
            f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
