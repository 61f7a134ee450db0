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
pub use crate::plan::PlannerParams;
pub use crate::sim::params::{Approach, GravityMode, Protocol, SimParams};
use crate::sim::Verdict;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Problems with a scenario file.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The input is not a scenario file that can be read (a folder, a missing path, a file
    /// of another kind).
    #[error("{path}: cannot read scenario: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// Reading the scenario file failed.
    #[error("{path}: cannot read scenario: {}", crate::messages::io_message(.error))]
    Read {
        /// The file.
        path: PathBuf,
        /// What the operating system said: not the error's `source()`, since the message
        /// already says it in a few stable words, and `{:#}` would print it twice.
        error: std::io::Error,
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
#[derive(Debug, Clone, serde::Serialize)]
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
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ObjectSpec {
    /// The STL file, resolved against the scenario's folder.
    pub mesh: PathBuf,
    /// The STL's length unit.
    pub units: LengthUnit,
    /// How the mass is given.
    pub mass: MassSpec,
    /// Coulomb friction coefficient between hand and object (thesis: 0.3).
    pub friction: f64,
    /// How the object's own frame is chosen ([`FrameRule`](crate::mesh::FrameRule); `[object]
    /// frame`).
    pub frame: crate::mesh::FrameRule,
}

impl ObjectSpec {
    /// The object `mesh` with the defaults a scenario's `[object]` table gets for what it
    /// leaves out: millimetres, [`DEFAULT_DENSITY_KG_M3`], [`DEFAULT_FRICTION`].
    pub fn with_defaults(mesh: PathBuf) -> ObjectSpec {
        ObjectSpec {
            mesh,
            units: LengthUnit::default(),
            mass: MassSpec::Default,
            friction: DEFAULT_FRICTION,
            frame: crate::mesh::FrameRule::default(),
        }
    }
}

/// The object's mass, from a density or given outright.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum MassSpec {
    /// Uniform density `[kg/m³]`.
    Density(f64),
    /// Total mass `[kg]`.
    Mass(f64),
    /// Neither given: the object file's own mass (a URDF's links' `<inertial>` masses) when it
    /// has one, else [`DEFAULT_DENSITY_KG_M3`].
    Default,
}

impl MassSpec {
    /// The mass `[kg]` of an object of `volume_mm3` `[mm³]` whose file gives `file_mass_kg`
    /// (a URDF's inertial masses), used only when the scenario gives neither mass nor density.
    pub fn mass_kg(self, volume_mm3: f64, file_mass_kg: Option<f64>) -> f64 {
        match self {
            MassSpec::Mass(m) => m,
            MassSpec::Density(d) => d * volume_mm3 * 1e-9,
            MassSpec::Default => file_mass_kg.unwrap_or(DEFAULT_DENSITY_KG_M3 * volume_mm3 * 1e-9),
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

    /// The physics check's verdict this outcome expects (`None` for `ungraspable`).
    pub fn verdict(self) -> Option<Verdict> {
        match self {
            Outcome::Hold => Some(Verdict::Hold),
            Outcome::Slip => Some(Verdict::Slip),
            Outcome::Drop => Some(Verdict::Drop),
            Outcome::Ungraspable => None,
        }
    }
}

/// What a scenario expects, with optional reference values for the planned grasp.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
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
    /// The least hold probability under `[sim] samples` perturbed checks, judged on its 95 %
    /// Wilson interval's lower bound (issue 34): 8 of 8 held is a lower bound of 0.68.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_hold_probability: Option<f64>,
    /// True: the grasp must also hold as planned (`sim.fidelity.as_planned`, issue 55), not
    /// only hold; `outcome` must then be `hold`. Default: the verdict alone is judged.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub as_planned: bool,
    /// The least probability of a hold as planned under `[sim] samples` perturbed checks,
    /// judged on its 95 % Wilson interval's lower bound, as `min_hold_probability` is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_as_planned_probability: Option<f64>,
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

/// `message` (the one line made of `error`) with "; `key` is a key of `[section]`" appended
/// when `error` is an unknown key that another section of a scenario takes (`friction` written
/// under `[sim]` belongs in `[object]`) and no near key of its own section was suggested.
fn with_section_hint(message: String, error: &str) -> String {
    let Some((unknown, known)) = crate::messages::unknown_field(error) else {
        return message;
    };
    if crate::messages::did_you_mean(unknown, known).is_some() {
        return message;
    }
    let homes: Vec<String> = section_keys()
        .into_iter()
        .filter(|(_, keys)| keys.iter().any(|k| k == unknown))
        .map(|(section, _)| format!("`[{section}]`"))
        .collect();
    if homes.is_empty() {
        return message;
    }
    format!("{message}; `{unknown}` is a key of {}", homes.join(" and "))
}

/// Each scenario section's keys, read from its parser's own answer to a key it does not take
/// (serde's "unknown field `x`, expected one of ..."), so that the list cannot drift from the
/// structs.
fn section_keys() -> Vec<(&'static str, Vec<String>)> {
    fn keys<T: serde::de::DeserializeOwned>() -> Vec<String> {
        let Err(e) = toml::from_str::<T>("__not_a_key__ = 0") else {
            return Vec::new();
        };
        crate::messages::unknown_field(e.message())
            .map(|(_, known)| known.into_iter().map(str::to_string).collect())
            .unwrap_or_default()
    }
    vec![
        ("object", keys::<RawObject>()),
        ("hand", keys::<RawHand>()),
        ("planner", keys::<PlannerParams>()),
        ("sim", keys::<SimParams>()),
        ("expect", keys::<Expect>()),
    ]
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
    units: Option<LengthUnit>,
    density_kg_m3: Option<f64>,
    mass_kg: Option<f64>,
    #[serde(default = "default_friction")]
    friction: f64,
    #[serde(default)]
    frame: crate::mesh::FrameRule,
}

fn default_friction() -> f64 {
    DEFAULT_FRICTION
}

/// Coulomb friction between hand and object when the scenario gives none (the thesis's).
pub const DEFAULT_FRICTION: f64 = 0.3;

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawHand {
    /// A hand file relative to the scenario, or the name of a bundled hand; default `thesis`.
    file: Option<PathBuf>,
    /// A hand's URDF relative to the scenario (issue 37), instead of `file`.
    urdf: Option<PathBuf>,
    /// A hand's MJCF relative to the scenario (issue 37), instead of `file`.
    mjcf: Option<PathBuf>,
    /// Which links and joints of the URDF or MJCF are the palm and the fingers.
    mapping: Option<crate::hand::import::Mapping>,
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
                message: "is a folder, not a scenario file (`grasp-sim batch FOLDER` runs every scenario, URDF or mesh in a folder)".to_string(),
            });
        }
        let text =
            crate::files::read_regular_string(path, crate::files::MAX_TEXT_BYTES).map_err(|e| {
                ScenarioError::Read {
                    path: path.to_path_buf(),
                    error: e,
                }
            })?;
        Scenario::parse(&text, path)
    }

    /// Reads a template for bare meshes (`batch --template`, `tune --template`): a scenario
    /// whose `[object] mesh` each mesh replaces, so it may leave it out (or the whole
    /// `[object]` table).
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn load_template(path: &Path) -> Result<Scenario, ScenarioError> {
        let scenario = Scenario::load(path);
        let text = match &scenario {
            Err(ScenarioError::Parse { .. }) => {
                crate::files::read_regular_string(path, crate::files::MAX_TEXT_BYTES).ok()
            }
            _ => None,
        };
        let Some(mut table) = text.and_then(|t| t.parse::<toml::Table>().ok()) else {
            return scenario;
        };
        let object = table
            .entry("object")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        match object.as_table_mut() {
            Some(o) if !o.contains_key("mesh") => {
                o.insert("mesh".into(), toml::Value::String(String::new()));
            }
            // The mesh is there (or `object` is not a table): the first error stands.
            _ => return scenario,
        }
        Scenario::parse_as(&table.to_string(), path, true)
    }

    /// Parses scenario TOML; relative paths resolve against `path`'s folder.
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn parse(text: &str, path: &Path) -> Result<Scenario, ScenarioError> {
        Scenario::parse_as(text, path, false)
    }

    /// [`Scenario::parse`]; a template (`template`) may leave `[object] mesh` empty, since each
    /// mesh of the batch replaces it.
    fn parse_as(text: &str, path: &Path, template: bool) -> Result<Scenario, ScenarioError> {
        let raw: RawScenario = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            path: path.to_path_buf(),
            message: with_section_hint(crate::messages::toml_message(&e, text), e.message()),
        })?;
        let _ = raw.description;
        let invalid = |key: &str, problem: String| ScenarioError::Invalid {
            path: path.to_path_buf(),
            key: key.to_string(),
            problem: crate::messages::short_numbers(&problem),
        };
        let dir = path.parent().unwrap_or(Path::new("."));
        let o = raw.object;
        if o.mesh.as_os_str().is_empty() && !template {
            return Err(invalid(
                "object.mesh",
                "is empty: give the mesh file's path (STL, OBJ, PLY or URDF)".to_string(),
            ));
        }
        let mass = validate_object(&o).map_err(|(key, problem)| invalid(key, problem))?;
        let (hand_file, hand) = load_hand(raw.hand, dir, path)?;

        validate_planner(&raw.planner, &hand, o.friction)
            .map_err(|(key, problem)| invalid(key, problem))?;
        raw.sim
            .validate(hand.finger_list.len())
            .map_err(|(key, problem)| invalid(key, problem))?;
        validate_expect(raw.expect.as_ref(), hand.finger_list.len())
            .map_err(|(key, problem)| invalid(key, problem))?;
        validate_name(raw.name.as_deref()).map_err(|(key, problem)| invalid(key, problem))?;
        let name = raw.name.unwrap_or_else(|| {
            crate::files::folder_name(
                &path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default(),
            )
        });
        Ok(Scenario {
            path: path.to_path_buf(),
            name,
            object: ObjectSpec {
                mesh: dir.join(o.mesh),
                units: o.units.unwrap_or_default(),
                mass,
                friction: o.friction,
                frame: o.frame,
            },
            hand,
            hand_file,
            planner: raw.planner,
            sim: raw.sim,
            expect: raw.expect,
        })
    }
}

/// The least Coulomb friction a scenario may give.
pub const MIN_FRICTION: f64 = 0.01;
/// The lightest object a scenario may give `[kg]`: a milligram.
pub const MIN_MASS_KG: f64 = 1e-6;
/// The least density a scenario may give `[kg/m³]` (silica aerogel is about 1).
pub const MIN_DENSITY_KG_M3: f64 = 0.1;
/// The heaviest object a scenario may give `[kg]`.
pub const MAX_MASS_KG: f64 = 10_000.0;
/// The densest object a scenario may give `[kg/m³]`.
pub const MAX_DENSITY_KG_M3: f64 = 100_000.0;

/// Checks a scenario's `[object]` (one of density and mass, positive and at most the limits
/// above; a URDF in metres; the friction in range) and returns how its mass is given.
///
/// # Errors
/// The key and the problem, for [`ScenarioError::Invalid`].
fn validate_object(o: &RawObject) -> Result<MassSpec, (&'static str, String)> {
    let mass = match (o.density_kg_m3, o.mass_kg) {
        (Some(_), Some(_)) => {
            return Err((
                "object.mass_kg",
                "and `object.density_kg_m3` are both given; give one".to_string(),
            ))
        }
        (Some(d), None) => MassSpec::Density(d),
        (None, Some(m)) => MassSpec::Mass(m),
        (None, None) => MassSpec::Default,
    };
    match mass {
        MassSpec::Density(d) if !(d.is_finite() && d > 0.0) => {
            return Err(("object.density_kg_m3", format!("must be positive, got {d}")))
        }
        MassSpec::Mass(m) if !(m.is_finite() && m > 0.0) => {
            return Err(("object.mass_kg", format!("must be positive, got {m}")))
        }
        // The physics check works in f32: past these an object's forces overflow and a check
        // could say `hold` of 1e20 kg.
        MassSpec::Density(d) if !(MIN_DENSITY_KG_M3..=MAX_DENSITY_KG_M3).contains(&d) => {
            return Err((
                "object.density_kg_m3",
                format!(
                    "must be in [{MIN_DENSITY_KG_M3}, {MAX_DENSITY_KG_M3}] kg/m³ (osmium is 22590), got {d}"
                ),
            ))
        }
        MassSpec::Mass(m) if !(MIN_MASS_KG..=MAX_MASS_KG).contains(&m) => {
            return Err((
                "object.mass_kg",
                format!(
                    "must be in [{MIN_MASS_KG}, {MAX_MASS_KG}] kg (no hand holds more), got {m}"
                ),
            ))
        }
        _ => {}
    }
    // A URDF's lengths are metres by its format: another unit would be silently ignored.
    let is_urdf =
        crate::mesh::MeshFormat::from_path(&o.mesh) == Some(crate::mesh::MeshFormat::Urdf);
    if let (true, Some(u)) = (is_urdf, o.units.filter(|&u| u != LengthUnit::M)) {
        return Err((
            "object.units",
            format!(
                "is \"{}\", but a URDF's lengths are metres (its meshes' `scale` gives their \
                 unit); remove `units` or set it to \"m\"",
                u.name()
            ),
        ));
    }
    // Coulomb friction between a hand and an object: PTFE on steel, the slipperiest pair in
    // the tables, is about 0.04; rubber on rubber rarely exceeds ~1.5, so [0.01, 2] bounds any
    // plausible value (5e-324 was taken, and blamed on the planner's vertical deviation).
    if !(o.friction.is_finite() && (MIN_FRICTION..=2.0).contains(&o.friction)) {
        return Err((
            "object.friction",
            format!("must be in [{MIN_FRICTION}, 2], got {}", o.friction),
        ));
    }
    Ok(mass)
}

/// The `[expect]` table against a hand of `fingers` fingers: the probabilities in [0, 1], an
/// as-planned hold asked only with outcome `hold`, one `theta_deg` entry per finger. The key
/// and the problem of the first that is wrong.
fn validate_expect(expect: Option<&Expect>, fingers: usize) -> Result<(), (&'static str, String)> {
    for (key, p) in expect.map_or(vec![], |e| {
        vec![
            ("expect.min_hold_probability", e.min_hold_probability),
            (
                "expect.min_as_planned_probability",
                e.min_as_planned_probability,
            ),
        ]
    }) {
        if let Some(p) = p {
            if !(p.is_finite() && (0.0..=1.0).contains(&p)) {
                return Err((key, format!("must be in [0, 1], got {p}")));
            }
        }
    }
    if let Some(e) = expect.filter(|e| e.as_planned) {
        if e.outcome != Outcome::Hold {
            return Err((
                "expect.as_planned",
                format!(
                    "asks for a hold as planned, but outcome is \"{}\": set outcome = \"hold\"",
                    e.outcome.as_str()
                ),
            ));
        }
    }
    if let Some(t) = expect.and_then(|e| e.theta_deg.as_ref()) {
        if t.len() != fingers {
            return Err((
                "expect.theta_deg",
                format!("has {} fingers, the hand has {}", t.len(), fingers),
            ));
        }
    }
    Ok(())
}

/// The scenario's `name`, when given: the output folders' subfolder (`--report DIR/NAME`), so
/// one folder name, checked here (a file stem, the name otherwise, is made one: `..stl` would
/// name `.`).
fn validate_name(name: Option<&str>) -> Result<(), (&'static str, String)> {
    if let Some(problem) = name.and_then(crate::files::folder_name_problem) {
        return Err((
            "name",
            format!(
                "{problem}: it names the run's folder inside --report, --export-mjcf and \
                 --export-urdf, so it must be one folder name (not `.` or `..`, no `/`, `\\`, \
                 NUL or control characters, at most {} bytes)",
                crate::files::MAX_FOLDER_NAME_BYTES
            ),
        ));
    }
    Ok(())
}

/// Loads the scenario's hand (a bundled one by name unless a file of that name is beside the
/// scenario) with its overrides, naming the scenario for a problem its override caused.
///
/// # Errors
/// [`ScenarioError`]: the hand file's own, or [`ScenarioError::Invalid`] for an override.
fn load_hand(raw: RawHand, dir: &Path, path: &Path) -> Result<(PathBuf, Hand), ScenarioError> {
    let overrides: Vec<(String, f64)> = raw.overrides.into_iter().collect();
    let invalid = |key: &str, problem: &str| ScenarioError::Invalid {
        path: path.to_path_buf(),
        key: key.to_string(),
        problem: problem.to_string(),
    };
    let robot = match (&raw.file, raw.urdf, raw.mjcf) {
        (None, Some(f), None) | (None, None, Some(f)) => Some(f),
        (_, None, None) => None,
        _ => {
            return Err(invalid(
                "hand",
                "gives more than one of `file`, `urdf` and `mjcf`: give one",
            ))
        }
    };
    if let Some(f) = robot {
        let f = dir.join(f);
        let mapping = raw.mapping.unwrap_or_default();
        let derived = crate::hand::import::load(&f, &mapping, &overrides);
        return derived
            .map(|d| (f, d.hand))
            .map_err(|e| hand_error(e, &overrides, path));
    }
    if raw.mapping.is_some() {
        return Err(invalid(
            "hand.mapping",
            "maps the joints of a URDF or MJCF: give `urdf` or `mjcf` with it",
        ));
    }
    let file = raw.file.unwrap_or_else(|| PathBuf::from("thesis"));
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
    let hand = loaded.map_err(|e| hand_error(e, &overrides, path))?;
    Ok((hand_file, hand))
}

/// A hand file's error, or the scenario's when its override caused it.
fn hand_error(e: HandError, overrides: &[(String, f64)], path: &Path) -> ScenarioError {
    match e {
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
        // A value out of range that the scenario's override set: name the scenario.
        HandError::Invalid {
            path: hand,
            key,
            problem,
        } if overrides.iter().any(|(k, _)| *k == key) => ScenarioError::Invalid {
            path: path.to_path_buf(),
            key: format!("hand.overrides.\"{key}\""),
            problem: format!("{problem} ({} with this override)", hand.display()),
        },
        other => other.into(),
    }
}

/// Checks planner parameters against the hand and the friction (see
/// [`PlannerParams::validate`]).
///
/// # Errors
/// `(key, problem)`.
pub fn validate_planner(
    params: &PlannerParams,
    hand: &Hand,
    friction: f64,
) -> Result<(), (&'static str, String)> {
    params.validate(hand, friction)
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
        assert_eq!(s.object.mass, MassSpec::Default);
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
            ("", "[sim]\noverride_index = 5", "sim.override_index"),
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
                "hand.overrides.\"palm.offset_mm\"",
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
