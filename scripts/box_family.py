#!/usr/bin/env python3
"""Write a family of boxes as binary STL (12 triangles each, centred, millimetres).

    python3 scripts/box_family.py OUT_DIR

Cubes of 30 to 100 mm (`cubeS.stl`) and square plates (`plateSxH.stl`): the shapes whose moments
of inertia are equal, on which the object's frame from its geometry (docs/FRAMES.md) decides
the grasp axes within a plane of equal moments.
"""
import os
import struct
import sys


def box_triangles(w, d, h):
    """The box's 12 triangles as (outward normal, (a, b, c)), anticlockwise seen from outside."""
    half = (w / 2, d / 2, h / 2)
    tris = []
    for axis in range(3):
        for s in (-1, 1):
            o = [i for i in range(3) if i != axis]
            corners = []
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                c = [0.0, 0.0, 0.0]
                c[axis], c[o[0]], c[o[1]] = s, a, b
                corners.append([c[i] * half[i] for i in range(3)])
            n = [0.0, 0.0, 0.0]
            n[axis] = float(s)
            for t in ((corners[0], corners[1], corners[2]), (corners[0], corners[2], corners[3])):
                u = [t[1][i] - t[0][i] for i in range(3)]
                v = [t[2][i] - t[0][i] for i in range(3)]
                cross = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
                if sum(cross[i] * n[i] for i in range(3)) < 0:
                    t = (t[0], t[2], t[1])
                tris.append((n, t))
    return tris


def box(w, d, h, path):
    tris = box_triangles(w, d, h)
    with open(path, "wb") as f:
        f.write(b"\0" * 80)
        f.write(struct.pack("<I", len(tris)))
        for n, t in tris:
            f.write(struct.pack("<3f", *n))
            for p in t:
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")


def main(argv):
    if len(argv) != 1:
        sys.exit(__doc__)
    out = argv[0]
    os.makedirs(out, exist_ok=True)
    for s in (30, 40, 50, 60, 70, 80, 90, 100):
        box(s, s, s, os.path.join(out, f"cube{s}.stl"))
    for s, h in ((50, 25), (60, 30), (80, 40), (100, 40)):
        box(s, s, h, os.path.join(out, f"plate{s}x{h}.stl"))


if __name__ == "__main__":
    main(sys.argv[1:])
