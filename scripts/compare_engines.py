#!/usr/bin/env python3
"""Compare grasp-sim's rapier verdicts with a MuJoCo replay of the exported scenes.

    python3 scripts/compare_engines.py GRASP_SIM_BINARY OUT_DIR [--require NAME ...] SCENARIO...

Runs `GRASP_SIM_BINARY --json --export-mjcf OUT_DIR SCENARIO...`, replays every exported scene
with scripts/mujoco_replay.py, and prints a Markdown table of both engines' verdicts and numbers.
Exits 1 if a scenario named with --require gets different verdicts (CI requires D40 and the cup).
"""
import json
import pathlib
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import mujoco_replay  # noqa: E402


def main(argv):
    if len(argv) < 4:
        print(__doc__, file=sys.stderr)
        return 2
    binary, out_dir, rest = argv[1], pathlib.Path(argv[2]), argv[3:]
    required, scenarios = [], []
    i = 0
    while i < len(rest):
        if rest[i] == "--require":
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
    print(
        "| scenario | rapier | translation [mm] | rotation [deg] | MuJoCo | translation [mm] "
        "| rotation [deg] | agree | rapier [ms] | MuJoCo [ms] | ratio |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    failed = []
    for name, sim in rapier.items():
        scene = out_dir / name
        if not (scene / "scene.xml").is_file():
            print(f"| {name} | {sim['verdict']} | | | (no grasp to export) | | | | | | |")
            continue
        m = mujoco_replay.replay(scene)
        agree = m["verdict"] == sim["verdict"]
        # Wall times of the same check, in the same run: rapier's whole check (closing and every
        # direction) against MuJoCo's simulation loop (no Python start-up, no model loading).
        ratio = sim["wall_ms"] / m["wall_ms"] if m["wall_ms"] > 0 else float("nan")
        print(
            f"| {name} | {sim['verdict']} | {sim['translation_mm']:.2f} | {sim['rotation_deg']:.2f} "
            f"| {m['verdict']} | {m['translation_mm']:.2f} | {m['rotation_deg']:.2f} | {'yes' if agree else 'no'} "
            f"| {sim['wall_ms']:.1f} | {m['wall_ms']:.1f} | {ratio:.3f} |"
        )
        if name in required and not agree:
            failed.append(name)
    for name in required:
        if name not in rapier:
            failed.append(name)
    if failed:
        print(f"engines disagree on: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
