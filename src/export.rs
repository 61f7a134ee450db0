//! Exporting a planned grasp for other tools: an MJCF scene for MuJoCo and a URDF of the hand.
//!
//! Units: metres, kilograms, radians (MuJoCo's and URDF's). Frames: the aligned object frame of
//! grasp-sim (principal axis +Z, gravity along −Z). Every joint's angle is the thesis's bend
//! (180° − θ) about `(0, 0, side)` in its parent's frame, exactly as in the rapier scene
//! (`crate::sim`), so a joint value read in either engine means the same thing.
//!
//! The MJCF scene: the palm welded to the world at the planned pose (a body without joints);
//! per finger two phalanx bodies with hinge joints (the hand's limits) and position actuators with
//! the rapier check's gains and torque limit (`forcerange`); the object as a free body with its
//! mesh (the convex decomposition's parts when the check used one) and an explicit inertial from
//! grasp-sim's mass properties; keyframes `open` (where the check starts) and `planned` (the
//! planned joint angles); gravity as in the scenario. `protocol.json` beside it carries what the
//! replay script needs to run the same protocol (scripts/mujoco_replay.py).

use crate::hand::{bend, palm_rotation, Hand, HandBox};
use crate::mesh::{AlignedObject, Mesh};
use crate::sim::params::{GravityMode, SimParams};
use crate::sim::scene::Start;
use crate::sim::Case;
use nalgebra::{Point3, UnitQuaternion, Vector3};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Problems writing an export.
///
/// Its message names the file and the reason, the I/O error: `{path}: cannot write: {reason}`
/// (not the error's `source()`, so that a chain printed whole says the reason once).
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot write: {}", crate::messages::io_message(.error))]
pub struct ExportError {
    /// The file or folder.
    pub path: PathBuf,
    /// What the operating system said.
    pub error: std::io::Error,
}

/// Everything an export needs about the grasp.
pub struct ExportInput<'a> {
    /// Scenario name (the MJCF model name).
    pub name: &'a str,
    /// The aligned object (its mesh is written beside the XML).
    pub object: &'a AlignedObject,
    /// The physics check the scene mirrors: hand, pose, collision shape, mass, friction and
    /// protocol parameters.
    pub case: Case<'a>,
}

/// Metres per millimetre: the one conversion the rapier scene uses too.
const MM: f64 = crate::sim::convert::M_PER_MM;

/// MuJoCo's timestep in the exported scene `[s]`. The thesis hand's phalanx 2 (a 14 × 20 ×
/// 14 mm box of 3.9 g, 5.9e-7 kg·m² about its joint) on its 20 N·m/rad servo has a natural
/// frequency of 5,800 rad/s. Where `forcerange` caps that servo, `implicitfast` (which
/// linearises the servo's damping into its step) makes joint 2's velocity alternate from step
/// to step unless ω·dt is small: at 0.2 ms (ω·dt 1.2) phalanx 2 swung between 0 and 170 rad/s,
/// 19.5° in 4 ms where the motor law (`clamp(kp·e − kv·ω, ±τ)`, integrated at 1 µs) swings
/// it 7.5°, and struck objects out of the hand; at 0.05 ms it was still 6.9° off under a 1 N·m
/// cap. At 0.025 ms (ω·dt 0.15) a lone phalanx 2 follows the law within 0.4°
/// (docs/studies/2026-12-06-mujoco-timestep.md, `scripts/mujoco_servo_step.py`).
pub const MUJOCO_TIMESTEP_S: f64 = 2.5e-5;

/// The time constant of MuJoCo's contacts (`solref`) `[s]`: 0.4 ms, the contact stiffness
/// every replay has used, independent of the step (MuJoCo asks for at least twice the step).
pub const MUJOCO_CONTACT_TIMECONST_S: f64 = 4e-4;

/// Iterations of MuJoCo's noslip solver in the exported scene. MuJoCo's friction is a soft
/// constraint: under a steady tangential load a held object creeps (MuJoCo's documentation of
/// `noslip_iterations`: a post-processing PGS pass "to suppress slip/drift in friction
/// dimensions resulting from the soft-constraint model"). rapier's Coulomb friction does not
/// creep, so without it the replay judged `slip` grasps that both engines hold in position: a
/// milk carton crept 6.1 mm in 2 s, a thermos 8.2 mm (docs/MUJOCO.md). With 10 iterations they
/// move 0.3 and 0.1 mm, and every bundled scenario keeps its verdict (the weak-motor cup still
/// drops, the weak-motor chapter 4 object still slips).
pub const MUJOCO_NOSLIP_ITERATIONS: usize = 10;

fn v3(v: &Vector3<f64>) -> String {
    format!("{:.9} {:.9} {:.9}", v.x, v.y, v.z)
}

fn quat(q: &UnitQuaternion<f64>) -> String {
    format!("{:.12} {:.12} {:.12} {:.12}", q.w, q.i, q.j, q.k)
}

/// An MJCF box geom `name` of `b` (millimetres, written in metres), with `extra` attributes.
fn box_geom(s: &mut String, indent: &str, name: &str, b: &HandBox, extra: &str) {
    let _ = writeln!(
        s,
        "{indent}<geom name=\"{name}\" type=\"box\" size=\"{}\" pos=\"{}\"{extra}/>",
        v3(&(b.half_extents * MM)),
        v3(&(b.centre * MM))
    );
}

/// Writes `scene.xml`, the object's mesh file(s) and `protocol.json` into `dir`.
///
/// # Errors
/// [`ExportError`] naming the file that could not be written.
pub fn write_mjcf(dir: &Path, input: &ExportInput) -> Result<(), ExportError> {
    std::fs::create_dir_all(dir).map_err(|e| io_error(dir, e))?;
    let case = &input.case;
    let meshes = object_meshes(input);
    for (name, mesh) in &meshes {
        let path = dir.join(format!("{name}.stl"));
        crate::files::write_replacing(&path, &mesh.to_binary_stl())
            .map_err(|e| io_error(&path, e))?;
    }
    // Where the rapier check starts: the palm backed off and the fingers opened clear of the
    // object's collider (`sim::scene::start`).
    let start = crate::sim::scene::start(case);
    let keys = Keyframes::new(case, &start);

    let mut s = String::new();
    let _ = writeln!(s, "<mujoco model=\"grasp-sim {}\">", xml_attr(input.name));
    mjcf_options(&mut s, case, &meshes);
    let _ = writeln!(s, "  <worldbody>");
    mjcf_hand(&mut s, case, &start);
    mjcf_object(&mut s, case, &meshes);
    let _ = writeln!(s, "  </worldbody>");
    mjcf_contacts(&mut s, case.hand);
    mjcf_actuators(&mut s, case);
    keys.write(&mut s);
    let _ = writeln!(s, "</mujoco>");
    let path = dir.join("scene.xml");
    crate::files::write_replacing(&path, s.as_bytes()).map_err(|e| io_error(&path, e))?;

    let path = dir.join("protocol.json");
    crate::files::write_replacing(
        &path,
        serde_json::to_string_pretty(&protocol(input, &keys))
            .unwrap_or_default()
            .as_bytes(),
    )
    .map_err(|e| io_error(&path, e))?;
    Ok(())
}

/// `text` as the value of an XML attribute in double quotes: a scenario's name may hold `"`,
/// `<` or `&`.
fn xml_attr(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn io_error(path: &Path, e: std::io::Error) -> ExportError {
    ExportError {
        path: path.to_path_buf(),
        error: e,
    }
}

/// The joint ranges as bends `[(lo1, hi1), (lo2, hi2)]` `[rad]`.
fn bend_limits(hand: &Hand) -> [(f64, f64); 2] {
    let lim = |r: [f64; 2]| (bend(r[1]), bend(r[0]));
    [
        lim(hand.joints.theta1_range_deg),
        lim(hand.joints.theta2_range_deg),
    ]
}

/// The object's meshes, in metres: the convex decomposition's parts when the check used one,
/// else the aligned mesh.
fn object_meshes(input: &ExportInput) -> Vec<(String, Mesh)> {
    let mut meshes: Vec<(String, Mesh)> = Vec::new();
    match input.case.object.shape.as_compound() {
        Some(compound) => {
            for (k, (pose, part)) in compound.shapes().iter().enumerate() {
                if let Some(poly) = part.as_convex_polyhedron() {
                    // Where the part's pose puts it (a decomposition moved into another axis's
                    // frame: `ObjectShape::moved`).
                    let points: Vec<Point3<f64>> = poly
                        .points()
                        .iter()
                        .map(|p| *pose * *p)
                        .map(|p| Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
                        .collect();
                    let soup: Vec<[Point3<f64>; 3]> = poly
                        .to_trimesh()
                        .1
                        .iter()
                        .map(|t| {
                            [
                                points[t[0] as usize],
                                points[t[1] as usize],
                                points[t[2] as usize],
                            ]
                        })
                        .collect();
                    meshes.push((format!("object_part_{k}"), Mesh::from_triangles(&soup).0));
                }
            }
        }
        None => {
            let mut mesh = input.object.mesh.clone();
            mesh.map_vertices(|p| p * MM);
            meshes.push(("object".to_string(), mesh));
        }
    }
    meshes
}

/// `<compiler>`, `<option>`, `<default>` and `<asset>`.
fn mjcf_options(s: &mut String, case: &Case, meshes: &[(String, Mesh)]) {
    let g = match case.params.gravity {
        GravityMode::Down | GravityMode::Six => "0 0 -9.81",
    };
    let _ = writeln!(s, "  <compiler angle=\"radian\" autolimits=\"true\"/>");
    // MuJoCo integrates actuator stiffness explicitly: a 20–200 N·m/rad servo on a phalanx of
    // 5.9e-7–3.5e-5 kg·m² (natural frequencies 2,400–5,800 rad/s) is unstable at rapier's 1 ms
    // step, so the scene uses MuJoCo's `implicitfast` integrator and a step with ω·dt ≤ 0.15
    // (`MUJOCO_TIMESTEP_S`).
    let _ = writeln!(
        s,
        "  <option timestep=\"{MUJOCO_TIMESTEP_S}\" integrator=\"implicitfast\" gravity=\"{g}\" cone=\"elliptic\" impratio=\"10\" noslip_iterations=\"{MUJOCO_NOSLIP_ITERATIONS}\"/>"
    );
    let _ = writeln!(s, "  <default>");
    let _ = writeln!(
        s,
        "    <geom friction=\"{} 0 0\" condim=\"3\" solref=\"{:.6} 1\"/>",
        case.friction, MUJOCO_CONTACT_TIMECONST_S
    );
    let _ = writeln!(s, "  </default>");
    let _ = writeln!(s, "  <asset>");
    for (name, _) in meshes {
        let _ = writeln!(s, "    <mesh name=\"{name}\" file=\"{name}.stl\"/>");
    }
    // A hand file's own link meshes (issue 37): each piece's vertices, whose convex hull
    // MuJoCo takes, as the rapier check does.
    for (name, piece) in hand_pieces(case.hand) {
        let v: Vec<String> = piece.iter().map(|p| v3(&(p.coords * MM))).collect();
        let _ = writeln!(s, "    <mesh name=\"{name}\" vertex=\"{}\"/>", v.join(" "));
    }
    let _ = writeln!(s, "  </asset>");
}

/// The hand's link-mesh pieces ([`crate::hand::link_geometry`]) with their MJCF mesh names
/// (`hand_<body>_<n>`), in body order (palm, then each finger's phalanx 1 and 2).
fn hand_pieces(hand: &Hand) -> Vec<(String, &[nalgebra::Point3<f64>])> {
    let Some(g) = hand.link_geometry.as_deref() else {
        return Vec::new();
    };
    let mut names = vec!["palm".to_string()];
    for f in &hand.finger_list {
        names.push(format!("{}_phalanx_1", f.name));
        names.push(format!("{}_phalanx_2", f.name));
    }
    let mut out = Vec::new();
    for (k, body) in names.iter().enumerate() {
        for (n, piece) in g.body(k).iter().enumerate() {
            out.push((format!("hand_{body}_{n}"), piece.as_slice()));
        }
    }
    out
}

/// Writes body `body`'s geoms: its link-mesh pieces where it has them, else the model's boxes
/// (`boxes`, each with its geom name).
fn hand_body_geoms(
    s: &mut String,
    indent: &str,
    hand: &Hand,
    body: &str,
    boxes: &[(String, HandBox)],
    extra: &str,
) {
    let pieces: Vec<String> = hand_pieces(hand)
        .into_iter()
        .map(|(name, _)| name)
        .filter(|name| {
            name.strip_prefix(&format!("hand_{body}_"))
                .is_some_and(|n| n.bytes().all(|b| b.is_ascii_digit()))
        })
        .collect();
    if pieces.is_empty() {
        for (name, b) in boxes {
            box_geom(s, indent, name, b, extra);
        }
    }
    for name in pieces {
        let _ = writeln!(
            s,
            "{indent}<geom name=\"{name}\" type=\"mesh\" mesh=\"{name}\"{extra}/>"
        );
    }
}

/// The palm body welded at the start pose, and each finger's two phalanx bodies with their
/// hinges, nested in it.
fn mjcf_hand(s: &mut String, case: &Case, start: &Start) {
    let hand = case.hand;
    let [(lo1, hi1), (lo2, hi2)] = bend_limits(hand);
    let _ = writeln!(
        s,
        "    <body name=\"palm\" pos=\"{}\" quat=\"{}\">",
        v3(&(start.origin_mm.coords * MM)),
        quat(&palm_rotation(&case.pose.axes))
    );
    let palm = [("palm".to_string(), hand.palm_box())];
    hand_body_geoms(s, "      ", hand, "palm", &palm, "");
    let density = format!(" density=\"{}\"", case.params.fingers.finger_density_kg_m3);
    for f in &hand.finger_list {
        let sd = f.side.sign();
        let n = &f.name;
        let (p1, p2) = hand.phalanx_boxes(f.side);
        let anchor = hand.joint1_anchor_mm(f) * MM;
        let _ = writeln!(
            s,
            "      <body name=\"{n}_phalanx_1\" pos=\"{}\">",
            v3(&anchor)
        );
        let _ = writeln!(
            s,
            "        <joint name=\"{n}_joint_1\" type=\"hinge\" axis=\"0 0 {sd}\" range=\"{lo1:.9} {hi1:.9}\" damping=\"0\"/>"
        );
        let body = format!("{n}_phalanx_1");
        hand_body_geoms(s, "        ", hand, &body, &[(body.clone(), p1)], &density);
        let _ = writeln!(
            s,
            "        <body name=\"{n}_phalanx_2\" pos=\"{}\">",
            v3(&(hand.joint2_anchor_mm(f.side) * MM))
        );
        let _ = writeln!(
            s,
            "          <joint name=\"{n}_joint_2\" type=\"hinge\" axis=\"0 0 {sd}\" range=\"{lo2:.9} {hi2:.9}\" damping=\"0\"/>"
        );
        // The contact part of phalanx 2, then its thinned tip if it has one.
        let boxes: Vec<(String, HandBox)> = p2
            .iter()
            .zip(["phalanx_2", "tip"])
            .map(|(b, part)| (format!("{n}_{part}"), *b))
            .collect();
        hand_body_geoms(
            s,
            "          ",
            hand,
            &format!("{n}_phalanx_2"),
            &boxes,
            &density,
        );
        let _ = writeln!(s, "        </body>");
        let _ = writeln!(s, "      </body>");
    }
    let _ = writeln!(s, "    </body>");
}

/// The object: free, at the origin of the aligned frame, with the mass distribution the rapier
/// check gives it: its collider's (convex hull or decomposition) at the scenario's mass. (The
/// mesh's own surface integral is no inertia at all for an open mesh.)
fn mjcf_object(s: &mut String, case: &Case, meshes: &[(String, Mesh)]) {
    let (c, inertia) = crate::sim::collider_inertia(case.object, case.mass_kg);
    let _ = writeln!(s, "    <body name=\"object\" pos=\"0 0 0\">");
    let _ = writeln!(s, "      <freejoint name=\"object\"/>");
    let _ = writeln!(
        s,
        "      <inertial pos=\"{}\" mass=\"{:.9}\" fullinertia=\"{:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e}\"/>",
        v3(&c),
        case.mass_kg,
        inertia[(0, 0)],
        inertia[(1, 1)],
        inertia[(2, 2)],
        inertia[(0, 1)],
        inertia[(0, 2)],
        inertia[(1, 2)]
    );
    for (name, _) in meshes {
        let _ = writeln!(
            s,
            "      <geom name=\"{name}\" type=\"mesh\" mesh=\"{name}\" mass=\"0\"/>"
        );
    }
    let _ = writeln!(s, "    </body>");
}

/// The hand's bodies collide as in the rapier check: everything but the pairs a joint joins
/// (the palm and each phalanx 1, each phalanx 1 and its phalanx 2), so fingers meet each other
/// and phalanx 2 the palm where they reach them. MuJoCo only filters parent-child pairs, and
/// not those of a body welded to the world such as the palm, so the jointed pairs are listed.
fn mjcf_contacts(s: &mut String, hand: &Hand) {
    let _ = writeln!(s, "  <contact>");
    for f in &hand.finger_list {
        let (p1, p2) = (
            format!("{}_phalanx_1", f.name),
            format!("{}_phalanx_2", f.name),
        );
        for (a, b) in [("palm", p1.as_str()), (p1.as_str(), p2.as_str())] {
            let _ = writeln!(s, "    <exclude body1=\"{a}\" body2=\"{b}\"/>");
        }
    }
    let _ = writeln!(s, "  </contact>");
}

/// A position actuator per joint, with the rapier check's gains and torque limit.
fn mjcf_actuators(s: &mut String, case: &Case) {
    let sim = case.params;
    let limits = bend_limits(case.hand);
    let (kp, kv) = (
        sim.fingers.motor_stiffness_nm_per_rad,
        sim.fingers.motor_damping_nms_per_rad,
    );
    let torques = crate::sim::scene::finger_torque_limits(case.hand, sim);
    let _ = writeln!(s, "  <actuator>");
    for (f, tau) in case.hand.finger_list.iter().zip(torques) {
        for (j, (lo, hi)) in [(1, limits[0]), (2, limits[1])] {
            let _ = writeln!(
                s,
                "    <position name=\"{n}_joint_{j}\" joint=\"{n}_joint_{j}\" kp=\"{kp}\" kv=\"{kv}\" forcerange=\"{:.6} {tau:.6}\" ctrlrange=\"{lo:.9} {hi:.9}\"/>",
                -tau,
                n = f.name
            );
        }
    }
    let _ = writeln!(s, "  </actuator>");
}

/// The joint values of the keyframes, two per finger, as bends `[rad]`.
struct Keyframes {
    /// Where the check starts.
    open: Vec<f64>,
    /// The planned angles.
    planned: Vec<f64>,
    /// The motor targets: planned plus the squeeze, within the limits.
    ctrl: Vec<f64>,
}

impl Keyframes {
    fn new(case: &Case, start: &Start) -> Keyframes {
        let sim = case.params;
        let [(lo1, hi1), (lo2, hi2)] = bend_limits(case.hand);
        let mut k = Keyframes {
            open: Vec::new(),
            planned: Vec::new(),
            ctrl: Vec::new(),
        };
        for ([t1, t2], [o1, o2]) in start.theta_deg.iter().zip(&start.open_bend_rad) {
            let (b1, b2) = (bend(*t1), bend(*t2));
            k.open.push(*o1);
            k.open.push(*o2);
            k.planned.push(b1);
            k.planned.push(b2);
            k.ctrl
                .push((b1 + sim.fingers.squeeze_deg.to_radians()).clamp(lo1, hi1));
            k.ctrl
                .push((b2 + sim.fingers.squeeze2_deg.to_radians()).clamp(lo2, hi2));
        }
        k
    }

    /// `<keyframe>`: `open` and `planned`; the object's free joint at rest at the origin.
    fn write(&self, s: &mut String) {
        let join = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.9}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let _ = writeln!(s, "  <keyframe>");
        let _ = writeln!(
            s,
            "    <key name=\"open\" qpos=\"{} 0 0 0 1 0 0 0\" ctrl=\"{}\"/>",
            join(&self.open),
            join(&self.open)
        );
        let _ = writeln!(
            s,
            "    <key name=\"planned\" qpos=\"{} 0 0 0 1 0 0 0\" ctrl=\"{}\"/>",
            join(&self.planned),
            join(&self.ctrl)
        );
        let _ = writeln!(s, "  </keyframe>");
    }
}

/// `protocol.json`: what scripts/mujoco_replay.py needs to run the check's protocol.
fn protocol(input: &ExportInput, keys: &Keyframes) -> serde_json::Value {
    let case = &input.case;
    let sim = case.params;
    serde_json::json!({
        "scenario": input.name,
        "fingers": case.hand.finger_list.iter().map(|f| f.name.clone()).collect::<Vec<_>>(),
        "planned_bend_rad": keys.planned,
        "open_bend_rad": keys.open,
        "target_bend_rad": keys.ctrl,
        "close_duration_s": sim.closing.close_duration_s,
        "close_until_stalled": sim.closing.close_until_stalled,
        "stall": {
            "joint_rad_s": crate::sim::STALL.joint_rad_s,
            "object_mm_s": crate::sim::STALL.object_mm_s,
            "object_rad_s": crate::sim::STALL.object_rad_s,
            "window_s": crate::sim::STALL.window_s,
        },
        "duration_s": sim.hold.duration_s,
        "joint1_lock_torque_nm": sim.fingers.joint1_lock_torque_nm,
        "motor_stiffness_nm_per_rad": sim.fingers.motor_stiffness_nm_per_rad,
        "hold_translation_mm": sim.hold.hold_translation_mm,
        "hold_rotation_deg": sim.hold.hold_rotation_deg,
        "max_closing_shift_mm": sim.hold.max_closing_shift_mm,
        "min_on_plan_fraction": sim.hold.min_on_plan_fraction,
        "max_penetration_mm": sim.hold.max_penetration_mm,
        "approach": sim.closing.approach,
        "reseat": sim.closing.reseat,
        "reseat_only_lifted": sim.closing.reseat_only_lifted,
        "ramp_s": crate::sim::RAMP_S,
        "reseat_rad_s": crate::sim::RESEAT_RAD_S,
        "gravity": match sim.gravity { GravityMode::Down => "down", GravityMode::Six => "six" },
        "is_revolution": case.object.is_revolution,
        "mass_kg": case.mass_kg,
        "friction": case.friction,
    })
}

/// Writes a URDF link of one box `size` at `at` in its frame `[m]`, of density `rho`
/// `[kg/m³]`: its inertial (a solid box's), visual and collision.
fn urdf_box_link(s: &mut String, name: &str, size: Vector3<f64>, at: Vector3<f64>, rho: f64) {
    let mass = rho * size.x * size.y * size.z;
    let (ixx, iyy, izz) = (
        mass * (size.y * size.y + size.z * size.z) / 12.0,
        mass * (size.x * size.x + size.z * size.z) / 12.0,
        mass * (size.x * size.x + size.y * size.y) / 12.0,
    );
    let geometry = format!(
        "<origin xyz=\"{}\"/><geometry><box size=\"{}\"/></geometry>",
        v3(&at),
        v3(&size)
    );
    let _ = writeln!(s, "  <link name=\"{name}\">");
    let _ = writeln!(
        s,
        "    <inertial><origin xyz=\"{}\"/><mass value=\"{mass:.9}\"/><inertia ixx=\"{ixx:.6e}\" ixy=\"0\" ixz=\"0\" iyy=\"{iyy:.6e}\" iyz=\"0\" izz=\"{izz:.6e}\"/></inertial>",
        v3(&at)
    );
    let _ = writeln!(s, "    <visual>{geometry}</visual>");
    let _ = writeln!(s, "    <collision>{geometry}</collision>");
    let _ = writeln!(s, "  </link>");
}

/// Writes a revolute URDF joint `name` from `links.0` to `links.1` at `origin` `[m]`, about
/// `(0, 0, side)`, within the bends `range` `[rad]`, with the motors' torque limit `[N·m]`.
fn urdf_joint(
    s: &mut String,
    name: &str,
    (parent, child): (&str, &str),
    origin: Vector3<f64>,
    sd: f64,
    range: (f64, f64),
    torque_limit_nm: f64,
) {
    let _ = writeln!(s, "  <joint name=\"{name}\" type=\"revolute\">");
    let _ = writeln!(
        s,
        "    <parent link=\"{parent}\"/><child link=\"{child}\"/>"
    );
    let _ = writeln!(s, "    <origin xyz=\"{}\" rpy=\"0 0 0\"/>", v3(&origin));
    let _ = writeln!(s, "    <axis xyz=\"0 0 {sd}\"/>");
    let _ = writeln!(
        s,
        "    <limit lower=\"{:.9}\" upper=\"{:.9}\" effort=\"{}\" velocity=\"10\"/>",
        range.0, range.1, torque_limit_nm
    );
    let _ = writeln!(s, "  </joint>");
}

/// Writes the hand (palm and six phalanges, revolute joints with limits and effort) as
/// `hand.urdf` into `dir`, in the palm frame, joints at their zero (straight) bend.
///
/// # Errors
/// [`ExportError`] naming the file that could not be written.
pub fn write_urdf(dir: &Path, hand: &Hand, sim: &SimParams) -> Result<(), ExportError> {
    std::fs::create_dir_all(dir).map_err(|e| io_error(dir, e))?;
    let o = hand.fingers.offset_mm * MM;
    let l2 = hand.phalanx_2.length_mm * MM;
    let rho = sim.fingers.finger_density_kg_m3;
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(s, "<robot name=\"{}\">", hand.name);
    let boxed = |s: &mut String, name: &str, size: Vector3<f64>, at: Vector3<f64>| {
        urdf_box_link(s, name, size, at, rho);
    };
    let palm = hand.palm_box();
    boxed(
        &mut s,
        "palm",
        palm.half_extents * (2.0 * MM),
        palm.centre * MM,
    );
    let lim = |r: [f64; 2]| (bend(r[1]), bend(r[0]));
    for f in &hand.finger_list {
        let sd = f.side.sign();
        let n = &f.name;
        let (p1, _) = hand.phalanx_boxes(f.side);
        boxed(
            &mut s,
            &format!("{n}_phalanx_1"),
            p1.half_extents * (2.0 * MM),
            p1.centre * MM,
        );
        // Phalanx 2 as one box over its whole length: the URDF leaves out the thinned tip.
        boxed(
            &mut s,
            &format!("{n}_phalanx_2"),
            Vector3::new(2.0 * o, l2, 2.0 * o),
            Vector3::new(0.0, sd * l2 / 2.0, 0.0),
        );
        for (j, parent, child, origin, range) in [
            (
                1,
                "palm".to_string(),
                format!("{n}_phalanx_1"),
                hand.joint1_anchor_mm(f) * MM,
                lim(hand.joints.theta1_range_deg),
            ),
            (
                2,
                format!("{n}_phalanx_1"),
                format!("{n}_phalanx_2"),
                hand.joint2_anchor_mm(f.side) * MM,
                lim(hand.joints.theta2_range_deg),
            ),
        ] {
            urdf_joint(
                &mut s,
                &format!("{n}_joint_{j}"),
                (&parent, &child),
                origin,
                sd,
                range,
                sim.fingers.torque_limit_nm,
            );
        }
    }
    let _ = writeln!(s, "</robot>");
    let path = dir.join("hand.urdf");
    crate::files::write_replacing(&path, s.as_bytes()).map_err(|e| io_error(&path, e))
}
