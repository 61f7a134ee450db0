//! The run report's types: the JSON contract of DESIGN.md section 6, as written.
//!
//! Field names are a contract that outside scripts read: add fields, never rename. A physics
//! check that has not run is reported as such (`"verdict": "not_run"` and its `reason`), never
//! with invented numbers. Outcomes are enums in Rust whose JSON names are the strings scripts
//! read (`feasible`, `hold`, `not_run`, `override_angles`, ...).
//!
//! [`RecordView`] reads a line back: the one typed view that `batch` (counts, `--resume`,
//! `--merge`) and `summarize` read.

use super::check::{ClosingOutcome, ColliderReport, DirectionOutcome, Fidelity, Start, Verdict};
use super::robust::{Perturbation, Robust};
use crate::scenario::Outcome;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize};

pub use crate::plan::StageTimings;

/// Everything one scenario run produced.
#[derive(Debug, Clone, Serialize)]
pub struct RunReport {
    /// Scenario name.
    pub scenario: String,
    /// The object as loaded and aligned.
    pub object: ObjectReport,
    /// The kinematic plan.
    pub plan: PlanReport,
    /// The physics check.
    pub sim: SimReport,
    /// Whether the scenario's expectations were met.
    pub expect: ExpectReport,
    /// The chosen grasp's analytic quality (Ferrari–Canny epsilon and volume, with its
    /// contacts); `null` without a grasp. From the physics check's contacts when it ran on
    /// the grasp (`quality.source` = `sim`), else from the planned contacts (`planned`).
    pub quality: Option<crate::quality::Quality>,
    /// One-line warnings about the input (repairs made, an open surface, ...).
    pub warnings: Vec<String>,
    /// The MJCF scene this run wrote (`--export-mjcf`), if it wrote one: not part of the JSON.
    #[serde(skip)]
    pub mjcf_scene: Option<std::path::PathBuf>,
}

/// The `object` part of the report.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectReport {
    /// The STL path as resolved from the scenario.
    pub mesh: String,
    /// Triangles kept after validation.
    pub triangles: usize,
    /// Enclosed volume `[mm³]`.
    pub volume_mm3: f64,
    /// The principal axis (aligned +Z) in the mesh's original frame, unit.
    pub principal_axis: [f64; 3],
    /// Height along the principal axis `[mm]`.
    pub height_mm: f64,
    /// Centroid in the original frame `[mm]`.
    pub centroid_mm: [f64; 3],
    /// Object mass `[kg]` from the scenario's density or mass.
    pub mass_kg: f64,
    /// Zero-area triangles dropped on loading.
    pub degenerate_dropped: usize,
    /// Edges used by one triangle only (0 for a closed shell).
    pub boundary_edges: usize,
    /// The transform from the original to the aligned frame.
    pub to_aligned: PoseReport,
}

/// A rigid transform.
#[derive(Debug, Clone, Serialize)]
pub struct PoseReport {
    /// Translation `[mm]`.
    pub position_mm: [f64; 3],
    /// Rotation as a unit quaternion, scalar first.
    pub quaternion_wxyz: [f64; 4],
}

/// The `plan` part of the report.
#[derive(Debug, Clone, Serialize)]
pub struct PlanReport {
    /// `feasible` or `ungraspable`.
    pub status: PlanStatus,
    /// Why, when not feasible.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Effective Elevation `[lo, hi]` `[mm]` (stage 1).
    pub effective_elevation_mm: [f64; 2],
    /// Number of Indexed Elevations.
    pub indexed_elevations: usize,
    /// Elevation of index 1 and the HeightStep: index i is at `first + (i − 1) × step` `[mm]`.
    pub index_elevation_mm: IndexScale,
    /// Candidate Finger_1 indices after stage 3, best first.
    pub sorted_indices: Vec<usize>,
    /// The graspable diameter range used `[min, max]` `[mm]`.
    pub graspable_diameter_mm: [f64; 2],
    /// Where the largest graspable diameter comes from (`kinematic`).
    pub graspable_diameter_basis: DiameterBasis,
    /// The thesis's largest graspable diameter, Magnify_Factor × smallest (eq. 3.3), not used.
    pub thesis_largest_diameter_mm: f64,
    /// The Largest Span Height (3.4.4.1) `[mm]`.
    pub largest_span_mm: f64,
    /// Effective Diameter per index `[mm]` (null where a slice is missed).
    pub effective_diameter_mm: Vec<Option<f64>>,
    /// Per-index grade vectors (null where ungraspable).
    pub grades: GradesReport,
    /// Candidates (elevation × approach angle) tried by the search.
    pub candidates_tried: usize,
    /// Where the search stopped at its candidate budget (`planner.candidate_budget`, per rule
    /// set) with candidates left: each axis and rule set, with the candidates it tried of those
    /// it had. Absent when the budget stopped nothing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub search_stopped: Option<String>,
    /// How often each constraint rejected a candidate.
    pub rejections: std::collections::BTreeMap<String, usize>,
    /// The first feasible grasp (the thesis's Grasp Parameter Set).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grasp: Option<GraspReport>,
    /// Every feasible grasp collected, in search order (across axes and rules; under `[sim]
    /// order_by_closing` the closed picks first, in the order checked, each with its
    /// `closing_order`): with `--candidates N` at least N, with the physics check every
    /// candidate checked, each with its verdict. Empty when the first grasp is the only one (it
    /// is `grasp`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub grasps: Vec<GraspReport>,
    /// Candidates the physics check ran on, in the order checked until one held.
    pub candidates_checked: usize,
    /// Vertical slices (of the axis reported) with a contour that stays open after its ends
    /// were joined: an open mesh's gaps wider than the joining tolerance.
    pub open_slices: usize,
    /// Each principal axis and rule set the planner tried, in order.
    pub axes: Vec<AxisReport>,
    /// Per-stage wall times `[ms]`.
    pub timings_ms: StageTimings,
}

/// Where the largest graspable diameter comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiameterBasis {
    /// The finger kinematics: the largest circle the fingers wrap (`plan::kinematics`), not
    /// the thesis's Magnify_Factor rule (eq. 3.3), which is reported beside it.
    Kinematic,
}

impl DiameterBasis {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            DiameterBasis::Kinematic => "kinematic",
        }
    }
}

impl std::fmt::Display for DiameterBasis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// The planner's outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanStatus {
    /// A kinematically feasible grasp was found.
    Feasible,
    /// None was.
    Ungraspable,
}

impl PlanStatus {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            PlanStatus::Feasible => "feasible",
            PlanStatus::Ungraspable => "ungraspable",
        }
    }
}

impl std::fmt::Display for PlanStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// A feasible grasp.
#[derive(Debug, Clone, Serialize)]
pub struct GraspReport {
    /// Approach angle `[deg]`.
    pub approach_angle_deg: f64,
    /// Palm pitch `[deg]`, positive when the palm's top leans towards the object.
    pub palm_pitch_deg: f64,
    /// Finger_1's elevation index.
    pub elevation_index: usize,
    /// Finger_1's elevation `[mm]` (aligned frame).
    pub elevation_mm: f64,
    /// Palm pose in the mesh's original frame: the palm centre on its contact surface, and the
    /// rotation of the palm frame (x away from the object, y towards finger_1's side, z up).
    pub palm_pose: PoseReport,
    /// Palm pose in the aligned object frame.
    pub palm_pose_aligned: PoseReport,
    /// Per finger, the centre ALS's angles and all three ALS.
    pub fingers: Vec<FingerReport>,
    /// The principal axis the grasp wraps (the aligned +Z it was planned about), unit, in the
    /// mesh's original frame.
    pub axis: [f64; 3],
    /// That axis by its moment of inertia: `least` (the thesis's), `middle` or `largest`, with
    /// `-` when turned round.
    pub axis_name: String,
    /// `thesis` or `extended`.
    pub rules: crate::plan::RuleSet,
    /// The thesis rules the grasp relaxed (empty under the thesis's rules).
    pub relaxations: Vec<crate::plan::Relaxation>,
    /// How far the palm stands off the object, which the phalanges hold in front of it
    /// (issue 37: a hand with `palm.standoff_max_mm`, such as the Schunk SDH-2) `[mm]`; left out
    /// where the object rests on the palm (the thesis's model).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub palm_standoff_mm: Option<f64>,
    /// The physics check on this grasp, when it ran on it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub check: Option<CandidateCheck>,
    /// This grasp's analytic quality, without its contacts (the chosen grasp's are in the
    /// report's `quality`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quality: Option<GraspQuality>,
    /// Under `[sim] order_by_closing`, what this candidate's closing did with gravity off, for
    /// a candidate it closed: the order the search checked it in.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closing_order: Option<ClosingOrder>,
}

/// A candidate's closing with gravity off (`[sim] order_by_closing`).
#[derive(Debug, Clone, Serialize)]
pub struct ClosingOrder {
    /// The closing kept the plan (`sim.fidelity.as_planned`'s rules).
    pub as_planned: bool,
    /// How far it pushed the object `[mm]`.
    pub shift_mm: f64,
    /// Under `[sim] order_samples`, how many of its perturbed closings kept the plan.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sampled_on_plan: Option<usize>,
}

/// A candidate grasp's analytic quality in brief.
#[derive(Debug, Clone, Serialize)]
pub struct GraspQuality {
    /// `sim` or `planned` contacts.
    pub source: &'static str,
    /// L1 Ferrari–Canny epsilon (0: not force closure).
    pub epsilon: f64,
    /// L1 wrench-space volume.
    pub volume: f64,
    /// L∞ epsilon, when computed.
    pub epsilon_linf: Option<f64>,
    /// True if and only if the origin lies strictly inside the wrench space.
    pub force_closure: bool,
    /// Number of contacts.
    pub contacts: usize,
}

impl GraspQuality {
    /// The brief of `q`.
    pub fn of(q: &crate::quality::Quality) -> GraspQuality {
        GraspQuality {
            source: q.source,
            epsilon: q.epsilon,
            volume: q.volume,
            epsilon_linf: q.linf.map(|m| m.epsilon),
            force_closure: q.force_closure,
            contacts: q.contacts.len(),
        }
    }
}

/// The physics check's verdict on one candidate grasp.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateCheck {
    /// `verdict`: `hold`, `slip` or `drop`, what gravity did; `not_run` (with its `reason`)
    /// for a candidate whose closing left the plan under `[sim] closing_decides`, which was not
    /// held under gravity.
    #[serde(flatten)]
    pub verdict: SimVerdict,
    /// Whether the grasp the closing made is the one planned (issue 55).
    pub fidelity: Fidelity,
    /// Per finger, `[θ1, θ2]` where the closing left the joints `[deg]`: the grasp to command
    /// when it held but not as planned.
    pub closed_joint_angles_deg: Vec<[f64; 2]>,
    /// Worst direction's translation relative to the palm `[mm]`.
    pub translation_mm: f64,
    /// Worst direction's rotation relative to the palm `[deg]`.
    pub rotation_deg: f64,
    /// With `[sim] choose = "robust"`, which samples every candidate it checks: the samples
    /// that held, of how many, and the 95 % Wilson interval of the hold probability.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robust: Option<CandidateRobust>,
}

impl CandidateCheck {
    /// The verdict, when the candidate was held under gravity.
    pub fn ran(&self) -> Option<Verdict> {
        self.verdict.verdict()
    }
}

/// A checked candidate's hold probability under perturbation, in brief (`sim.robust` has the
/// chosen grasp's in full).
#[derive(Debug, Clone, Serialize)]
pub struct CandidateRobust {
    /// Samples that held (in every direction).
    pub held: usize,
    /// Samples checked.
    pub samples: usize,
    /// `held / samples`.
    pub hold_probability: f64,
    /// 95 % Wilson score interval of the hold probability.
    pub interval: [f64; 2],
    /// Samples that held with a closing that kept the planned grasp, over `samples`.
    pub as_planned_probability: f64,
    /// Its 95 % Wilson score interval.
    pub as_planned_interval: [f64; 2],
}

/// What the planner found about one principal axis under one rule set.
#[derive(Debug, Clone, Serialize)]
pub struct AxisReport {
    /// The axis, unit, in the mesh's original frame.
    pub axis: [f64; 3],
    /// `least`, `middle` or `largest` (moment), `-` when turned round.
    pub axis_name: String,
    /// `thesis` or `extended`.
    pub rules: crate::plan::RuleSet,
    /// True for the extended rules' last pass, with the fingertip pinch
    /// (`distal_contact_only`); absent otherwise.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub pinch: bool,
    /// True for the last pass, the palm leaning at the Pitch Range's limit on one contact
    /// (`palm_pitch_clamped`); absent otherwise.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub leaning: bool,
    /// Indexed elevations about this axis.
    pub indexed_elevations: usize,
    /// Candidate palm elevations after stage 3.
    pub sorted_indices: usize,
    /// Candidates (elevation × approach angle) tried.
    pub candidates_tried: usize,
    /// Candidates the sorted domain held (elevations × approach angles).
    pub candidates_available: usize,
    /// True when the candidate budget stopped this search with candidates left; absent
    /// otherwise.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub budget_stopped: bool,
    /// Feasible grasps found.
    pub grasps_found: usize,
    /// Why there was none, when there was none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// One finger of a grasp.
#[derive(Debug, Clone, Serialize)]
pub struct FingerReport {
    /// Finger name.
    pub name: String,
    /// Joint 1 of the centre ALS `[deg]`.
    pub theta1_deg: f64,
    /// Joint 2 of the centre ALS `[deg]`.
    pub theta2_deg: f64,
    /// `[θ1, θ2]` of the top, centre and bottom ALS `[deg]`.
    pub als: AlsReport,
    /// True if and only if the centre ALS's phalanx 2 touches with its tip.
    pub tip_contact: bool,
}

/// The three ALS of a finger.
#[derive(Debug, Clone, Serialize)]
pub struct AlsReport {
    /// Top ALS.
    pub top: [f64; 2],
    /// Centre ALS.
    pub centre: [f64; 2],
    /// Bottom ALS.
    pub bottom: [f64; 2],
}

/// Index-to-elevation scale.
#[derive(Debug, Clone, Serialize)]
pub struct IndexScale {
    /// Elevation of index 1 `[mm]`.
    pub first: f64,
    /// HeightStep `[mm]`.
    pub step: f64,
}

/// Per-index grades, index i at position i − 1; null where ungraspable.
#[derive(Debug, Clone, Serialize)]
pub struct GradesReport {
    /// Curvature pattern grades.
    pub curvature: Vec<Option<f64>>,
    /// Effective Diameter grades.
    pub diameter: Vec<Option<f64>>,
    /// Combined with the significance factors.
    pub combined: Vec<Option<f64>>,
    /// Palm grades at Finger_1's index.
    pub palm: Vec<Option<f64>>,
}

/// Whether the physics check ran: its verdict, or why it did not run.
#[derive(Debug, Clone, PartialEq)]
pub enum SimVerdict {
    /// The check did not run (`--no-sim`, no grasp to check, a pose that cannot be placed).
    NotRun {
        /// Why.
        reason: String,
    },
    /// The check ran.
    Ran(Verdict),
}

impl SimVerdict {
    /// The verdict, when the check ran.
    pub fn verdict(&self) -> Option<Verdict> {
        match self {
            SimVerdict::Ran(v) => Some(*v),
            SimVerdict::NotRun { .. } => None,
        }
    }

    /// Why the check did not run, when it did not.
    pub fn reason(&self) -> Option<&str> {
        match self {
            SimVerdict::NotRun { reason } => Some(reason),
            SimVerdict::Ran(_) => None,
        }
    }

    /// The JSON's `verdict`: `hold`, `slip`, `drop` or `not_run`.
    pub fn as_str(&self) -> &'static str {
        match self {
            SimVerdict::Ran(v) => v.as_str(),
            SimVerdict::NotRun { .. } => "not_run",
        }
    }
}

impl std::fmt::Display for SimVerdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// As the two JSON fields `verdict` and, when the check did not run, `reason`.
impl Serialize for SimVerdict {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("verdict", self.as_str())?;
        if let SimVerdict::NotRun { reason } = self {
            map.serialize_entry("reason", reason)?;
        }
        map.end()
    }
}

/// Where the grasp the physics check ran on came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GraspSource {
    /// The planner's chosen grasp.
    Planner,
    /// The scenario's `[sim] override_angles`.
    OverrideAngles,
    /// A grasp given to check from outside the planner (the library's and Python's `check`).
    Given,
}

/// The `sim` part of the report.
#[derive(Debug, Clone, Serialize)]
pub struct SimReport {
    /// `verdict` (`hold`, `slip`, `drop` or `not_run`) and, when not run, `reason`.
    #[serde(flatten)]
    pub verdict: SimVerdict,
    /// Object translation relative to the palm during the hold, worst direction `[mm]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub translation_mm: Option<f64>,
    /// Object rotation relative to the palm during the hold, worst direction `[deg]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotation_deg: Option<f64>,
    /// Simulated time over all gravity directions `[s]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simulated_s: Option<f64>,
    /// Physics steps over all gravity directions.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub steps: Option<usize>,
    /// Wall time of the check `[ms]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wall_ms: Option<f64>,
    /// Where the check started: how far the palm was backed off the object's collider, how far
    /// each finger started open, and any penetration left.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start: Option<Start>,
    /// The object's collider: `convex_hull` or `convex_decomposition`, and its part count.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collider: Option<ColliderReport>,
    /// Object mass simulated `[kg]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// `override_angles` when the grasp came from the scenario, `planner` otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grasp_source: Option<GraspSource>,
    /// Largest mass multiplier (up to 64) at which the grasp still holds (`--payload`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub payload_margin: Option<f64>,
    /// The smallest mass multiplier the payload search saw fail, within 5 % above the margin
    /// (`--payload`; absent when the grasp held at 64×). Hold and failure need not alternate
    /// once around that boundary: near it the outcome depends on the details of the contacts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub payload_fails_at: Option<f64>,
    /// What the closing did (issue 33): the object's shift and turn, each finger's planned and
    /// final joint angles, and the first touch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closing: Option<ClosingOutcome>,
    /// Whether the grasp that held is the one planned (issue 55): `as_planned` by
    /// `max_closing_shift_mm`, `min_on_plan_fraction` and `max_penetration_mm`, with the
    /// figures that decided it. The verdict is gravity's alone.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fidelity: Option<Fidelity>,
    /// Per gravity direction.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub directions: Vec<DirectionOutcome>,
    /// The limits the verdict (`translation_mm`, `rotation_deg`) and the fidelity
    /// (`penetration_mm`, `closing_shift_mm`, `on_plan_fraction`) were judged by.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits: Option<HoldLimits>,
    /// The hold probability under `[sim] samples` perturbed checks (issue 34); absent with one
    /// sample (the default: the main check only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robust: Option<Robust>,
    /// The perturbation the main check ran under (`[sim] replay_sample`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub replay: Option<Perturbation>,
}

/// The limits of a hold: how far the object may move and turn relative to the palm, and how
/// deep a finger may end the closing inside it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HoldLimits {
    /// `[mm]`.
    pub translation_mm: f64,
    /// `[deg]`.
    pub rotation_deg: f64,
    /// `[mm]`.
    pub penetration_mm: f64,
    /// How far the closing may push the object (`[sim] max_closing_shift_mm`) `[mm]`.
    pub closing_shift_mm: f64,
    /// The least share of the hand's phalanges that must end the closing on their plan
    /// (`[sim] min_on_plan_fraction`).
    pub on_plan_fraction: f64,
}

impl SimReport {
    /// The report of a check that did not run, and why.
    pub fn not_run(reason: &str) -> SimReport {
        SimReport {
            verdict: SimVerdict::NotRun {
                reason: reason.to_string(),
            },
            translation_mm: None,
            rotation_deg: None,
            simulated_s: None,
            steps: None,
            wall_ms: None,
            start: None,
            collider: None,
            mass_kg: None,
            grasp_source: None,
            payload_margin: None,
            payload_fails_at: None,
            closing: None,
            fidelity: None,
            directions: Vec::new(),
            limits: None,
            robust: None,
            replay: None,
        }
    }
}

/// The `expect` part of the report.
///
/// A scenario without `[expect]` (and a bare mesh) keeps the same shape, so scripts reading
/// `expect.met` need no change: `outcome` is `"none"`, `met` is `null`, and `details` says that
/// no expectation was given.
#[derive(Debug, Clone, Serialize)]
pub struct ExpectReport {
    /// The expected outcome, or `none` when the scenario states none.
    #[serde(serialize_with = "outcome_or_none")]
    pub outcome: Option<Outcome>,
    /// True when every judged expectation held; `null` when nothing was judged.
    pub met: Option<bool>,
    /// What was compared, or why nothing was.
    pub details: String,
}

/// `None` as `"none"`.
fn outcome_or_none<S: serde::Serializer>(o: &Option<Outcome>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(o.map_or("none", Outcome::as_str))
}

/// A line of JSON Lines output read back: a run report (`--json`, `batch`), or the
/// `{"scenario", "error"}` line of an object that could not be run, with what `batch` adds
/// under `"batch"`. Only the fields the readers (`batch`'s counts, `--resume` and `--merge`,
/// `summarize`) use.
///
/// Read as the readers read untyped JSON before: every field is optional, and a field of
/// another JSON type than expected reads as absent (so old, partial or hand-edited lines
/// still read); strings are kept as written, so that a reader can print what it read.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct RecordView {
    /// `scenario`.
    #[serde(deserialize_with = "lenient")]
    pub scenario: Option<String>,
    /// `error`, present for an object that could not be run (the key's presence marks it,
    /// whatever its value).
    #[serde(deserialize_with = "present_error")]
    pub error: Option<ErrorView>,
    /// `plan`.
    #[serde(deserialize_with = "lenient_object")]
    pub plan: PlanView,
    /// `sim`.
    #[serde(deserialize_with = "lenient_object")]
    pub sim: SimView,
    /// `expect`.
    #[serde(deserialize_with = "lenient_object")]
    pub expect: ExpectView,
    /// `batch`, on lines written by `batch`.
    #[serde(deserialize_with = "lenient_object")]
    pub batch: BatchView,
}

/// A line's `error`: the text `batch` writes, or (a line written otherwise) another JSON value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ErrorView {
    /// A string: the error in words.
    Text(String),
    /// Any other value (`null` included), as its JSON text.
    NotText(String),
}

impl ErrorView {
    /// The error in words: the string, or the other value's JSON text.
    pub fn text(&self) -> &str {
        match self {
            ErrorView::Text(s) | ErrorView::NotText(s) => s,
        }
    }

    /// The string, when the error is one.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            ErrorView::Text(s) => Some(s),
            ErrorView::NotText(_) => None,
        }
    }
}

/// The `plan` fields a reader uses.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct PlanView {
    /// `plan.status`: `feasible` or `ungraspable`.
    #[serde(deserialize_with = "lenient")]
    pub status: Option<String>,
    /// `plan.timings_ms`, the numbers among its values, in key order (`None` when it is not
    /// an object).
    #[serde(deserialize_with = "numbers_of_object")]
    pub timings_ms: Option<Vec<f64>>,
}

/// The `sim` fields a reader uses.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct SimView {
    /// `sim.verdict`: `hold`, `slip`, `drop` or `not_run`.
    #[serde(deserialize_with = "lenient")]
    pub verdict: Option<String>,
    /// `sim.translation_mm`.
    #[serde(deserialize_with = "lenient")]
    pub translation_mm: Option<f64>,
    /// `sim.rotation_deg`.
    #[serde(deserialize_with = "lenient")]
    pub rotation_deg: Option<f64>,
    /// `sim.payload_margin`.
    #[serde(deserialize_with = "lenient")]
    pub payload_margin: Option<f64>,
    /// `sim.wall_ms`.
    #[serde(deserialize_with = "lenient")]
    pub wall_ms: Option<f64>,
    /// `sim.directions` (empty when absent or not a list).
    #[serde(deserialize_with = "lenient_list")]
    pub directions: Vec<DirectionView>,
    /// `sim.robust` (all absent when the line has none).
    #[serde(deserialize_with = "lenient_object")]
    pub robust: RobustView,
}

/// The `sim.robust` fields a reader uses (issue 34).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct RobustView {
    /// `samples`.
    #[serde(deserialize_with = "lenient")]
    pub samples: Option<usize>,
    /// `hold_probability`.
    #[serde(deserialize_with = "lenient")]
    pub hold_probability: Option<f64>,
    /// `interval`, the numbers of the list (empty when it is not a list).
    #[serde(deserialize_with = "numbers_of_list")]
    pub interval: Vec<f64>,
}

impl RobustView {
    /// The interval's lower bound, when the line gives one.
    pub fn lower_bound(&self) -> Option<f64> {
        self.interval.first().copied()
    }
}

impl SimView {
    /// The verdict, when the check ran and `verdict` names one.
    pub fn ran(&self) -> Option<Verdict> {
        verdict_named(self.verdict.as_deref())
    }
}

/// One entry of `sim.directions` as a reader uses it.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct DirectionView {
    /// `gravity`, the numbers of the list (empty when it is not a list).
    #[serde(deserialize_with = "numbers_of_list")]
    pub gravity: Vec<f64>,
    /// `verdict`.
    #[serde(deserialize_with = "lenient")]
    pub verdict: Option<String>,
}

impl DirectionView {
    /// The verdict under this direction, when `verdict` names one.
    pub fn ran(&self) -> Option<Verdict> {
        verdict_named(self.verdict.as_deref())
    }
}

/// The `expect` fields a reader uses.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct ExpectView {
    /// `expect.outcome`.
    #[serde(deserialize_with = "lenient")]
    pub outcome: Option<String>,
    /// `expect.met` (`None` for null: nothing judged).
    #[serde(deserialize_with = "lenient")]
    pub met: Option<bool>,
}

/// What `batch` adds to each line, as read back.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct BatchView {
    /// `batch.input`.
    #[serde(deserialize_with = "lenient")]
    pub input: Option<String>,
    /// `batch.input_hash`.
    #[serde(deserialize_with = "lenient")]
    pub input_hash: Option<String>,
    /// `batch.wall_ms`.
    #[serde(deserialize_with = "lenient")]
    pub wall_ms: Option<f64>,
}

impl RecordView {
    /// The view of a parsed JSON value (all absent when it is not an object).
    pub fn of(value: &serde_json::Value) -> RecordView {
        object_or_default(value.clone())
    }

    /// Returns true if and only if the plan found a grasp (`plan.status` is `feasible`).
    pub fn is_feasible(&self) -> bool {
        self.plan.status.as_deref() == Some(PlanStatus::Feasible.as_str())
    }
}

/// The verdict `name` names, if any.
fn verdict_named(name: Option<&str>) -> Option<Verdict> {
    name.and_then(Verdict::named)
}

/// `T` from `v` when `v` is an object, else `T`'s default (every field absent).
fn object_or_default<T: DeserializeOwned + Default>(v: serde_json::Value) -> T {
    if v.is_object() {
        serde_json::from_value(v).unwrap_or_default()
    } else {
        T::default()
    }
}

/// A value of type `T`, or `None` for a value of another type.
fn lenient<'de, D: Deserializer<'de>, T: DeserializeOwned>(d: D) -> Result<Option<T>, D::Error> {
    Ok(serde_json::from_value(serde_json::Value::deserialize(d)?).ok())
}

/// A nested object, or its default (every field absent) for a value that is not one.
fn lenient_object<'de, D: Deserializer<'de>, T: DeserializeOwned + Default>(
    d: D,
) -> Result<T, D::Error> {
    Ok(object_or_default(serde_json::Value::deserialize(d)?))
}

/// A list of objects, each that is not an object read as the default (every field absent);
/// empty for a value that is not a list.
fn lenient_list<'de, D: Deserializer<'de>, T: DeserializeOwned + Default>(
    d: D,
) -> Result<Vec<T>, D::Error> {
    Ok(match serde_json::Value::deserialize(d)? {
        serde_json::Value::Array(items) => items.into_iter().map(object_or_default).collect(),
        _ => Vec::new(),
    })
}

/// The numbers of a list, others left out; empty for a value that is not a list.
fn numbers_of_list<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    Ok(match serde_json::Value::deserialize(d)? {
        serde_json::Value::Array(items) => items.iter().filter_map(|v| v.as_f64()).collect(),
        _ => Vec::new(),
    })
}

/// The numbers among an object's values, in key order, others left out; `None` for a value
/// that is not an object.
fn numbers_of_object<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<f64>>, D::Error> {
    Ok(match serde_json::Value::deserialize(d)? {
        serde_json::Value::Object(m) => Some(m.values().filter_map(|v| v.as_f64()).collect()),
        _ => None,
    })
}

/// A present `error`, whatever its value.
fn present_error<'de, D: Deserializer<'de>>(d: D) -> Result<Option<ErrorView>, D::Error> {
    Ok(Some(match serde_json::Value::deserialize(d)? {
        serde_json::Value::String(s) => ErrorView::Text(s),
        other => ErrorView::NotText(other.to_string()),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(line: &str) -> RecordView {
        RecordView::of(&serde_json::from_str(line).unwrap())
    }

    #[test]
    fn a_record_reads_back_as_the_untyped_readers_read_it() {
        let v = view(
            r#"{"scenario":"a","plan":{"status":"feasible","timings_ms":{"load":1.5,"x":"y","align":2}},"sim":{"verdict":"slip","translation_mm":3,"directions":[{"gravity":[0,0,-1],"verdict":"hold"},7]},"expect":{"outcome":"hold","met":false},"batch":{"input":"d/a.toml","input_hash":"sha256:0","wall_ms":12.5}}"#,
        );
        assert!(v.is_feasible() && v.error.is_none());
        assert_eq!(v.plan.timings_ms, Some(vec![2.0, 1.5]));
        assert_eq!(v.sim.ran(), Some(Verdict::Slip));
        assert_eq!(v.sim.translation_mm, Some(3.0));
        assert_eq!(v.sim.directions.len(), 2);
        assert_eq!(v.sim.directions[0].gravity, [0.0, 0.0, -1.0]);
        assert_eq!(v.sim.directions[0].ran(), Some(Verdict::Hold));
        assert_eq!(v.sim.directions[1], DirectionView::default());
        assert_eq!(v.expect.met, Some(false));
        assert_eq!(v.batch.input.as_deref(), Some("d/a.toml"));
        assert_eq!(v.batch.wall_ms, Some(12.5));
    }

    #[test]
    fn error_lines_and_odd_fields_read_as_absent_not_as_failures() {
        let e = view(r#"{"scenario":"m.stl","error":"bad mesh"}"#);
        assert_eq!(e.error, Some(ErrorView::Text("bad mesh".to_string())));
        let null = view(r#"{"scenario":"m.stl","error":null}"#);
        assert_eq!(null.error.as_ref().map(ErrorView::text), Some("null"));
        assert_eq!(null.error.as_ref().and_then(ErrorView::as_str), None);
        let odd = view(r#"{"scenario":1,"plan":"feasible","sim":{"verdict":5},"batch":[1]}"#);
        assert_eq!(odd.scenario, None);
        assert!(!odd.is_feasible());
        assert_eq!(odd.sim.verdict, None);
        assert_eq!(odd.batch, BatchView::default());
        assert_eq!(view("[1, 2]"), RecordView::default());
    }
}
