//! Issue 30's study of the physics check's verdicts across frames (docs/studies/
//! 2026-12-02-frames-verdicts.md): runs a scenario several times under a null perturbation, a change
//! no measurement could tell from none, and prints each run's candidates in search order with
//! their verdicts, so that a verdict that flips under a null can be told from one that a frame
//! changes.
//!
//!     cargo run --release --example frames_null -- SCENARIO MODE K [STL]
//!
//! Run k of K (run 0 unperturbed) under MODE:
//!
//! - `stiff`: `contact_stiffness_hz` × (1 + k·10⁻⁶); every other input bit for bit the same,
//!   the collider included;
//! - `jitter`: every vertex coordinate of the mesh moved by a uniform ±10⁻⁵ mm (seed k), about
//!   the single-precision round-off of a file written in another frame;
//! - `none`: no perturbation (with `--samples`, the hold probability of every candidate).
//!
//! The mesh is written as binary STL in mm, as the frame test writes it; STL replaces the
//! scenario's mesh (a frame the test dumped with `GRASP_SIM_FRAMES_DUMP`). `--samples N` (after
//! the arguments) samples every candidate checked N times under `choose = "robust"`, and prints
//! each candidate's samples held; `--robust-bound B` sets `choose_min_lower_bound` (default 0.8:
//! the search stops at the first candidate whose samples all held).

use grasp_sim::scenario::Scenario;
use grasp_sim::{run, RunOptions};

/// A deterministic pseudo-random number in [0, 1) (SplitMix64 on a counter).
fn unit(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut option = |name: &str| {
        let i = args.iter().position(|a| a == name)?;
        let v = args.get(i + 1).cloned();
        args.drain(i..(i + 2).min(args.len()));
        v
    };
    let samples: usize = option("--samples").map_or(1, |s| s.parse().expect("--samples N"));
    let bound: Option<f64> = option("--robust-bound").map(|s| s.parse().expect("--robust-bound B"));
    if args.len() < 3 {
        eprintln!("usage: frames_null SCENARIO stiff|jitter|none K [STL] [--samples N] [--robust-bound B]");
        std::process::exit(2);
    }
    let base = Scenario::load(std::path::Path::new(&args[0])).expect("scenario");
    let mode = args[1].as_str();
    let runs: u64 = args[2].parse().expect("K");
    let (src, units) = match args.get(3) {
        Some(stl) => (stl.into(), grasp_sim::mesh::LengthUnit::Mm),
        None => (base.object.mesh.clone(), base.object.units),
    };
    let dir = tempfile::tempdir().expect("temp dir");
    for k in 0..runs {
        let mut s = base.clone();
        let mut mesh = grasp_sim::mesh::load_mesh(&src, units).expect("mesh").mesh;
        match mode {
            "jitter" if k > 0 => {
                let mut state = k.wrapping_mul(1_000_003);
                for p in &mut mesh.vertices {
                    for c in p.coords.iter_mut() {
                        *c += (unit(&mut state) * 2.0 - 1.0) * 1e-5;
                    }
                }
            }
            "stiff" => s.sim.solver.contact_stiffness_hz *= 1.0 + k as f64 * 1e-6,
            "jitter" | "none" => {}
            other => panic!("unknown mode {other}"),
        }
        if samples > 1 {
            s.sim.robust.samples = samples;
            s.sim.robust.choose = grasp_sim::sim::params::Choose::Robust;
            if let Some(b) = bound {
                s.sim.robust.choose_min_lower_bound = b;
            }
        }
        let path = dir.path().join(format!("{}.stl", s.name));
        std::fs::write(&path, mesh.to_binary_stl()).expect("write");
        s.object.mesh = path;
        s.object.units = grasp_sim::mesh::LengthUnit::Mm;
        let r = run(&s, &RunOptions::default()).expect("run");
        let grasps: Vec<_> = if r.plan.grasps.is_empty() {
            r.plan.grasp.iter().collect()
        } else {
            r.plan.grasps.iter().collect()
        };
        let mut line = format!("{} {mode} k={k}:", s.name);
        for g in grasps {
            line += &format!(
                " [{} #{} {:.0}",
                g.axis_name, g.elevation_index, g.approach_angle_deg
            );
            if let Some(c) = &g.check {
                line += &format!(" {:?} {:.2} mm", c.verdict, c.translation_mm);
                if let Some(rb) = &c.robust {
                    line += &format!(" {}/{}", rb.held, rb.samples);
                }
            }
            line += "]";
        }
        let collider = r.sim.collider.map_or(String::new(), |c| c.to_string());
        line += &format!(" -> {:?} | {collider}", r.sim.verdict);
        println!("{line}");
    }
}
