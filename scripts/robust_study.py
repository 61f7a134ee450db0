#!/usr/bin/env python3
"""The hold-probability study of issue 34 on the real-object set (docs/SIM.md, "Hold probability").

    python3 scripts/robust_study.py [--binary target/release/grasp-sim] [--out out/robust]
                                    [--samples 16] [--mujoco none|down|six] [--mujoco-jobs 1]
                                    [--figure docs/figures/hold_probability.svg] [NAME ...]

For every scenario in assets/real/scenarios/ (as scripts/real_objects_eval.py runs them: the
scenario's own mesh and hand paths made absolute, `[sim] gravity = "six"`): one run of
`grasp-sim --json --samples N --export-mjcf OUT/mjcf`, which plans, makes the main check (the
verdict at N = 1, unchanged by the samples) and N perturbed checks, each in six directions, and
writes every sample's scene for MuJoCo. With `--mujoco six` (or `down`) every sample's scene is
replayed by scripts/mujoco_replay.py in the six directions from one closing (or under the
scene's gravity only).

Each object's result is kept in OUT/rapier/<name>.json and OUT/mujoco/<name>.json, so a run
that stops can be continued, and `--mujoco` can be added later without running grasp-sim
again. Prints the Markdown table and the summary lines (the distribution of the hold
probabilities; the main-check holds whose 95 % lower bound is under 0.9; the agreement with
MuJoCo: mean |p_rapier - p_MuJoCo|, the Brier score of each engine's p against the other's
per-sample outcomes, and the grasps where one says >= 0.9 while the other says < 0.5), writes
them to OUT/study.md, and draws the figure (SVG written by hand: no plotting library needed).
"""
import argparse
import csv
import json
import pathlib
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
from real_objects_eval import REAL, TIMEOUT_S, scenario_text  # noqa: E402

DIRS = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"]


def run_rapier(binary, scenario, samples, tmp, mjcf):
    """One object's run: the JSON line of grasp-sim, with the process's wall time."""
    s = pathlib.Path(tmp) / f"{scenario.stem}.toml"
    s.write_text(scenario_text(scenario, "six"))
    cmd = [binary, "--json", "--samples", str(samples), "--export-mjcf", str(mjcf), s.as_posix()]
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout: no result within {TIMEOUT_S} s", "wall_s": TIMEOUT_S}
    wall = time.monotonic() - t0
    if p.returncode == 2 or not p.stdout.strip():
        last = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "no output"
        return {"error": last, "wall_s": wall}
    r = json.loads(p.stdout.splitlines()[0])
    sim = r["sim"]
    return {
        "wall_s": wall,
        "plan": r["plan"]["status"],
        "verdict": sim["verdict"],
        "main_directions": [d["verdict"] for d in sim.get("directions", [])],
        "robust": sim.get("robust"),
    }


def run_mujoco(mjcf, name, samples, mode):
    """MuJoCo's verdict of every sample's exported scene (`mode`: "six" or "down")."""
    import mujoco_replay

    verdicts, directions, wall = [], [], 0.0
    for k in range(samples):
        m = mujoco_replay.replay(mjcf / name / "samples" / str(k),
                                 mujoco_replay.SIX if mode == "six" else None)
        verdicts.append(m["verdict"])
        directions.append([d["verdict"] for d in m.get("directions", [])])
        wall += m["wall_ms"]
    return {"mode": mode, "verdicts": verdicts, "directions": directions, "wall_ms": wall}


def mujoco_one(job):
    """One object's MuJoCo replay, kept in OUT/mujoco/<name>.json (a process of its own)."""
    out, mjcf, name, samples, mode = job
    path = out / "mujoco" / f"{name}.json"
    if path.is_file() and json.loads(path.read_text())["mode"] == mode:
        return json.loads(path.read_text())
    m = run_mujoco(mjcf, name, samples, mode)
    path.write_text(json.dumps(m))
    print(f"{name}: MuJoCo {sum(v == 'hold' for v in m['verdicts'])} of {samples} held", file=sys.stderr)
    return m


def cached(path, make):
    """`make()` stored as JSON at `path`, or what an earlier run stored there."""
    if path.is_file():
        return json.loads(path.read_text())
    value = make()
    path.write_text(json.dumps(value))
    return value


def bins(ps):
    """The distribution's five classes."""
    return {
        "p = 1": sum(p == 1.0 for p in ps),
        "0.9 <= p < 1": sum(0.9 <= p < 1.0 for p in ps),
        "0.5 <= p < 0.9": sum(0.5 <= p < 0.9 for p in ps),
        "0 < p < 0.5": sum(0.0 < p < 0.5 for p in ps),
        "p = 0": sum(p == 0.0 for p in ps),
    }


def agreement(rows):
    """MuJoCo against rapier over the grasps both ran: mean |dp|, both Brier scores, splits."""
    both = [r for r in rows if r.get("mujoco")]
    if not both:
        return None

    def brier(p_engine, other):
        terms = [(r[p_engine] - (v == "hold")) ** 2 for r in both for v in r[other]]
        return sum(terms) / len(terms)

    return {
        "grasps": len(both),
        "mean_abs_diff": sum(abs(r["p"] - r["mujoco_p"]) for r in both) / len(both),
        "brier_rapier": brier("p", "mujoco_verdicts"),
        "brier_mujoco": brier("mujoco_p", "verdicts"),
        "split": [r["name"] for r in both
                  if (r["p"] >= 0.9 and r["mujoco_p"] < 0.5) or (r["mujoco_p"] >= 0.9 and r["p"] < 0.5)],
        "same_samples": sum(sum(a == b for a, b in zip(r["verdicts"], r["mujoco_verdicts"])) for r in both),
        "samples": sum(len(r["verdicts"]) for r in both),
        "mode": both[0]["mujoco"]["mode"],
        "rapier_ms": sum(r["wall_ms"] for r in both),
        "mujoco_ms": sum(r["mujoco"]["wall_ms"] for r in both),
    }


def named(rows):
    """"name held/n, ..." of `rows`."""
    return ", ".join(f"{r['name']} {r['held']}/{r['n']}" for r in rows)


def table(rows, labels):
    """The Markdown table and the summary lines."""
    out = ["| object | label | main check | held of N | p | 95 % interval | per direction (held: "
           "+X -X +Y -Y +Z -Z) | MuJoCo p | same verdict | samples' wall [s] |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "p" not in r:
            out.append(f"| {r['name']} | {labels[r['name']]} | {r['verdict']} | | | | | | | |")
            continue
        mj = r.get("mujoco")
        mp = f"{r['mujoco_p']:.3f}" if mj else ""
        same = f"{sum(a == b for a, b in zip(r['verdicts'], mj['verdicts']))} of {r['n']}" if mj else ""
        lo, hi = r["interval"]
        out.append(f"| {r['name']} | {labels[r['name']]} | {r['verdict']} | {r['held']} of {r['n']} "
                   f"| {r['p']:.3f} | [{lo:.2f}, {hi:.2f}] | {' '.join(str(h) for h in r['per_direction'])} "
                   f"| {mp} | {same} | {r['wall_ms'] / 1000:.1f} |")
    sampled = [r for r in rows if "p" in r]
    holds = [r for r in sampled if r["verdict"] == "hold"]
    weak = [r for r in holds if r["interval"][0] < 0.9]
    below1 = [r for r in holds if r["p"] < 1.0]
    lucky = [r for r in sampled if r["verdict"] != "hold" and r["p"] > 0.0]
    dist = ", ".join(f"{k}: {v}" for k, v in bins([r["p"] for r in sampled]).items())
    out += ["", f"{len(rows)} objects, {len(sampled)} grasps sampled ({len(rows) - len(sampled)} without "
            f"a grasp to sample); distribution of p: {dist}",
            f"main-check holds: {len(holds)}; of those with a 95 % lower bound under 0.9: {len(weak)}; "
            f"with p < 1: {len(below1)} ({named(below1)}); with p < 0.5: "
            f"{sum(r['p'] < 0.5 for r in holds)}",
            f"main check not `hold` but some samples held: {len(lucky)} "
            f"({named(lucky)})"]
    a = agreement(rows)
    if a:
        out.append(f"MuJoCo ({a['mode']}) on the same samples, {a['grasps']} grasps: mean |p_rapier - "
                   f"p_MuJoCo| {a['mean_abs_diff']:.3f}; Brier score of rapier's p against MuJoCo's "
                   f"samples {a['brier_rapier']:.3f}, of MuJoCo's p against rapier's "
                   f"{a['brier_mujoco']:.3f}; one engine >= 0.9 while the other < 0.5: "
                   f"{len(a['split'])} ({', '.join(a['split'])}); samples with the same verdict: "
                   f"{a['same_samples']} of {a['samples']}; wall: rapier's samples "
                   f"{a['rapier_ms'] / 1000:.0f} s, MuJoCo's {a['mujoco_ms'] / 1000:.0f} s")
    return "\n".join(out)


def svg(rows, path):
    """Two panels: the number of grasps per count of held samples (bars split by the main
    check's verdict), and each grasp's rapier p against MuJoCo's."""
    sampled = [r for r in rows if "p" in r]
    if not sampled:
        return
    n = max(r["n"] for r in sampled)
    w, h, left, bottom, top = 820, 330, 50, 50, 40
    pw = 420
    counts = [[0, 0] for _ in range(n + 1)]
    for r in sampled:
        counts[r["held"]][0 if r["verdict"] == "hold" else 1] += 1
    ymax = max(sum(c) for c in counts)
    ymax = max(1, ymax)
    ph = h - bottom - top
    bw = pw / (n + 1)
    e = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" '
         f'font-size="11"><rect width="{w}" height="{h}" fill="white"/>',
         f'<text x="{left}" y="16" font-size="13">Hold probability under perturbation, real-object set '
         f'({len(sampled)} grasps, N = {n}, six directions)</text>']
    y0 = top + ph

    def ybar(v):
        return y0 - ph * v / ymax

    for t in range(0, ymax + 1, max(1, ymax // 5)):
        e.append(f'<line x1="{left}" y1="{ybar(t):.1f}" x2="{left + pw}" y2="{ybar(t):.1f}" stroke="#ddd"/>'
                 f'<text x="{left - 6}" y="{ybar(t) + 4:.1f}" text-anchor="end">{t}</text>')
    for k, (hold, other) in enumerate(counts):
        x = left + k * bw + 1
        if hold:
            e.append(f'<rect x="{x:.1f}" y="{ybar(hold):.1f}" width="{bw - 2:.1f}" '
                     f'height="{y0 - ybar(hold):.1f}" fill="#2b7bba"/>')
        if other:
            e.append(f'<rect x="{x:.1f}" y="{ybar(hold + other):.1f}" width="{bw - 2:.1f}" '
                     f'height="{ybar(hold) - ybar(hold + other):.1f}" fill="#e08a3c"/>')
        if k % 2 == 0:
            e.append(f'<text x="{x + bw / 2 - 1:.1f}" y="{y0 + 14}" text-anchor="middle">{k}</text>')
    e.append(f'<line x1="{left}" y1="{y0}" x2="{left + pw}" y2="{y0}" stroke="black"/>')
    e.append(f'<text x="{left + pw / 2}" y="{y0 + 32}" text-anchor="middle">samples held of {n} '
             f'(every direction)</text>')
    e.append(f'<text x="14" y="{top + ph / 2}" text-anchor="middle" transform="rotate(-90 14 '
             f'{top + ph / 2})">grasps</text>')
    lx = left + 0.3 * pw
    e.append(f'<rect x="{lx}" y="{top}" width="10" height="10" fill="#2b7bba"/>'
             f'<text x="{lx + 14}" y="{top + 9}">main check (N = 1): hold</text>'
             f'<rect x="{lx}" y="{top + 16}" width="10" height="10" fill="#e08a3c"/>'
             f'<text x="{lx + 14}" y="{top + 25}">main check (N = 1): slip, drop</text>')
    both = [r for r in sampled if r.get("mujoco")]
    sx, side = left + pw + 70, ph
    e.append(f'<rect x="{sx}" y="{top}" width="{side}" height="{side}" fill="none" stroke="black"/>')
    for t in (0.0, 0.5, 1.0):
        e.append(f'<text x="{sx + side * t:.1f}" y="{y0 + 14}" text-anchor="middle">{t:g}</text>'
                 f'<text x="{sx - 6}" y="{y0 - side * t + 4:.1f}" text-anchor="end">{t:g}</text>')
    e.append(f'<line x1="{sx}" y1="{y0}" x2="{sx + side}" y2="{top}" stroke="#bbb" stroke-dasharray="4 3"/>')
    e.append(f'<text x="{sx + side / 2}" y="{y0 + 32}" text-anchor="middle">rapier p</text>')
    e.append(f'<text x="{sx - 30}" y="{top + side / 2}" text-anchor="middle" transform="rotate(-90 '
             f'{sx - 30} {top + side / 2})">MuJoCo p (same samples)</text>')
    if not both:
        e.append(f'<text x="{sx + side / 2}" y="{top + side / 2}" text-anchor="middle">(MuJoCo not run)</text>')
    # Grasps at the same point are drawn as one circle whose area grows with their number.
    points = {}
    for r in both:
        points.setdefault((r["p"], r["mujoco_p"]), []).append(r["name"])
    for (p, q), names in sorted(points.items()):
        rad = 3.0 * len(names) ** 0.5
        e.append(f'<circle cx="{sx + side * p:.1f}" cy="{y0 - side * q:.1f}" r="{rad:.1f}" fill="#2b7bba" '
                 f'fill-opacity="0.6"><title>{", ".join(names)}</title></circle>')
        if len(names) > 1:
            e.append(f'<text x="{sx + side * p + rad + 2:.1f}" y="{y0 - side * q - rad:.1f}" '
                     f'font-size="9">{len(names)}</text>')
    e.append("</svg>")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(e) + "\n")


def row_of(name, r, m):
    row = {"name": name, "verdict": r.get("verdict", "not_run"), "wall_ms": 0.0}
    rb = r.get("robust")
    if not rb:
        if "error" in r:
            row["verdict"] = f"not_run ({r['error'][:60]})"
        return row
    row.update(n=rb["samples"], held=rb["counts"]["hold"], p=rb["hold_probability"], interval=rb["interval"],
               per_direction=[d["counts"]["hold"] for d in rb["directions"]], verdicts=rb["verdicts"],
               wall_ms=rb["wall_ms"])
    if m:
        row.update(mujoco=m, mujoco_verdicts=m["verdicts"],
                   mujoco_p=sum(v == "hold" for v in m["verdicts"]) / len(m["verdicts"]))
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "grasp-sim"))
    ap.add_argument("--out", default=str(ROOT / "out" / "robust"))
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--mujoco", choices=["none", "down", "six"], default="none")
    ap.add_argument("--mujoco-jobs", type=int, default=1)
    ap.add_argument("--mujoco-budget-s", type=float, default=0.0,
                    help="start no MuJoCo replay of a new object after this many seconds (0: no limit)")
    ap.add_argument("--no-rapier", action="store_true",
                    help="use only the objects whose grasp-sim run is already in OUT/rapier")
    ap.add_argument("--figure", default=str(ROOT / "docs" / "figures" / "hold_probability.svg"))
    ap.add_argument("names", nargs="*", help="only these objects")
    a = ap.parse_args()

    labels = {r["name"]: r["label"] for r in csv.DictReader(open(REAL / "manifest.csv"))}
    scenarios = sorted((REAL / "scenarios").glob("*.toml"))
    if a.names:
        scenarios = [s for s in scenarios if s.stem in a.names]
    out = pathlib.Path(a.out)
    mjcf = out / "mjcf"
    for d in (mjcf, out / "rapier", out / "mujoco"):
        d.mkdir(parents=True, exist_ok=True)
    rapier = {}
    with tempfile.TemporaryDirectory() as tmp:
        for s in scenarios:
            path = out / "rapier" / f"{s.stem}.json"
            if a.no_rapier and not path.is_file():
                continue
            rapier[s.stem] = cached(path, lambda s=s: run_rapier(a.binary, s, a.samples, tmp, mjcf))
            r = rapier[s.stem]
            print(f"{s.stem}: {r.get('verdict', r.get('error'))}, "
                  f"{(r.get('robust') or {}).get('counts', {}).get('hold', '-')} of {a.samples} held",
                  file=sys.stderr)
    scenarios = [s for s in scenarios if s.stem in rapier]
    mj = {}
    if a.mujoco != "none":
        # The most informative first, as far as the time budget goes: the grasps rapier finds
        # marginal (0 < p < 1), then those that held every sample, then those that held none.
        def order(name):
            p = rapier[name]["robust"]["hold_probability"]
            return (0 if 0.0 < p < 1.0 else 1 if p == 1.0 else 2, name)

        todo = sorted((s.stem for s in scenarios if rapier[s.stem].get("robust")), key=order)
        jobs = [(out, mjcf, name, a.samples, a.mujoco) for name in todo]
        t0 = time.monotonic()
        with ProcessPoolExecutor(a.mujoco_jobs) as pool:
            running = {}
            for job in jobs:
                if a.mujoco_budget_s and time.monotonic() - t0 > a.mujoco_budget_s:
                    print(f"MuJoCo: time budget spent, {job[2]} and after not started", file=sys.stderr)
                    break
                running[job[2]] = pool.submit(mujoco_one, job)
                while sum(not f.done() for f in running.values()) >= a.mujoco_jobs:
                    time.sleep(1.0)
            for name, f in running.items():
                mj[name] = f.result()
    for s in scenarios:
        path = out / "mujoco" / f"{s.stem}.json"
        if s.stem not in mj and path.is_file():
            mj[s.stem] = json.loads(path.read_text())
    rows = [row_of(s.stem, rapier[s.stem], mj.get(s.stem)) for s in scenarios]
    text = table(rows, labels)
    print(text)
    (out / "study.md").write_text(text + "\n")
    svg(rows, pathlib.Path(a.figure))


if __name__ == "__main__":
    main()
