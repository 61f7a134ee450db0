//! Building the rapier scene: palm, phalanges, joints with motors, and the object.

use super::convert;
use crate::hand::{Hand, Side};
use crate::mesh::Mesh;
use crate::scenario::SimParams;
use nalgebra::{Point3, Rotation3, UnitQuaternion, Vector3};
use rapier3d::parry::transformation::vhacd::VHACDParameters;
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
}

impl SimHand {
    /// The palm pose and the centre ALS's joint angles of a planned grasp.
    pub fn from_grasp(g: &crate::plan::search::Grasp) -> SimHand {
        SimHand {
            origin_mm: g.palm.origin,
            axes: g.palm.axes,
            theta_deg: g
                .fingers
                .iter()
                .map(|f| [f.centre.theta1_deg, f.centre.theta2_deg])
                .collect(),
        }
    }
}

/// The object's collision shape, built once per object and shared by every run.
#[derive(Clone)]
pub struct ObjectShape {
    /// The shape in metres, aligned frame.
    pub shape: SharedShape,
    /// How it was made: `convex_hull` or `convex_decomposition`.
    pub kind: &'static str,
    /// Number of convex parts.
    pub parts: usize,
    /// True if and only if the object is inertially a body of revolution about its principal
    /// axis (aligned Z): its two transverse principal moments agree within 0.1 %.
    pub is_revolution: bool,
}

impl ObjectShape {
    /// The convex hull of `mesh` (aligned, millimetres) if the mesh is convex (hull volume within
    /// 2 % of `volume_mm3`), a convex decomposition otherwise.
    pub fn from_mesh(mesh: &Mesh, volume_mm3: f64) -> ObjectShape {
        let props = crate::mesh::mass_properties(mesh);
        let (ixx, iyy) = (props.inertia[(0, 0)], props.inertia[(1, 1)]);
        let is_revolution = (ixx - iyy).abs() <= 1e-3 * ixx.abs().max(iyy.abs());
        let points: Vec<Vector> = mesh.vertices.iter().map(convert::point_m).collect();
        if let Some(hull) = SharedShape::convex_hull(&points) {
            let hull_mm3 = f64::from(hull.mass_properties(1.0).mass()) * 1e9;
            if hull_mm3 <= volume_mm3 * 1.02 {
                return ObjectShape {
                    shape: hull,
                    kind: "convex_hull",
                    parts: 1,
                    is_revolution,
                };
            }
        }
        let params = VHACDParameters {
            resolution: 64,
            ..VHACDParameters::default()
        };
        let shape =
            SharedShape::convex_decomposition_with_params(&points, &mesh.triangles, &params);
        let parts = shape.as_compound().map_or(1, |c| c.shapes().len());
        ObjectShape {
            shape,
            kind: "convex_decomposition",
            parts,
            is_revolution,
        }
    }
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
    /// Phalanx bodies per finger and the bend each joint should reach `[rad]`: (body1, body2,
    /// planned bend 1, planned bend 2).
    pub fingers: Vec<(RigidBodyHandle, RigidBodyHandle, f64, f64)>,
    /// Joint 2 of each finger and its motor target once released `[rad]` (held open until then).
    pub joint2: Vec<(MultibodyJointHandle, f32)>,
    /// Joint 1 of each finger.
    pub joint1: Vec<MultibodyJointHandle>,
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
            joint2: self.joint2.clone(),
            joint1: self.joint1.clone(),
            ..*self
        }
    }

    /// Sets the object's mass `[kg]` (its inertia follows, at the same density distribution).
    pub fn set_object_mass(&mut self, mass_kg: f64) {
        if let Some(c) = self.world.colliders.get_mut(self.object_collider) {
            c.set_mass(mass_kg as f32);
        }
    }

    /// Locks joint 1 where it stopped and lets joint 2 close to its target: thesis 3.6.2 fixes
    /// phalanx 1 before phalanx 2, and a Barrett finger (TorqueSwitch) closes joint 1 until it
    /// stalls, after which its worm drive, which cannot be back-driven, holds it while joint 2
    /// closes. Without the lock, joint 2's reaction torque lifts phalanx 1 off the object.
    pub fn release_joint2(&mut self) {
        let (k, d) = self.motor_gains;
        for &h in &self.joint1 {
            if let Some((mb, id)) = self.world.multibody_joints.get_mut(h) {
                if let Some(link) = mb.link_mut(id) {
                    let angle = link.joint.coords()[3];
                    link.joint
                        .data
                        .set_motor_position(JointAxis::AngX, angle, k * 10.0, d)
                        .set_motor_max_force(JointAxis::AngX, self.lock_torque);
                }
            }
        }
        for &(h, target) in &self.joint2 {
            if let Some((mb, id)) = self.world.multibody_joints.get_mut(h) {
                if let Some(link) = mb.link_mut(id) {
                    link.joint
                        .data
                        .set_motor_position(JointAxis::AngX, target, k, d);
                }
            }
        }
    }
}

/// Bend from straight of a joint at interior angle `theta_deg` `[rad]`: the joint value used
/// by the rapier scene and by the MJCF and URDF exports alike.
pub fn bend(theta_deg: f64) -> f64 {
    (180.0 - theta_deg).to_radians()
}

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

/// Builds the scene with the fingers open and gravity off.
pub fn build(case: &Case) -> Scene {
    let Case {
        hand,
        pose,
        object,
        mass_kg,
        friction,
        params,
    } = *case;
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::ZERO;
    let ip = &mut world.integration_parameters;
    ip.dt = params.timestep_s as f32;
    // rapier's tolerances scale with length_unit (allowed linear error 5e-3 × unit, prediction
    // distance 2e-2 × unit); at the default of 1 m they would be 5 mm and 20 mm, a sizeable part
    // of a 40 mm object. 1 cm makes them 0.05 mm and 0.2 mm (pinned by a test).
    ip.length_unit = 0.01;
    // A grasp is a closed loop of stiff contacts and joints (palm, phalanges, object): rapier's
    // default of one PGS sweep per substep leaves the object creeping under the squeeze (the
    // convergence study in docs/SIM.md); more sweeps per substep settle it.
    ip.num_solver_iterations = params.solver_iterations;
    ip.num_internal_pgs_iterations = params.pgs_iterations;
    ip.num_internal_stabilization_iterations = params.stabilization_iterations;
    // Contact softness is a natural frequency relative to the bodies' effective mass. rapier's
    // default (30 Hz; 60 Hz against fixed bodies) is a spring of about 430 N/m against a 12 g
    // phalanx: a 1 N·m finger squeezing at 30 mm (33 N) would sink centimetres into the object.
    // 1 kHz is about 5e5 N/m, under 0.1 mm at that force.
    // Grasps live on friction: one Coulomb friction constraint per contact point, not rapier's
    // default simplification (one per four contacts plus a twist constraint), and no recycling
    // of stale contacts between steps.
    ip.friction_model = FrictionModel::Coulomb;
    ip.contact_recycling = false;
    let hz = params.contact_stiffness_hz as f32;
    ip.contact_softness = SpringCoefficients::new(hz, 10.0);
    ip.static_contact_softness = SpringCoefficients::new(hz, 10.0);

    let [x, y, z] = pose.axes;
    let r_palm = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
        nalgebra::Matrix3::from_columns(&[x, y, z]),
    ));
    // The palm never moves during the check: a fixed body. (A kinematic body here made rapier
    // refresh the palm's contacts irregularly: the object, pressed against the palm, sank into it
    // for about five steps and was thrown back in one, a 0.16 mm sawtooth that ratcheted it along
    // the fingers by 0.03 mm per period, docs/SIM.md.)
    let palm = world
        .bodies
        .insert(RigidBodyBuilder::fixed().pose(convert::pose(&pose.origin_mm, &r_palm)));
    let mm = |v: f64| (v * convert::M_PER_MM) as f32;
    let (h_lo, h_hi) = hand.finger_height_span();
    let m = hand.palm.margin_mm;
    let (z_lo, z_hi) = (h_lo - m, h_hi + m);
    let mut hand_colliders = Vec::new();
    hand_colliders.push(
        world.colliders.insert_with_parent(
            ColliderBuilder::cuboid(
                mm(hand.palm.offset_mm / 2.0),
                mm(hand.palm.half_width_mm),
                mm((z_hi - z_lo) / 2.0),
            )
            .translation(Vector::new(
                mm(hand.palm.offset_mm / 2.0),
                0.0,
                mm((z_hi + z_lo) / 2.0),
            ))
            .friction(friction as f32),
            palm,
            &mut world.bodies,
        ),
    );

    let o = hand.fingers.offset_mm;
    let (l1, l2) = (hand.phalanx_1.length_mm, hand.phalanx_2.length_mm);
    let l2_contact = l2 - hand.phalanx_2.unusable_distal_mm;
    let density = params.finger_density_kg_m3 as f32;
    let open_margin = params.open_margin_deg.to_radians();
    let limits1 = [
        bend(hand.joints.theta1_range_deg[1]) as f32,
        bend(hand.joints.theta1_range_deg[0]) as f32,
    ];
    let limits2 = [
        bend(hand.joints.theta2_range_deg[1]) as f32,
        bend(hand.joints.theta2_range_deg[0]) as f32,
    ];
    let squeeze = params.squeeze_deg.to_radians();
    let squeeze2 = params.squeeze2_deg.to_radians();
    let motor = |target: f64, limits: [f32; 2]| (target as f32).clamp(limits[0], limits[1]);
    let mut fingers = Vec::new();
    let mut opening = Vec::new();
    let mut joint2_handles = Vec::new();
    let mut joint1_handles = Vec::new();
    for (f, [t1, t2]) in hand.finger_list.iter().zip(&pose.theta_deg) {
        let s: f32 = match f.side {
            Side::Left => 1.0,
            Side::Right => -1.0,
        };
        // A phalanx's frame is its parent's turned by side × bend about the palm's z: the
        // revolute joint's angle about (0, 0, side) is then the bend itself.
        let turn = |b: f64| UnitQuaternion::from_axis_angle(&Vector3::z_axis(), f64::from(s) * b);
        let anchor1_mm = Vector3::new(
            hand.joints.setback_mm,
            f64::from(s) * hand.joints.lateral_mm,
            f.height_mm,
        );
        // Start open: each joint `open_margin_deg` short of its plan (within its limits), so
        // contact is made by closing along the planned path.
        let open1 = (bend(*t1) - open_margin).max(f64::from(limits1[0]));
        let open2 = (bend(*t2) - open_margin).max(f64::from(limits2[0]));
        let r1 = r_palm * turn(open1);
        let j1 = pose.origin_mm + r_palm * anchor1_mm;
        let b1 = world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .pose(convert::pose(&j1, &r1))
                .can_sleep(false),
        );
        hand_colliders.push(
            world.colliders.insert_with_parent(
                ColliderBuilder::cuboid(mm(o), mm(l1 / 2.0), mm(o))
                    .translation(Vector::new(0.0, s * mm(l1 / 2.0), 0.0))
                    .density(density)
                    .friction(friction as f32),
                b1,
                &mut world.bodies,
            ),
        );
        let axis = Vector::new(0.0, 0.0, s);
        let joint1 = RevoluteJointBuilder::new(axis)
            .local_anchor1(convert::vector_m(&anchor1_mm))
            .local_anchor2(Vector::ZERO)
            .limits(limits1)
            .motor_model(MotorModel::ForceBased)
            .motor_position(
                motor(bend(*t1) + squeeze, limits1),
                params.motor_stiffness_nm_per_rad as f32,
                params.motor_damping_nms_per_rad as f32,
            )
            .motor_max_force(params.torque_limit_nm as f32)
            .contacts_enabled(false);
        if let Some(h) = world.multibody_joints.insert(palm, b1, joint1, true) {
            joint1_handles.push(h);
        }

        let r2 = r1 * turn(open2);
        let j2 = j1 + r1 * Vector3::new(0.0, f64::from(s) * l1, 0.0);
        let b2 = world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .pose(convert::pose(&j2, &r2))
                .can_sleep(false),
        );
        hand_colliders.push(
            world.colliders.insert_with_parent(
                ColliderBuilder::cuboid(mm(o), mm(l2_contact / 2.0), mm(o))
                    .translation(Vector::new(0.0, s * mm(l2_contact / 2.0), 0.0))
                    .density(density)
                    .friction(friction as f32),
                b2,
                &mut world.bodies,
            ),
        );
        if l2 > l2_contact + 1e-9 {
            // The thinned tip (thesis Fig. 3.8): its contact side recedes to the tip thickness.
            let t = hand.fingers.tip_thickness_mm;
            hand_colliders.push(
                world.colliders.insert_with_parent(
                    ColliderBuilder::cuboid(mm(t / 2.0), mm((l2 - l2_contact) / 2.0), mm(o))
                        .translation(Vector::new(
                            mm(o - t / 2.0),
                            s * mm((l2 + l2_contact) / 2.0),
                            0.0,
                        ))
                        .density(density)
                        .friction(friction as f32),
                    b2,
                    &mut world.bodies,
                ),
            );
        }
        // Joint 2 is held at its open angle until released (see `Scene::release_joint2`).
        let joint2 = RevoluteJointBuilder::new(axis)
            .local_anchor1(Vector::new(0.0, s * mm(l1), 0.0))
            .local_anchor2(Vector::ZERO)
            .limits(limits2)
            .motor_model(MotorModel::ForceBased)
            .motor_position(
                open2 as f32,
                params.motor_stiffness_nm_per_rad as f32,
                params.motor_damping_nms_per_rad as f32,
            )
            .motor_max_force(params.torque_limit_nm as f32)
            .contacts_enabled(false);
        if let Some(h) = world.multibody_joints.insert(b1, b2, joint2, true) {
            joint2_handles.push((h, motor(bend(*t2) + squeeze2, limits2)));
        }
        fingers.push((b1, b2, bend(*t1), bend(*t2)));
        opening.push((b1, open1, b2, open2));
    }
    // A multibody places its links from its joint coordinates, which start at zero (every
    // phalanx straight): set them to the open pose and move the bodies there.
    for (b1, open1, b2, open2) in opening {
        let Some(link) = world.multibody_joints.rigid_body_link(b1).copied() else {
            continue;
        };
        let Some(mb) = world.multibody_joints.get_multibody_mut(link.multibody) else {
            continue;
        };
        let mut disp = vec![0.0; mb.ndofs()];
        for (body, angle) in [(b1, open1), (b2, open2)] {
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

    let object_body = world
        .bodies
        .insert(RigidBodyBuilder::dynamic().can_sleep(false));
    let object_collider = world.colliders.insert_with_parent(
        ColliderBuilder::new(object.shape.clone())
            .mass(mass_kg as f32)
            .friction(friction as f32),
        object_body,
        &mut world.bodies,
    );
    // Reach: the palm box's farthest corner, or a finger's joint 1 plus phalanx 1 plus the
    // farthest point of phalanx 2 (or its tip) from joint 2, whichever is larger; the finger
    // boxes are 2 × offset thick and wide.
    let mut reach_mm = Vector3::new(
        hand.palm.offset_mm,
        hand.palm.half_width_mm,
        z_lo.abs().max(z_hi.abs()),
    )
    .norm();
    for f in &hand.finger_list {
        let anchor = Vector3::new(hand.joints.setback_mm, hand.joints.lateral_mm, f.height_mm);
        let finger = anchor.norm() + l1 + (l2 * l2 + 2.0 * o * o).sqrt();
        reach_mm = reach_mm.max(finger);
    }
    let object_radius_m = {
        let sphere = object.shape.compute_local_bounding_sphere();
        let com = object.shape.mass_properties(1.0).local_com;
        f64::from(sphere.radius() + (sphere.center() - com).length())
    };
    Scene {
        world,
        palm,
        object: object_body,
        object_collider,
        hand_colliders,
        fingers,
        joint2: joint2_handles,
        joint1: joint1_handles,
        lock_torque: params.joint1_lock_torque_nm as f32,
        motor_gains: (
            params.motor_stiffness_nm_per_rad as f32,
            params.motor_damping_nms_per_rad as f32,
        ),
        reach_m: reach_mm * convert::M_PER_MM,
        object_radius_m,
    }
}

/// The object's centre of mass `[m]` and inertia tensor about it `[kg·m²]`, aligned frame, as the
/// rapier check has them: its collider's mass distribution scaled to `mass_kg`.
pub fn collider_inertia(
    object: &ObjectShape,
    mass_kg: f64,
) -> (nalgebra::Vector3<f64>, nalgebra::Matrix3<f64>) {
    let unit = object.shape.mass_properties(1.0);
    let density = mass_kg / f64::from(unit.mass()).max(f64::MIN_POSITIVE);
    let props = object.shape.mass_properties(density as f32);
    let m = props.reconstruct_inertia_matrix();
    let c = props.local_com;
    let cols = m.to_cols_array();
    (
        nalgebra::Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z)),
        nalgebra::Matrix3::from_column_slice(&cols.map(f64::from)),
    )
}
