//! The colliders of the hand's bodies (issue 37): the model's boxes, or, for a hand read from a
//! URDF or MJCF whose links have meshes, the convex hull of each of that link's geometry
//! elements ([`crate::hand::link_geometry`]), as the object's collider is its mesh's hull.
//!
//! Units: the pieces in millimetres in their body's frame, the shapes in metres (rapier's).

use super::convert;
use crate::hand::Hand;
use rapier3d::prelude::*;

/// The convex hulls of body `k`'s pieces (0 the palm, then each finger's phalanx 1 and 2, as
/// [`Hand::body_poses`]), in its frame `[m]`; `None` where the model's boxes stand (no link
/// geometry, or none of the body's pieces spans a volume).
pub fn link_shapes(hand: &Hand, k: usize) -> Option<Vec<SharedShape>> {
    let geometry = hand.link_geometry.as_ref()?;
    let shapes: Vec<SharedShape> = geometry
        .body(k)
        .iter()
        .filter_map(|piece| {
            let points: Vec<Vector> = piece.iter().map(convert::point_m).collect();
            SharedShape::convex_hull(&points)
        })
        .collect();
    (!shapes.is_empty()).then_some(shapes)
}

/// Inserts the palm's colliders ([`colliders`] of body 0) on `palm`; returns their handles.
pub(super) fn insert(
    world: &mut PhysicsWorld,
    palm: RigidBodyHandle,
    hand: &Hand,
    friction: f64,
    boxes: impl FnOnce() -> Vec<ColliderBuilder>,
) -> Vec<ColliderHandle> {
    colliders(hand, 0, friction, boxes)
        .into_iter()
        .map(|c| {
            world
                .colliders
                .insert_with_parent(c, palm, &mut world.bodies)
        })
        .collect()
}

/// The colliders of body `k`: its link shapes at `friction`, or `boxes()` (the model's, as the
/// scene builds them) where it has none.
pub(super) fn colliders(
    hand: &Hand,
    k: usize,
    friction: f64,
    boxes: impl FnOnce() -> Vec<ColliderBuilder>,
) -> Vec<ColliderBuilder> {
    match link_shapes(hand, k) {
        Some(shapes) => shapes
            .into_iter()
            .map(|s| ColliderBuilder::new(s).friction(friction as f32))
            .collect(),
        None => boxes(),
    }
}
