#!/usr/bin/env python3
"""Replay shorter rest windows, gated by how near the contacts are to sliding, on full holds.

    cargo run --release --example early_rule -- --six --dump HOLDS.jsonl SCENARIO...
    python3 scripts/rest_rule_friction.py HOLDS.jsonl

The study behind docs/SIM.md, "Deciding early: shorter windows and the friction cone". Each line
of HOLDS.jsonl is one full-length hold sampled every 1/192 s: the object's pose relative to the
palm and, from the solver's last substep, how near the hand's contacts were to the edge of the
friction cone (`fmax`: the largest |tangent| / (mu x normal) impulse over the points carrying 2 %
of the load; `fslide`: the share of the normal load at 98 % of the cone or more).

First the default rule (the scenario's window and margin, sampled as the protocol samples, every
1/48 s) is replayed as `EarlyDecision::decide` computes it: its counts must be the Rust study's default row. Then, beside
it, a hold may also be decided over a shorter window (sampled every 1/96 s) when the contacts
carried at most a given share of their load at the cone's edge throughout that window. A
decision is wrong when the full hold ends with another verdict; its numbers are off when the
end differs by more than 0.5 mm or 10 % (0.5 deg or 10 %). Needs numpy.
"""
import json
import sys

import numpy as np

REPORT_ABS, REPORT_FRACTION = 0.5, 0.1


def z_axes(q):
    w, x, y, z = q.T
    return np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], axis=-1)


def load(path):
    holds = []
    with open(path) as f:
        for line in f:
            h = json.loads(line)
            for k in ("p", "q", "fmax", "fslide", "fpoints", "pc", "qc"):
                h[k] = np.array(h[k], dtype=float)
            h["z"] = z_axes(h["q"])
            holds.append(h)
    return holds


def judged_pairwise(h, idx):
    """Judged rotation between every pair of the samples `idx` [deg] (RestFrame::judged)."""
    if h["revolution"]:
        z = h["z"][idx]
        return np.degrees(np.arccos(np.clip(z @ z.T, -1, 1)))
    q = h["q"][idx]
    return np.degrees(2 * np.arccos(np.clip(np.abs(q @ q.T), -1, 1)))


def judged_from_closing(h, i):
    if h["revolution"]:
        zc = z_axes(h["qc"][None])[0]
        return float(np.degrees(np.arccos(np.clip(h["z"][i] @ zc, -1, 1))))
    return float(np.degrees(2 * np.arccos(np.clip(abs(h["q"][i] @ h["qc"]), -1, 1))))


def decide(h, i, window_s, every):
    """EarlyDecision::decide at fine sample `i`, on the samples every `every` fine samples."""
    dt = h["sample_dt"] * every
    w = max(1, round(window_s / dt))
    idx = np.arange(i - w * every, i + 1, every)
    if idx[0] < every - 1:
        return None
    remaining = h["duration_s"] - (i + 1) * h["sample_dt"]
    if remaining <= 1e-9:
        return None
    p = h["p"][idx]
    spread_mm = np.max(np.linalg.norm(p[:, None] - p[None], axis=-1))
    rot = judged_pairwise(h, idx)
    now_mm = float(np.linalg.norm(p[-1] - h["pc"]))
    now_deg = judged_from_closing(h, idx[-1])
    more_mm = h["safety"] * (np.linalg.norm(p[-1] - p[0]) / (w * dt) * remaining + spread_mm)
    more_deg = h["safety"] * (rot[0, -1] / (w * dt) * remaining + rot.max())
    if more_mm > max(REPORT_ABS, REPORT_FRACTION * now_mm) or more_deg > max(
        REPORT_ABS, REPORT_FRACTION * now_deg
    ):
        return None
    th_mm, th_deg = h["thresholds"]
    margin = h.get("margin", 0.8)
    if now_mm + more_mm <= margin * th_mm and now_deg + more_deg <= margin * th_deg:
        return "hold"
    if now_mm - more_mm >= th_mm / margin or now_deg - more_deg >= th_deg / margin:
        return "slip"
    return "slip" if h["penetrated"] else None


def rule(short_s=None, max_share=None):
    """The default rule; with `short_s`, also a hold over that window when at most `max_share`
    of the load was at the cone's edge at every fine sample of it."""

    def at(h, i):
        # The default rule on its own samples (every `rule_every` fine samples, 1/48 s).
        every = h.get("rule_every", 4)
        if (i + 1) % every == 0:
            v = decide(h, i, h.get("window_s", 0.2), every)
            if v:
                return v
        # The short window on every other fine sample; the gate over the same samples.
        if short_s is not None and (i + 1) % 2 == 0:
            j = i - max(1, round(short_s / (h["sample_dt"] * 2))) * 2
            if j >= 0 and (h["fpoints"][j : i + 1] > 0).all():
                if h["fslide"][j : i + 1].max() <= max_share + 1e-9 and decide(h, i, short_s, 2) == "hold":
                    return "hold"
        return None

    return at


def evaluate(label, at, holds):
    times = {"hold": [], "slip": []}
    wrong, off, d40 = [], 0, None

    def near(a, b):
        return abs(a - b) <= REPORT_ABS or abs(a - b) <= REPORT_FRACTION * max(abs(a), abs(b))

    for h in holds:
        for i in range(len(h["p"])):
            v = at(h, i)
            # A slip at rest is a rest on the hand: the protocol checks the contact.
            if v is None or (v == "slip" and h["fpoints"][i] == 0):
                continue
            t = (i + 1) * h["sample_dt"]
            times[v].append(t)
            g = h["gravity"]
            if h["name"] == "cylinder_d40" and g[2] < -0.5:
                d40 = t
            mm = float(np.linalg.norm(h["p"][i] - h["pc"]))
            deg = judged_from_closing(h, i)
            expected = "slip" if v == "hold" and h["penetrated"] else v
            name = f"{h['name']} g=({g[0]:.0f},{g[1]:.0f},{g[2]:.0f})"
            if h["verdict"] != expected:
                wrong.append(
                    f"{name}: {v} at {t:.3f} s ({mm:.2f} mm, {deg:.2f} deg), "
                    f"full {h['verdict']} ({h['translation_mm']:.2f} mm, {h['rotation_deg']:.2f} deg)"
                )
            elif not near(mm, h["translation_mm"]) or not near(deg, h["rotation_deg"]):
                off += 1
            break
    mean = {k: (sum(v) / len(v) if v else 0.0) for k, v in times.items()}
    d40_s = f"{d40:.3f}" if d40 is not None else "end"
    print(
        f"| {label} | {len(times['hold'])} | {mean['hold']:.2f} | {len(times['slip'])} | "
        f"{mean['slip']:.2f} | {len(wrong)} | {off} | {d40_s} |"
    )
    return wrong


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    holds = load(argv[1])
    print(f"{len(holds)} holds\n")
    print(
        "| rule | decided `hold` | mean [s] | decided `slip` | mean [s] | wrong | numbers off "
        "| D40 down decided [s] |"
    )
    print("|---|---|---|---|---|---|---|---|")
    notes = []
    wrong = evaluate("0.2 s (the default)", rule(), holds)
    notes += [f"0.2 s: {w}" for w in wrong]
    for short_s in (0.03, 0.05, 0.1):
        for share in (0.0, 0.2, 0.3, 0.5, 1.0):
            label = f"+ {short_s} s, at most {share:.0%} of the load at the cone's edge"
            wrong = evaluate(label, rule(short_s, share), holds)
            notes += [f"{short_s} s, {share:.0%}: {w}" for w in wrong]
    print()
    for n in notes:
        print("wrong:", n)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
