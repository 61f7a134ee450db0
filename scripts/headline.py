#!/usr/bin/env python3
"""The README's headline figures, copied from the generated blocks that hold them.

    python3 scripts/headline.py            # rewrite the README's block
    python3 scripts/headline.py --check    # exit 1 if the README's block is not what it would write

Every figure of the README's `<!-- BEGIN GENERATED: scripts/headline.py -->` block comes from a
block another script writes (scripts/docblock.py), so the README cannot drift from them:

- the thesis table: docs/USAGE.md, scripts/thesis_table.py (its headline line);
- the real-object set and MuJoCo's replay of it: docs/REAL_OBJECTS.md,
  scripts/real_objects_eval.py (its **Summary** line);
- planning time: BENCHMARKS.md, scripts/plan_bench.py (its headline line);
- the check's speed: BENCHMARKS.md, scripts/speed_ratios.py (its headline line);
- MuJoCo on the bundled and tuning sets: docs/MUJOCO.md, scripts/compare_engines.py (its
  headline line).

Each of those scripts' `--write-doc` rewrites the README's block too (scripts/docblock.py);
run it by hand after editing a block. `cargo test --test it repository` builds the same block
from the same sources (tests/it/repository.rs) and fails when the README's differs.
"""
import argparse
import pathlib
import re
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import docblock  # noqa: E402

ROOT = docblock.ROOT
SCRIPT = "scripts/headline.py"


def real_objects():
    """REAL_OBJECTS.md's **Summary** line's figures: graspable, planned, held down, held six,
    MuJoCo's replays and its agreements on the verdict."""
    text = docblock.block(ROOT / "docs" / "REAL_OBJECTS.md", "scripts/real_objects_eval.py")
    line = next(l for l in text.splitlines() if l.startswith("**Summary**"))
    found = re.search(r"of (\d+) objects labelled graspable, (\d+) get a planned grasp.*?"
                      r"(\d+) hold with gravity down.*? and (\d+) in all six directions.*?"
                      r"MuJoCo replays (\d+) checked grasps and agrees on the verdict for (\d+)", line)
    if not found:
        raise SystemExit(f"docs/REAL_OBJECTS.md: the Summary line is not as expected: {line}")
    return [int(n) for n in found.groups()]


def block():
    t = docblock.headline(ROOT / "docs" / "USAGE.md", "scripts/thesis_table.py")
    p = docblock.headline(ROOT / "BENCHMARKS.md", "scripts/plan_bench.py")
    s = docblock.headline(ROOT / "BENCHMARKS.md", "scripts/speed_ratios.py")
    m = docblock.headline(ROOT / "docs" / "MUJOCO.md", "scripts/compare_engines.py")
    r = real_objects()
    graspable, planned, down, six, replayed, agree = r
    lines = [
        f"- **The thesis.** {t['matching']} of the {t['scenarios']} thesis scenarios match the "
        f"thesis's Grasp Parameter Set within its tolerances ({t['names'].replace(',', ', ')}); "
        "the others differ for a stated reason "
        "([docs/USAGE.md](docs/USAGE.md#the-grasp-parameter-sets-against-the-thesis)).",
        f"- **Real objects.** Of {graspable} real objects labelled graspable, {planned} get a "
        f"grasp; {down} hold with gravity down and {six} in all six directions "
        "([docs/REAL_OBJECTS.md](docs/REAL_OBJECTS.md#the-table)).",
        f"- **Another engine.** MuJoCo replays the checked grasps and agrees with rapier on "
        f"{m['agree']} of {m['compared']} bundled and tuning-set grasps and on {agree} of "
        f"{replayed} real-object grasps ([docs/MUJOCO.md](docs/MUJOCO.md#agreement)).",
        f"- **Planning time.** {p['within_5s']} of {p['objects']} real and hard meshes plan "
        f"within 5 s: median {p['median_s']} s, 95th percentile {p['p95_s']} s, the slowest "
        f"({p['slowest']}) {p['max_s']} s, in a run at load average {p['load']} on 2 cores "
        "([BENCHMARKS.md](BENCHMARKS.md#planning-time-on-any-mesh)).",
        f"- **The check's speed.** The D40 cylinder's check takes {s['down_ratio']} of the time "
        f"MuJoCo's replay of the same scene (at its 0.025 ms step) takes with gravity down "
        f"({s['down_ms']} ms) and "
        f"{s['six_ratio']} in six directions; a batch of the real-object set runs "
        f"{s['checks_per_s']} six-direction "
        f"checks a second on 2 cores at load average {s['load']} "
        "([BENCHMARKS.md](BENCHMARKS.md#physics-check)).",
    ]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    text = block()
    if a.check:
        have = docblock.block(ROOT / "README.md", SCRIPT).strip("\n")
        if have != text.strip("\n"):
            print("README.md's headline block differs; run python3 scripts/headline.py",
                  file=sys.stderr)
            return 1
        return 0
    docblock.replace(ROOT / "README.md", SCRIPT, text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
