#!/usr/bin/env python3
"""Rings planned on an arc, checked whole: does a grasp planned on an arc of a ring hold (issue 58)?

    python3 scripts/ring_parts.py gate MESH...
    python3 scripts/ring_parts.py run --binary B --out O [--half DEG] [--sectors N] \
        [--units U] [--jobs N] [--gravity six] MESH...
    python3 scripts/ring_parts.py summary O
    python3 scripts/ring_parts.py crops --binary B [--halves 50,70,90,120,150] O
    python3 scripts/ring_parts.py order LABELS.jsonl O

The planner's axes pass through the object's centroid, which for a ring lies in its hole, so it
never sees the ring's tube as a bar to wrap. This crops a ring to an arc of its tube, plans on
the arc, and checks the arc's grasps on the whole ring (`grasp-sim check --grasps`).

`gate`: a mesh is a ring when the line through its centroid along the principal axis of the
largest moment meets no triangle, and each line along the other two axes crosses the surface on
both sides of the centroid, an even number of times on each (the centroid is outside the
material, enclosed by it in the ring's plane). Mass properties are the closed surface's (signed
tetrahedra about the vertices' mean).

`run`: for each ring MESH (others are skipped) and each of `--sectors` (at most 4) directions in
the ring's plane (the first along the largest-variance axis of the vertices, then every 90
degrees), keeps the triangles whose centroid lies within `--half` degrees of the direction
seen from the ring's axis, closes each cut with a fan about its outline's mean, and writes
O/parts/NAME_kK.stl (in the mesh's own frame, so its grasps are the ring's). Then `B label
O/parts --grasps 4 --samples 1` plans each arc, and `B check --grasps ... --samples 8` checks
each arc's picks on the whole ring (O/grasps/NAME.jsonl and NAME.out.jsonl); O/whole.jsonl is
`B label` of the rings themselves (`--grasps 1 --samples 8`, their first candidate). Gravity is
`down` (or `--gravity six`) in the whole ring's frame for both: the arc's grasps are given
grasps there, named by the arc's axis, which on the whole ring is the whole ring's. `--units`
scales the meshes to mm first (written so into O/whole and O/parts).

`summary` (also the end of `run`): per ring, the whole ring's first candidate's hold
probability and each arc's first grasp's; the means over the rings planned both ways and over
the rings each arc plans; and the arc grasps' closings (as planned, shift, turn). Meshes are
binary or ASCII STL, or OBJ. Needs numpy.

`crops` (after `run`): checks each arc's grasps again on wider crops of the whole ring about the
same direction (`--halves`, degrees; written into O/crops), and prints, per crop and for the
whole ring, the nominal closings kept as planned and their median shift; then the arc grasps by
where the palm sits on the tube (on its outer rim, in the hole, on a face of the ring's plane):
their hold probability on the whole ring and their closings as planned on the arc and on the
whole.

`order` (after `run`): what the search's closing order (`[sim] order_by_closing`) would check
first, from the nominal closings already run. LABELS.jsonl is `grasp-sim label` of the whole
rings with several grasps each (`--grasps 16`). Per ring, the first of: the whole ring's picks as
the tool orders them today (its first candidate if its closing kept the plan, else the closing
kept as planned, then the least shift), the first arc's first grasp, and the same closing order
over the arc grasps, and over the arc grasps and the whole ring's picks together; each one's
hold probability, and their means.
"""
import argparse
import collections
import json
import math
import os
import statistics
import struct
import subprocess
import sys

import numpy as np

from squeeze_study import load_obj, load_stl


def load_mesh(path):
    return load_obj(path) if path.lower().endswith(".obj") else load_stl(path)


def write_stl(path, tris):
    with open(path, "wb") as f:
        f.write(b"\0" * 80)
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            n = np.cross(t[1] - t[0], t[2] - t[0])
            length = np.linalg.norm(n)
            n = n / length if length > 0 else n
            f.write(struct.pack("<12fH", *n, *t[0], *t[1], *t[2], 0))


def mass_axes(tris):
    """Centroid and principal axes (columns, moments ascending) of a closed surface."""
    o = tris.reshape(-1, 3).mean(0)
    a, b, c = tris[:, 0] - o, tris[:, 1] - o, tris[:, 2] - o
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6
    if vol.sum() < 0:
        vol, b, c = -vol, c, b
    total = vol.sum()
    cen = (vol[:, None] * (a + b + c) / 4).sum(0) / total
    p = np.stack([a, b, c], 1)
    s = p.sum(1)
    second = np.einsum("t,tki,tkj->ij", vol, p, p) + np.einsum("t,ti,tj->ij", vol, s, s)
    cov = second / 20 / total - np.outer(cen, cen)
    inertia = np.trace(cov) * np.eye(3) - cov
    _, axes = np.linalg.eigh(inertia)
    return cen + o, axes


def crossings(tris, p, d):
    """Crossings of the line p + t d with the triangles, on the side t > 0 and t < 0."""
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    h = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, h)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
    s = p - tris[:, 0]
    u = inv * np.einsum("ij,ij->i", s, h)
    q = np.cross(s, e1)
    v = inv * (q @ d)
    t = inv * np.einsum("ij,ij->i", e2, q)
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1)
    return int(np.sum(hit & (t > 0))), int(np.sum(hit & (t < 0)))


def is_ring(tris):
    cen, axes = mass_axes(tris)
    if sum(crossings(tris, cen, axes[:, 2])) != 0:
        return False
    for k in (0, 1):
        ahead, behind = crossings(tris, cen, axes[:, k])
        if min(ahead, behind) == 0 or ahead % 2 or behind % 2:
            return False
    return True


def arc(tris, half_deg, k):
    """The triangles within half_deg of direction k (k quarter turns), each cut closed by a fan."""
    verts = tris.reshape(-1, 3)
    mean = verts.mean(0)
    _, vecs = np.linalg.eigh(np.cov((verts - mean).T))
    normal, e1, e2 = vecs[:, 0], vecs[:, 2], vecs[:, 1]
    ang = math.pi / 2 * k
    d = math.cos(ang) * e1 + math.sin(ang) * e2
    cen = tris.mean(1) - mean
    lean = np.degrees(np.arctan2(cen @ np.cross(normal, d), cen @ d))
    keep = tris[np.abs(lean) <= half_deg]
    key = lambda p: tuple(np.round(p, 6))
    edges = collections.Counter()
    for t in keep:
        for i in range(3):
            edges[(key(t[i]), key(t[(i + 1) % 3]))] += 1
    nxt = {a: b for (a, b) in edges if (b, a) not in edges}
    caps, seen = [], set()
    for start in list(nxt):
        if start in seen:
            continue
        loop, p = [start], nxt[start]
        seen.add(start)
        while p != start and p in nxt and p not in seen:
            loop.append(p)
            seen.add(p)
            p = nxt[p]
        pts = np.array(loop)
        m = pts.mean(0)
        caps += [np.array([pts[(i + 1) % len(pts)], pts[i], m]) for i in range(len(pts))]
    return np.array(list(keep) + caps)


def records(path):
    return [json.loads(l) for l in open(path) if l.strip()]


def run(args):
    scale = {"mm": 1.0, "cm": 10.0, "m": 1000.0}[args.units]
    rings = [m for m in args.meshes if is_ring(load_mesh(m))]
    print(f"{len(rings)} of {len(args.meshes)} meshes are rings", file=sys.stderr)
    parts, whole, grasps = (os.path.join(args.out, d) for d in ("parts", "whole", "grasps"))
    for d in (parts, whole, grasps):
        os.makedirs(d, exist_ok=True)
    for m in rings:
        name = os.path.splitext(os.path.basename(m))[0]
        tris = load_mesh(m) * scale
        write_stl(os.path.join(whole, name + ".stl"), tris)
        for k in range(args.sectors):
            write_stl(os.path.join(parts, f"{name}_k{k}.stl"), arc(tris, args.half, k))
    b = args.binary
    label = [b, "label", "--jobs", str(args.jobs)]
    gravity = ["--gravity", args.gravity]
    quiet = {"check": True, "stderr": subprocess.DEVNULL}
    whole_out = os.path.join(args.out, "whole.jsonl")
    subprocess.run(label + gravity + [whole, "--grasps", "1", "--samples", "8", "--out", whole_out], **quiet)
    parts_out = os.path.join(args.out, "parts.jsonl")
    subprocess.run(label + [parts, "--grasps", "4", "--samples", "1", "--out", parts_out], **quiet)
    by = collections.defaultdict(list)
    for r in records(parts_out):
        if "palm_pose" in r:
            r["part"], r["object"] = r["object"], r["object"].rsplit("_k", 1)[0]
            by[r["object"]].append(r)
    for name, rs in sorted(by.items()):
        g = os.path.join(grasps, name + ".jsonl")
        with open(g, "w") as f:
            f.writelines(json.dumps(r) + "\n" for r in rs)
        ring = os.path.join(whole, name + ".stl")
        cmd = [b, "check", "--grasps", g, ring, "--samples", "8"] + gravity
        out = subprocess.run(cmd, capture_output=True, text=True)
        with open(os.path.join(grasps, name + ".out.jsonl"), "w") as f:
            f.write(out.stdout)
    summary(args.out)


def summary(out):
    """The table and the means of a finished `run` in `out`."""
    grasps = os.path.join(out, "grasps")
    names = sorted(os.path.splitext(f)[0] for f in os.listdir(os.path.join(out, "whole")))
    lines = records(os.path.join(out, "whole.jsonl"))
    first_whole = {r["object"]: r for r in lines if "hold_probability" in r}
    print("| ring | whole: first candidate | arcs: each arc's first |")
    print("|---|---|---|")
    wp, ap, fid = [], [], []
    by_arc = collections.defaultdict(list)
    for name in names:
        checked = []
        given = os.path.join(grasps, name + ".jsonl")
        if os.path.exists(given):
            # `check` writes one record per line of its input, in order.
            pairs = zip(records(given), records(os.path.join(grasps, name + ".out.jsonl")))
            checked = [dict(r, part=g["part"]) for g, r in pairs if "hold_probability" in r]
        w = first_whole.get(name)
        firsts = [r for r in checked if r["grasp_index"] == 0]
        for r in firsts:
            by_arc[r["part"].rsplit("_k", 1)[1]].append(r["hold_probability"])
        shown = ", ".join(str(r["hold_probability"]) for r in firsts) or "no plan"
        print(f"| {name} | {w['hold_probability'] if w else 'no plan'} | {shown} |")
        if w and firsts:
            wp.append(w["hold_probability"])
            ap.append(firsts[0]["hold_probability"])
        fid += [r["fidelity"] for r in checked]
    if wp:
        mean_w, mean_a = sum(wp) / len(wp), sum(ap) / len(ap)
        print(f"\nrings planned both ways: {len(wp)}; first candidate whole {mean_w:.3f}, the first arc's first {mean_a:.3f}")
    for k, ps in sorted(by_arc.items()):
        print(f"arc {k}: planned on {len(ps)} rings, its first grasp {sum(ps) / len(ps):.3f}")
    if fid:
        shift = statistics.median(f["shift_mm"] for f in fid)
        turn = statistics.median(f["turn_deg"] for f in fid)
        planned = sum(f["as_planned"] for f in fid)
        print(f"arc grasps checked: {len(fid)}; nominal closings as planned {planned}; "
              f"median shift {shift:.1f} mm, turn {turn:.1f} deg")


def tube_frame(tris, k):
    """The ring's plane normal, arc direction k and tube radius, as `arc` takes them."""
    verts = tris.reshape(-1, 3)
    mean = verts.mean(0)
    _, vecs = np.linalg.eigh(np.cov((verts - mean).T))
    normal, e1, e2 = vecs[:, 0], vecs[:, 2], vecs[:, 1]
    ang = math.pi / 2 * k
    v = verts - mean
    radial = np.linalg.norm(v - np.outer(v @ normal, normal), axis=1)
    return mean, normal, math.cos(ang) * e1 + math.sin(ang) * e2, (radial.min() + radial.max()) / 2


def placement(tris, k, palm_pose):
    """Where the palm sits about the tube: `rim` (outside), `hole` or `face`."""
    mean, normal, _, radius = tube_frame(tris, k)
    p = np.array(palm_pose)[:3, 3] - mean
    out = np.linalg.norm(p - (p @ normal) * normal) - radius
    a = abs(math.degrees(math.atan2(p @ normal, out)))
    return "rim" if a < 45 else "hole" if a > 135 else "face"


def crops(args):
    grasps = os.path.join(args.out, "grasps")
    cdir = os.path.join(args.out, "crops")
    os.makedirs(cdir, exist_ok=True)
    halves = [float(h) for h in args.halves.split(",")]
    closed = collections.defaultdict(list)
    places = collections.defaultdict(list)
    for f in sorted(os.listdir(grasps)):
        if f.endswith(".out.jsonl"):
            continue
        name = f[: -len(".jsonl")]
        given = records(os.path.join(grasps, f))
        tris = load_mesh(os.path.join(args.out, "whole", name + ".stl"))
        for g, r in zip(given, records(os.path.join(grasps, name + ".out.jsonl"))):
            if "fidelity" not in r:
                continue
            closed["whole"].append(r["fidelity"])
            k = int(g["part"].rsplit("_k", 1)[1])
            places[placement(tris, k, g["palm_pose"])].append((r, g["fidelity"]["as_planned"]))
        for part in sorted({g["part"] for g in given}):
            k = int(part.rsplit("_k", 1)[1])
            mine = [g for g in given if g["part"] == part]
            gfile = os.path.join(cdir, part + ".jsonl")
            with open(gfile, "w") as fh:
                fh.writelines(json.dumps(g) + "\n" for g in mine)
            for h in halves:
                mesh = os.path.join(cdir, f"{part}_h{h:g}.stl")
                write_stl(mesh, arc(tris, h, k))
                cmd = [args.binary, "check", "--grasps", gfile, mesh, "--samples", "1"]
                out = subprocess.run(cmd, capture_output=True, text=True).stdout
                closed[f"+-{h:g} deg"] += [r["fidelity"] for r in map(json.loads, out.splitlines()) if "fidelity" in r]
    print("| checked on | grasps | nominal closings as planned | median shift [mm] |")
    print("|---|---|---|---|")
    for key, fs in closed.items():
        shift = statistics.median(f["shift_mm"] for f in fs)
        print(f"| {key} | {len(fs)} | {sum(f['as_planned'] for f in fs)} | {shift:.1f} |")
    print("\n| palm | grasps | hold probability on the whole | as planned: arc / whole |")
    print("|---|---|---|---|")
    for where, rs in sorted(places.items()):
        p = sum(r["hold_probability"] for r, _ in rs) / len(rs)
        whole = sum(r["fidelity"]["as_planned"] for r, _ in rs)
        print(f"| {where} | {len(rs)} | {p:.3f} | {sum(a for _, a in rs)} / {whole} |")


def closing_order(rs):
    """The candidate the closings' order puts first: kept as planned, then the least shift."""
    return min(rs, key=lambda r: (not r["fidelity"]["as_planned"], r["fidelity"]["shift_mm"]))


def order(args):
    whole = collections.defaultdict(list)
    for r in records(args.labels):
        if "hold_probability" in r:
            whole[r["object"]].append(r)
    grasps = os.path.join(args.out, "grasps")
    rows = []
    for f in sorted(os.listdir(grasps)):
        if not f.endswith(".out.jsonl"):
            continue
        name = f[: -len(".out.jsonl")]
        given = records(os.path.join(grasps, name + ".jsonl"))
        arcs = [dict(r, part=g["part"]) for g, r in zip(given, records(os.path.join(grasps, f)))
                if "hold_probability" in r]
        if not arcs:
            continue
        first_part = min(r["part"] for r in arcs)
        first = min((r for r in arcs if r["part"] == first_part), key=lambda r: r["grasp_index"])
        kept = first["fidelity"]["as_planned"]
        w = sorted(whole.get(name, []), key=lambda r: r["grasp_index"])
        today = None
        if w:
            today = w[0] if w[0]["fidelity"]["as_planned"] else closing_order(w)
        rows.append((name, today and today["hold_probability"], first["hold_probability"],
                     (first if kept else closing_order(arcs))["hold_probability"],
                     (first if kept else closing_order(arcs + w))["hold_probability"]))
    heads = ["whole ring, the tool today", "first arc's first grasp",
             "closings' order over the arc grasps", "closings' order over arcs and whole"]
    print("| ring | " + " | ".join(heads) + " |")
    print("|---|" + "---|" * len(heads))
    for r in rows:
        print(f"| {r[0]} | " + " | ".join("no plan" if x is None else f"{x:.3f}" for x in r[1:]) + " |")
    both = [r for r in rows if r[1] is not None]
    for i, h in enumerate(heads, 1):
        every = [r[i] for r in rows if r[i] is not None]
        print(f"{h}: {sum(every) / len(every):.3f} over {len(every)} rings; "
              f"{sum(r[i] for r in both) / max(1, len(both)):.3f} over the {len(both)} planned both ways")


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    g = sub.add_parser("gate")
    g.add_argument("meshes", nargs="+")
    sub.add_parser("summary").add_argument("out")
    c = sub.add_parser("crops")
    c.add_argument("--binary", required=True)
    c.add_argument("--halves", default="50,70,90,120,150")
    c.add_argument("out")
    o = sub.add_parser("order")
    o.add_argument("labels")
    o.add_argument("out")
    r = sub.add_parser("run")
    r.add_argument("--binary", required=True)
    r.add_argument("--out", required=True)
    r.add_argument("--half", type=float, default=50.0)
    r.add_argument("--sectors", type=int, default=2, choices=[1, 2, 3, 4])
    r.add_argument("--jobs", type=int, default=2)
    r.add_argument("--gravity", choices=["down", "six"], default="down")
    r.add_argument("--units", choices=["mm", "cm", "m"], default="mm")
    r.add_argument("meshes", nargs="+")
    args = ap.parse_args()
    if args.cmd == "summary":
        summary(args.out)
    elif args.cmd == "crops":
        crops(args)
    elif args.cmd == "order":
        order(args)
    elif args.cmd == "gate":
        for m in args.meshes:
            print(("ring " if is_ring(load_mesh(m)) else "     ") + m)
    else:
        run(args)


if __name__ == "__main__":
    main()
