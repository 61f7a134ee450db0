//! The kinematic planner (thesis chapter 3), one file per stage.
//!
//! - [`domain`]: stage 1 (3.4.2) — vertical slices, Effective Elevation, Indexed Elevations.
//! - [`curvature`]: stage 2 (3.4.3.1) — curvature pattern grades.
//! - [`diameter`]: stage 2 (3.4.3.2) — Effective Diameter grades.
//! - [`kinematics`]: the hand's graspable diameter range (eq. 3.2 and its largest counterpart),
//!   which lives with the hand ([`crate::hand::kinematics`]: the hand file's validation needs it).
//! - [`palm_grade`]: significance factors (3.4.3.3) and stage 3 (3.4.4): palm grades, sorting.
//! - [`palm`]: palm positioning (3.5); [`finger`]: ALS finger positioning (3.6);
//!   [`search`]: the walk over the sorted domain (3.7); [`refine`]: the joint angles refined by
//!   the real contact (issue 33), which the physics check applies on its collider.
//!
//! Units: millimetres and degrees at the boundary (parameters, reports), radians inside. The
//! object is in the aligned frame (principal axis +Z, bottom at Z = 0).

pub mod contacts;
pub mod curvature;
pub mod diameter;
pub mod domain;
pub mod finger;
pub mod geom2;
pub mod order;
pub use crate::hand::kinematics;
pub mod palm;
pub mod palm_grade;
pub mod params;
pub mod refine;
pub mod search;
pub mod squeeze;
pub mod timings;

pub use curvature::{CurvatureParams, SideGrade};
pub use domain::{Domain, Touch};
pub use palm_grade::{GradedDomain, Grades};
pub use params::PlannerParams;
pub use timings::StageTimings;

use crate::hand::Hand;
use crate::mesh::Mesh;
use std::time::Instant;
use timings::ms;

/// A grade of an indexed elevation: a number (larger is better), or ungraspable.
pub type Grade = Option<f64>;

/// Which rules the planner applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RuleSet {
    /// The thesis's rules, as written.
    Thesis,
    /// The thesis's rules with the relaxations of [`Relaxation`], tried only when the thesis's
    /// rules find no grasp on any axis (or none that holds in the physics check).
    Extended,
    /// The extended rules with the fingertip pinch as well ([`Relaxation::DistalContactOnly`]),
    /// tried last: only when the extended rules find no grasp on any axis (or none that holds).
    /// A pinch holds by phalanx 2's tips alone, so a wrap is preferred wherever one exists.
    /// Reported as `extended` (its grasps list `distal_contact_only`).
    #[serde(rename = "extended")]
    Pinch,
    /// The pinch's rules with the palm leaning at the Pitch Range's limit where its second
    /// contact needs more ([`Relaxation::PalmPitchClamped`]), tried after the pinch on the same
    /// terms, on those candidates alone (the others were the pinch's): a diamond or a star has
    /// no other grasp, but where a grasp with the palm on two contacts exists it is preferred.
    /// Reported as `extended` (its grasps list `palm_pitch_clamped`).
    #[serde(rename = "extended")]
    Leaning,
}

impl RuleSet {
    /// True for the rule sets beyond the thesis.
    pub fn is_extended(self) -> bool {
        self != RuleSet::Thesis
    }

    /// The rule set whose stage-1 domain and grades this one uses (the pinch changes only
    /// how a finger is placed).
    pub fn domain_rules(self) -> RuleSet {
        match self {
            RuleSet::Pinch | RuleSet::Leaning => RuleSet::Extended,
            r => r,
        }
    }

    /// True for the rule sets whose fingers may pinch ([`Relaxation::DistalContactOnly`]).
    pub fn pinches(self) -> bool {
        matches!(self, RuleSet::Pinch | RuleSet::Leaning)
    }
}

/// A rule of the thesis relaxed under [`RuleSet::Extended`], and why it may be.
///
/// The thesis is strict so that a kinematic plan is safe without any force analysis; with the
/// physics check judging every grasp, the planner may propose more.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Relaxation {
    /// An outer finger sits beyond the Effective Elevation (or on an elevation graded
    /// ungraspable) where it still meets the object: a short object (a ball, a can lying down)
    /// is shorter than the fingers' span, yet a real hand wraps it with the outer fingers on its
    /// shoulders.
    OuterFingerBeyondElevation,
    /// A touch point the curvature rules call ungraspable (a slope beyond the Vertical Deviation
    /// Range, a sharp curve change) is graded below every category instead of rejected, while
    /// the finger still makes contact: a rounded object has no vertical wall, but friction and
    /// the enveloping fingers still hold it.
    CurvatureGraded,
    /// The palm outline would take in part of the object (a knob's grip, a handle, a rim
    /// wider than the elevation the palm was placed at): the palm is moved back along its
    /// normal until it only touches, and the fingers reach round from there.
    PalmBackedOff,
    /// The palm's second contact needs more pitch than the Pitch Range (a rounded profile
    /// curving away from the palm's first contact: an egg's shoulder, a star-shaped
    /// superellipsoid): the palm leans at the range's limit on its first contact alone, which a
    /// real palm does on any convex bulge, and the fingers close from there.
    PalmPitchClamped,
    /// An ALS of a finger meets nothing (the finger's edge is off the object) while another ALS
    /// of the finger touches: the finger closes until its first ALS touches.
    AlsOffObject,
    /// The ALS of a finger disagree beyond the Joint Angular Deviation: the finger stops where its
    /// first ALS touches (its most open angles), and the deviation is recorded, not rejected.
    JointDeviationRecorded,
    /// Phalanx 1 of an ALS meets nothing: joint 1 closes on until phalanx 2 meets the object
    /// ([`finger::place_als_distal`]): a thin object (a book, a flat box) held by the fingertips
    /// with the palm on its narrow face, where the 61 mm phalanx 1 reaches past the object and
    /// only phalanx 2 comes back to it.
    DistalContactOnly,
}

/// Runs stages 1–3 on an aligned object: the reduced, graded, sorted search domain.
///
/// `timings` receives the wall time of each stage `[ms]`.
pub fn grade_domain(
    mesh: &Mesh,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    timings: &mut StageTimings,
) -> GradedDomain {
    grade_domain_with(mesh, hand, params, friction, RuleSet::Thesis, timings)
}

/// Stages 1–3 under a rule set: the extended rules widen the Effective Elevation to the whole
/// object (for the outer fingers only) and grade curvature instead of rejecting it.
pub fn grade_domain_with(
    mesh: &Mesh,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    rules: RuleSet,
    timings: &mut StageTimings,
) -> GradedDomain {
    let t = Instant::now();
    let domain = stage1_with(mesh, hand, params, rules);
    timings.stage1_domain = ms(t);
    grade_built_with(domain, hand, params, friction, rules, timings)
}

/// Stage 1 under a rule set: the thesis's Effective Elevation, or under the extended rules the
/// whole object widened so that an outer finger may overhang its ends.
pub fn stage1_with(mesh: &Mesh, hand: &Hand, params: &PlannerParams, rules: RuleSet) -> Domain {
    Domain::build_with(mesh, params, hand, stage1_shrink(hand, rules))
}

/// [`grade_domain_with`] on the vertical slices of `other`, a stage-1 domain of the same
/// aligned mesh under another rule set (the slices depend only on the mesh, the AngularStep
/// and the hand, not on the rules' Effective Elevation): the same graded domain, without
/// cutting and bridging the slices again (issue 30).
pub fn grade_domain_reusing(
    other: &Domain,
    mesh: &Mesh,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    rules: RuleSet,
    timings: &mut StageTimings,
) -> GradedDomain {
    let t = Instant::now();
    let domain = Domain::reshrunk(other, mesh, params, stage1_shrink(hand, rules));
    timings.stage1_domain = ms(t);
    grade_built_with(domain, hand, params, friction, rules, timings)
}

/// How far stage 1 shrinks the Effective Elevation at both ends under `rules` `[mm]`.
fn stage1_shrink(hand: &Hand, rules: RuleSet) -> f64 {
    match rules {
        RuleSet::Thesis => hand.fingers.offset_mm,
        // An outer finger's centreline may lie beyond the object's end by up to the finger
        // offset less EXTENDED_MIN_OVERLAP_MM: its inner edge still overlaps the object.
        RuleSet::Extended | RuleSet::Pinch | RuleSet::Leaning => {
            EXTENDED_MIN_OVERLAP_MM - hand.fingers.offset_mm
        }
    }
}

/// Stages 2–3 on an already built stage-1 domain (which depends only on the mesh, the
/// AngularStep, the HeightStep and the finger offset): what a parameter sweep repeats.
pub fn grade_built(
    domain: Domain,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    timings: &mut StageTimings,
) -> GradedDomain {
    grade_built_with(domain, hand, params, friction, RuleSet::Thesis, timings)
}

/// [`grade_built`] under a rule set.
pub fn grade_built_with(
    domain: Domain,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    rules: RuleSet,
    timings: &mut StageTimings,
) -> GradedDomain {
    let t = Instant::now();
    let mut cparams = CurvatureParams::from_planner(params, hand, friction);
    if rules.is_extended() {
        cparams.ungraspable_grade = Some(EXTENDED_CURVATURE_FLOOR);
    }
    let (curvature, floored) = curvature::grade_elevations_marked(&domain, &cparams);
    timings.stage2_curvature = ms(t);
    let t = Instant::now();
    let range = kinematics::graspable_range_with(hand, params.magnify_factor);
    let diameter = diameter::grade_elevations(&domain, range.used());
    timings.stage2_diameter = ms(t);
    let t = Instant::now();
    let mut graded = palm_grade::rank_with(domain, curvature, diameter, range, params, hand, rules);
    graded.curvature_relaxed = floored;
    timings.stage3_palm = ms(t);
    graded
}

/// Under the extended rules, how much of an outer finger's width must still lie on the
/// object's extent along the axis `[mm]`.
pub const EXTENDED_MIN_OVERLAP_MM: f64 = 2.0;

/// The curvature grade of a touch point the thesis calls ungraspable, under the extended rules:
/// below the lowest category (Cat_8, 0.6), so such elevations come after every graded one.
pub const EXTENDED_CURVATURE_FLOOR: f64 = 0.5;

/// The whole kinematic planner on an aligned object: stages 1–3, then the search for up to
/// `max_grasps` feasible grasps (thesis chapter 3).
pub fn plan(
    mesh: &Mesh,
    hand: &Hand,
    params: &PlannerParams,
    friction: f64,
    max_grasps: usize,
    timings: &mut StageTimings,
) -> (GradedDomain, search::SearchResult) {
    let graded = grade_domain(mesh, hand, params, friction, timings);
    let t = Instant::now();
    let found = search::search(mesh, hand, &graded, params, max_grasps.max(1));
    timings.search = ms(t);
    (graded, found)
}
