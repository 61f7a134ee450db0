//! The physics check's parameters (DESIGN.md section 5), as a scenario's `[sim]` table gives
//! them, and their validation. Units in the names: seconds, newton-metres, millimetres, degrees.

use crate::messages::keyed;
use serde::Deserialize;

/// Gravity directions for the hold test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GravityMode {
    /// −Z of the aligned object frame (the thesis's weight direction).
    Down,
    /// ±X, ±Y, ±Z in turn (as DexGraspNet and BODex test).
    Six,
}

/// How the physics check runs the hold test (docs/SIM.md, "Protocols").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Protocol {
    /// Close the hand once, branch a copy of the closed scene per gravity direction and payload
    /// multiplier, end each direction as soon as its verdict can no longer change, and run the
    /// directions in parallel.
    Fast,
    /// The reference: a fresh scene closed again for every direction and payload multiplier,
    /// each direction held for the whole `duration_s`, one after another.
    Full,
}

/// The default of `[sim] max_closing_shift_mm` `[mm]` (docs/SIM.md, "What the closing does").
pub const DEFAULT_MAX_CLOSING_SHIFT_MM: f64 = 5.0;

/// Physics check parameters (DESIGN.md section 5); used by the physics check.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimParams {
    /// Gravity direction(s).
    pub gravity: GravityMode,
    /// `fast` (default) or `full`, the reference protocol the fast one is compared with.
    pub protocol: Protocol,
    /// `fast` protocol: the window over which the object's motion relative to the palm is
    /// measured before a direction can be decided `hold` or `slip` at rest, and the least hold
    /// time `[s]`.
    pub rest_window_s: f64,
    /// `fast` protocol: the fastest motion of that window is projected to the end of the hold
    /// at this many times its speed.
    pub rest_safety: f64,
    /// `fast` protocol: a `hold` is decided early only if the object stays within this
    /// fraction of `hold_translation_mm` and `hold_rotation_deg`, the projected motion included;
    /// a `slip` only if it stays beyond one of them divided by this.
    pub rest_margin: f64,
    /// Hold time per gravity direction `[s]`.
    pub duration_s: f64,
    /// Physics timestep `[s]`.
    pub timestep_s: f64,
    /// Joint 1's motor target closes this far past its planned angle `[deg]`.
    pub squeeze_deg: f64,
    /// Joint 2's motor target closes this far past its planned angle `[deg]`.
    pub squeeze2_deg: f64,
    /// Joint motor torque limit `[N·m]`.
    pub torque_limit_nm: f64,
    /// Torque a stalled joint 1 holds once joint 2 closes (a worm drive's lock) `[N·m]`.
    pub joint1_lock_torque_nm: f64,
    /// Largest translation relative to the palm that still counts as `hold` `[mm]`.
    pub hold_translation_mm: f64,
    /// Largest rotation relative to the palm that still counts as `hold` `[deg]`.
    pub hold_rotation_deg: f64,
    /// Time the fingers get to close before gravity is turned on `[s]`: with
    /// `close_until_stalled`, the longest they get.
    pub close_duration_s: f64,
    /// Each closing phase (joint 1, then joint 2) ends as soon as the hand and the object have
    /// stopped (`sim::STALL`), at most at half `close_duration_s`; `false`: each phase takes
    /// its half of `close_duration_s` (the check before issue 15).
    pub close_until_stalled: bool,
    /// Constraint solver iterations (substeps) per step.
    pub solver_iterations: usize,
    /// PGS sweeps per solver iteration.
    pub pgs_iterations: usize,
    /// Stabilisation (position correction) sweeps per solver iteration.
    pub stabilization_iterations: usize,
    /// Joint motor stiffness `[N·m/rad]`: torque per radian short of the target, up to the limit.
    pub motor_stiffness_nm_per_rad: f64,
    /// Joint motor damping `[N·m·s/rad]`.
    pub motor_damping_nms_per_rad: f64,
    /// Density of the phalanges `[kg/m³]` (the hand file gives no masses).
    pub finger_density_kg_m3: f64,
    /// Natural frequency of contacts `[Hz]`: their stiffness relative to the bodies' masses.
    pub contact_stiffness_hz: f64,
    /// The fingers start this much more open than planned at each joint `[deg]`.
    pub open_margin_deg: f64,
    /// Skip the planner and close the fingers to these `[θ1, θ2]` per finger `[deg]`, with the
    /// palm upright at Finger_1's `override_index` (a sim-only scenario).
    pub override_angles: Option<Vec<[f64; 2]>>,
    /// Finger_1's elevation index for `override_angles` (default: the middle of the domain).
    pub override_index: Option<usize>,
    /// A run checks the planner's candidates in search order until one holds or this many have
    /// been checked (1: only the first grasp, as the thesis would give it).
    pub max_checked: usize,
    /// Deepest a finger or the palm may be inside the object at the end of closing for the
    /// grasp to count as a hold `[mm]`: a grasp that holds only because a finger passed into
    /// the object is not a hold (issue 14). Beyond it the verdict is `slip` (the object stays
    /// in the hand, but not by a grasp a real hand could make).
    pub max_penetration_mm: f64,
    /// Farthest the closing may push the object relative to the palm for the grasp to count
    /// as a hold of the planned grasp `[mm]` (issue 33): beyond it the object was pushed across
    /// until the other fingers caught it, a different grasp from the one planned, and the
    /// verdict is `slip` (`closing_pushed`), so the candidate search moves on as for a slip.
    pub max_closing_shift_mm: f64,
    /// Each finger's motors are capped at `torque_limit_nm` times the number of fingers on the
    /// palm's less crowded side over the number on its own side, so that the two sides squeeze
    /// the object equally (issue 33: with equal torques the thesis hand's two fingers push the
    /// object across towards its one thumb until the contacts' angles balance them);
    /// `false`: every finger at `torque_limit_nm`.
    pub balanced_squeeze: bool,
    /// How joint 1 closes: `squeeze` (each finger straight to its target, the check before
    /// issue 33) or `together` (a finger that touches the object stops there until every
    /// finger has touched, or the others have stopped, then all squeeze at once).
    pub approach: Approach,
}

/// How the fingers' joint 1 close (`[sim] approach`, docs/SIM.md "What the closing does").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Approach {
    /// Every finger closes straight to its squeeze target.
    Squeeze,
    /// A finger stops where it touches until every finger has touched (or the hand has
    /// stopped), then all squeeze together.
    Together,
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            gravity: GravityMode::Down,
            protocol: Protocol::Fast,
            rest_window_s: 0.2,
            rest_safety: 2.0,
            rest_margin: 0.8,
            duration_s: 2.0,
            timestep_s: 1.0 / 960.0,
            squeeze_deg: 10.0,
            squeeze2_deg: 10.0,
            torque_limit_nm: 1.0,
            joint1_lock_torque_nm: 10.0,
            hold_translation_mm: 5.0,
            hold_rotation_deg: 5.0,
            close_duration_s: 0.5,
            close_until_stalled: true,
            solver_iterations: 8,
            pgs_iterations: 8,
            stabilization_iterations: 2,
            motor_stiffness_nm_per_rad: 20.0,
            motor_damping_nms_per_rad: 0.2,
            finger_density_kg_m3: 1000.0,
            contact_stiffness_hz: 10000.0,
            open_margin_deg: 20.0,
            override_angles: None,
            override_index: None,
            max_checked: crate::DEFAULT_MAX_CHECKED,
            max_penetration_mm: 2.0,
            max_closing_shift_mm: DEFAULT_MAX_CLOSING_SHIFT_MM,
            balanced_squeeze: true,
            approach: Approach::Squeeze,
        }
    }
}

impl SimParams {
    /// Checks every value's range, and `override_angles` against a hand of `fingers` fingers:
    /// the key and the problem of the first one out of range.
    ///
    /// # Errors
    /// `(key, problem)`.
    pub fn validate(&self, fingers: usize) -> Result<(), (&'static str, String)> {
        let s = self;
        for (key, v) in keyed!("sim", s;
            duration_s,
            timestep_s,
            torque_limit_nm,
            joint1_lock_torque_nm,
            hold_translation_mm,
            hold_rotation_deg,
            close_duration_s,
            motor_stiffness_nm_per_rad,
            finger_density_kg_m3,
            contact_stiffness_hz,
            open_margin_deg,
            rest_window_s,
            rest_safety,
            rest_margin,
            max_penetration_mm,
            max_closing_shift_mm,
        ) {
            if !(v.is_finite() && v > 0.0) {
                return Err((key, format!("must be positive, got {v}")));
            }
        }
        for (key, v) in keyed!("sim", s;
            solver_iterations,
            pgs_iterations,
            stabilization_iterations,
            max_checked,
        ) {
            if !(1..=100).contains(&v) {
                return Err((key, format!("must be in 1..=100, got {v}")));
            }
        }
        if !(s.motor_damping_nms_per_rad.is_finite() && s.motor_damping_nms_per_rad >= 0.0) {
            return Err((
                "sim.motor_damping_nms_per_rad",
                format!(
                    "must be zero or positive, got {}",
                    s.motor_damping_nms_per_rad
                ),
            ));
        }
        if s.rest_margin > 1.0 {
            return Err((
                "sim.rest_margin",
                format!(
                    "must be at most 1 (a fraction of the thresholds), got {}",
                    s.rest_margin
                ),
            ));
        }
        if s.timestep_s > 0.05 || s.timestep_s * 10.0 > s.duration_s {
            return Err((
                "sim.timestep_s",
                format!(
                    "must be at most 0.05 s and a tenth of duration_s, got {}",
                    s.timestep_s
                ),
            ));
        }
        if let Some(a) = &s.override_angles {
            if a.len() != fingers {
                return Err((
                    "sim.override_angles",
                    format!("has {} fingers, the hand has {fingers}", a.len()),
                ));
            }
            if a.iter()
                .flatten()
                .any(|v| !(v.is_finite() && *v > 0.0 && *v <= 180.0))
            {
                return Err((
                    "sim.override_angles",
                    "angles must be in (0, 180] degrees".to_string(),
                ));
            }
        }
        if s.override_index.is_some() && s.override_angles.is_none() {
            return Err((
                "sim.override_index",
                "applies only with override_angles (the planner places the palm otherwise)"
                    .to_string(),
            ));
        }
        for (key, v) in keyed!("sim", s; squeeze_deg, squeeze2_deg) {
            if !v.is_finite() || v < 0.0 {
                return Err((key, format!("must be zero or positive, got {v}")));
            }
        }
        Ok(())
    }
}
