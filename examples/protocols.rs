//! Runs the physics check of each scenario under both protocols, `full` (the reference) and
//! `fast` (the default), and prints a Markdown table of their verdicts, numbers and wall times
//! (docs/SIM.md, "Fast against full").
//!
//!     cargo run --release --example protocols -- [--six] [--payload] [--jsonl FILE]
//!         [--set KEY=VALUE ...] [--only fast|full] SCENARIO...
//!
//! `--set` changes a `[sim]` key of every scenario (a TOML value: `--set timestep_s=0.002`),
//! `--only` runs one protocol (then nothing is compared).
//! Exits 1 if a verdict differs, a held object's translation differs by more than 0.5 mm and
//! 10 %, or a payload margin differs by more than the search's 5 % step.

#[path = "common/mod.rs"]
mod common;

use grasp_sim::report::SimReport;
use grasp_sim::scenario::{GravityMode, Protocol};
use grasp_sim::{run, RunOptions};
use std::io::Write;

fn main() {
    let mut six = false;
    let mut payload = false;
    let mut jsonl: Option<std::fs::File> = None;
    let mut files = Vec::new();
    let mut sets: Vec<(String, toml::Value)> = Vec::new();
    let mut only: Option<Protocol> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--six" => six = true,
            "--payload" => payload = true,
            "--jsonl" => jsonl = Some(std::fs::File::create(args.next().expect("FILE")).unwrap()),
            "--set" => sets.push(common::parse_set(&args.next().expect("KEY=VALUE"))),
            "--only" => {
                only = Some(match args.next().as_deref() {
                    Some("fast") => Protocol::Fast,
                    Some("full") => Protocol::Full,
                    _ => panic!("--only fast|full"),
                })
            }
            _ => files.push(a),
        }
    }
    let options = RunOptions {
        payload,
        ..RunOptions::default()
    };
    if let Some(p) = only {
        println!(
            "| scenario | {} | translation [mm] | rotation [deg] | decided at [s] | payload | wall [ms] |",
            format!("{p:?}").to_lowercase()
        );
        println!("|---|---|---|---|---|---|---|");
    } else {
        println!(
            "| scenario | full | fast | translation full / fast [mm] | rotation full / fast [deg] | \
             decided at [s] | payload full / fast | wall full / fast [ms] | agree |"
        );
        println!("|---|---|---|---|---|---|---|---|---|");
    }
    let mut failed = Vec::new();
    let (mut wall_full, mut wall_fast) = (0.0, 0.0);
    for f in &files {
        let mut s = common::load_with(f, &sets);
        if six {
            s.sim.gravity = GravityMode::Six;
        }
        let mut by = |protocol| {
            s.sim.protocol = protocol;
            let r = run(&s, &options).expect("run");
            if let Some(out) = jsonl.as_mut() {
                let line = serde_json::json!({
                    "scenario": r.scenario,
                    "protocol": format!("{protocol:?}").to_lowercase(),
                    "sim": r.sim,
                });
                writeln!(out, "{line}").unwrap();
            }
            r.sim
        };
        if let Some(p) = only {
            let r = by(p);
            println!(
                "| {} | {} | {:.3} | {:.3} | {:.2} | {} | {} |",
                s.name,
                r.verdict,
                r.translation_mm.unwrap_or(f64::NAN),
                r.rotation_deg.unwrap_or(f64::NAN),
                r.directions
                    .iter()
                    .map(|d| d.decided_at_s)
                    .fold(0.0f64, f64::max),
                r.payload_margin.map_or("—".into(), |m| format!("{m:.2}x")),
                r.wall_ms.map_or("".into(), |w| format!("{w:.0}")),
            );
            continue;
        }
        let full = by(Protocol::Full);
        let fast = by(Protocol::Fast);
        if full.verdict.verdict().is_none() {
            println!("| {} | not run | not run | | | | | | |", s.name);
            continue;
        }
        let ok = agree(&full, &fast);
        if !ok {
            failed.push(s.name.clone());
        }
        let decided = fast
            .directions
            .iter()
            .map(|d| d.decided_at_s)
            .fold(0.0f64, f64::max);
        let margin = |r: &SimReport| r.payload_margin.map_or("—".into(), |m| format!("{m:.2}x"));
        wall_full += full.wall_ms.unwrap_or(0.0);
        wall_fast += fast.wall_ms.unwrap_or(0.0);
        println!(
            "| {} | {} | {} | {:.2} / {:.2} | {:.2} / {:.2} | {:.2} | {} / {} | {:.0} / {:.0} | {} |",
            s.name,
            full.verdict,
            fast.verdict,
            full.translation_mm.unwrap_or(f64::NAN),
            fast.translation_mm.unwrap_or(f64::NAN),
            full.rotation_deg.unwrap_or(f64::NAN),
            fast.rotation_deg.unwrap_or(f64::NAN),
            decided,
            margin(&full),
            margin(&fast),
            full.wall_ms.unwrap_or(f64::NAN),
            fast.wall_ms.unwrap_or(f64::NAN),
            if ok { "yes" } else { "**no**" }
        );
    }
    if only.is_none() {
        println!(
            "\ncheck wall time in total: full {wall_full:.0} ms, fast {wall_fast:.0} ms ({:.1}x)",
            wall_full / wall_fast.max(1e-9)
        );
    }
    if !failed.is_empty() {
        eprintln!("protocols disagree on: {}", failed.join(", "));
        std::process::exit(1);
    }
}

/// The fast protocol's result agrees with the full one's: same verdict in every direction;
/// translations (of what is still in the hand) within 0.5 mm or 10 %; payload margins within
/// the search's 5 % step either way.
fn agree(full: &SimReport, fast: &SimReport) -> bool {
    let close =
        |a: f64, b: f64| (a - b).abs() <= 0.5 || (a - b).abs() <= 0.1 * a.abs().max(b.abs());
    full.verdict == fast.verdict
        && full.directions.len() == fast.directions.len()
        && full
            .directions
            .iter()
            .zip(&fast.directions)
            .all(|(a, b)| a.verdict == b.verdict && close(a.translation_mm, b.translation_mm))
        && match (full.payload_margin, fast.payload_margin) {
            (Some(a), Some(b)) => a == b || (a / b).max(b / a) <= 1.05 * 1.05 + 1e-9,
            (None, None) => true,
            _ => false,
        }
}
