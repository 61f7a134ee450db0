#!/usr/bin/env python3
"""Write a family of procedurally made objects as binary STL (millimetres), for sweeps of the
whole pipeline over shapes no one drew: what plans, what holds, what the tool trips on.

    python3 scripts/random_shapes.py OUT_DIR [--count 120] [--seed 7]

Object i is of kind i mod 6, each closed and outward-wound, sized for the thesis hand (10 to
130 mm across), turned by a uniformly random rotation and moved by up to 40 mm:

- `superellipsoid`: semi-axes 10-60 mm, exponents 0.25-2.5 (boxes with round edges to stars);
- `lathe`: a random profile of 3-7 radii (8-50 mm) turned about its axis, 40-200 mm tall
  (bottles, vases, spools), flat caps;
- `prism`: a star-shaped polygon of 3-9 corners, radii 12-50 mm, extruded 20-160 mm;
- `compound`: 2-4 boxes, cylinders and spheres overlapping, each a closed shell of its own
  (the loader unites them);
- `torus`: major radius 20-55 mm, minor 5-20 mm;
- `handle`: a cylinder with a bent bar beside it (a mug-like body and loop), two shells.

Deterministic: the same seed gives the same bytes.
"""

import argparse
import math
import os
import random

from box_family import box_triangles
from gen_dataset import random_rotation, write_binary_stl


def grid_surface(point, nu, nv, closed_u=False):
    """Triangles of a surface point(u, v) on a grid: v wraps around (0..nv), u runs 0..nu with
    its two ends collapsed to poles unless closed_u, where u wraps too (a torus)."""
    tris = []
    rows = nu if closed_u else nu + 1
    pts = [[point(i, j) for j in range(nv)] for i in range(rows)]
    last = nu if closed_u else nu
    for i in range(last):
        i2 = (i + 1) % rows
        for j in range(nv):
            j2 = (j + 1) % nv
            a, b, c, d = pts[i][j], pts[i][j2], pts[i2][j2], pts[i2][j]
            if not closed_u and i == 0:
                tris.append((a, c, d))
            elif not closed_u and i == nu - 1:
                tris.append((a, b, c))
            else:
                tris.append((a, b, c))
                tris.append((a, c, d))
    return tris


def spow(x, e):
    return math.copysign(abs(x) ** e, x)


def superellipsoid(rng):
    ax = [rng.uniform(10, 60) for _ in range(3)]
    e1, e2 = rng.uniform(0.25, 2.5), rng.uniform(0.25, 2.5)
    nu, nv = 40, 64

    def point(i, j):
        u = -math.pi / 2 + math.pi * i / nu
        v = 2 * math.pi * j / nv
        cu, su = math.cos(u), math.sin(u)
        return (
            ax[0] * spow(cu, e1) * spow(math.cos(v), e2),
            ax[1] * spow(cu, e1) * spow(math.sin(v), e2),
            ax[2] * spow(su, e1),
        )

    return grid_surface(point, nu, nv)


def lathe_tris(radii, height, nv=48, z0=0.0):
    """A solid of revolution about z: radii at evenly spaced heights, flat caps."""
    n = len(radii)
    rings = []
    for i, r in enumerate(radii):
        z = z0 + height * i / (n - 1)
        rings.append([(r * math.cos(2 * math.pi * j / nv), r * math.sin(2 * math.pi * j / nv), z) for j in range(nv)])
    tris = []
    for i in range(n - 1):
        for j in range(nv):
            j2 = (j + 1) % nv
            a, b, c, d = rings[i][j], rings[i][j2], rings[i + 1][j2], rings[i + 1][j]
            tris.append((a, b, c))
            tris.append((a, c, d))
    bottom, top = (0.0, 0.0, z0), (0.0, 0.0, z0 + height)
    for j in range(nv):
        j2 = (j + 1) % nv
        tris.append((bottom, rings[0][j2], rings[0][j]))
        tris.append((top, rings[-1][j], rings[-1][j2]))
    return tris


def lathe(rng):
    k = rng.randint(3, 7)
    radii = [rng.uniform(8, 50) for _ in range(k)]
    # smooth the profile: 4 points between each pair of knots (cosine blend)
    fine = []
    for i in range(k - 1):
        for s in range(4):
            t = s / 4
            w = (1 - math.cos(math.pi * t)) / 2
            fine.append(radii[i] * (1 - w) + radii[i + 1] * w)
    fine.append(radii[-1])
    return lathe_tris(fine, rng.uniform(40, 200), z0=-60.0)


def prism(rng):
    n = rng.randint(3, 9)
    angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(n))
    # keep corners at least 15 degrees apart so the polygon stays star-shaped about its centre
    for i in range(1, n):
        angles[i] = max(angles[i], angles[i - 1] + math.radians(15))
    if angles[-1] - angles[0] > 2 * math.pi - math.radians(15):
        angles = [2 * math.pi * i / n for i in range(n)]
    radii = [rng.uniform(12, 50) for _ in range(n)]
    h = rng.uniform(20, 160)
    lo = [(r * math.cos(a), r * math.sin(a), -h / 2) for a, r in zip(angles, radii)]
    hi = [(x, y, h / 2) for x, y, _ in lo]
    tris = []
    for i in range(n):
        i2 = (i + 1) % n
        tris.append((lo[i], lo[i2], hi[i2]))
        tris.append((lo[i], hi[i2], hi[i]))
        tris.append(((0.0, 0.0, -h / 2), lo[i2], lo[i]))
        tris.append(((0.0, 0.0, h / 2), hi[i], hi[i2]))
    return tris


def box_tris(w, d, h):
    return [tuple(tuple(p) for p in t) for _, t in box_triangles(w, d, h)]


def sphere_tris(r):
    nu, nv = 24, 36

    def point(i, j):
        u = -math.pi / 2 + math.pi * i / nu
        v = 2 * math.pi * j / nv
        return (r * math.cos(u) * math.cos(v), r * math.cos(u) * math.sin(v), r * math.sin(u))

    return grid_surface(point, nu, nv)


def transform(tris, rot, off):
    def f(p):
        return tuple(sum(rot[i][k] * p[k] for k in range(3)) + off[i] for i in range(3))

    return [(f(a), f(b), f(c)) for a, b, c in tris]


def compound(rng):
    tris = []
    for k in range(rng.randint(2, 4)):
        kind = rng.choice(["box", "cylinder", "sphere"])
        if kind == "box":
            part = box_tris(rng.uniform(15, 90), rng.uniform(15, 60), rng.uniform(15, 60))
        elif kind == "cylinder":
            part = lathe_tris([rng.uniform(8, 35)] * 2, rng.uniform(20, 120), z0=0.0)
            part = transform(part, [[1, 0, 0], [0, 1, 0], [0, 0, 1]], (0, 0, -part[0][0][2] - 30))
        else:
            part = sphere_tris(rng.uniform(10, 35))
        off = (0.0, 0.0, 0.0) if k == 0 else tuple(rng.uniform(-25, 25) for _ in range(3))
        tris += transform(part, random_rotation(rng), off)
    return tris


def torus(rng):
    big, small = rng.uniform(20, 55), rng.uniform(5, 20)
    nu, nv = 48, 24

    def point(i, j):
        u = 2 * math.pi * i / nu
        v = 2 * math.pi * j / nv
        rr = big + small * math.cos(v)
        return (rr * math.cos(u), rr * math.sin(u), small * math.sin(v))

    # u around the ring, v around the tube; wound outward
    return [(a, c, b) for a, b, c in grid_surface(point, nu, nv, closed_u=True)]


def handle(rng):
    r, h = rng.uniform(20, 45), rng.uniform(50, 130)
    body = lathe_tris([r, r], h, z0=-h / 2)
    bar_r = rng.uniform(3, 8)
    reach = rng.uniform(15, 35)
    # a bar of three straight cylinders: out, down, back in, outside the body on +x
    tris = list(body)
    top, bot = h / 2 - rng.uniform(5, 15), -h / 2 + rng.uniform(5, 15)
    pieces = [
        ((r - 3, 0, top), (r + reach, 0, top)),
        ((r + reach, 0, top), (r + reach, 0, bot)),
        ((r + reach, 0, bot), (r - 3, 0, bot)),
    ]
    for a, b in pieces:
        d = [b[i] - a[i] for i in range(3)]
        length = math.sqrt(sum(x * x for x in d))
        z = [x / length for x in d]
        t = [0.0, 1.0, 0.0] if abs(z[1]) < 0.9 else [1.0, 0.0, 0.0]
        x = [t[1] * z[2] - t[2] * z[1], t[2] * z[0] - t[0] * z[2], t[0] * z[1] - t[1] * z[0]]
        n = math.sqrt(sum(v * v for v in x))
        x = [v / n for v in x]
        y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]]
        rot = [[x[i], y[i], z[i]] for i in range(3)]
        part = lathe_tris([bar_r, bar_r], length + 2 * bar_r, nv=16, z0=-bar_r)
        tris += transform(part, rot, a)
    return tris


KINDS = [superellipsoid, lathe, prism, compound, torus, handle]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=120)
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for i in range(args.count):
        rng = random.Random(args.seed * 1_000_003 + i)
        kind = KINDS[i % len(KINDS)]
        tris = kind(rng)
        off = tuple(rng.uniform(-40, 40) for _ in range(3))
        tris = transform(tris, random_rotation(rng), off)
        path = os.path.join(args.out, f"{i:03d}_{kind.__name__}.stl")
        write_binary_stl(path, tris, "random_shapes.py")


if __name__ == "__main__":
    main()
