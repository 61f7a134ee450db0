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
//! - The largest circle is the top of the first interval of circles both phalanges wrap
//!   ([`graspable_circle_radii`]), scanned from the smallest circle up: a hand whose phalanx 1 is
//!   long against its phalanx 2 wraps no small circle (phalanx 2 starts past them and cannot
//!   bend back), and the old scan, started at eq. 3.2's circle, stopped there and reported a
//!   largest diameter of 0. A hand whose range is empty (it wraps no circle, or none larger than
//!   eq. 3.2's) is refused when its hand file is read, with the reason.
//! - Beyond the thesis (issue 37): a hand with `palm.standoff_max_mm` may also hold the circle in
//!   front of the palm, on its normal through the centre, between the phalanges
//!   ([`wrapping_standoff`]): a circle counts as wrapped at the nearest stand-off (0 first, in
//!   1 mm steps) where both phalanges touch it within their ranges. The Schunk SDH-2's distal
//!   joint closes at most 90°, and resting on its palm it wraps nothing under 89 mm.

use super::Hand;
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
///
/// For a hand that wraps no circle (refused by the hand file's validation) the range is
/// `[eq. 3.2, 0]`, which would grade every object ungraspable.
pub fn graspable_range_with(hand: &Hand, magnify_factor: f64) -> GraspableRange {
    let eq32 = smallest_graspable_diameter(hand);
    let (min, max) = match graspable_circle_radii(hand) {
        // Eq. 3.2 stays the smallest (the thesis's rule, and the one that lets the prism's
        // corners be grasped with tip contact where no circle of its size is wrapped); only a
        // hand whose joint 1 cannot close past upright, where eq. 3.2 has no triangle, takes
        // the smallest wrapped circle instead.
        Some((_, hi)) if eq32 > 0.0 => (eq32, 2.0 * hi),
        Some((lo, hi)) => (2.0 * lo, 2.0 * hi),
        None => (eq32, 0.0),
    };
    GraspableRange {
        min_mm: min,
        max_kinematic_mm: max,
        max_thesis_mm: magnify_factor * eq32,
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
/// `r` about `c`. `None` if it never does, or if the straight link is already inside the
/// circle.
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
        // Already in the object while straight: closing cannot make a first touch.
        return None;
    }
    let mut hi = step;
    while hi <= std::f64::consts::PI + 1e-12 {
        if gap(hi) <= 0.0 {
            for _ in 0..40 {
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
    circle_contact_angles_off(hand, r, 0.0)
}

/// As [`circle_contact_angles`] for the circle held `standoff` in front of the palm's contact
/// surface (on the palm's normal through its centre) instead of resting on it `[mm]`.
pub fn circle_contact_angles_off(hand: &Hand, r: f64, standoff: f64) -> Option<[f64; 2]> {
    let o = hand.fingers.offset_mm;
    let c = Point2::new(-r - standoff, 0.0);
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

/// Returns true if and only if both phalanges of the +y finger touch the circle of radius `r`
/// resting on the palm centre with joint angles inside their ranges; for a hand with a palm
/// stand-off (`palm.standoff_max_mm`), resting on the palm or held in front of it at one of
/// [`Hand::palm_standoffs_mm`] (in 1 mm steps here, finer than the planner's).
fn wraps_circle(hand: &Hand, r: f64) -> bool {
    let max = hand.palm.standoff_max_mm.unwrap_or(0.0);
    let steps = max.floor() as usize;
    (0..=steps).any(|k| wraps_circle_at(hand, r, (k as f64).min(max)))
}

/// [`wraps_circle`] with the circle held `standoff` in front of the palm `[mm]`.
fn wraps_circle_at(hand: &Hand, r: f64, standoff: f64) -> bool {
    match circle_contact_angles_off(hand, r, standoff) {
        Some([t1, t2]) => {
            let [a1, b1] = hand.joints.theta1_range_deg;
            let [a2, b2] = hand.joints.theta2_range_deg;
            (a1..=b1).contains(&t1) && (a2..=b2).contains(&t2)
        }
        None => false,
    }
}

/// The nearest stand-off in front of the palm `[mm]` (in 1 mm steps, up to
/// `palm.standoff_max_mm`) at which both phalanges wrap the circle of radius `r`, with the joint
/// angles there; `None` if none does. 0 is the thesis's circle resting on the palm.
pub fn wrapping_standoff(hand: &Hand, r: f64) -> Option<(f64, [f64; 2])> {
    let max = hand.palm.standoff_max_mm.unwrap_or(0.0);
    (0..=max.floor() as usize)
        .map(|k| (k as f64).min(max))
        .find(|&d| wraps_circle_at(hand, r, d))
        .and_then(|d| circle_contact_angles_off(hand, r, d).map(|a| (d, a)))
}

/// Largest radius the scan looks at `[mm]`: a 2 m object is no object for a hand.
const RADIUS_LIMIT_MM: f64 = 1000.0;

/// The radii `[smallest, largest]` `[mm]` of the first interval of circles, resting on the palm
/// centre, that both phalanges touch within their joint ranges (scanned in 1 mm of radius from
/// 0.25 mm, both ends bisected to 1e-6 mm); `None` if the hand wraps no circle up to 1 m.
pub fn graspable_circle_radii(hand: &Hand) -> Option<(f64, f64)> {
    let step = 1.0;
    let mut r = 0.25;
    while r <= RADIUS_LIMIT_MM && !wraps_circle(hand, r) {
        r += step;
    }
    if r > RADIUS_LIMIT_MM {
        return None;
    }
    let bisect = |mut ok: f64, mut bad: f64| {
        while (ok - bad).abs() > 1e-6 {
            let mid = 0.5 * (ok + bad);
            if wraps_circle(hand, mid) {
                ok = mid;
            } else {
                bad = mid;
            }
        }
        ok
    };
    let lo = if r > 0.25 { bisect(r, r - step) } else { r };
    while r + step <= RADIUS_LIMIT_MM && wraps_circle(hand, r + step) {
        r += step;
    }
    let hi = if r + step <= RADIUS_LIMIT_MM {
        bisect(r, r + step)
    } else {
        r
    };
    Some((lo, hi))
}

/// Largest graspable diameter from the kinematics `[mm]`: the top of
/// [`graspable_circle_radii`], doubled; 0 if no circle is graspable.
pub fn largest_graspable_diameter(hand: &Hand) -> f64 {
    graspable_circle_radii(hand).map_or(0.0, |(_, hi)| 2.0 * hi)
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

    /// A hand file with the given numbers (the thesis hand's layout).
    #[allow(clippy::too_many_arguments)]
    fn hand_toml(
        offset: f64,
        lateral: f64,
        setback: f64,
        t1: [f64; 2],
        t2: [f64; 2],
        finger_offset: f64,
        l1: f64,
        l2: f64,
    ) -> String {
        format!(
            "name = \"p\"\n[palm]\noffset_mm = {offset}\nmargin_mm = 7.0\nhalf_width_mm = {lateral}\n\
             [joints]\nlateral_mm = {lateral}\nsetback_mm = {setback}\n\
             theta1_range_deg = [{}, {}]\ntheta2_range_deg = [{}, {}]\n\
             [fingers]\ngap_mm = 25.0\noffset_mm = {finger_offset}\ntip_thickness_mm = {}\n\
             [phalanx_1]\nlength_mm = {l1}\nunusable_proximal_mm = {}\nunusable_distal_mm = {}\n\
             [phalanx_2]\nlength_mm = {l2}\nunusable_proximal_mm = {}\nunusable_distal_mm = 0.0\n\
             [[finger]]\nname = \"finger_1\"\nside = \"left\"\nheight_mm = 25.0\n\
             [[finger]]\nname = \"finger_2\"\nside = \"right\"\nheight_mm = 0.0\n\
             [[finger]]\nname = \"finger_3\"\nside = \"left\"\nheight_mm = -25.0\n",
            t1[0],
            t1[1],
            t2[0],
            t2[1],
            finger_offset / 2.0,
            l1 * 0.05,
            l1 * 0.05,
            l2 * 0.1,
        )
    }

    #[test]
    fn longer_first_phalanges_narrow_the_range_or_are_refused() {
        // Issue 16, item 1: 90, 100 and 200 mm gave [17.4, 0.0] and graded everything too thick.
        let base = include_str!("../../assets/hands/thesis.toml");
        let path = std::path::Path::new("thesis.toml");
        let mut last_min = 0.0;
        for l1 in [61.0, 70.0, 80.0] {
            let h = Hand::parse(base, path, &[("phalanx_1.length_mm".into(), l1)]).unwrap();
            let r = graspable_range(&h);
            assert!(
                r.min_mm < r.max_kinematic_mm && r.min_mm >= last_min,
                "phalanx 1 {l1} mm: {r:?}"
            );
            // The largest end is wrapped by both phalanges within the joint ranges.
            let [t1, t2] = circle_contact_angles(&h, r.max_kinematic_mm / 2.0 - 0.01).unwrap();
            assert!((45.0..=135.0).contains(&t1) && (45.0..=135.0).contains(&t2));
            last_min = r.min_mm;
        }
        for l1 in [90.0, 100.0, 200.0] {
            let e = Hand::parse(base, path, &[("phalanx_1.length_mm".into(), l1)])
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("phalanx_1.length_mm") && e.contains("wrap"),
                "{l1}: {e}"
            );
        }
    }

    /// Property: every hand the hand file accepts has a non-empty graspable range whose ends are
    /// wrapped by both phalanges; every other hand is refused with a reason. Hands drawn from a
    /// fixed-seed generator (deterministic), over the validated bounds of each dimension.
    #[test]
    fn every_accepted_hand_has_a_graspable_range() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
        };
        let (mut accepted, mut refused) = (0, 0);
        for _ in 0..40 {
            let t1lo = next(20.0, 90.0);
            let t2lo = next(20.0, 120.0);
            let text = hand_toml(
                next(1.0, 20.0),
                next(10.0, 80.0),
                next(0.0, 15.0),
                [t1lo, next(t1lo + 5.0, 180.0)],
                [t2lo, next(t2lo + 5.0, 180.0)],
                next(2.0, 12.0),
                next(15.0, 200.0),
                next(8.0, 100.0),
            );
            match Hand::parse(&text, std::path::Path::new("p.toml"), &[]) {
                Ok(h) => {
                    accepted += 1;
                    let r = graspable_range(&h);
                    assert!(
                        r.min_mm > 0.0 && r.min_mm < r.max_kinematic_mm,
                        "{r:?} for\n{text}"
                    );
                    let (lo, hi) = graspable_circle_radii(&h).unwrap();
                    assert!(wraps_circle(&h, lo) && wraps_circle(&h, hi), "{text}");
                }
                Err(e) => {
                    refused += 1;
                    let e = e.to_string();
                    assert!(e.starts_with("p.toml: `") && e.len() > 40, "{e}");
                }
            }
        }
        assert!(
            accepted > 5 && refused > 0,
            "{accepted} accepted, {refused} refused"
        );
    }

    #[test]
    fn the_bh8_hand_has_a_range_sized_like_a_barretthand() {
        let (_, text) = crate::hand::bundled("bh8").unwrap();
        let h = Hand::parse(text, std::path::Path::new("bh8"), &[]).unwrap();
        let r = graspable_range(&h);
        // Wider than the thesis hand at both ends: its fingers are longer and further apart.
        assert!(r.min_mm > 20.0 && r.min_mm < 40.0, "{r:?}");
        assert!(r.max_kinematic_mm > 150.0, "{r:?}");
    }

    /// A palm stand-off (issue 37) changes nothing for a circle the hand wraps resting on its
    /// palm (the nearest stand-off is 0, the angles are the thesis model's), and wraps circles
    /// below the smallest the palm allows (resting on it, the thesis hand's joint 1 would have
    /// to close past 45°), at the nearest stand-off with every angle in range.
    #[test]
    fn a_palm_standoff_wraps_circles_the_palm_cannot() {
        let (_, text) = crate::hand::bundled("thesis").unwrap();
        let path = std::path::Path::new("thesis.toml");
        let on_palm = Hand::parse(text, path, &[]).unwrap();
        let with = text.replacen("[palm]\n", "[palm]\nstandoff_max_mm = 30.0\n", 1);
        let off = Hand::parse(&with, path, &[]).unwrap();
        assert_eq!(off.palm_standoffs_mm().len(), 16);
        assert_eq!(on_palm.palm_standoffs_mm(), vec![0.0]);
        let (d, a) = wrapping_standoff(&off, 20.0).unwrap();
        assert_eq!(d, 0.0);
        assert_eq!(a, circle_contact_angles(&on_palm, 20.0).unwrap());
        let (lo, _) = graspable_circle_radii(&on_palm).unwrap();
        let r = lo - 1.5;
        assert!(wrapping_standoff(&on_palm, r).is_none());
        let (d, [t1, t2]) = wrapping_standoff(&off, r).unwrap();
        assert!((1.0..=30.0).contains(&d), "{d}");
        assert!(!wraps_circle_at(&off, r, d - 1.0));
        let [a1, b1] = off.joints.theta1_range_deg;
        let [a2, b2] = off.joints.theta2_range_deg;
        assert!(
            (a1..=b1).contains(&t1) && (a2..=b2).contains(&t2),
            "{t1} {t2}"
        );
        assert!(graspable_circle_radii(&off).unwrap().0 < lo - 1.5);
    }
}
