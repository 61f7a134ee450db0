#!/usr/bin/env python3
"""Would the order's terms do better if the candidates of every axis plan competed? (issue 58)

    python3 scripts/order_across_axes.py LABELS.jsonl [--folds K]

Reads a `grasp-sim label` file and, for each objective of `grasp-sim tune --labels` (first,
checks, auc), tunes the five significance factors by the same coordinate descent with the same
folds (a SHA-256 of the object's name), two ways:

  - within: the planner's order today (src/plan/order.rs): axis plans in search order, each
    axis's candidates by falling score; this reproduces `tune --labels`'s held-out figures;
  - across: one score over every labelled candidate of the object, the axis plan's rank one
    more term (`- w * axis_plan`, w from 2, which is the thesis's order, tuned with the others), so a
    later axis's candidate can be checked first.

Prints, per objective and way, the held-out mean hold probability of the first candidate and
the expected checks to a hold (at most 8), each object scored by the factors tuned without its
fold, beside the thesis's order and the labelled ceilings (the best candidate of the first axis
plan, of any). A study tool: the planner has no `across` order.
"""
import hashlib
import json
import math
import sys
from collections import defaultdict

MAX_CHECKED = 8
TERMS = ["centred", "opposed", "spread", "margin", "even"]
N = len(TERMS)


def load(path):
    objs = defaultdict(list)
    for line in open(path):
        v = json.loads(line)
        if "error" in v or v.get("hold_probability") is None:
            continue
        g = v["grade"]
        objs[v["object"]].append(dict(
            axis=g["axis_plan"], place=g["place"], found=g["found"],
            t=[g["terms"][k] for k in TERMS],
            hold=v["hold_probability"], ap=v["as_planned_probability"]))
    return dict(objs)


def fold_of(name, k):
    d = hashlib.sha256(name.encode()).digest()
    return int.from_bytes(d[:8], "little") % k


def score(c, x, across):
    s = -c["place"] / max(c["found"], 1) + sum(a * b for a, b in zip(x[:N], c["t"]))
    return s - x[N] * c["axis"] if across else s


def ordered(cands, x, across):
    if across:
        return sorted(cands, key=lambda c: (-score(c, x, across), c["axis"], c["place"]))
    return sorted(cands, key=lambda c: (c["axis"], -score(c, x, across), c["place"]))


def measure(objs, names, x, across):
    first = checks = 0.0
    holding = 0
    pairs = wins = 0.0
    for n in names:
        cands = objs[n]
        o = ordered(cands, x, across)
        first += o[0]["hold"]
        if any(c["hold"] > 0 for c in cands):
            e, none = 0.0, 1.0
            for c in o[:MAX_CHECKED]:
                e += none
                none *= 1 - c["hold"]
            checks += e
            holding += 1
        sc = [(score(c, x, across), c["ap"] >= 0.5) for c in cands]
        for sa, pa in sc:
            for sb, pb in sc:
                if pa and not pb:
                    pairs += 1
                    wins += 1 if sa > sb else 0.5 if sa == sb else 0
    return dict(first=first / len(names), checks=checks / max(holding, 1),
                auc=wins / pairs if pairs else float("nan"))


def value(m, objective):
    if objective == "first":
        return m["first"]
    if objective == "checks":
        return -m["checks"]
    return 0.5 if math.isnan(m["auc"]) else m["auc"]


def descend(objs, names, objective, across):
    """Coordinate descent as src/tune/order.rs's `descend`, from the thesis's order."""
    x = [0.0] * N + [2.0 if across else 0.0]
    dims = range(N + 1 if across else N)
    best = value(measure(objs, names, x, across), objective)
    step = 8.0
    while step >= 0.125:
        improved, rounds = True, 0
        while improved and rounds < 50:
            improved = False
            rounds += 1
            for k in dims:
                for d in (1, -1):
                    y = list(x)
                    y[k] = max(-100.0, min(100.0, y[k] + d * step))
                    v = value(measure(objs, names, y, across), objective)
                    if v > best + 1e-12:
                        best, x, improved = v, y, True
        step /= 2
    return x


def held_out(objs, objective, across, folds):
    names = sorted(objs)
    per = {}
    for f in range(folds):
        train = [n for n in names if fold_of(n, folds) != f]
        x = descend(objs, train, objective, across)
        for n in names:
            if fold_of(n, folds) == f:
                per[n] = x
    first = sum(ordered(objs[n], per[n], across)[0]["hold"] for n in names) / len(names)
    holding = [n for n in names if any(c["hold"] > 0 for c in objs[n])]
    checks = sum(measure(objs, [n], per[n], across)["checks"] for n in holding) / len(holding)
    return first, checks


def main(argv):
    args = argv[1:]
    folds = 5
    if "--folds" in args:
        i = args.index("--folds")
        folds = int(args[i + 1])
        del args[i:i + 2]
    if len(args) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    objs = load(args[0])
    names = sorted(objs)
    thesis = measure(objs, names, [0.0] * (N + 1), False)
    lowest = {n: min(c["axis"] for c in objs[n]) for n in names}
    ceiling_first = sum(max(c["hold"] for c in objs[n] if c["axis"] == lowest[n]) for n in names) / len(names)
    ceiling_any = sum(max(c["hold"] for c in objs[n]) for n in names) / len(names)
    print(f"{len(names)} objects, {sum(map(len, objs.values()))} candidates, {folds} folds")
    print(f"thesis's order: first {thesis['first']:.3f}, checks {thesis['checks']:.3f}; "
          f"ceilings: first axis plan {ceiling_first:.3f}, any {ceiling_any:.3f}")
    print("| objective | within: first | within: checks | across: first | across: checks |")
    print("|---|---|---|---|---|")
    for objective in ("first", "checks", "auc"):
        w = held_out(objs, objective, False, folds)
        a = held_out(objs, objective, True, folds)
        print(f"| {objective} | {w[0]:.3f} | {w[1]:.3f} | {a[0]:.3f} | {a[1]:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
