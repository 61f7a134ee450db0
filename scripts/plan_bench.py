#!/usr/bin/env python3
"""Planning time per object (issue 30): every real-object scenario and every hard mesh, planned
one at a time with `--no-sim`, each in a process of its own (its wall time from start to exit,
loading included), both cores free for it.

    cargo build --release
    ./target/release/grasp-sim gen-assets --hard --out out/hard
    python3 scripts/plan_bench.py                         # table, median, 95th percentile, max
    python3 scripts/plan_bench.py --bin /tmp/old-grasp-sim --timeout 120 --out out/bench_old.json

The default inputs are assets/real/scenarios/*.toml and out/hard/*.stl. An object that runs past
`--timeout` seconds is killed and counted at the timeout (marked `>`).
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def run_one(binary, path, timeout):
    t0 = time.monotonic()
    try:
        p = subprocess.run(
            [binary, "--json", "--no-sim", str(path)],
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return {"input": str(path), "wall_s": timeout, "timed_out": True}
    wall = time.monotonic() - t0
    row = {"input": str(path), "wall_s": wall, "timed_out": False, "exit": p.returncode}
    line = next((l for l in p.stdout.splitlines() if l.startswith("{")), None)
    if line is None:
        row["error"] = p.stderr.strip().splitlines()[-1:] or ["no output"]
        return row
    r = json.loads(line)
    plan = r["plan"]
    row.update(
        status=plan["status"],
        reason=plan.get("reason"),
        triangles=r["object"]["triangles"],
        candidates_tried=plan["candidates_tried"],
        stopped=plan.get("search_stopped"),
    )
    g = plan.get("grasp")
    if g:
        row["grasp"] = f'{g["axis_name"]} {g["rules"]} #{g["elevation_index"]} {g["approach_angle_deg"]:.1f} deg'
    return row


def percentile(xs, q):
    xs = sorted(xs)
    k = max(0, min(len(xs) - 1, int(round(q * (len(xs) - 1)))))
    return xs[k]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("inputs", nargs="*", type=pathlib.Path)
    ap.add_argument("--bin", default=str(ROOT / "target/release/grasp-sim"))
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--out", type=pathlib.Path, help="write the rows as JSON here")
    a = ap.parse_args()
    inputs = a.inputs or (
        sorted((ROOT / "assets/real/scenarios").glob("*.toml"))
        + sorted((ROOT / "out/hard").glob("*.stl"))
    )
    rows = []
    for path in inputs:
        row = run_one(a.bin, path, a.timeout)
        rows.append(row)
        mark = ">" if row["timed_out"] else " "
        what = row.get("grasp") or (row.get("reason") or "")[:90] or row.get("error")
        print(
            f'{mark}{row["wall_s"]:8.3f} s  {pathlib.Path(row["input"]).stem:36} '
            f'{row.get("triangles", ""):>7} {row.get("candidates_tried", ""):>6} '
            f'{row.get("status", "timeout" if row["timed_out"] else "error"):12} {what}',
            flush=True,
        )
    walls = [r["wall_s"] for r in rows]
    print(
        f"\n{len(rows)} objects: median {statistics.median(walls):.3f} s, "
        f"95th percentile {percentile(walls, 0.95):.3f} s, max {max(walls):.3f} s, "
        f"within 0.5 s {sum(w <= 0.5 for w in walls)}, within 5 s {sum(w <= 5 for w in walls)}, "
        f"timed out {sum(r['timed_out'] for r in rows)}"
    )
    if a.out:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
