//! Building the rapier scene: the hand's placement ([`SimHand`]), where the check starts clear of
//! the object's collider ([`Start`]), the palm, phalanges and joints with motors, and the object
//! (its collider from [`super::collider`]). Units: millimetres and degrees at the interface,
//! metres inside rapier.

use super::collider::ObjectShape;
use super::convert;
use super::impulse_hand::{insert_joint, FingerJoint};
use super::params::{HandJoints, SimParams};
use crate::hand::{palm_rotation, BodyPose, Hand, HandBox};
use nalgebra::{Point3, UnitQuaternion, Vector3};
use rapier3d::prelude::*;

/// The hand's placement for the physics check: the palm pose and the planned joint angles.
#[derive(Debug, Clone, PartialEq)]
pub struct SimHand {
    /// Palm centre on its contact surface, aligned object frame `[mm]`.
    pub origin_mm: Point3<f64>,
    /// Palm axes in the aligned frame: x away from the object, y sideways, z up.
    pub axes: [Vector3<f64>; 3],
    /// Planned `[θ1, θ2]` per finger `[deg]`.
    pub theta_deg: Vec<[f64; 2]>,
    /// Where the plan has the phalanges touch the object, aligned object frame `[mm]`, a group
    /// per phalanx (its contacts in the finger's planes), in the order of
    /// [`crate::quality::planned_contacts`]; empty for a pose given by its angles alone. The
    /// collider is made true there ([`super::ObjectShape::true_at`]). The palm's are left out:
    /// a plate the width of the hand rests on the rims of a groove its contact point lies in
    /// (the basketball's seams).
    pub planned_contacts_mm: Vec<Vec<Point3<f64>>>,
}

impl SimHand {
    /// The palm pose, the centre ALS's joint angles and the planned contacts of a grasp planned
    /// for `hand`.
    pub fn from_grasp(g: &crate::plan::search::Grasp, hand: &Hand) -> SimHand {
        SimHand {
            origin_mm: g.palm.origin,
            axes: g.palm.axes,
            theta_deg: g
                .fingers
                .iter()
                .map(|f| [f.centre.theta1_deg, f.centre.theta2_deg])
                .collect(),
            planned_contacts_mm: by_body(&crate::plan::contacts::planned_contacts(g, hand)),
        }
    }
}

/// The points of `contacts`, a group per phalanx (finger and phalanx), in the order each
/// first appears; the palm's left out.
fn by_body(contacts: &[crate::plan::contacts::Contact]) -> Vec<Vec<Point3<f64>>> {
    let mut bodies: Vec<(&str, u8)> = Vec::new();
    let mut groups: Vec<Vec<Point3<f64>>> = Vec::new();
    for c in contacts.iter().filter(|c| c.phalanx > 0) {
        let body = (c.finger.as_str(), c.phalanx);
        let k = bodies.iter().position(|b| *b == body).unwrap_or_else(|| {
            bodies.push(body);
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[k].push(Point3::from(c.point_mm));
    }
    groups
}

/// Handles of what the protocol measures.
pub struct Scene {
    /// The world.
    pub world: PhysicsWorld,
    /// The palm body.
    pub palm: RigidBodyHandle,
    /// The object body.
    pub object: RigidBodyHandle,
    /// The object's collider.
    pub object_collider: ColliderHandle,
    /// Every hand collider.
    pub hand_colliders: Vec<ColliderHandle>,
    /// The fingers, in the hand's order.
    pub fingers: Vec<SimFinger>,
    /// Motor stiffness and damping.
    motor_gains: (f32, f32),
    /// Torque that holds a locked joint 1 `[N·m]`.
    lock_torque: f32,
    /// Radius about the palm origin of a sphere that holds every hand collider at any joint
    /// angle `[m]`: nothing outside it can touch the hand.
    pub reach_m: f64,
    /// Radius about the object's centre of mass of a sphere that holds the object `[m]`.
    pub object_radius_m: f64,
}

/// One finger of the scene: its phalanx bodies, its joints and what they aim at.
#[derive(Debug, Clone, Copy)]
pub struct SimFinger {
    /// Phalanx 1's body.
    pub phalanx1: RigidBodyHandle,
    /// Phalanx 2's body.
    pub phalanx2: RigidBodyHandle,
    /// The planned bend of joint 1 and joint 2 `[rad]`.
    pub planned_bend_rad: [f64; 2],
    /// Joint 1 (palm to phalanx 1).
    pub joint1: FingerJoint,
    /// Joint 2 (phalanx 1 to phalanx 2), held open until released.
    pub joint2: FingerJoint,
    /// Joint 2's motor target once released `[rad]`.
    pub joint2_target: f32,
    /// Joint 1's motor target while it closes `[rad]`.
    pub joint1_target: f32,
}

/// A copy of `w` that continues bit for bit as `w` would: every part of rapier's state, with
/// fresh pipelines (they hold only workspace: rapier's docs, and its snapshot test restores
/// into fresh ones; `tests/it/sim.rs` checks it for this scene).
pub fn copy_world(w: &PhysicsWorld) -> PhysicsWorld {
    PhysicsWorld {
        gravity: w.gravity,
        integration_parameters: w.integration_parameters,
        physics_pipeline: PhysicsPipeline::new(),
        collision_pipeline: CollisionPipeline::new(),
        islands: w.islands.clone(),
        broad_phase: w.broad_phase.clone(),
        narrow_phase: w.narrow_phase.clone(),
        bodies: w.bodies.clone(),
        colliders: w.colliders.clone(),
        impulse_joints: w.impulse_joints.clone(),
        multibody_joints: w.multibody_joints.clone(),
        soft_bodies: w.soft_bodies.clone(),
        ccd_solver: w.ccd_solver.clone(),
    }
}

impl Scene {
    /// A copy of the scene in its present state, to continue from (a gravity direction, a
    /// payload multiplier) while this one stays as it is.
    pub fn branch(&self) -> Scene {
        Scene {
            world: copy_world(&self.world),
            hand_colliders: self.hand_colliders.clone(),
            fingers: self.fingers.clone(),
            ..*self
        }
    }

    /// Sets the object's mass `[kg]` (its inertia follows, at the same density distribution).
    pub fn set_object_mass(&mut self, mass_kg: f64) {
        if let Some(c) = self.world.colliders.get_mut(self.object_collider) {
            c.set_mass(mass_kg as f32);
        }
    }

    /// Holds finger `k`'s joint 1 where it is now (`hold`) or sends it on to its closing target
    /// (the approach that waits for every finger to touch, `[sim] approach = "together"`).
    pub fn hold_joint1(&mut self, k: usize, hold: bool) {
        let Some(f) = self.fingers.get(k) else { return };
        let Some(angle) = f.joint1.angle(&self.world) else {
            return;
        };
        let target = if hold { angle } else { f.joint1_target };
        f.joint1
            .set_motor(&mut self.world, target, self.motor_gains, None);
    }

    /// Locks joint 1 where it stopped and lets joint 2 close to its target: thesis 3.6.2 fixes
    /// phalanx 1 before phalanx 2, and a Barrett finger (TorqueSwitch) closes joint 1 until it
    /// stalls, after which its worm drive, which cannot be back-driven, holds it while joint 2
    /// closes. Without the lock, joint 2's reaction torque lifts phalanx 1 off the object.
    pub fn release_joint2(&mut self) {
        let (k, d) = self.motor_gains;
        for f in &self.fingers {
            if let Some(angle) = f.joint1.angle(&self.world) {
                let lock = Some(self.lock_torque);
                f.joint1
                    .set_motor(&mut self.world, angle, (k * 10.0, d), lock);
            }
        }
        for f in &self.fingers {
            f.joint2
                .set_motor(&mut self.world, f.joint2_target, (k, d), None);
        }
    }
}

/// The joint value of an interior angle (see [`crate::hand::bend`]).
pub use crate::hand::bend;

/// What one physics check is about: the hand, where it is and how it is planned to close, the
/// object and its physical properties, and the protocol's parameters.
#[derive(Clone, Copy)]
pub struct Case<'a> {
    /// The hand.
    pub hand: &'a Hand,
    /// Palm pose and planned joint angles.
    pub pose: &'a SimHand,
    /// The object's collision shape.
    pub object: &'a ObjectShape,
    /// Object mass `[kg]`.
    pub mass_kg: f64,
    /// Coulomb friction coefficient, everywhere.
    pub friction: f64,
    /// The protocol's parameters.
    pub params: &'a SimParams,
}

impl Case<'_> {
    /// The same case with the object's mass multiplied by `k`.
    pub fn heavier(&self, k: f64) -> Self {
        Case {
            mass_kg: self.mass_kg * k,
            ..*self
        }
    }
}

/// Each finger's joint torque limit `[N·m]`, in the hand's order: `torque_limit_nm`, or with
/// `balanced_squeeze` scaled by the number of fingers on the palm's less crowded side over the
/// number on the finger's own side (the thesis hand: 0.5 for finger_1 and finger_3, 1 for the
/// thumb), so that both sides squeeze equally.
pub fn finger_torque_limits(hand: &Hand, params: &SimParams) -> Vec<f64> {
    let count = |side| hand.finger_list.iter().filter(|f| f.side == side).count();
    let (left, right) = (
        count(crate::hand::Side::Left),
        count(crate::hand::Side::Right),
    );
    let fewest = left.min(right);
    hand.finger_list
        .iter()
        .map(|f| {
            let own = count(f.side);
            if params.fingers.balanced_squeeze && fewest > 0 && own > 0 {
                params.fingers.torque_limit_nm * fewest as f64 / own as f64
            } else {
                params.fingers.torque_limit_nm
            }
        })
        .collect()
}

/// The collision shape of a hand box `[m]`.
fn box_shape(b: &HandBox) -> SharedShape {
    let h = convert::vector_m(&b.half_extents);
    SharedShape::cuboid(h.x, h.y, h.z)
}

/// Where the check starts (docs/SIM.md, "Starting clear"): the palm at the planned pose, backed
/// off along its normal if it starts inside the object's collider, and each finger opened
/// `open_margin_deg` short of its plan at both joints, or, if a phalanx would start inside the
/// collider there, the nearest margin in 5° steps (wider first, up to the joint limits, then
/// narrower down to 0) at which the whole finger is clear. The planner works on the mesh, the
/// check on its convex hull or decomposition, whose parts bulge past the mesh by millimetres: a
/// hand collider starting inside one is thrown out by the solver (MuJoCo's stiff contacts threw
/// a golf club 3 m), which is a different test from closing on the object.
#[derive(Debug, Clone, PartialEq)]
pub struct Start {
    /// The palm's origin `[mm]` (the planned one moved by `palm_backoff_mm` along palm x).
    pub origin_mm: Point3<f64>,
    /// How far the palm was backed off the collider `[mm]` (0 when it starts clear).
    pub palm_backoff_mm: f64,
    /// Per finger, the bends the joints start at `[rad]`.
    pub open_bend_rad: Vec<[f64; 2]>,
    /// Per finger, the margin it starts open by `[deg]`.
    pub open_margin_deg: Vec<f64>,
    /// The deepest penetration of a hand collider into the object's left at the start `[mm]`
    /// (0 when everything starts clear).
    pub penetration_mm: f64,
    /// Per finger, the `[θ1, θ2]` the check commands `[deg]` (plus the squeeze): the plan's,
    /// or with `[sim] refine_contacts` the plan refined by the contact.
    pub theta_deg: Vec<[f64; 2]>,
    /// Per finger, what the refinement by the contact did (`sim::refine`); empty when it did not
    /// run (`refine_contacts = false`, or `override_angles`).
    pub refinement: Vec<crate::plan::refine::FingerRefinement>,
}

/// A hand collider penetrates the object's collider deeper than this at the start `[mm]`: twice
/// rapier's allowed linear error at the scene's length unit (0.05 mm), so flush contact counts
/// as clear.
const START_TOLERANCE_MM: f64 = 0.1;

/// Depth of the deepest overlap of `boxes` (posed by `frame`) with the object `[mm]`, 0 if none.
fn overlap_mm(object: &SharedShape, frame: &BodyPose, boxes: &[HandBox]) -> f64 {
    let at_origin = Pose::IDENTITY;
    boxes
        .iter()
        .map(|b| {
            let c = frame.0 + frame.1 * b.centre;
            let pose = convert::pose(&c, &frame.1);
            match rapier3d::parry::query::contact(
                &pose,
                &*box_shape(b).0,
                &at_origin,
                &*object.0,
                0.0,
            ) {
                Ok(Some(contact)) => (-f64::from(contact.dist) / convert::M_PER_MM).max(0.0),
                _ => 0.0,
            }
        })
        .fold(0.0, f64::max)
}

/// The palm's origin `[mm]` backed off the object along palm x by the depth found, plus the
/// tolerance, until clear (a few rounds: moving off one part can meet another only in a
/// concave object), and how far it was backed off `[mm]`.
fn backed_off(pose: &SimHand, object: &ObjectShape, palm: &[HandBox]) -> (Point3<f64>, f64) {
    let r_palm = palm_rotation(&pose.axes);
    let mut origin = pose.origin_mm;
    let mut backoff = 0.0;
    for _ in 0..10 {
        let d = overlap_mm(&object.shape, &(origin, r_palm), palm);
        if d <= START_TOLERANCE_MM {
            break;
        }
        backoff += d + START_TOLERANCE_MM;
        origin = pose.origin_mm + pose.axes[0] * backoff;
    }
    (origin, backoff)
}

/// The margins a finger may start open by `[deg]`, in the order they are tried: `margin0`, then
/// wider in 5° steps up to 90°, then narrower down to 0.
fn open_margins(margin0: f64) -> Vec<f64> {
    let mut margins = vec![margin0];
    margins.extend(
        (1..)
            .map(|k| margin0 + 5.0 * f64::from(k))
            .take_while(|m| *m <= 90.0),
    );
    margins.extend(
        (1..)
            .map(|k| margin0 - 5.0 * f64::from(k))
            .take_while(|m| *m >= 0.0),
    );
    margins
}

/// The start of the check for `case` (see [`Start`]).
pub fn start(case: &Case) -> Start {
    let Case {
        hand, pose, object, ..
    } = *case;
    let r_palm = palm_rotation(&pose.axes);
    let palm = [hand.palm_box()];
    let (origin, backoff) = backed_off(pose, object, &palm);
    let palm_pose = (origin, r_palm);
    let refines =
        case.params.closing.refine_contacts && case.params.input.override_angles.is_none();
    let refinement = if refines {
        super::refine::refine(case, &palm_pose, |theta| {
            opened(case, &palm_pose, theta).bends
        })
    } else {
        Vec::new()
    };
    let theta_deg: Vec<[f64; 2]> = if refines {
        refinement.iter().map(|r| r.refined_deg).collect()
    } else {
        pose.theta_deg.clone()
    };
    let open = opened(case, &palm_pose, &theta_deg);
    Start {
        origin_mm: origin,
        palm_backoff_mm: backoff,
        open_bend_rad: open.bends,
        open_margin_deg: open.margins,
        penetration_mm: overlap_mm(&object.shape, &palm_pose, &palm).max(open.penetration_mm),
        theta_deg,
        refinement,
    }
}

/// The fingers opened for the start (see [`Start`]).
struct Opened {
    /// Per finger, the bends the joints start at `[rad]`.
    bends: Vec<[f64; 2]>,
    /// Per finger, the margin it starts open by `[deg]`.
    margins: Vec<f64>,
    /// The deepest penetration of a finger no margin clears `[mm]` (0 when none).
    penetration_mm: f64,
}

/// Each finger of `case`, commanded `theta` `[deg]` with the palm at `palm`, opened by
/// `open_margin_deg`, or by the nearest margin at which it starts clear (see [`Start`]).
fn opened(case: &Case, palm: &BodyPose, theta: &[[f64; 2]]) -> Opened {
    let Case {
        hand,
        object,
        params,
        ..
    } = *case;
    let limits1 = [
        bend(hand.joints.theta1_range_deg[1]),
        bend(hand.joints.theta1_range_deg[0]),
    ];
    let limits2 = [
        bend(hand.joints.theta2_range_deg[1]),
        bend(hand.joints.theta2_range_deg[0]),
    ];
    let margin0 = params.closing.open_margin_deg;
    let margins = open_margins(margin0);
    let mut out = Opened {
        bends: Vec::new(),
        margins: Vec::new(),
        penetration_mm: 0.0,
    };
    for (f, [t1, t2]) in hand.finger_list.iter().zip(theta) {
        let (p1, p2) = hand.phalanx_boxes(f.side);
        let at = |m: f64| {
            let b1 = (bend(*t1) - m.to_radians()).max(limits1[0]);
            let b2 = (bend(*t2) - m.to_radians()).max(limits2[0]);
            let [f1, f2] = hand.finger_poses(f, palm, [b1, b2]);
            let d = overlap_mm(&object.shape, &f1, &[p1]).max(overlap_mm(&object.shape, &f2, &p2));
            ([b1, b2], d)
        };
        let (first, d0) = at(margin0);
        let found = if d0 <= START_TOLERANCE_MM {
            Some((margin0, first))
        } else {
            margins[1..].iter().find_map(|&m| {
                let (b, d) = at(m);
                (d <= START_TOLERANCE_MM).then_some((m, b))
            })
        };
        let (m, b) = found.unwrap_or_else(|| {
            // No margin clears it: start as the scenario says, and report the overlap.
            out.penetration_mm = out.penetration_mm.max(d0);
            (margin0, first)
        });
        out.margins.push(m);
        out.bends.push(b);
    }
    out
}

/// Builds the scene with the fingers open and gravity off.
///
/// # Panics
/// If rapier refuses a finger's joint (it does only for a joint that would close a kinematic
/// loop, which a hand of open chains never has).
pub fn build(case: &Case) -> Scene {
    let Case {
        hand,
        pose,
        object,
        mass_kg,
        friction,
        params,
    } = *case;
    let mut world = new_world(params);
    let r_palm = palm_rotation(&pose.axes);
    let start = start(case);
    // The palm never moves during the check: a fixed body. (A kinematic body here made rapier
    // refresh the palm's contacts irregularly: the object, pressed against the palm, sank into it
    // for about five steps and was thrown back in one, a 0.16 mm sawtooth that ratcheted it along
    // the fingers by 0.03 mm per period: docs/studies/2026-11-22-mujoco-two-faults.md.)
    let palm = world
        .bodies
        .insert(RigidBodyBuilder::fixed().pose(convert::pose(&start.origin_mm, &r_palm)));
    // The palm's colliders: its box, or the hand file's own link meshes (`hand_shapes`).
    let palm_box = || vec![hand_collider(&hand.palm_box(), friction)];
    let mut hand_colliders = super::hand_shapes::insert(&mut world, palm, hand, friction, palm_box);
    let fingers: Vec<SimFinger> = hand
        .finger_list
        .iter()
        .zip(&start.theta_deg)
        .zip(&start.open_bend_rad)
        .zip(finger_torque_limits(hand, params))
        .map(|(((f, theta), open), torque_nm)| {
            let at = FingerAt {
                finger: f,
                theta_deg: *theta,
                open_bend_rad: *open,
                palm_pose: (start.origin_mm, r_palm),
                torque_nm,
            };
            insert_finger(&mut world, &mut hand_colliders, case, palm, &at)
        })
        .collect();
    // Impulse-joint phalanges are inserted where the open bends put them; a multibody's are
    // placed from its coordinates.
    if params.solver.hand_joints == HandJoints::Multibody {
        for (f, open) in fingers.iter().zip(&start.open_bend_rad) {
            set_open(&mut world, f, *open);
        }
    }

    let object_body = world
        .bodies
        .insert(RigidBodyBuilder::dynamic().can_sleep(false));
    // The same shape with its hulls scanned in lanes: the same contacts, faster (fast_hull).
    let collider = ColliderBuilder::new(super::fast_hull::with_fast_hulls(&object.shape))
        .friction(friction as f32);
    // The mesh's mass distribution where known, else the collider's scaled to the mass.
    let collider = match object.mesh_mass {
        Some(_) => {
            collider.mass_properties(super::collider::object_mass_properties(object, mass_kg))
        }
        None => collider.mass(mass_kg as f32),
    };
    let object_collider =
        world
            .colliders
            .insert_with_parent(collider, object_body, &mut world.bodies);
    Scene {
        world,
        palm,
        object: object_body,
        object_collider,
        hand_colliders,
        fingers,
        lock_torque: params.fingers.joint1_lock_torque_nm as f32,
        motor_gains: (
            params.fingers.motor_stiffness_nm_per_rad as f32,
            params.fingers.motor_damping_nms_per_rad as f32,
        ),
        reach_m: reach_mm(hand) * convert::M_PER_MM,
        object_radius_m: object_radius_m(object),
    }
}

/// An empty world, gravity off, with the integration parameters of the check.
fn new_world(params: &SimParams) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    // Contact manifolds checked against parry's own contact query, and rebuilt from scratch
    // where they miss a phalanx inside the object (`dispatcher`).
    world.narrow_phase = NarrowPhase::with_query_dispatcher(super::dispatcher::CheckedManifolds);
    world.gravity = Vector::ZERO;
    let ip = &mut world.integration_parameters;
    ip.dt = params.solver.timestep_s as f32;
    // rapier's tolerances scale with length_unit (allowed linear error 5e-3 × unit, prediction
    // distance 2e-2 × unit); at the default of 1 m they would be 5 mm and 20 mm, a sizeable part
    // of a 40 mm object. 1 cm makes them 0.05 mm and 0.2 mm (pinned by a test).
    ip.length_unit = 0.01;
    // A grasp is a closed loop of stiff contacts and joints (palm, phalanges, object): rapier's
    // default of one PGS sweep per substep leaves the object creeping under the squeeze (the
    // convergence study in docs/SIM.md); more sweeps per substep settle it.
    ip.num_solver_iterations = params.solver.solver_iterations;
    ip.num_internal_pgs_iterations = params.solver.pgs_iterations;
    ip.num_internal_stabilization_iterations = params.solver.stabilization_iterations;
    // Contact softness is a natural frequency relative to the bodies' effective mass. rapier's
    // default (30 Hz; 60 Hz against fixed bodies) is a spring of about 430 N/m against a 12 g
    // phalanx: a 1 N·m finger squeezing at 30 mm (33 N) would sink centimetres into the object.
    // 1 kHz is about 5e5 N/m against a phalanx's own mass, but not stiff enough against the
    // motors: with the 10° squeeze overshoot, phalanx 2 was driven 5.2 mm into the D40 cylinder
    // (2.2 mm at 5°), and at 3 kHz still 6.5 mm into a box of cream cheese, its tip pushed past
    // the far face instead of stopping on it. At 10 kHz the fingers stop on the surface
    // (0.01 mm on both) and every real object's penetration after closing is within
    // `max_penetration_mm` (issue 14, docs/SIM.md "Penetration"); the bundled scenarios keep
    // their verdicts and MuJoCo still agrees on all of them.
    // Grasps live on friction: one Coulomb friction constraint per contact point, not rapier's
    // default simplification (one per four contacts plus a twist constraint), and no recycling
    // of stale contacts between steps.
    ip.friction_model = FrictionModel::Coulomb;
    ip.contact_recycling = false;
    let hz = params.solver.contact_stiffness_hz as f32;
    ip.contact_softness = SpringCoefficients::new(hz, 10.0);
    ip.static_contact_softness = SpringCoefficients::new(hz, 10.0);
    world
}

/// The collider of a hand box, in its body's frame.
fn hand_collider(b: &HandBox, friction: f64) -> ColliderBuilder {
    ColliderBuilder::new(box_shape(b))
        .translation(convert::vector_m(&b.centre))
        .friction(friction as f32)
}

/// A finger to insert: its planned angles `[deg]`, the bends it starts at `[rad]` and the
/// palm's pose.
struct FingerAt<'a> {
    finger: &'a crate::hand::Finger,
    theta_deg: [f64; 2],
    open_bend_rad: [f64; 2],
    palm_pose: BodyPose,
    /// Its joints' torque limit `[N·m]` ([`finger_torque_limits`]).
    torque_nm: f64,
}

/// Inserts one finger's phalanx bodies, their colliders (pushed onto `hand_colliders`) and its
/// two motored joints; the phalanges are placed open (see [`Start`]), so contact is made by
/// closing along the planned path.
fn insert_finger(
    world: &mut PhysicsWorld,
    hand_colliders: &mut Vec<ColliderHandle>,
    case: &Case,
    palm: RigidBodyHandle,
    at: &FingerAt,
) -> SimFinger {
    let Case {
        hand,
        friction,
        params,
        ..
    } = *case;
    let f = at.finger;
    let [t1, t2] = at.theta_deg;
    let [open1, open2] = at.open_bend_rad;
    let density = params.fingers.finger_density_kg_m3 as f32;
    let limits = |range: [f64; 2]| [bend(range[1]) as f32, bend(range[0]) as f32];
    let limits1 = limits(hand.joints.theta1_range_deg);
    let limits2 = limits(hand.joints.theta2_range_deg);
    let motor = |target: f64, limits: [f32; 2]| (target as f32).clamp(limits[0], limits[1]);
    let revolute = |anchor: &Vector3<f64>, limits: [f32; 2], target: f32| {
        let axis = Vector::new(0.0, 0.0, f.side.sign() as f32);
        revolute_joint(axis, anchor, limits, target, params, at.torque_nm)
    };
    let (p1, p2) = hand.phalanx_boxes(f.side);
    let [(j1, r1), (j2, r2)] = hand.finger_poses(f, &at.palm_pose, [open1, open2]);
    // Body `k` of the hand (`Hand::body_poses`' order): phalanx 1 of finger `i` is 1 + 2i.
    let index = hand
        .finger_list
        .iter()
        .position(|g| std::ptr::eq(g, f))
        .unwrap_or(0);
    let first = 1 + 2 * index;
    let mut phalanx = |world: &mut PhysicsWorld, pose: Pose, boxes: &[HandBox], k: usize| {
        let body = world
            .bodies
            .insert(RigidBodyBuilder::dynamic().pose(pose).can_sleep(false));
        let colliders = super::hand_shapes::colliders(hand, k, friction, || {
            boxes.iter().map(|b| hand_collider(b, friction)).collect()
        });
        for c in colliders {
            hand_colliders.push(world.colliders.insert_with_parent(
                c.density(density),
                body,
                &mut world.bodies,
            ));
        }
        body
    };
    let squeeze = params.fingers.squeeze_deg.to_radians();
    let squeeze2 = params.fingers.squeeze2_deg.to_radians();
    // Body, colliders, joint, in this order for each phalanx: rapier's state (and so the run)
    // depends on the order of insertion.
    let b1 = phalanx(world, convert::pose(&j1, &r1), &[p1], first);
    let joint1 = revolute(
        &hand.joint1_anchor_mm(f),
        limits1,
        motor(bend(t1) + squeeze, limits1),
    );
    let kind = params.solver.hand_joints;
    let base = match kind {
        HandJoints::Multibody if index > 0 => finger_base(world, palm, b1),
        HandJoints::Multibody | HandJoints::Impulse => palm,
    };
    let joint1 = insert_joint(world, kind, base, b1, joint1);
    let b2 = phalanx(world, convert::pose(&j2, &r2), &p2, first + 1);
    // Joint 2 is held at its open angle until released (see `Scene::release_joint2`).
    let joint2 = revolute(&hand.joint2_anchor_mm(f.side), limits2, open2 as f32);
    let joint2 = insert_joint(world, kind, b1, b2, joint2);
    SimFinger {
        phalanx1: b1,
        phalanx2: b2,
        planned_bend_rad: [bend(t1), bend(t2)],
        joint1,
        joint2,
        joint2_target: motor(bend(t2) + squeeze2, limits2),
        joint1_target: motor(bend(t1) + squeeze, limits1),
    }
}

/// Membership of the palm's colliders, which its fingers' phalanx 1s do not touch.
const PALM: Group = Group::GROUP_1;
/// Membership of a phalanx 1's colliders, which the palm's do not touch.
const PHALANX_1: Group = Group::GROUP_2;

/// The root of a finger's multibody but the first's: a fixed body without colliders at the
/// palm's pose, so that each finger is a multibody of its own (two coordinates) rather than a
/// branch of one rooted at the palm (six). The first finger's multibody keeps the palm as its
/// root, so that the palm's contacts are solved as before (as a multibody link's, not a fixed
/// body's). The equations are the same: the fingers' coordinates share no mass-matrix entries,
/// so the hand's matrix is block-diagonal and the zeros between its blocks change no sum; on
/// every scenario measured the results are the same to the bit (docs/SIM.md, "The fingers as
/// separate multibodies": measured, not structural, so a rapier upgrade repeats the
/// comparison) and the solve is smaller. A multibody keeps jointed links off each other, and phalanx 1 is no longer
/// jointed to the palm: collision groups keep them apart, as the joint did, and leave phalanx 2
/// touching the palm, as before.
fn finger_base(
    world: &mut PhysicsWorld,
    palm: RigidBodyHandle,
    phalanx1: RigidBodyHandle,
) -> RigidBodyHandle {
    let pose = *world.bodies[palm].position();
    let base = world.bodies.insert(RigidBodyBuilder::fixed().pose(pose));
    let groups = |member: Group, shun: Group| {
        InteractionGroups::new(member, Group::ALL ^ shun, InteractionTestMode::And)
    };
    for (body, groups) in [
        (palm, groups(PALM, PHALANX_1)),
        (phalanx1, groups(PHALANX_1, PALM)),
    ] {
        for c in world.bodies[body].colliders().to_vec() {
            world.colliders[c].set_collision_groups(groups);
        }
    }
    base
}

/// A finger joint: revolute about `axis` (the parent's frame) at `anchor` `[mm]` on the parent,
/// within `limits` `[rad]`, with a force-based position motor towards `target` `[rad]` at the
/// scenario's stiffness and damping, capped at `torque_nm`; the two phalanges it joins do not
/// collide.
fn revolute_joint(
    axis: Vector,
    anchor: &Vector3<f64>,
    limits: [f32; 2],
    target: f32,
    params: &SimParams,
    torque_nm: f64,
) -> RevoluteJointBuilder {
    RevoluteJointBuilder::new(axis)
        .local_anchor1(convert::vector_m(anchor))
        .local_anchor2(Vector::ZERO)
        .limits(limits)
        .motor_model(MotorModel::ForceBased)
        .motor_position(
            target,
            params.fingers.motor_stiffness_nm_per_rad as f32,
            params.fingers.motor_damping_nms_per_rad as f32,
        )
        .motor_max_force(torque_nm as f32)
        .contacts_enabled(false)
}

/// A multibody places its links from its joint coordinates, which start at zero (every
/// phalanx straight): sets them to the open bends and moves the finger's bodies there.
fn set_open(world: &mut PhysicsWorld, f: &SimFinger, [open1, open2]: [f64; 2]) {
    let Some(link) = world.multibody_joints.rigid_body_link(f.phalanx1).copied() else {
        return;
    };
    let Some(mb) = world.multibody_joints.get_multibody_mut(link.multibody) else {
        return;
    };
    let mut disp = vec![0.0; mb.ndofs()];
    for (body, angle) in [(f.phalanx1, open1), (f.phalanx2, open2)] {
        if let Some(l) = mb.links().find(|l| l.rigid_body_handle() == body) {
            disp[l.assembly_id()] = angle as f32;
        }
    }
    // rapier gives every multibody angular dof a default viscous damping of 0.1 N·m·s/rad
    // (`MultibodyJoint::default_damping`). The hand has none (the motors carry their own
    // damping) and neither has the MJCF export: at a 0.07 N·m torque limit it capped the
    // closing speed near 0.7 rad/s, so phalanx 2 had only just touched when gravity came on.
    mb.damping_mut().fill(0.0);
    mb.apply_displacements(&disp);
    mb.forward_kinematics(&world.bodies, true);
    mb.update_rigid_bodies(&mut world.bodies, true);
}

/// Radius about the palm origin of a sphere that holds every hand collider at any joint angle
/// `[mm]`: the palm box's farthest corner, or a finger's joint 1 plus phalanx 1 plus the
/// farthest point of phalanx 2 (or its tip) from joint 2, whichever is larger; the finger boxes
/// are 2 × offset thick and wide.
fn reach_mm(hand: &Hand) -> f64 {
    let pb = hand.palm_box();
    let mut reach_mm = (pb.centre.abs() + pb.half_extents).norm();
    let (o, l1, l2) = (
        hand.fingers.offset_mm,
        hand.phalanx_1.length_mm,
        hand.phalanx_2.length_mm,
    );
    for f in &hand.finger_list {
        let anchor = Vector3::new(hand.joints.setback_mm, hand.joints.lateral_mm, f.height_mm);
        let finger = anchor.norm() + l1 + (l2 * l2 + 2.0 * o * o).sqrt();
        reach_mm = reach_mm.max(finger);
    }
    reach_mm
}

/// Radius about the object's centre of mass of a sphere that holds the object `[m]`.
fn object_radius_m(object: &ObjectShape) -> f64 {
    let sphere = object.shape.compute_local_bounding_sphere();
    let com = super::collider::object_com_m(object);
    f64::from(sphere.radius() + (sphere.center() - com).length())
}

/// The palm, phalanx 1 and 2 of each finger, then the object (aligned frame, metres).
pub(super) fn poses(scene: &Scene) -> Vec<super::BodyPose> {
    let mut handles = vec![scene.palm];
    for f in &scene.fingers {
        handles.push(f.phalanx1);
        handles.push(f.phalanx2);
    }
    handles.push(scene.object);
    handles
        .iter()
        .map(|h| {
            let p = scene.world.bodies[*h].position();
            (
                convert::vector_mm(p.translation) * convert::M_PER_MM,
                convert::unit_quaternion(p.rotation),
            )
        })
        .collect()
}

/// The object's pose relative to the palm: (translation in mm, rotation).
pub(super) fn relative(scene: &Scene) -> (Vector3<f64>, UnitQuaternion<f64>) {
    let palm = scene.world.bodies[scene.palm].position();
    let obj = scene.world.bodies[scene.object].position();
    let rel = palm.inverse() * *obj;
    (
        convert::vector_mm(rel.translation),
        convert::unit_quaternion(rel.rotation),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn thesis_hand() -> Hand {
        let (_, text) = crate::hand::bundled("thesis").unwrap();
        Hand::parse(text, Path::new("thesis.toml"), &[]).unwrap()
    }

    /// A 40 x 100 x 80 mm box about the z axis, its faces at x = ±20 and y = ±50.
    fn box_shape() -> ObjectShape {
        let mesh = crate::objects::prism(40.0, 100.0, 80.0);
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        ObjectShape::from_mesh(&mesh, volume)
    }

    /// The palm facing the box's −x face, its contact surface at `x`, fingers at `theta`.
    fn hand_at(x: f64, theta: [f64; 2]) -> SimHand {
        SimHand {
            origin_mm: Point3::new(x, 0.0, 40.0),
            axes: [-Vector3::x(), -Vector3::y(), Vector3::z()],
            theta_deg: vec![theta; 3],
            planned_contacts_mm: Vec::new(),
        }
    }

    /// Where the thesis hand at `pose` starts on the box, with the default parameters.
    fn start_on_box(pose: &SimHand) -> Start {
        let (hand, object, params) = (thesis_hand(), box_shape(), SimParams::default());
        start(&Case {
            hand: &hand,
            pose,
            object: &object,
            mass_kg: 0.1,
            friction: 0.5,
            params: &params,
        })
    }

    /// Whether any collider of `a` has an active contact with any collider of `b`.
    fn touching(world: &PhysicsWorld, a: RigidBodyHandle, b: RigidBodyHandle) -> bool {
        world.bodies[a].colliders().iter().any(|&ca| {
            world.bodies[b].colliders().iter().any(|&cb| {
                world
                    .narrow_phase
                    .contact_pair(ca, cb)
                    .is_some_and(|p| p.has_any_active_contact())
            })
        })
    }

    #[test]
    fn each_finger_is_a_multibody_of_its_own_and_phalanx_1_never_touches_the_palm() {
        let (hand, object, params) = (thesis_hand(), box_shape(), SimParams::default());
        // Fingers bent so far that phalanx 1 would lie on the palm's face: the box is 30 mm
        // away from the palm, out of the way.
        let pose = hand_at(-50.0, [95.0, 180.0]);
        let case = Case {
            hand: &hand,
            pose: &pose,
            object: &object,
            mass_kg: 0.1,
            friction: 0.5,
            params: &params,
        };
        let mut scene = build(&case);
        let roots: Vec<_> = scene
            .fingers
            .iter()
            .map(|f| {
                let link = scene.world.multibody_joints.rigid_body_link(f.phalanx1);
                let mb = scene
                    .world
                    .multibody_joints
                    .get_multibody(link.unwrap().multibody);
                let mb = mb.unwrap();
                assert_eq!((mb.ndofs(), mb.num_links()), (2, 3));
                mb.root().rigid_body_handle()
            })
            .collect();
        // The first finger keeps the palm as its root; the others have roots of their own.
        assert_eq!(roots[0], scene.palm);
        assert!(roots[1] != scene.palm && roots[2] != scene.palm && roots[1] != roots[2]);
        for _ in 0..20 {
            scene.world.step();
        }
        for f in &scene.fingers {
            assert!(!touching(&scene.world, scene.palm, f.phalanx1));
        }
        // The groups keep nothing else apart: every hand body may touch the object, phalanx 2
        // the palm, and the fingers each other, as in one multibody with self-contacts.
        let groups = |b: RigidBodyHandle| {
            let c = scene.world.bodies[b].colliders()[0];
            scene.world.colliders[c].collision_groups()
        };
        let object = scene.world.colliders[scene.object_collider].collision_groups();
        for (i, f) in scene.fingers.iter().enumerate() {
            for b in [scene.palm, f.phalanx1, f.phalanx2] {
                assert!(groups(b).test(object));
            }
            assert!(groups(scene.palm).test(groups(f.phalanx2)));
            for g in &scene.fingers[i + 1..] {
                for (a, b) in [(f.phalanx1, g.phalanx1), (f.phalanx1, g.phalanx2)] {
                    assert!(groups(a).test(groups(b)) && groups(b).test(groups(a)));
                }
            }
        }
        // Without the collision groups phalanx 1 of a finger with its own root lies on the palm.
        let f = &scene.fingers[1];
        for &c in scene.world.bodies[f.phalanx1].colliders().to_vec().iter() {
            scene.world.colliders[c].set_collision_groups(InteractionGroups::default());
        }
        for _ in 0..20 {
            scene.world.step();
        }
        assert!(touching(&scene.world, scene.palm, f.phalanx1));
    }

    #[test]
    fn a_palm_inside_the_collider_starts_backed_off() {
        // Flush on the face: nothing to do.
        let pose = hand_at(-20.0, [120.0, 120.0]);
        let s = start_on_box(&pose);
        assert_eq!(s.palm_backoff_mm, 0.0);
        assert_eq!(s.origin_mm, pose.origin_mm);
        // 3 mm inside: backed off by the depth plus the tolerance, along palm x.
        let pose = hand_at(-17.0, [120.0, 120.0]);
        let s = start_on_box(&pose);
        assert!((s.palm_backoff_mm - 3.1).abs() < 1e-3, "{s:?}");
        assert!((s.origin_mm.x + 20.1).abs() < 1e-3, "{s:?}");
        assert_eq!((s.origin_mm.y, s.origin_mm.z), (0.0, 40.0));
        assert!(
            overlap_mm(
                &box_shape().shape,
                &(s.origin_mm, palm_rotation(&pose.axes)),
                &[thesis_hand().palm_box()]
            ) <= START_TOLERANCE_MM
        );
    }

    #[test]
    fn a_finger_that_cannot_start_clear_is_reported() {
        // A 100 mm wide face: the fingers' planes (36.7 mm either side of the palm's centre) cut
        // the box, and even fully open (45° bend) phalanx 1 starts inside it.
        let s = start_on_box(&hand_at(-20.0, [120.0, 120.0]));
        assert!(s.penetration_mm > 10.0, "{s:?}");
        assert_eq!(s.open_margin_deg, vec![20.0; 3]);
    }
}
