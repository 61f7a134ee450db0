//! The kinematic planner (thesis chapter 3), one file per stage.
//!
//! - [`domain`]: stage 1 (3.4.2) — vertical slices, Effective Elevation, Indexed Elevations.
//! - [`curvature`]: stage 2 (3.4.3.1) — curvature pattern grades.
//! - [`diameter`]: stage 2 (3.4.3.2) — Effective Diameter grades.
//! - [`kinematics`]: the hand's graspable diameter range (eq. 3.2 and its largest counterpart).
//! - [`palm_grade`]: significance factors (3.4.3.3) and stage 3 (3.4.4): palm grades, sorting.
//! - [`palm`]: palm positioning (3.5); [`finger`]: ALS finger positioning (3.6);
//!   [`search`]: the walk over the sorted domain (3.7).
//!
//! Units: millimetres and degrees at the boundary (parameters, reports), radians inside. The
//! object is in the aligned frame (principal axis +Z, bottom at Z = 0).

pub mod curvature;
pub mod diameter;
pub mod domain;
pub mod finger;
pub mod geom2;
pub mod kinematics;
pub mod palm;
pub mod palm_grade;
pub mod search;

pub use curvature::{CurvatureParams, SideGrade};
pub use domain::{Domain, Touch};
pub use palm_grade::{GradedDomain, Grades};

use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::scenario::PlannerParams;
use std::collections::BTreeMap;
use std::time::Instant;

/// A grade of an indexed elevation: a number (larger is better), or ungraspable.
pub type Grade = Option<f64>;

/// Runs stages 1–3 on an aligned object: the reduced, graded, sorted search domain.
///
/// `timings` receives the wall time of each stage `[ms]`.
pub fn grade_domain(
    mesh: &Mesh,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    timings: &mut BTreeMap<String, f64>,
) -> GradedDomain {
    let t = Instant::now();
    let domain = Domain::build(mesh, params, hand);
    timings.insert("stage1_domain".to_string(), ms(t));
    grade_built(domain, hand, params, friction, timings)
}

/// Stages 2–3 on an already built stage-1 domain (which depends only on the mesh, the
/// AngularStep, the HeightStep and the finger offset): what a parameter sweep repeats.
pub fn grade_built(
    domain: Domain,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    timings: &mut BTreeMap<String, f64>,
) -> GradedDomain {
    let t = Instant::now();
    let cparams = CurvatureParams::from_planner(params, hand, friction);
    let curvature = curvature::grade_elevations(&domain, &cparams);
    timings.insert("stage2_curvature".to_string(), ms(t));
    let t = Instant::now();
    let range = kinematics::graspable_range_with(hand, params.magnify_factor);
    let diameter = diameter::grade_elevations(&domain, range.used());
    timings.insert("stage2_diameter".to_string(), ms(t));
    let t = Instant::now();
    let graded = palm_grade::rank(domain, curvature, diameter, range, params, hand);
    timings.insert("stage3_palm".to_string(), ms(t));
    graded
}

/// The whole kinematic planner on an aligned object: stages 1–3, then the search for up to
/// `max_grasps` feasible grasps (thesis chapter 3).
pub fn plan(
    mesh: &Mesh,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    max_grasps: usize,
    timings: &mut BTreeMap<String, f64>,
) -> (GradedDomain, search::SearchResult) {
    let graded = grade_domain(mesh, hand, params, friction, timings);
    let t = Instant::now();
    let found = search::search(mesh, hand, &graded, params, max_grasps.max(1));
    timings.insert("search".to_string(), ms(t));
    (graded, found)
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1000.0
}
