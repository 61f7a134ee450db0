//! Scenario files (TOML): what to grasp, with which hand, planner and physics settings, and what
//! outcome to expect (DESIGN.md section 6).
//!
//! Paths in a scenario are relative to the scenario file. Every section but `[object]` is
//! optional: `[hand]` defaults to the bundled thesis hand (and `file` may name a bundled hand,
//! `"thesis"` or `"bh8"`), `[planner]` and `[sim]` to the thesis's values, and without `[expect]`
//! the run reports what it found and judges nothing. Unknown keys and wrong types are
//! errors naming the file, the line and the key. Units are in the key names: millimetres, degrees,
//! kilograms, seconds, newton-metres.

use crate::hand::{Hand, HandError};
use crate::mesh::LengthUnit;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Problems with a scenario file.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{path}: cannot read scenario: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// Bad TOML, an unknown key or a wrong type.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// One line: where, which key, what.
        message: String,
    },
    /// A value out of range, or values that contradict each other.
    #[error("{path}: `{key}` {problem}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The dotted key.
        key: String,
        /// What is wrong.
        problem: String,
    },
    /// The hand file named by the scenario is bad.
    #[error(transparent)]
    Hand(#[from] HandError),
}

/// A parsed, validated scenario with paths resolved.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The scenario file.
    pub path: PathBuf,
    /// Its name (the file stem when `name` is not given).
    pub name: String,
    /// The object.
    pub object: ObjectSpec,
    /// The hand, loaded, with the scenario's overrides applied.
    pub hand: Hand,
    /// The hand file.
    pub hand_file: PathBuf,
    /// Planner parameters.
    pub planner: PlannerParams,
    /// Physics check parameters.
    pub sim: SimParams,
    /// What the run should show; `None` when the scenario has no `[expect]` (nothing is judged).
    pub expect: Option<Expect>,
}

/// The object to grasp.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSpec {
    /// The STL file, resolved against the scenario's folder.
    pub mesh: PathBuf,
    /// The STL's length unit.
    pub units: LengthUnit,
    /// How the mass is given.
    pub mass: MassSpec,
    /// Coulomb friction coefficient between hand and object (thesis: 0.3).
    pub friction: f64,
}

/// The object's mass, from a density or given outright.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MassSpec {
    /// Uniform density `[kg/m³]`.
    Density(f64),
    /// Total mass `[kg]`.
    Mass(f64),
}

/// Planner parameters (thesis chapter 3); defaults reproduce the thesis.
#[derive(Debug, Clone, PartialEq, Deserialize)]
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
}

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
        }
    }
}

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

/// Physics check parameters (DESIGN.md section 5); used by the physics check.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimParams {
    /// Gravity direction(s).
    pub gravity: GravityMode,
    /// `fast` (default) or `full`, the reference protocol the fast one is compared with.
    pub protocol: Protocol,
    /// `fast` protocol: the window over which the object's motion relative to the palm is
    /// measured before a direction can be decided `hold` early, and the least hold time `[s]`.
    pub rest_window_s: f64,
    /// `fast` protocol: the fastest motion of that window is projected to the end of the hold
    /// at this many times its speed.
    pub rest_safety: f64,
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
    /// Time the fingers get to close before gravity is turned on `[s]`.
    pub close_duration_s: f64,
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
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            gravity: GravityMode::Down,
            protocol: Protocol::Fast,
            rest_window_s: 0.5,
            rest_safety: 2.0,
            duration_s: 2.0,
            timestep_s: 1.0 / 960.0,
            squeeze_deg: 10.0,
            squeeze2_deg: 10.0,
            torque_limit_nm: 1.0,
            joint1_lock_torque_nm: 10.0,
            hold_translation_mm: 5.0,
            hold_rotation_deg: 5.0,
            close_duration_s: 0.5,
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
        }
    }
}

/// Expected outcome of a scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// Planned, and the object stays within the hold thresholds.
    Hold,
    /// Planned, and the object moves beyond the thresholds but stays in the hand.
    Slip,
    /// Planned, and the object leaves the hand.
    Drop,
    /// The planner finds no kinematically feasible grasp.
    Ungraspable,
}

impl Outcome {
    /// The lower-case name used in TOML and JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Hold => "hold",
            Outcome::Slip => "slip",
            Outcome::Drop => "drop",
            Outcome::Ungraspable => "ungraspable",
        }
    }
}

/// What a scenario expects, with optional reference values for the planned grasp.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// Expected outcome.
    pub outcome: Outcome,
    /// Reference approach angle `[deg]` (matched exactly).
    pub approach_angle_deg: Option<f64>,
    /// Reference palm pitch `[deg]`.
    pub palm_pitch_deg: Option<f64>,
    /// Reference Finger_1 elevation index.
    pub elevation_index: Option<i64>,
    /// Reference joint angles `[θ1, θ2]` per finger, in hand order `[deg]`.
    pub theta_deg: Option<Vec<[f64; 2]>>,
    /// Tolerance on the elevation index (DESIGN.md: ±2).
    #[serde(default = "default_index_tolerance")]
    pub index_tolerance: i64,
    /// Tolerance on the palm pitch `[deg]` (DESIGN.md: ±1.5°).
    #[serde(default = "default_pitch_tolerance")]
    pub pitch_tolerance_deg: f64,
    /// Tolerance on joint angles `[deg]` (DESIGN.md: ±3°).
    #[serde(default = "default_theta_tolerance")]
    pub theta_tolerance_deg: f64,
    /// Tolerance on θ2 alone, when it must differ from `theta_tolerance_deg` `[deg]`.
    pub theta2_tolerance_deg: Option<f64>,
}

fn default_index_tolerance() -> i64 {
    2
}
fn default_pitch_tolerance() -> f64 {
    1.5
}
fn default_theta_tolerance() -> f64 {
    3.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: Option<String>,
    description: Option<String>,
    object: RawObject,
    #[serde(default)]
    hand: RawHand,
    #[serde(default)]
    planner: PlannerParams,
    #[serde(default)]
    sim: SimParams,
    expect: Option<Expect>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    mesh: PathBuf,
    #[serde(default)]
    units: LengthUnit,
    density_kg_m3: Option<f64>,
    mass_kg: Option<f64>,
    #[serde(default = "default_friction")]
    friction: f64,
}

fn default_friction() -> f64 {
    0.3
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawHand {
    /// A hand file relative to the scenario, or the name of a bundled hand; default `thesis`.
    file: Option<PathBuf>,
    #[serde(default)]
    overrides: BTreeMap<String, f64>,
}

/// Default density when neither density nor mass is given `[kg/m³]` (DexGraspNet, Get a Grip).
pub const DEFAULT_DENSITY_KG_M3: f64 = 500.0;

impl Scenario {
    /// Reads, parses and validates a scenario, and loads its hand file.
    ///
    /// # Errors
    /// [`ScenarioError`] naming the scenario (or hand) file and the problem.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        if path.is_dir() {
            return Err(ScenarioError::Io {
                path: path.to_path_buf(),
                message: "is a directory, not a scenario file".to_string(),
            });
        }
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError::Io {
            path: path.to_path_buf(),
            message: io_message(&e),
        })?;
        Scenario::parse(&text, path)
    }

    /// Parses scenario TOML; relative paths resolve against `path`'s folder.
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn parse(text: &str, path: &Path) -> Result<Scenario, ScenarioError> {
        let raw: RawScenario = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            path: path.to_path_buf(),
            message: toml_message(&e, text),
        })?;
        let _ = raw.description;
        let invalid = |key: &str, problem: String| ScenarioError::Invalid {
            path: path.to_path_buf(),
            key: key.to_string(),
            problem,
        };
        let dir = path.parent().unwrap_or(Path::new("."));
        let o = raw.object;
        let mass = match (o.density_kg_m3, o.mass_kg) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "object.mass_kg",
                    "and `object.density_kg_m3` are both given; give one".to_string(),
                ))
            }
            (Some(d), None) => MassSpec::Density(d),
            (None, Some(m)) => MassSpec::Mass(m),
            (None, None) => MassSpec::Density(DEFAULT_DENSITY_KG_M3),
        };
        match mass {
            MassSpec::Density(d) if !(d.is_finite() && d > 0.0) => {
                return Err(invalid(
                    "object.density_kg_m3",
                    format!("must be positive, got {d}"),
                ))
            }
            MassSpec::Mass(m) if !(m.is_finite() && m > 0.0) => {
                return Err(invalid(
                    "object.mass_kg",
                    format!("must be positive, got {m}"),
                ))
            }
            _ => {}
        }
        // Coulomb friction between a hand and an object: 0 is frictionless; rubber on rubber
        // rarely exceeds ~1.5, so 2 bounds any plausible value.
        if !(o.friction.is_finite() && o.friction > 0.0 && o.friction <= 2.0) {
            return Err(invalid(
                "object.friction",
                format!("must be in (0, 2], got {}", o.friction),
            ));
        }
        let overrides: Vec<(String, f64)> = raw.hand.overrides.into_iter().collect();
        let file = raw.hand.file.unwrap_or_else(|| PathBuf::from("thesis"));
        let bundled = file
            .to_str()
            .and_then(crate::hand::bundled)
            .filter(|_| !dir.join(&file).is_file());
        let (hand_file, loaded) = match bundled {
            Some((name, text)) => {
                let label = PathBuf::from(format!("<bundled hand {name}>"));
                let hand = Hand::parse(text, &label, &overrides);
                (label, hand)
            }
            None => {
                let f = dir.join(&file);
                let hand = Hand::load(&f, &overrides);
                (f, hand)
            }
        };
        let hand = loaded.map_err(|e| match e {
            // The override was written in the scenario: name the scenario.
            HandError::BadOverride {
                path: hand,
                key,
                problem,
            } => ScenarioError::Invalid {
                path: path.to_path_buf(),
                key: format!("hand.overrides.\"{key}\""),
                problem: format!("{problem} ({})", hand.display()),
            },
            other => other.into(),
        })?;

        validate_planner(&raw.planner, &hand, o.friction)
            .map_err(|(key, problem)| invalid(key, problem))?;
        let s = &raw.sim;
        for (key, v) in [
            ("sim.duration_s", s.duration_s),
            ("sim.timestep_s", s.timestep_s),
            ("sim.torque_limit_nm", s.torque_limit_nm),
            ("sim.joint1_lock_torque_nm", s.joint1_lock_torque_nm),
            ("sim.hold_translation_mm", s.hold_translation_mm),
            ("sim.hold_rotation_deg", s.hold_rotation_deg),
            ("sim.close_duration_s", s.close_duration_s),
            (
                "sim.motor_stiffness_nm_per_rad",
                s.motor_stiffness_nm_per_rad,
            ),
            ("sim.finger_density_kg_m3", s.finger_density_kg_m3),
            ("sim.contact_stiffness_hz", s.contact_stiffness_hz),
            ("sim.open_margin_deg", s.open_margin_deg),
            ("sim.rest_window_s", s.rest_window_s),
            ("sim.rest_safety", s.rest_safety),
            ("sim.max_penetration_mm", s.max_penetration_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(key, format!("must be positive, got {v}")));
            }
        }
        for (key, v) in [
            ("sim.solver_iterations", s.solver_iterations),
            ("sim.pgs_iterations", s.pgs_iterations),
            ("sim.stabilization_iterations", s.stabilization_iterations),
            ("sim.max_checked", s.max_checked),
        ] {
            if !(1..=100).contains(&v) {
                return Err(invalid(key, format!("must be in 1..=100, got {v}")));
            }
        }
        if !(s.motor_damping_nms_per_rad.is_finite() && s.motor_damping_nms_per_rad >= 0.0) {
            return Err(invalid(
                "sim.motor_damping_nms_per_rad",
                format!(
                    "must be zero or positive, got {}",
                    s.motor_damping_nms_per_rad
                ),
            ));
        }
        if s.timestep_s > 0.05 || s.timestep_s * 10.0 > s.duration_s {
            return Err(invalid(
                "sim.timestep_s",
                format!(
                    "must be at most 0.05 s and a tenth of duration_s, got {}",
                    s.timestep_s
                ),
            ));
        }
        if let Some(a) = &s.override_angles {
            if a.len() != hand.finger_list.len() {
                return Err(invalid(
                    "sim.override_angles",
                    format!(
                        "has {} fingers, the hand has {}",
                        a.len(),
                        hand.finger_list.len()
                    ),
                ));
            }
            if a.iter()
                .flatten()
                .any(|v| !(v.is_finite() && *v > 0.0 && *v <= 180.0))
            {
                return Err(invalid(
                    "sim.override_angles",
                    "angles must be in (0, 180] degrees".to_string(),
                ));
            }
        }
        for (key, v) in [
            ("sim.squeeze_deg", s.squeeze_deg),
            ("sim.squeeze2_deg", s.squeeze2_deg),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(invalid(key, format!("must be zero or positive, got {v}")));
            }
        }
        if let Some(t) = raw.expect.as_ref().and_then(|e| e.theta_deg.as_ref()) {
            if t.len() != hand.finger_list.len() {
                return Err(invalid(
                    "expect.theta_deg",
                    format!(
                        "has {} fingers, the hand has {}",
                        t.len(),
                        hand.finger_list.len()
                    ),
                ));
            }
        }
        let name = raw.name.unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
        Ok(Scenario {
            path: path.to_path_buf(),
            name,
            object: ObjectSpec {
                mesh: dir.join(o.mesh),
                units: o.units,
                mass,
                friction: o.friction,
            },
            hand,
            hand_file,
            planner: raw.planner,
            sim: raw.sim,
            expect: raw.expect,
        })
    }
}

/// Checks planner parameters against the hand and the friction: the key and the problem of the
/// first one out of range (a scenario reports it with its file, the tuner skips the setting).
///
/// # Errors
/// `(key, problem)`.
pub fn validate_planner(
    params: &PlannerParams,
    hand: &Hand,
    friction: f64,
) -> Result<(), (&'static str, String)> {
    let p = params;
    let step = p.height_step_mm;
    if !(step.is_finite() && step > 0.0) {
        return Err((
            "planner.height_step_mm",
            format!("must be positive, got {step}"),
        ));
    }
    let ratio = hand.fingers.gap_mm / step;
    if (ratio - ratio.round()).abs() > 1e-9 * ratio.max(1.0) {
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
    let a = p.angular_step_deg;
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
    let friction_cone_deg = friction.atan().to_degrees();
    if !(p.vertical_deviation_deg >= 0.0 && p.vertical_deviation_deg < friction_cone_deg) {
        return Err((
            "planner.vertical_deviation_deg",
            format!(
                "must be in [0, {friction_cone_deg:.1}) (below the friction cone of mu = {}), got {}",
                friction, p.vertical_deviation_deg
            ),
        ));
    }
    if p.curvature_segments == 0 {
        return Err((
            "planner.curvature_segments",
            "must be at least 1".to_string(),
        ));
    }
    for (key, v) in [
        ("planner.magnify_factor", p.magnify_factor),
        (
            "planner.joint_deviation_theta1_deg",
            p.joint_deviation_theta1_deg,
        ),
        (
            "planner.joint_deviation_theta2_deg",
            p.joint_deviation_theta2_deg,
        ),
        ("planner.pitch_range_deg", p.pitch_range_deg),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err((key, format!("must be zero or positive, got {v}")));
        }
    }
    Ok(())
}

/// A short, stable description of an I/O error.
pub(crate) fn io_message(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        std::io::ErrorKind::InvalidData => "not UTF-8 text".to_string(),
        _ => e.to_string(),
    }
}

/// The top-level sections of a scenario, for naming a missing one.
const SECTIONS: [&str; 5] = ["object", "hand", "planner", "sim", "expect"];

/// One line from a TOML error: `line N: `the line`: message`. A missing section is named
/// as such rather than pinned on line 1.
pub(crate) fn toml_message(e: &toml::de::Error, text: &str) -> String {
    let message = with_suggestion(&e.message().replace('\n', " "));
    if let Some(field) = message
        .strip_prefix("missing field `")
        .and_then(|m| m.strip_suffix('`'))
    {
        let at_top = e.span().is_none_or(|s| s.start == 0);
        if at_top && SECTIONS.contains(&field) {
            return format!("missing section `[{field}]`");
        }
    }
    match e.span() {
        Some(span) => {
            let start = span.start.min(text.len());
            let line_no = text[..start].matches('\n').count() + 1;
            let line = text.lines().nth(line_no - 1).unwrap_or("").trim();
            if line.is_empty() {
                format!("line {line_no}: {message}")
            } else {
                format!("line {line_no} (`{line}`): {message}")
            }
        }
        None => message,
    }
}

/// `message` with "; did you mean `key`?" appended when it is serde's "unknown field `x`,
/// expected one of `a`, `b`, ..." (or "expected `a`") and one known key is close to `x`.
pub(crate) fn with_suggestion(message: &str) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return message.to_string();
    };
    let Some((unknown, expected)) = rest.split_once('`') else {
        return message.to_string();
    };
    let known: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    match did_you_mean(unknown, known) {
        Some(k) => format!("{message}; did you mean `{k}`?"),
        None => message.to_string(),
    }
}

/// The known key nearest to `unknown` by edit distance (case-insensitive), when it is close
/// enough to be a typo: at most a third of the longer name's characters differ (at least 1,
/// at most 3). The first of equally near keys wins, so the answer is deterministic.
pub(crate) fn did_you_mean<'a>(
    unknown: &str,
    known: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let u = unknown.to_lowercase();
    let mut best: Option<(usize, &'a str)> = None;
    for k in known {
        let d = edit_distance(&u, &k.to_lowercase());
        let limit = (u.chars().count().max(k.chars().count()) / 3).clamp(1, 3);
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, k));
        }
    }
    best.map(|(_, k)| k)
}

/// Levenshtein distance (insertions, deletions, substitutions), with a swap of two adjacent
/// characters counted as one edit (Damerau, optimal string alignment): `lenght` → `length` is 1.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod suggestion_tests {
    use super::{did_you_mean, edit_distance};

    #[test]
    fn near_keys_are_suggested_and_far_ones_not() {
        assert_eq!(edit_distance("lenght", "length"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("planer", "planner"), 1);
        let keys = ["mesh", "units", "density_kg_m3", "mass_kg", "friction"];
        assert_eq!(did_you_mean("densty_kg_m3", keys), Some("density_kg_m3"));
        assert_eq!(did_you_mean("Units", keys), Some("units"));
        assert_eq!(did_you_mean("colour", keys), None);
        assert_eq!(did_you_mean("", keys), None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scenario with the given extra TOML after a minimal `[object]` table.
    fn parse(object_extra: &str, rest: &str) -> Result<Scenario, ScenarioError> {
        let text = format!("[object]\nmesh = \"cup.stl\"\n{object_extra}\n{rest}");
        Scenario::parse(&text, Path::new("/nowhere/cup_test.toml"))
    }

    #[test]
    fn defaults_fill_what_a_minimal_scenario_leaves_out() {
        let s = parse("", "").unwrap();
        assert_eq!(s.name, "cup_test");
        assert_eq!(s.object.mesh, PathBuf::from("/nowhere/cup.stl"));
        assert_eq!(s.object.mass, MassSpec::Density(DEFAULT_DENSITY_KG_M3));
        assert_eq!(s.object.friction, 0.3);
        assert_eq!(s.hand.name, "thesis");
        assert_eq!(s.hand_file, PathBuf::from("<bundled hand thesis>"));
        assert_eq!(s.planner, PlannerParams::default());
        assert_eq!(s.sim, SimParams::default());
        assert!(s.expect.is_none());
    }

    #[test]
    fn values_given_are_kept() {
        let table = [
            ("mass_kg = 0.2", MassSpec::Mass(0.2)),
            ("density_kg_m3 = 1000.0", MassSpec::Density(1000.0)),
        ];
        for (line, mass) in table {
            assert_eq!(parse(line, "").unwrap().object.mass, mass, "{line}");
        }
        let text =
            "name = \"x\"\n[object]\nmesh = \"m.stl\"\nfriction = 0.8\n[hand]\nfile = \"bh8\"\n";
        let s = Scenario::parse(text, Path::new("s.toml")).unwrap();
        assert_eq!(
            (s.name.as_str(), s.object.friction, s.hand.name.as_str()),
            ("x", 0.8, "bh8")
        );
    }

    #[test]
    fn out_of_range_values_name_their_key() {
        let table = [
            ("mass_kg = 1.0\ndensity_kg_m3 = 1.0", "", "object.mass_kg"),
            ("mass_kg = 0.0", "", "object.mass_kg"),
            ("density_kg_m3 = -5.0", "", "object.density_kg_m3"),
            ("friction = 0.0", "", "object.friction"),
            ("friction = 2.5", "", "object.friction"),
            ("", "[sim]\nduration_s = 0.0", "sim.duration_s"),
            ("", "[sim]\ntimestep_s = 0.1", "sim.timestep_s"),
            ("", "[sim]\nmax_checked = 0", "sim.max_checked"),
            (
                "",
                "[sim]\nsolver_iterations = 101",
                "sim.solver_iterations",
            ),
            ("", "[sim]\nsqueeze_deg = -1.0", "sim.squeeze_deg"),
            (
                "",
                "[sim]\nmotor_damping_nms_per_rad = -1.0",
                "sim.motor_damping_nms_per_rad",
            ),
            (
                "",
                "[sim]\noverride_angles = [[90.0, 90.0]]",
                "sim.override_angles",
            ),
            (
                "",
                "[sim]\noverride_angles = [[90.0, 90.0], [90.0, 0.0], [90.0, 90.0]]",
                "sim.override_angles",
            ),
            (
                "",
                "[expect]\noutcome = \"hold\"\ntheta_deg = [[90.0, 90.0]]",
                "expect.theta_deg",
            ),
            (
                "",
                "[hand]\noverrides = { \"palm.offset_mm\" = -1.0 }",
                "palm.offset_mm",
            ),
            (
                "",
                "[hand]\noverrides = { \"palm.ofset_mm\" = 1.0 }",
                "hand.overrides.\"palm.ofset_mm\"",
            ),
        ];
        for (object_extra, rest, expected) in table {
            let err = parse(object_extra, rest).unwrap_err();
            let key = match &err {
                ScenarioError::Invalid { key, .. } => key.clone(),
                ScenarioError::Hand(HandError::Invalid { key, .. }) => key.clone(),
                other => panic!("{object_extra:?} {rest:?}: {other}"),
            };
            assert_eq!(key, expected, "{object_extra:?} {rest:?}: {err}");
        }
    }

    #[test]
    fn unknown_keys_and_wrong_types_are_parse_errors_with_the_key() {
        let table = [
            ("colour = \"red\"", "", "colour"),
            ("friction = \"high\"", "", "friction"),
            ("", "[planner]\nheight_stp_mm = 2.5", "height_stp_mm"),
            ("", "[sim]\nduration_s = \"long\"", "duration_s"),
        ];
        for (object_extra, rest, key) in table {
            match parse(object_extra, rest) {
                Err(ScenarioError::Parse { message, .. }) => {
                    assert!(message.contains(key), "{key}: {message}")
                }
                other => panic!("{key}: {other:?}"),
            }
        }
    }
}
