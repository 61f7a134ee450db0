//! The hand's graspable diameter range (thesis 3.4.3.2, eq. 3.2, Fig. 3.17–3.18).
//!
//! Works in a finger plane of the palm frame (millimetres): the palm contact surface is the line
//! x = 0 facing −x, the object lies at x < 0, and the joint-1 axes are at
//! `(setback, ±lateral)`. A joint angle θ is interior: a link at 180° lies straight on from the one
//! before (phalanx 1 along the palm, pointing away from the palm centre); closing decreases θ.
//!
//! - Smallest graspable diameter (eq. 3.2): the circle inscribed in the triangle that the palm
//!   surface and the two opposing phalanx-1 contact surfaces make with joint 1 at its lower
//!   limit; r = K / S (area over semi-perimeter).
//! - Largest graspable diameter (the thesis had "no mathematical technique" and used 9 × the
//!   smallest, eq. 3.3): the largest circle resting on the palm centre that each finger can still
//!   touch with both phalanges within their joint ranges. Each phalanx closes from straight
//!   until its usable contact surface (offset by the finger offset from its centreline, between
//!   its unusable lengths) first touches the circle; that angle must lie in the joint's range.
//!   Both are reported; the kinematic one is used.

use crate::hand::Hand;
use nalgebra::{Point2, Rotation2, Vector2};

/// The graspable diameter range of a hand `[mm]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraspableRange {
    /// Smallest graspable diameter, eq. 3.2.
    pub min_mm: f64,
    /// Largest graspable diameter from the finger kinematics (used by the planner).
    pub max_kinematic_mm: f64,
    /// The thesis's largest graspable diameter: Magnify_Factor × smallest (eq. 3.3), for
    /// comparison only.
    pub max_thesis_mm: f64,
}

impl GraspableRange {
    /// The range the planner uses: `[smallest (eq. 3.2), largest (kinematic)]`.
    pub fn used(&self) -> [f64; 2] {
        [self.min_mm, self.max_kinematic_mm]
    }
}

/// The range for `hand`, with the thesis's magnify factor for the comparison value.
pub fn graspable_range_with(hand: &Hand, magnify_factor: f64) -> GraspableRange {
    let min = smallest_graspable_diameter(hand);
    GraspableRange {
        min_mm: min,
        max_kinematic_mm: largest_graspable_diameter(hand),
        max_thesis_mm: magnify_factor * min,
    }
}

/// As [`graspable_range_with`] with the thesis's Magnify_Factor of 9.
pub fn graspable_range(hand: &Hand) -> GraspableRange {
    graspable_range_with(hand, 9.0)
}

/// Joint-1 axis of the finger on the +y side.
fn joint1(hand: &Hand) -> Point2<f64> {
    Point2::new(hand.joints.setback_mm, hand.joints.lateral_mm)
}

/// Unit direction of phalanx 1 of the +y finger at interior angle `theta1_rad`.
pub fn phalanx1_direction(theta1_rad: f64) -> Vector2<f64> {
    Vector2::new(-theta1_rad.sin(), -theta1_rad.cos())
}

/// The inward normal of a link with direction `d` on the +y finger: `d` turned 90° the way the
/// finger closes (counter-clockwise).
pub fn inward_normal(d: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(-d.y, d.x)
}

/// Smallest graspable diameter (eq. 3.2) `[mm]`.
///
/// Returns 0 when joint 1's lower limit does not close the triangle (the two phalanges do not
/// converge in front of the palm).
pub fn smallest_graspable_diameter(hand: &Hand) -> f64 {
    let theta = hand.joints.theta1_range_deg[0].to_radians();
    let d = phalanx1_direction(theta);
    let n = inward_normal(&d);
    let start = joint1(hand) + n * hand.fingers.offset_mm;
    // Contact line of the +y finger: start + t d. By symmetry it meets its mirror at y = 0 and
    // the palm line at x = 0.
    if d.y >= 0.0 || d.x >= 0.0 {
        return 0.0;
    }
    let t_apex = -start.y / d.y;
    let apex = start + d * t_apex;
    let t_palm = -start.x / d.x;
    let palm = start + d * t_palm;
    if apex.x >= 0.0 || palm.y <= 0.0 {
        return 0.0;
    }
    // Triangle (0, palm.y), (0, -palm.y), (apex.x, 0).
    let base = 2.0 * palm.y;
    let height = -apex.x;
    let side = (palm - apex).norm();
    let area = 0.5 * base * height;
    let semi = 0.5 * (base + 2.0 * side);
    2.0 * area / semi
}

/// Smallest bend from straight (radians, in `[0, π]`) at which the usable contact surface of a
/// link pivoting at `pivot`, straight direction `straight`, first touches the circle of radius
/// `r` about `c`. `None` if it never does.
fn first_touch_bend(
    pivot: Point2<f64>,
    straight: Vector2<f64>,
    usable: (f64, f64),
    offset: f64,
    c: Point2<f64>,
    r: f64,
) -> Option<f64> {
    let gap = |bend: f64| -> f64 {
        let d = Rotation2::new(bend) * straight;
        let n = inward_normal(&d);
        // Distance from c to the contact segment, minus r.
        let a = pivot + n * offset + d * usable.0;
        let b = pivot + n * offset + d * usable.1;
        let ab = b - a;
        let t = ((c - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
        (a + ab * t - c).norm() - r
    };
    // Scan in 2° steps for the first touch, then bisect to 1e-9 rad. (A touch window narrower
    // than 2° of bend would be missed; the gap is a smooth function of the bend, and for a
    // circle it closes over tens of degrees.)
    let step = 2f64.to_radians();
    let mut lo = 0.0;
    if gap(lo) <= 0.0 {
        return Some(0.0);
    }
    let mut hi = step;
    while hi <= std::f64::consts::PI + 1e-12 {
        if gap(hi) <= 0.0 {
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if gap(mid) <= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(hi);
        }
        lo = hi;
        hi += step;
    }
    None
}

/// The joint angles `[θ1, θ2]` (degrees) at which the +y finger first touches a circle of radius
/// `r` resting on the palm centre, closing each phalanx in turn; `None` if a phalanx never
/// touches.
pub fn circle_contact_angles(hand: &Hand, r: f64) -> Option<[f64; 2]> {
    let o = hand.fingers.offset_mm;
    let c = Point2::new(-r, 0.0);
    let j1 = joint1(hand);
    let p1 = &hand.phalanx_1;
    let straight1 = phalanx1_direction(std::f64::consts::PI);
    let bend1 = first_touch_bend(
        j1,
        straight1,
        (
            p1.unusable_proximal_mm,
            p1.length_mm - p1.unusable_distal_mm,
        ),
        o,
        c,
        r,
    )?;
    let d1 = Rotation2::new(bend1) * straight1;
    let j2 = j1 + d1 * p1.length_mm;
    let p2 = &hand.phalanx_2;
    let bend2 = first_touch_bend(
        j2,
        d1,
        (
            p2.unusable_proximal_mm,
            p2.length_mm - p2.unusable_distal_mm,
        ),
        o,
        c,
        r,
    )?;
    Some([180.0 - bend1.to_degrees(), 180.0 - bend2.to_degrees()])
}

/// Largest graspable diameter from the kinematics `[mm]`: the largest circle resting on the palm
/// centre whose contact angles both lie in the joint ranges (scanned in 2 mm of radius, then
/// bisected to 0.01 mm). Returns 0 if no circle is graspable.
pub fn largest_graspable_diameter(hand: &Hand) -> f64 {
    let in_range = |r: f64| -> bool {
        match circle_contact_angles(hand, r) {
            Some([t1, t2]) => {
                let [a1, b1] = hand.joints.theta1_range_deg;
                let [a2, b2] = hand.joints.theta2_range_deg;
                (a1..=b1).contains(&t1) && (a2..=b2).contains(&t2)
            }
            None => false,
        }
    };
    let r_min = smallest_graspable_diameter(hand) / 2.0;
    let limit = 1000.0;
    let mut r = r_min.max(0.5);
    let mut last_ok: Option<f64> = None;
    while r < limit {
        if in_range(r) {
            last_ok = Some(r);
        } else if last_ok.is_some() {
            break;
        }
        r += 2.0;
    }
    let Some(mut lo) = last_ok else {
        return 0.0;
    };
    let mut hi = lo + 2.0;
    while hi - lo > 0.005 {
        let mid = 0.5 * (lo + hi);
        if in_range(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    2.0 * lo
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thesis_hand() -> Hand {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/hands/thesis.toml");
        Hand::load(std::path::Path::new(path), &[]).unwrap()
    }

    #[test]
    fn smallest_diameter_is_the_inscribed_circle_of_the_45_degree_triangle() {
        // At 45° the contact lines meet the palm at y = ±a and each other at x = −a, with
        // a = lateral − setback − offset·√2 = 36.7 − 5.8 − 7·√2 = 21.00 for the thesis hand: a
        // right isosceles triangle with legs a√2 and hypotenuse 2a, so r = a / (1 + √2).
        let h = thesis_hand();
        let a = 36.7 - 5.8 - 7.0 * 2f64.sqrt();
        let expected = 2.0 * a / (1.0 + 2f64.sqrt());
        let got = smallest_graspable_diameter(&h);
        assert!(
            (got - expected).abs() < 1e-9,
            "smallest {got}, expected {expected}"
        );
        // The thesis: D10 is below it, the prism's 23 mm and D40 above.
        assert!(got > 10.0 && got < 23.0, "{got}");
    }

    #[test]
    fn the_circle_model_reproduces_the_d40_joint_1_angle() {
        // DESIGN.md section 3: the circle model fits the thesis's theta1 = 72.2° for D40.
        let h = thesis_hand();
        let [t1, _] = circle_contact_angles(&h, 20.0).unwrap();
        assert!((t1 - 72.2).abs() < 0.75, "theta1 {t1}");
        // Closed form: L sin θ − (r + setback) cos θ = r + offset.
        let (l, sb, o, r) = (36.7f64, 5.8f64, 7.0f64, 20.0f64);
        let big_r = (l * l + (r + sb) * (r + sb)).sqrt();
        let beta = (r + sb).atan2(l);
        let closed = (beta + ((r + o) / big_r).asin()).to_degrees();
        assert!(
            (t1 - closed).abs() < 1e-6,
            "numeric {t1} vs closed form {closed}"
        );
    }

    #[test]
    fn larger_circles_need_more_open_fingers() {
        let h = thesis_hand();
        let mut last = [0.0, 0.0];
        for r in [12.0, 20.0, 30.0, 40.0] {
            let a = circle_contact_angles(&h, r).unwrap();
            assert!(a[0] > last[0], "theta1 not increasing at r = {r}: {a:?}");
            last = a;
        }
    }

    #[test]
    fn largest_diameter_sits_at_a_joint_limit() {
        let h = thesis_hand();
        let dmax = largest_graspable_diameter(&h);
        assert!(dmax > 40.0, "{dmax}");
        let inside = circle_contact_angles(&h, dmax / 2.0 - 0.05).unwrap();
        let hi1 = h.joints.theta1_range_deg[1];
        let hi2 = h.joints.theta2_range_deg[1];
        assert!(inside[0] <= hi1 && inside[1] <= hi2, "{inside:?}");
        let beyond = circle_contact_angles(&h, dmax / 2.0 + 0.05);
        assert!(
            beyond.is_none_or(|b| b[0] > hi1 || b[1] > hi2),
            "just beyond the largest diameter is still in range: {beyond:?}"
        );
    }
}
