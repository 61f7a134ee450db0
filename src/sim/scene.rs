//! Building the rapier scene: palm, phalanges, joints with motors, and the object.

use super::convert;
use super::params::SimParams;
use crate::hand::{palm_rotation, BodyPose, Hand, HandBox};
use crate::mesh::Mesh;
use nalgebra::{Point3, Vector3};
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

/// Why a scenario's `[sim] override_angles` cannot be checked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OverrideError {
    /// The graded domain has no indexed elevation to put the palm on.
    #[error("override_angles: the object has no indexed elevation")]
    NoElevation,
    /// The palm could not be placed at the chosen elevation.
    #[error("override_angles: palm placement failed: {0:?}")]
    PalmPlacement(crate::plan::palm::PalmRejection),
}

impl SimHand {
    /// The hand pose for a scenario whose joint angles are fixed by `[sim] override_angles`:
    /// the palm at approach 0 and pitch 0 on indexed elevation `override_index` (default: the
    /// middle one) of the graded domain.
    ///
    /// # Errors
    /// [`OverrideError`]: why the grasp cannot be checked.
    pub fn from_override(
        mesh: &Mesh,
        hand: &Hand,
        graded: &crate::plan::GradedDomain,
        p: &SimParams,
        angles: &[[f64; 2]],
    ) -> Result<SimHand, OverrideError> {
        let n = graded.domain.elevations.len();
        if n == 0 {
            return Err(OverrideError::NoElevation);
        }
        let index = p.override_index.unwrap_or(n.div_ceil(2)).clamp(1, n);
        let z1 = graded.domain.elevations[index - 1];
        let palm = crate::plan::palm::place_palm(mesh, hand, z1, 0.0, 0.0)
            .map_err(OverrideError::PalmPlacement)?;
        Ok(SimHand {
            origin_mm: palm.origin,
            axes: palm.axes,
            theta_deg: angles.to_vec(),
        })
    }

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

/// How the object's collider was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ColliderKind {
    /// The convex hull of the mesh (the mesh is convex).
    ConvexHull,
    /// A convex decomposition (V-HACD) of the mesh.
    ConvexDecomposition,
}

impl ColliderKind {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            ColliderKind::ConvexHull => "convex_hull",
            ColliderKind::ConvexDecomposition => "convex_decomposition",
        }
    }
}

impl std::fmt::Display for ColliderKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// The object's collision shape, built once per object and shared by every run.
#[derive(Clone)]
pub struct ObjectShape {
    /// The shape in metres, aligned frame.
    pub shape: SharedShape,
    /// How it was made.
    pub kind: ColliderKind,
    /// Number of convex parts.
    pub parts: usize,
    /// True if and only if the object is inertially a body of revolution about its principal
    /// axis (aligned Z): its two transverse principal moments agree within 0.1 %.
    pub is_revolution: bool,
    /// For a convex hull that parry would merge into bent faces, rebuilt from its face planes
    /// (see `coarsened_hull`): the full hull's vertex count.
    pub coarsened_from: Option<usize>,
}

/// Convex decompositions made in this process, by the digest of their mesh: the same object
/// in several scenarios of one run (the chapter 4 object and its weak-motor twin, a tuning
/// set) is decomposed once. At most [`SHAPE_CACHE_LEN`], the oldest dropped first.
static SHAPE_CACHE: std::sync::Mutex<Vec<([u8; 32], ObjectShape)>> =
    std::sync::Mutex::new(Vec::new());

/// Convex decompositions kept by [`ObjectShape::cached`].
pub const SHAPE_CACHE_LEN: usize = 16;

/// The digest of what [`ObjectShape::from_mesh`] reads: vertices, triangles and volume.
fn shape_key(mesh: &Mesh, volume_mm3: f64) -> [u8; 32] {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    for p in &mesh.vertices {
        for v in [p.x, p.y, p.z] {
            h.update(v.to_bits().to_le_bytes());
        }
    }
    h.update(b"t");
    for t in &mesh.triangles {
        for i in t {
            h.update(i.to_le_bytes());
        }
    }
    h.update(volume_mm3.to_bits().to_le_bytes());
    h.finalize().into()
}

impl ObjectShape {
    /// [`ObjectShape::from_mesh`], with convex decompositions (0.1–0.4 s each) and rebuilt hulls
    /// (tens of milliseconds) kept for the rest of the process: the same mesh gives the same
    /// shape, bit for bit, either way.
    pub fn cached(mesh: &Mesh, volume_mm3: f64) -> ObjectShape {
        let key = shape_key(mesh, volume_mm3);
        let lock = || SHAPE_CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, s)) = lock().iter().find(|(k, _)| *k == key) {
            return s.clone();
        }
        let shape = ObjectShape::from_mesh(mesh, volume_mm3);
        if shape.kind == ColliderKind::ConvexDecomposition || shape.coarsened_from.is_some() {
            let mut cache = lock();
            if !cache.iter().any(|(k, _)| *k == key) {
                if cache.len() >= SHAPE_CACHE_LEN {
                    cache.remove(0);
                }
                cache.push((key, shape.clone()));
            }
        }
        shape
    }

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
                let rebuilt = (bent_shape_m(&hull) > MERGED_FACE_TOLERANCE_M)
                    .then(|| coarsened_hull(&points))
                    .flatten();
                let (shape, coarsened_from) = match rebuilt {
                    Some((coarse, from)) => (coarse, Some(from)),
                    None => (hull, None),
                };
                return ObjectShape {
                    shape,
                    kind: ColliderKind::ConvexHull,
                    parts: 1,
                    is_revolution,
                    coarsened_from,
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
            kind: ColliderKind::ConvexDecomposition,
            parts,
            is_revolution,
            coarsened_from: None,
        }
    }
}

/// How far a vertex of a merged hull face may lie off that face's plane `[m]`: rapier's allowed
/// contact error at the check's 1 cm length unit (0.05 mm).
const MERGED_FACE_TOLERANCE_M: f32 = 5e-5;

/// How far the faces of `poly` leave their planes `[m]`. parry builds a hull's faces by merging
/// neighbouring triangles whose unit normals differ by less than √ε of f32 in `1 − n₁·n₂`
/// (about 1.5°; `ConvexPolyhedron::from_convex_mesh`), with the normal of one of them: right for a plane split into triangles, wrong for a finely tessellated curved
/// surface (a cylinder of more than about 240 segments, whose faces meet at under 1.5°), which
/// it chains into one non-planar face. The contacts against that face let a finger sink in:
/// 8.4 mm into a 512-segment cylinder of 60 mm, against 0.01 mm at 144 segments.
fn bent_face_m(poly: &rapier3d::parry::shape::ConvexPolyhedron) -> f32 {
    let (points, ids) = (poly.points(), poly.vertices_adj_to_face());
    poly.faces()
        .iter()
        .map(|f| {
            let first = f.first_vertex_or_edge as usize;
            let face = &ids[first..first + f.num_vertices_or_edges as usize];
            let p = points[face[0] as usize];
            face.iter()
                .map(|&i| f.normal.dot(points[i as usize] - p).abs())
                .fold(0.0f32, f32::max)
        })
        .fold(0.0f32, f32::max)
}

/// [`bent_face_m`] of a shape that is a convex polyhedron (0 for any other).
fn bent_shape_m(shape: &SharedShape) -> f32 {
    shape.as_convex_polyhedron().map_or(0.0, bent_face_m)
}

/// Neighbouring faces of the hull from [`coarsened_hull`] are at least this far apart in
/// normal: 2°, beyond parry's merge of 1.5°.
const MIN_FACE_ANGLE_RAD: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// A face plane of the hull is a supporting plane if no hull vertex lies further than this
/// outside it `[m]` (0.1 µm; f32 coordinates of a 0.1 m object are good to about 0.01 µm).
const SUPPORT_TOLERANCE_M: f64 = 1e-7;

/// The rebuilt hull may stand off the true one by at most this `[m]` (0.05 mm) or it is not used.
const MAX_OUTER_STANDOFF_M: f64 = 5e-5;

/// The convex hull of `points` (metres), rebuilt where parry would merge curved faces into
/// non-planar ones ([`bent_face_m`]): the hull's face planes are taken largest
/// face first, each kept only if its normal is at least [`MIN_FACE_ANGLE_RAD`] from every plane
/// kept (a plane split into triangles is one plane, kept once), and the hull is rebuilt as the
/// intersection of the kept half-spaces (its vertices found through the polar dual: the convex
/// hull of the planes' poles, each of whose triangles is a vertex where its three planes meet).
/// Every kept plane is a plane of the true hull, so the rebuilt one contains it, and stands off
/// it by about r·θ²/8 on a round part of radius r (0.01 mm on a 60 mm cylinder at 2°); any
/// two of its faces meet at 2° or more, so parry keeps them apart. Returns it with the full
/// hull's vertex count, or `None` where the full hull needs no rebuilding (every thesis object)
/// or the rebuilt one would stand off by more than [`MAX_OUTER_STANDOFF_M`].
fn coarsened_hull(points: &[Vector]) -> Option<(SharedShape, usize)> {
    use rapier3d::parry::transformation::try_convex_hull;
    let (vertices, triangles) = try_convex_hull(points).ok()?;
    let v64: Vec<Vector3<f64>> = vertices
        .iter()
        .map(|v| Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z)))
        .collect();
    let centre = v64.iter().sum::<Vector3<f64>>() / v64.len() as f64;
    // Each triangle's plane n·(x − centre) = d, with its area.
    let true_planes: Vec<(f64, Vector3<f64>, f64)> = triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| v64[i as usize]);
            let cross = (b - a).cross(&(c - a));
            let area = cross.norm();
            (area > 0.0).then(|| {
                let n = cross / area;
                (area, n, n.dot(&(a - centre)))
            })
        })
        .collect();
    let mut planes: Vec<(f64, Vector3<f64>, f64)> =
        true_planes.iter().copied().filter(|p| p.2 > 0.0).collect();
    planes.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.2.total_cmp(&b.2)));
    let cos_min = MIN_FACE_ANGLE_RAD.cos();
    let mut kept: Vec<(Vector3<f64>, f64)> = Vec::new();
    // A sliver triangle of nearly collinear points (a side's rings, one above the other) has a
    // normal of rounding noise: its plane is kept only if the whole hull is on its inner side.
    let supporting = |n: &Vector3<f64>, d: f64| {
        v64.iter()
            .all(|v| n.dot(&(v - centre)) <= d + SUPPORT_TOLERANCE_M)
    };
    for (_, n, d) in planes {
        if kept.iter().all(|(m, _)| m.dot(&n) < cos_min) && supporting(&n, d) {
            kept.push((n, d));
        }
    }
    // The poles n / d; each triangle of their hull is a vertex of the intersection.
    let poles: Vec<Vector> = kept
        .iter()
        .map(|(n, d)| {
            let p = n / *d;
            Vector::new(p.x as f32, p.y as f32, p.z as f32)
        })
        .collect();
    let (dual_points, dual_triangles) = try_convex_hull(&poles).ok()?;
    let by_pole: std::collections::HashMap<[u32; 3], usize> = poles
        .iter()
        .enumerate()
        .map(|(k, p)| (p.to_array().map(f32::to_bits), k))
        .collect();
    // How far a point (relative to the centre) stands outside the true hull `[m]`.
    let standoff = |x: &Vector3<f64>| {
        true_planes
            .iter()
            .map(|(_, n, d)| n.dot(x) - d)
            .fold(0.0f64, f64::max)
    };
    let mut corners: Vec<Vector> = Vec::new();
    for t in &dual_triangles {
        let planes = t.map(|i| {
            by_pole
                .get(&dual_points[i as usize].to_array().map(f32::to_bits))
                .map(|&k| kept[k])
        });
        let [Some(p1), Some(p2), Some(p3)] = planes else {
            continue;
        };
        let m =
            nalgebra::Matrix3::from_rows(&[p1.0.transpose(), p2.0.transpose(), p3.0.transpose()]);
        // Three nearly parallel planes (a sliver of the dual hull) meet far off, or nowhere:
        // their corner is another triangle's.
        let Some(x) = m.lu().solve(&Vector3::new(p1.1, p2.1, p3.1)) else {
            continue;
        };
        if x.iter().all(|c| c.is_finite()) && standoff(&x) <= MAX_OUTER_STANDOFF_M {
            let p = x + centre;
            corners.push(Vector::new(p.x as f32, p.y as f32, p.z as f32));
        }
    }
    let rebuilt = SharedShape::convex_hull(&corners)?;
    let poly = rebuilt.as_convex_polyhedron()?;
    if poly.points().len() < 4 || bent_face_m(poly) > MERGED_FACE_TOLERANCE_M {
        return None;
    }
    // It must hold the whole true hull (no corner lost to the skips above): every vertex inside
    // every face plane parry made.
    let ids = poly.vertices_adj_to_face();
    let inside = poly.faces().iter().all(|f| {
        let a = poly.points()[ids[f.first_vertex_or_edge as usize] as usize];
        let a = Vector3::new(f64::from(a.x), f64::from(a.y), f64::from(a.z));
        let n = Vector3::new(
            f64::from(f.normal.x),
            f64::from(f.normal.y),
            f64::from(f.normal.z),
        );
        v64.iter().all(|x| n.dot(&(x - a)) <= SUPPORT_TOLERANCE_M)
    });
    inside.then_some((rebuilt, vertices.len()))
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
    pub joint1: MultibodyJointHandle,
    /// Joint 2 (phalanx 1 to phalanx 2), held open until released.
    pub joint2: MultibodyJointHandle,
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
        let (stiffness, d) = self.motor_gains;
        let Some(f) = self.fingers.get(k) else { return };
        if let Some((mb, id)) = self.world.multibody_joints.get_mut(f.joint1) {
            if let Some(link) = mb.link_mut(id) {
                let target = if hold {
                    link.joint.coords()[3]
                } else {
                    f.joint1_target
                };
                link.joint
                    .data
                    .set_motor_position(JointAxis::AngX, target, stiffness, d);
            }
        }
    }

    /// Locks joint 1 where it stopped and lets joint 2 close to its target: thesis 3.6.2 fixes
    /// phalanx 1 before phalanx 2, and a Barrett finger (TorqueSwitch) closes joint 1 until it
    /// stalls, after which its worm drive, which cannot be back-driven, holds it while joint 2
    /// closes. Without the lock, joint 2's reaction torque lifts phalanx 1 off the object.
    pub fn release_joint2(&mut self) {
        let (k, d) = self.motor_gains;
        for f in &self.fingers {
            if let Some((mb, id)) = self.world.multibody_joints.get_mut(f.joint1) {
                if let Some(link) = mb.link_mut(id) {
                    let angle = link.joint.coords()[3];
                    link.joint
                        .data
                        .set_motor_position(JointAxis::AngX, angle, k * 10.0, d)
                        .set_motor_max_force(JointAxis::AngX, self.lock_torque);
                }
            }
        }
        for f in &self.fingers {
            if let Some((mb, id)) = self.world.multibody_joints.get_mut(f.joint2) {
                if let Some(link) = mb.link_mut(id) {
                    link.joint
                        .data
                        .set_motor_position(JointAxis::AngX, f.joint2_target, k, d);
                }
            }
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
            if params.balanced_squeeze && fewest > 0 && own > 0 {
                params.torque_limit_nm * fewest as f64 / own as f64
            } else {
                params.torque_limit_nm
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
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Start {
    /// The palm's origin `[mm]` (the planned one moved by `palm_backoff_mm` along palm x).
    #[serde(skip)]
    pub origin_mm: Point3<f64>,
    /// How far the palm was backed off the collider `[mm]` (0 when it starts clear).
    pub palm_backoff_mm: f64,
    /// Per finger, the bends the joints start at `[rad]`.
    #[serde(skip)]
    pub open_bend_rad: Vec<[f64; 2]>,
    /// Per finger, the margin it starts open by `[deg]`.
    pub open_margin_deg: Vec<f64>,
    /// The deepest penetration of a hand collider into the object's left at the start `[mm]`
    /// (0 when everything starts clear).
    pub penetration_mm: f64,
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

/// The start of the check for `case` (see [`Start`]).
pub fn start(case: &Case) -> Start {
    let Case {
        hand,
        pose,
        object,
        params,
        ..
    } = *case;
    let r_palm = palm_rotation(&pose.axes);
    let palm = [hand.palm_box()];
    let limits1 = [
        bend(hand.joints.theta1_range_deg[1]),
        bend(hand.joints.theta1_range_deg[0]),
    ];
    let limits2 = [
        bend(hand.joints.theta2_range_deg[1]),
        bend(hand.joints.theta2_range_deg[0]),
    ];
    // The palm: backed off by the depth found, plus the tolerance, until clear (a few rounds:
    // moving off one part can meet another only in a concave object).
    let mut origin = pose.origin_mm;
    let mut backoff = 0.0;
    for _ in 0..10 {
        let d = overlap_mm(&object.shape, &(origin, r_palm), &palm);
        if d <= START_TOLERANCE_MM {
            break;
        }
        backoff += d + START_TOLERANCE_MM;
        origin = pose.origin_mm + pose.axes[0] * backoff;
    }
    let mut penetration = overlap_mm(&object.shape, &(origin, r_palm), &palm);
    let margin0 = params.open_margin_deg;
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
    let mut open_bend = Vec::new();
    let mut open_margin = Vec::new();
    for (f, [t1, t2]) in hand.finger_list.iter().zip(&pose.theta_deg) {
        let (p1, p2) = hand.phalanx_boxes(f.side);
        let at = |m: f64| {
            let b1 = (bend(*t1) - m.to_radians()).max(limits1[0]);
            let b2 = (bend(*t2) - m.to_radians()).max(limits2[0]);
            let [f1, f2] = hand.finger_poses(f, &(origin, r_palm), [b1, b2]);
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
        match found {
            Some((m, b)) => {
                open_margin.push(m);
                open_bend.push(b);
            }
            None => {
                // No margin clears it: start as the scenario says, and report the overlap.
                penetration = penetration.max(d0);
                open_margin.push(margin0);
                open_bend.push(first);
            }
        }
    }
    Start {
        origin_mm: origin,
        palm_backoff_mm: backoff,
        open_bend_rad: open_bend,
        open_margin_deg: open_margin,
        penetration_mm: penetration,
    }
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
    // the fingers by 0.03 mm per period, docs/SIM.md.)
    let palm = world
        .bodies
        .insert(RigidBodyBuilder::fixed().pose(convert::pose(&start.origin_mm, &r_palm)));
    let mut hand_colliders = vec![world.colliders.insert_with_parent(
        hand_collider(&hand.palm_box(), friction),
        palm,
        &mut world.bodies,
    )];
    let fingers: Vec<SimFinger> = hand
        .finger_list
        .iter()
        .zip(&pose.theta_deg)
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
    for (f, open) in fingers.iter().zip(&start.open_bend_rad) {
        set_open(&mut world, f, *open);
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
    Scene {
        world,
        palm,
        object: object_body,
        object_collider,
        hand_colliders,
        fingers,
        lock_torque: params.joint1_lock_torque_nm as f32,
        motor_gains: (
            params.motor_stiffness_nm_per_rad as f32,
            params.motor_damping_nms_per_rad as f32,
        ),
        reach_m: reach_mm(hand) * convert::M_PER_MM,
        object_radius_m: object_radius_m(object),
    }
}

/// An empty world, gravity off, with the integration parameters of the check.
fn new_world(params: &SimParams) -> PhysicsWorld {
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
    let hz = params.contact_stiffness_hz as f32;
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
    let density = params.finger_density_kg_m3 as f32;
    let limits = |range: [f64; 2]| [bend(range[1]) as f32, bend(range[0]) as f32];
    let limits1 = limits(hand.joints.theta1_range_deg);
    let limits2 = limits(hand.joints.theta2_range_deg);
    let motor = |target: f64, limits: [f32; 2]| (target as f32).clamp(limits[0], limits[1]);
    let revolute = |anchor: &Vector3<f64>, limits: [f32; 2], target: f32| {
        RevoluteJointBuilder::new(Vector::new(0.0, 0.0, f.side.sign() as f32))
            .local_anchor1(convert::vector_m(anchor))
            .local_anchor2(Vector::ZERO)
            .limits(limits)
            .motor_model(MotorModel::ForceBased)
            .motor_position(
                target,
                params.motor_stiffness_nm_per_rad as f32,
                params.motor_damping_nms_per_rad as f32,
            )
            .motor_max_force(at.torque_nm as f32)
            .contacts_enabled(false)
    };
    let (p1, p2) = hand.phalanx_boxes(f.side);
    let [(j1, r1), (j2, r2)] = hand.finger_poses(f, &at.palm_pose, [open1, open2]);
    let mut phalanx = |world: &mut PhysicsWorld, pose: Pose, boxes: &[HandBox]| {
        let body = world
            .bodies
            .insert(RigidBodyBuilder::dynamic().pose(pose).can_sleep(false));
        for b in boxes {
            hand_colliders.push(world.colliders.insert_with_parent(
                hand_collider(b, friction).density(density),
                body,
                &mut world.bodies,
            ));
        }
        body
    };
    let squeeze = params.squeeze_deg.to_radians();
    let squeeze2 = params.squeeze2_deg.to_radians();
    // Body, colliders, joint, in this order for each phalanx: rapier's state (and so the run)
    // depends on the order of insertion.
    let b1 = phalanx(world, convert::pose(&j1, &r1), &[p1]);
    let joint1 = revolute(
        &hand.joint1_anchor_mm(f),
        limits1,
        motor(bend(t1) + squeeze, limits1),
    );
    let joint1 = world
        .multibody_joints
        .insert(palm, b1, joint1, true)
        .expect("joint 1 closes no loop");
    let b2 = phalanx(world, convert::pose(&j2, &r2), &p2);
    // Joint 2 is held at its open angle until released (see `Scene::release_joint2`).
    let joint2 = revolute(&hand.joint2_anchor_mm(f.side), limits2, open2 as f32);
    let joint2 = world
        .multibody_joints
        .insert(b1, b2, joint2, true)
        .expect("joint 2 closes no loop");
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
    let com = object.shape.mass_properties(1.0).local_com;
    f64::from(sphere.radius() + (sphere.center() - com).length())
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn thesis_hand() -> Hand {
        let (_, text) = crate::hand::bundled("thesis").unwrap();
        Hand::parse(text, Path::new("thesis.toml"), &[]).unwrap()
    }

    #[test]
    fn a_convex_decomposition_is_made_once_per_mesh() {
        let objects = crate::objects::thesis_objects();
        let mesh = &objects.iter().find(|(n, _)| *n == "chapter4").unwrap().1;
        let mesh = crate::mesh::align(mesh).mesh;
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let first = ObjectShape::cached(&mesh, volume);
        assert_eq!(first.kind, ColliderKind::ConvexDecomposition);
        // The same mesh again: the same shape, not a new decomposition.
        let again = ObjectShape::cached(&mesh, volume);
        assert!(std::sync::Arc::ptr_eq(&first.shape.0, &again.shape.0));
        // Equal to one made afresh, part for part.
        let fresh = ObjectShape::from_mesh(&mesh, volume);
        assert_eq!(fresh.parts, first.parts);
        let aabb = |s: &ObjectShape| s.shape.compute_local_aabb();
        assert_eq!(aabb(&fresh), aabb(&first));
        // Another mesh (one vertex moved) is another key.
        let mut moved = mesh.clone();
        moved.vertices[0].x += 1e-3;
        assert_ne!(shape_key(&moved, volume), shape_key(&mesh, volume));
        // A convex mesh is not kept (its hull is cheap).
        let prism = crate::objects::prism(40.0, 100.0, 80.0);
        let v = crate::mesh::mass_properties(&prism).volume_mm3;
        let a = ObjectShape::cached(&prism, v);
        let b = ObjectShape::cached(&prism, v);
        assert_eq!(a.kind, ColliderKind::ConvexHull);
        assert!(!std::sync::Arc::ptr_eq(&a.shape.0, &b.shape.0));
    }

    /// A cylinder of 60 mm and 120 mm on `segments` facets, with a ring every 10 mm.
    fn fine_cylinder(segments: usize) -> Mesh {
        use crate::objects::{radial_solid, uniform_angles, Ring};
        let rings: Vec<Ring> = (0..=12)
            .map(|k| Ring {
                z: 10.0 * k as f64,
                radii: vec![30.0; segments],
            })
            .collect();
        radial_solid(&uniform_angles(segments), &rings)
    }

    #[test]
    fn a_hull_parry_would_merge_into_curved_faces_is_rebuilt_from_its_planes() {
        let shape = |segments| {
            let mesh = fine_cylinder(segments);
            let v = crate::mesh::mass_properties(&mesh).volume_mm3;
            (ObjectShape::from_mesh(&mesh, v), mesh)
        };
        let hull_of = |s: &ObjectShape| {
            let c = s.shape.as_convex_polyhedron().unwrap();
            rapier3d::parry::transformation::try_convex_hull(c.points()).unwrap()
        };
        // 144 facets meet at 2.5°: parry keeps them apart, and the hull is the plain one, as for
        // every thesis object.
        let (plain, _) = shape(144);
        assert_eq!(plain.coarsened_from, None);
        assert_eq!(plain.kind, ColliderKind::ConvexHull);
        // 512 facets meet at 0.7°, within parry's 1.5° merge: the side would become one face
        // bent round the cylinder, some 30 mm off its own plane.
        let mesh = fine_cylinder(512);
        let points: Vec<Vector> = mesh.vertices.iter().map(convert::point_m).collect();
        let bent = bent_shape_m(&SharedShape::convex_hull(&points).unwrap());
        assert!(bent > 0.02, "{bent} m");
        assert!(bent_shape_m(&plain.shape) <= MERGED_FACE_TOLERANCE_M);
        let (rebuilt, mesh) = shape(512);
        assert_eq!(rebuilt.coarsened_from, Some(1024));
        let (v, t) = hull_of(&rebuilt);
        assert!(bent_shape_m(&rebuilt.shape) <= MERGED_FACE_TOLERANCE_M);
        // Fewer facets, no two within 2° of each other: 512 / (2° of 0.703°) rounds to 148 or so.
        assert!((200..=400).contains(&v.len()), "{} vertices", v.len());
        // It holds the whole mesh (every vertex inside every face plane, to 0.1 µm) and stands
        // off it by under 0.05 mm: every corner within 30 mm + 0.05 mm of the axis and within
        // the caps.
        for tri in &t {
            let [a, b, c] = tri.map(|i| v[i as usize]);
            let n = (b - a).cross(c - a).normalize();
            for p in &mesh.vertices {
                let out = n.dot(convert::point_m(p) - a);
                assert!(out <= 1e-7, "{p:?}: {out} m outside");
            }
        }
        for c in &v {
            let r = (c.x * c.x + c.y * c.y).sqrt();
            assert!((0.0299..=0.030_05).contains(&r), "{r} m");
            assert!(c.z >= -1e-6 && c.z <= 0.120 + 1e-6, "{} m", c.z);
        }
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
