//! The narrow phase's contact generation, with parry's manifolds checked against its own contact
//! query.
//!
//! parry 0.31 keeps a convex pair's contact manifold from one step to the next, only updating
//! its points' separations, while the shapes turn under 1° and slide under 1 mm
//! (`ContactManifold::try_update_contacts_eps`), and when it does rebuild one it starts GJK from
//! the kept manifold's normal (`contact_manifold_pfm_pfm`'s `init_dir`). From that start, on a
//! phalanx box that has slid onto another facet of a hull, GJK and EPA can settle on a wrong
//! normal: the Adroit ball's finger_3 phalanx 2 ended 0.37–0.48 mm inside the ball's hull with
//! the rebuilt manifold's one point 2.3 mm clear, step after step, so the solver had no contact
//! and the motor closed it through its whole squeeze (docs/SIM.md, "The cause, and the fix").
//!
//! [`CheckedManifolds`] is parry's default dispatcher, except that before a convex pair's
//! manifold is updated, parry's `contact` query (GJK from the shapes' own offset) is run on the
//! pair, and if it finds them overlapping and deeper than the manifold's deepest point by more
//! than [`DISAGREE_M`], the manifold is rebuilt from scratch: not kept, and GJK not started from
//! its old normal. (A manifold that only misjudges a gap is left alone: the solver's predictive
//! contacts cover a gap, and rebuilding those too made the D40's hold creep, its six directions
//! decided at 0.17 s instead of 0.06.) The points are kept for parry's matching of feature ids (the solver's warm
//! start). Convex parts of a compound (an object's convex decomposition) are checked part by
//! part. A manifold that agrees with the query is left to parry, so a closing whose contacts
//! are right is the same as before to the bit.

use rapier3d::parry::query::{
    self, ClosestPoints, Contact, ContactManifold, ContactManifoldsWorkspace,
    DefaultQueryDispatcher, NonlinearRigidMotion, PersistentQueryDispatcher, QueryDispatcher,
    ShapeCastHit, ShapeCastOptions, Unsupported,
};
use rapier3d::parry::shape::{Shape, ShapeType};
use rapier3d::prelude::{Pose, Real, Vector};

/// How much deeper than a kept manifold's deepest point parry's contact query must find an
/// overlapping convex pair before the manifold is rebuilt `[m]`: 0.05 mm, a quarter of the contact
/// prediction distance at the check's `length_unit`.
pub const DISAGREE_M: Real = 5e-5;

/// parry's default dispatcher, with each convex pair's manifold checked against parry's contact
/// query and rebuilt from scratch when the two disagree.
#[derive(Debug, Clone, Copy, Default)]
pub struct CheckedManifolds;

/// Marks `manifold` for a rebuild from scratch if the shapes overlap deeper than its deepest
/// point.
fn check<M, C: Default + Copy>(
    manifold: &mut ContactManifold<M, C>,
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    prediction: Real,
) {
    let kept = manifold
        .points
        .iter()
        .map(|p| p.dist)
        .fold(Real::INFINITY, Real::min);
    if !kept.is_finite() {
        // No points: parry builds the manifold afresh anyway.
        return;
    }
    if let Ok(Some(c)) = DefaultQueryDispatcher.contact(pos12, g1, g2, prediction) {
        if c.dist < 0.0 && c.dist < kept - DISAGREE_M {
            manifold.mark_shapes_deformed();
            manifold.local_n1 = Vector::ZERO;
        }
    }
}

impl QueryDispatcher for CheckedManifolds {
    fn intersection_test(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<query::ShapeIntersection, Unsupported> {
        DefaultQueryDispatcher.intersection_test(pos12, g1, g2)
    }

    fn distance(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<query::ShapeDistance, Unsupported> {
        DefaultQueryDispatcher.distance(pos12, g1, g2)
    }

    fn contact(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
    ) -> Result<Option<Contact>, Unsupported> {
        DefaultQueryDispatcher.contact(pos12, g1, g2, prediction)
    }

    fn closest_points(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        max_dist: Real,
    ) -> Result<ClosestPoints, Unsupported> {
        DefaultQueryDispatcher.closest_points(pos12, g1, g2, max_dist)
    }

    fn cast_shapes(
        &self,
        pos12: &Pose,
        local_vel12: Vector,
        g1: &dyn Shape,
        g2: &dyn Shape,
        options: ShapeCastOptions,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        DefaultQueryDispatcher.cast_shapes(pos12, local_vel12, g1, g2, options)
    }

    fn cast_shapes_nonlinear(
        &self,
        motion1: &NonlinearRigidMotion,
        g1: &dyn Shape,
        motion2: &NonlinearRigidMotion,
        g2: &dyn Shape,
        start_time: Real,
        end_time: Real,
        stop_at_penetration: bool,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        DefaultQueryDispatcher.cast_shapes_nonlinear(
            motion1,
            g1,
            motion2,
            g2,
            start_time,
            end_time,
            stop_at_penetration,
        )
    }
}

impl<M, C> PersistentQueryDispatcher<M, C> for CheckedManifolds
where
    M: Default + Clone + Send + Sync,
    C: Default + Copy + Send + Sync,
{
    fn contact_manifolds(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
        manifolds: &mut Vec<ContactManifold<M, C>>,
        workspace: &mut Option<ContactManifoldsWorkspace>,
    ) -> Result<(), Unsupported> {
        use rapier3d::parry::query::details::{
            contact_manifolds_composite_shape_composite_shape as composite_composite,
            contact_manifolds_composite_shape_shape as composite_shape,
        };
        let is_compound = |g: &dyn Shape| g.shape_type() == ShapeType::Compound;
        let is_convex = |g: &dyn Shape| g.is_convex();
        // Compounds of convex parts and convex shapes go through this dispatcher, so that
        // every convex pair is checked; anything else is parry's.
        match (is_compound(g1), is_compound(g2)) {
            (true, true) => {
                let (c1, c2) = (g1.as_composite_shape(), g2.as_composite_shape());
                if let (Some(c1), Some(c2)) = (c1, c2) {
                    composite_composite(self, pos12, c1, c2, prediction, manifolds, workspace);
                    return Ok(());
                }
            }
            (true, false) if is_convex(g2) => {
                if let Some(c1) = g1.as_composite_shape() {
                    composite_shape(self, pos12, c1, g2, prediction, manifolds, workspace, false);
                    return Ok(());
                }
            }
            (false, true) if is_convex(g1) => {
                if let Some(c2) = g2.as_composite_shape() {
                    let pos21 = pos12.inverse();
                    composite_shape(self, &pos21, c2, g1, prediction, manifolds, workspace, true);
                    return Ok(());
                }
            }
            (false, false) if is_convex(g1) && is_convex(g2) => {
                if manifolds.is_empty() {
                    manifolds.push(ContactManifold::new());
                }
                return self.contact_manifold_convex_convex(
                    pos12,
                    g1,
                    g2,
                    None,
                    None,
                    prediction,
                    &mut manifolds[0],
                );
            }
            _ => {}
        }
        DefaultQueryDispatcher.contact_manifolds(pos12, g1, g2, prediction, manifolds, workspace)
    }

    fn contact_manifold_convex_convex(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        normal_constraints1: Option<&dyn query::details::NormalConstraints>,
        normal_constraints2: Option<&dyn query::details::NormalConstraints>,
        prediction: Real,
        manifold: &mut ContactManifold<M, C>,
    ) -> Result<(), Unsupported> {
        check(manifold, pos12, g1, g2, prediction);
        DefaultQueryDispatcher.contact_manifold_convex_convex(
            pos12,
            g1,
            g2,
            normal_constraints1,
            normal_constraints2,
            prediction,
            manifold,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::convert;
    use nalgebra::{Point3, UnitQuaternion, Vector3};
    use rapier3d::parry::shape::{ConvexPolyhedron, Cuboid};

    /// A 100 mm block whose top bends down by 0.5° at x = 0 (face A level for x ≤ 0, face B
    /// beyond), a hull as finely faceted as a ball's `[m]`.
    fn roof() -> ConvexPolyhedron {
        let drop = (0.05 * 0.5f64.to_radians().tan()) as f32;
        let mut points = Vec::new();
        for y in [-0.05f32, 0.05] {
            points.extend([
                Vector::new(-0.05, y, 0.0),
                Vector::new(0.0, y, 0.0),
                Vector::new(0.05, y, -drop),
                Vector::new(-0.05, y, -0.05),
                Vector::new(0.05, y, -0.05),
            ]);
        }
        ConvexPolyhedron::from_convex_hull(&points).expect("a convex hull")
    }

    /// The deepest contact of `manifolds` `[mm]` (negative inside).
    fn deepest_mm(manifolds: &[ContactManifold<(), ()>]) -> f64 {
        let d = manifolds
            .iter()
            .flat_map(|m| m.points.iter())
            .map(|p| p.dist)
            .fold(f32::INFINITY, f32::min);
        f64::from(d) * 1e3
    }

    /// A 50 mm phalanx from x = −30 to 20 mm, its underside 0.01 mm over face A, level, then
    /// turned 0.95° (its +x end down) about its underside's line over the ridge: `d`'s
    /// manifolds after the two steps, with the 0.2 mm prediction of the check.
    fn after_turn(d: &dyn PersistentQueryDispatcher<(), ()>) -> Vec<ContactManifold<(), ()>> {
        let phalanx = Cuboid::new(Vector::new(0.025, 0.005, 0.005));
        let object = roof();
        let (mut manifolds, mut workspace) = (Vec::new(), None);
        for turn in [0.0f64, 0.95] {
            let r = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), turn.to_radians());
            let centre = Point3::new(0.0, 0.0, 0.01) - r * Vector3::new(5.0, 0.0, -5.0);
            let pos12 = convert::pose(&centre, &r).inverse();
            d.contact_manifolds(
                &pos12,
                &phalanx,
                &object,
                2e-4,
                &mut manifolds,
                &mut workspace,
            )
            .expect("a supported pair");
        }
        manifolds
    }

    #[test]
    fn a_manifold_that_misses_a_phalanx_inside_is_rebuilt() {
        // After the turn the phalanx's far end is 0.147 mm inside face B. parry keeps the
        // manifold of the level step (turned under 1°, no point changed sign): nothing inside.
        let inside = 20.0 * 0.5f64.to_radians().tan() + 0.01 - 20.0 * 0.95f64.to_radians().sin();
        assert!((inside + 0.147).abs() < 1e-3, "{inside}");
        let kept = deepest_mm(&after_turn(&DefaultQueryDispatcher));
        assert!(kept > 0.0, "parry's kept manifold: {kept} mm");
        // Checked against the contact query, the manifold is rebuilt: the far end's corners.
        let checked = deepest_mm(&after_turn(&CheckedManifolds));
        assert!((checked - inside).abs() < 0.01, "checked: {checked} mm");
    }
}
