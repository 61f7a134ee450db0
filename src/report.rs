//! The run report: the JSON contract of DESIGN.md section 6 and the human summary.
//!
//! Field names are a contract that outside scripts read: add fields, never rename. Stages that
//! have not run are reported as such (`"status": "not_run"`, `"verdict": "not_run"`), never with
//! invented numbers.

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
    /// One-line warnings about the input (repairs made, an open surface, ...).
    pub warnings: Vec<String>,
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
    /// `feasible`, `ungraspable`, or `not_run` while the planner does not run.
    pub status: String,
    /// Why, when not feasible.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Per-stage wall times `[ms]`.
    pub timings_ms: std::collections::BTreeMap<String, f64>,
}

/// The `sim` part of the report.
#[derive(Debug, Clone, Serialize)]
pub struct SimReport {
    /// `hold`, `slip`, `drop` or `not_run`.
    pub verdict: String,
    /// Why it did not run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// The `expect` part of the report.
#[derive(Debug, Clone, Serialize)]
pub struct ExpectReport {
    /// The expected outcome.
    pub outcome: String,
    /// True when every judged expectation held; `null` when nothing could be judged yet.
    pub met: Option<bool>,
    /// What was compared, or why nothing was.
    pub details: String,
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
        let plan_line = match &self.plan.reason {
            Some(r) => format!("{} ({r})", self.plan.status),
            None => self.plan.status.clone(),
        };
        let _ = writeln!(s, "  Plan        {plan_line}");
        let sim_line = match &self.sim.reason {
            Some(r) => format!("{} ({r})", self.sim.verdict),
            None => self.sim.verdict.clone(),
        };
        let _ = writeln!(s, "  Sim         {sim_line}");
        let met = match self.expect.met {
            Some(true) => "met",
            Some(false) => "NOT MET",
            None => "not judged",
        };
        let _ = writeln!(
            s,
            "  Expect      {}: {met} ({})",
            self.expect.outcome, self.expect.details
        );
        s
    }
}
