#!/usr/bin/env python3
"""How well the planner's order predicts a hold, before and after tuning (issue 58).

    python3 scripts/order_study.py LABELS.jsonl TUNE_DIR FIGURE.svg [--other OTHER.jsonl]

LABELS.jsonl is a `grasp-sim label` file made with the thesis's order (every `sf_*` factor 0);
TUNE_DIR the output of `grasp-sim tune --labels LABELS.jsonl --out TUNE_DIR` (its tune.json
gives each fold's factors and the objects it held out). Prints, for the thesis's order and for
the tuned one on the folds it did not tune on: the first candidate's mean hold probability,
the expected candidates checked before a hold, the AUC of the order against a hold as planned
(within objects), in the order tune.json measured (`search`: the first by the grade, then by the
nominal closings, as a run's search checks them; `grade`: the grade alone, the AUC by its
score), the same for the grade alone, each term's own AUC, and the ceiling (the best labelled candidate of the
first axis plan, and of any). Writes FIGURE.svg: each labelled candidate's hold probability
against its score's rank within its object (0: first), thesis beside tuned (held out).
With --other, also the same measures on OTHER.jsonl, labels of objects the tuning never saw,
under the factors tuned on every object of LABELS.jsonl.
"""
import json
import math
import statistics
import sys
from collections import defaultdict

TERMS = ["centred", "opposed", "spread", "margin", "even"]


def score(c, f):
    g = c["grade"]
    return -g["place"] / max(g["found"], 1) + sum(f.get("sf_" + t, 0.0) * g["terms"][t] for t in TERMS)


def by_grade(cands, f):
    """The candidates in the order the factors give: axis plans in search order, by score."""
    return sorted(cands, key=lambda c: (c["grade"]["axis_plan"], -score(c, f), c["grade"]["place"]))


def ranked(cands, f, order="grade"):
    """The candidates in `order`: by the grade, or as a run's search checks them (`search`):
    the first by the grade first if its nominal closing kept the plan; the others, and the
    first if it did not as one off plan, as planned first, then by the closing's shift in whole
    millimetres, then by the grade (`grasp-sim tune --order search`)."""
    g = by_grade(cands, f)
    if order != "search" or any("fidelity" not in c for c in g):
        return g
    first_held = g[0]["fidelity"]["as_planned"]

    def key(i):
        fid = g[i]["fidelity"]
        return (not (i == 0 and first_held), not (fid["as_planned"] and i > 0), math.floor(fid["shift_mm"]), i)
    return [g[i] for i in sorted(range(len(g)), key=key)]


def measures(by, factors_of, order="grade"):
    first, checks, pairs, wins = [], [], 0, 0.0
    for name, cands in by.items():
        f = factors_of(name)
        order_ = ranked(cands, f, order)
        first.append(order_[0]["hold_probability"])
        if any(c["hold_probability"] > 0 for c in cands):
            e, none_yet = 0.0, 1.0
            for c in order_[:8]:
                e += none_yet
                none_yet *= 1 - c["hold_probability"]
            checks.append(e)
        if order == "search":
            s = [(-k, c["as_planned_probability"] >= 0.5) for k, c in enumerate(order_)]
        else:
            s = [(score(c, f), c["as_planned_probability"] >= 0.5) for c in cands]
        for sa, pa in s:
            for sb, pb in s:
                if pa and not pb:
                    pairs += 1
                    wins += 1 if sa > sb else 0.5 if sa == sb else 0
    return statistics.mean(first), statistics.mean(checks), wins / pairs if pairs else float("nan")


def term_auc(by, key):
    pairs, wins = 0, 0.0
    for cands in by.values():
        for a in cands:
            for b in cands:
                if a["as_planned_probability"] >= 0.5 and b["as_planned_probability"] < 0.5:
                    pairs += 1
                    wins += 1 if key(a) > key(b) else 0.5 if key(a) == key(b) else 0
    return wins / pairs if pairs else float("nan")


def figure(by, factors_of, path, order="grade"):
    w, h, pad = 720, 300, 40
    panels = [(f"thesis's factors, the {order} order", lambda n: {}), (f"tuned, held out, the {order} order", factors_of)]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="11">',
           f'<rect width="{w}" height="{h}" fill="white"/>']
    pw = (w - 3 * pad) / 2
    for k, (title, fo) in enumerate(panels):
        x0 = pad + k * (pw + pad)
        y0, ph = 30, h - 70
        out.append(f'<text x="{x0 + pw / 2}" y="18" text-anchor="middle">{title}</text>')
        out.append(f'<rect x="{x0}" y="{y0}" width="{pw}" height="{ph}" fill="none" stroke="#888"/>')
        means = defaultdict(list)
        for name, cands in by.items():
            ranks = ranked(cands, fo(name), order)
            n = len(ranks)
            for i, c in enumerate(ranks):
                r = i / max(n - 1, 1)
                means[min(int(r * 4), 3)].append(c["hold_probability"])
                x = x0 + r * pw
                y = y0 + (1 - c["hold_probability"]) * ph
                colour = "#c33" if i == 0 else "#36c"
                out.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{3 if i == 0 else 1.6}" fill="{colour}" fill-opacity="0.45"/>')
        for q, v in sorted(means.items()):
            x = x0 + (q + 0.5) / 4 * pw
            y = y0 + (1 - statistics.mean(v)) * ph
            out.append(f'<rect x="{x - 12:.1f}" y="{y - 1.5:.1f}" width="24" height="3" fill="black"/>')
        out.append(f'<text x="{x0 + pw / 2}" y="{h - 20}" text-anchor="middle">rank within the object (0: first, red)</text>')
        out.append(f'<text x="{x0 - 6}" y="{y0 + 4}" text-anchor="end">1</text>')
        out.append(f'<text x="{x0 - 6}" y="{y0 + ph}" text-anchor="end">0</text>')
    out.append(f'<text x="{w / 2}" y="{h - 5}" text-anchor="middle">hold probability of each labelled candidate; bars: the mean per quarter of the ranks</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def load(path):
    by = defaultdict(list)
    for line in open(path):
        r = json.loads(line)
        if "hold_probability" in r and "grade" in r:
            by[r["object"]].append(r)
    return by


def main(argv):
    other = None
    if "--other" in argv:
        i = argv.index("--other")
        other = argv[i + 1]
        argv = argv[:i] + argv[i + 2:]
    if len(argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    by = load(argv[1])
    tune = json.load(open(f"{argv[2]}/tune.json"))
    fold_of = {}
    for fold in tune["folds"]:
        for name in fold["held_out"]:
            fold_of[name] = fold["factors"]
    held = lambda name: fold_of.get(name, {})  # noqa: E731
    n = sum(len(c) for c in by.values())
    order = tune.get("order", "grade")
    print(f"{len(by)} objects, {n} labelled candidates, objective {tune['objective']}, {len(tune['folds'])} folds, "
          f"the {order} order")
    rows = [("thesis's factors", lambda _: {}, order), ("tuned, held out", held, order)]
    if order == "search":
        rows.append(("the grade alone, thesis's factors", lambda _: {}, "grade"))
    for label, fo, o in rows:
        first, checks, auc = measures(by, fo, o)
        print(f"{label}: first candidate's mean hold probability {first:.3f}, expected checks to a hold "
              f"{checks:.2f}, AUC against a hold as planned {auc:.3f}")
    for t in TERMS:
        print(f"term {t}: AUC alone {term_auc(by, lambda c: c['grade']['terms'][t]):.3f}")
    print(f"the palm grade: AUC {term_auc(by, lambda c: c['grade']['palm'] or 0.0):.3f}")
    best0 = statistics.mean(max(c["hold_probability"] for c in cands
                                if c["grade"]["axis_plan"] == min(x["grade"]["axis_plan"] for x in cands))
                            for cands in by.values())
    best = statistics.mean(max(c["hold_probability"] for c in cands) for cands in by.values())
    print(f"ceiling: the best labelled candidate of the first axis plan {best0:.3f}, of any {best:.3f}")
    print(f"factors tuned on every object: {tune['factors']}")
    if other:
        by2 = load(other)
        print(f"{other}: {len(by2)} objects the tuning never saw, {sum(len(c) for c in by2.values())} candidates")
        for label, fo in [("thesis's order", lambda _: {}), ("tuned on every object", lambda _: tune["factors"])]:
            first, checks, auc = measures(by2, fo, order)
            print(f"  {label}: first candidate {first:.3f}, expected checks {checks:.2f}, AUC {auc:.3f}")
    figure(by, held, argv[3], order)
    print(f"wrote {argv[3]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
