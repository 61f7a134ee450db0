#!/usr/bin/env python3
"""How two runs of the physics check close and hold (docs/SIM.md, "The impulse-joint hand").

    python3 scripts/hand_joints_compare.py A.jsonl B.jsonl

Both files are runs of `cargo run --release --example protocols -- --only fast --six --set
max_checked=1 [--set KEY=VALUE] --jsonl FILE SCENARIO...` on the same scenarios (e.g. the
multibody hand and `--set hand_joints="impulse"`). Prints, over the scenarios both checked: where
B's fingers stop against A's (the largest difference of a final joint bend, median and largest
over scenarios), the deepest contact after closing (median, 90th percentile, largest), the
closing's length and shift, the steps, and the verdicts by direction (same, changed, and how).
"""
import collections
import json
import statistics
import sys


def load(path):
    out = {}
    for line in open(path):
        d = json.loads(line)
        if d["sim"].get("directions"):
            out[d["scenario"]] = d["sim"]
    return out


def pct(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(p * (len(xs) - 1))))]


def main(a_path, b_path):
    a, b = load(a_path), load(b_path)
    common = [s for s in a if s in b]
    angle, rows = [], []
    for s in common:
        fa = [f["final_deg"] for f in a[s]["closing"]["fingers"]]
        fb = [f["final_deg"] for f in b[s]["closing"]["fingers"]]
        angle.append(max(abs(x - y) for p, q in zip(fa, fb) for x, y in zip(p, q)))
    stat = collections.Counter()
    for s in common:
        for da, db in zip(a[s]["directions"], b[s]["directions"]):
            stat[(da["verdict"], db["verdict"])] += 1

    def column(run, f):
        return [f(run[s]) for s in common]

    def line(name, xs, unit):
        print(f"| {name} | {statistics.median(xs[0]):.3f} / {statistics.median(xs[1]):.3f} "
              f"| {pct(xs[0], 0.9):.3f} / {pct(xs[1], 0.9):.3f} | {max(xs[0]):.3f} / {max(xs[1]):.3f} "
              f"| {unit} |")

    print(f"{len(common)} scenarios checked by both; A = {a_path}, B = {b_path}\n")
    print("| figure (A / B) | median | 90th pct | largest | unit |")
    print("|---|---|---|---|---|")
    pen = lambda r: max(d["closing_penetration_mm"] for d in r["directions"])  # noqa: E731
    line("deepest contact after closing", (column(a, pen), column(b, pen)), "mm")
    line("closing length", (column(a, lambda r: r["closing"]["duration_s"]),
                            column(b, lambda r: r["closing"]["duration_s"])), "s")
    line("closing shift", (column(a, lambda r: r["closing"]["shift_mm"]),
                           column(b, lambda r: r["closing"]["shift_mm"])), "mm")
    line("steps", (column(a, lambda r: r["steps"]), column(b, lambda r: r["steps"])), "")
    print(f"\nfinal joint bends, B against A: largest difference per scenario median "
          f"{statistics.median(angle):.2f} deg, 90th pct {pct(angle, 0.9):.2f}, "
          f"largest {max(angle):.2f}; within 1 deg: {sum(x <= 1 for x in angle)} of {len(angle)}")
    same = sum(n for (x, y), n in stat.items() if x == y)
    total = sum(stat.values())
    print(f"verdicts by direction: {same} of {total} the same; changed: " + ", ".join(
        f"{x} -> {y} {n}" for (x, y), n in sorted(stat.items()) if x != y))
    steps_a = sum(r["steps"] for r in a.values())
    steps_b = sum(r["steps"] for r in b.values())
    print(f"steps in total: {steps_a:,} / {steps_b:,} ({steps_b / steps_a:.2f}x)")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
