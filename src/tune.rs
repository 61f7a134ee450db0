//! Tuning the planner against simulated outcomes: a grid over planner parameters, every object
//! planned and checked at every setting, settings ranked by what the physics check says.
//!
//! Score of a setting, compared in this order: hold rate (objects held / objects), then the
//! mean payload margin (0 for an object not held), then the mean translation of the held objects
//! during the hold (smaller is better).
//!
//! Work that does not depend on a swept parameter is done once: each object is loaded and
//! aligned once; its stage-1 domain (the vertical slices, which depend only on the AngularStep
//! and the HeightStep) is built once per distinct pair of those; a grasp that two settings both
//! produce is simulated once (its physics does not depend on how it was found).

use crate::batch::{scenario_for, Item};
use crate::mesh::AlignedObject;
use crate::prepared::PreparedObject;
use crate::report::StageTimings;
use crate::plan::{self, Domain};
use crate::scenario::{validate_planner, PlannerParams, Scenario};
use crate::sim::{self, ObjectShape, SimHand, Verdict};
use crate::Error;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;

/// The parameters the tuner can sweep.
pub const PARAMETERS: [&str; 8] = [
    "sf_c",
    "height_step_mm",
    "angular_step_deg",
    "vertical_deviation_deg",
    "joint_deviation_deg",
    "joint_deviation_theta1_deg",
    "joint_deviation_theta2_deg",
    "pitch_range_deg",
];

/// One swept parameter: its name and values.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sweep {
    /// Parameter name (one of [`PARAMETERS`]).
    pub name: String,
    /// Values, in order.
    pub values: Vec<f64>,
}

/// Parses `NAME=START:END:STEP`.
///
/// # Errors
/// A one-line message.
pub fn parse_sweep(s: &str) -> Result<Sweep, String> {
    let (name, range) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}` is not NAME=START:END:STEP"))?;
    if !PARAMETERS.contains(&name) {
        return Err(format!(
            "unknown parameter `{name}` (one of {})",
            PARAMETERS.join(", ")
        ));
    }
    let parts: Vec<f64> = range
        .split(':')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}`: START, END and STEP must be numbers"))?;
    let [start, end, step] = parts[..] else {
        return Err(format!("`{s}` is not NAME=START:END:STEP"));
    };
    if !(step > 0.0 && end >= start && start.is_finite() && end.is_finite()) {
        return Err(format!("`{s}`: need STEP > 0 and END >= START"));
    }
    let n = ((end - start) / step + 1e-9).floor() as usize + 1;
    if n > 1000 {
        return Err(format!("`{s}`: {n} values, more than 1000"));
    }
    // Rounded to 1e-9 so that 0.1 steps give 0.3, not 0.30000000000000004.
    let values = (0..n)
        .map(|i| ((start + i as f64 * step) * 1e9).round() / 1e9)
        .collect();
    Ok(Sweep {
        name: name.to_string(),
        values,
    })
}

fn apply(p: &mut PlannerParams, name: &str, v: f64) {
    match name {
        "sf_c" => p.sf_c = v,
        "height_step_mm" => p.height_step_mm = v,
        "angular_step_deg" => p.angular_step_deg = v,
        "vertical_deviation_deg" => p.vertical_deviation_deg = v,
        "joint_deviation_deg" => {
            p.joint_deviation_theta1_deg = v;
            p.joint_deviation_theta2_deg = v;
        }
        "joint_deviation_theta1_deg" => p.joint_deviation_theta1_deg = v,
        "joint_deviation_theta2_deg" => p.joint_deviation_theta2_deg = v,
        "pitch_range_deg" => p.pitch_range_deg = v,
        _ => {}
    }
}

/// Every combination of the sweeps' values, the first sweep varying slowest.
pub fn grid(sweeps: &[Sweep]) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::new()];
    for s in sweeps {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                s.values.iter().map(move |v| {
                    let mut p = prefix.clone();
                    p.push(*v);
                    p
                })
            })
            .collect();
    }
    out
}

/// An object's result at one setting.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectResult {
    /// Scenario name.
    pub scenario: String,
    /// `feasible`, `ungraspable`, `override_angles` (the scenario fixes the joint angles: checked
    /// with them, not planned), or `invalid` (the setting breaks a rule for this hand).
    pub status: String,
    /// `hold`, `slip`, `drop` or `not_run`.
    pub verdict: String,
    /// Translation during the hold `[mm]`.
    pub translation_mm: Option<f64>,
    /// Payload margin (held objects only).
    pub payload_margin: Option<f64>,
    /// Why the setting is `invalid` for this object's hand.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// One setting's results and score.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SettingResult {
    /// Parameter values, in the order of the sweeps.
    pub values: Vec<f64>,
    /// Objects held / objects.
    pub hold_rate: f64,
    /// Mean payload margin over all objects (0 for an object not held).
    pub mean_payload_margin: f64,
    /// Mean translation of the held objects `[mm]` (`null` when none is held).
    pub mean_translation_mm: Option<f64>,
    /// Per object.
    pub objects: Vec<ObjectResult>,
    /// Why the setting is invalid (it breaks a rule for an object's hand, e.g. a HeightStep
    /// that does not divide the finger gap): such a setting is not run and not ranked, and its
    /// scores are 0. Absent for a valid setting.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub invalid: Option<String>,
}

/// Counters that show which work was shared.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TuneCounters {
    /// Objects loaded and aligned (once each).
    pub objects_loaded: usize,
    /// Stage-1 domains built (once per object and distinct AngularStep, HeightStep).
    pub domains_built: usize,
    /// Plans (stages 2–3 and search) run.
    pub plans: usize,
    /// Physics checks run (hold tests, payload bisections included).
    pub sim_runs: usize,
    /// Physics checks saved because another setting produced the same grasp.
    pub sim_reused: usize,
}

/// The whole tuning run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TuneResult {
    /// The sweeps.
    pub sweeps: Vec<Sweep>,
    /// Every setting, in grid order.
    pub settings: Vec<SettingResult>,
    /// Index into `settings` of the best valid one (0 when every setting is invalid).
    pub best: usize,
    /// Work counters.
    pub counters: TuneCounters,
}

struct Prepared {
    scenario: Scenario,
    object: PreparedObject,
}

/// Simulated grasps by (axis, fingerprint): verdict, translation, payload margin of a hold, and
/// the outcome.
type SimCache =
    HashMap<(crate::mesh::GraspAxis, Vec<u64>), (Verdict, f64, Option<f64>, sim::SimOutcome)>;

/// The physics check of a pose (and its payload margin when it holds), cached by `key`.
fn simulate(
    p: &Prepared,
    pose: &SimHand,
    shape: &ObjectShape,
    key: (crate::mesh::GraspAxis, Vec<u64>),
    sims: &mut SimCache,
    counters: &mut TuneCounters,
) -> (Verdict, f64, Option<f64>, sim::SimOutcome) {
    if let Some(o) = sims.get(&key) {
        counters.sim_reused += 1;
        return o.clone();
    }
    let case = p.object.case(&p.scenario, pose, shape);
    let out = sim::check(&case);
    counters.sim_runs += 1;
    let margin = (out.verdict == Verdict::Hold).then(|| sim::payload_margin(&case));
    let o = (out.verdict, out.translation_mm, margin, out);
    sims.insert(key, o.clone());
    o
}

/// What identifies a grasp for the physics check: its palm pose and joint angles, bit for bit.
fn fingerprint(h: &SimHand) -> Vec<u64> {
    let mut k: Vec<u64> = h.origin_mm.iter().map(|v| v.to_bits()).collect();
    for a in &h.axes {
        k.extend(a.iter().map(|v| v.to_bits()));
    }
    for t in &h.theta_deg {
        k.extend(t.iter().map(|v| v.to_bits()));
    }
    k
}

struct PerObject {
    results: Vec<ObjectResult>,
    counters: TuneCounters,
}

/// Runs the grid over `items` on `jobs` threads (objects in parallel).
///
/// # Errors
/// A bad scenario or mesh among the items.
pub fn tune(
    items: &[Item],
    template: &Scenario,
    sweeps: &[Sweep],
    candidates: usize,
    jobs: usize,
) -> Result<TuneResult, Error> {
    tune_with_progress(items, template, sweeps, candidates, jobs, &|_| {})
}

/// [`tune`], calling `progress` with the object's scenario name each time one object is done at
/// one setting (objects × settings calls in all, from the worker threads).
///
/// # Errors
/// A bad scenario or mesh among the items.
pub fn tune_with_progress(
    items: &[Item],
    template: &Scenario,
    sweeps: &[Sweep],
    candidates: usize,
    jobs: usize,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<TuneResult, Error> {
    let settings = grid(sweeps);
    let mut prepared = Vec::new();
    for item in items {
        let scenario = scenario_for(item, template)?;
        let object = PreparedObject::load(&scenario.object, &mut StageTimings::default())?;
        prepared.push(Prepared { scenario, object });
    }
    let work = || -> Vec<PerObject> {
        prepared
            .par_iter()
            .map(|p| run_object(p, sweeps, &settings, candidates, progress))
            .collect()
    };
    let per_object = match rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
    {
        Ok(pool) => pool.install(work),
        Err(_) => work(),
    };
    let mut counters = TuneCounters {
        objects_loaded: prepared.len(),
        ..TuneCounters::default()
    };
    for o in &per_object {
        counters.domains_built += o.counters.domains_built;
        counters.plans += o.counters.plans;
        counters.sim_runs += o.counters.sim_runs;
        counters.sim_reused += o.counters.sim_reused;
    }
    let results: Vec<SettingResult> = settings
        .iter()
        .enumerate()
        .map(|(k, values)| {
            let objects: Vec<ObjectResult> =
                per_object.iter().map(|o| o.results[k].clone()).collect();
            score(values.clone(), objects)
        })
        .collect();
    let best = (0..results.len())
        .filter(|&k| results[k].invalid.is_none())
        .min_by(|&a, &b| rank(&results[a], &results[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    Ok(TuneResult {
        sweeps: sweeps.to_vec(),
        settings: results,
        best,
        counters,
    })
}

/// Orders settings best first.
pub fn rank(a: &SettingResult, b: &SettingResult) -> std::cmp::Ordering {
    b.hold_rate
        .total_cmp(&a.hold_rate)
        .then(b.mean_payload_margin.total_cmp(&a.mean_payload_margin))
        .then(
            a.mean_translation_mm
                .unwrap_or(f64::INFINITY)
                .total_cmp(&b.mean_translation_mm.unwrap_or(f64::INFINITY)),
        )
}

fn score(values: Vec<f64>, objects: Vec<ObjectResult>) -> SettingResult {
    let invalid = objects
        .iter()
        .find_map(|o| o.reason.as_ref().map(|r| format!("{}: {r}", o.scenario)));
    let n = objects.len().max(1) as f64;
    let held: Vec<&ObjectResult> = objects.iter().filter(|o| o.verdict == "hold").collect();
    let mean_translation_mm = (!held.is_empty())
        .then(|| held.iter().filter_map(|o| o.translation_mm).sum::<f64>() / held.len() as f64);
    SettingResult {
        values,
        hold_rate: held.len() as f64 / n,
        // Folded from +0.0: an empty f64 sum is -0.0, printed "-0.00".
        mean_payload_margin: objects
            .iter()
            .filter_map(|o| o.payload_margin)
            .fold(0.0, |a, m| a + m)
            / n,
        mean_translation_mm,
        objects,
        invalid,
    }
}

fn run_object(
    p: &Prepared,
    sweeps: &[Sweep],
    settings: &[Vec<f64>],
    candidates: usize,
    progress: &(dyn Fn(&str) + Sync),
) -> PerObject {
    let mut counters = TuneCounters::default();
    let mut domains: HashMap<(u64, u64), Domain> = HashMap::new();
    let mut sims: SimCache = HashMap::new();
    let select_domains: crate::select::DomainCache = Default::default();
    let hand = &p.scenario.hand;
    let friction = p.scenario.object.friction;
    let mut results = Vec::with_capacity(settings.len());
    for values in settings {
        if !results.is_empty() {
            progress(&p.scenario.name);
        }
        let mut params = p.scenario.planner.clone();
        for (s, v) in sweeps.iter().zip(values) {
            apply(&mut params, &s.name, *v);
        }
        let name = p.scenario.name.clone();
        if let Err((key, why)) = validate_planner(&params, hand, friction) {
            results.push(ObjectResult {
                scenario: name,
                status: "invalid".to_string(),
                verdict: "not_run".to_string(),
                translation_mm: None,
                payload_margin: None,
                reason: Some(format!("{key} {why}")),
            });
            continue;
        }
        let s = &p.scenario.sim;
        // A scenario that fixes the joint angles (`[sim] override_angles`) is checked with them,
        // as `grasp-sim scenario.toml` does: its outcome does not depend on the planner.
        if let Some(angles) = &s.override_angles {
            let key = (
                params.angular_step_deg.to_bits(),
                params.height_step_mm.to_bits(),
            );
            let domain = domains
                .entry(key)
                .or_insert_with(|| {
                    counters.domains_built += 1;
                    Domain::build(&p.object.aligned.mesh, &params, hand)
                })
                .clone();
            let mut t = StageTimings::default();
            let graded = plan::grade_built(domain, hand, &params, friction, &mut t);
            let aligned = &p.object.aligned;
            let pose = SimHand::from_override(&aligned.mesh, hand, &graded, s, angles);
            let outcome = pose.ok().map(|pose| {
                let key = (crate::mesh::GraspAxis::THESIS, fingerprint(&pose));
                let shape = p.object.shape(aligned);
                simulate(p, &pose, &shape, key, &mut sims, &mut counters)
            });
            results.push(ObjectResult {
                scenario: name,
                status: "override_angles".to_string(),
                verdict: outcome
                    .as_ref()
                    .map_or("not_run", |o| o.0.as_str())
                    .to_string(),
                translation_mm: outcome.as_ref().map(|o| o.1),
                payload_margin: outcome.as_ref().and_then(|o| o.2),
                reason: None,
            });
            continue;
        }
        // As a run plans and chooses (every axis, the extended rules when the thesis's find
        // nothing, candidates checked until one holds): the grasp a setting leads to. A grasp
        // two settings share is simulated once.
        let sims_cell = std::cell::RefCell::new(std::mem::take(&mut sims));
        let counters_cell = std::cell::RefCell::new(std::mem::take(&mut counters));
        let check = |a: &AlignedObject, g: &plan::search::Grasp| -> sim::SimOutcome {
            let pose = SimHand::from_grasp(g);
            let shape = p.object.shape(a);
            let key = (a.axis, fingerprint(&pose));
            let o = simulate(
                p,
                &pose,
                &shape,
                key,
                &mut sims_cell.borrow_mut(),
                &mut counters_cell.borrow_mut(),
            );
            sim::SimOutcome {
                verdict: o.0,
                translation_mm: o.1,
                ..o.3.clone()
            }
        };
        let mut t = StageTimings::default();
        let selection = crate::select::select(
            p.object.mesh(),
            &p.object.props,
            &crate::select::SelectParams {
                hand,
                planner: &params,
                friction,
                collect: candidates,
                max_checked: Some(s.max_checked.max(1)),
                check: &check,
                domains: Some(&select_domains),
            },
            &mut t,
        );
        sims = sims_cell.into_inner();
        counters = counters_cell.into_inner();
        counters.domains_built = domains.len() + select_domains.borrow().len();
        counters.plans += 1;
        let chosen = selection.chosen().and_then(|c| {
            let a = &selection.axes[c.axis_plan].aligned;
            let pose = SimHand::from_grasp(&c.grasp);
            sims.get(&(a.axis, fingerprint(&pose))).cloned()
        });
        let Some(best) = chosen else {
            results.push(ObjectResult {
                scenario: name,
                status: if selection.chosen.is_some() {
                    "feasible"
                } else {
                    "ungraspable"
                }
                .to_string(),
                verdict: "not_run".to_string(),
                translation_mm: None,
                payload_margin: None,
                reason: None,
            });
            continue;
        };
        let status = "feasible";
        let (verdict, translation, margin) = (best.0, best.1, best.2);
        results.push(ObjectResult {
            scenario: name,
            status: status.to_string(),
            verdict: verdict.as_str().to_string(),
            translation_mm: Some(translation),
            payload_margin: margin,
            reason: None,
        });
    }
    if !results.is_empty() {
        progress(&p.scenario.name);
    }
    PerObject { results, counters }
}

/// The results as CSV: one row per setting, a column per swept parameter.
pub fn to_csv(r: &TuneResult) -> String {
    let mut s = String::new();
    for sw in &r.sweeps {
        s.push_str(&sw.name);
        s.push(',');
    }
    s.push_str("hold_rate,mean_payload_margin,mean_translation_mm,held,feasible,objects,invalid\n");
    for set in &r.settings {
        for v in &set.values {
            s.push_str(&format!("{v},"));
        }
        if let Some(why) = &set.invalid {
            // Not run: no scores, only the reason (quoted, doubled quotes inside).
            s.push_str(&format!(
                ",,,,,{},\"{}\"\n",
                set.objects.len(),
                why.replace('"', "\"\"")
            ));
            continue;
        }
        let held = set.objects.iter().filter(|o| o.verdict == "hold").count();
        let feasible = set
            .objects
            .iter()
            .filter(|o| o.status == "feasible")
            .count();
        s.push_str(&format!(
            "{:.6},{:.6},{},{held},{feasible},{},\n",
            set.hold_rate,
            set.mean_payload_margin,
            set.mean_translation_mm
                .map_or(String::new(), |t| format!("{t:.6}")),
            set.objects.len()
        ));
    }
    s
}

/// The results as a table, best setting marked.
pub fn to_table(r: &TuneResult) -> String {
    let mut s = String::new();
    for sw in &r.sweeps {
        s.push_str(&format!("{:>24} ", sw.name));
    }
    s.push_str(" hold rate  payload margin  translation [mm]\n");
    for (k, set) in r.settings.iter().enumerate() {
        for v in &set.values {
            s.push_str(&format!("{v:>24} "));
        }
        if let Some(why) = &set.invalid {
            s.push_str(&format!(" invalid, not ranked: {why}\n"));
            continue;
        }
        s.push_str(&format!(
            " {:>9.3}  {:>14.2}  {:>16}{}\n",
            set.hold_rate,
            set.mean_payload_margin,
            set.mean_translation_mm
                .map_or("-".to_string(), |t| format!("{t:.2}")),
            if k == r.best { "  <- best" } else { "" }
        ));
    }
    s
}

/// Writes one SVG per swept parameter: hold rate and mean payload margin of the best setting at
/// each value of that parameter.
///
/// # Errors
/// A message when the plot cannot be drawn or written.
pub fn plot(r: &TuneResult, dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>, String> {
    use plotters::prelude::*;
    let mut written = Vec::new();
    for (i, sw) in r.sweeps.iter().enumerate() {
        // For each value, the best setting having it.
        let points: Vec<(f64, f64, f64)> = sw
            .values
            .iter()
            .filter_map(|v| {
                r.settings
                    .iter()
                    .filter(|s| s.values[i] == *v && s.invalid.is_none())
                    .min_by(|a, b| rank(a, b))
                    .map(|s| (*v, s.hold_rate, s.mean_payload_margin))
            })
            .collect();
        let path = dir.join(format!("score_{}.svg", sw.name));
        let (x0, x1) = (sw.values[0], *sw.values.last().unwrap_or(&sw.values[0]));
        let (x0, x1) = if x1 > x0 {
            (x0, x1)
        } else {
            (x0 - 1.0, x0 + 1.0)
        };
        let margin_max = points.iter().map(|p| p.2).fold(1.0f64, f64::max) * 1.1;
        let draw = || -> Result<(), Box<dyn std::error::Error>> {
            let root = SVGBackend::new(&path, (720, 420)).into_drawing_area();
            root.fill(&WHITE)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(
                    format!("Tuning: score against {}", sw.name),
                    ("sans-serif", 20),
                )
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(50)
                .right_y_label_area_size(50)
                .build_cartesian_2d(x0..x1, 0f64..1.05f64)?
                .set_secondary_coord(x0..x1, 0f64..margin_max);
            chart
                .configure_mesh()
                .x_desc(sw.name.as_str())
                .y_desc("hold rate")
                .draw()?;
            chart
                .configure_secondary_axes()
                .y_desc("mean payload margin")
                .draw()?;
            chart
                .draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.1)), &BLUE))?
                .label("hold rate")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
            chart.draw_series(
                points
                    .iter()
                    .map(|p| Circle::new((p.0, p.1), 3, BLUE.filled())),
            )?;
            chart
                .draw_secondary_series(LineSeries::new(points.iter().map(|p| (p.0, p.2)), &RED))?
                .label("mean payload margin")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
            root.present()?;
            Ok(())
        };
        draw().map_err(|e| format!("{}: cannot draw: {e}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}
