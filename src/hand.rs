//! The hand model, read from a TOML file under `assets/hands/` (thesis 3.3.2, Fig. 3.6).
//!
//! Units: millimetres and degrees, as in the thesis. Angles are interior angles: 180° is a link
//! lying straight on in line with the one before it (for joint 1, the finger lying out along the
//! palm), smaller is more closed.
//!
//! The frame of the hand (used by the planner): the palm contact surface is the plane X = 0 of
//! the palm frame, facing −X towards the object; +Z is the palm's up axis (parallel to the finger
//! joint axes); fingers sit at heights along Z and curl in planes normal to Z.

use serde::Deserialize;
use std::path::{Path, PathBuf};

mod geometry;
pub mod import;
mod import_frame;
pub mod kinematics;
pub mod link_geometry;
pub mod mjcf_hand;
pub mod urdf_hand;
pub use geometry::{bend, palm_rotation, BodyPose, HandBox};

/// The largest length a hand file may give `[mm]`: a hand is hand-sized (issue 32).
pub const MAX_LENGTH_MM: f64 = 2000.0;
/// The shortest positive length a hand may have `[mm]`: 10 µm, far under any finger and far
/// above the f32 physics check's rounding at a hand's size.
pub const MIN_LENGTH_MM: f64 = 0.01;

/// The hands built into the binary, by name: found wherever grasp-sim runs, without a path.
pub const BUNDLED: [(&str, &str); 2] = [
    ("thesis", include_str!("../assets/hands/thesis.toml")),
    ("bh8", include_str!("../assets/hands/bh8.toml")),
];

/// The bundled hand called `name` (e.g. `thesis`), as `(name, TOML)`.
pub fn bundled(name: &str) -> Option<(&'static str, &'static str)> {
    BUNDLED.iter().copied().find(|(n, _)| *n == name)
}

/// The bundled thesis hand, parsed: the hand most unit tests plan with.
#[cfg(test)]
pub(crate) fn thesis_for_tests() -> Hand {
    let (_, text) = bundled("thesis").expect("the thesis hand is bundled");
    Hand::parse(text, Path::new("thesis.toml"), &[]).expect("the thesis hand parses")
}

/// Problems with a hand file.
#[derive(Debug, thiserror::Error)]
pub enum HandError {
    /// The file could not be read.
    #[error("{path}: cannot read hand file: {}", crate::messages::io_message(.error))]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said: not the error's `source()`, since the message
        /// already says it in a few stable words, and `{:#}` would print it twice.
        error: std::io::Error,
    },
    /// The TOML does not parse or does not fit the schema.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// One-line description with the line and key.
        message: String,
    },
    /// An override given by a scenario names no numeric key of the hand file.
    #[error("{path}: override `{key}` {problem}")]
    BadOverride {
        /// The hand file.
        path: PathBuf,
        /// The dotted key.
        key: String,
        /// What is wrong.
        problem: String,
    },
    /// A value is out of its physical range.
    #[error("{path}: `{key}` {problem}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The dotted key.
        key: String,
        /// What is wrong.
        problem: String,
    },
}

/// A three-fingered hand with two phalanges per finger (Barrett-like).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Hand {
    /// Name of the hand.
    pub name: String,
    /// The palm.
    pub palm: Palm,
    /// Joint placement and ranges, shared by all fingers.
    pub joints: Joints,
    /// Finger cross-section and spacing, shared by all fingers.
    pub fingers: FingerGeometry,
    /// First (proximal) phalanx.
    pub phalanx_1: Phalanx,
    /// Second (distal) phalanx.
    pub phalanx_2: Phalanx,
    /// The fingers, in the thesis's order (finger_1 top, finger_2 the opposing thumb, finger_3).
    #[serde(rename = "finger")]
    pub finger_list: Vec<Finger>,
    /// Joints the hand couples (issue 37: a URDF's `mimic`, an MJCF's `<equality><joint>`),
    /// as relations between interior angles. The planner treats the joints as independent; a
    /// plan is checked against each coupling ([`Hand::coupling_checks`]), not refused.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub coupling: Vec<Coupling>,
    /// The hand file's own link geometry where its links have meshes (issue 37: a hand read
    /// from a URDF or MJCF), which the physics check and `--export-mjcf` use instead of the
    /// model's boxes for those bodies. Never in a hand TOML, never serialised.
    #[serde(skip)]
    pub link_geometry: Option<std::sync::Arc<link_geometry::LinkGeometry>>,
}

/// A coupling between two joints of the model: θ(follower) = multiplier × θ(leader) +
/// offset_deg, interior angles in degrees.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Coupling {
    /// The following joint: `[finger number (1-3, model order), joint (1 or 2)]`.
    pub follower: [usize; 2],
    /// The joint it follows, likewise.
    pub leader: [usize; 2],
    /// The multiplier (between interior angles).
    pub multiplier: f64,
    /// The offset `[deg]`.
    pub offset_deg: f64,
    /// Where the file states it, in words.
    #[serde(default)]
    pub source: String,
}

/// How far a plan is from holding a coupling.
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingCheck {
    /// The coupling, in words.
    pub coupling: String,
    /// The follower's planned angle minus the angle the coupling gives it `[deg]`.
    pub error_deg: f64,
}

/// The step between the palm stand-offs the planner tries ([`Hand::palm_standoffs_mm`]) `[mm]`.
pub const STANDOFF_STEP_MM: f64 = 2.0;

/// How closely a plan must keep a coupling to keep it `[deg]`: the thesis's Joint Angular
/// Deviation.
pub const COUPLING_TOLERANCE_DEG: f64 = 5.0;

impl Coupling {
    /// The coupling in words, with the model's joint names.
    pub fn describe(&self) -> String {
        let j = |r: [usize; 2]| format!("finger_{} θ{}", r[0], r[1]);
        let what = format!(
            "{} = {:.4} × {} {} {:.2}°",
            j(self.follower),
            self.multiplier,
            j(self.leader),
            if self.offset_deg < 0.0 { "−" } else { "+" },
            self.offset_deg.abs()
        );
        if self.source.is_empty() {
            what
        } else {
            format!("{what} ({})", self.source)
        }
    }
}
/// Palm dimensions.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Palm {
    /// Palm thickness from its centreline to its contact surface `[mm]`.
    pub offset_mm: f64,
    /// Distance from the outer fingers' centrelines to the palm's top and bottom edges `[mm]`.
    pub margin_mm: f64,
    /// Half the palm's width across the fingers' curling direction `[mm]`.
    pub half_width_mm: f64,
    /// How far in front of the palm's contact surface the fingers may hold an object they
    /// cannot wrap resting on it `[mm]` (beyond the thesis, issue 37): the object is held
    /// between the phalanges, the palm stood off it. Optional: without it (or at 0) the
    /// thesis's model, every object rests on the palm. A hand whose distal joint closes at
    /// most 90° (the Schunk SDH-2) wraps nothing resting on its palm and needs it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub standoff_max_mm: Option<f64>,
}

/// Where the joint-1 axes are and how far each joint turns.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Joints {
    /// Distance of each joint-1 axis from the palm centre, sideways `[mm]`.
    pub lateral_mm: f64,
    /// Distance of the joint-1 axes behind the palm contact surface `[mm]`.
    pub setback_mm: f64,
    /// Range of joint 1 `[deg]`, interior angle relative to the palm.
    pub theta1_range_deg: [f64; 2],
    /// Range of joint 2 `[deg]`, interior angle relative to phalanx 1.
    pub theta2_range_deg: [f64; 2],
}

/// Finger cross-section and spacing.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct FingerGeometry {
    /// Distance between the centrelines of adjacent fingers along the palm's up axis `[mm]`.
    pub gap_mm: f64,
    /// Distance from a finger's centreline to its contact surface and to its side walls `[mm]`.
    pub offset_mm: f64,
    /// Thickness of the thinned fingertip of phalanx 2 `[mm]` (thesis Fig. 3.8).
    pub tip_thickness_mm: f64,
    /// Relief a finger does not feel `[mm]` (beyond the thesis, issue 30): the search places
    /// fingers and the palm on slice contours simplified within this distance (teeth, knurls,
    /// a scanner's noise shallower than it are not there for the finger). Optional: without
    /// it, an eighth of the fingertip's thickness ([`Hand::relief_mm`]).
    #[serde(default)]
    pub relief_mm: Option<f64>,
}

/// One phalanx.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Phalanx {
    /// Length from its joint axis to the next joint axis, or to the tip `[mm]`.
    pub length_mm: f64,
    /// Unusable length next to its joint, kept free of contact `[mm]`.
    pub unusable_proximal_mm: f64,
    /// Unusable length at its far end `[mm]`.
    pub unusable_distal_mm: f64,
}

/// Which side of the palm a finger's joints are on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Joint 1 at +lateral (the palm frame's +Y).
    Left,
    /// Joint 1 at −lateral.
    Right,
}

/// One finger.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Finger {
    /// Name (`finger_1` …).
    pub name: String,
    /// Side of its joints.
    pub side: Side,
    /// Height of its centreline above the palm centre along the palm's up axis `[mm]`.
    pub height_mm: f64,
}

impl Hand {
    /// The palm's stand-offs the planner tries, nearest first `[mm]`: 0 (the object resting on
    /// the palm, the thesis's model), then [`STANDOFF_STEP_MM`] steps up to
    /// `palm.standoff_max_mm`. Just `[0]` for a hand without a stand-off.
    pub fn palm_standoffs_mm(&self) -> Vec<f64> {
        let max = self.palm.standoff_max_mm.unwrap_or(0.0);
        let steps = (max / STANDOFF_STEP_MM).floor() as usize;
        (0..=steps).map(|k| k as f64 * STANDOFF_STEP_MM).collect()
    }

    /// Checks planned joint angles `[θ1, θ2]` per finger (model order, degrees) against every
    /// coupling: the planner does not refuse a plan that breaks one, the check says by how much.
    pub fn coupling_checks(&self, theta_deg: &[[f64; 2]]) -> Vec<CouplingCheck> {
        let angle = |r: [usize; 2]| {
            theta_deg
                .get(r[0].wrapping_sub(1))
                .and_then(|t| t.get(r[1].wrapping_sub(1)))
                .copied()
        };
        self.coupling
            .iter()
            .filter_map(|c| {
                let (f, l) = (angle(c.follower)?, angle(c.leader)?);
                Some(CouplingCheck {
                    coupling: c.describe(),
                    error_deg: f - (c.multiplier * l + c.offset_deg),
                })
            })
            .collect()
    }

    /// [`Hand::coupling_checks`] as one line each for a run's warnings: which coupling, by how
    /// much the plan breaks or keeps it, and that it is checked, not refused.
    pub fn coupling_lines(&self, theta_deg: &[[f64; 2]]) -> Vec<String> {
        self.coupling_checks(theta_deg)
            .into_iter()
            .map(|c| {
                let verdict = if c.error_deg.abs() <= COUPLING_TOLERANCE_DEG {
                    "keeps it".to_string()
                } else {
                    format!("breaks it by {:+.1}°", c.error_deg)
                };
                format!(
                    "hand `{}`: coupling {}: the plan {verdict} (checked, not refused: the \
                     planner and the physics check drive each joint on its own)",
                    self.name, c.coupling
                )
            })
            .collect()
    }

    /// A finger's width `[mm]`: its centreline to each side wall is the finger offset (thesis
    /// 3.3.2), so no gap narrower than this lets a finger in.
    pub fn finger_width_mm(&self) -> f64 {
        2.0 * self.fingers.offset_mm
    }

    /// The relief this hand's fingers do not feel `[mm]`: `fingers.relief_mm`, or an eighth of
    /// the fingertip's thickness (0.5 mm for the thesis hand's 4 mm tip). Slice contours are
    /// simplified within it before a finger or the palm is placed on them.
    pub fn relief_mm(&self) -> f64 {
        self.fingers
            .relief_mm
            .unwrap_or(self.fingers.tip_thickness_mm / 8.0)
    }

    /// Reads and validates a hand file, applying `overrides` (dotted key → number) first.
    ///
    /// # Errors
    /// [`HandError`] naming the file: unreadable, bad TOML, unknown key or wrong type, an override
    /// naming no numeric key, or a value out of range.
    pub fn load(path: &Path, overrides: &[(String, f64)]) -> Result<Hand, HandError> {
        let text =
            crate::files::read_regular_string(path, crate::files::MAX_TEXT_BYTES).map_err(|e| {
                HandError::Io {
                    path: path.to_path_buf(),
                    error: e,
                }
            })?;
        Hand::parse(&text, path, overrides)
    }

    /// Parses hand TOML; `path` is used in messages only.
    ///
    /// # Errors
    /// As [`Hand::load`].
    pub fn parse(text: &str, path: &Path, overrides: &[(String, f64)]) -> Result<Hand, HandError> {
        let parse_err = |message| HandError::Parse {
            path: path.to_path_buf(),
            message,
        };
        let mut doc: toml::Table = toml::from_str(text)
            .map_err(|e: toml::de::Error| parse_err(crate::messages::toml_message(&e, text)))?;
        for (key, value) in overrides {
            set_number(&mut doc, key, *value).map_err(|problem| {
                let mut keys = Vec::new();
                number_keys(&doc, "", &mut keys);
                let problem =
                    match crate::messages::did_you_mean(key, keys.iter().map(|k| k.as_str())) {
                        Some(k) => format!("{problem}; did you mean `{k}`?"),
                        None => problem,
                    };
                HandError::BadOverride {
                    path: path.to_path_buf(),
                    key: key.clone(),
                    problem,
                }
            })?;
        }
        // Without overrides, parse the text itself so an error carries its line; with them, the
        // edited table (the line is then that of the hand file as written, if any).
        let hand: Hand = if overrides.is_empty() {
            toml::from_str(text)
                .map_err(|e: toml::de::Error| parse_err(crate::messages::toml_message(&e, text)))?
        } else {
            toml::Value::Table(doc)
                .try_into()
                .map_err(|e: toml::de::Error| {
                    parse_err(crate::messages::with_suggestion(
                        &e.message().replace('\n', " "),
                    ))
                })?
        };
        hand.validate(path)?;
        Ok(hand)
    }

    /// Checks the hand's values; every problem names its key.
    fn validate(&self, path: &Path) -> Result<(), HandError> {
        self.check_lengths()
            .and_then(|()| self.check_links())
            .and_then(|()| self.check_wraps())
            .map_err(|(key, problem)| HandError::Invalid {
                path: path.to_path_buf(),
                key: key.to_string(),
                problem,
            })
    }

    /// The lengths: positive or non-negative as each must be, finite, and hand-sized.
    fn check_lengths(&self) -> Result<(), (&'static str, String)> {
        let positive = [
            ("palm.offset_mm", self.palm.offset_mm),
            ("palm.half_width_mm", self.palm.half_width_mm),
            ("joints.lateral_mm", self.joints.lateral_mm),
            ("fingers.gap_mm", self.fingers.gap_mm),
            ("fingers.offset_mm", self.fingers.offset_mm),
            ("fingers.tip_thickness_mm", self.fingers.tip_thickness_mm),
            ("phalanx_1.length_mm", self.phalanx_1.length_mm),
            ("phalanx_2.length_mm", self.phalanx_2.length_mm),
        ];
        for (key, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err((key, format!("must be a positive length, got {v}")));
            }
            if v < MIN_LENGTH_MM {
                return Err((
                    key,
                    format!("must be in [{MIN_LENGTH_MM}, {MAX_LENGTH_MM}] mm, got {v}"),
                ));
            }
        }
        let non_negative = [
            ("palm.margin_mm", self.palm.margin_mm),
            ("joints.setback_mm", self.joints.setback_mm),
            (
                "palm.standoff_max_mm",
                self.palm.standoff_max_mm.unwrap_or(0.0),
            ),
            (
                "phalanx_1.unusable_proximal_mm",
                self.phalanx_1.unusable_proximal_mm,
            ),
            (
                "phalanx_1.unusable_distal_mm",
                self.phalanx_1.unusable_distal_mm,
            ),
            (
                "phalanx_2.unusable_proximal_mm",
                self.phalanx_2.unusable_proximal_mm,
            ),
            (
                "phalanx_2.unusable_distal_mm",
                self.phalanx_2.unusable_distal_mm,
            ),
        ];
        if let Some(v) = self.fingers.relief_mm {
            if !(v.is_finite() && (0.0..self.fingers.offset_mm).contains(&v)) {
                return Err((
                    "fingers.relief_mm",
                    format!("must be zero or positive and below fingers.offset_mm, got {v}"),
                ));
            }
        }
        for (key, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err((key, format!("must be zero or positive, got {v}")));
            }
        }
        // A hand is hand-sized: the same 2 m the object size warning takes as the largest
        // plausible object. Far past it (a 300 m phalanx, issue 32) the physics check's f32
        // arithmetic turns the motors' limits into NaN and panics.
        for (key, v) in positive.iter().chain(&non_negative) {
            if *v > MAX_LENGTH_MM {
                return Err((
                    key,
                    format!("must be at most {MAX_LENGTH_MM} mm (a hand's size), got {v}"),
                ));
            }
        }
        Ok(())
    }

    /// The links, the joint ranges and the fingers: contact length left on each phalanx, a tip
    /// no thicker than the finger offset, joint ranges within (0, 180], fingers named once.
    fn check_links(&self) -> Result<(), (&'static str, String)> {
        for (key, p) in [
            ("phalanx_1", &self.phalanx_1),
            ("phalanx_2", &self.phalanx_2),
        ] {
            if p.unusable_proximal_mm + p.unusable_distal_mm >= p.length_mm {
                return Err((key, "unusable lengths leave no contact length".to_string()));
            }
        }
        if self.fingers.tip_thickness_mm > self.fingers.offset_mm {
            return Err((
                "fingers.tip_thickness_mm",
                "must not exceed fingers.offset_mm (the tip is thinned, thesis Fig. 3.8)"
                    .to_string(),
            ));
        }
        for (key, [lo, hi]) in [
            ("joints.theta1_range_deg", self.joints.theta1_range_deg),
            ("joints.theta2_range_deg", self.joints.theta2_range_deg),
        ] {
            if !(lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < hi && hi <= 180.0) {
                return Err((
                    key,
                    format!("must be [low, high] with 0 < low < high <= 180, got [{lo}, {hi}]"),
                ));
            }
        }
        if self.finger_list.is_empty() {
            return Err(("finger", "the hand has no fingers".to_string()));
        }
        let n = self.finger_list.len();
        let joint_ok = |r: [usize; 2]| (1..=n).contains(&r[0]) && (1..=2).contains(&r[1]);
        for c in &self.coupling {
            if !(joint_ok(c.follower)
                && joint_ok(c.leader)
                && c.multiplier.is_finite()
                && c.multiplier.abs() <= 100.0
                && c.offset_deg.is_finite()
                && c.offset_deg.abs() <= 360.0)
            {
                return Err((
                    "coupling",
                    format!(
                        "must name [finger 1-{n}, joint 1-2] twice with a multiplier in \
                         [-100, 100] and an offset in [-360, 360]°, got {c:?}"
                    ),
                ));
            }
        }
        for (i, f) in self.finger_list.iter().enumerate() {
            if self.finger_list[..i].iter().any(|g| g.name == f.name) {
                return Err(("finger.name", format!("`{}` appears twice", f.name)));
            }
            if !(f.height_mm.is_finite() && f.height_mm.abs() <= MAX_LENGTH_MM) {
                return Err((
                    "finger.height_mm",
                    format!(
                        "must be in [-{MAX_LENGTH_MM}, {MAX_LENGTH_MM}] mm for {}, got {}",
                        f.name, f.height_mm
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The planner's graspable diameter range exists.
    fn check_wraps(&self) -> Result<(), (&'static str, String)> {
        // The planner's graspable diameter range must exist: a finger whose phalanx 2 cannot
        // reach back to any object resting on the palm wraps nothing (issue 16, item 1).
        let range = kinematics::graspable_range(self);
        if range.max_kinematic_mm.partial_cmp(&range.min_mm) != Some(std::cmp::Ordering::Greater) {
            let what = if range.max_kinematic_mm == 0.0 {
                "no object resting on the palm (up to 2 m across) is touched by both phalanges \
                 within the joint ranges, so the hand can wrap nothing"
                    .to_string()
            } else {
                format!(
                    "the largest object both phalanges wrap ({:.1} mm) is not larger than the \
                     smallest graspable diameter ({:.1} mm, thesis eq. 3.2), so the hand can wrap \
                     nothing",
                    range.max_kinematic_mm, range.min_mm
                )
            };
            return Err((
                "phalanx_1.length_mm",
                format!(
                    "{} mm with phalanx_2.length_mm {} mm and these joint ranges: {what}; shorten \
                     phalanx 1, lengthen phalanx 2 or widen the joint ranges",
                    self.phalanx_1.length_mm, self.phalanx_2.length_mm
                ),
            ));
        }
        Ok(())
    }

    /// Palm contact length along its up axis: outer finger centrelines plus the margins `[mm]`.
    pub fn palm_height_mm(&self) -> f64 {
        let (lo, hi) = self.finger_height_span();
        hi - lo + 2.0 * self.palm.margin_mm
    }

    /// Lowest and highest finger centreline heights relative to the palm centre `[mm]`.
    pub fn finger_height_span(&self) -> (f64, f64) {
        self.finger_list
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), f| {
                (lo.min(f.height_mm), hi.max(f.height_mm))
            })
    }
}

/// Every dotted key of `doc` that holds a number, in the table's order.
fn number_keys(doc: &toml::Table, prefix: &str, out: &mut Vec<String>) {
    for (k, v) in doc {
        match v {
            toml::Value::Float(_) | toml::Value::Integer(_) => out.push(format!("{prefix}{k}")),
            toml::Value::Table(t) => number_keys(t, &format!("{prefix}{k}."), out),
            _ => {}
        }
    }
}

/// Sets the number at dotted `key` in `doc`; the key must already hold a number.
fn set_number(doc: &mut toml::Table, key: &str, value: f64) -> Result<(), String> {
    let mut parts = key.split('.').peekable();
    let mut table = doc;
    while let Some(part) = parts.next() {
        if parts.peek().is_none() {
            return match table.get_mut(part) {
                Some(v @ (toml::Value::Float(_) | toml::Value::Integer(_))) => {
                    *v = toml::Value::Float(value);
                    Ok(())
                }
                Some(_) => Err("is not a number in the hand file".to_string()),
                None => Err("names no key of the hand file".to_string()),
            };
        }
        table = match table.get_mut(part) {
            Some(toml::Value::Table(t)) => t,
            _ => return Err("names no key of the hand file".to_string()),
        };
    }
    Err("is empty".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, UnitQuaternion, Vector3};
    use std::f64::consts::FRAC_PI_2;

    fn thesis(overrides: &[(&str, f64)]) -> Result<Hand, HandError> {
        let (_, text) = bundled("thesis").unwrap();
        let overrides: Vec<(String, f64)> =
            overrides.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        Hand::parse(text, Path::new("thesis.toml"), &overrides)
    }

    fn close(a: Vector3<f64>, b: Vector3<f64>) -> bool {
        (a - b).norm() < 1e-9
    }

    #[test]
    fn derived_quantities_of_the_thesis_hand() {
        let h = thesis(&[]).unwrap();
        assert_eq!(h.finger_width_mm(), 14.0);
        assert_eq!(h.finger_height_span(), (-25.0, 25.0));
        assert_eq!(h.palm_height_mm(), 64.0);
        assert_eq!(h.palm_z_range_mm(), [-32.0, 32.0]);
        let palm = h.palm_box();
        assert_eq!(palm.half_extents, Vector3::new(5.0, 36.7, 32.0));
        assert_eq!(palm.centre, Vector3::new(5.0, 0.0, 0.0));
    }

    #[test]
    fn sides_bends_and_anchors() {
        assert_eq!(Side::Left.sign(), 1.0);
        assert_eq!(Side::Right.sign(), -1.0);
        for (theta, expected) in [
            (180.0, 0.0),
            (90.0, FRAC_PI_2),
            (45.0, 3.0 * FRAC_PI_2 / 2.0),
        ] {
            assert!((bend(theta) - expected).abs() < 1e-12, "bend({theta})");
        }
        let h = thesis(&[]).unwrap();
        let table = [
            (
                0,
                Vector3::new(5.8, 36.7, 25.0),
                Vector3::new(0.0, 61.0, 0.0),
            ),
            (
                1,
                Vector3::new(5.8, -36.7, 0.0),
                Vector3::new(0.0, -61.0, 0.0),
            ),
            (
                2,
                Vector3::new(5.8, 36.7, -25.0),
                Vector3::new(0.0, 61.0, 0.0),
            ),
        ];
        for (k, joint1, joint2) in table {
            let f = &h.finger_list[k];
            assert_eq!(h.joint1_anchor_mm(f), joint1, "{}", f.name);
            assert_eq!(h.joint2_anchor_mm(f.side), joint2, "{}", f.name);
        }
    }

    #[test]
    fn phalanx_boxes_with_and_without_a_thinned_tip() {
        // The thesis hand's phalanx 2 may touch with its tip: no thinned part.
        let h = thesis(&[]).unwrap();
        let (p1, p2) = h.phalanx_boxes(Side::Right);
        assert_eq!(p1.half_extents, Vector3::new(7.0, 30.5, 7.0));
        assert_eq!(p1.centre, Vector3::new(0.0, -30.5, 0.0));
        assert_eq!(p2.len(), 1);
        assert_eq!(p2[0].half_extents, Vector3::new(7.0, 10.0, 7.0));
        // 4 mm unusable at the far end: a 16 mm contact part and a 4 mm tip, 4 mm thick, flush
        // with the back of the finger.
        let h = thesis(&[("phalanx_2.unusable_distal_mm", 4.0)]).unwrap();
        let (_, p2) = h.phalanx_boxes(Side::Left);
        assert_eq!(p2.len(), 2);
        assert_eq!(p2[0].half_extents, Vector3::new(7.0, 8.0, 7.0));
        assert_eq!(p2[0].centre, Vector3::new(0.0, 8.0, 0.0));
        assert_eq!(p2[1].half_extents, Vector3::new(2.0, 2.0, 7.0));
        assert_eq!(p2[1].centre, Vector3::new(5.0, 18.0, 0.0));
    }

    #[test]
    fn forward_kinematics_curls_both_sides_towards_the_object() {
        let h = thesis(&[]).unwrap();
        let palm = (Point3::origin(), UnitQuaternion::identity());
        // (finger, bends, joint 2, phalanx 2's axis along the finger): straight, then joint 1
        // at 90° (phalanx 1 points at the object, −x), then both at 90° (phalanx 2 turns back
        // across the palm).
        let table = [
            (0, [0.0, 0.0], Vector3::new(5.8, 97.7, 25.0), Vector3::y()),
            (
                0,
                [FRAC_PI_2, 0.0],
                Vector3::new(-55.2, 36.7, 25.0),
                -Vector3::x(),
            ),
            (
                1,
                [FRAC_PI_2, 0.0],
                Vector3::new(-55.2, -36.7, 0.0),
                Vector3::x(),
            ),
            (
                0,
                [FRAC_PI_2, FRAC_PI_2],
                Vector3::new(-55.2, 36.7, 25.0),
                -Vector3::y(),
            ),
        ];
        for (k, bends, joint2, axis) in table {
            let f = &h.finger_list[k];
            let [(j1, _), (j2, r2)] = h.finger_poses(f, &palm, bends);
            assert!(
                close(j1.coords, h.joint1_anchor_mm(f)),
                "{k} {bends:?}: {j1}"
            );
            assert!(close(j2.coords, joint2), "{k} {bends:?}: {j2}");
            // Phalanx 2's own y axis, as seen from the finger's side.
            let along = r2 * Vector3::y() * f.side.sign();
            let expected = if f.side == Side::Left { axis } else { -axis };
            assert!(close(along, expected), "{k} {bends:?}: {along}");
        }
        let poses = h.body_poses(&palm, &[[0.0, 0.0]; 3]);
        assert_eq!(poses.len(), 7);
        assert_eq!(poses[0], palm);
    }

    #[test]
    fn a_rotated_palm_carries_the_fingers() {
        let h = thesis(&[]).unwrap();
        let axes = [Vector3::y(), -Vector3::x(), Vector3::z()];
        let r = palm_rotation(&axes);
        for (k, a) in axes.iter().enumerate() {
            let mut e = Vector3::zeros();
            e[k] = 1.0;
            assert!(close(r * e, *a), "axis {k}");
        }
        let origin = Point3::new(10.0, 0.0, 50.0);
        let [(j1, _), _] = h.finger_poses(&h.finger_list[0], &(origin, r), [0.0, 0.0]);
        // (5.8, 36.7, 25) in the palm frame: x → +y, y → −x.
        assert!(
            close(j1.coords, Vector3::new(10.0 - 36.7, 5.8, 75.0)),
            "{j1}"
        );
    }

    #[test]
    fn out_of_range_values_name_their_key() {
        let table: [(&[(&str, f64)], &str); 8] = [
            (&[("palm.offset_mm", -1.0)], "palm.offset_mm"),
            (&[("fingers.gap_mm", 0.0)], "fingers.gap_mm"),
            (&[("palm.margin_mm", -0.5)], "palm.margin_mm"),
            (
                &[("fingers.tip_thickness_mm", 8.0)],
                "fingers.tip_thickness_mm",
            ),
            (
                &[
                    ("phalanx_1.unusable_proximal_mm", 30.0),
                    ("phalanx_1.unusable_distal_mm", 31.0),
                ],
                "phalanx_1",
            ),
            (&[("phalanx_1.length_mm", 400.0)], "phalanx_1.length_mm"),
            (&[("phalanx_2.length_mm", 1e6)], "phalanx_2.length_mm"),
            (&[("palm.margin_mm", 2500.0)], "palm.margin_mm"),
        ];
        for (overrides, expected) in table {
            match thesis(overrides) {
                Err(HandError::Invalid { key, .. }) => assert_eq!(key, expected, "{overrides:?}"),
                other => panic!("{overrides:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn a_mistyped_override_is_named_with_a_suggestion() {
        let table = [
            (
                "palm.offest_mm",
                "names no key of the hand file; did you mean `palm.offset_mm`?",
            ),
            ("name", "is not a number in the hand file"),
            ("palm", "is not a number in the hand file"),
            ("nothing.like.it", "names no key of the hand file"),
        ];
        for (key, expected) in table {
            match thesis(&[(key, 1.0)]) {
                Err(HandError::BadOverride {
                    key: k, problem, ..
                }) => {
                    assert_eq!((k.as_str(), problem.as_str()), (key, expected))
                }
                other => panic!("{key}: {other:?}"),
            }
        }
    }
}
