#!/usr/bin/env python3
"""How far can an order of the labelled candidates go (issue 58)?

    python3 scripts/order_ceiling.py NAME=LABELS.jsonl [NAME=LABELS.jsonl ...] [--model]

Each LABELS.jsonl is a `grasp-sim label` file made with the thesis's order (every `sf_*` 0).
For every file, the first candidate's mean hold probability and the expected candidates checked
before a hold (the first 8 of the order, as `scripts/order_study.py` counts them) under orders
that know more and more of the physics:

- `thesis`: the search order (`grasp_index`);
- `closing`: the nominal check's closing, gravity off: as planned first, then the closing shift
  in whole millimetres, then the search order;
- `nominal`: the nominal check itself: held as planned, held, then the search order;
- `best`: the labelled candidate with the highest hold probability (no order reaches more).

The nominal check is not one of the perturbed samples that give the hold probability, so an
order by it is judged on outcomes it did not see.

With `--model` (needs scikit-learn), also an order by a classifier of "holds" (probability at
least 0.5) from the plan alone: the grade and its terms, the joint angles, the relaxations, and
figures of the planned contacts in the palm's frame (each phalanx's distance from its joint, the
net push of torque-limited fingers). Gradient-boosted trees, scored on objects the fit did not
see: 5 folds over the objects of each file, and each file from a fit on all the others.
"""
import json
import math
import sys
from collections import defaultdict

from order_study import term_auc

RELAXATIONS = [
    "outer_finger_beyond_elevation",
    "curvature_graded",
    "als_off_object",
    "joint_deviation_recorded",
    "palm_backed_off",
    "palm_pitch_clamped",
    "distal_contact_only",
]


def load(path):
    by = defaultdict(list)
    with open(path) as f:
        for line in f:
            r = json.loads(line)
            if "grasp_index" in r and r.get("hold_probability") is not None:
                by[r["object"]].append(r)
    return by


def fidelity(r):
    return r.get("fidelity") or {}


ORDERS = {
    "thesis": lambda r: (-r["grasp_index"],),
    "closing": lambda r: (
        bool(fidelity(r).get("as_planned")),
        -math.floor(fidelity(r).get("shift_mm", math.inf)),
        -r["grasp_index"],
    ),
    "nominal": lambda r: (
        r["verdict"] == "hold" and bool(fidelity(r).get("as_planned")),
        r["verdict"] == "hold",
        -r["grasp_index"],
    ),
    "best": lambda r: (r["hold_probability"], -r["grasp_index"]),
}


def measures(by, key):
    """First candidate's mean hold probability, mean expected checks and the AUC against a hold
    as planned (`as_planned_probability` at least 0.5, within objects) under `key` (higher
    first; candidates `key` cannot tell apart count half)."""
    first, checks = [], []
    for cands in by.values():
        order = sorted(cands, key=key, reverse=True)
        first.append(order[0]["hold_probability"])
        if any(c["hold_probability"] > 0 for c in cands):
            e, none_yet = 0.0, 1.0
            for c in order[:8]:
                e += none_yet
                none_yet *= 1 - c["hold_probability"]
            checks.append(e)
    return sum(first) / len(first), sum(checks) / max(len(checks), 1), term_auc(by, key)


# The thesis hand (assets/hands/thesis.toml): joint 1 at (setback, ±lateral) in the palm's
# frame (x the palm normal, the object at x < 0; z up), phalanx 1 61 mm, finger heights.
FINGERS = [(25.0, 1.0), (0.0, -1.0), (-25.0, 1.0)]
SETBACK, LATERAL, LINK1, OFFSET = 5.8, 36.7, 61.0, 7.0
TORQUE = [0.5, 1.0, 0.5]  # balanced squeeze: the two-finger side at half the thumb's torque


def contacts_in_palm(r):
    """(finger, phalanx, distance from its joint [mm], inward normal (x, y)) per planned
    contact group, in the palm's frame."""
    p = r["palm_pose"]
    rot = [[p[i][j] for j in range(3)] for i in range(3)]
    t = [p[i][3] for i in range(3)]

    def to_palm(c):
        d = [c[i] - t[i] for i in range(3)]
        return [sum(rot[i][j] * d[i] for i in range(3)) for j in range(3)]

    out = []
    for group in r.get("planned_contacts_mm") or []:
        pts = [to_palm(c) for c in group]
        m = [sum(q[i] for q in pts) / len(pts) for i in range(3)]
        f = min(range(3), key=lambda i: abs(m[2] - FINGERS[i][0]))
        s = FINGERS[f][1]
        t1, t2 = (math.radians(a) for a in r["joint_angles_deg"][f])
        d1 = (-math.sin(t1), -s * math.cos(t1))
        n1 = (math.cos(t1), -s * math.sin(t1))  # the inward normal, mirrored for side s
        j1 = (SETBACK, s * LATERAL)
        rel = (m[0] - j1[0], m[1] - j1[1])
        along = rel[0] * d1[0] + rel[1] * d1[1]
        perp = rel[0] * n1[0] + rel[1] * n1[1]
        if abs(perp - OFFSET) < 2.5 and along <= LINK1 + 1.0:
            out.append((f, 1, along, n1))
        else:
            phi = math.pi - t2
            ux, uy = -math.sin(t1), -math.cos(t1)
            ex, ey = ux * math.cos(phi) - uy * math.sin(phi), ux * math.sin(phi) + uy * math.cos(phi)
            d2 = (ex, s * ey)
            n2 = (-ey, s * ex)
            j2 = (j1[0] + LINK1 * d1[0], j1[1] + LINK1 * d1[1])
            rel2 = (m[0] - j2[0], m[1] - j2[1])
            out.append((f, 2, rel2[0] * d2[0] + rel2[1] * d2[1], n2))
    return out


def features(r):
    g = r["grade"]
    x = [g["palm"], g["place"] / max(g["found"], 1)]
    x += [g["terms"][k] for k in sorted(g["terms"])]
    x += [a for f in r["joint_angles_deg"] for a in f]
    x += [1.0 if k in (r.get("relaxations") or []) else 0.0 for k in RELAXATIONS]
    x.append(1.0 if r.get("rules") == "thesis" else 0.0)
    cs = contacts_in_palm(r)
    dist = [max(c[2], 3.0) for c in cs] or [0.0]
    force = [TORQUE[c[0]] / max(c[2], 3.0) for c in cs]
    total = sum(force) or 1.0
    fx = sum(fc * c[3][0] for fc, c in zip(force, cs)) / total
    fy = sum(fc * c[3][1] for fc, c in zip(force, cs)) / total
    per_finger = [sum(fc for fc, c in zip(force, cs) if c[0] == i) for i in range(3)]
    x += [
        len(cs),
        sum(1 for c in cs if c[1] == 1),
        sum(1 for c in cs if c[1] == 2),
        min(dist),
        max(dist),
        sum(force),
        min(per_finger),
        fx,
        abs(fy),
    ]
    return x


def model_scores(train, test):
    from sklearn.ensemble import GradientBoostingClassifier

    xs = [features(r) for cands in train.values() for r in cands]
    ys = [1 if r["hold_probability"] >= 0.5 else 0 for cands in train.values() for r in cands]
    if len(set(ys)) < 2:
        return None
    fit = GradientBoostingClassifier(
        n_estimators=150, max_depth=3, learning_rate=0.05, subsample=0.8, random_state=0
    ).fit(xs, ys)
    scores = {}
    for name, cands in test.items():
        name = name[1] if isinstance(name, tuple) else name
        p = fit.predict_proba([features(r) for r in cands])[:, 1]
        for r, s in zip(cands, p):
            scores[(name, r["grasp_index"])] = float(s)
    return scores


def by_model(scores):
    return lambda r: (scores[(r["object"], r["grasp_index"])], -r["grasp_index"])


def main(argv):
    model = "--model" in argv
    sets = {}
    for a in argv:
        if a == "--model":
            continue
        name, _, path = a.partition("=")
        sets[name] = load(path)
    if not sets:
        sys.exit(__doc__)
    cols = list(ORDERS) + (["model (5 folds)", "model (other files)"] if model else [])
    print("first-candidate mean hold probability / expected checks / AUC, per order")
    print(f"{'labels':10s} {'objects':>7s} " + " ".join(f"{c:>21s}" for c in cols))
    for name, by in sets.items():
        row = [measures(by, key) for key in ORDERS.values()]
        if model:
            objects = sorted(by)
            scores = {}
            for k in range(5):
                held = {o: by[o] for o in objects[k::5]}
                rest = {o: by[o] for o in objects if o not in held}
                fold = model_scores(rest, held)
                if fold is None:
                    scores = None
                    break
                scores.update(fold)
            row.append(measures(by, by_model(scores)) if scores else (math.nan, math.nan, math.nan))
            others = {}
            for other, ob in sets.items():
                # not a file of the same objects (labels of another gravity mode, say)
                if other != name and len(set(ob) & set(by)) * 2 < len(by):
                    others.update({(other, o): c for o, c in ob.items()})
            scores = model_scores(others, by) if others else None
            row.append(measures(by, by_model(scores)) if scores else (math.nan, math.nan, math.nan))
        print(f"{name:10s} {len(by):7d} " + " ".join(f"{f:>8.3f} / {c:4.2f} / {a:.2f}" for f, c, a in row))


if __name__ == "__main__":
    main(sys.argv[1:])
