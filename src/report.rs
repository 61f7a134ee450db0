//! The run report: the JSON contract of DESIGN.md section 6 and the human summary.
//!
//! Field names are a contract that outside scripts read: add fields, never rename. A physics
//! check that has not run is reported as such (`"verdict": "not_run"` and its `reason`), never
//! with invented numbers. Outcomes are enums in Rust whose JSON names are the strings scripts
//! read (`feasible`, `hold`, `not_run`, `override_angles`, ...).

use crate::scenario::{Expect, Outcome};
use crate::sim::Verdict;
use serde::Serialize;

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
    pub graspable_diameter_basis: String,
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

impl GraspReport {
    /// Returns true if and only if `other` is the same grasp: the same axis, rules, approach,
    /// elevation, pitch and joint angles.
    pub fn is_same_grasp(&self, other: &GraspReport) -> bool {
        self.axis_name == other.axis_name
            && self.rules == other.rules
            && self.approach_angle_deg == other.approach_angle_deg
            && self.elevation_index == other.elevation_index
            && self.palm_pitch_deg == other.palm_pitch_deg
            && self
                .fingers
                .iter()
                .zip(&other.fingers)
                .all(|(a, b)| a.theta1_deg == b.theta1_deg && a.theta2_deg == b.theta2_deg)
    }

    /// The rules in words: `thesis`, or `extended: ` and the relaxations used.
    pub fn one_line_rules(&self) -> String {
        let rules = match serde_json::to_value(self.rules) {
            Ok(serde_json::Value::String(r)) => r,
            _ => String::new(),
        };
        let relaxed: Vec<String> = self
            .relaxations
            .iter()
            .filter_map(|r| match serde_json::to_value(r) {
                Ok(serde_json::Value::String(r)) => Some(r),
                _ => None,
            })
            .collect();
        if relaxed.is_empty() {
            rules
        } else {
            format!("{rules}: {}", relaxed.join(", "))
        }
    }

    /// The grasp in one line: axis and rules (with relaxations), approach, elevation, pitch,
    /// joint angles, and the physics check's verdict when it ran on this grasp.
    pub fn one_line(&self) -> String {
        let rules = self.one_line_rules();
        let thetas: Vec<String> = self
            .fingers
            .iter()
            .map(|f| format!("{:.1}/{:.1}", f.theta1_deg, f.theta2_deg))
            .collect();
        let check = match &self.check {
            Some(c) => format!(
                "; check: {} ({:.2} mm, {:.2} deg)",
                c.verdict, c.translation_mm, c.rotation_deg
            ),
            None => "; not checked".to_string(),
        };
        let quality = match &self.quality {
            Some(q) => format!("; epsilon {:.3} ({} contacts)", q.epsilon, q.source),
            None => String::new(),
        };
        format!(
            "axis {} ({rules}), approach {:.0} deg, index {} (Z {:.1} mm), pitch {} deg, theta1/theta2 {}{check}{quality}",
            self.axis_name,
            self.approach_angle_deg,
            self.elevation_index,
            self.elevation_mm,
            fmt_signed(self.palm_pitch_deg, 1),
            thetas.join(", ")
        )
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

impl ExpectReport {
    /// The report when there is no expectation: nothing judged.
    pub fn none() -> ExpectReport {
        ExpectReport {
            outcome: None,
            met: None,
            details: "no expectation given ([expect] absent): nothing judged".to_string(),
        }
    }

    /// Returns true if and only if there was an expectation to judge.
    pub fn is_given(&self) -> bool {
        self.outcome.is_some()
    }

    /// The expected outcome's name, or `none`.
    pub fn outcome_name(&self) -> &'static str {
        self.outcome.map_or("none", Outcome::as_str)
    }

    /// Judges `[expect]`: the planning part (status and reference values), then, when the
    /// physics check ran, its verdict against the expected outcome. A scenario that fixes the
    /// joint angles (`override_angles`) is judged on the verdict alone.
    pub fn judge(expect: &Expect, plan: &PlanReport, sim: &SimReport) -> ExpectReport {
        let outcome = Some(expect.outcome);
        if sim.grasp_source == Some(GraspSource::OverrideAngles) {
            let verdict = sim.verdict.verdict();
            return ExpectReport {
                outcome,
                met: Some(verdict.is_some() && verdict == expect.outcome.verdict()),
                details: format!("sim-only (override_angles): verdict {}", sim.verdict),
            };
        }
        let (met, details) = match (expect.outcome, &plan.grasp) {
            (Outcome::Ungraspable, None) => (true, "planner: ungraspable, as expected".to_string()),
            (Outcome::Ungraspable, Some(_)) => (
                false,
                "planner found a feasible grasp; expected ungraspable".to_string(),
            ),
            (_, None) => (false, format!("planner: {}; expected a grasp", plan.status)),
            (_, Some(g)) => {
                let misses = planning_misses(expect, g);
                if !misses.is_empty() {
                    let misses = misses.join("; ");
                    (false, format!("planning part not met: {misses}"))
                } else {
                    judge_check(expect.outcome, &sim.verdict)
                }
            }
        };
        ExpectReport {
            outcome,
            met: Some(met),
            details,
        }
    }
}

/// Once the planning part is met: the physics check's verdict against the expected outcome.
fn judge_check(expected: Outcome, verdict: &SimVerdict) -> (bool, String) {
    match verdict.verdict() {
        None => (
            true,
            "planning part met (feasible, reference values within tolerance); physics check \
             not run"
                .to_string(),
        ),
        Some(v) if expected.verdict() == Some(v) => {
            (true, format!("planning part met; physics check: {v}"))
        }
        Some(v) => (
            false,
            format!("physics check: {v}, expected {}", expected.as_str()),
        ),
    }
}

/// The reference values of `expect` that the grasp misses, each in words.
fn planning_misses(expect: &Expect, g: &GraspReport) -> Vec<String> {
    let mut misses = Vec::new();
    if let Some(a) = expect.approach_angle_deg {
        if (g.approach_angle_deg - a).abs() > 1e-9 {
            misses.push(format!(
                "approach {} deg (expected {a})",
                g.approach_angle_deg
            ));
        }
    }
    if let Some(p) = expect.palm_pitch_deg {
        if (g.palm_pitch_deg - p).abs() > expect.pitch_tolerance_deg {
            misses.push(format!(
                "pitch {:.1} deg (expected {p} +- {})",
                g.palm_pitch_deg, expect.pitch_tolerance_deg
            ));
        }
    }
    if let Some(i) = expect.elevation_index {
        if (g.elevation_index as i64 - i).abs() > expect.index_tolerance {
            misses.push(format!(
                "index {} (expected {i} +- {})",
                g.elevation_index, expect.index_tolerance
            ));
        }
    }
    if let Some(t) = &expect.theta_deg {
        let tol2 = expect
            .theta2_tolerance_deg
            .unwrap_or(expect.theta_tolerance_deg);
        for (f, [t1, t2]) in g.fingers.iter().zip(t) {
            for (got, want, which, tol) in [
                (f.theta1_deg, *t1, "theta1", expect.theta_tolerance_deg),
                (f.theta2_deg, *t2, "theta2", tol2),
            ] {
                if (got - want).abs() > tol {
                    misses.push(format!(
                        "{} {which} {got:.1} (expected {want} +- {tol})",
                        f.name
                    ));
                }
            }
        }
    }
    misses
}

impl RunReport {
    /// The human summary, in the thesis's "Grasp Parameter Set" style where a plan exists.
    pub fn summary(&self) -> String {
        use std::fmt::Write;
        let o = &self.object;
        let mut s = String::new();
        let _ = writeln!(s, "{}", self.scenario);
        let _ = writeln!(
            s,
            "  Object      {}: {} triangles, volume {:.1} cm^3, mass {:.3} kg, height {:.1} mm",
            o.mesh,
            o.triangles,
            o.volume_mm3 / 1000.0,
            o.mass_kg,
            o.height_mm
        );
        let a = o.principal_axis;
        let _ = writeln!(
            s,
            "  Principal axis (original frame) ({:.4}, {:.4}, {:.4})",
            a[0], a[1], a[2]
        );
        let p = &self.plan;
        // The height above is along the least axis; a grasp about another one is planned, and
        // its elevations below measured, along that one.
        if let Some(g) = p.grasp.as_ref().filter(|g| g.axis_name != "least") {
            let _ = writeln!(
                s,
                "  Grasp axis  the {} principal axis ({:.4}, {:.4}, {:.4}), original frame: the elevations below are along it",
                g.axis_name, g.axis[0], g.axis[1], g.axis[2]
            );
        }
        // Under the extended rules the range is the whole object widened so that an outer
        // finger may overhang its ends: not the thesis's Effective Elevation, so not called so.
        let range_name = match p.grasp.as_ref().map(|g| g.rules) {
            Some(crate::plan::RuleSet::Thesis) | None => "Effective elevation",
            Some(_) => "Search elevation (extended rules: outer fingers may overhang the ends)",
        };
        let [lo, hi] = p.effective_elevation_mm;
        // An object shorter than the two finger offsets has no Effective Elevation: its range
        // would print inverted.
        let range = if hi >= lo {
            format!("{lo:.1}..{hi:.1} mm")
        } else {
            "none (the object is shorter than the finger width)".to_string()
        };
        let _ = writeln!(
            s,
            "  {range_name} {range}, {} indexed elevations; graspable diameter {:.1}..{:.1} mm ({}; thesis 9x rule {:.1})",
            p.indexed_elevations,
            p.graspable_diameter_mm[0],
            p.graspable_diameter_mm[1],
            p.graspable_diameter_basis,
            p.thesis_largest_diameter_mm
        );
        let head: Vec<String> = p
            .sorted_indices
            .iter()
            .take(8)
            .map(|&i| {
                format!(
                    "{i} (Z {:.1})",
                    p.index_elevation_mm.first + (i - 1) as f64 * p.index_elevation_mm.step
                )
            })
            .collect();
        let more = p.sorted_indices.len().saturating_sub(8);
        let _ = writeln!(
            s,
            "  Sorted palm indices ({}): {}{}",
            p.sorted_indices.len(),
            if head.is_empty() {
                "none".to_string()
            } else {
                head.join(", ")
            },
            if more > 0 {
                format!(", ... {more} more")
            } else {
                String::new()
            }
        );
        let plan_line = match (&p.reason, &p.grasp) {
            (Some(r), _) => format!("{} ({r})", p.status),
            (None, Some(g)) if g.rules != crate::plan::RuleSet::Thesis => format!(
                "{} under rules beyond the thesis ({}), as the thesis's own found no grasp, or none that held",
                p.status,
                g.one_line_rules()
            ),
            (None, _) => p.status.to_string(),
        };
        let checked = if p.candidates_checked > 0 {
            format!(", {} checked", p.candidates_checked)
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "  Plan        {plan_line}; {} tried{checked}",
            crate::batch::plural(p.candidates_tried, "candidate")
        );
        if p.grasps.len() > 1 {
            let _ = writeln!(
                s,
                "  Candidates  {} collected, in search order (* the one reported below):",
                p.grasps.len()
            );
            for (k, g) in p.grasps.iter().enumerate() {
                let chosen = p.grasp.as_ref().is_some_and(|c| c.is_same_grasp(g));
                let _ = writeln!(
                    s,
                    "   {}{:>2}. {}",
                    if chosen { "*" } else { " " },
                    k + 1,
                    g.one_line()
                );
            }
        }
        if let Some(g) = &p.grasp {
            let _ = writeln!(s, "  Grasp Parameter Set:");
            let _ = writeln!(s, "    GraspCondition -> Passed");
            for f in &g.fingers {
                let _ = writeln!(
                    s,
                    "    {} -> theta1 = {:.1} deg  theta2 = {:.1} deg{}",
                    capitalise(&f.name),
                    f.theta1_deg,
                    f.theta2_deg,
                    if f.tip_contact { "  (tip contact)" } else { "" }
                );
            }
            let _ = writeln!(
                s,
                "    ApproachAngle = {:.0} deg  Palm_Pitch_Angle = {} deg",
                g.approach_angle_deg,
                fmt_signed(g.palm_pitch_deg, 1)
            );
            let _ = writeln!(
                s,
                "    Finger_1 Approach Elevation index = {}  Z = {:.1} mm",
                g.elevation_index, g.elevation_mm
            );
            let pp = &g.palm_pose;
            let _ = writeln!(
                s,
                "    Palm pose (original frame): position ({:.2}, {:.2}, {:.2}) mm, quaternion wxyz ({:.4}, {:.4}, {:.4}, {:.4})",
                pp.position_mm[0], pp.position_mm[1], pp.position_mm[2],
                pp.quaternion_wxyz[0], pp.quaternion_wxyz[1], pp.quaternion_wxyz[2], pp.quaternion_wxyz[3]
            );
        }
        let sim_line = match (&self.sim.verdict, self.sim.translation_mm) {
            (SimVerdict::NotRun { reason }, _) => format!("not run ({reason})"),
            (SimVerdict::Ran(verdict), Some(t)) => format!(
                "{verdict}: moved {:.2} mm and {:.2} deg relative to the palm {}; {} steps, {:.0} ms{}",
                t,
                self.sim.rotation_deg.unwrap_or(0.0),
                if *verdict == Verdict::Drop {
                    "by the end of the hold"
                } else {
                    "while held"
                },
                self.sim.steps.unwrap_or(0),
                self.sim.wall_ms.unwrap_or(0.0),
                match self.sim.payload_margin {
                    Some(m) if *verdict == Verdict::Hold => format!("; payload margin {m:.2}x"),
                    Some(_) => "; payload margin none (it does not hold its own weight)".to_string(),
                    None => String::new(),
                }
            ),
            (SimVerdict::Ran(verdict), None) => verdict.to_string(),
        };
        let _ = writeln!(s, "  Sim         {sim_line}");
        if let Some(c) = &self.sim.closing {
            let _ = writeln!(s, "  Closing     {}", closing_line(c));
            let set = |f: &crate::sim::FingerClosing,
                       which: fn(&crate::sim::FingerClosing) -> [f64; 2]| {
                let [a, b] = which(f);
                format!("{a:.1}/{b:.1}")
            };
            let planned: Vec<String> = c
                .fingers
                .iter()
                .map(|f| format!("{} {}", f.name, set(f, |f| f.planned_deg)))
                .collect();
            let closed: Vec<String> = c
                .fingers
                .iter()
                .map(|f| format!("{} {}", f.name, set(f, |f| f.final_deg)))
                .collect();
            let _ = writeln!(s, "    theta1/theta2 planned {} deg", planned.join(", "));
            let _ = writeln!(s, "    theta1/theta2 closed  {} deg", closed.join(", "));
        }
        if let Some(q) = &self.quality {
            let _ = writeln!(s, "  Quality     {}", quality_line(q));
        }
        let _ = writeln!(s, "  Result      {}", self.result_sentence());
        if self.expect.is_given() {
            let met = match self.expect.met {
                Some(true) => "met",
                Some(false) => "NOT MET",
                None => "not judged",
            };
            let _ = writeln!(
                s,
                "  Expect      {}: {met} ({})",
                self.expect.outcome_name(),
                self.expect.details
            );
        } else {
            let _ = writeln!(s, "  Expect      none given: nothing judged");
        }
        s
    }

    /// One plain sentence: which grasp, whether it held, and why not when it did not.
    pub fn result_sentence(&self) -> String {
        let p = &self.plan;
        let Some(g) = &p.grasp else {
            return format!(
                "no grasp found: {}",
                p.reason
                    .as_deref()
                    .unwrap_or("the planner found no feasible grasp")
            );
        };
        let grasp = format!(
            "grasp at approach {:.0} deg, Finger_1 index {} (Z {:.1} mm), palm pitch {} deg",
            g.approach_angle_deg,
            g.elevation_index,
            g.elevation_mm,
            fmt_signed(g.palm_pitch_deg, 1)
        );
        let sim = &self.sim;
        let moved = format!(
            "{:.2} mm and {:.2} deg relative to the palm",
            sim.translation_mm.unwrap_or(0.0),
            sim.rotation_deg.unwrap_or(0.0)
        );
        match &sim.verdict {
            SimVerdict::Ran(Verdict::Hold) => {
                format!("{grasp}: HELD under gravity (moved {moved})")
            }
            SimVerdict::Ran(Verdict::Slip) => match (penetrated_slip(sim), pushed_slip(sim)) {
                (None, Some(c)) => format!(
                    "{grasp}: NOT held as planned: the closing pushed the object {:.1} mm, more \
                     than max_closing_shift_mm ({} mm), before the fingers caught it, so the \
                     grasp that held is not the one planned (the object then moved {moved})",
                    c.shift_mm, c.max_shift_mm
                ),
                (Some((depth, limit)), _) => format!(
                    "{grasp}: NOT held: a finger ended the closing {depth:.2} mm inside the \
                     object, more than max_penetration_mm ({limit} mm), so the grip is not one a \
                     real hand makes (the object moved {moved})"
                ),
                (None, None) => format!(
                    "{grasp}: NOT held: the object slipped {moved}, beyond the hold limits{}, but \
                     stayed in the hand",
                    sim.limits.map_or(String::new(), |l| format!(
                        " ({} mm, {} deg)",
                        l.translation_mm, l.rotation_deg
                    ))
                ),
            },
            SimVerdict::Ran(Verdict::Drop) => {
                format!("{grasp}: NOT held: the object fell out of the hand (moved {moved})")
            }
            SimVerdict::NotRun { reason } => {
                format!("{grasp}; not checked in physics ({reason})")
            }
        }
    }
}

/// For a `slip` that moved within the hold limits in every direction: it is a slip because a
/// finger ended the closing deeper in the object than the limit. Returns the depth and the
/// limit `[mm]`.
fn penetrated_slip(sim: &SimReport) -> Option<(f64, f64)> {
    let l = sim.limits?;
    let within = sim.directions.iter().all(|d| {
        d.verdict != Verdict::Slip
            || (d.translation_mm <= l.translation_mm && d.rotation_deg <= l.rotation_deg)
    });
    let depth = sim
        .directions
        .iter()
        .map(|d| d.closing_penetration_mm)
        .fold(0.0, f64::max);
    (within && depth > l.penetration_mm).then_some((depth, l.penetration_mm))
}

/// For a `slip` that moved within the hold limits in every direction and left no finger too
/// deep: it is a slip because the closing pushed the object farther than its bound.
fn pushed_slip(sim: &SimReport) -> Option<&crate::sim::ClosingOutcome> {
    let l = sim.limits?;
    let c = sim.closing.as_ref().filter(|c| c.pushed)?;
    let within = sim.directions.iter().all(|d| {
        d.verdict != Verdict::Slip
            || (d.translation_mm <= l.translation_mm && d.rotation_deg <= l.rotation_deg)
    });
    within.then_some(c)
}

/// The summary's closing line (issue 33): how far the closing pushed and turned the object,
/// which body touched first, and the joint furthest from its plan, e.g. "the closing pushed
/// the object 23.0 mm; finger_2 stopped 27.0 deg short of its plan".
pub fn closing_line(c: &crate::sim::ClosingOutcome) -> String {
    let mut s = format!(
        "the closing pushed the object {:.1} mm and turned it {:.1} deg{}",
        c.shift_mm,
        c.turn_deg,
        if c.pushed {
            format!(
                " (more than max_closing_shift_mm, {} mm: not a hold of the planned grasp)",
                c.max_shift_mm
            )
        } else {
            String::new()
        }
    );
    if let Some((name, joint, e)) = c.worst_joint() {
        let how = if e < 0.0 { "short of" } else { "past" };
        s += &format!(
            "; {name} joint {joint} stopped {:.1} deg {how} its plan",
            e.abs()
        );
    }
    let phalanges = 2 * c.fingers.len();
    s += &format!(
        "; {} of {phalanges} phalanges end on the object within {} deg of their plan",
        c.phalanges_on_plan,
        crate::sim::protocol::WITHIN_PLAN_DEG
    );
    match &c.first_touch {
        Some(t) if t.phalanx == 0 => s += &format!("; the palm touched first, at {:.3} s", t.at_s),
        Some(t) => {
            s += &format!(
                "; {} phalanx {} touched first, at {:.3} s",
                t.body, t.phalanx, t.at_s
            )
        }
        None => s += "; nothing touched the object",
    }
    s
}

/// The summary's quality line: epsilon and volume, what they were computed from, and why
/// epsilon is 0 when it is.
fn quality_line(q: &crate::quality::Quality) -> String {
    let closure = if q.force_closure {
        "force closure".to_string()
    } else {
        format!(
            "not force closure: {}",
            q.note.as_deref().unwrap_or("the origin is not inside")
        )
    };
    let from = match q.source {
        "sim" => "at the end of closing",
        _ => "planned",
    };
    format!(
        "epsilon {:.3} ({closure}), volume {:.3e} (L1 grasp wrench space, {} cone edges, mu {}); {} {from}",
        q.epsilon,
        q.volume,
        q.cone_edges,
        q.friction,
        crate::batch::plural(q.contacts.len(), "contact")
    )
}

/// Significant digits kept in reported JSON figures: float noise from the arithmetic
/// (7.000000000000007) goes, every measured or planned figure keeps more digits than it is
/// accurate to (micrometres on a metre-sized object, 1e-10 on a unit quaternion).
pub const JSON_SIGNIFICANT_DIGITS: usize = 12;

/// Magnitudes below this are float noise around zero in the report's units (mm, deg, kg, s,
/// a unit quaternion's components): reported as 0.
pub const JSON_ZERO_BELOW: f64 = 1e-10;

/// `value` as JSON text with every fractional number rounded to [`JSON_SIGNIFICANT_DIGITS`]
/// significant digits, magnitudes below [`JSON_ZERO_BELOW`] and -0 written as 0, and integers
/// and field order left as they are. Deterministic: the same value gives the same text.
///
/// # Errors
/// When `value` cannot be serialized (never for the report types).
pub fn to_rounded_json<T: Serialize>(value: &T) -> serde_json::Result<String> {
    Ok(round_json_numbers(&serde_json::to_string(value)?))
}

/// [`to_rounded_json`] on JSON text, pretty-printed with indentation.
///
/// # Errors
/// As [`to_rounded_json`].
pub fn to_rounded_json_pretty<T: Serialize>(value: &T) -> serde_json::Result<String> {
    Ok(round_json_numbers(&serde_json::to_string_pretty(value)?))
}

/// Rewrites every number with a fraction or an exponent in JSON text, outside strings.
fn round_json_numbers(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    let mut chars = json.char_indices().peekable();
    let mut in_string = false;
    let mut escaped = false;
    while let Some((i, c)) = chars.next() {
        if in_string {
            out.push(c);
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => in_string = false,
                _ => {}
            }
            continue;
        }
        if c == '"' {
            in_string = true;
            out.push(c);
            continue;
        }
        if c == '-' || c.is_ascii_digit() {
            let mut end = i + c.len_utf8();
            while let Some(&(j, d)) = chars.peek() {
                if d.is_ascii_digit() || matches!(d, '.' | 'e' | 'E' | '+' | '-') {
                    end = j + d.len_utf8();
                    chars.next();
                } else {
                    break;
                }
            }
            let token = &json[i..end];
            let is_float = token.contains(['.', 'e', 'E']);
            match token.parse::<f64>() {
                Ok(x) if is_float => {
                    let r = round_significant(x, JSON_SIGNIFICANT_DIGITS);
                    let r = if r.abs() < JSON_ZERO_BELOW { 0.0 } else { r };
                    match serde_json::Number::from_f64(r) {
                        Some(n) => out.push_str(&n.to_string()),
                        None => out.push_str(token),
                    }
                }
                _ => out.push_str(token),
            }
            continue;
        }
        out.push(c);
    }
    out
}

/// `x` rounded to `digits` significant digits (through its decimal text, so 7.000000000000007
/// becomes exactly 7.0), with -0 as 0; non-finite values unchanged.
pub fn round_significant(x: f64, digits: usize) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return if x == 0.0 { 0.0 } else { x };
    }
    let r: f64 = format!("{:.*e}", digits.saturating_sub(1), x)
        .parse()
        .unwrap_or(x);
    r + 0.0
}

/// `v` with `digits` decimals, without the sign of a value that rounds to zero ("-0.0").
pub fn fmt_signed(v: f64, digits: usize) -> String {
    let s = format!("{v:.digits$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

fn capitalise(name: &str) -> String {
    let mut c = name.chars();
    match c.next() {
        Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::fmt_signed;

    #[test]
    fn reported_figures_lose_float_noise_only() {
        use super::{round_significant, to_rounded_json};
        assert_eq!(round_significant(7.000000000000007, 12), 7.0);
        assert_eq!(round_significant(0.30000000000000004, 12), 0.3);
        assert_eq!(round_significant(-6.225829064425771, 12), -6.22582906443);
        assert_eq!(round_significant(6842.683214567891, 12), 6842.68321457);
        assert_eq!(round_significant(-0.0, 12), 0.0);
        assert!(round_significant(-0.0, 12).is_sign_positive());
        assert_eq!(round_significant(1.5e-18, 12), 1.5e-18);
        #[derive(serde::Serialize)]
        struct T {
            z: Vec<f64>,
            a: f64,
            s: &'static str,
            n: i64,
        }
        let v = to_rounded_json(&T {
            z: vec![7.000000000000007, 3.0, 3.6063889953e-16, -0.0],
            a: -1.25e-3,
            s: "x 7.000000000000007 \" 1.0000000000001",
            n: -12,
        })
        .unwrap();
        assert_eq!(
            v,
            r#"{"z":[7.0,3.0,0.0,0.0],"a":-0.00125,"s":"x 7.000000000000007 \" 1.0000000000001","n":-12}"#
        );
    }

    #[test]
    fn a_value_that_rounds_to_zero_has_no_sign() {
        assert_eq!(fmt_signed(-0.0, 2), "0.00");
        assert_eq!(fmt_signed(-0.004, 2), "0.00");
        assert_eq!(fmt_signed(-0.006, 2), "-0.01");
        assert_eq!(fmt_signed(7.25, 1), "7.2");
        assert_eq!(fmt_signed(-6.2, 1), "-6.2");
    }
}
