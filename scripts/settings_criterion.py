#!/usr/bin/env python3
"""The criterion for a cheaper physics setting (docs/SIM.md, "One criterion for a cheaper setting").

    python3 scripts/settings_criterion.py --base BASE.jsonl --null N1.jsonl --null N2.jsonl ...
        [--mujoco MJ.json] NAME=CANDIDATE.jsonl ...

Each .jsonl is one run of `cargo run --release --example protocols -- --only fast --six
--set max_checked=1 [--set KEY=VALUE] --jsonl FILE SCENARIO...` (one line per scenario, six
directions each). The two questions of a check are judged apart (issue 55): the null set of
verdicts is the union of the directions whose verdict a null perturbation (a 1 ppm change of a
constant) changes against BASE, and the null set of fidelity the union of those whose
`as_planned` a null changes. A candidate passes the first half of the criterion when every
direction whose verdict it changes is in the first, and every one whose `as_planned` it changes
in the second. The
second half, agreement with MuJoCo not dropping, takes `--mujoco`: the file
`scripts/engine_agreement.py --json` writes, whose variant `base` is the defaults and whose
other variants are named as the candidates here. Prints a Markdown table: changed, changed outside the
null set, steps and wall time against BASE, MuJoCo agreement, pass/fail. `--substeps
NAME=CLOSE/HOLD` gives a run's substeps per step while closing and while holding (default
8/8, the defaults' `solver_iterations`); the table then also gives the substeps in all against
BASE's, the cost of the physics as the solver counts it (a substep costs about the same in
either phase), which no load can change.
"""
import argparse
import json
import sys


def load(path, substeps=(8, 8)):
    """({(scenario, direction index): verdict}, {(scenario, direction index): as_planned}),
    total steps, total wall [ms], total substeps (`substeps`: per step while closing, while
    holding). A file written before issue 55 has no `as_planned`: its fidelity is unknown
    (None) and compares equal to itself only."""
    verdicts, planned, steps, wall, sub = {}, {}, 0, 0.0, 0.0
    with open(path) as f:
        for line in f:
            d = json.loads(line)
            sim = d["sim"]
            n = sim.get("steps") or 0
            steps += n
            wall += sim.get("wall_ms") or 0.0
            dirs = sim.get("directions") or []
            # The closing's share of the steps: closed_at_s against the time simulated.
            t_close = dirs[0]["closed_at_s"] if dirs else 0.0
            t_all = t_close + sum(dr["decided_at_s"] for dr in dirs)
            closing = n * t_close / t_all if t_all > 0 else 0.0
            sub += closing * substeps[0] + (n - closing) * substeps[1]
            for k, dr in enumerate(dirs):
                verdicts[(d["scenario"], k)] = dr["verdict"]
                planned[(d["scenario"], k)] = dr.get("as_planned")
    return (verdicts, planned), steps, wall, sub


def changed(base, other):
    """The directions both runs checked whose answers differ (a run cut short, such as a
    null stopped early, contributes the scenarios it reached)."""
    return {k for k in set(base) & set(other) if base[k] != other[k]}


def changes(base, other):
    """(verdicts changed, `as_planned` changed) between two `load` results."""
    return changed(base[0], other[0]), changed(base[1], other[1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", required=True)
    ap.add_argument("--null", action="append", default=[])
    ap.add_argument("--mujoco", action="append", default=[], metavar="MJ.json")
    ap.add_argument("--substeps", action="append", default=[], metavar="NAME=CLOSE/HOLD")
    ap.add_argument("candidates", nargs="*", metavar="NAME=FILE")
    a = ap.parse_args()
    subs = {}
    for kv in a.substeps:
        name, v = kv.split("=", 1)
        c, h = v.split("/")
        subs[name] = (int(c), int(h))
    base, bsteps, bwall, bsub = load(a.base)
    null_set, null_planned = set(), set()
    rows = []
    for path in a.null:
        v, s, w, _ = load(path)
        c, cp = changes(base, v)
        rows.append((f"null: {path}", c, cp, s, w))
        null_set |= c
        null_planned |= cp
    nulls = [c for _, c, _, _, _ in rows]
    mj = {}
    for path in a.mujoco:
        for name, by_scenario in json.load(open(path)).items():
            mj[name] = {k: r["agree"] for k, r in by_scenario.items()}

    def agreement(name):
        m = mj.get(name)
        if m is None:
            return ""
        return f"{sum(1 for x in m.values() if x)} of {len(m)}"

    print(f"directions: {len(base[0])}; null set: {len(null_set)} directions of "
          f"{len({k[0] for k in null_set})} objects from {len(a.null)} nulls (verdicts), "
          f"{len(null_planned)} directions of {len({k[0] for k in null_planned})} objects "
          f"(as_planned)")
    print()
    print("| run | verdicts changed | outside the null set | as_planned changed | outside its null set "
          "| objects | steps / base | substeps / base | wall / base | MuJoCo agrees (`down`) | passes |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    print(f"| base: {a.base} | 0 | 0 | 0 | 0 | 0 | {bsteps:,} | {bsub:,.0f} | {bwall / 1000:.1f} s "
          f"| {agreement('base')} | |")
    for i, (name, c, cp, s, w) in enumerate(rows):
        others = set().union(*[n for j, n in enumerate(nulls) if j != i])
        print(f"| {name} | {len(c)} | {len(c - others)} outside the other nulls | {len(cp)} | | "
              f"{len({k[0] for k in c})} | {s / bsteps:.3f} | | {w / bwall:.3f} | | |")
    failed = False
    for kv in a.candidates:
        name, path = kv.split("=", 1)
        v, s, w, sub = load(path, subs.get(name, (8, 8)))
        c, cp = changes(base, v)
        out = c - null_set
        out_planned = cp - null_planned
        ok = not out and not out_planned
        if name in mj and "base" in mj:
            agree_c = sum(1 for x in mj[name].values() if x)
            agree_b = sum(1 for x in mj["base"].values() if x)
            ok = ok and agree_c >= agree_b
        failed |= not ok
        print(f"| {name} | {len(c)} | {len(out)} | {len(cp)} | {len(out_planned)} "
              f"| {len({k[0] for k in c | cp})} | {s / bsteps:.3f} "
              f"| {sub / bsub:.3f} | {w / bwall:.3f} | {agreement(name)} "
              f"| {'yes' if ok else '**no**'} |")
        if out or out_planned:
            objs = sorted({k[0] for k in out})
            objs_p = sorted({k[0] for k in out_planned})
            print(f"|  outside: {', '.join(objs)} | | | {', '.join(objs_p)} | | | | | | | |")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
