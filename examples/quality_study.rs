//! Does the Ferrari–Canny epsilon predict a simulated hold? (issue 18, docs/QUALITY.md)
//!
//!     cargo run --release --example quality_study -- OUT_DIR
//!         [--candidates N] [--gravity both|down] SCENARIO.toml... [--candidates M ...] ...
//!
//! Options apply to the scenarios after them (defaults: 4 candidates, both).
//!
//! `scripts/quality_study.sh` runs it on the bundled scenarios, the tuning set and the
//! real-object set, as docs/QUALITY.md reports it.
//!
//! For every scenario, up to N feasible grasps in the planner's search order, as
//! `--candidates N` collects them (every axis and the extended rules as a run plans; no physics
//! check chooses among them here: every one is checked). For each: the physics check with
//! gravity `down` and (with `--gravity both`) `six`, the payload margin
//! (`--payload`'s search, 0 when `down` does not hold), the analytic quality from the contacts at
//! the end of `down`'s closing (`sim`) and from the planned contacts (`planned`), and the
//! planner's own grade (the palm grade of the grasp's elevation, thesis 3.4.4) and search
//! order. The set of a scenario is told by its path: `real` (assets/real/), `tuning`
//! (assets/objects/train/) or `bundled`.
//!
//! Writes `OUT_DIR/quality_study.csv` (one row per grasp; the time columns are wall clock, the
//! rest is the same run after run), `OUT_DIR/quality_study_run.txt` (run time, scenarios
//! without a grasp), then, from those two, `OUT_DIR/quality_study.md` (statistics and the full
//! table) and `OUT_DIR/quality_epsilon_payload.svg`, and prints the statistics.
//! `quality_study OUT_DIR --report-only` writes the last two again from the first two.

use grasp_sim::scenario::{GravityMode, Scenario};
use grasp_sim::{mesh, plan, quality, select, sim};
use plotters::prelude::*;
use rayon::prelude::*;
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

struct Row {
    set: &'static str,
    scenario: String,
    candidate: usize,
    axis: String,
    rules: String,
    grade: f64,
    eps_sim: f64,
    vol_sim: f64,
    eps_sim_linf: Option<f64>,
    vol_sim_linf: Option<f64>,
    vol_sim_linf_se: Option<f64>,
    contacts_sim: usize,
    eps_plan: f64,
    vol_plan: f64,
    payload: f64,
    down: sim::Verdict,
    six: Option<sim::Verdict>,
    ms_down: f64,
    ms_six: f64,
    ms_payload: f64,
    ms_quality: f64,
}

/// A scenario planned: what the grasps of it need.
struct Planned {
    set: &'static str,
    sc: Scenario,
    volume: f64,
    mass_kg: f64,
    selection: select::Selection,
}

fn set_of(path: &Path) -> &'static str {
    let full = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    let p = full.to_string_lossy().replace('\\', "/");
    if p.contains("assets/real/") {
        "real"
    } else if p.contains("assets/objects/train/") {
        "tuning"
    } else {
        "bundled"
    }
}

fn plan_one(path: &Path, collect: usize) -> Result<Planned, String> {
    let sc = Scenario::load(path).map_err(|e| e.to_string())?;
    let loaded = mesh::load_mesh(&sc.object.mesh, sc.object.units).map_err(|e| e.to_string())?;
    let props = mesh::mass_properties(&loaded.mesh);
    let volume = props.volume_mm3;
    let mass_kg = sc.object.mass.mass_kg(volume, loaded.mass_kg);
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
            collect,
            max_checked: None,
            check: &no_check,
            recheck: None,
            probe: None,
            domains: None,
            frame: sc.object.frame,
            order_by_closing: None,
            order_samples: None,
            plan_reach: 0,
            order_reach: 0,
        },
        &mut grasp_sim::report::StageTimings::default(),
    );
    if selection.candidates.is_empty() {
        return Err("no feasible grasp".to_string());
    }
    Ok(Planned {
        set: set_of(path),
        sc,
        volume,
        mass_kg,
        selection,
    })
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn study_grasp(p: &Planned, k: usize, six: bool) -> Row {
    let sc = &p.sc;
    let c = &p.selection.candidates[k];
    let axis = &p.selection.axes[c.axis_plan];
    let shape = sim::ObjectShape::from_mesh(&axis.aligned.mesh, p.volume);
    let pose = sim::SimHand::from_grasp(&c.grasp, &sc.hand);
    let mut down_params = sc.sim.clone();
    down_params.gravity = GravityMode::Down;
    let mut six_params = sc.sim.clone();
    six_params.gravity = GravityMode::Six;
    let case = |params| sim::Case {
        hand: &sc.hand,
        pose: &pose,
        object: &shape,
        mass_kg: p.mass_kg,
        friction: sc.object.friction,
        params,
    };
    let t = Instant::now();
    let down = sim::check(&case(&down_params));
    let ms_down = ms(t);
    let t = Instant::now();
    let six_out = six.then(|| sim::check(&case(&six_params)));
    let ms_six = if six { ms(t) } else { 0.0 };
    let t = Instant::now();
    let payload = if down.verdict == sim::Verdict::Hold {
        sim::payload_margin(&case(&down_params))
    } else {
        0.0
    };
    let ms_payload = ms(t);
    let t = Instant::now();
    let q_sim = quality::of_grasp(
        &c.grasp,
        &axis.aligned,
        Some(&down),
        &sc.hand,
        sc.object.friction,
    );
    let ms_quality = ms(t);
    let q_plan = quality::of_grasp(&c.grasp, &axis.aligned, None, &sc.hand, sc.object.friction);
    let grade = axis
        .graded
        .grades
        .palm
        .get(c.grasp.elevation_index.wrapping_sub(1))
        .copied()
        .flatten()
        .unwrap_or(0.0);
    Row {
        set: p.set,
        scenario: sc.name.clone(),
        candidate: k + 1,
        axis: axis.aligned.axis.name(),
        rules: if axis.rules.is_extended() {
            "extended"
        } else {
            "thesis"
        }
        .to_string(),
        grade,
        eps_sim: q_sim.epsilon,
        vol_sim: q_sim.volume,
        eps_sim_linf: q_sim.linf.map(|m| m.epsilon),
        vol_sim_linf: q_sim.linf.and_then(|m| m.volume),
        vol_sim_linf_se: q_sim.linf.and_then(|m| m.volume_rel_se),
        contacts_sim: q_sim.contacts.len(),
        eps_plan: q_plan.epsilon,
        vol_plan: q_plan.volume,
        payload,
        down: down.verdict,
        six: six_out.map(|o| o.verdict),
        ms_down,
        ms_six,
        ms_payload,
        ms_quality,
    }
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

/// Spearman's rank correlation (Pearson's on tie-averaged ranks); NaN when either is constant.
fn spearman(a: &[f64], b: &[f64]) -> f64 {
    pearson(&ranks(a), &ranks(b))
}

/// ROC AUC of `score` for `positive` (Mann–Whitney; ties count half); NaN without both classes.
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

/// Within each object, over the pairs of its grasps whose payload margins differ: the share
/// ordered the same way by `score` (ties in the score count half), and the number of pairs.
fn within_object_agreement(rows: &[&Row], score: impl Fn(&Row) -> f64) -> (f64, usize) {
    let (mut agree, mut pairs) = (0.0, 0usize);
    for (i, a) in rows.iter().enumerate() {
        for b in &rows[i + 1..] {
            if a.scenario != b.scenario || a.payload == b.payload {
                continue;
            }
            pairs += 1;
            let (sa, sb) = (score(a), score(b));
            agree += if sa == sb {
                0.5
            } else if (sa > sb) == (a.payload > b.payload) {
                1.0
            } else {
                0.0
            };
        }
    }
    (agree / pairs as f64, pairs)
}

fn fmt2(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}")
    } else {
        "n/a".to_string()
    }
}

type Score = (&'static str, fn(&Row) -> f64);

const SCORES: [Score; 8] = [
    ("epsilon, sim contacts (L1)", |r| r.eps_sim),
    ("volume, sim contacts (L1)", |r| r.vol_sim),
    ("epsilon, sim contacts (L-inf)", |r| {
        r.eps_sim_linf.unwrap_or(f64::NAN)
    }),
    ("volume, sim contacts (L-inf)", |r| {
        r.vol_sim_linf.unwrap_or(f64::NAN)
    }),
    ("epsilon, planned contacts (L1)", |r| r.eps_plan),
    ("volume, planned contacts (L1)", |r| r.vol_plan),
    ("planner's palm grade", |r| r.grade),
    ("planner's search order (first = best)", |r| {
        -(r.candidate as f64)
    }),
];

/// The statistics of `rows` as Markdown.
fn statistics(title: &str, rows: &[&Row]) -> String {
    let mut s = String::new();
    let objects: BTreeSet<&str> = rows.iter().map(|r| r.scenario.as_str()).collect();
    let holds = rows.iter().filter(|r| r.down == sim::Verdict::Hold).count();
    let with_six = rows.iter().filter(|r| r.six.is_some()).count();
    let holds6 = rows
        .iter()
        .filter(|r| r.six == Some(sim::Verdict::Hold))
        .count();
    let closure = rows.iter().filter(|r| r.eps_sim > 0.0).count();
    let _ = writeln!(
        s,
        "**{title}**: {} grasps of {} objects; {holds} hold (down), {holds6} of {with_six} hold (six), {closure} force closure (sim contacts)\n",
        rows.len(),
        objects.len(),
    );
    let held: Vec<&Row> = rows
        .iter()
        .filter(|r| r.down == sim::Verdict::Hold)
        .copied()
        .collect();
    let _ = writeln!(
        s,
        "| score | n | Spearman vs payload margin | Spearman among holds (n = {}) | ROC AUC, hold (down) | ROC AUC, hold (six) | within-object pairs ordered as payload |",
        held.len()
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for (name, f) in SCORES {
        let sub: Vec<&Row> = rows.iter().filter(|r| f(r).is_finite()).copied().collect();
        if sub.is_empty() {
            let _ = writeln!(s, "| {name} | 0 | | | | | |");
            continue;
        }
        let score: Vec<f64> = sub.iter().map(|r| f(r)).collect();
        let payload: Vec<f64> = sub.iter().map(|r| r.payload).collect();
        let hold: Vec<bool> = sub.iter().map(|r| r.down == sim::Verdict::Hold).collect();
        let six_rows: Vec<&Row> = sub.iter().filter(|r| r.six.is_some()).copied().collect();
        let six_score: Vec<f64> = six_rows.iter().map(|r| f(r)).collect();
        let hold6: Vec<bool> = six_rows
            .iter()
            .map(|r| r.six == Some(sim::Verdict::Hold))
            .collect();
        let held_sub: Vec<&Row> = held.iter().filter(|r| f(r).is_finite()).copied().collect();
        let hs: Vec<f64> = held_sub.iter().map(|r| f(r)).collect();
        let hp: Vec<f64> = held_sub.iter().map(|r| r.payload).collect();
        let (agree, pairs) = within_object_agreement(&sub, f);
        let _ = writeln!(
            s,
            "| {name} | {} | {} | {} | {} | {} | {} of {pairs} pairs |",
            sub.len(),
            fmt2(spearman(&score, &payload)),
            fmt2(spearman(&hs, &hp)),
            fmt2(auc(&score, &hold)),
            fmt2(auc(&six_score, &hold6)),
            fmt2(agree),
        );
    }
    s
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

fn quantile(mut v: Vec<f64>, q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[((v.len() - 1) as f64 * q).round() as usize]
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let usage =
        "usage: quality_study OUT_DIR [--candidates N] [--gravity both|down] SCENARIO.toml... \
                 (options apply to the scenarios after them)\n       \
                 quality_study OUT_DIR --report-only (statistics and plot again from the CSV)";
    let Some(out) = args.next().filter(|a| !a.starts_with("--")) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    // Each scenario with the options in force where it stands: (path, candidates, six).
    let mut files: Vec<(String, usize, bool)> = Vec::new();
    let (mut collect, mut six) = (4usize, true);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--candidates" => match args.next().and_then(|n| n.parse::<usize>().ok()) {
                Some(n) if n > 0 => collect = n,
                _ => {
                    eprintln!("quality_study: --candidates takes a positive count\n{usage}");
                    std::process::exit(2);
                }
            },
            "--gravity" => match args.next().as_deref() {
                Some("both") => six = true,
                Some("down") => six = false,
                _ => {
                    eprintln!("quality_study: --gravity takes both or down\n{usage}");
                    std::process::exit(2);
                }
            },
            f => files.push((f.to_string(), collect, six)),
        }
    }
    if files.is_empty() {
        eprintln!("{usage}");
        std::process::exit(2);
    }
    let out = PathBuf::from(out);
    if files.len() == 1 && files[0].0 == "--report-only" {
        let read = |name: &str| {
            std::fs::read_to_string(out.join(name)).unwrap_or_else(|e| {
                eprintln!("quality_study: {}: {e}", out.join(name).display());
                std::process::exit(2);
            })
        };
        let csv = read("quality_study.csv");
        report(&out, &parse_csv(&csv), &read("quality_study_run.txt"));
        return;
    }
    std::fs::create_dir_all(&out).expect("creating the output folder");
    let t_all = Instant::now();

    // Plan every scenario, then check every grasp: one task per grasp keeps both cores busy
    // to the end.
    let planned: Vec<(String, bool, Result<Planned, String>)> = files
        .par_iter()
        .map(|(f, collect, six)| (f.clone(), *six, plan_one(Path::new(f), *collect)))
        .collect();
    let mut skipped = Vec::new();
    let mut jobs = Vec::new();
    for (i, (f, _, p)) in planned.iter().enumerate() {
        match p {
            Ok(p) => jobs.extend((0..p.selection.candidates.len()).map(|k| (i, k))),
            Err(e) => skipped.push(format!("{f}: {e}")),
        }
    }
    eprintln!(
        "planned {} scenarios in {:.0} s; checking {} grasps",
        files.len(),
        t_all.elapsed().as_secs_f64(),
        jobs.len()
    );
    let rows: Vec<Row> = jobs
        .par_iter()
        .map(|&(i, k)| {
            let (_, six, p) = &planned[i];
            study_grasp(p.as_ref().expect("planned"), k, *six)
        })
        .collect();

    let mut csv = String::from(
        "set,scenario,candidate,axis,rules,planner_grade,epsilon_sim,volume_sim,epsilon_linf_sim,contacts_sim,epsilon_planned,volume_planned,payload_margin,down,six,down_ms,six_ms,payload_ms,quality_ms,volume_linf_sim,volume_linf_sim_rel_se\n",
    );
    for r in &rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:.4},{:.5},{:.4e},{},{},{:.5},{:.4e},{:.3},{},{},{:.1},{:.1},{:.1},{:.3},{},{}",
            r.set,
            r.scenario,
            r.candidate,
            r.axis,
            r.rules,
            r.grade,
            r.eps_sim,
            r.vol_sim,
            r.eps_sim_linf.map_or(String::new(), |e| format!("{e:.5}")),
            r.contacts_sim,
            r.eps_plan,
            r.vol_plan,
            r.payload,
            r.down.as_str(),
            r.six.map_or("not_run", |v| v.as_str()),
            r.ms_down,
            r.ms_six,
            r.ms_payload,
            r.ms_quality,
            r.vol_sim_linf.map_or(String::new(), |v| format!("{v:.4e}")),
            r.vol_sim_linf_se.map_or(String::new(), |v| format!("{v:.4}"))
        );
    }
    std::fs::write(out.join("quality_study.csv"), &csv).expect("writing the CSV");
    let mut note = format!("Whole run {:.0} s.\n", t_all.elapsed().as_secs_f64());
    if !skipped.is_empty() {
        let _ = writeln!(note, "\nNo grasp to check ({}):\n", skipped.len());
        for s in &skipped {
            let _ = writeln!(note, "- {s}");
        }
    }
    std::fs::write(out.join("quality_study_run.txt"), &note).expect("writing the run note");
    // The statistics from the CSV as written, so `--report-only` gives them again exactly.
    report(&out, &parse_csv(&csv), &note);
}

/// Reads back the CSV [`main`] writes.
fn parse_csv(csv: &str) -> Vec<Row> {
    let verdict = |v: &str| match v {
        "hold" => Some(sim::Verdict::Hold),
        "slip" => Some(sim::Verdict::Slip),
        "drop" => Some(sim::Verdict::Drop),
        _ => None,
    };
    csv.lines()
        .skip(1)
        .map(|line| {
            let c: Vec<&str> = line.split(',').collect();
            let f = |i: usize| c[i].parse::<f64>().expect("a number in the CSV");
            Row {
                set: match c[0] {
                    "real" => "real",
                    "tuning" => "tuning",
                    _ => "bundled",
                },
                scenario: c[1].to_string(),
                candidate: c[2].parse().expect("a candidate number"),
                axis: c[3].to_string(),
                rules: c[4].to_string(),
                grade: f(5),
                eps_sim: f(6),
                vol_sim: f(7),
                eps_sim_linf: c[8].parse().ok(),
                contacts_sim: c[9].parse().expect("a contact count"),
                eps_plan: f(10),
                vol_plan: f(11),
                payload: f(12),
                down: verdict(c[13]).expect("a down verdict"),
                six: verdict(c[14]),
                ms_down: f(15),
                ms_six: f(16),
                ms_payload: f(17),
                ms_quality: f(18),
                vol_sim_linf: c.get(19).and_then(|v| v.parse().ok()),
                vol_sim_linf_se: c.get(20).and_then(|v| v.parse().ok()),
            }
        })
        .collect()
}

/// Writes `quality_study.md` (statistics, costs, `note`, the table) and the SVG, and prints
/// the statistics.
fn report(out: &Path, rows: &[Row], note: &str) {
    let all: Vec<&Row> = rows.iter().collect();
    let mut md = String::new();
    md.push_str(&statistics("All", &all));
    for (title, sets) in [
        (
            "Bundled scenarios and tuning set",
            &["bundled", "tuning"][..],
        ),
        ("Real-object set", &["real"][..]),
    ] {
        let sub: Vec<&Row> = rows.iter().filter(|r| sets.contains(&r.set)).collect();
        if !sub.is_empty() && sub.len() < rows.len() {
            md.push('\n');
            md.push_str(&statistics(title, &sub));
        }
    }
    let six_ms: Vec<f64> = rows
        .iter()
        .filter(|r| r.six.is_some())
        .map(|r| r.ms_six)
        .collect();
    let _ = writeln!(
        md,
        "\nCost per grasp, wall clock, release build (median / 90th percentile / largest): \
         quality (sim contacts, L1 and L-inf) {:.2} / {:.2} / {:.0} ms; physics check `down` \
         {:.0} / {:.0} / {:.0} ms; `six` {:.0} / {:.0} / {:.0} ms; payload search {:.0} / {:.0} / {:.0} ms.",
        median(rows.iter().map(|r| r.ms_quality).collect()),
        quantile(rows.iter().map(|r| r.ms_quality).collect(), 0.9),
        quantile(rows.iter().map(|r| r.ms_quality).collect(), 1.0),
        median(rows.iter().map(|r| r.ms_down).collect()),
        quantile(rows.iter().map(|r| r.ms_down).collect(), 0.9),
        quantile(rows.iter().map(|r| r.ms_down).collect(), 1.0),
        median(six_ms.clone()),
        quantile(six_ms.clone(), 0.9),
        quantile(six_ms, 1.0),
        median(rows.iter().map(|r| r.ms_payload).collect()),
        quantile(rows.iter().map(|r| r.ms_payload).collect(), 0.9),
        quantile(rows.iter().map(|r| r.ms_payload).collect(), 1.0),
    );
    md.push_str(note);
    print!("{md}");
    let _ = writeln!(
        md,
        "\n| set | object | # | axis | rules | grade | epsilon (sim) | volume (sim) | volume L∞ (sim) | contacts (sim) | epsilon (planned) | payload | down | six |"
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:.2} | {:.4} | {:.2e} | {} | {} | {:.4} | {:.1} | {} | {} |",
            r.set,
            r.scenario,
            r.candidate,
            r.axis,
            r.rules,
            r.grade,
            r.eps_sim,
            r.vol_sim,
            r.vol_sim_linf.map_or("n/a".to_string(), |v| format!("{v:.2e}")),
            r.contacts_sim,
            r.eps_plan,
            r.payload,
            r.down.as_str(),
            r.six.map_or("not run", |v| v.as_str())
        );
    }
    std::fs::write(out.join("quality_study.md"), md).expect("writing the Markdown");
    plot(&out.join("quality_epsilon_payload.svg"), rows).expect("writing the SVG");
}

fn plot(path: &Path, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (760, 500)).into_drawing_area();
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
        .build_cartesian_2d(0.0..xmax, 0.0..88.0)?;
    chart
        .configure_mesh()
        .x_desc("Ferrari-Canny epsilon (L1)")
        .y_desc("payload margin (x mass; 0 = not hold)")
        .draw()?;
    let class = |r: &Row| match (r.down, r.six) {
        (sim::Verdict::Hold, Some(sim::Verdict::Hold)) => 0,
        (sim::Verdict::Hold, None) => 1,
        (sim::Verdict::Hold, _) => 2,
        _ => 3,
    };
    let classes = [
        ("hold (down), holds six", GREEN),
        ("hold (down), six not run", CYAN),
        ("hold (down), fails six", BLUE),
        ("slip or drop (down)", RED),
    ];
    for (c, (label, color)) in classes.into_iter().enumerate() {
        for (set_label, real) in [("bundled/tuning", false), ("real", true)] {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| class(r) == c && (r.set == "real") == real)
                .map(|r| (r.eps_sim, r.payload))
                .collect();
            if pts.is_empty() {
                continue;
            }
            let name = format!("{label}, {set_label}");
            if real {
                chart
                    .draw_series(
                        pts.iter()
                            .map(|p| TriangleMarker::new(*p, 5, color.stroke_width(1))),
                    )?
                    .label(name)
                    .legend(move |(x, y)| TriangleMarker::new((x, y), 5, color.stroke_width(1)));
            } else {
                chart
                    .draw_series(pts.iter().map(|p| Circle::new(*p, 4, color.filled())))?
                    .label(name)
                    .legend(move |(x, y)| Circle::new((x, y), 4, color.filled()));
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
