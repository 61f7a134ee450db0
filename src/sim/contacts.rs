//! The contacts that carry the grip: the contact points between the hand's colliders and the
//! object where the solver pushed at the last step, in the object's frame.
//!
//! The object body starts at the identity pose, so its local frame is the aligned object frame
//! (in metres); points are reported in it in millimetres, as [`crate::quality`] takes them.

use super::convert;
use super::scene::Scene;
use rapier3d::prelude::*;

/// How far a query looks for the nearer side of two shapes `[m]`: far beyond any object.
const REACH_M: f32 = 1.0;

/// The separation between two shapes `[m]`, 0 when they touch or overlap; `None` if parry
/// measures nothing.
///
/// parry's `distance` between two convex shapes reads a GJK that has not converged after its
/// 100 iterations as 0 (parry3d 0.31.1, `distance_support_map_support_map`: "GJK did not
/// converge"): a phalanx box 1.7 mm clear of the Adroit ball's 482-vertex hull, never touched
/// in the closing, read 0. Its `contact` query (GJK from the other side, then EPA) measured
/// 1.7 mm, as the narrow phase's own manifold had the pair apart. So the contact query, with
/// a reach far beyond any object, measures; `distance` answers only where it finds nothing.
pub fn separation_m(
    pose1: &Pose,
    shape1: &dyn Shape,
    pose2: &Pose,
    shape2: &dyn Shape,
) -> Option<f64> {
    match rapier3d::parry::query::contact(pose1, shape1, pose2, shape2, REACH_M) {
        Ok(Some(c)) => Some(f64::from(c.dist).max(0.0)),
        _ => rapier3d::parry::query::distance(pose1, shape1, pose2, shape2)
            .ok()
            .map(|d| f64::from(d.distance)),
    }
}

/// One contact point between the hand and the object.
#[derive(Debug, Clone, PartialEq)]
pub struct GripContact {
    /// Contact point on the object, aligned object frame `[mm]`.
    pub point_mm: [f64; 3],
    /// Unit direction in which the hand pushes the object, aligned object frame.
    pub normal: [f64; 3],
    /// The finger's index in the hand, `None` for the palm.
    pub finger: Option<usize>,
    /// 1 or 2 for a phalanx (the thinned tip counts as phalanx 2), 0 for the palm.
    pub phalanx: u8,
    /// The normal force the solver applied at the last step `[N]`.
    pub force_n: f64,
}

/// The contacts between the hand and the object that carried force at the last step (a
/// positive normal impulse), in a fixed order (by finger, phalanx, then as rapier lists them).
pub fn grip_contacts(scene: &Scene) -> Vec<GripContact> {
    let world = &scene.world;
    let dt = f64::from(world.integration_parameters.dt);
    let Some(obj) = world.bodies.get(scene.object) else {
        return Vec::new();
    };
    let obj_pose = *obj.position();
    let part_of = |c: ColliderHandle| -> Option<(Option<usize>, u8)> {
        let body = world.colliders.get(c)?.parent()?;
        if body == scene.palm {
            return Some((None, 0));
        }
        scene.fingers.iter().enumerate().find_map(|(i, f)| {
            (body == f.phalanx1)
                .then_some((Some(i), 1))
                .or((body == f.phalanx2).then_some((Some(i), 2)))
        })
    };
    let mut out = Vec::new();
    for pair in world.narrow_phase.contact_pairs_with(scene.object_collider) {
        let (hand, object_first) = if pair.collider1 == scene.object_collider {
            (pair.collider2, true)
        } else {
            (pair.collider1, false)
        };
        let Some((finger, phalanx)) = part_of(hand) else {
            continue;
        };
        let Some(obj_collider) = world.colliders.get(scene.object_collider) else {
            continue;
        };
        let co_pose = *obj_collider.position();
        // The solver's manifolds, not the narrow phase's: against a compound object (a convex
        // decomposition) rapier merges the per-part manifolds that share a normal into clusters
        // and solves those, so only the clusters carry impulses.
        for m in pair.solver_manifolds() {
            // `data.normal` points from collider 1 to collider 2 (world frame).
            let n_world = if object_first {
                -m.data.normal
            } else {
                m.data.normal
            };
            let n_obj = obj_pose.rotation.inverse() * n_world;
            for p in &m.points {
                if p.data.impulse <= 0.0 {
                    continue;
                }
                // In the part's frame for a plain manifold of a compound, in the collider's
                // for a cluster (which has no part pose).
                let (local, part) = if object_first {
                    (p.local_p1, m.subshape_pos1())
                } else {
                    (p.local_p2, m.subshape_pos2())
                };
                let local = part.map_or(local, |pose| pose.transform_point(local));
                let world_p = co_pose.transform_point(local);
                let in_obj = obj_pose.inverse_transform_point(world_p);
                let mm = convert::vector_mm(in_obj);
                let n = convert::vector_mm(n_obj) * convert::M_PER_MM;
                out.push(GripContact {
                    point_mm: [mm.x, mm.y, mm.z],
                    normal: [n.x, n.y, n.z],
                    finger,
                    phalanx,
                    force_n: f64::from(p.data.impulse) / dt,
                });
            }
        }
    }
    out.sort_by_key(|c| (c.finger.map_or(0, |i| i + 1), c.phalanx));
    out
}

/// How close the hand's contacts on the object are to sliding, at the last substep.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrictionUse {
    /// The largest `|tangent impulse| / (μ × normal impulse)` over the contact points that
    /// carry at least 2 % of the total normal impulse (1 = at the edge of the friction cone).
    pub max_ratio: f64,
    /// The share of the total normal impulse carried by points at 98 % of the cone or more.
    pub sliding_share: f64,
    /// The number of contact points carrying a normal impulse.
    pub points: usize,
}

/// The friction the solver used at the last substep on the contacts between the hand and the
/// object, against what Coulomb's cone allows (the solver caps each point's tangent impulse at
/// μ times its normal impulse).
pub fn friction_use(scene: &Scene) -> FrictionUse {
    let world = &scene.world;
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for pair in world.narrow_phase.contact_pairs_with(scene.object_collider) {
        let hand = if pair.collider1 == scene.object_collider {
            pair.collider2
        } else {
            pair.collider1
        };
        if !scene.hand_colliders.contains(&hand) {
            continue;
        }
        for m in pair.solver_manifolds() {
            let mu = f64::from(m.data.friction);
            for sc in &m.data.solver_contacts {
                let id = (sc.contact_id[0] & !NEW_CONTACT_BIT) as usize;
                let Some(p) = m.points.get(id) else { continue };
                let n = f64::from(p.data.warmstart_impulse);
                if n <= 0.0 {
                    continue;
                }
                let t = f64::from(p.data.warmstart_tangent_impulse.norm());
                let ratio = if mu > 0.0 { t / (mu * n) } else { 1.0 };
                pts.push((n, ratio));
            }
        }
    }
    let total: f64 = pts.iter().map(|p| p.0).sum();
    let mut out = FrictionUse {
        points: pts.len(),
        ..FrictionUse::default()
    };
    for (n, ratio) in pts {
        if n >= 0.02 * total {
            out.max_ratio = out.max_ratio.max(ratio);
        }
        if ratio >= 0.98 {
            out.sliding_share += n / total;
        }
    }
    out
}

/// True if and only if the object touches the hand.
pub(super) fn touches_hand(scene: &Scene) -> bool {
    scene
        .world
        .narrow_phase
        .contact_pairs_with(scene.object_collider)
        .any(|pair| {
            pair.has_any_active_contact()
                && (scene.hand_colliders.contains(&pair.collider1)
                    || scene.hand_colliders.contains(&pair.collider2))
        })
}
