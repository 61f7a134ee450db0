//! The physics check's refinement of the planned joint angles by the real contact (issue 33,
//! docs/SIM.md "Refining the plan by the contact"): [`crate::plan::refine`] on the check's own
//! hand boxes and the object's collider, with the palm where the check starts it (backed off the
//! collider if it started inside) and each finger opened as the check opens it. The refined bends
//! are the ones the check commands (plus its squeeze), the MJCF export writes and the report
//! prints beside the plan's ALS angles. Units: millimetres and degrees, metres inside parry.

use super::convert;
use super::scene::Case;
use crate::hand::{bend, BodyPose, HandBox};
use crate::plan::refine::{refine_finger, FingerRefinement, Sweep};
use rapier3d::prelude::*;

/// The refinement is repeated from the open bends its own angles give (the check opens each
/// finger a margin short of what it commands) until no angle moves by more than
/// [`SETTLED_DEG`], at most this many times.
pub const MAX_PASSES: usize = 4;

/// A pass that moves no angle by more than this has settled `[deg]`.
pub const SETTLED_DEG: f64 = 0.01;

/// The gap between `boxes` (posed by `frame`) and the object `[mm]`: 0 when they touch or
/// overlap.
pub(super) fn gap_mm(object: &SharedShape, frame: &BodyPose, boxes: &[HandBox]) -> f64 {
    boxes
        .iter()
        .map(|b| {
            let c = frame.0 + frame.1 * b.centre;
            let pose = convert::pose(&c, &frame.1);
            let h = convert::vector_m(&b.half_extents);
            super::contacts::separation_m(
                &pose,
                &rapier3d::parry::shape::Cuboid::new(h),
                &Pose::IDENTITY,
                &*object.0,
            )
            .map_or(f64::INFINITY, |d| d / convert::M_PER_MM)
        })
        .fold(f64::INFINITY, f64::min)
        .max(0.0)
}

/// Refines every finger of `case` with the palm at `palm`: `open(theta)` gives the bends
/// `[rad]` each finger starts the closing from when it is commanded `theta` `[deg]`. Returns one
/// refinement per finger, its `als_deg` the planned angles.
pub(super) fn refine(
    case: &Case,
    palm: &BodyPose,
    open: impl Fn(&[[f64; 2]]) -> Vec<[f64; 2]>,
) -> Vec<FingerRefinement> {
    let hand = case.hand;
    let closed_limit = [
        bend(hand.joints.theta1_range_deg[0]),
        bend(hand.joints.theta2_range_deg[0]),
    ];
    let mut theta = case.pose.theta_deg.clone();
    let mut refined = Vec::new();
    for _ in 0..MAX_PASSES {
        let open_bend = open(&theta);
        refined = hand
            .finger_list
            .iter()
            .zip(&theta)
            .zip(&open_bend)
            .map(|((f, planned), open)| {
                let (p1, p2) = hand.phalanx_boxes(f.side);
                let sweep = Sweep {
                    open_bend: *open,
                    closed_limit,
                };
                refine_finger(*planned, &sweep, |bends| {
                    let [f1, f2] = hand.finger_poses(f, palm, bends);
                    let shape = &case.object.shape;
                    [gap_mm(shape, &f1, &[p1]), gap_mm(shape, &f2, &p2)]
                })
            })
            .collect();
        let moved = refined
            .iter()
            .zip(&theta)
            .flat_map(|(r, t)| (0..2).map(move |j| (r.refined_deg[j] - t[j]).abs()))
            .fold(0.0, f64::max);
        theta = refined.iter().map(|r| r.refined_deg).collect();
        if moved <= SETTLED_DEG {
            break;
        }
    }
    for (r, planned) in refined.iter_mut().zip(&case.pose.theta_deg) {
        r.als_deg = *planned;
        // Phalanx 2 meets the object first and phalanx 1 ends off it (a pinch by the fingertip,
        // or a tip that reaches round first): where joint 2 then stops depends on how the tip
        // slides, which the sweep does not model. Measured on the real-object set, commanding the
        // tip's touching bend there made MuJoCo disagree on pinches that hold as planned (the
        // black book, the cereal box): such a finger keeps its plan.
        if !r.touches[0] {
            r.refined_deg = *planned;
            r.touches = [false, false];
        }
    }
    refined
}

#[cfg(test)]
mod tests {
    use super::super::params::SimParams;
    use super::super::scene::{start, SimHand};
    use super::super::ObjectShape;
    use super::*;
    use nalgebra::{Point3, Vector2, Vector3};

    /// The interior angle `[deg]` at which a link from `pivot`, pointing along `(-sin b, cos b)`
    /// at bend `b` (a left finger in the palm's 2D frame), has its inner face (the side of
    /// `(-cos b, -sin b)`, `o` off its axis) tangent to the circle of radius `r` about `c`: the
    /// bend, closing from straight, with `(pivot − c) · (cos b, sin b) = o + r` (the circle's
    /// centre `o + r` in front of the phalanx's axis).
    fn tangent_theta_deg(pivot: Vector2<f64>, c: Vector2<f64>, o: f64, r: f64) -> f64 {
        let q = pivot - c;
        let (rho, gamma) = (q.norm(), q.y.atan2(q.x));
        // q·(cos b, sin b) = rho cos(b − gamma) = o + r.
        let b = gamma + ((o + r) / rho).acos();
        180.0 - b.to_degrees()
    }

    #[test]
    fn a_backed_off_palm_closes_to_the_bends_that_touch_the_d40() {
        // The D40's planned grasp (72.11/91.81) with the palm 10 mm further from the cylinder
        // than planned. In the palm's 2D frame the cylinder's axis is at (−30, 0) instead of
        // (−20, 0), and a finger's joint 1 at (5.8, ±36.7). Phalanx 1 (its inner face 7 mm off
        // its axis) is tangent to the 20 mm circle at θ1 = 76.07° (72.11° flush, the plan);
        // the refinement moves θ1 there, to the 144-gon's rounding.
        let hand = crate::hand::thesis_for_tests();
        let mesh = crate::objects::cylinder(40.0, 124.0);
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let shape = ObjectShape::from_mesh(&mesh, volume);
        let mut params = SimParams::default();
        params.closing.refine_contacts = true;
        let pose = |backoff: f64| SimHand {
            origin_mm: Point3::new(-20.0 - backoff, 0.0, 62.0),
            axes: [-Vector3::x(), -Vector3::y(), Vector3::z()],
            theta_deg: vec![[72.11, 91.81]; 3],
            planned_contacts_mm: Vec::new(),
        };
        let j1 = Vector2::new(5.8, 36.7);
        let flush = tangent_theta_deg(j1, Vector2::new(-20.0, 0.0), 7.0, 20.0);
        let backed = tangent_theta_deg(j1, Vector2::new(-30.0, 0.0), 7.0, 20.0);
        assert!((flush - 72.11).abs() < 0.01 && (backed - 76.07).abs() < 0.01);
        // Phalanx 2 then turns about joint 2, 61 mm along phalanx 1: its inner face is tangent
        // to the circle 17.4 mm along it (within its 20 mm), at θ2 = 114.35° (the plan's 91.81°
        // is a tip contact with the palm flush).
        let b1 = (180.0 - backed).to_radians();
        let j2 = j1 + 61.0 * Vector2::new(-b1.sin(), b1.cos());
        // The tangent's total bend b1 + b2 is 180° − T; θ2 = 180° − b2.
        let theta2 = tangent_theta_deg(j2, Vector2::new(-30.0, 0.0), 7.0, 20.0) + 180.0 - backed;
        assert!((theta2 - 114.35).abs() < 0.01, "{theta2}");
        for (backoff, expected) in [(0.0, [flush, 91.81]), (10.0, [backed, theta2])] {
            let p = pose(backoff);
            let s = start(&Case {
                hand: &hand,
                pose: &p,
                object: &shape,
                mass_kg: 0.08,
                friction: 0.3,
                params: &params,
            });
            assert_eq!(s.refinement.len(), 3);
            for (r, commanded) in s.refinement.iter().zip(&s.theta_deg) {
                assert_eq!(r.als_deg, [72.11, 91.81]);
                assert_eq!(&r.refined_deg, commanded);
                assert_eq!(r.touches, [true, true], "{backoff} mm: {r:?}");
                // The 144-gon's hull against the circle: within 0.05° at joint 1, 0.05° at
                // joint 2 (its facets meet phalanx 2's face a little sooner or later).
                let [t1, t2] = r.refined_deg;
                assert!(
                    (t1 - expected[0]).abs() < 0.05,
                    "{backoff} mm: {r:?}, {expected:?}"
                );
                assert!(
                    (t2 - expected[1]).abs() < 0.05,
                    "{backoff} mm: {r:?}, {expected:?}"
                );
            }
        }
        // Off (the default): the plan is commanded as it is.
        let off = SimParams::default();
        let p = pose(10.0);
        let s = start(&Case {
            hand: &hand,
            pose: &p,
            object: &shape,
            mass_kg: 0.08,
            friction: 0.3,
            params: &off,
        });
        assert!(s.refinement.is_empty());
        assert_eq!(s.theta_deg, vec![[72.11, 91.81]; 3]);
    }
}
