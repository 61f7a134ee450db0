//! Tuning the planner against simulated outcomes: a grid over planner parameters, every object
//! planned and checked at every setting, settings ranked by what the physics check says.
//!
//! Score of a setting, compared in this order: hold rate (objects held / objects), then the
//! mean payload margin (0 for an object not held), then the mean translation of the held objects
//! during the hold (smaller is better). With `[sim] samples` above 1 (issue 34) the chosen grasp
//! of each object is checked under that many perturbations, and the mean hold probability
//! (0 for an object without a grasp) comes first: a setting is ranked by how reliably its
//! grasps hold, not by one deterministic sample of each.
//!
//! Work that does not depend on a swept parameter is done once: each object is loaded and
//! aligned once; its stage-1 domain (the vertical slices, which depend only on the AngularStep
//! and the HeightStep) is built once per distinct pair of those; a grasp that two settings both
//! produce is simulated once (its physics does not depend on how it was found).

pub mod command;
pub mod order;

use crate::batch::{scenario_for, Item};
use crate::mesh::AlignedObject;
use crate::plan::{self, Domain};
use crate::prepared::PreparedObject;
use crate::report::StageTimings;
use crate::scenario::{validate_planner, PlannerParams, Scenario};
use crate::sim::{self, ObjectShape, SimHand, Verdict};
use crate::Error;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;

/// A planner parameter the tuner can sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TunedParam {
    /// `sf_c`: the curvature significance factor Sf_c.
    SfC,
    /// `height_step_mm`: the HeightStep.
    HeightStepMm,
    /// `angular_step_deg`: the AngularStep.
    AngularStepDeg,
    /// `vertical_deviation_deg`: the Vertical Deviation Range.
    VerticalDeviationDeg,
    /// `joint_deviation_deg`: the Joint Angular Deviation of both joints at once.
    JointDeviationDeg,
    /// `joint_deviation_theta1_deg`: the Joint Angular Deviation of joint 1.
    JointDeviationTheta1Deg,
    /// `joint_deviation_theta2_deg`: the Joint Angular Deviation of joint 2.
    JointDeviationTheta2Deg,
    /// `pitch_range_deg`: the largest palm pitch tried either way.
    PitchRangeDeg,
}

impl TunedParam {
    /// Every parameter, in the order the help lists them.
    pub const ALL: [TunedParam; 8] = [
        TunedParam::SfC,
        TunedParam::HeightStepMm,
        TunedParam::AngularStepDeg,
        TunedParam::VerticalDeviationDeg,
        TunedParam::JointDeviationDeg,
        TunedParam::JointDeviationTheta1Deg,
        TunedParam::JointDeviationTheta2Deg,
        TunedParam::PitchRangeDeg,
    ];

    /// The name: the `[planner]` key it sets; `joint_deviation_deg` sets both
    /// `joint_deviation_theta1_deg` and `joint_deviation_theta2_deg`.
    pub fn as_str(self) -> &'static str {
        match self {
            TunedParam::SfC => "sf_c",
            TunedParam::HeightStepMm => "height_step_mm",
            TunedParam::AngularStepDeg => "angular_step_deg",
            TunedParam::VerticalDeviationDeg => "vertical_deviation_deg",
            TunedParam::JointDeviationDeg => "joint_deviation_deg",
            TunedParam::JointDeviationTheta1Deg => "joint_deviation_theta1_deg",
            TunedParam::JointDeviationTheta2Deg => "joint_deviation_theta2_deg",
            TunedParam::PitchRangeDeg => "pitch_range_deg",
        }
    }

    /// Every name, comma-separated.
    pub fn names() -> String {
        TunedParam::ALL.map(TunedParam::as_str).join(", ")
    }

    /// Sets this parameter of `p` to `v`.
    pub fn apply(self, p: &mut PlannerParams, v: f64) {
        match self {
            TunedParam::SfC => p.sf_c = v,
            TunedParam::HeightStepMm => p.height_step_mm = v,
            TunedParam::AngularStepDeg => p.angular_step_deg = v,
            TunedParam::VerticalDeviationDeg => p.vertical_deviation_deg = v,
            TunedParam::JointDeviationDeg => {
                p.joint_deviation_theta1_deg = v;
                p.joint_deviation_theta2_deg = v;
            }
            TunedParam::JointDeviationTheta1Deg => p.joint_deviation_theta1_deg = v,
            TunedParam::JointDeviationTheta2Deg => p.joint_deviation_theta2_deg = v,
            TunedParam::PitchRangeDeg => p.pitch_range_deg = v,
        }
    }
}

impl std::fmt::Display for TunedParam {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

impl std::str::FromStr for TunedParam {
    type Err = SweepError;

    fn from_str(name: &str) -> Result<Self, SweepError> {
        TunedParam::ALL
            .into_iter()
            .find(|p| p.as_str() == name)
            .ok_or_else(|| SweepError::UnknownParameter(name.to_string()))
    }
}

impl Serialize for TunedParam {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

/// One swept parameter: its name and values.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sweep {
    /// The parameter.
    pub name: TunedParam,
    /// Values, in order.
    pub values: Vec<f64>,
}

/// Why a `--param` value is not a sweep; each variant holds the value given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SweepError {
    /// Not of the form `NAME=START:END:STEP`.
    #[error("`{0}` is not NAME=START:END:STEP")]
    NotASweep(String),
    /// A name that is not a [`TunedParam`].
    #[error("unknown parameter `{0}` (one of {names})", names = TunedParam::names())]
    UnknownParameter(String),
    /// START, END or STEP is not a number.
    #[error("`{0}`: START, END and STEP must be numbers")]
    NotNumbers(String),
    /// STEP ≤ 0, END < START, or a bound not finite.
    #[error("`{0}`: need STEP > 0 and END >= START")]
    BadRange(String),
    /// More than 1000 values.
    #[error("`{sweep}`: {values} values, more than 1000")]
    TooManyValues {
        /// The value given.
        sweep: String,
        /// How many values it makes.
        values: usize,
    },
}

/// Parses `NAME=START:END:STEP`.
///
/// # Errors
/// [`SweepError`] saying what is wrong.
pub fn parse_sweep(s: &str) -> Result<Sweep, SweepError> {
    let not_a_sweep = || SweepError::NotASweep(s.to_string());
    let (name, range) = s.split_once('=').ok_or_else(not_a_sweep)?;
    let name: TunedParam = name.parse()?;
    let parts: Vec<f64> = range
        .split(':')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| SweepError::NotNumbers(s.to_string()))?;
    let [start, end, step] = parts[..] else {
        return Err(not_a_sweep());
    };
    if !(step > 0.0 && end >= start && start.is_finite() && end.is_finite()) {
        return Err(SweepError::BadRange(s.to_string()));
    }
    let n = ((end - start) / step + 1e-9).floor() as usize + 1;
    if n > 1000 {
        return Err(SweepError::TooManyValues {
            sweep: s.to_string(),
            values: n,
        });
    }
    // Rounded to 1e-9 so that 0.1 steps give 0.3, not 0.30000000000000004.
    let values = (0..n)
        .map(|i| ((start + i as f64 * step) * 1e9).round() / 1e9)
        .collect();
    Ok(Sweep { name, values })
}

impl std::str::FromStr for Sweep {
    type Err = SweepError;

    fn from_str(s: &str) -> Result<Self, SweepError> {
        parse_sweep(s)
    }
}

/// The most settings a tuning grid may have: each is a plan and a physics check per object, and
/// the grid is held in memory (three sweeps of 1000 values each would be 10⁹ settings).
pub const MAX_SETTINGS: usize = 10_000;

/// How many settings the sweeps make (their values' product, saturating).
pub fn grid_size(sweeps: &[Sweep]) -> usize {
    sweeps
        .iter()
        .fold(1usize, |n, s| n.saturating_mul(s.values.len()))
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

/// What became of an object at one setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectStatus {
    /// Planned: a feasible grasp found.
    Feasible,
    /// No feasible grasp.
    Ungraspable,
    /// The scenario fixes the joint angles (`[sim] override_angles`): checked with them, not
    /// planned.
    OverrideAngles,
    /// The setting breaks a rule for this object's hand: not run.
    Invalid,
}

/// `None` as `"not_run"`.
fn verdict_or_not_run<S: serde::Serializer>(v: &Option<Verdict>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(v.map_or("not_run", Verdict::as_str))
}

/// An object's result at one setting.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectResult {
    /// Scenario name.
    pub scenario: String,
    /// What became of the object.
    pub status: ObjectStatus,
    /// The physics check's verdict; `not_run` in JSON when it did not run (`None`).
    #[serde(serialize_with = "verdict_or_not_run")]
    pub verdict: Option<Verdict>,
    /// Translation during the hold `[mm]`.
    pub translation_mm: Option<f64>,
    /// Payload margin (held objects only).
    pub payload_margin: Option<f64>,
    /// The chosen grasp's hold probability under `[sim] samples` perturbations (absent with
    /// one sample).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hold_probability: Option<f64>,
    /// True if and only if the chosen grasp's closing kept the plan (`sim.fidelity`); absent
    /// when the check did not run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub as_planned: Option<bool>,
    /// The chosen grasp's probability of a hold as planned under the same samples (absent with
    /// one sample).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub as_planned_probability: Option<f64>,
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
    /// Objects held as planned / objects.
    pub as_planned_rate: f64,
    /// Mean payload margin over all objects (0 for an object not held).
    pub mean_payload_margin: f64,
    /// Mean translation of the held objects `[mm]` (`null` when none is held).
    pub mean_translation_mm: Option<f64>,
    /// Mean hold probability over all objects (0 for one without a probability), when any
    /// object was sampled (`[sim] samples` above 1); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_hold_probability: Option<f64>,
    /// Mean probability of a hold as planned over all objects (0 for one without), when any
    /// object was sampled; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_as_planned_probability: Option<f64>,
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
    /// Inputs that could not be loaded, left out of every setting: the file and the problem.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<(String, String)>,
}

struct Prepared {
    scenario: Scenario,
    object: PreparedObject,
}

/// A simulated grasp: the candidate search's check of it, or once it was chosen, its check as
/// reported with the payload margin of a hold.
#[derive(Clone)]
struct Simulated {
    /// The check's outcome.
    outcome: sim::SimOutcome,
    /// The payload margin, for a chosen grasp that held.
    payload_margin: Option<f64>,
    /// True if and only if checked as the chosen grasp is reported.
    reported: bool,
}

/// Simulated grasps by (axis, fingerprint).
type SimCache = HashMap<(crate::mesh::GraspAxis, Vec<u64>), Simulated>;

/// The candidate search's check of a pose, in full ([`sim::entry::search_in_full`]: every check
/// of a sweep, so that which candidate an object with no hold reports, and so what its samples
/// measure, does not depend on `slip` against `drop`), cached by `key`.
fn simulate(
    p: &Prepared,
    pose: &SimHand,
    shape: &ObjectShape,
    key: (crate::mesh::GraspAxis, Vec<u64>),
    sims: &mut SimCache,
    counters: &mut TuneCounters,
) -> Simulated {
    if let Some(o) = sims.get(&key) {
        counters.sim_reused += 1;
        return o.clone();
    }
    let case = p.object.case(&p.scenario, pose, shape);
    let out = sim::entry::search_in_full(&case);
    counters.sim_runs += 1;
    let o = Simulated {
        outcome: out,
        payload_margin: None,
        reported: false,
    };
    sims.insert(key, o.clone());
    o
}

/// `o`, the chosen grasp, checked as a run reports it ([`sim::entry::reported`]: the replayed
/// sample, the payload margin of a hold, the perturbed checks of `[sim] samples`), once per
/// grasp and kept in the cache.
fn sampled(
    p: &Prepared,
    pose: &SimHand,
    shape: &ObjectShape,
    key: (crate::mesh::GraspAxis, Vec<u64>),
    o: Simulated,
    sims: &mut SimCache,
) -> Simulated {
    if o.reported {
        return o;
    }
    let case = p.object.case(&p.scenario, pose, shape);
    let r = sim::entry::reported(&case, Some(o.outcome), true);
    let o = Simulated {
        outcome: r.outcome,
        payload_margin: r.payload.map(|(held, _)| held),
        reported: true,
    };
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
    for body in &h.planned_contacts_mm {
        k.push(body.len() as u64);
        for c in body {
            k.extend(c.iter().map(|v| v.to_bits()));
        }
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
    let mut skipped = Vec::new();
    let mut first_error = None;
    // A bad input is left out (and reported), as in a batch: the others are still tuned on.
    for item in items {
        let loaded = scenario_for(item, template).and_then(|scenario| {
            let object = PreparedObject::load(&scenario.object, &mut StageTimings::default())?;
            Ok(Prepared { scenario, object })
        });
        match loaded {
            Ok(p) => prepared.push(p),
            Err(e) => {
                skipped.push((item.path().display().to_string(), e.to_string()));
                first_error.get_or_insert(e);
            }
        }
    }
    // Nothing to tune on: the first input's error, as a run of that input alone would give.
    if prepared.is_empty() {
        if let Some(e) = first_error {
            return Err(e);
        }
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
        skipped,
    })
}

/// Orders settings best first: by the mean probability of a hold as planned, the mean hold
/// probability, the share held as planned, the share held, the payload margin, then the least
/// translation.
pub fn rank(a: &SettingResult, b: &SettingResult) -> std::cmp::Ordering {
    let ap = |s: &SettingResult| s.mean_as_planned_probability.unwrap_or(0.0);
    let p = |s: &SettingResult| s.mean_hold_probability.unwrap_or(0.0);
    ap(b)
        .total_cmp(&ap(a))
        .then(p(b).total_cmp(&p(a)))
        .then(b.as_planned_rate.total_cmp(&a.as_planned_rate))
        .then(b.hold_rate.total_cmp(&a.hold_rate))
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
    let held: Vec<&ObjectResult> = objects
        .iter()
        .filter(|o| o.verdict == Some(Verdict::Hold))
        .collect();
    let mean_translation_mm = (!held.is_empty())
        .then(|| held.iter().filter_map(|o| o.translation_mm).sum::<f64>() / held.len() as f64);
    let sampled = objects.iter().any(|o| o.hold_probability.is_some());
    let mean = |p: fn(&ObjectResult) -> Option<f64>| {
        sampled.then(|| objects.iter().filter_map(p).fold(0.0, |a, p| a + p) / n)
    };
    let mean_hold_probability = mean(|o| o.hold_probability);
    let mean_as_planned_probability = mean(|o| o.as_planned_probability);
    let as_planned = held.iter().filter(|o| o.as_planned == Some(true)).count();
    SettingResult {
        values,
        hold_rate: held.len() as f64 / n,
        as_planned_rate: as_planned as f64 / n,
        mean_hold_probability,
        mean_as_planned_probability,
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
    let mut shared = Shared::default();
    let mut results = Vec::with_capacity(settings.len());
    for values in settings {
        if !results.is_empty() {
            progress(&p.scenario.name);
        }
        let mut params = p.scenario.planner.clone();
        for (s, v) in sweeps.iter().zip(values) {
            s.name.apply(&mut params, *v);
        }
        let valid = validate_planner(&params, &p.scenario.hand, p.scenario.object.friction);
        results.push(match (valid, &p.scenario.sim.input.override_angles) {
            (Err((key, why)), _) => {
                object_result(p, ObjectStatus::Invalid, None, Some(format!("{key} {why}")))
            }
            // A scenario that fixes the joint angles (`[sim] override_angles`) is checked with
            // them, as `grasp-sim scenario.toml` does: its outcome does not depend on the planner.
            (Ok(()), Some(angles)) => run_override(p, &params, angles, &mut shared),
            (Ok(()), None) => run_planned(p, &params, candidates, &mut shared),
        });
    }
    if !results.is_empty() {
        progress(&p.scenario.name);
    }
    PerObject {
        results,
        counters: shared.counters,
    }
}

/// What an object's runs at different settings share.
#[derive(Default)]
struct Shared {
    counters: TuneCounters,
    /// Thesis-axis stage-1 domains by (AngularStep, HeightStep) bits, for `override_angles`.
    domains: HashMap<(u64, u64), Domain>,
    sims: SimCache,
    /// Stage-1 domains of the planner's selection, every axis and rule set.
    select_domains: crate::select::DomainCache,
}

fn object_result(
    p: &Prepared,
    status: ObjectStatus,
    outcome: Option<&Simulated>,
    reason: Option<String>,
) -> ObjectResult {
    ObjectResult {
        scenario: p.scenario.name.clone(),
        status,
        verdict: outcome.map(|o| o.outcome.verdict),
        translation_mm: outcome.map(|o| o.outcome.translation_mm),
        payload_margin: outcome.and_then(|o| o.payload_margin),
        hold_probability: outcome
            .and_then(|o| o.outcome.robust.as_ref().map(|r| r.hold_probability)),
        as_planned: outcome.map(|o| o.outcome.fidelity.as_planned),
        as_planned_probability: outcome
            .and_then(|o| o.outcome.robust.as_ref().map(|r| r.as_planned_probability)),
        reason,
    }
}

/// An `override_angles` scenario at one setting: the fixed angles at the pose the setting's
/// graded domain (thesis axis) gives.
fn run_override(
    p: &Prepared,
    params: &PlannerParams,
    angles: &[[f64; 2]],
    shared: &mut Shared,
) -> ObjectResult {
    let (hand, aligned) = (&p.scenario.hand, &p.object.aligned);
    let key = (
        params.angular_step_deg.to_bits(),
        params.height_step_mm.to_bits(),
    );
    let counters = &mut shared.counters;
    let domain = shared
        .domains
        .entry(key)
        .or_insert_with(|| {
            counters.domains_built += 1;
            Domain::build(&aligned.mesh, params, hand)
        })
        .clone();
    let mut t = StageTimings::default();
    let graded = plan::grade_built(domain, hand, params, p.scenario.object.friction, &mut t);
    let pose = crate::select::override_pose(
        &aligned.mesh,
        hand,
        &graded,
        p.scenario.sim.input.override_index,
        angles,
    );
    let outcome = pose.ok().map(|pose| {
        let key = (crate::mesh::GraspAxis::THESIS, fingerprint(&pose));
        let shape = p.object.shape(aligned, &pose, &p.scenario.hand);
        let o = simulate(
            p,
            &pose,
            &shape,
            key.clone(),
            &mut shared.sims,
            &mut shared.counters,
        );
        sampled(p, &pose, &shape, key, o, &mut shared.sims)
    });
    object_result(p, ObjectStatus::OverrideAngles, outcome.as_ref(), None)
}

/// A planned object at one setting, planned and chosen as a run does (every axis, the extended
/// rules when the thesis's find nothing, candidates checked until one holds, in the order the
/// closings give under `[sim] order_by_closing`). A grasp two settings share is simulated once.
fn run_planned(
    p: &Prepared,
    params: &PlannerParams,
    candidates: usize,
    shared: &mut Shared,
) -> ObjectResult {
    let cache = std::cell::RefCell::new((
        std::mem::take(&mut shared.sims),
        std::mem::take(&mut shared.counters),
    ));
    let check = |a: &AlignedObject, g: &plan::search::Grasp| -> sim::SimOutcome {
        let pose = SimHand::from_grasp(g, &p.scenario.hand);
        let shape = p.object.shape(a, &pose, &p.scenario.hand);
        let key = (a.axis, fingerprint(&pose));
        let (sims, counters) = &mut *cache.borrow_mut();
        let o = simulate(p, &pose, &shape, key, sims, counters);
        o.outcome
    };
    // `[sim] order_by_closing`, as a run orders its search.
    let close = |a: &AlignedObject, g: &plan::search::Grasp| -> crate::select::Preclosed {
        crate::pipeline::preclosed(&p.scenario, &p.object, a, g)
    };
    let sampled_closings = |a: &AlignedObject, g: &plan::search::Grasp| -> usize {
        crate::pipeline::sampled_closings_on_plan(&p.scenario, &p.object, a, g)
    };
    let mut t = StageTimings::default();
    let selection = crate::select::select(
        p.object.mesh(),
        &p.object.props,
        &crate::select::SelectParams {
            hand: &p.scenario.hand,
            planner: params,
            friction: p.scenario.object.friction,
            collect: candidates,
            max_checked: Some(p.scenario.sim.selection.max_checked.max(1)),
            check: &check,
            recheck: None,
            probe: None,
            domains: Some(&shared.select_domains),
            frame: p.scenario.object.frame,
            order_by_closing: Some((p.scenario.sim.selection.order_by_closing, &close)),
            order_samples: Some((p.scenario.sim.selection.order_samples, &sampled_closings)),
            plan_reach: 0,
            order_reach: p.scenario.sim.selection.order_reach,
        },
        &mut t,
    );
    (shared.sims, shared.counters) = cache.into_inner();
    shared.counters.domains_built = shared.domains.len() + shared.select_domains.borrow().len();
    shared.counters.plans += 1;
    let best = selection.chosen().and_then(|c| {
        let a = &selection.axes[c.axis_plan].aligned;
        let pose = SimHand::from_grasp(&c.grasp, &p.scenario.hand);
        let key = (a.axis, fingerprint(&pose));
        let o = shared.sims.get(&key).cloned()?;
        Some(sampled(
            p,
            &pose,
            &p.object.shape(a, &pose, &p.scenario.hand),
            key,
            o,
            &mut shared.sims,
        ))
    });
    let status = match selection.chosen {
        Some(_) => ObjectStatus::Feasible,
        None => ObjectStatus::Ungraspable,
    };
    object_result(p, status, best.as_ref(), None)
}

/// The results as CSV: one row per setting, a column per swept parameter.
pub fn to_csv(r: &TuneResult) -> String {
    let mut s = String::new();
    for sw in &r.sweeps {
        s.push_str(sw.name.as_str());
        s.push(',');
    }
    let sampled = r.settings.iter().any(|s| s.mean_hold_probability.is_some());
    s.push_str("hold_rate,mean_payload_margin,mean_translation_mm,held,feasible,objects,invalid");
    s.push_str(if sampled {
        ",mean_hold_probability\n"
    } else {
        "\n"
    });
    for set in &r.settings {
        for v in &set.values {
            s.push_str(&format!("{v},"));
        }
        if let Some(why) = &set.invalid {
            // Not run: no scores, only the reason (quoted, doubled quotes inside).
            s.push_str(&format!(
                ",,,,,{},\"{}\"{}\n",
                set.objects.len(),
                why.replace('"', "\"\""),
                if sampled { "," } else { "" }
            ));
            continue;
        }
        let held = set
            .objects
            .iter()
            .filter(|o| o.verdict == Some(Verdict::Hold))
            .count();
        let feasible = set
            .objects
            .iter()
            .filter(|o| o.status == ObjectStatus::Feasible)
            .count();
        s.push_str(&format!(
            "{:.6},{:.6},{},{held},{feasible},{},",
            set.hold_rate,
            set.mean_payload_margin,
            set.mean_translation_mm
                .map_or(String::new(), |t| format!("{t:.6}")),
            set.objects.len()
        ));
        if sampled {
            let p = set.mean_hold_probability.unwrap_or(0.0);
            s.push_str(&format!(",{p:.6}"));
        }
        s.push('\n');
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
        if let Some(p) = set.mean_hold_probability {
            // At the end of the line, before its newline.
            let at = s.len() - 1;
            s.insert_str(at, &format!("  (mean hold probability {p:.3})"));
        }
    }
    s
}

/// A score plot that could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot draw: {message}", path.display())]
pub struct PlotError {
    /// The SVG file.
    pub path: std::path::PathBuf,
    /// What went wrong.
    pub message: String,
}

/// Writes one SVG per swept parameter: hold rate and mean payload margin of the best setting at
/// each value of that parameter.
///
/// # Errors
/// [`PlotError`] when a plot cannot be drawn or written.
pub fn plot(r: &TuneResult, dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>, PlotError> {
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
        draw().map_err(|e| PlotError {
            path: path.clone(),
            message: e.to_string(),
        })?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tuned_parameter_parses_from_its_name_and_sets_a_planner_value() {
        for p in TunedParam::ALL {
            assert_eq!(p.as_str().parse::<TunedParam>(), Ok(p));
            let mut params = PlannerParams::default();
            p.apply(&mut params, 0.125);
            assert_ne!(params, PlannerParams::default(), "{p}");
        }
        assert_eq!(
            "colour".parse::<TunedParam>(),
            Err(SweepError::UnknownParameter("colour".to_string()))
        );
    }

    #[test]
    fn names_keep_their_padding_in_tables() {
        assert_eq!(format!("{:>6}|", TunedParam::SfC), "  sf_c|");
    }
}
