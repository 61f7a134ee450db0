#!/usr/bin/env python3
"""Agreement with MuJoCo, and the `down` speed ratio, for one or more rapier settings in one run.

    python3 scripts/engine_agreement.py [--binary target/release/grasp-sim] [--out DIR]
        [--variant NAME=KEY=VALUE[,KEY=VALUE...] ...] [--json FILE] SCENARIO...

Every scenario is checked with gravity `down` on its first planned grasp (`max_checked = 1`, so
every setting checks the same grasp), once per variant (`base`, the defaults, always first), the
first variant's scene exported (`--export-mjcf`: the scene does not depend on the rapier
settings) and replayed once in MuJoCo (scripts/mujoco_replay.py, the full-length protocol with
the same closing rule; its simulation loop timed alone). Prints one Markdown row per scenario
(each variant's verdict and wall time, MuJoCo's, agreement) and per variant: how many verdicts
agree with MuJoCo's, the sum of the checks' wall times against MuJoCo's, and D40's ratio.
--json writes {variant: {scenario: {"rapier", "mujoco", "agree", "rapier_ms", "mujoco_ms"}}}.
--mujoco-from FILE takes MuJoCo's verdicts and times from such a file (an earlier run's, same
scenarios) instead of exporting and replaying again: more variants judged against one replay.
"""
import argparse
import json
import pathlib
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import mujoco_replay  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
PATH_KEY = re.compile(r'^(\s*(?:mesh|file)\s*=\s*")([^"]+)(")', re.M)


def with_sim(path, keys):
    """The scenario's text with absolute paths and `keys` ({key: TOML value}) in its [sim]."""
    path = pathlib.Path(path).resolve()
    text = path.read_text()

    def absolute(m):
        v = m.group(2)
        if v.startswith("/") or ("/" not in v and "." not in v):
            return m.group(0)
        return m.group(1) + str((path.parent / v).resolve()) + m.group(3)

    text = PATH_KEY.sub(absolute, text)
    for k in keys:
        text = re.sub(rf"^\s*{re.escape(k)}\s*=.*$", "", text, flags=re.M)
    lines = "".join(f"{k} = {v}\n" for k, v in keys.items())
    if re.search(r"^\[sim\]\s*$", text, re.M):
        return re.sub(r"^\[sim\]\s*$", "[sim]\n" + lines.rstrip("\n"), text, count=1, flags=re.M)
    return text + "\n[sim]\n" + lines


def run_variant(binary, scenarios, keys, tmp, export):
    files = []
    for s in scenarios:
        f = pathlib.Path(tmp) / pathlib.Path(s).name
        f.write_text(with_sim(s, keys))
        files.append(str(f))
    cmd = [binary, "--json", *files]
    if export is not None:
        cmd[1:1] = ["--export-mjcf", str(export)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode == 2:
        sys.exit(p.stderr)
    return {json.loads(line)["scenario"]: json.loads(line)["sim"] for line in p.stdout.splitlines()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "grasp-sim"))
    ap.add_argument("--out", default=str(ROOT / "out" / "engine_agreement"))
    ap.add_argument("--variant", action="append", default=[], metavar="NAME=KEY=VALUE,...")
    ap.add_argument("--json")
    ap.add_argument("--mujoco-from", metavar="MJ.json")
    ap.add_argument("scenarios", nargs="+")
    a = ap.parse_args()
    base = {"max_checked": "1", "gravity": '"down"'}
    variants = [("base", dict(base))]
    for v in a.variant:
        name, kvs = v.split("=", 1)
        keys = dict(base)
        for kv in kvs.split(","):
            k, val = kv.split("=", 1)
            keys[k.strip()] = val.strip()
        variants.append((name, keys))
    out = pathlib.Path(a.out)
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for i, (name, keys) in enumerate(variants):
            d = pathlib.Path(tmp) / name
            d.mkdir()
            export = out if i == 0 and not a.mujoco_from else None
            results[name] = run_variant(a.binary, a.scenarios, keys, d, export)
    names = [n for n, _ in variants]
    mj = {}
    if a.mujoco_from:
        earlier = json.loads(pathlib.Path(a.mujoco_from).read_text())["base"]
        mj = {scen: {"verdict": r["mujoco"], "wall_ms": r["mujoco_ms"]}
              for scen, r in earlier.items() if scen in results["base"]}
    for scen in results["base"] if not a.mujoco_from else []:
        if (out / scen / "scene.xml").is_file():
            mj[scen] = mujoco_replay.replay(out / scen)
    table = {n: {} for n in names}
    head = " | ".join(f"{n} | {n} [ms]" for n in names)
    print(f"| scenario | {head} | MuJoCo | MuJoCo [ms] | agree |")
    print("|---|" + "---|---|" * len(names) + "---|---|---|")
    for scen, m in mj.items():
        cells, agrees = [], []
        for n in names:
            sim = results[n].get(scen, {})
            agree = sim.get("verdict") == m["verdict"]
            table[n][scen] = {"rapier": sim.get("verdict"), "mujoco": m["verdict"], "agree": agree,
                              "rapier_ms": sim.get("wall_ms"), "mujoco_ms": m["wall_ms"]}
            cells.append(f"{sim.get('verdict')} | {sim.get('wall_ms') or 0:.1f}")
            agrees.append("yes" if agree else "**no**")
        print(f"| {scen} | {' | '.join(cells)} | {m['verdict']} | {m['wall_ms']:.1f} | "
              f"{' / '.join(agrees)} |")
    print()
    for n in names:
        t = table[n]
        agree = sum(1 for r in t.values() if r["agree"])
        rs = sum(r["rapier_ms"] or 0 for r in t.values())
        ms = sum(r["mujoco_ms"] for r in t.values())
        d40 = next((r for s, r in t.items() if s == "cylinder_d40"), None)
        d40r = f", D40 {d40['rapier_ms'] / d40['mujoco_ms']:.3f}" if d40 else ""
        print(f"{n}: MuJoCo agrees on {agree} of {len(t)}; checks {rs:.0f} ms against MuJoCo's "
              f"{ms:.0f} ms, ratio {rs / ms:.3f}{d40r}")
    if a.json:
        pathlib.Path(a.json).write_text(json.dumps(table, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
