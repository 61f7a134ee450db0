#!/usr/bin/env python3
"""Does a grasp push its object out along the grasp axis, and does that rank the hold (issue 58)?

    python3 scripts/squeeze_study.py NAME=LABELS.jsonl [NAME=LABELS.jsonl ...] [--units U]

The thesis grades a finger on a surface steeper than the friction cone (atan 0.3, 17 degrees
from the grasp axis) as ungraspable (Cat_5); the planner's rules beyond the thesis
(`curvature_graded`) grade such elevations instead of dropping them. A finger that squeezes a
surface leaning from the axis pushes the object along the axis; where every contact leans the
same way nothing holds it back but friction (a pyramid, a cone, a cube held on an edge).

For each labelled candidate, the outward surface normal at each planned contact group (the
nearest triangles of the object's mesh, within 0.5 mm of the closest) against the grasp axis
(the palm frame's z, `palm_pose`'s third column):

- `net`: |sum of the normals' axial components| / contacts, the push along the axis per unit
  squeeze (0: balanced, as on a cylinder or a waist; 1: every contact faces along the axis);
- `beyond`: the contacts whose surface leans from the axis by more than the friction cone;
- `steepest`: the largest lean [deg].

Reported per file: each figure's AUC against a hold as planned (`as_planned_probability` at
least 0.5) within objects (lower first), the mean hold probability by `net`, and the AUC held out
over 5 folds of objects (seed 1) of the grade's `margin` and `even` terms weighted with and
without `net` (weights by coordinate search on the folds' training objects); then each object
none of whose labelled candidates holds (hold probability at least 0.5), with its candidates'
median `net` and share of contacts beyond the cone. Needs numpy. Meshes are read as the label
records' `label.input` names them (a scenario's `[object] mesh` and `units`, or a bare mesh in
`--units`, mm by default); run from the folder the labelling ran in.
"""
import json
import math
import os
import random
import sys
import tomllib
from collections import defaultdict

import numpy as np

from order_study import term_auc

SCALE = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "inch": 25.4}
CONE_DEG = math.degrees(math.atan(0.3))


def load_stl(path):
    data = open(path, "rb").read()
    if data[:5] == b"solid" and b"facet" in data[:400]:
        text = data.decode(errors="ignore").splitlines()
        vs = [list(map(float, l.split()[1:4])) for l in text if l.strip().startswith("vertex")]
        return np.array(vs).reshape(-1, 3, 3)
    n = int.from_bytes(data[80:84], "little")
    rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    return np.frombuffer(data[84 : 84 + 50 * n], dtype=rec)["v"].astype(float)


def load_obj(path):
    verts, tris = [], []
    for line in open(path, errors="ignore"):
        if line.startswith("v "):
            verts.append(list(map(float, line.split()[1:4])))
        elif line.startswith("f "):
            idx = [int(t.split("/")[0]) for t in line.split()[1:]]
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            tris += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    return np.array(verts)[np.array(tris)]


MESHES = {}


def mesh_of(record, units):
    """(triangles, unit normals) of the record's object in millimetres, the file's frame."""
    source = record["label"]["input"]
    if source not in MESHES:
        if source.endswith(".toml"):
            obj = tomllib.load(open(source, "rb"))["object"]
            path = os.path.join(os.path.dirname(source), obj["mesh"])
            unit = obj.get("units", "mm")
        else:
            path, unit = source, units
        tri = (load_stl(path) if path.lower().endswith(".stl") else load_obj(path)) * SCALE[unit]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area = np.linalg.norm(n, axis=1)
        keep = area > 1e-12
        MESHES[source] = (tri[keep], n[keep] / area[keep, None], area[keep])
    return MESHES[source]


def distance_to_triangles(p, tri):
    """The distance from point `p` to each triangle (closest point by region)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    ab, ac = b - a, c - a
    normal = np.cross(ab, ac)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    height = ((p - a) * normal).sum(1)
    q = p - normal * height[:, None]

    def inside(x, y):
        return (np.cross(y - x, q - x) * normal).sum(1) >= 0

    within = inside(a, b) & inside(b, c) & inside(c, a)

    def segment(x, y):
        t = ((p - x) * (y - x)).sum(1) / np.maximum(((y - x) ** 2).sum(1), 1e-18)
        return np.linalg.norm(x + (y - x) * np.clip(t, 0, 1)[:, None] - p, axis=1)

    edge = np.minimum(np.minimum(segment(a, b), segment(b, c)), segment(c, a))
    return np.where(within, np.abs(height), edge)


def figures(record, units):
    tri, normals, area = mesh_of(record, units)
    axis = np.array(record["palm_pose"])[:3, 2]
    axial = []
    for group in record.get("planned_contacts_mm") or []:
        if not group:
            continue
        d = distance_to_triangles(np.mean(np.array(group), axis=0), tri)
        near = d <= d.min() + 0.5
        n = (normals[near] * area[near, None]).sum(0)
        axial.append(float(n @ axis) / (np.linalg.norm(n) + 1e-12))
    if not axial:
        return None
    lean = [math.degrees(math.asin(min(1.0, abs(x)))) for x in axial]
    return {
        "net": abs(sum(axial)) / len(axial),
        "beyond": sum(x > CONE_DEG for x in lean) / len(lean),
        "steepest": max(lean),
    }


def auc(by, objects, score):
    """AUC against a hold as planned, within objects (ties count a half): order_study's."""
    return term_auc({o: by[o] for o in objects}, score)


def fitted(by, objects, keys):
    grid = [-8, -4, -2, -1, -0.5, -0.25, 0, 0.25, 0.5, 1, 2, 4, 8]
    w = [1.0] + [0.0] * (len(keys) - 1)

    def score_with(w):
        return auc(by, objects, lambda r: sum(wk * r[k] for wk, k in zip(w, keys)))

    best = score_with(w)
    for _ in range(3):
        for i in range(1, len(keys)):
            for g in grid:
                trial = w[:i] + [g] + w[i + 1 :]
                a = score_with(trial)
                if a > best + 1e-12:
                    best, w = a, trial
    return w


def held_out(by, keys):
    objects = sorted(by)
    shuffled = objects[:]
    random.Random(1).shuffle(shuffled)
    folds = [shuffled[i::5] for i in range(5)]
    scores = []
    for fold in folds:
        w = fitted(by, [o for o in objects if o not in fold], keys)
        scores.append(auc(by, fold, lambda r: sum(wk * r[k] for wk, k in zip(w, keys))))
    return sum(scores) / len(scores)


def study(name, path, units):
    by = defaultdict(list)
    for line in open(path):
        r = json.loads(line)
        if r.get("hold_probability") is None or "palm_pose" not in r:
            continue
        f = figures(r, units)
        if f is None:
            continue
        terms = r["grade"]["terms"]
        f.update(
            as_planned_probability=r.get("as_planned_probability", 0.0),
            hp=r["hold_probability"],
            margin=terms["margin"],
            even=terms["even"],
        )
        by[r["object"]].append(f)
    objects = sorted(by)
    n = sum(len(v) for v in by.values())
    print(f"## {name}: {n} candidates of {len(objects)} objects\n")
    print("| figure | AUC within objects (lower first) |\n|---|---|")
    for k in ("net", "beyond", "steepest"):
        print(f"| `{k}` | {auc(by, objects, lambda r: -r[k]):.3f} |")
    print("\n| `net` | candidates | mean hold probability |\n|---|---|---|")
    every = [r for o in objects for r in by[o]]
    for lo, hi in ((0, 0.05), (0.05, 0.15), (0.15, 0.3), (0.3, 1.01)):
        s = [r["hp"] for r in every if lo <= r["net"] < hi]
        mean = f"{sum(s) / len(s):.3f}" if s else "-"
        print(f"| {lo}–{min(hi, 1)} | {len(s)} | {mean} |")
    print("\n| terms, weights tuned on 4 folds | AUC on the fifth, mean of 5 |\n|---|---|")
    for keys in (["margin", "even"], ["margin", "even", "net"], ["margin", "net"]):
        label = " + ".join(f"`{k}`" for k in keys)
        print(f"| {label} | {held_out(by, keys):.3f} |")
    print("\n| object none of whose candidates holds | best hold probability | median `net` | contacts beyond the cone |\n|---|---|---|---|")
    for o in objects:
        rs = by[o]
        if max(r["hp"] for r in rs) < 0.5:
            net = sorted(r["net"] for r in rs)[len(rs) // 2]
            beyond = sum(r["beyond"] for r in rs) / len(rs)
            print(f"| {o} | {max(r['hp'] for r in rs):.3f} | {net:.2f} | {beyond:.0%} |")
    print()


def main(argv):
    units = "mm"
    if "--units" in argv:
        i = argv.index("--units")
        units = argv[i + 1]
        argv = argv[:i] + argv[i + 2 :]
    if not argv:
        sys.exit(__doc__)
    for arg in argv:
        name, _, path = arg.rpartition("=")
        study(name or path, path, units)


if __name__ == "__main__":
    main(sys.argv[1:])
