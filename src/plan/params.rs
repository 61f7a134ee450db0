//! The planner's parameters (thesis chapter 3), as a scenario's `[planner]` table gives them,
//! and their validation against the hand. Units in the names: millimetres and degrees.

use crate::hand::Hand;
use crate::messages::keyed;
use serde::Deserialize;

/// Planner parameters (thesis chapter 3); defaults reproduce the thesis.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerParams {
    /// HeightStep between indexed elevations `[mm]`; must divide the finger gap (3.4.2).
    pub height_step_mm: f64,
    /// AngularStep between vertical slices and approach angles `[deg]`; must divide 360.
    pub angular_step_deg: f64,
    /// Curvature significance factor Sf_c; Sf_t = 1 − Sf_c (eq. 3.4).
    pub sf_c: f64,
    /// Vertical Deviation Range: slopes within ± this count as vertical `[deg]` (3.4.3.1).
    pub vertical_deviation_deg: f64,
    /// Segments counted before and after a touch point for the angular trend (3.4.3.1).
    pub curvature_segments: usize,
    /// Magnify_Factor: the thesis's largest graspable diameter is this × the smallest (eq. 3.3).
    pub magnify_factor: f64,
    /// Joint Angular Deviation for joint 1 between a finger's ALS `[deg]` (Table 3.2).
    pub joint_deviation_theta1_deg: f64,
    /// Joint Angular Deviation for joint 2 `[deg]` (Table 3.2).
    pub joint_deviation_theta2_deg: f64,
    /// Largest palm pitch tried either way when placing the palm `[deg]` (3.5.2).
    pub pitch_range_deg: f64,
    /// Try the rules beyond the thesis ([`super::RuleSet::Extended`]) when the thesis's find
    /// nothing (or, with the physics check, nothing that holds); `false`: the thesis's rules
    /// only, as the thesis plans.
    pub extended_rules: bool,
    /// Under the rules beyond the thesis, reject a grasp whose planned contacts together push
    /// the object along the grasp axis beyond the friction cone ([`super::squeeze`]): the
    /// thesis's cone, which its rules apply to each finger, applied to the net push of the
    /// grasp. Off by default: on, the first candidate's hold probability fell on two of three
    /// sets (docs/studies/2026-12-07-net-push-cone.md).
    pub net_push_cone: bool,
    /// The search's budget (beyond the thesis, issue 30): each rule set (the thesis's, the
    /// extended rules, the fingertip pinch) tries at most this many candidates over all its
    /// axes, each axis at most an equal share of what is left of it, so a run's cost is bounded
    /// whatever the object; a search stopped by it says so (`plan.search_stopped`). Counted in
    /// candidates, not seconds, so the answer does not depend on the machine. 0: no limit.
    pub candidate_budget: usize,
    /// The significance factor of [`super::order::OrderTerms::centred`] (issue 58). The five
    /// `sf_*` factors reorder each axis's candidates by [`super::order::OrderFactors::score`];
    /// all 0 (the default) is the thesis's order. Factors tuned on the real-object set did not
    /// carry over to a third set (docs/studies/2026-12-05-order-even.md).
    pub sf_centred: f64,
    /// The factor of [`super::order::OrderTerms::opposed`].
    pub sf_opposed: f64,
    /// The factor of [`super::order::OrderTerms::spread`].
    pub sf_spread: f64,
    /// The factor of [`super::order::OrderTerms::margin`].
    pub sf_margin: f64,
    /// The factor of [`super::order::OrderTerms::even`].
    pub sf_even: f64,
}

impl PlannerParams {
    /// These parameters with every order factor 0: the thesis's order, bit for bit.
    pub fn in_thesis_order(self) -> PlannerParams {
        PlannerParams {
            sf_centred: 0.0,
            sf_opposed: 0.0,
            sf_spread: 0.0,
            sf_margin: 0.0,
            sf_even: 0.0,
            ..self
        }
    }
}

/// The default [`PlannerParams::candidate_budget`]: a rule set's candidates over all axes.
pub const DEFAULT_CANDIDATE_BUDGET: usize = 1500;

/// The largest [`PlannerParams::candidate_budget`] accepted (issue 32): a million candidates per
/// rule set, hours of search, far past what any object needs (the default is 1500); a larger
/// budget is a mistyped one.
pub const MAX_CANDIDATE_BUDGET: usize = 1_000_000;

impl Default for PlannerParams {
    fn default() -> Self {
        PlannerParams {
            height_step_mm: 2.5,
            angular_step_deg: 10.0,
            sf_c: 0.6,
            vertical_deviation_deg: 12.0,
            curvature_segments: 3,
            magnify_factor: 9.0,
            joint_deviation_theta1_deg: 5.0,
            joint_deviation_theta2_deg: 5.0,
            pitch_range_deg: 20.0,
            extended_rules: true,
            net_push_cone: false,
            candidate_budget: DEFAULT_CANDIDATE_BUDGET,
            sf_centred: 0.0,
            sf_opposed: 0.0,
            sf_spread: 0.0,
            sf_margin: 0.0,
            sf_even: 0.0,
        }
    }
}

/// The most curvature segments accepted (thesis default 3): each counts segments of a slice
/// before and after a touch point.
pub const MAX_CURVATURE_SEGMENTS: usize = 1000;

/// The finest HeightStep accepted `[mm]` (thesis default 2.5): 1e-6 mm ran out of memory.
pub const MIN_HEIGHT_STEP_MM: f64 = 0.1;
/// The finest AngularStep accepted `[deg]` (thesis default 10): 1e-6° ran out of memory.
pub const MIN_ANGULAR_STEP_DEG: f64 = 1.0;

impl PlannerParams {
    /// Checks the parameters against the hand and the friction: the key and the problem of the
    /// first one out of range (a scenario reports it with its file, the tuner skips the setting).
    ///
    /// # Errors
    /// `(key, problem)`.
    pub fn validate(&self, hand: &Hand, friction: f64) -> Result<(), (&'static str, String)> {
        let p = self;
        if p.candidate_budget > MAX_CANDIDATE_BUDGET {
            return Err((
                "planner.candidate_budget",
                format!(
                    "must be at most {MAX_CANDIDATE_BUDGET} (0: no limit), got {}",
                    p.candidate_budget
                ),
            ));
        }
        p.validate_height_step(hand)?;
        let a = p.angular_step_deg;
        if a.is_finite() && a > 0.0 && a < MIN_ANGULAR_STEP_DEG {
            return Err((
                "planner.angular_step_deg",
                format!("must be at least {MIN_ANGULAR_STEP_DEG} (360 approach angles), got {a}"),
            ));
        }
        let turns = 360.0 / a;
        if !(a.is_finite() && a > 0.0 && a <= 360.0 && (turns - turns.round()).abs() < 1e-9) {
            return Err((
                "planner.angular_step_deg",
                format!("must divide 360 evenly (thesis 3.5), got {a}"),
            ));
        }
        if !(0.0..=1.0).contains(&p.sf_c) {
            return Err(("planner.sf_c", format!("must be in [0, 1], got {}", p.sf_c)));
        }
        // The friction is checked before (`object.friction`, in [0.01, 2]): a cone too narrow
        // for the deviation is the deviation's to fit, and the message says both.
        let friction_cone_deg = friction.atan().to_degrees();
        if !(p.vertical_deviation_deg >= 0.0 && p.vertical_deviation_deg < friction_cone_deg) {
            return Err((
                "planner.vertical_deviation_deg",
                format!(
                    "must be in [0, {friction_cone_deg:.1}) (below the friction cone of object.friction = {}), got {}; lower it or raise object.friction above {:.3}",
                    friction,
                    p.vertical_deviation_deg,
                    p.vertical_deviation_deg.to_radians().tan()
                ),
            ));
        }
        if !(1..=MAX_CURVATURE_SEGMENTS).contains(&p.curvature_segments) {
            return Err((
                "planner.curvature_segments",
                format!(
                    "must be in 1..={MAX_CURVATURE_SEGMENTS}, got {}",
                    p.curvature_segments
                ),
            ));
        }
        for (key, v) in keyed!("planner", p; sf_centred, sf_opposed, sf_spread, sf_margin, sf_even,)
        {
            let m = super::order::MAX_FACTOR;
            if !(v.is_finite() && v.abs() <= m) {
                return Err((
                    key,
                    format!("must be in [-{m}, {m}] (0: the thesis's order), got {v}"),
                ));
            }
        }
        // Each number's physical range, stated (issue 56).
        for ((key, v), (hi, unit)) in keyed!("planner", p;
            magnify_factor,
            joint_deviation_theta1_deg,
            joint_deviation_theta2_deg,
            pitch_range_deg,
        )
        .into_iter()
        .zip([(1000.0, ""), (180.0, "°"), (180.0, "°"), (90.0, "°")])
        {
            if !(v.is_finite() && (0.0..=hi).contains(&v)) {
                return Err((key, format!("must be in [0, {hi}]{unit}, got {v}")));
            }
        }
        Ok(())
    }

    /// The HeightStep's part of [`Self::validate`]: positive, not finer than
    /// [`MIN_HEIGHT_STEP_MM`], dividing the finger gap and every finger's height below Finger_1.
    fn validate_height_step(&self, hand: &Hand) -> Result<(), (&'static str, String)> {
        let step = self.height_step_mm;
        if !(step.is_finite() && step > 0.0) {
            return Err((
                "planner.height_step_mm",
                format!("must be positive, got {step}"),
            ));
        }
        // The work the steps imply: elevations x approach angles grow as their inverse product.
        if step < MIN_HEIGHT_STEP_MM {
            return Err((
                "planner.height_step_mm",
                format!("must be at least {MIN_HEIGHT_STEP_MM} mm (a finer index is more work than any finger can use), got {step}"),
            ));
        }
        let ratio = hand.fingers.gap_mm / step;
        // A step longer than the gap divides it zero times, which is no division (issue 32:
        // 1e308 passed as dividing 20 mm, giving one elevation).
        if ratio.round() < 1.0 || (ratio - ratio.round()).abs() > 1e-9 * ratio.max(1.0) {
            return Err((
                "planner.height_step_mm",
                format!(
                    "must divide the finger gap of {} mm evenly (thesis 3.4.2), got {step}",
                    hand.fingers.gap_mm
                ),
            ));
        }
        // Every finger must sit on an indexed elevation when Finger_1 does (thesis 3.4.4.2).
        let top = hand.finger_list[0].height_mm;
        for f in &hand.finger_list[1..] {
            let k = (top - f.height_mm) / step;
            if (k - k.round()).abs() > 1e-9 * k.abs().max(1.0) {
                return Err((
                    "planner.height_step_mm",
                    format!(
                        "must divide the height difference of finger_1 and {} ({} mm), got {step}",
                        f.name,
                        top - f.height_mm
                    ),
                ));
            }
        }
        Ok(())
    }
}
