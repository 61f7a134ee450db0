#!/usr/bin/env python3
"""Which features of a labelled candidate predict a hold as planned, set by set (issue 58).

    python3 scripts/label_features.py LABELS.jsonl [MORE.jsonl ...]

Each LABELS file is a `grasp-sim label` file. For every feature a label line gives before any
physics (the order's five terms, the thesis's palm and finger grades, the planned joint angles,
the phalanges with a planned contact, the rules beyond the thesis it needed), prints its AUC
within objects against "held as planned" (`as_planned_probability` >= 0.5): over every pair of
candidates of one object, one held as planned and one not, the fraction the feature ranks the
held one higher (ties count half). 0.5 is chance; a feature that helps a planner on objects it
never saw is above 0.5 in every set.
"""
import json
import sys
from collections import defaultdict

TERMS = ["centred", "opposed", "spread", "margin", "even"]


def features(line):
    """The features of one label line, each oriented so that higher should mean better."""
    g = line["grade"]
    angles = line["joint_angles_deg"]
    fingers = [f for f in g["fingers"] if f.get("combined") is not None]
    mean = lambda key: sum(f[key] for f in fingers) / len(fingers) if fingers else 0.0  # noqa: E731
    out = {f"term {t}": g["terms"][t] for t in TERMS}
    out.update({
        "palm grade": g["palm"],
        "thesis place (earlier first)": -g["place"],
        "finger grade, mean": mean("combined"),
        "finger curvature grade, mean": mean("curvature"),
        "finger diameter grade, mean": mean("diameter"),
        "joint 1 angles, sum": sum(a[0] for a in angles),
        "joint 2 angles, sum": sum(a[1] for a in angles),
        "joint 2 angle, least": min(a[1] for a in angles),
        "phalanges with a planned contact": sum(1 for c in line["planned_contacts_mm"] if c),
        "rules beyond the thesis (fewer first)": -len(line.get("relaxations") or []),
    })
    return out


def load(path):
    by = defaultdict(list)
    with open(path) as f:
        for text in f:
            line = json.loads(text)
            if line.get("as_planned_probability") is None or "grade" not in line:
                continue
            by[line["object"]].append((features(line), line["as_planned_probability"] >= 0.5))
    return by


def auc(by, key):
    wins, pairs = 0.0, 0
    for cands in by.values():
        held = [f[key] for f, h in cands if h]
        not_held = [f[key] for f, h in cands if not h]
        for a in held:
            for b in not_held:
                pairs += 1
                wins += 1.0 if a > b else 0.5 if a == b else 0.0
    return (wins / pairs if pairs else float("nan")), pairs


def main(paths):
    if not paths:
        print(__doc__, file=sys.stderr)
        return 2
    sets = [(p, load(p)) for p in paths]
    keys = list(next(f for _, by in sets for c in by.values() for f, _ in c).keys())
    print("| feature | " + " | ".join(p for p, _ in sets) + " |")
    print("|---|" + "---|" * len(sets))
    for k in keys:
        cells = []
        for _, by in sets:
            a, n = auc(by, k)
            cells.append(f"{a:.3f} ({n} pairs)")
        print(f"| {k} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
