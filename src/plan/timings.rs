//! Per-stage wall times of a run `[ms]`: what the planner's stages, the mesh loading and the
//! search each took, reported in the run's JSON as `timings_ms`.
//!
//! The planner fills them in as it runs its stages, so they live with it; [`crate::report`]
//! re-exports them for the JSON contract.

use serde::Serialize;
use std::time::Instant;

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

/// Milliseconds elapsed since `t`: how every stage's time is taken.
pub fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1000.0
}
