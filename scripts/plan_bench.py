#!/usr/bin/env python3
"""Planning time per object (issue 30): every real-object scenario and every hard mesh, planned
one at a time with `--no-sim`, each in a process of its own (its wall time from start to exit,
loading included), both cores free for it.

    cargo build --release
    ./target/release/grasp-sim gen-assets --hard --out out/hard
    python3 scripts/plan_bench.py                         # table, median, 95th percentile, max
    python3 scripts/plan_bench.py --bin out/old-grasp-sim --timeout 120 --out out/bench_old.json

The default inputs are assets/real/scenarios/*.toml and out/hard/*.stl. An object that runs past
`--timeout` seconds is killed and counted at the timeout (marked `>`).

    python3 scripts/plan_bench.py --against out/old-grasp-sim --out out/bench.json

times a second binary on each object just before the first (both under the same load, which on a
shared machine drifts), prints both tables and the results that differ, and writes its rows to
OUT with `.against` before the suffix.

    python3 scripts/plan_bench.py --write-doc

also replaces the generated block of BENCHMARKS.md ("Planning time on any mesh") with the
summary and the slowest objects, and the figures of the README's headline come from it
(scripts/headline.py).
"""

import argparse
import datetime
import json
import os
import pathlib
import statistics
import subprocess
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import docblock  # noqa: E402

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
    ap.add_argument("--against", help="a second binary, run on each object just before --bin")
    ap.add_argument("--write-doc", action="store_true",
                    help="replace BENCHMARKS.md's generated block with this run's figures")
    a = ap.parse_args()
    load0 = os.getloadavg()[0]
    inputs = a.inputs or (
        sorted((ROOT / "assets/real/scenarios").glob("*.toml"))
        + sorted((ROOT / "out/hard").glob("*.stl"))
    )
    rows = []
    against = []
    for path in inputs:
        if a.against:
            against.append(run_one(a.against, path, a.timeout))
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
    if a.against:
        print(f"\n{a.against}:")
        summary(against)
        for old, new in zip(against, rows):
            key = ("status", "candidates_tried", "grasp")
            if [old.get(k) for k in key] != [new.get(k) for k in key]:
                name = pathlib.Path(new["input"]).stem
                print(f"differs: {name}: {[old.get(k) for k in key]} -> {[new.get(k) for k in key]}")
        print(f"\n{a.bin}:")
    summary(rows)
    if a.out:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text(json.dumps(rows, indent=1))
        if a.against:
            other = a.out.with_suffix(".against" + a.out.suffix)
            other.write_text(json.dumps(against, indent=1))
    if a.write_doc:
        docblock.replace(ROOT / "BENCHMARKS.md", "scripts/plan_bench.py",
                         doc(rows, load0, os.getloadavg()[0]))
    return 0


def doc(rows, load0, load1):
    """The generated block of BENCHMARKS.md: a headline line, the summary, the slowest objects."""
    walls = [r["wall_s"] for r in rows]
    slowest = sorted(rows, key=lambda r: -r["wall_s"])
    real = sum(pathlib.Path(r["input"]).suffix == ".toml" for r in rows)
    head = docblock.headline_line(
        objects=len(rows), within_5s=sum(w <= 5 for w in walls),
        within_05s=sum(w <= 0.5 for w in walls), median_s=f"{statistics.median(walls):.3f}",
        p95_s=f"{percentile(walls, 0.95):.3f}", max_s=f"{max(walls):.2f}",
        slowest=pathlib.Path(slowest[0]["input"]).stem, load=f"{load0:.1f}–{load1:.1f}")
    text = [head, "",
            f"Run at {docblock.revision()} on {datetime.date.today()}, load average "
            f"{load0:.1f} at the start and {load1:.1f} at the end, {os.cpu_count()} CPUs: "
            f"{len(rows)} objects ({real} "
            f"real-object scenarios, {len(rows) - real} hard meshes), median "
            f"{statistics.median(walls):.3f} s, 95th percentile {percentile(walls, 0.95):.3f} s, "
            f"max {max(walls):.2f} s; {sum(w <= 0.5 for w in walls)} within 0.5 s, "
            f"{sum(w <= 5 for w in walls)} within 5 s, "
            f"{sum(r['timed_out'] for r in rows)} timed out.",
            "", "The ten slowest:", "",
            "| object | triangles | wall [s] | candidates tried | result |",
            "|---|---|---|---|---|"]
    for r in slowest[:10]:
        what = r.get("grasp") or (r.get("reason") or "")[:60] or r.get("error") or "timed out"
        text.append(f"| {pathlib.Path(r['input']).stem} | {r.get('triangles', '')} "
                    f"| {r['wall_s']:.2f} | {r.get('candidates_tried', '')} | {what} |")
    return "\n".join(text) + "\n"


def summary(rows):
    """Prints the median, the 95th percentile, the max and the counts within 0.5 s and 5 s."""
    walls = [r["wall_s"] for r in rows]
    print(
        f"{len(rows)} objects: median {statistics.median(walls):.3f} s, "
        f"95th percentile {percentile(walls, 0.95):.3f} s, max {max(walls):.3f} s, "
        f"within 0.5 s {sum(w <= 0.5 for w in walls)}, within 5 s {sum(w <= 5 for w in walls)}, "
        f"timed out {sum(r['timed_out'] for r in rows)}"
    )


if __name__ == "__main__":
    sys.exit(main())
