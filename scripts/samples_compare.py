#!/usr/bin/env python3
"""The third condition of the settings criterion (docs/SIM.md, "One criterion for a cheaper
setting"): every grasp's hold probability moves by at most 0.1.

    python3 scripts/samples_compare.py [--binary target/release/grasp-sim] [--samples 16]
        [--gravity six] --variant NAME=KEY=VALUE[,KEY=VALUE...] [--variant ...] SCENARIO...

Each scenario's first planned grasp (`max_checked = 1`) is checked with `--samples N` (issue 34,
src/sim/robust.rs: the same N perturbations, drawn from `[sim] seed`) under the defaults and
under each variant, alternating scenario by scenario. Prints one Markdown row per scenario (each
variant's hold probability and its change against the defaults, the checks' wall time) and per
variant the largest change; exits 1 when a variant moves a probability by more than 0.1.
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from engine_agreement import with_sim  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent


def probability(binary, scenario, keys, samples, gravity, tmp):
    """(hold probability, robust wall [ms]) of `scenario` with `keys` in its [sim]."""
    f = pathlib.Path(tmp) / pathlib.Path(scenario).name
    f.write_text(with_sim(scenario, {**keys, "max_checked": "1"}))
    p = subprocess.run([binary, "--json", "--samples", str(samples), "--gravity", gravity, str(f)],
                       capture_output=True, text=True)
    if p.returncode == 2:
        sys.exit(p.stderr)
    sim = json.loads(p.stdout.splitlines()[0]).get("sim") or {}
    robust = sim.get("robust")
    if robust is None:
        return None, 0.0
    return robust["hold_probability"], robust.get("wall_ms") or 0.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "grasp-sim"))
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--gravity", default="six")
    ap.add_argument("--variant", action="append", default=[], metavar="NAME=KEY=VALUE,...")
    ap.add_argument("scenarios", nargs="+")
    a = ap.parse_args()
    variants = [("base", {})]
    for v in a.variant:
        name, kvs = v.split("=", 1)
        variants.append((name, dict(kv.split("=", 1) for kv in kvs.split(","))))
    worst = {n: 0.0 for n, _ in variants[1:]}
    wall = {n: 0.0 for n, _ in variants}
    head = " | ".join(f"{n} p | Δ" for n, _ in variants[1:])
    print(f"| scenario | base p | {head} |")
    print("|---|---|" + "---|---|" * (len(variants) - 1))
    with tempfile.TemporaryDirectory() as tmp:
        for s in a.scenarios:
            ps = {}
            for name, keys in variants:
                d = pathlib.Path(tmp) / f"{pathlib.Path(s).stem}_{name}"
                d.mkdir()
                ps[name], ms = probability(a.binary, s, keys, a.samples, a.gravity, d)
                wall[name] += ms
            if ps["base"] is None:
                print(f"| {pathlib.Path(s).stem} | (no grasp checked) |")
                continue
            cells = []
            for name, _ in variants[1:]:
                dp = ps[name] - ps["base"]
                worst[name] = max(worst[name], abs(dp))
                cells.append(f"{ps[name]:.3f} | {dp:+.3f}")
            print(f"| {pathlib.Path(s).stem} | {ps['base']:.3f} | {' | '.join(cells)} |",
                  flush=True)
    print()
    failed = False
    for name, _ in variants[1:]:
        ok = worst[name] <= 0.1
        failed |= not ok
        print(f"{name}: largest change of a hold probability {worst[name]:.3f} "
              f"({'within' if ok else 'beyond'} 0.1); the samples' wall {wall[name] / 1000:.1f} s "
              f"against the defaults' {wall['base'] / 1000:.1f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
