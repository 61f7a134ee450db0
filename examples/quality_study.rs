//! Does the Ferrari–Canny epsilon predict a simulated hold? (issue 18, docs/QUALITY.md)
//!
//!     cargo run --release --example quality_study -- OUT_DIR SCENARIO.toml...
//!
//! For every scenario, up to four feasible grasps in the planner's search order (as
//! `--candidates 4`); for each, the physics check with gravity `down` and with `six`, the payload
//! margin (`--payload`'s search, 0 when `down` does not hold), the analytic quality from the
//! contacts at the end of closing (`sim`) and from the planned contacts (`planned`), and the
//! planner's own grade (the palm grade of the grasp's elevation, thesis 3.4.4). Writes
//! `OUT_DIR/quality_study.csv`, `OUT_DIR/quality_epsilon_payload.svg` and prints the statistics
//! (Spearman rank correlation with the payload margin, ROC AUC for hold against not-hold) as a
//! Markdown table.

use grasp_sim::scenario::{GravityMode, MassSpec, Scenario};
use grasp_sim::{mesh, plan, quality, select, sim};
use plotters::prelude::*;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

struct Row {
    scenario: String,
    candidate: usize,
    grade: f64,
    eps_sim: f64,
    vol_sim: f64,
    eps_sim_linf: Option<f64>,
    contacts_sim: usize,
    eps_plan: f64,
    vol_plan: f64,
    payload: f64,
    down: sim::Verdict,
    six: sim::Verdict,
    ms_quality: f64,
}

fn study(path: &Path) -> Result<Vec<Row>, String> {
    let sc = Scenario::load(path).map_err(|e| e.to_string())?;
    let loaded = mesh::load_mesh(&sc.object.mesh, sc.object.units).map_err(|e| e.to_string())?;
    let props = mesh::mass_properties(&loaded.mesh);
    let volume = props.volume_mm3;
    let mass_kg = match sc.object.mass {
        MassSpec::Mass(m) => m,
        MassSpec::Density(d) => d * volume * 1e-9,
    };
    let no_check = |_: &mesh::AlignedObject, _: &plan::search::Grasp| -> sim::SimOutcome {
        unreachable!("max_checked is None")
    };
    let selection = select::select(
        &loaded.mesh,
        &props,
        &select::SelectParams {
            hand: &sc.hand,
            planner: &sc.planner,
            friction: sc.object.friction,
            collect: 4,
            max_checked: None,
            check: &no_check,
            domains: None,
        },
        &mut BTreeMap::new(),
    );
    let mut rows = Vec::new();
    for (k, c) in selection.candidates.iter().enumerate() {
        let axis = &selection.axes[c.axis_plan];
        let shape = sim::ObjectShape::from_mesh(&axis.aligned.mesh, volume);
        let pose = sim::SimHand::from_grasp(&c.grasp);
        let mut down_params = sc.sim.clone();
        down_params.gravity = GravityMode::Down;
        let mut six_params = sc.sim.clone();
        six_params.gravity = GravityMode::Six;
        let case = |params| sim::Case {
            hand: &sc.hand,
            pose: &pose,
            object: &shape,
            mass_kg,
            friction: sc.object.friction,
            params,
        };
        let down = sim::check(&case(&down_params));
        let six = sim::check(&case(&six_params));
        let payload = if down.verdict == sim::Verdict::Hold {
            sim::payload_margin(&case(&down_params))
        } else {
            0.0
        };
        let t0 = std::time::Instant::now();
        let q_sim = quality::of_grasp(
            &c.grasp,
            &axis.aligned,
            Some(&down),
            &sc.hand,
            sc.object.friction,
        );
        let ms_quality = t0.elapsed().as_secs_f64() * 1e3;
        let q_plan = quality::of_grasp(&c.grasp, &axis.aligned, None, &sc.hand, sc.object.friction);
        let grade = axis
            .graded
            .grades
            .palm
            .get(c.grasp.elevation_index.wrapping_sub(1))
            .copied()
            .flatten()
            .unwrap_or(0.0);
        rows.push(Row {
            scenario: sc.name.clone(),
            candidate: k + 1,
            grade,
            eps_sim: q_sim.epsilon,
            vol_sim: q_sim.volume,
            eps_sim_linf: q_sim.linf.map(|m| m.epsilon),
            contacts_sim: q_sim.contacts.len(),
            eps_plan: q_plan.epsilon,
            vol_plan: q_plan.volume,
            payload,
            down: down.verdict,
            six: six.verdict,
            ms_quality,
        });
    }
    Ok(rows)
}

/// Ranks with ties averaged (1-based).
fn ranks(x: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut r = vec![0.0; x.len()];
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && x[idx[j + 1]] == x[idx[i]] {
            j += 1;
        }
        for &k in &idx[i..=j] {
            r[k] = (i + j) as f64 / 2.0 + 1.0;
        }
        i = j + 1;
    }
    r
}

fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// Spearman's rank correlation (Pearson's on tie-averaged ranks).
fn spearman(a: &[f64], b: &[f64]) -> f64 {
    pearson(&ranks(a), &ranks(b))
}

/// ROC AUC of `score` for `positive` (Mann–Whitney; ties count half).
fn auc(score: &[f64], positive: &[bool]) -> f64 {
    let (mut num, mut pairs) = (0.0, 0.0);
    for (i, &si) in score.iter().enumerate() {
        for (j, &sj) in score.iter().enumerate() {
            if positive[i] && !positive[j] {
                pairs += 1.0;
                num += if si > sj {
                    1.0
                } else if si == sj {
                    0.5
                } else {
                    0.0
                };
            }
        }
    }
    num / pairs
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((out, files)) = args.split_first() else {
        eprintln!("usage: quality_study OUT_DIR SCENARIO.toml...");
        std::process::exit(2);
    };
    let out = PathBuf::from(out);
    std::fs::create_dir_all(&out).expect("creating the output folder");
    let results: Vec<(String, Result<Vec<Row>, String>)> = files
        .par_iter()
        .map(|f| (f.clone(), study(Path::new(f))))
        .collect();
    let mut rows = Vec::new();
    for (f, r) in results {
        match r {
            Ok(mut r) => rows.append(&mut r),
            Err(e) => eprintln!("{f}: skipped: {e}"),
        }
    }
    let mut csv = String::from(
        "scenario,candidate,planner_grade,epsilon_sim,volume_sim,epsilon_linf_sim,contacts_sim,epsilon_planned,volume_planned,payload_margin,down,six,quality_ms\n",
    );
    for r in &rows {
        let _ = writeln!(
            csv,
            "{},{},{:.4},{:.5},{:.4e},{},{},{:.5},{:.4e},{:.3},{},{},{:.3}",
            r.scenario,
            r.candidate,
            r.grade,
            r.eps_sim,
            r.vol_sim,
            r.eps_sim_linf.map_or("".to_string(), |e| format!("{e:.5}")),
            r.contacts_sim,
            r.eps_plan,
            r.vol_plan,
            r.payload,
            r.down.as_str(),
            r.six.as_str(),
            r.ms_quality
        );
    }
    std::fs::write(out.join("quality_study.csv"), csv).expect("writing the CSV");

    let payload: Vec<f64> = rows.iter().map(|r| r.payload).collect();
    let hold: Vec<bool> = rows.iter().map(|r| r.down == sim::Verdict::Hold).collect();
    let hold6: Vec<bool> = rows.iter().map(|r| r.six == sim::Verdict::Hold).collect();
    let scores: Vec<(&str, Vec<f64>)> = vec![
        (
            "epsilon, sim contacts (L1)",
            rows.iter().map(|r| r.eps_sim).collect(),
        ),
        (
            "volume, sim contacts (L1)",
            rows.iter().map(|r| r.vol_sim).collect(),
        ),
        (
            "epsilon, sim contacts (L-inf)",
            rows.iter().map(|r| r.eps_sim_linf.unwrap_or(0.0)).collect(),
        ),
        (
            "epsilon, planned contacts (L1)",
            rows.iter().map(|r| r.eps_plan).collect(),
        ),
        (
            "volume, planned contacts (L1)",
            rows.iter().map(|r| r.vol_plan).collect(),
        ),
        (
            "planner's palm grade",
            rows.iter().map(|r| r.grade).collect(),
        ),
        (
            "planner's search order (first = best)",
            rows.iter().map(|r| -(r.candidate as f64)).collect(),
        ),
    ];
    println!(
        "{} grasps of {} objects; {} hold (down), {} hold (six), {} force closure (sim contacts)\n",
        rows.len(),
        rows.iter()
            .map(|r| &r.scenario)
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        hold.iter().filter(|h| **h).count(),
        hold6.iter().filter(|h| **h).count(),
        rows.iter().filter(|r| r.eps_sim > 0.0).count()
    );
    println!("| score | Spearman vs payload margin | ROC AUC, hold (down) | ROC AUC, hold (six) |");
    println!("|---|---|---|---|");
    for (name, s) in &scores {
        println!(
            "| {name} | {:.2} | {:.2} | {:.2} |",
            spearman(s, &payload),
            auc(s, &hold),
            auc(s, &hold6)
        );
    }
    let held: Vec<&Row> = rows
        .iter()
        .filter(|r| r.down == sim::Verdict::Hold)
        .collect();
    if held.len() > 2 {
        let e: Vec<f64> = held.iter().map(|r| r.eps_sim).collect();
        let p: Vec<f64> = held.iter().map(|r| r.payload).collect();
        let g: Vec<f64> = held.iter().map(|r| r.grade).collect();
        println!(
            "\nAmong the {} grasps that hold: Spearman vs payload margin, epsilon (sim) {:.2}, planner's grade {:.2}",
            held.len(),
            spearman(&e, &p),
            spearman(&g, &p)
        );
    }
    let mut ms: Vec<f64> = rows.iter().map(|r| r.ms_quality).collect();
    ms.sort_by(f64::total_cmp);
    if !ms.is_empty() {
        println!(
            "\nquality cost per grasp (sim contacts, L1 and L-inf): median {:.2} ms, max {:.2} ms",
            ms[ms.len() / 2],
            ms[ms.len() - 1]
        );
    }
    println!("\n| object | # | grade | epsilon (sim) | volume (sim) | epsilon (planned) | payload | down | six |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {} | {} | {:.2} | {:.4} | {:.2e} | {:.4} | {:.1} | {} | {} |",
            r.scenario,
            r.candidate,
            r.grade,
            r.eps_sim,
            r.vol_sim,
            r.eps_plan,
            r.payload,
            r.down.as_str(),
            r.six.as_str()
        );
    }
    plot(&out.join("quality_epsilon_payload.svg"), &rows).expect("writing the SVG");
}

fn plot(path: &Path, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (720, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let xmax = rows
        .iter()
        .map(|r| r.eps_sim)
        .fold(0.0f64, f64::max)
        .max(1e-3)
        * 1.05;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Epsilon (sim contacts, L1) against payload margin",
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..xmax, 0.0..70.0)?;
    chart
        .configure_mesh()
        .x_desc("Ferrari-Canny epsilon (L1)")
        .y_desc("payload margin (x mass; 0 = not hold)")
        .draw()?;
    for (label, verdict, color) in [
        ("hold (down), holds six", 0, GREEN),
        ("hold (down), fails six", 1, BLUE),
        ("slip or drop (down)", 2, RED),
    ] {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| {
                let v = match (r.down, r.six) {
                    (sim::Verdict::Hold, sim::Verdict::Hold) => 0,
                    (sim::Verdict::Hold, _) => 1,
                    _ => 2,
                };
                v == verdict
            })
            .map(|r| (r.eps_sim, r.payload))
            .collect();
        chart
            .draw_series(pts.iter().map(|p| Circle::new(*p, 4, color.filled())))?
            .label(label)
            .legend(move |(x, y)| Circle::new((x, y), 4, color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
