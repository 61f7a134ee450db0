//! grasp-sim: kinematic enveloping grasp planning for a three-fingered hand, after S. Salimi's
//! thesis "Kinematic Enveloping Grasp Planning Method for Robotic Dexterous Hands and
//! Three-Dimensional Objects" (McMaster University), checked in a rapier3d physics scene.
//!
//! Data flow (each stage a plain function, so tests, benches and the tuner can call one alone):
//!
//! ```text
//! scenario.toml → scenario::Scenario → mesh::load_stl → mesh::align → slice::slice → plan … → report
//! ```
//!
//! Units: the mesh, slicer and planner work in millimetres and degrees in the aligned object frame
//! (principal axis +Z, bottom at Z = 0), as the thesis does; the physics check will work in SI
//! units, converted once at its boundary.
//!
//! Math types: the planner uses nalgebra (f64). rapier3d 0.36 and parry3d 0.31 use glam types
//! (`Vec3`, `Pose3`, f32 by default); the conversion between the two will live in one small
//! module of the physics check (`sim::convert`), the only place that knows both.

#![warn(missing_docs)]

pub mod hand;
pub mod mesh;
pub mod objects;
pub mod plan;
pub mod report;
pub mod scenario;
pub mod slice;

use report::{
    ExpectReport, GradesReport, IndexScale, ObjectReport, PlanReport, PoseReport, RunReport,
    SimReport,
};
use scenario::{MassSpec, Outcome, Scenario};
use std::collections::BTreeMap;
use std::time::Instant;

/// Any error that stops a scenario from running: bad input, never a grasp outcome.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A bad scenario or hand file.
    #[error(transparent)]
    Scenario(#[from] scenario::ScenarioError),
    /// A bad mesh file.
    #[error(transparent)]
    Mesh(#[from] mesh::MeshError),
}

/// How to run a scenario.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// Skip the physics check.
    pub no_sim: bool,
}

/// Loads, validates and aligns the scenario's object, and reports what exists of the pipeline.
///
/// # Errors
/// [`Error`] for a bad mesh file.
pub fn run(scenario: &Scenario, options: &RunOptions) -> Result<RunReport, Error> {
    let mut timings = BTreeMap::new();
    let t0 = Instant::now();
    let loaded = mesh::load_stl(&scenario.object.mesh, scenario.object.units)?;
    timings.insert("load".to_string(), ms(t0));
    let t1 = Instant::now();
    let aligned = mesh::align(&loaded.mesh);
    timings.insert("align".to_string(), ms(t1));

    let volume = aligned.original.volume_mm3;
    let mass_kg = match scenario.object.mass {
        MassSpec::Mass(m) => m,
        MassSpec::Density(d) => d * volume * 1e-9,
    };
    let axis = aligned.principal_axis_original();
    let c = aligned.original.centroid;
    let q = aligned.to_aligned.rotation;
    let tr = aligned.to_aligned.translation.vector;
    let object = ObjectReport {
        mesh: scenario.object.mesh.display().to_string(),
        triangles: loaded.mesh.triangles.len(),
        volume_mm3: volume,
        principal_axis: [axis.x, axis.y, axis.z],
        height_mm: aligned.height_mm,
        centroid_mm: [c.x, c.y, c.z],
        mass_kg,
        degenerate_dropped: loaded.degenerate_dropped,
        boundary_edges: loaded.topology.boundary_edges,
        to_aligned: PoseReport {
            position_mm: [tr.x, tr.y, tr.z],
            quaternion_wxyz: [q.w, q.i, q.j, q.k],
        },
    };
    let graded = plan::grade_domain(
        &aligned.mesh,
        &scenario.hand,
        &scenario.planner,
        scenario.object.friction,
        &mut timings,
    );
    let is_ungraspable = graded.sorted_indices.is_empty();
    let (status, reason) = if is_ungraspable {
        ("ungraspable", graded.reason.clone())
    } else {
        (
            "not_run",
            Some(format!(
                "stages 1-3 left {} candidate palm elevations; palm and finger positioning \
                 (thesis 3.5-3.6) is not built yet",
                graded.sorted_indices.len()
            )),
        )
    };
    let g = &graded.grades;
    let plan = PlanReport {
        status: status.to_string(),
        reason,
        effective_elevation_mm: graded.domain.effective,
        indexed_elevations: graded.domain.elevations.len(),
        index_elevation_mm: IndexScale {
            first: graded.domain.effective[0],
            step: graded.domain.height_step_mm,
        },
        sorted_indices: graded.sorted_indices.clone(),
        graspable_diameter_mm: graded.range.used(),
        graspable_diameter_basis: "kinematic".to_string(),
        thesis_largest_diameter_mm: graded.range.max_thesis_mm,
        largest_span_mm: graded.largest_span_mm,
        effective_diameter_mm: graded
            .diameters_mm
            .iter()
            .map(|d| d.is_finite().then_some(*d))
            .collect(),
        grades: GradesReport {
            curvature: g.curvature.clone(),
            diameter: g.diameter.clone(),
            combined: g.combined.clone(),
            palm: g.palm.clone(),
        },
        timings_ms: timings,
    };
    let sim = SimReport {
        verdict: "not_run".to_string(),
        reason: Some(if options.no_sim {
            "--no-sim".to_string()
        } else {
            "the physics check is not built yet".to_string()
        }),
    };
    let expect = judge(scenario.expect.outcome, is_ungraspable);
    Ok(RunReport {
        scenario: scenario.name.clone(),
        object,
        plan,
        sim,
        expect,
        warnings: loaded
            .warnings()
            .into_iter()
            .map(|w| format!("{}: {w}", scenario.object.mesh.display()))
            .collect(),
    })
}

/// Judges what can be judged without palm and finger positioning: an `ungraspable` verdict of
/// stages 1-3 is final (positioning only removes candidates); a surviving candidate list decides
/// nothing yet.
fn judge(expected: Outcome, is_ungraspable: bool) -> ExpectReport {
    let (met, details) = match (expected, is_ungraspable) {
        (Outcome::Ungraspable, true) => {
            (Some(true), "stages 1-3 found no palm position".to_string())
        }
        (_, true) => (
            Some(false),
            "stages 1-3 found no palm position, so nothing can be grasped".to_string(),
        ),
        (_, false) => (
            None,
            "stages 1-3 left candidates; the grasp itself is judged once palm and finger \
             positioning exist"
                .to_string(),
        ),
    };
    ExpectReport {
        outcome: expected.as_str().to_string(),
        met,
        details,
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1000.0
}
