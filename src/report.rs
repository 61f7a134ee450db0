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
    /// `feasible`, `ungraspable`, or `not_run` while the positioning stages are not built.
    pub status: String,
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
    /// Per-stage wall times `[ms]`.
    pub timings_ms: std::collections::BTreeMap<String, f64>,
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
        let p = &self.plan;
        let _ = writeln!(
            s,
            "  Effective elevation {:.1}..{:.1} mm, {} indexed elevations; graspable diameter {:.1}..{:.1} mm ({}; thesis 9x rule {:.1})",
            p.effective_elevation_mm[0],
            p.effective_elevation_mm[1],
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
        let plan_line = match &p.reason {
            Some(r) => format!("{} ({r})", p.status),
            None => p.status.clone(),
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
