#!/usr/bin/env python3
"""Generate a folder of objects for dataset-scale runs: scaled, rotated and moved copies of the
thesis objects and the tuning set's shapes (assets/objects/*.stl, assets/objects/train/*.stl).

    python3 scripts/gen_dataset.py OUT_DIR [--count 200] [--seed 19]

Object i is base shape i mod 15 (sorted by name), scaled across its axis (X and Y) by one
factor and along it (Z) by another, each uniform in [0.85, 1.15], then turned by a uniformly
random rotation and moved by up to 50 mm along each axis, so the planner's principal-axis
alignment has work to do. Deterministic: the same seed gives the same bytes. Binary STL in,
binary STL out, millimetres.
"""

import argparse
import glob
import math
import os
import random
import struct
import sys


def read_binary_stl(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 84:
        raise ValueError(f"{path}: too short for a binary STL")
    (n,) = struct.unpack_from("<I", data, 80)
    if len(data) != 84 + 50 * n:
        raise ValueError(f"{path}: not a binary STL ({n} triangles but {len(data)} bytes)")
    tris = []
    for i in range(n):
        v = struct.unpack_from("<12f", data, 84 + 50 * i)
        tris.append((v[3:6], v[6:9], v[9:12]))
    return tris


def random_rotation(rng):
    """A uniformly random rotation matrix (Shoemake's method)."""
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    a, b = math.sqrt(1 - u1), math.sqrt(u1)
    w, x, y, z = (a * math.sin(2 * math.pi * u2), a * math.cos(2 * math.pi * u2),
                  b * math.sin(2 * math.pi * u3), b * math.cos(2 * math.pi * u3))
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def write_binary_stl(path, tris, header):
    out = bytearray(header.encode()[:80].ljust(80, b" "))
    out += struct.pack("<I", len(tris))
    for a, b, c in tris:
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        l = math.sqrt(sum(x * x for x in n)) or 1.0
        out += struct.pack("<3f", *(x / l for x in n))
        for p in (a, b, c):
            out += struct.pack("<3f", *p)
        out += b"\0\0"
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(out)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--seed", type=int, default=19)
    ap.add_argument("--assets", default=os.path.join(os.path.dirname(__file__), "..", "assets"))
    args = ap.parse_args()
    bases = sorted(glob.glob(os.path.join(args.assets, "objects", "*.stl"))
                   + glob.glob(os.path.join(args.assets, "objects", "train", "*.stl")),
                   key=os.path.basename)
    if not bases:
        print(f"gen_dataset: error: {args.assets}: no objects/*.stl", file=sys.stderr)
        return 2
    shapes = [(os.path.splitext(os.path.basename(b))[0], read_binary_stl(b)) for b in bases]
    os.makedirs(args.out, exist_ok=True)
    rng = random.Random(args.seed)
    for i in range(args.count):
        name, tris = shapes[i % len(shapes)]
        radial, axial = rng.uniform(0.85, 1.15), rng.uniform(0.85, 1.15)
        r = random_rotation(rng)
        t = [rng.uniform(-50, 50) for _ in range(3)]

        def move(p):
            q = (p[0] * radial, p[1] * radial, p[2] * axial)
            return tuple(sum(r[j][k] * q[k] for k in range(3)) + t[j] for j in range(3))

        out = [tuple(move(p) for p in tri) for tri in tris]
        fname = f"{i:03d}_{name}_r{radial:.2f}_a{axial:.2f}.stl"
        write_binary_stl(os.path.join(args.out, fname), out,
                         f"gen_dataset.py seed {args.seed}: {name} x{radial:.3f}/{axial:.3f}")
    print(f"gen_dataset: {args.count} objects from {len(shapes)} shapes in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
