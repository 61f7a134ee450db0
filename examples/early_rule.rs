//! The study of the `fast` protocol's rest rule (docs/SIM.md, "Deciding early"): runs each
//! scenario's first grasp under the full-length protocol, keeps every hold's sampled motion, and
//! replays the rest rule on it for several windows. The fast protocol's run is the full one's up
//! to its decision (the same closing, a copy that continues bit for bit), so a rule that decides
//! a hold here decides it there, at the same time, on the same numbers.
//!
//!     cargo run --release --example early_rule -- [--six] [--set KEY=VALUE ...] SCENARIO...
//!
//! Prints, per window, how many holds it decided early, how early on average, and every
//! decision that the full-length hold contradicts: a verdict that changes later (`wrong`), or a
//! translation or rotation that moves on by more than the report tolerance (0.5 mm or 10 %,
//! 0.5° or 10 %) (`numbers`).
//!
//! `--dump FILE` also writes every hold as a JSON line, sampled four times finer than the rule
//! samples (1/192 s), with how near the hand's contacts were to sliding at each sample: the input
//! of `scripts/rest_rule_friction.py`, which replays rules with shorter windows on it.

#[path = "common/mod.rs"]
mod common;

use grasp_sim::scenario::{GravityMode, Protocol, SimParams};
use grasp_sim::sim::protocol::{traced, HoldTrace};
use grasp_sim::sim::{EarlyDecision, Verdict};
use grasp_sim::{run, RunOptions};

/// (window `[s]`, margin) pairs studied.
const RULES: [(f64, f64); 11] = [
    (0.1, 1.0),
    (0.2, 1.0),
    (0.3, 1.0),
    (0.5, 1.0),
    (0.05, 0.8),
    (0.075, 0.8),
    (0.1, 0.8),
    (0.15, 0.8),
    (0.2, 0.8),
    (0.3, 0.8),
    (0.5, 0.8),
];

/// Where the rule with `window_s` and `margin` decides `t`'s hold: (verdict by motion, time,
/// translation, rotation) at the decision, or `None` if it runs to the end. The verdict is
/// `hold` for a rest within the thresholds, `slip` for a rest beyond them (a rest under
/// gravity is a rest on the hand).
fn decide(
    t: &HoldTrace,
    params: &SimParams,
    (window_s, margin): (f64, f64),
) -> Option<(Verdict, f64, f64, f64)> {
    let rule = EarlyDecision {
        window_s,
        margin,
        ..EarlyDecision::from_params(params)
    };
    let dt = t.frame.sample_dt;
    for i in 0..t.samples.len() {
        let at = (i + 1) as f64 * dt;
        let remaining = t.duration_s - at;
        if remaining <= 1e-9 {
            return None;
        }
        if !rule.joints_settled(&t.joints[..=i], t.frame.sample_dt, remaining) {
            continue;
        }
        let Some(verdict) = rule.decide(&t.samples[..=i], &t.frame, remaining, params) else {
            continue;
        };
        let (p, q) = t.samples[i];
        return Some((
            verdict,
            at,
            (p - t.frame.pc).norm(),
            t.frame.judged(&t.frame.qc, &q),
        ));
    }
    None
}

fn main() {
    let mut six = false;
    let mut sets: Vec<(String, toml::Value)> = Vec::new();
    let mut files = Vec::new();
    let mut dump: Option<std::fs::File> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--six" => six = true,
            "--dump" => {
                dump = Some(std::fs::File::create(args.next().expect("FILE")).expect("--dump FILE"))
            }
            "--set" => sets.push(common::parse_set(&args.next().expect("KEY=VALUE"))),
            _ => files.push(a),
        }
    }
    // Per window and verdict by motion (hold, slip): directions decided early, the sum of their
    // decision times, and the contradictions.
    let mut decided = [[0usize; 2]; RULES.len()];
    let mut at_sum = [[0.0f64; 2]; RULES.len()];
    let mut bad: Vec<Vec<String>> = vec![Vec::new(); RULES.len()];
    let mut holds = 0;
    let mut slips = 0;
    let mut runs = 0;
    for f in &files {
        let mut s = common::load_with(f, &sets);
        s.sim.protocol = Protocol::Full;
        if six {
            s.sim.gravity = GravityMode::Six;
        }
        let options = RunOptions {
            max_checked: Some(1),
            ..RunOptions::default()
        };
        let (r, traces) = traced(|| run(&s, &options));
        if let Err(e) = r {
            eprintln!("{f}: {e}");
            continue;
        }
        for t in &traces {
            runs += 1;
            let o = &t.outcome;
            if let Some(d) = dump.as_mut() {
                use std::io::Write;
                let q = |q: &nalgebra::UnitQuaternion<f64>| [q.w, q.i, q.j, q.k];
                let line = serde_json::json!({
                    "name": s.name, "gravity": o.gravity, "verdict": o.verdict.as_str(),
                    "translation_mm": o.translation_mm, "rotation_deg": o.rotation_deg,
                    "penetrated": o.closing_penetration_mm > s.sim.hold.max_penetration_mm,
                    "duration_s": t.duration_s, "sample_dt": t.fine_dt,
                    "thresholds": [s.sim.hold.hold_translation_mm, s.sim.hold.hold_rotation_deg],
                    "safety": s.sim.early.rest_safety,
                    "margin": s.sim.early.rest_margin, "window_s": s.sim.early.rest_window_s,
                    "rule_every": (t.frame.sample_dt / t.fine_dt).round() as usize,
                    "pc": [t.frame.pc.x, t.frame.pc.y, t.frame.pc.z], "qc": q(&t.frame.qc),
                    "revolution": t.frame.is_revolution,
                    "p": t.fine.iter().map(|s| [s.0.x, s.0.y, s.0.z]).collect::<Vec<_>>(),
                    "q": t.fine.iter().map(|s| q(&s.1)).collect::<Vec<_>>(),
                    "fmax": t.fine.iter().map(|f| f.2.max_ratio).collect::<Vec<_>>(),
                    "fslide": t.fine.iter().map(|f| f.2.sliding_share).collect::<Vec<_>>(),
                    "fpoints": t.fine.iter().map(|f| f.2.points).collect::<Vec<_>>(),
                });
                writeln!(d, "{line}").expect("write --dump");
            }
            match o.verdict {
                Verdict::Hold => holds += 1,
                Verdict::Slip => slips += 1,
                _ => {}
            }
            for (w, &window) in RULES.iter().enumerate() {
                let Some((by_motion, at, mm, deg)) = decide(t, &s.sim, window) else {
                    continue;
                };
                let k = usize::from(by_motion == Verdict::Slip);
                decided[w][k] += 1;
                at_sum[w][k] += at;
                let g = o.gravity;
                let name = format!("{} g=({:.0},{:.0},{:.0})", s.name, g[0], g[1], g[2]);
                let close = |a: f64, b: f64, abs: f64| {
                    (a - b).abs() <= abs || (a - b).abs() <= 0.1 * a.abs().max(b.abs())
                };
                // A rest within the thresholds is a `hold` by motion, and the full verdict may
                // also be `slip` for a penetration, which both protocols share.
                let expected = if by_motion == Verdict::Hold
                    && o.closing_penetration_mm > s.sim.hold.max_penetration_mm
                {
                    Verdict::Slip
                } else {
                    by_motion
                };
                if o.verdict != expected {
                    bad[w].push(format!(
                        "wrong: {name}: {by_motion} at rest at {at:.2} s ({mm:.2} mm, {deg:.2}°), full {} ({:.2} mm, {:.2}°)",
                        o.verdict, o.translation_mm, o.rotation_deg
                    ));
                } else if !close(mm, o.translation_mm, 0.5) || !close(deg, o.rotation_deg, 0.5) {
                    bad[w].push(format!(
                        "numbers: {name}: {by_motion} at rest at {at:.2} s ({mm:.2} mm, {deg:.2}°), full end ({:.2} mm, {:.2}°)",
                        o.translation_mm, o.rotation_deg
                    ));
                }
            }
        }
    }
    println!("{runs} holds simulated full-length ({holds} of them `hold`, {slips} `slip`)\n");
    println!("| window [s] | margin | decided `hold` at rest | mean decision [s] | decided `slip` at rest | mean decision [s] | wrong verdicts | numbers beyond tolerance |");
    println!("|---|---|---|---|---|---|---|---|");
    for (w, (window, margin)) in RULES.iter().enumerate() {
        let wrong = bad[w].iter().filter(|b| b.starts_with("wrong")).count();
        let mean = |k: usize| at_sum[w][k] / decided[w][k].max(1) as f64;
        println!(
            "| {window} | {margin} | {} | {:.2} | {} | {:.2} | {wrong} | {} |",
            decided[w][0],
            mean(0),
            decided[w][1],
            mean(1),
            bad[w].len() - wrong
        );
    }
    for (w, (window, margin)) in RULES.iter().enumerate() {
        for b in &bad[w] {
            println!("window {window}, margin {margin}: {b}");
        }
    }
}
