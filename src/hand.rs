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
pub use geometry::{bend, palm_rotation, BodyPose, HandBox};

/// The hands built into the binary, by name: found wherever grasp-sim runs, without a path.
pub const BUNDLED: [(&str, &str); 2] = [
    ("thesis", include_str!("../assets/hands/thesis.toml")),
    ("bh8", include_str!("../assets/hands/bh8.toml")),
];

/// The bundled hand called `name` (e.g. `thesis`), as `(name, TOML)`.
pub fn bundled(name: &str) -> Option<(&'static str, &'static str)> {
    BUNDLED.iter().copied().find(|(n, _)| *n == name)
}

/// Problems with a hand file.
#[derive(Debug, thiserror::Error)]
pub enum HandError {
    /// The file could not be read.
    #[error("{path}: cannot read hand file: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
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
#[derive(Debug, Clone, PartialEq, Deserialize)]
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
}

/// Palm dimensions.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Palm {
    /// Palm thickness from its centreline to its contact surface `[mm]`.
    pub offset_mm: f64,
    /// Distance from the outer fingers' centrelines to the palm's top and bottom edges `[mm]`.
    pub margin_mm: f64,
    /// Half the palm's width across the fingers' curling direction `[mm]`.
    pub half_width_mm: f64,
}

/// Where the joint-1 axes are and how far each joint turns.
#[derive(Debug, Clone, PartialEq, Deserialize)]
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
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FingerGeometry {
    /// Distance between the centrelines of adjacent fingers along the palm's up axis `[mm]`.
    pub gap_mm: f64,
    /// Distance from a finger's centreline to its contact surface and to its side walls `[mm]`.
    pub offset_mm: f64,
    /// Thickness of the thinned fingertip of phalanx 2 `[mm]` (thesis Fig. 3.8).
    pub tip_thickness_mm: f64,
}

/// One phalanx.
#[derive(Debug, Clone, PartialEq, Deserialize)]
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Joint 1 at +lateral (the palm frame's +Y).
    Left,
    /// Joint 1 at −lateral.
    Right,
}

/// One finger.
#[derive(Debug, Clone, PartialEq, Deserialize)]
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
    /// A finger's width `[mm]`: its centreline to each side wall is the finger offset (thesis
    /// 3.3.2), so no gap narrower than this lets a finger in.
    pub fn finger_width_mm(&self) -> f64 {
        2.0 * self.fingers.offset_mm
    }

    /// Reads and validates a hand file, applying `overrides` (dotted key → number) first.
    ///
    /// # Errors
    /// [`HandError`] naming the file: unreadable, bad TOML, unknown key or wrong type, an override
    /// naming no numeric key, or a value out of range.
    pub fn load(path: &Path, overrides: &[(String, f64)]) -> Result<Hand, HandError> {
        let text = std::fs::read_to_string(path).map_err(|e| HandError::Io {
            path: path.to_path_buf(),
            message: crate::scenario::io_message(&e),
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
            .map_err(|e: toml::de::Error| parse_err(crate::scenario::toml_message(&e, text)))?;
        for (key, value) in overrides {
            set_number(&mut doc, key, *value).map_err(|problem| {
                let mut keys = Vec::new();
                number_keys(&doc, "", &mut keys);
                let problem =
                    match crate::scenario::did_you_mean(key, keys.iter().map(|k| k.as_str())) {
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
                .map_err(|e: toml::de::Error| parse_err(crate::scenario::toml_message(&e, text)))?
        } else {
            toml::Value::Table(doc)
                .try_into()
                .map_err(|e: toml::de::Error| {
                    parse_err(crate::scenario::with_suggestion(
                        &e.message().replace('\n', " "),
                    ))
                })?
        };
        hand.validate(path)?;
        Ok(hand)
    }

    fn validate(&self, path: &Path) -> Result<(), HandError> {
        let bad = |key: &str, problem: String| {
            Err(HandError::Invalid {
                path: path.to_path_buf(),
                key: key.to_string(),
                problem,
            })
        };
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
                return bad(key, format!("must be a positive length, got {v}"));
            }
        }
        let non_negative = [
            ("palm.margin_mm", self.palm.margin_mm),
            ("joints.setback_mm", self.joints.setback_mm),
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
        for (key, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(key, format!("must be zero or positive, got {v}"));
            }
        }
        for (key, p) in [
            ("phalanx_1", &self.phalanx_1),
            ("phalanx_2", &self.phalanx_2),
        ] {
            if p.unusable_proximal_mm + p.unusable_distal_mm >= p.length_mm {
                return bad(key, "unusable lengths leave no contact length".to_string());
            }
        }
        if self.fingers.tip_thickness_mm > self.fingers.offset_mm {
            return bad(
                "fingers.tip_thickness_mm",
                "must not exceed fingers.offset_mm (the tip is thinned, thesis Fig. 3.8)"
                    .to_string(),
            );
        }
        for (key, [lo, hi]) in [
            ("joints.theta1_range_deg", self.joints.theta1_range_deg),
            ("joints.theta2_range_deg", self.joints.theta2_range_deg),
        ] {
            if !(lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < hi && hi <= 180.0) {
                return bad(
                    key,
                    format!("must be [low, high] with 0 < low < high <= 180, got [{lo}, {hi}]"),
                );
            }
        }
        if self.finger_list.is_empty() {
            return bad("finger", "the hand has no fingers".to_string());
        }
        for (i, f) in self.finger_list.iter().enumerate() {
            if self.finger_list[..i].iter().any(|g| g.name == f.name) {
                return bad("finger.name", format!("`{}` appears twice", f.name));
            }
            if !f.height_mm.is_finite() {
                return bad("finger.height_mm", format!("must be finite for {}", f.name));
            }
        }
        // The planner's graspable diameter range must exist: a finger whose phalanx 2 cannot
        // reach back to any object resting on the palm wraps nothing (issue 16, item 1).
        let range = crate::plan::kinematics::graspable_range(self);
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
            return bad(
                "phalanx_1.length_mm",
                format!(
                    "{} mm with phalanx_2.length_mm {} mm and these joint ranges: {what}; shorten \
                     phalanx 1, lengthen phalanx 2 or widen the joint ranges",
                    self.phalanx_1.length_mm, self.phalanx_2.length_mm
                ),
            );
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
