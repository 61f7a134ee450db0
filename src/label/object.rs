//! Labelling one object: plan its candidates once, pick diverse ones, and check each picked
//! grasp (or each given grasp) with its perturbed samples, every check of the object spread over
//! the cores; and the check of one grasp line, the one place both `label` and `check --grasps`
//! turn a grasp into its record, so that the two agree bit for bit.
//!
//! Per-object work is done once: the mesh is loaded and aligned once, the planner slices and
//! grades each axis once (its candidates are collected in one search), and the collider of each
//! axis is made once ([`PreparedObject::own_shape`]: a convex decomposition is made once, in the
//! thesis axis's frame, and moved into the others') and shared by every check of the object.

use super::line::{Carried, ErrorRecord, GraspLine, LabelInfo, LabelRecord, UngraspableRecord};
use crate::mesh::{self, AlignedObject, GraspAxis};
use crate::pick::{self, feature_of, Feature};
use crate::pipeline::Error;
use crate::plan::search::Grasp;
use crate::plan::StageTimings;
use crate::prepared::PreparedObject;
use crate::report::to_rounded_json;
use crate::scenario::Scenario;
use crate::select::{self, AxisPlan, Selection};
use crate::sim::{self, Perturbation, SimHand, SimOutcome};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeSet;
use std::sync::Mutex;
use std::time::Instant;

/// What `label` asks of each object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LabelParams {
    /// Grasps to label per object (`--grasps K`).
    pub grasps: usize,
    /// Perturbed checks per grasp (`--samples S`).
    pub samples: usize,
    /// Feasible candidates to plan at most, to pick from (`--candidates N`).
    pub candidates: usize,
}

/// `--export-mjcf DIR --mujoco-fraction F`: the MJCF scene of a deterministic fraction of the
/// labelled grasps, for `scripts/compare_engines.py --labels`.
#[derive(Debug, Clone, PartialEq)]
pub struct MjcfExport {
    /// The folder: a grasp's scene goes to `DIR/<object>/<grasp_index>/`.
    pub dir: std::path::PathBuf,
    /// The fraction of the grasps exported, from 0 to 1.
    pub fraction: f64,
}

impl MjcfExport {
    /// True if and only if grasp `index` of `object` is among the fraction exported: the same
    /// grasps whatever the run, the thread count or the order (a hash of the two, not a draw).
    pub fn takes(&self, object: &str, index: usize) -> bool {
        use sha2::{Digest, Sha256};
        let mut h = Sha256::new();
        h.update(object.as_bytes());
        h.update([0]);
        h.update((index as u64).to_le_bytes());
        let d = h.finalize();
        let x = u64::from_le_bytes([d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7]]);
        (x as f64) < self.fraction * (u64::MAX as f64)
    }
}

pub use crate::pick::DEFAULT_CANDIDATES;

/// One finished line of an object: its grasp index (`None` for an object-level line) and its
/// JSON text.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// The grasp index, or `None` for a line about the whole object.
    pub grasp_index: Option<usize>,
    /// Where the line goes among the object's lines: the picked candidate's index in search
    /// order, or the given grasp's line number from 0.
    pub order: usize,
    /// True if and only if the line reports an error.
    pub is_error: bool,
    /// The JSON object, one line, no newline.
    pub text: String,
}

/// What labelling an object found and cost, for the summary line and the benchmark.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ObjectSummary {
    /// The scenario's name.
    pub object: String,
    /// Feasible candidates the planner found.
    pub candidates: usize,
    /// Grasps picked (and labelled, less those skipped as already in the file).
    pub picked: usize,
    /// Grasps labelled by this run.
    pub labelled: usize,
    /// Perturbed checks this run ran.
    pub samples_checked: usize,
    /// Of the grasps labelled, those whose hold probability is at least 0.5.
    pub holding: usize,
    /// Mean pairwise palm distance of the picks: translation `[mm]`, rotation `[deg]`.
    pub picked_spread: (f64, f64),
    /// The same of the first `picked` candidates in search order.
    pub first_spread: (f64, f64),
    /// Loading, aligning and planning `[ms]`.
    pub plan_ms: f64,
    /// Making the colliders `[ms]`.
    pub collider_ms: f64,
    /// The checks `[ms]`.
    pub check_ms: f64,
    /// The whole object `[ms]`.
    pub wall_ms: f64,
}

impl ObjectSummary {
    /// The share of the object's time spent before any check: load, plan, collider.
    pub fn fixed_fraction(&self) -> f64 {
        (self.plan_ms + self.collider_ms) / self.wall_ms.max(f64::MIN_POSITIVE)
    }

    /// The summary in one line, e.g. `cup: 667 candidates, 16 picked (spread 42 mm, 61 deg; the
    /// first 16: 3 mm, 70 deg), 16 labelled, 11 hold p >= 0.5; plan 0.5 s, collider 0.1 s,
    /// checks 30.2 s`.
    pub fn line(&self) -> String {
        if self.candidates == 0 {
            return format!(
                "{}: no feasible grasp to label; plan {:.1} s",
                self.object,
                self.plan_ms / 1000.0
            );
        }
        format!(
            "{}: {} candidates, {} picked (spread {:.0} mm, {:.0} deg; the first {}: {:.0} mm, {:.0} deg), {} labelled, {} with hold probability >= 0.5; plan {:.1} s, collider {:.1} s, checks {:.1} s",
            self.object,
            self.candidates,
            self.picked,
            self.picked_spread.0,
            self.picked_spread.1,
            self.picked,
            self.first_spread.0,
            self.first_spread.1,
            self.labelled,
            self.holding,
            self.plan_ms / 1000.0,
            self.collider_ms / 1000.0,
            self.check_ms / 1000.0
        )
    }
}

/// The planner's grade of a grasp (the record's `grade`): the palm grade at Finger_1's index
/// (thesis 3.4.4.2) and its terms, each finger's elevation grades (curvature, diameter and
/// their combination by Sf_c, eq. 3.4) at its index.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Grade {
    /// The palm grade at Finger_1's index (`null` where ungraspable).
    pub palm: Option<f64>,
    /// Its place among the sorted palm indices (0: the best).
    pub palm_rank: Option<usize>,
    /// Sf_c, the curvature's significance factor.
    pub sf_c: f64,
    /// Per finger, in the hand's order.
    pub fingers: Vec<FingerGrade>,
    /// The order's terms beyond the thesis (issue 58, [`crate::plan::order`]).
    pub terms: crate::plan::order::OrderTerms,
    /// Which axis plan of the search it came from (0: the first searched).
    pub axis_plan: usize,
    /// Its place in that axis plan's thesis order (0: the thesis's first), whatever order the
    /// `[planner] sf_*` factors searched it in.
    pub place: usize,
    /// The feasible grasps that axis plan found.
    pub found: usize,
}

/// A finger's elevation grades at its index.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FingerGrade {
    /// Its elevation index.
    pub index: i64,
    /// Curvature pattern grade.
    pub curvature: Option<f64>,
    /// Effective Diameter grade.
    pub diameter: Option<f64>,
    /// Combined grade.
    pub combined: Option<f64>,
}

/// Where a candidate sits in the search: its axis plan, its place in that plan's order, and
/// the grasps that plan found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Place {
    /// The axis plan's index.
    pub axis_plan: usize,
    /// The place in its order.
    pub place: usize,
    /// The grasps it found.
    pub found: usize,
}

/// The grade of `g`, planned on `plan` (at `at` in the search) for `hand`, under Sf_c `sf_c`.
pub fn grade_of(
    g: &Grasp,
    plan: &AxisPlan,
    place: Place,
    hand: &crate::hand::Hand,
    sf_c: f64,
) -> Grade {
    let graded = &plan.graded;
    let at = |v: &[Option<f64>], i: i64| -> Option<f64> {
        usize::try_from(i - 1)
            .ok()
            .and_then(|k| v.get(k).copied().flatten())
    };
    let i = g.elevation_index as i64;
    Grade {
        palm: at(&graded.grades.palm, i),
        palm_rank: graded
            .sorted_indices
            .iter()
            .position(|&s| s == g.elevation_index),
        sf_c,
        fingers: graded
            .finger_offsets
            .iter()
            .map(|&o| FingerGrade {
                index: i - o,
                curvature: at(&graded.grades.curvature, i - o),
                diameter: at(&graded.grades.diameter, i - o),
                combined: at(&graded.grades.combined, i - o),
            })
            .collect(),
        terms: crate::plan::order::terms(g, &plan.aligned, hand),
        axis_plan: place.axis_plan,
        place: place.place,
        found: place.found,
    }
}

/// `scenario` as every check of a label run takes it: `samples` perturbed checks per grasp.
pub fn with_samples(scenario: &Scenario, samples: usize) -> Scenario {
    let mut s = scenario.clone();
    s.sim.robust.samples = samples;
    s
}

/// The record of checking `line` with `scenario`'s samples, from the nominal check and the
/// samples' checks already run on `case`.
fn record_of(
    scenario: &Scenario,
    index: usize,
    line: &GraspLine,
    case: &sim::Case,
    nominal: &SimOutcome,
    runs: &[(Perturbation, SimOutcome)],
    label: LabelInfo,
) -> LabelRecord {
    let robust = sim::robust::robust_of(case, runs, 0.0);
    LabelRecord::of(&scenario.name, index, line, nominal, &robust, label)
}

/// A grasp of an object ready to check: its line, its pose and collider about its axis.
struct Posed {
    /// Its index among the object's grasps (the search order, or the given line's number).
    index: usize,
    line: GraspLine,
    pose: SimHand,
    shape: sim::ObjectShape,
}

/// Per grasp being checked: its nominal check, its samples' checks, and how many of them are
/// done.
type Slot = (
    Option<SimOutcome>,
    Vec<Option<(Perturbation, SimOutcome)>>,
    usize,
);

/// Runs one check of a grasp, its nominal check (`k` = `None`) or its sample `k`, and stores it
/// in the grasp's `slot`; returns true if and only if it was the last of the grasp's `samples +
/// 1` checks to finish.
fn run_task(case: &sim::Case, slot: &Mutex<Slot>, k: Option<usize>, samples: usize) -> bool {
    match k {
        None => {
            let out = sim::entry::labelled(case);
            let mut slot = slot.lock().unwrap_or_else(|e| e.into_inner());
            slot.0 = Some(out);
            slot.2 += 1;
            slot.2 == samples + 1
        }
        Some(k) => {
            let run = sim::entry::labelled_sample(case, k);
            let mut slot = slot.lock().unwrap_or_else(|e| e.into_inner());
            slot.1[k] = Some(run);
            slot.2 += 1;
            slot.2 == samples + 1
        }
    }
}

/// The nominal check and the samples' checks of a grasp whose checks are all done, taken out of
/// its `slot`; `None` if one is missing.
fn take_checks(slot: &Mutex<Slot>) -> Option<(SimOutcome, Vec<(Perturbation, SimOutcome)>)> {
    let (nominal, runs) = {
        let mut slot = slot.lock().unwrap_or_else(|e| e.into_inner());
        (slot.0.take(), std::mem::take(&mut slot.1))
    };
    Some((nominal?, runs.into_iter().collect::<Option<Vec<_>>>()?))
}

/// Checks every grasp of `grasps` (the nominal check and `scenario.sim.robust.samples` samples
/// each), all the object's checks spread over the cores, and calls `emit` with each grasp's
/// record as soon as its checks are done. Returns the perturbed checks run and how many grasps
/// held with a probability of at least 0.5.
fn check_all(
    scenario: &Scenario,
    object: &PreparedObject,
    grasps: &[Posed],
    info: &(dyn Fn(usize, f64) -> LabelInfo + Sync),
    emit: &(dyn Fn(Line) + Sync),
) -> (usize, usize) {
    let samples = scenario.sim.robust.samples;
    let cases: Vec<sim::Case> = grasps
        .iter()
        .map(|g| object.case(scenario, &g.pose, &g.shape))
        .collect();
    let slots: Vec<Mutex<Slot>> = grasps
        .iter()
        .map(|_| Mutex::new((None, vec![None; samples], 0)))
        .collect();
    let starts: Vec<Mutex<Option<Instant>>> = grasps.iter().map(|_| Mutex::new(None)).collect();
    let held = std::sync::atomic::AtomicUsize::new(0);
    let tasks: Vec<(usize, Option<usize>)> = (0..grasps.len())
        .flat_map(|g| std::iter::once((g, None)).chain((0..samples).map(move |k| (g, Some(k)))))
        .collect();
    tasks.par_iter().for_each(|&(g, k)| {
        starts[g]
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get_or_insert_with(Instant::now);
        let case = &cases[g];
        if !run_task(case, &slots[g], k, samples) {
            return;
        }
        let Some((nominal, runs)) = take_checks(&slots[g]) else {
            return;
        };
        let started = starts[g]
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .unwrap_or_else(Instant::now);
        let wall_ms = started.elapsed().as_secs_f64() * 1000.0;
        let grasp = &grasps[g];
        let record = record_of(
            scenario,
            grasp.index,
            &grasp.line,
            case,
            &nominal,
            &runs,
            info(grasp.index, wall_ms),
        );
        if record.hold_probability >= 0.5 {
            held.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        emit(record_line(&record, grasp.index));
    });
    (grasps.len() * samples, held.into_inner())
}

/// A record as its line.
fn record_line(record: &LabelRecord, index: usize) -> Line {
    match to_rounded_json(record) {
        Ok(text) => Line {
            grasp_index: Some(record.grasp_index),
            order: index,
            is_error: false,
            text,
        },
        Err(e) => error_line(
            &record.object,
            Some(index),
            &format!("cannot write the record as JSON: {e}"),
            record.label.clone(),
        ),
    }
}

/// The line of an error: of a grasp (`index`) or of the whole object.
pub fn error_line(object: &str, index: Option<usize>, error: &str, label: LabelInfo) -> Line {
    let record = ErrorRecord {
        object: object.to_string(),
        grasp_index: index,
        error: error.replace('\n', " "),
        label,
    };
    Line {
        grasp_index: index,
        order: index.unwrap_or(0),
        is_error: true,
        text: to_rounded_json(&record)
            .unwrap_or_else(|_| serde_json::json!({"object": object, "error": error}).to_string()),
    }
}

/// Plans `object`'s candidates as a run does, without checking any: every feasible grasp in
/// search order, up to `candidates`, the rule sets after the first that finds grasps included
/// while fewer than the scenario's `max_checked` were found (what its search could reach).
fn plan_candidates(
    scenario: &Scenario,
    object: &PreparedObject,
    candidates: usize,
    timings: &mut StageTimings,
) -> Selection {
    let no_check = |_: &AlignedObject, _: &Grasp| -> SimOutcome {
        unreachable!("label plans with max_checked None: no candidate is checked")
    };
    select::select(
        object.mesh(),
        &object.props,
        &select::SelectParams {
            hand: &scenario.hand,
            planner: &scenario.planner,
            friction: scenario.object.friction,
            collect: candidates.max(1),
            max_checked: None,
            check: &no_check,
            recheck: None,
            probe: None,
            domains: None,
            frame: scenario.object.frame,
            order_by_closing: None,
            order_samples: None,
            plan_reach: scenario.sim.selection.max_checked,
            order_reach: 0,
        },
        timings,
    )
}

/// Labels `scenario`'s object (see the module docs): plans up to `params.candidates`, picks
/// `params.grasps` diverse ones, and checks each with `params.samples` samples, calling `emit`
/// with each grasp's line as it is done (in no set order) and skipping the grasp indices in
/// `skip` (already labelled). `info(index, wall_ms)` gives a line's `label` part. An object
/// with no feasible grasp gets one `ungraspable` line.
///
/// # Errors
/// [`Error`] for a bad mesh file (the caller writes the object's error line).
pub fn label_object(
    scenario: &Scenario,
    params: &LabelParams,
    export: Option<&MjcfExport>,
    skip: &BTreeSet<usize>,
    info: &(dyn Fn(usize, usize, f64) -> LabelInfo + Sync),
    emit: &(dyn Fn(Line) + Sync),
) -> Result<ObjectSummary, Error> {
    let t0 = Instant::now();
    let scenario = with_samples(scenario, params.samples);
    let mut timings = StageTimings::default();
    let object = crate::pipeline::prepare(&scenario, &mut timings)?;
    let selection = plan_candidates(&scenario, &object, params.candidates, &mut timings);
    let hand = &scenario.hand;
    let features: Vec<Feature> = selection
        .candidates
        .iter()
        .map(|c| feature_of(&c.grasp, &selection.axes[c.axis_plan].aligned, hand))
        .collect();
    // The first rule set's candidates first; the later rule sets' (planned when the first
    // gave fewer than the search checks) fill what they leave of the K.
    let (own, later) = crate::select::by_first_rule_set(&selection);
    let mut picks = pick::farthest_among(&features, &own, params.grasps);
    picks.extend(pick::farthest_among(
        &features,
        &later,
        params.grasps - picks.len(),
    ));
    let first: Vec<&Feature> = features.iter().take(picks.len()).collect();
    let picked: Vec<&Feature> = picks.iter().map(|&i| &features[i]).collect();
    let mut summary = ObjectSummary {
        object: scenario.name.clone(),
        candidates: selection.candidates.len(),
        picked: picks.len(),
        picked_spread: pick::mean_pairwise(&picked),
        first_spread: pick::mean_pairwise(&first),
        plan_ms: t0.elapsed().as_secs_f64() * 1000.0,
        ..ObjectSummary::default()
    };
    let n = picks.len();
    if n == 0 {
        let reason = selection
            .axes
            .first()
            .and_then(|a| a.graded.reason.clone())
            .unwrap_or_else(|| "no kinematically feasible grasp".to_string());
        let record = UngraspableRecord {
            object: scenario.name.clone(),
            ungraspable: reason,
            label: info(0, 0, 0.0),
        };
        emit(Line {
            grasp_index: None,
            order: 0,
            is_error: false,
            text: to_rounded_json(&record).unwrap_or_default(),
        });
        summary.wall_ms = t0.elapsed().as_secs_f64() * 1000.0;
        return Ok(summary);
    }
    let t1 = Instant::now();
    let todo: Vec<usize> = picks.into_iter().filter(|i| !skip.contains(i)).collect();
    let posed = pose_picks(&scenario, &object, &selection, &todo, export)?;
    summary.collider_ms = t1.elapsed().as_secs_f64() * 1000.0;
    let t2 = Instant::now();
    let (samples, held) = check_all(
        &scenario,
        &object,
        &posed,
        &|i, wall| info(i, n, wall),
        emit,
    );
    summary.check_ms = t2.elapsed().as_secs_f64() * 1000.0;
    summary.labelled = posed.len();
    summary.samples_checked = samples;
    summary.holding = held;
    summary.wall_ms = t0.elapsed().as_secs_f64() * 1000.0;
    Ok(summary)
}

/// The candidates `picks` of `selection` posed for their checks (the line as written, its pose
/// and collider), each exported as an MJCF scene when `export` takes it.
///
/// # Errors
/// [`Error::Export`] for a scene that cannot be written.
fn pose_picks(
    scenario: &Scenario,
    object: &PreparedObject,
    selection: &Selection,
    picks: &[usize],
    export: Option<&MjcfExport>,
) -> Result<Vec<Posed>, Error> {
    // Each candidate's place in its axis plan's thesis order.
    let places: Vec<Place> = selection
        .candidates
        .iter()
        .map(|c| Place {
            axis_plan: c.axis_plan,
            place: c.thesis_place,
            found: selection.axes[c.axis_plan].grasps_found,
        })
        .collect();
    let hand = &scenario.hand;
    picks
        .iter()
        .map(|&i| -> Result<Posed, Error> {
            let c = &selection.candidates[i];
            let plan = &selection.axes[c.axis_plan];
            let planned = SimHand::from_grasp(&c.grasp, hand);
            let carried = Carried {
                grasp_index: Some(i),
                rules: serde_json::to_value(c.grasp.rules).ok(),
                relaxations: serde_json::to_value(&c.grasp.relaxations).ok(),
                grade: serde_json::to_value(grade_of(
                    &c.grasp,
                    plan,
                    places[i],
                    hand,
                    scenario.planner.sf_c,
                ))
                .ok(),
            };
            let line = GraspLine::of_pose(&planned, &plan.aligned, carried);
            let pose = line.pose_in(&plan.aligned);
            let shape = object.shape(&plan.aligned, &pose, hand);
            if let Some(e) = export.filter(|e| e.takes(&scenario.name, i)) {
                let folder = e
                    .dir
                    .join(crate::files::folder_name(&scenario.name))
                    .join(i.to_string());
                crate::export::write_mjcf(
                    &folder,
                    &crate::export::ExportInput {
                        name: &scenario.name,
                        object: &plan.aligned,
                        case: object.case(scenario, &pose, &shape),
                    },
                )?;
            }
            Ok(Posed {
                index: i,
                line,
                pose,
                shape,
            })
        })
        .collect()
}

/// Checks given grasp lines (`lines`: each the text of one line, or why it could not be read)
/// on `scenario`'s object with `samples` samples each, calling `emit` with each line's record
/// (or its error line). `info(index, wall_ms)` gives a line's `label` part.
///
/// # Errors
/// [`Error`] for a bad mesh file.
pub fn check_lines(
    scenario: &Scenario,
    lines: &[Result<String, String>],
    samples: usize,
    info: &(dyn Fn(usize, f64) -> LabelInfo + Sync),
    emit: &(dyn Fn(Line) + Sync),
) -> Result<ObjectSummary, Error> {
    let numbers: Vec<usize> = (1..=lines.len()).collect();
    check_numbered_lines(scenario, lines, &numbers, samples, info, emit)
}

/// [`check_lines`] with each line's number in its file (`numbers[i]` for `lines[i]`), which an
/// error record names: the file's blank lines and the lines of other objects are not given.
///
/// # Errors
/// [`Error`] for a bad mesh file.
pub fn check_numbered_lines(
    scenario: &Scenario,
    lines: &[Result<String, String>],
    numbers: &[usize],
    samples: usize,
    info: &(dyn Fn(usize, f64) -> LabelInfo + Sync),
    emit: &(dyn Fn(Line) + Sync),
) -> Result<ObjectSummary, Error> {
    let t0 = Instant::now();
    let scenario = with_samples(scenario, samples);
    let mut timings = StageTimings::default();
    let object = crate::pipeline::prepare(&scenario, &mut timings)?;
    let hand = &scenario.hand;
    let fingers = hand.finger_list.len();
    let parsed: Vec<Result<GraspLine, String>> = lines
        .iter()
        .map(|l| l.clone().and_then(|text| GraspLine::parse(&text, fingers)))
        .collect();
    // Each axis aligned once, as the planner aligns it.
    let axes: BTreeSet<GraspAxis> = parsed.iter().flatten().map(|l| l.axis).collect();
    let aligned: Vec<(GraspAxis, AlignedObject)> = axes
        .into_iter()
        .map(|a| {
            (
                a,
                mesh::align_with_rule(object.mesh(), &object.props, a, scenario.object.frame),
            )
        })
        .collect();
    let aligned_of = |a: GraspAxis| &aligned.iter().find(|(x, _)| *x == a).expect("aligned").1;
    let mut summary = ObjectSummary {
        object: scenario.name.clone(),
        candidates: lines.len(),
        picked: lines.len(),
        plan_ms: t0.elapsed().as_secs_f64() * 1000.0,
        ..ObjectSummary::default()
    };
    let t1 = Instant::now();
    let mut posed = Vec::new();
    for (i, p) in parsed.into_iter().enumerate() {
        match p {
            Ok(line) => {
                let a = aligned_of(line.axis);
                let pose = line.pose_in(a);
                let shape = object.shape(a, &pose, hand);
                posed.push(Posed {
                    index: i,
                    line,
                    pose,
                    shape,
                });
            }
            Err(why) => emit(error_line(
                &scenario.name,
                Some(i),
                &format!("line {}: {why}", numbers.get(i).copied().unwrap_or(i + 1)),
                info(i, 0.0),
            )),
        }
    }
    summary.collider_ms = t1.elapsed().as_secs_f64() * 1000.0;
    let t2 = Instant::now();
    let (samples, held) = check_all(&scenario, &object, &posed, info, emit);
    summary.check_ms = t2.elapsed().as_secs_f64() * 1000.0;
    summary.labelled = posed.len();
    summary.samples_checked = samples;
    summary.holding = held;
    summary.wall_ms = t0.elapsed().as_secs_f64() * 1000.0;
    Ok(summary)
}
