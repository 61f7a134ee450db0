#!/usr/bin/env python3
"""Issue 35's three speed figures in one run, each variant beside the defaults, alternating.

    python3 scripts/speed_ratios.py [--binary target/release/grasp-sim] [--rounds 5]
        [--scenario scenarios/cylinder_d40.toml] [--variant NAME=KEY=VALUE[,KEY=VALUE...] ...]
        [--batch] [--batch-mujoco] [--jobs 2] [--batch-dir assets/real/scenarios] [--json FILE]

Per round, for the defaults (`base`) and each variant in turn: the scenario's check with
gravity `down` and with `six` (grasp-sim's `sim.wall_ms`: the physics check alone, planning
excluded), and once per round MuJoCo's replay of the same exported `down` scene
(scripts/mujoco_replay.py, its simulation loop timed alone). Each ratio is taken within its
round and the median over the rounds printed:

- `down`: rapier's `down` check / MuJoCo's replay (issue 35's target: at most 0.1);
- `six`: rapier's `six` check / MuJoCo's `down` replay (target: at most 0.15);

and the steps of each check (`sim.steps`, deterministic). With --batch, every real-object
scenario (the book left out: its planning takes minutes) is written with `gravity = "six"` (and
the variant's keys) and run by `grasp-sim batch --jobs N`, base and variants one after another:
the six-direction checks (`plan.candidates_checked`, summed) per second of the batch's wall time
(target: at least 20 on 2 cores), and per CPU-second of its worker processes. The load average
(`/proc/loadavg`) is printed with every figure: wall times on a shared machine are only as good
as the load lets them be.

With --batch-mujoco, the dataset figure beside MuJoCo (issue 35's third deliverable): each of
those real-object scenarios is run once more by grasp-sim with `--export-mjcf` (its reported
grasp's scene, `gravity = "six"`), and MuJoCo replays the exported scenes in six directions
(`mujoco_replay.replay(dir, SIX)`: one closing, each direction held from it for the whole hold),
`--jobs` replays at a time in worker processes: the scenes replayed per second of wall time and
per CPU-second of the workers, and the sum of the replays' simulation loops against the sum of
grasp-sim's `sim.wall_ms` for the same grasps (the physics of the same six-direction checks,
one thread).

With --write-doc, the table (and the MuJoCo line) replaces the generated block of BENCHMARKS.md
("Physics check"), whose headline line gives the README's speed figures (scripts/headline.py:
the `base` variant's medians and batch rate).
"""
import argparse
import concurrent.futures
import datetime
import json
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import docblock  # noqa: E402
import mujoco_replay  # noqa: E402
from engine_agreement import with_sim  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent


def load():
    return " ".join(pathlib.Path("/proc/loadavg").read_text().split()[:3])


def check(binary, scenario, keys, tmp, export=None, env=None):
    """grasp-sim's JSON `sim` of `scenario` with `keys` in its [sim]."""
    f = pathlib.Path(tmp) / pathlib.Path(scenario).name
    f.write_text(with_sim(scenario, keys))
    cmd = [binary, "--json", str(f)]
    if export is not None:
        cmd[1:1] = ["--export-mjcf", str(export)]
    p = subprocess.run(cmd, capture_output=True, text=True,
                       env=None if env is None else {**os.environ, **env})
    if p.returncode == 2:
        sys.exit(p.stderr)
    return json.loads(p.stdout.splitlines()[0]).get("sim")


def parse_variants(specs):
    variants = [("base", {})]
    for v in specs:
        name, kvs = v.split("=", 1)
        keys = {}
        for kv in kvs.split(","):
            k, val = kv.split("=", 1)
            keys[k.strip()] = val.strip()
        variants.append((name, keys))
    return variants


def ratios(a, variants, tmp):
    """Per variant: the rounds' `down` and `six` ratios, steps and walls."""
    out = {n: {"down": [], "six": [], "down_ms": [], "six_ms": [], "mujoco_ms": []}
           for n, _ in variants}
    scen = pathlib.Path(a.scenario).stem
    for r in range(a.rounds):
        exp = pathlib.Path(tmp) / f"export{r}"
        sims = {}
        for i, (name, keys) in enumerate(variants):
            d = pathlib.Path(tmp) / f"r{r}_{name}"
            d.mkdir()
            base = {"max_checked": "1"}
            down = check(a.binary, a.scenario, {**base, **keys, "gravity": '"down"'}, d,
                         exp if i == 0 else None)
            six = check(a.binary, a.scenario, {**base, **keys, "gravity": '"six"'}, d)
            sims[name] = (down, six)
        mj = mujoco_replay.replay(exp / scen)
        for name, (down, six) in sims.items():
            o = out[name]
            o["down"].append(down["wall_ms"] / mj["wall_ms"])
            o["six"].append(six["wall_ms"] / mj["wall_ms"])
            o["down_ms"].append(down["wall_ms"])
            o["six_ms"].append(six["wall_ms"])
            o["mujoco_ms"].append(mj["wall_ms"])
            o["steps"] = (down["steps"], six["steps"])
            o["verdicts"] = (down["verdict"], six["verdict"], mj["verdict"])
        print(f"round {r + 1}: load {load()}; MuJoCo {mj['wall_ms']:.1f} ms; "
              + "; ".join(f"{n} down {out[n]['down_ms'][-1]:.1f} six {out[n]['six_ms'][-1]:.1f} ms"
                          for n in out), file=sys.stderr)
    return out


def batch(a, keys, tmp, name):
    """The batch over the real-object set in six directions: checks, wall, CPU, load."""
    d = pathlib.Path(tmp) / f"batch_{name}"
    d.mkdir()
    for s in sorted(pathlib.Path(a.batch_dir).glob("*.toml")):
        if any(k in s.stem for k in a.skip):
            continue
        (d / s.name).write_text(with_sim(s, {**keys, "gravity": '"six"'}))
    out = pathlib.Path(tmp) / f"batch_{name}.jsonl"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    l0 = load()
    t0 = time.monotonic()
    p = subprocess.run([a.binary, "batch", "--jobs", str(a.jobs), "--out", str(out), str(d)],
                       capture_output=True, text=True)
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode == 2 and not out.is_file():
        sys.exit(p.stderr)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    checks, objects, sim_ms, verdicts = 0, 0, 0.0, {}
    errors = []
    for line in out.read_text().splitlines():
        rec = json.loads(line)
        if "error" in rec:
            errors.append(f"{rec.get('scenario')}: {rec['error']}")
            continue
        objects += 1
        checks += (rec.get("plan") or {}).get("candidates_checked") or 0
        sim = rec.get("sim") or {}
        v = sim.get("verdict", "not_run")
        verdicts[v] = verdicts.get(v, 0) + 1
    if errors:
        # A missing mesh (the LIBERO ones are not in git: scripts/real_objects.py makes them)
        # would make the rate a figure of fewer objects without saying so.
        sys.exit(f"speed_ratios: {len(errors)} of the batch's scenarios failed, first: "
                 f"{errors[0]} (run python3 scripts/real_objects.py for the real-object meshes)")
    return {"objects": objects, "checks": checks, "wall_s": wall, "cpu_s": cpu,
            "rate": checks / wall, "per_cpu_s": checks / cpu if cpu else 0.0,
            "load": f"{l0} → {load()}", "verdicts": verdicts, "sim_ms": sim_ms}


def export_six(binary, scenario, tmp):
    """grasp-sim's run of `scenario` in six directions with its reported grasp's scene exported:
    (the scene's directory, or None when no grasp was checked; the JSON's `sim`). One thread, so
    that `sim.wall_ms` is the physics' CPU time, as a batch worker's is."""
    d = pathlib.Path(tmp) / "mj_export"
    d.mkdir(exist_ok=True)
    sim = check(binary, scenario, {"gravity": '"six"'}, d, d / "scenes",
                {"RAYON_NUM_THREADS": "1"}) or {}
    scene = d / "scenes" / pathlib.Path(scenario).stem
    return (scene if (scene / "scene.xml").is_file() else None), sim


def replay_six(scene):
    """MuJoCo's six-direction replay of one exported scene, in a worker process."""
    r = mujoco_replay.replay(scene, mujoco_replay.SIX)
    return {"wall_ms": r["wall_ms"], "verdict": r["verdict"], "steps": r["steps"]}


def batch_mujoco(a, tmp):
    """MuJoCo replaying the real-object set's reported grasps in six directions, `--jobs` at a
    time, beside grasp-sim's physics for the same grasps."""
    scenes, rapier_ms = [], 0.0
    for s in sorted(pathlib.Path(a.batch_dir).glob("*.toml")):
        if any(k in s.stem for k in a.skip):
            continue
        scene, sim = export_six(a.binary, s, tmp)
        if scene is not None and sim.get("wall_ms") is not None:
            scenes.append(scene)
            rapier_ms += sim["wall_ms"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    l0 = load()
    t0 = time.monotonic()
    with concurrent.futures.ProcessPoolExecutor(max_workers=a.jobs) as pool:
        runs = list(pool.map(replay_six, scenes))
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    loops_ms = sum(r["wall_ms"] for r in runs)
    return {"scenes": len(scenes), "wall_s": wall, "cpu_s": cpu, "rate": len(scenes) / wall,
            "per_cpu_s": len(scenes) / cpu if cpu else 0.0, "mujoco_loops_ms": loops_ms,
            "rapier_sim_ms": rapier_ms, "ratio": rapier_ms / loops_ms if loops_ms else None,
            "load": f"{l0} → {load()}"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "grasp-sim"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--scenario", default=str(ROOT / "scenarios" / "cylinder_d40.toml"))
    ap.add_argument("--variant", action="append", default=[], metavar="NAME=KEY=VALUE,...")
    ap.add_argument("--batch", action="store_true")
    ap.add_argument("--batch-mujoco", action="store_true",
                    help="MuJoCo replaying the real-object set's grasps in six directions")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--batch-dir", default=str(ROOT / "assets" / "real" / "scenarios"))
    ap.add_argument("--skip", action="append", default=["black_book"],
                    help="leave out scenarios whose name contains this (default: the book)")
    ap.add_argument("--batch-only", action="append", default=[], metavar="NAME",
                    help="run the batch for these variants only (default: all)")
    ap.add_argument("--json")
    ap.add_argument("--write-doc", action="store_true",
                    help="replace BENCHMARKS.md's generated block with this run's table")
    a = ap.parse_args()
    variants = parse_variants(a.variant)
    result = {}
    with tempfile.TemporaryDirectory() as tmp:
        start_load = load()
        print(f"load at the start: {start_load}", file=sys.stderr)
        r = ratios(a, variants, tmp) if a.rounds > 0 else {}
        b = {n: batch(a, keys, tmp, n) for n, keys in variants
             if a.batch and (not a.batch_only or n in a.batch_only)}
        m = batch_mujoco(a, tmp) if a.batch_mujoco else None
    lines = []

    def out(text=""):
        lines.append(text)
        print(text)

    out(f"| variant | `down` / MuJoCo (target ≤ 0.1) | `six` / MuJoCo's `down` (≤ 0.15) | "
        f"steps down, six | six-direction checks a second, batch --jobs {a.jobs} (≥ 20) |")
    out("|---|---|---|---|---|")
    for n, _ in variants:
        cells = ["", "", "", ""]
        if n in r:
            o = r[n]
            cells[0] = (f"{statistics.median(o['down']):.3f} ({min(o['down']):.3f}–"
                        f"{max(o['down']):.3f}; {statistics.median(o['down_ms']):.1f} against "
                        f"{statistics.median(o['mujoco_ms']):.1f} ms)")
            cells[1] = (f"{statistics.median(o['six']):.3f} ({min(o['six']):.3f}–"
                        f"{max(o['six']):.3f}; {statistics.median(o['six_ms']):.1f} ms)")
            cells[2] = f"{o['steps'][0]:,}, {o['steps'][1]:,} ({'/'.join(o['verdicts'])})"
        if n in b:
            x = b[n]
            cells[3] = (f"{x['rate']:.2f} ({x['checks']} checks of {x['objects']} objects in "
                        f"{x['wall_s']:.0f} s; {x['per_cpu_s']:.2f} per CPU-second; load "
                        f"{x['load']})")
        out(f"| {n} | " + " | ".join(cells) + " |")
        result[n] = {"ratios": r.get(n), "batch": b.get(n)}
    if m is not None:
        out(f"\nMuJoCo, the same set's {m['scenes']} reported grasps replayed in six directions, "
            f"{a.jobs} at a time: {m['rate']:.2f} a second ({m['wall_s']:.0f} s wall; "
            f"{m['per_cpu_s']:.2f} per CPU-second; load {m['load']}); its simulation loops "
            f"{m['mujoco_loops_ms'] / 1000:.1f} s in all against grasp-sim's physics of the "
            f"same six-direction checks {m['rapier_sim_ms'] / 1000:.1f} s (ratio "
            f"{m['ratio']:.3f})")
        result["mujoco_batch"] = m
    out(f"\n{a.rounds} rounds alternating; load at the end: {load()}; "
        f"{os.cpu_count()} CPUs")
    if a.json:
        pathlib.Path(a.json).write_text(json.dumps(result, indent=1))
    if a.write_doc:
        if "base" not in r or "base" not in b:
            sys.exit("speed_ratios: --write-doc needs --rounds 1 or more and --batch")
        o, x = r["base"], b["base"]
        head = docblock.headline_line(
            down_ratio=f"{statistics.median(o['down']):.3f}",
            six_ratio=f"{statistics.median(o['six']):.3f}",
            down_ms=f"{statistics.median(o['down_ms']):.1f}",
            six_ms=f"{statistics.median(o['six_ms']):.1f}",
            checks_per_s=f"{x['rate']:.2f}", checks_per_cpu_s=f"{x['per_cpu_s']:.2f}",
            load=f"{float(start_load.split()[0]):.1f}–{float(load().split()[0]):.1f}")
        # The command as a reader would type it: a binary's path names a folder of this machine.
        args = sys.argv[1:]
        args = [x for i, x in enumerate(args)
                if x != "--binary" and not x.startswith("--binary=")
                and (i == 0 or args[i - 1] != "--binary")]
        intro = (f"Run at {docblock.revision()} on {datetime.date.today()} "
                 f"(`{' '.join(['python3', 'scripts/speed_ratios.py'] + args)}`), "
                 f"{a.rounds} rounds on {pathlib.Path(a.scenario).stem}:")
        docblock.replace(ROOT / "BENCHMARKS.md", "scripts/speed_ratios.py",
                         "\n".join([head, "", intro, ""] + lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
