#!/usr/bin/env python3
"""Classify the phalanges that end a closing off their plan (issue 33, docs/SIM.md "Why the
phalanges miss their plan").

    python3 scripts/closing_misses.py OUT/raw [OUT2/raw ...] [--json]

OUT/raw is what `scripts/real_objects_eval.py --raw --out OUT` keeps: every run's JSON. Over
every held grasp (`down` and `six` runs, every label, as the evaluation's closing line counts),
each phalanx is put in one class:

- `on_plan`: touching the object at the end of the closing (a solver contact) within 5 degrees
  of its commanded bend: the issue's measure;
- `touch_past` / `touch_short`: touching, but more than 5 degrees past / short of its bend;
- `near_within`: within 5 degrees, not touching, its gap to the collider at most 0.5 mm;
- `off_within`: within 5 degrees, gap over 0.5 mm;
- `through_squeeze`: not touching and more than 5 degrees past its bend (it closed through the
  squeeze without meeting the object, or met it and lost it);
- `off_short`: not touching, more than 5 degrees short;

and, for each, whether it ever touched during the closing (`first_contact_s`), which finger and
phalanx it is, the rule set, and whether the plan gives it a contact at all (phalanx 1 of a
fingertip pinch, `distal_contact_only`, has none).
"""
import argparse
import collections
import json
import pathlib

WITHIN_DEG = 5.0
NEAR_MM = 0.5


def classify(err, touching, gap):
    """One phalanx's class from its final-minus-commanded bend [deg], whether it touches and its
    gap [mm]."""
    if touching:
        if abs(err) <= WITHIN_DEG:
            return "on_plan"
        return "touch_past" if err > 0 else "touch_short"
    if abs(err) <= WITHIN_DEG:
        return "near_within" if gap <= NEAR_MM else "off_within"
    return "through_squeeze" if err > 0 else "off_short"


def phalanges(raw_dir):
    """Every phalanx of every held grasp in `raw_dir`: a dict per phalanx."""
    out = []
    for path in sorted(pathlib.Path(raw_dir).glob("*.json")):
        r = json.loads(path.read_text())
        sim = r.get("sim") or {}
        c = sim.get("closing")
        if sim.get("verdict") != "hold" or not c:
            continue
        g = r["plan"]["grasp"]
        pinch = "distal_contact_only" in (g.get("relaxations") or [])
        tips = {f["name"]: f.get("tip_contact", False) for f in g["fingers"]}
        for f in c["fingers"]:
            for j in range(2):
                out.append({
                    "run": path.stem,
                    "finger": f["name"],
                    "phalanx": j + 1,
                    "rules": g["rules"] + ("+pinch" if pinch else ""),
                    "planned_contact": not (pinch and j == 0),
                    "tip": tips.get(f["name"], False),
                    "error_deg": f["error_deg"][j],
                    "gap_mm": f["gap_mm"][j],
                    "touching": f["touching"][j],
                    "ever": f["first_contact_s"][j] is not None,
                    "class": classify(f["error_deg"][j], f["touching"][j], f["gap_mm"][j]),
                    "shift_mm": c["shift_mm"],
                })
    return out


def table(rows, key):
    """Counts of each class by `key(row)`."""
    classes = ["on_plan", "touch_past", "touch_short", "near_within", "off_within",
               "through_squeeze", "off_short"]
    by = collections.defaultdict(collections.Counter)
    for r in rows:
        by[key(r)][r["class"]] += 1
    lines = ["| group | phalanges | " + " | ".join(classes) + " | on plan |",
             "|---" * (len(classes) + 3) + "|"]
    for k in sorted(by, key=str):
        n = sum(by[k].values())
        lines.append(f"| {k} | {n} | " + " | ".join(str(by[k][c]) for c in classes)
                     + f" | {100.0 * by[k]['on_plan'] / n:.0f} % |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("raw", nargs="+")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    for raw in a.raw:
        rows = phalanges(raw)
        if a.json:
            print(json.dumps(rows))
            continue
        n = len(rows)
        on = sum(r["class"] == "on_plan" for r in rows)
        print(f"## {raw}: {n // 6 if n else 0}+ held grasps, {n} phalanges, on plan {on} "
              f"({100.0 * on / max(n, 1):.0f} %)\n")
        print(table(rows, lambda r: "all"))
        print(table(rows, lambda r: f"phalanx {r['phalanx']}"), "\n")
        print(table(rows, lambda r: f"{r['finger']} p{r['phalanx']}"), "\n")
        print(table(rows, lambda r: f"{r['rules']} p{r['phalanx']}"), "\n")
        print(table(rows, lambda r: f"ever touched: {r['ever']}"), "\n")
        planned = [r for r in rows if r["planned_contact"]]
        pon = sum(r["class"] == "on_plan" for r in planned)
        near = sum(r["class"] in ("on_plan", "near_within") for r in rows)
        print(f"- phalanges the plan gives a contact: {len(planned)}, on plan {pon} "
              f"({100.0 * pon / max(len(planned), 1):.0f} %)")
        # A phalanx the plan gives no contact (a pinch's phalanx 1) that never touched and ends
        # within 5 deg of its bend is where the plan put it: clear of the object.
        clear = sum(not r["planned_contact"] and not r["ever"] and abs(r["error_deg"]) <= 5.0
                    for r in rows)
        on = sum(r["class"] == "on_plan" for r in rows)
        print(f"- on plan, or planned clear and ending clear within 5 deg: {on + clear} of {n} "
              f"({100.0 * (on + clear) / max(n, 1):.0f} %; {clear} planned clear)")
        print(f"- within 5 deg and touching or within {NEAR_MM} mm: {near} of {n} "
              f"({100.0 * near / max(n, 1):.0f} %)\n")


if __name__ == "__main__":
    main()
