//! The run report's types: the JSON contract of DESIGN.md section 6, as written.
//!
//! Field names are a contract that outside scripts read: add fields, never rename. A physics
//! check that has not run is reported as such (`"verdict": "not_run"` and its `reason`), never
//! with invented numbers. Outcomes are enums in Rust whose JSON names are the strings scripts
//! read (`feasible`, `hold`, `not_run`, `override_angles`, ...).

use crate::scenario::Outcome;
use crate::sim::Verdict;
use serde::Serialize;

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
    /// Every feasible grasp collected, in search order (across axes and rules): with
    /// `--candidates N` at least N, with the physics check every candidate checked, each with
    /// its verdict. Empty when the first grasp is the only one (it is `grasp`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub grasps: Vec<GraspReport>,
    /// Candidates the physics check ran on, in search order until one held.
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

/// Per-stage wall times of a run `[ms]`, summed over the axes and rule sets planned.
///
/// The fields are in alphabetical order: the JSON keeps the key order of the sorted map this
/// struct replaced.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StageTimings {
    /// Aligning the object on its principal axis.
    pub align: f64,
    /// Loading and validating the mesh.
    pub load: f64,
    /// The search for feasible grasps (with the physics checks of candidates).
    pub search: f64,
    /// Stage 1: the search domain.
    pub stage1_domain: f64,
    /// Stage 2: curvature grades.
    pub stage2_curvature: f64,
    /// Stage 2: Effective Diameter grades.
    pub stage2_diameter: f64,
    /// Stage 3: palm grades and sorting.
    pub stage3_palm: f64,
}

impl StageTimings {
    /// Adds `other`'s times to these, stage by stage.
    pub fn add(&mut self, other: &StageTimings) {
        self.align += other.align;
        self.load += other.load;
        self.search += other.search;
        self.stage1_domain += other.stage1_domain;
        self.stage2_curvature += other.stage2_curvature;
        self.stage2_diameter += other.stage2_diameter;
        self.stage3_palm += other.stage3_palm;
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
    /// The physics check on this grasp, when it ran on it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub check: Option<CandidateCheck>,
    /// This grasp's analytic quality, without its contacts (the chosen grasp's are in the
    /// report's `quality`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quality: Option<GraspQuality>,
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
    /// `hold`, `slip` or `drop`.
    pub verdict: Verdict,
    /// Worst direction's translation relative to the palm `[mm]`.
    pub translation_mm: f64,
    /// Worst direction's rotation relative to the palm `[deg]`.
    pub rotation_deg: f64,
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
    /// each finger started open, and any penetration left (`sim::scene::Start`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start: Option<crate::sim::scene::Start>,
    /// The object's collider: `convex_hull` or `convex_decomposition`, and its part count.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collider: Option<String>,
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
    pub closing: Option<crate::sim::ClosingOutcome>,
    /// Per gravity direction.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub directions: Vec<crate::sim::DirectionOutcome>,
    /// The limits the verdict was judged by (`[sim] hold_translation_mm`, `hold_rotation_deg`,
    /// `max_penetration_mm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits: Option<HoldLimits>,
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
            directions: Vec::new(),
            limits: None,
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
