#!/usr/bin/env python3
"""Compare grasp-sim's rapier verdicts with a MuJoCo replay of the exported scenes.

    python3 scripts/compare_engines.py GRASP_SIM_BINARY OUT_DIR [--require NAME ...] SCENARIO...

Runs `GRASP_SIM_BINARY --json --export-mjcf OUT_DIR SCENARIO...`, replays every exported scene
with scripts/mujoco_replay.py, and prints a Markdown table of both engines' answers to each of
the check's two questions apart (issue 55): the verdict (what gravity did) and the fidelity
(`as_planned`), with the figures behind the second (the closing's shift, the phalanges on
plan), then the agreement on each and the distributions of the differences, so that a
disagreement across a threshold by a hair and one by 20 mm do not look alike. Exits 1 if a
scenario named with --require gets different verdicts (CI requires D40 and the cup).
With --write-doc the table and its count replace the generated block of docs/MUJOCO.md
("Agreement"), whose headline line the README's headline copies (scripts/headline.py):

    python3 scripts/compare_engines.py target/release/grasp-sim out/ --write-doc \
        scenarios/*.toml assets/objects/train/*.toml

    python3 scripts/compare_engines.py GRASP_SIM_BINARY OUT_DIR --robust N [--six] [--jsonl F] SCENARIO...

Issue 34: runs the binary with `--samples N` (and `--gravity six`), replays each perturbed
sample's exported scene (OUT_DIR/<scenario>/samples/<k>/) in MuJoCo, and prints per grasp both
engines' hold probabilities and probabilities of a hold as planned, their differences, the
per-sample agreement, and over all grasps the mean absolute difference of each, the Brier score of each engine's probability against the other's
per-sample outcomes, and how often one says >= 0.9 while the other says < 0.5. `--jsonl F`
writes one line per grasp with both engines' per-sample verdicts.

    python3 scripts/compare_engines.py --labels LABELS.jsonl SCENES_DIR [--jsonl F] [--libccd]

Issue 57: the agreement over a labelled dataset. `grasp-sim label ... --out LABELS.jsonl
--export-mjcf SCENES_DIR --mujoco-fraction F` writes the scene of a deterministic fraction of
its grasps into SCENES_DIR/<object>/<grasp_index>/; this replays each (in the record's gravity
directions) and prints how often MuJoCo's verdict and as_planned agree with the nominal check
`label` recorded, per object and over the dataset, and both engines' rates: rapier's perturbed
checks a second over the labelled grasps (from the lines' wall times) and MuJoCo's replays a
second. `--libccd`: MuJoCo with its libccd collision instead of its native one (see
scripts/mujoco_replay.py); the rows of two runs, one with it, show which verdicts MuJoCo
itself cannot decide.
"""
import json
import math
import os
import pathlib
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import docblock  # noqa: E402
import mujoco_replay  # noqa: E402


def robust(binary, out_dir, n, six, jsonl, scenarios):
    """The `--robust N` study (see the module docs)."""
    cmd = [binary, "--json", "--export-mjcf", str(out_dir), "--samples", str(n)]
    if six:
        cmd += ["--gravity", "six"]
    run = subprocess.run([*cmd, *scenarios], capture_output=True, text=True)
    if run.returncode == 2:
        # A bad input is reported on stderr; the others' lines are still compared.
        print(run.stderr, file=sys.stderr)
        if not run.stdout.strip():
            return 2
    print("| scenario | main check | rapier p [95 % interval] | MuJoCo p | difference | samples agreeing "
          "| rapier p as planned | MuJoCo p as planned | rapier [ms] | MuJoCo [ms] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    out = open(jsonl, "w") if jsonl else None
    for line in run.stdout.splitlines():
        d = json.loads(line)
        name, sim = d["scenario"], d["sim"]
        r = sim.get("robust")
        if r is None:
            print(f"| {name} | {sim['verdict']} | (not sampled) | | | | | | | |")
            continue
        verdicts, planned, wall = [], [], 0.0
        for k in range(r["samples"]):
            m = mujoco_replay.replay(out_dir / name / "samples" / str(k),
                                     mujoco_replay.SIX if six else None)
            verdicts.append(m["verdict"])
            planned.append(m["fidelity"]["as_planned"])
            wall += m["wall_ms"]
        pm = sum(v == "hold" for v in verdicts) / len(verdicts)
        pm_ap = sum(v == "hold" and a for v, a in zip(verdicts, planned)) / len(verdicts)
        pr = r["hold_probability"]
        pr_ap = r.get("as_planned_probability", pr)
        agree = sum(a == b for a, b in zip(verdicts, r["verdicts"]))
        lo, hi = r["interval"]
        print(f"| {name} | {sim['verdict']} | {pr:.3f} [{lo:.2f}, {hi:.2f}] | {pm:.3f} | {pr - pm:+.3f} "
              f"| {agree} of {len(verdicts)} | {pr_ap:.3f} | {pm_ap:.3f} | {r['wall_ms']:.0f} | {wall:.0f} |")
        row = {"scenario": name, "main": sim["verdict"], "rapier_p": pr, "rapier_interval": r["interval"],
               "mujoco_p": pm, "rapier": r["verdicts"], "mujoco": verdicts,
               "rapier_p_as_planned": pr_ap, "mujoco_p_as_planned": pm_ap,
               "rapier_as_planned": r.get("as_planned"), "mujoco_as_planned": planned,
               "rapier_ms": r["wall_ms"], "mujoco_ms": wall}
        rows.append(row)
        if out:
            out.write(json.dumps(row) + "\n")
    if out:
        out.close()
    if rows:
        def brier(p_key, outcomes_key):
            terms = [(row[p_key] - (v == "hold")) ** 2 for row in rows for v in row[outcomes_key]]
            return sum(terms) / len(terms)
        diff = sum(abs(r["rapier_p"] - r["mujoco_p"]) for r in rows) / len(rows)
        diff_ap = sum(abs(r["rapier_p_as_planned"] - r["mujoco_p_as_planned"]) for r in rows) / len(rows)
        split = sum((r["rapier_p"] >= 0.9 and r["mujoco_p"] < 0.5) or
                    (r["mujoco_p"] >= 0.9 and r["rapier_p"] < 0.5) for r in rows)
        weak = sum(r["main"] == "hold" and r["rapier_interval"][0] < 0.9 for r in rows)
        print()
        print(f"{len(rows)} grasps, {n} samples each{', six directions' if six else ''}: mean |p_rapier - p_mujoco| "
              f"{diff:.3f}; Brier score of rapier's p against MuJoCo's samples {brier('rapier_p', 'mujoco'):.3f}, "
              f"of MuJoCo's p against rapier's {brier('mujoco_p', 'rapier'):.3f}; one engine >= 0.9 while the "
              f"other < 0.5: {split}; main-check holds with a lower bound under 0.9: {weak}; "
              f"mean |p_rapier - p_mujoco| of a hold as planned {diff_ap:.3f}")
    return 0


def quantiles(xs):
    """Median, 90th percentile and largest of `xs` (nearest rank), or None for none."""
    xs = sorted(xs)
    if not xs:
        return None
    rank = lambda q: xs[min(len(xs) - 1, max(0, math.ceil(q * len(xs)) - 1))]  # noqa: E731
    return rank(0.5), rank(0.9), xs[-1]


def agreement_summary(rows):
    """One paragraph: agreement on the verdict and on `as_planned`, and the distributions of the
    engines' differences in the closing's shift and in the phalanges on plan."""
    n = len(rows)
    verdicts = sum(r["agree"] for r in rows)
    held = sum(r["agree_held"] for r in rows)
    planned = sum(r["agree_ap"] for r in rows)
    shifts = [abs(a - b) for a, b in (r["shift"] for r in rows) if a is not None and b is not None]
    on_plan = [abs(a - b) for a, b in (r["on_plan"] for r in rows) if a is not None and b is not None]
    words = [f"{n} grasps: the verdicts agree on {verdicts} ({100 * verdicts / n:.0f} %), "
             f"whether it held (hold against slip or drop) on {held} ({100 * held / n:.0f} %), "
             f"as_planned on {planned} ({100 * planned / n:.0f} %)"]
    q = quantiles(shifts)
    if q:
        words.append(f"|shift difference| median {q[0]:.1f} mm, p90 {q[1]:.1f} mm, max {q[2]:.1f} mm")
    q = quantiles(on_plan)
    if q:
        hist = {k: on_plan.count(k) for k in sorted(set(on_plan))}
        words.append("|phalanges on plan difference| " +
                     ", ".join(f"{k}: {v}" for k, v in hist.items()))
    words.append(disagreements(rows))
    return "; ".join(w for w in words if w)


def disagreements(rows):
    """What the verdicts' disagreements follow from: a closing that left the plan in one engine
    or both (a different grasp in each engine), or, with both closings as planned, gravity's
    motion alone (then the two translations, to tell a disagreement by a hair across the hold
    threshold from one by centimetres)."""
    off = {"MuJoCo": 0, "rapier": 0, "both": 0}
    gravity = []
    for r in rows:
        if r["agree"]:
            continue
        ra, ma = r.get("rapier_as_planned"), r.get("mujoco_as_planned")
        if ra and ma:
            t = r.get("translation_mm")
            gravity.append(f"{t[0]:.1f}/{t[1]:.1f}" if t else "?")
        else:
            off["both" if not ra and not ma else "MuJoCo" if ra else "rapier"] += 1
    n = sum(off.values()) + len(gravity)
    if n == 0:
        return ""
    text = (f"verdict disagreements {n}: after a closing off plan in MuJoCo alone "
            f"{off['MuJoCo']}, in rapier alone {off['rapier']}, in both {off['both']}; with both "
            f"closings as planned {len(gravity)}")
    if gravity:
        text += f" (translation rapier/MuJoCo [mm]: {', '.join(gravity)})"
    return text


def folder_name(name):
    """A scenario name as grasp-sim makes it a folder name (`files::folder_name`): `/`, `\\`
    and control characters as `_`, an empty name, `.` and `..` prefixed with `_`, at most 200
    bytes."""
    s = "".join("_" if c in "/\\" or ord(c) < 32 or 127 <= ord(c) < 160 else c for c in name)
    s = "_" + s if s in ("", ".", "..") else s
    b = s.encode()[:200]
    return b.decode("utf-8", "ignore")


def labels(path, scenes, jsonl, libccd=False):
    """`--labels`: MuJoCo's replay of the exported grasps of a label file against its records."""
    records = {}
    for line in pathlib.Path(path).read_text().splitlines():
        r = json.loads(line)
        if "grasp_index" in r and "verdict" in r:
            records[(r["object"], r["grasp_index"])] = r
    dirs = sorted(p.parent for p in pathlib.Path(scenes).glob("*/*/scene.xml"))
    per_object, rows, mujoco_ms, rapier = {}, [], 0.0, [0.0, 0]
    # A grasp's scene is in <object as a folder name>/<grasp_index>/ (`label --export-mjcf`).
    by_folder = {(folder_name(o), i): r for (o, i), r in records.items()}
    for d in dirs:
        r = by_folder.get((d.parent.name, int(d.name))) if d.name.isdigit() else None
        if r is None:
            print(f"{d}: no label record for it", file=sys.stderr)
            continue
        idx = r["grasp_index"]
        directions = [x["gravity"] for x in r["directions"]] if len(r["directions"]) > 1 else None
        m = mujoco_replay.replay(d, directions, libccd=libccd)
        mujoco_ms += m["wall_ms"]
        rapier[0] += r["label"]["wall_ms"]
        rapier[1] += r["samples"] + 1
        row = {"object": r["object"], "grasp_index": idx,
               "rapier": r["verdict"], "mujoco": m["verdict"],
               "rapier_as_planned": r["fidelity"]["as_planned"],
               "mujoco_as_planned": m["fidelity"]["as_planned"],
               "hold_probability": r["hold_probability"],
               "translation_mm": (r["translation_mm"], m["translation_mm"]),
               "shift": (r["fidelity"]["shift_mm"], m["fidelity"]["shift_mm"]),
               "on_plan": (r["fidelity"]["phalanges_on_plan"], m["fidelity"]["phalanges_on_plan"])}
        row["agree"] = row["rapier"] == row["mujoco"]
        row["agree_held"] = (row["rapier"] == "hold") == (row["mujoco"] == "hold")
        row["agree_ap"] = row["rapier_as_planned"] == row["mujoco_as_planned"]
        rows.append(row)
        o = per_object.setdefault(r["object"], [0, 0, 0])
        o[0] += 1
        o[1] += row["agree"]
        o[2] += row["agree_ap"]
    if jsonl:
        with open(jsonl, "w") as f:
            for row in rows:
                f.write(json.dumps(row) + "\n")
    print("| object | grasps replayed | verdicts agree | as planned agree |")
    print("|---|---|---|---|")
    for name, (n, a, ap) in sorted(per_object.items()):
        print(f"| {name} | {n} | {a} | {ap} |")
    n = len(rows)
    if n == 0:
        print("no exported grasp matched a label record", file=sys.stderr)
        return 2
    held = [r for r in rows if r["rapier"] == "hold"]
    print(f"\n**Summary**: MuJoCo replays labelled grasps of {len(per_object)} objects; "
          f"{agreement_summary(rows)}; of rapier's {len(held)} holds MuJoCo holds "
          f"{sum(r['mujoco'] == 'hold' for r in held)}.")
    # rapier's grasp wall time is its nominal check and samples on the object's share of the
    # cores; MuJoCo's is the one replay's simulation loop, on one core.
    if rapier[1] and mujoco_ms > 0:
        print(f"Rates: rapier {1000.0 * rapier[1] / rapier[0]:.2f} checks a second of grasp wall time "
              f"(nominal and samples), MuJoCo {1000.0 * n / mujoco_ms:.2f} replays a second.")
    return 0


def main(argv):
    if len(argv) >= 2 and argv[1] == "--labels":
        args = argv[2:]
        jsonl = None
        if "--jsonl" in args:
            j = args.index("--jsonl")
            jsonl = args[j + 1]
            del args[j:j + 2]
        libccd = "--libccd" in args
        args = [a for a in args if a != "--libccd"]
        if len(args) != 2:
            print(__doc__, file=sys.stderr)
            return 2
        return labels(args[0], args[1], jsonl, libccd)
    if len(argv) < 4:
        print(__doc__, file=sys.stderr)
        return 2
    if "--robust" in argv:
        args = argv[3:]
        i = args.index("--robust")
        n = int(args[i + 1])
        del args[i:i + 2]
        six = "--six" in args
        args = [a for a in args if a != "--six"]
        jsonl = None
        if "--jsonl" in args:
            j = args.index("--jsonl")
            jsonl = args[j + 1]
            del args[j:j + 2]
        return robust(argv[1], pathlib.Path(argv[2]), n, six, jsonl, args)
    binary, out_dir, rest = argv[1], pathlib.Path(argv[2]), argv[3:]
    required, scenarios, write_doc = [], [], False
    i = 0
    while i < len(rest):
        if rest[i] == "--write-doc":
            write_doc = True
            i += 1
        elif rest[i] == "--require":
            required.append(rest[i + 1])
            i += 2
        else:
            scenarios.append(rest[i])
            i += 1
    run = subprocess.run(
        [binary, "--json", "--export-mjcf", str(out_dir), *scenarios],
        capture_output=True,
        text=True,
    )
    if run.returncode == 2:
        print(run.stderr, file=sys.stderr)
        return 2
    rapier = {}
    for line in run.stdout.splitlines():
        d = json.loads(line)
        rapier[d["scenario"]] = d["sim"]
    lines = []

    def out(text):
        lines.append(text)
        print(text)

    out("| scenario | rapier | translation [mm] | rotation [deg] | MuJoCo | translation [mm] "
        "| rotation [deg] | verdicts agree | rapier as planned | MuJoCo as planned | as planned agree "
        "| shift rapier / MuJoCo [mm] | on plan rapier / MuJoCo | rapier [ms] | MuJoCo [ms] | ratio |")
    out("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    failed, compared, agreed, differ = [], 0, 0, []
    rows = []
    for name, sim in rapier.items():
        scene = out_dir / name
        if not (scene / "scene.xml").is_file():
            out(f"| {name} | {sim['verdict']} | | | (no grasp to export) | | | | | | | | | | | |")
            continue
        m = mujoco_replay.replay(scene)
        agree = m["verdict"] == sim["verdict"]
        compared += 1
        agreed += agree
        if not agree:
            differ.append(name)
        fr, fm = sim.get("fidelity") or {}, m["fidelity"]
        agree_ap = fr.get("as_planned") == fm["as_planned"]
        rows.append({"agree": agree, "agree_ap": agree_ap,
                     "agree_held": (m["verdict"] == "hold") == (sim["verdict"] == "hold"),
                     "rapier_as_planned": fr.get("as_planned"),
                     "mujoco_as_planned": fm["as_planned"],
                     "translation_mm": (sim["translation_mm"], m["translation_mm"]),
                     "shift": (fr.get("shift_mm"), fm["shift_mm"]),
                     "on_plan": (fr.get("phalanges_on_plan"), fm["phalanges_on_plan"])})
        # Wall times of the same check, in the same run: rapier's whole check (closing and every
        # direction) against MuJoCo's simulation loop (no Python start-up, no model loading).
        ratio = sim["wall_ms"] / m["wall_ms"] if m["wall_ms"] > 0 else float("nan")
        yes = lambda ok: "yes" if ok else "**no**"  # noqa: E731
        out(
            f"| {name} | {sim['verdict']} | {sim['translation_mm']:.2f} | {sim['rotation_deg']:.2f} "
            f"| {m['verdict']} | {m['translation_mm']:.2f} | {m['rotation_deg']:.2f} | {yes(agree)} "
            f"| {fr.get('as_planned')} | {fm['as_planned']} | {yes(agree_ap)} "
            f"| {fr.get('shift_mm', float('nan')):.1f} / {fm['shift_mm']:.1f} "
            f"| {fr.get('phalanges_on_plan')} / {fm['phalanges_on_plan']} "
            f"| {sim['wall_ms']:.1f} | {m['wall_ms']:.1f} | {ratio:.3f} |"
        )
        if name in required and not agree:
            failed.append(name)
    summary = (f"**Summary**: MuJoCo replays {compared} grasps and agrees with rapier on the verdict "
               f"for {agreed}" + (f" (not on {', '.join(differ)})" if differ else "")
               + (f"; {agreement_summary(rows)}." if rows else "."))
    print(f"\n{summary}")
    if write_doc:
        head = docblock.headline_line(compared=compared, agree=agreed,
                                      differ=",".join(differ) or "none")
        docblock.replace(docblock.ROOT / "docs" / "MUJOCO.md", "scripts/compare_engines.py",
                         "\n".join([head, "", f"Run at {docblock.revision()} (rapier's `fast` protocol; "
                                     "MuJoCo's replay full-length; wall times of that run, load "
                                     f"average {os.getloadavg()[0]:.1f} at its end):", "",
                                     *lines, "", summary]) + "\n")
    for name in required:
        if name not in rapier:
            failed.append(name)
    if failed:
        print(f"engines disagree on: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
