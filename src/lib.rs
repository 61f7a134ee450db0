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
pub mod report;
pub mod scenario;
pub mod slice;

use report::{ExpectReport, ObjectReport, PlanReport, PoseReport, RunReport, SimReport};
use scenario::{MassSpec, Scenario};
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
    let plan = PlanReport {
        status: "not_run".to_string(),
        reason: Some("the planner stages are not built yet".to_string()),
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
    let expect = ExpectReport {
        outcome: scenario.expect.outcome.as_str().to_string(),
        met: None,
        details: "nothing to judge: no plan and no physics check yet".to_string(),
    };
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

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1000.0
}
