//! One labelled grasp as a JSON line, and a grasp given to check read from one.
//!
//! A label line (DESIGN.md section 6) holds the grasp as a robot would command it, in the
//! object file's frame in millimetres: `palm_pose` (a 4 × 4 rigid transform), the planned
//! `joint_angles_deg` and the `closed_joint_angles_deg` the closing reached, the `axis_name` whose
//! aligned frame the gravity directions refer to, the `planned_contacts_mm` (so that a check of
//! the line sees the collider the planner's check saw), and what the check measured: the nominal
//! `verdict` and `fidelity`, then over `samples` perturbed checks the hold probability and the
//! probability of a hold as planned with their 95 % intervals, overall and per direction.
//!
//! The same line is valid input to `grasp-sim check --grasps` ([`GraspLine::parse`]): its pose,
//! angles, axis and contacts are read; its `grasp_index`, `rules`, `relaxations` and `grade`
//! are carried over to the record written for it, so that checking a label file reproduces it.

use crate::mesh::{AlignedObject, GraspAxis};
use crate::report::json::round_significant;
use crate::report::{Counts, Fidelity, Verdict};
use crate::sim::{Robust, SimHand, SimOutcome};
use nalgebra::{Matrix3, Matrix4, Point3};
use serde::Serialize;

/// A grasp to check: the palm's pose and the joint angles, in the object file's frame, about a
/// named principal axis, with the contacts it was planned to make (if known) and what a label
/// line carries over.
#[derive(Debug, Clone, PartialEq)]
pub struct GraspLine {
    /// The palm pose: rotation (columns the palm's x, y, z axes) and translation (the palm's
    /// centre on its contact surface) in the object file's frame `[mm]`.
    pub palm_pose: [[f64; 4]; 4],
    /// `[θ1, θ2]` per finger, in the hand's order `[deg]`.
    pub joint_angles_deg: Vec<[f64; 2]>,
    /// The principal axis whose aligned frame the check is built in (`least`, `middle-`, ...).
    pub axis: GraspAxis,
    /// The points the grasp was planned to touch, a group per phalanx, file frame `[mm]`.
    pub planned_contacts_mm: Vec<Vec<[f64; 3]>>,
    /// What the line carries over to the record written for it.
    pub carried: Carried,
}

/// What a given line carries over unchanged to the record written for it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Carried {
    /// `grasp_index`, when the line has one.
    pub grasp_index: Option<usize>,
    /// `rules`, as written.
    pub rules: Option<serde_json::Value>,
    /// `relaxations`, as written.
    pub relaxations: Option<serde_json::Value>,
    /// `grade`, as written.
    pub grade: Option<serde_json::Value>,
}

/// How far a rotation's columns may be from orthonormal, and its determinant from 1, for a
/// `palm_pose` to count as rigid (a pose written with 12 significant digits is good to 1e-11).
const RIGID_TOLERANCE: f64 = 1e-6;

/// How far from the file's origin a given palm may be `[mm]` (100 m: farther than any object
/// the planner's work bound admits).
const MAX_POSITION_MM: f64 = 1e5;

/// The joint angles a given grasp may have `[deg]` (interior angles; beyond a turn is no angle).
const MAX_JOINT_DEG: f64 = 360.0;

impl GraspLine {
    /// Reads a given grasp from one JSON line: `palm_pose` as a 4 × 4 nested list (or as the run
    /// report's `{"position_mm", "quaternion_wxyz"}`), `joint_angles_deg` (one `[θ1, θ2]` per
    /// finger of a hand of `fingers`), optional `axis_name` (default `least`) and
    /// `planned_contacts_mm`.
    ///
    /// # Errors
    /// What is wrong with the line, in words: not JSON, a field missing or of the wrong shape, a
    /// number that is not finite, a pose that is not rigid, an unknown axis.
    pub fn parse(line: &str, fingers: usize) -> Result<GraspLine, String> {
        let v = crate::files::parse_json_line(line).map_err(|e| {
            // Python's json.dumps writes NaN and Infinity, which are not JSON.
            let why = e
                .strip_prefix("not JSON (")
                .and_then(|w| w.strip_suffix(')'));
            match why {
                Some(why) if ["NaN", "Infinity"].iter().any(|w| line.contains(w)) => {
                    format!("holds NaN or Infinity, not a finite number (not JSON: {why})")
                }
                _ => e,
            }
        })?;
        let obj = v.as_object().ok_or("not a JSON object")?;
        let palm_pose = palm_pose_of(obj.get("palm_pose").ok_or("no `palm_pose`")?)?;
        let angles = obj.get("joint_angles_deg").ok_or("no `joint_angles_deg`")?;
        let joint_angles_deg = joint_angles_of(angles, fingers)?;
        let axis = match obj.get("axis_name") {
            None | Some(serde_json::Value::Null) => GraspAxis::THESIS,
            Some(serde_json::Value::String(name)) => GraspAxis::from_name(name).ok_or_else(|| {
                format!(
                    "`axis_name` \"{name}\" is none of least, middle, largest (each with - when turned round), arc0, arc90"
                )
            })?,
            Some(_) => return Err("`axis_name` is not a string".into()),
        };
        let planned_contacts_mm = match obj.get("planned_contacts_mm") {
            None | Some(serde_json::Value::Null) => Vec::new(),
            Some(serde_json::Value::Array(bodies)) => bodies
                .iter()
                .map(|b| points(b, "planned_contacts_mm"))
                .collect::<Result<_, _>>()?,
            Some(_) => return Err("`planned_contacts_mm` is not a list".into()),
        };
        let grasp_index = match obj.get("grasp_index") {
            None | Some(serde_json::Value::Null) => None,
            Some(i) => Some(
                i.as_u64()
                    .and_then(|i| usize::try_from(i).ok())
                    .ok_or("`grasp_index` is not a whole number")?,
            ),
        };
        Ok(GraspLine {
            palm_pose,
            joint_angles_deg,
            axis,
            planned_contacts_mm,
            carried: Carried {
                grasp_index,
                rules: obj.get("rules").cloned(),
                relaxations: obj.get("relaxations").cloned(),
                grade: obj.get("grade").cloned(),
            },
        })
    }

    /// The line of the planned grasp `pose` (aligned as `aligned` is), each number rounded as the
    /// JSON writes it: a check of the line as written checks exactly this.
    pub fn of_pose(pose: &SimHand, aligned: &AlignedObject, carried: Carried) -> GraspLine {
        let r = aligned.to_aligned.rotation.inverse().to_rotation_matrix();
        let axes = Matrix3::from_columns(&pose.axes);
        let rot = r.matrix() * axes;
        let t = aligned.to_original(&pose.origin_mm);
        let mut m = [[0.0; 4]; 4];
        for (i, row) in m.iter_mut().enumerate().take(3) {
            for (j, cell) in row.iter_mut().enumerate().take(3) {
                *cell = written(rot[(i, j)]);
            }
            row[3] = written(t[i]);
        }
        m[3][3] = 1.0;
        GraspLine {
            palm_pose: m,
            joint_angles_deg: pose.theta_deg.iter().map(|t| t.map(written)).collect(),
            axis: aligned.axis,
            planned_contacts_mm: pose
                .planned_contacts_mm
                .iter()
                .map(|body| {
                    body.iter()
                        .map(|p| aligned.to_original(p).coords.data.0[0].map(written))
                        .collect()
                })
                .collect(),
            carried,
        }
    }

    /// The hand pose in `aligned`'s frame (which must be aligned about [`GraspLine::axis`]).
    pub fn pose_in(&self, aligned: &AlignedObject) -> SimHand {
        let m = Matrix4::from_fn(|i, j| self.palm_pose[i][j]);
        let rot: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
        let to = aligned.to_aligned.rotation.to_rotation_matrix();
        let axes = to.matrix() * rot;
        let t = Point3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
        SimHand {
            origin_mm: aligned.to_aligned * t,
            axes: [0, 1, 2].map(|j| axes.column(j).into_owned()),
            theta_deg: self.joint_angles_deg.clone(),
            planned_contacts_mm: self
                .planned_contacts_mm
                .iter()
                .map(|body| {
                    body.iter()
                        .map(|p| aligned.to_aligned * Point3::from(*p))
                        .collect()
                })
                .collect(),
        }
    }
}

/// `x` as the JSON writes it back (12 significant digits, float noise around zero as 0).
fn written(x: f64) -> f64 {
    let r = round_significant(x, crate::report::json::JSON_SIGNIFICANT_DIGITS);
    if r.abs() < crate::report::json::JSON_ZERO_BELOW {
        0.0
    } else {
        r
    }
}

/// A finite number, or what is wrong.
fn number(v: &serde_json::Value, what: &str) -> Result<f64, String> {
    let x = v
        .as_f64()
        .ok_or_else(|| format!("`{what}`: {v} is not a number"))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("`{what}`: {x} is not a finite number"))
    }
}

/// A list of exactly `n` numbers.
fn numbers(v: &serde_json::Value, n: usize, what: &str) -> Result<Vec<f64>, String> {
    let list = v
        .as_array()
        .filter(|l| l.len() == n)
        .ok_or_else(|| format!("`{what}`: {} is not a list of {n} numbers", short(v)))?;
    list.iter().map(|x| number(x, what)).collect()
}

/// A JSON value in at most 60 characters, for a message.
fn short(v: &serde_json::Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 60 {
        format!("{}...", s.chars().take(57).collect::<String>())
    } else {
        s
    }
}

/// A given grasp's `palm_pose` (a 4 x 4 nested list or `{position_mm, quaternion_wxyz}`):
/// rigid, and within [`MAX_POSITION_MM`] of the file's origin.
fn palm_pose_of(pose: &serde_json::Value) -> Result<[[f64; 4]; 4], String> {
    let palm_pose = match pose {
        serde_json::Value::Array(_) => matrix4(pose)?,
        serde_json::Value::Object(_) => pose_of_report(pose)?,
        _ => {
            return Err(
                "`palm_pose` is neither a 4 x 4 list nor {position_mm, quaternion_wxyz}".into(),
            )
        }
    };
    check_rigid(&palm_pose)?;
    if let Some(x) = (0..3)
        .map(|i| palm_pose[i][3])
        .find(|x| x.abs() > MAX_POSITION_MM)
    {
        return Err(format!(
            "`palm_pose`'s translation {x} mm is farther than {MAX_POSITION_MM} mm from the file's origin"
        ));
    }
    Ok(palm_pose)
}

/// A given grasp's `joint_angles_deg`: one `[θ1, θ2]` per finger of a hand of `fingers`, each
/// within [`MAX_JOINT_DEG`].
fn joint_angles_of(angles: &serde_json::Value, fingers: usize) -> Result<Vec<[f64; 2]>, String> {
    let joint_angles_deg = pairs(angles, "joint_angles_deg")?;
    if joint_angles_deg.len() != fingers {
        return Err(format!(
            "`joint_angles_deg` has {} fingers' angles, the hand has {fingers} fingers",
            joint_angles_deg.len()
        ));
    }
    if let Some(a) = joint_angles_deg
        .iter()
        .flatten()
        .find(|a| a.abs() > MAX_JOINT_DEG)
    {
        return Err(format!(
            "`joint_angles_deg`: {a}° is outside [-{MAX_JOINT_DEG}°, {MAX_JOINT_DEG}°]"
        ));
    }
    Ok(joint_angles_deg)
}

/// A 4 × 4 nested list of numbers.
fn matrix4(v: &serde_json::Value) -> Result<[[f64; 4]; 4], String> {
    let rows = v
        .as_array()
        .filter(|r| r.len() == 4)
        .ok_or("`palm_pose` is not a list of 4 rows")?;
    let mut m = [[0.0; 4]; 4];
    for (row, r) in m.iter_mut().zip(rows) {
        let r = numbers(r, 4, "palm_pose")?;
        row.copy_from_slice(&r);
    }
    Ok(m)
}

/// The run report's `{"position_mm": [x, y, z], "quaternion_wxyz": [w, x, y, z]}` as a 4 × 4.
fn pose_of_report(v: &serde_json::Value) -> Result<[[f64; 4]; 4], String> {
    let p = numbers(
        v.get("position_mm")
            .ok_or("`palm_pose` has no `position_mm`")?,
        3,
        "palm_pose.position_mm",
    )?;
    let q = numbers(
        v.get("quaternion_wxyz")
            .ok_or("`palm_pose` has no `quaternion_wxyz`")?,
        4,
        "palm_pose.quaternion_wxyz",
    )?;
    let quat = nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]);
    if (quat.norm() - 1.0).abs() > RIGID_TOLERANCE {
        return Err(format!(
            "`palm_pose.quaternion_wxyz` has norm {}, not 1: not a rotation",
            quat.norm()
        ));
    }
    let r = nalgebra::UnitQuaternion::from_quaternion(quat).to_rotation_matrix();
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate().take(3) {
        for (j, cell) in row.iter_mut().enumerate().take(3) {
            *cell = r[(i, j)];
        }
        row[3] = p[i];
    }
    m[3][3] = 1.0;
    Ok(m)
}

/// `Ok` if and only if `m` is a rigid transform: its rotation orthonormal and right-handed,
/// its last row `[0, 0, 0, 1]`.
fn check_rigid(m: &[[f64; 4]; 4]) -> Result<(), String> {
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(format!(
            "`palm_pose`'s last row is {:?}, not [0, 0, 0, 1]: not a rigid transform",
            m[3]
        ));
    }
    let r = Matrix3::from_fn(|i, j| m[i][j]);
    let off = (r.transpose() * r - Matrix3::identity()).abs().max();
    if off > RIGID_TOLERANCE {
        return Err(format!(
            "`palm_pose`'s rotation is not orthonormal (RᵀR differs from I by {off:.3e}): not a rigid transform"
        ));
    }
    let det = r.determinant();
    if (det - 1.0).abs() > RIGID_TOLERANCE {
        return Err(format!(
            "`palm_pose`'s rotation has determinant {det:.6}, not 1: a reflection, not a rigid transform"
        ));
    }
    Ok(())
}

/// A list of `[a, b]` pairs of finite numbers.
fn pairs(v: &serde_json::Value, what: &str) -> Result<Vec<[f64; 2]>, String> {
    let list = v
        .as_array()
        .ok_or_else(|| format!("`{what}` is not a list of [theta1, theta2] pairs"))?;
    list.iter()
        .map(|p| {
            let p = numbers(p, 2, what)?;
            Ok([p[0], p[1]])
        })
        .collect()
}

/// A list of `[x, y, z]` points of finite numbers.
fn points(v: &serde_json::Value, what: &str) -> Result<Vec<[f64; 3]>, String> {
    let list = v
        .as_array()
        .ok_or_else(|| format!("`{what}`: a group is not a list of points"))?;
    list.iter()
        .map(|p| {
            let p = numbers(p, 3, what)?;
            Ok([p[0], p[1], p[2]])
        })
        .collect()
}

/// One labelled grasp: the JSON line `grasp-sim label` and `grasp-sim check --grasps` write.
#[derive(Debug, Clone, Serialize)]
pub struct LabelRecord {
    /// The scenario's name.
    pub object: String,
    /// The grasp's place in the planner's search order (0: the planner's first); for a given
    /// grasp, the line's own `grasp_index`, else its line number from 0.
    pub grasp_index: usize,
    /// The palm pose, object file frame, 4 × 4 `[mm]`.
    pub palm_pose: [[f64; 4]; 4],
    /// The planned `[θ1, θ2]` per finger `[deg]`.
    pub joint_angles_deg: Vec<[f64; 2]>,
    /// Where the nominal check's closing left the joints `[deg]`: the set to command.
    pub closed_joint_angles_deg: Vec<[f64; 2]>,
    /// The principal axis whose aligned frame the gravity directions refer to.
    pub axis_name: String,
    /// `thesis` or `extended` (a planned grasp's; a given line's as written).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rules: Option<serde_json::Value>,
    /// The thesis rules the grasp relaxed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relaxations: Option<serde_json::Value>,
    /// The planner's grade of the grasp ([`super::Grade`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grade: Option<serde_json::Value>,
    /// The points the grasp was planned to touch, a group per phalanx, file frame `[mm]`.
    pub planned_contacts_mm: Vec<Vec<[f64; 3]>>,
    /// The nominal check's verdict: what gravity did.
    pub verdict: Verdict,
    /// The nominal check's fidelity.
    pub fidelity: Fidelity,
    /// The nominal check's worst translation `[mm]`.
    pub translation_mm: f64,
    /// The nominal check's worst rotation `[deg]`.
    pub rotation_deg: f64,
    /// Perturbed checks run.
    pub samples: usize,
    /// Their verdicts.
    pub counts: Counts,
    /// Samples held in every direction / samples.
    pub hold_probability: f64,
    /// Its 95 % Wilson interval.
    pub interval: [f64; 2],
    /// Samples held in every direction with a closing as planned.
    pub held_as_planned: usize,
    /// `held_as_planned / samples`.
    pub as_planned_probability: f64,
    /// Its 95 % Wilson interval.
    pub as_planned_interval: [f64; 2],
    /// Per gravity direction.
    pub directions: Vec<DirectionLabel>,
    /// Physics steps of the nominal check and the samples.
    pub steps: usize,
    /// Where the line came from and when.
    pub label: LabelInfo,
}

/// One gravity direction of a labelled grasp.
#[derive(Debug, Clone, Serialize)]
pub struct DirectionLabel {
    /// Gravity direction (unit, the axis's aligned frame).
    pub gravity: [f64; 3],
    /// The nominal check's verdict under it.
    pub verdict: Verdict,
    /// The samples' verdicts under it.
    pub counts: Counts,
    /// Samples held under it with a closing as planned.
    pub held_as_planned: usize,
    /// Samples held under it / samples.
    pub hold_probability: f64,
}

/// What identifies a label line: its input as the command saw it, the hash of what decides its
/// result (as `batch`'s), how many grasps the object's run labels, and the time it took.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct LabelInfo {
    /// The input path.
    pub input: String,
    /// `sha256:` and the digest of the input, its template, the flags and the version.
    pub input_hash: String,
    /// Grasps the object's run labels (its lines with a `grasp_index`).
    pub grasps: usize,
    /// Wall time of this grasp's checks `[ms]` (a timing: it differs run to run).
    pub wall_ms: f64,
}

impl LabelRecord {
    /// The record of a checked grasp: `line` as checked, the nominal check `nominal` and the
    /// samples `robust`.
    pub fn of(
        object: &str,
        index: usize,
        line: &GraspLine,
        nominal: &SimOutcome,
        robust: &Robust,
        label: LabelInfo,
    ) -> LabelRecord {
        let directions = nominal
            .directions
            .iter()
            .zip(&robust.directions)
            .map(|(n, r)| DirectionLabel {
                gravity: n.gravity,
                verdict: n.verdict.into(),
                counts: (&r.counts).into(),
                held_as_planned: r.held_as_planned,
                hold_probability: r.hold_probability,
            })
            .collect();
        LabelRecord {
            object: object.to_string(),
            grasp_index: line.carried.grasp_index.unwrap_or(index),
            palm_pose: line.palm_pose,
            joint_angles_deg: line.joint_angles_deg.clone(),
            closed_joint_angles_deg: nominal
                .closing
                .fingers
                .iter()
                .map(|f| f.final_deg)
                .collect(),
            axis_name: line.axis.name(),
            rules: line.carried.rules.clone(),
            relaxations: line.carried.relaxations.clone(),
            grade: line.carried.grade.clone(),
            planned_contacts_mm: line.planned_contacts_mm.clone(),
            verdict: nominal.verdict.into(),
            fidelity: (&nominal.fidelity).into(),
            translation_mm: nominal.translation_mm,
            rotation_deg: nominal.rotation_deg,
            samples: robust.samples,
            counts: (&robust.counts).into(),
            hold_probability: robust.hold_probability,
            interval: robust.interval,
            held_as_planned: robust.held_as_planned,
            as_planned_probability: robust.as_planned_probability,
            as_planned_interval: robust.as_planned_interval,
            directions,
            steps: nominal.steps + robust.steps,
            label,
        }
    }
}

/// A line for something that could not be labelled: a grasp line that cannot be checked (with
/// its `grasp_index`), or an object that could not be run (without).
#[derive(Debug, Clone, Serialize)]
pub struct ErrorRecord {
    /// The scenario's name, or the input's path.
    pub object: String,
    /// The grasp's index (its line number from 0 for a given grasp); absent for the object.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grasp_index: Option<usize>,
    /// What is wrong, in one line.
    pub error: String,
    /// Where it came from.
    pub label: LabelInfo,
}

/// A line for an object with no feasible grasp to label.
#[derive(Debug, Clone, Serialize)]
pub struct UngraspableRecord {
    /// The scenario's name.
    pub object: String,
    /// Why the planner found no grasp.
    pub ungraspable: String,
    /// Where it came from.
    pub label: LabelInfo,
}
