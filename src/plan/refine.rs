//! Refining a planned grasp by the real contact (issue 33; the thesis's 6.2: the ALS model
//! "does not find exact contact points", so "a tuning method might be needed to adjust the grasp
//! parameters found before performing the grasp").
//!
//! The ALS model places each finger on three 2D slices of the mesh, with the palm where the
//! planner put it. The hand that closes is made of boxes as wide as the finger, and the object it
//! closes on may differ from the slices (a palm backed off the object, an ALS off or inside the
//! object, a collider that bulges past the mesh). Per finger, this module follows the closing the
//! physics check makes (joint 1 from its open bend with joint 2 held open, then joint 2) and
//! finds, by a short deterministic search, the bend at which each phalanx first touches: those
//! bends are the refined Grasp Parameter Set, to which the check adds its squeeze.
//!
//! What "touches" means is the caller's: a function from a finger's two joint bends to the gap
//! between each phalanx and the object `[mm]` (`sim::refine` gives the physics check's collider).
//! Units: bends in radians (the joint value, [`crate::hand::bend`]: larger is more closed),
//! angles reported in degrees, gaps in millimetres.

/// The sweep's coarse step `[rad]` (1°): a contact is bracketed between two such steps.
pub const SWEEP_STEP_RAD: f64 = std::f64::consts::PI / 180.0;

/// The bisection inside a bracket stops when it is this narrow `[rad]` (0.01°).
pub const BISECTION_TOL_RAD: f64 = std::f64::consts::PI / 18_000.0;

/// A phalanx touches the object when its gap is at most this `[mm]`.
pub const TOUCH_MM: f64 = 0.01;

/// What the refinement did to one finger.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerRefinement {
    /// The planned `[θ1, θ2]` it started from `[deg]` (the ALS angles).
    pub als_deg: [f64; 2],
    /// The refined `[θ1, θ2]` `[deg]`: where phalanx 1 (or, if it touches first, phalanx 2) stops
    /// joint 1, and where phalanx 2 then stops joint 2. A joint whose sweep meets nothing keeps
    /// its planned angle.
    pub refined_deg: [f64; 2],
    /// True if and only if phalanx 1, phalanx 2 touches the object at the refined bends.
    pub touches: [bool; 2],
}

/// The closing of one finger that the refinement follows, as joint values `[rad]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// The bends the joints start from: joint 2 stays at its open bend while joint 1 closes.
    pub open_bend: [f64; 2],
    /// The most closed bend of each joint (its limit).
    pub closed_limit: [f64; 2],
}

/// The interior angle `[deg]` of a joint value `[rad]` (the inverse of [`crate::hand::bend`]).
pub fn theta_deg(bend_rad: f64) -> f64 {
    180.0 - bend_rad.to_degrees()
}

/// The smallest bend in `[from, to]` at which `touches` holds, to [`BISECTION_TOL_RAD`]: `from`
/// itself if it touches there, else the first [`SWEEP_STEP_RAD`] step that touches, narrowed by
/// bisection to the bracket's closing end. `None` if no step touches (a touch thinner than a
/// step, between two steps that both miss, is not found).
pub fn first_touch(from: f64, to: f64, touches: impl Fn(f64) -> bool) -> Option<f64> {
    if touches(from) {
        return Some(from);
    }
    let steps = ((to - from) / SWEEP_STEP_RAD).ceil().max(0.0) as usize;
    let mut open = from;
    for k in 1..=steps {
        let b = (from + k as f64 * SWEEP_STEP_RAD).min(to);
        if touches(b) {
            let mut closed = b;
            while closed - open > BISECTION_TOL_RAD {
                let mid = 0.5 * (open + closed);
                if touches(mid) {
                    closed = mid;
                } else {
                    open = mid;
                }
            }
            return Some(closed);
        }
        open = b;
    }
    None
}

/// Refines one finger planned at `planned_deg` `[θ1, θ2]`: joint 1 closes from
/// `sweep.open_bend[0]` with joint 2 held at `sweep.open_bend[1]` until phalanx 1 or phalanx 2
/// touches; then joint 2 closes from its open bend until phalanx 2 touches. `gaps(bends)` is the
/// gap `[mm]` of phalanx 1 and of phalanx 2 to the object with the joints at `bends` `[rad]`.
pub fn refine_finger(
    planned_deg: [f64; 2],
    sweep: &Sweep,
    gaps: impl Fn([f64; 2]) -> [f64; 2],
) -> FingerRefinement {
    let touch = |g: f64| g <= TOUCH_MM;
    let [open1, open2] = sweep.open_bend;
    let [limit1, limit2] = sweep.closed_limit;
    let planned_bend = planned_deg.map(crate::hand::bend);
    let b1 = first_touch(open1, limit1, |b| {
        let [g1, g2] = gaps([b, open2]);
        touch(g1) || touch(g2)
    });
    let bends = match b1 {
        // Joint 1 meets nothing: the finger closes as planned (and misses).
        None => planned_bend,
        Some(b1) => {
            let b2 = first_touch(open2, limit2, |b| touch(gaps([b1, b])[1]));
            [b1, b2.unwrap_or(planned_bend[1])]
        }
    };
    let [g1, g2] = gaps(bends);
    FingerRefinement {
        als_deg: planned_deg,
        refined_deg: bends.map(theta_deg),
        touches: [touch(g1), touch(g2)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_first_touch_is_found_to_the_bisection_tolerance() {
        // A wall met at 0.3 rad: stepping from 0.05 brackets it in (0.29..., 0.30...], and the
        // bisection narrows the bracket to 0.01° on its closing side.
        let wall = 0.3;
        let b = first_touch(0.05, 1.0, |b| b >= wall).unwrap();
        assert!(b >= wall && b - wall <= BISECTION_TOL_RAD, "{b}");
        // Touching at the start: the start. Nothing within reach: none.
        assert_eq!(first_touch(0.4, 1.0, |b| b >= wall), Some(0.4));
        assert_eq!(first_touch(0.0, 0.2, |b| b >= wall), None);
        // The last step is clamped to the limit, which may be the touch.
        assert_eq!(first_touch(0.0, 0.0105, |b| b >= 0.0105), Some(0.0105));
    }

    #[test]
    fn a_finger_closes_to_a_wall_in_front_of_it() {
        // A planar finger: joint 1 at the origin, phalanx 1 (length 60) along +y at bend 0,
        // turning towards −x as it bends; a wall x = −30 in front of it. Phalanx 1's far end
        // reaches the wall at sin b1 = 30 / 60, b1 = 30° (θ1 = 150°), wherever the plan put it.
        // Joint 2 then turns phalanx 2 (length 20) from the end of phalanx 1; with phalanx 1
        // at 30°, its tip x = −30 − 20 sin(30° + b2): it touches at once (b2 from its open
        // bend): the wall is where phalanx 1 ends.
        let wall = -30.0;
        let gaps = |[b1, b2]: [f64; 2]| {
            let end1 = -60.0 * f64::sin(b1);
            let tip = end1 - 20.0 * f64::sin(b1 + b2);
            [end1 - wall, tip.min(end1) - wall]
        };
        let sweep = Sweep {
            open_bend: [0.0, 0.0],
            closed_limit: [PI / 2.0, PI / 2.0],
        };
        let r = refine_finger([120.0, 150.0], &sweep, |b| gaps(b).map(|g| g.max(0.0)));
        // With phalanx 2 straight, its tip (at 80 from the joint) meets the wall first:
        // sin b1 = 30 / 80, b1 = 22.02°, θ1 = 157.98°; phalanx 1 does not touch.
        let b1 = (30.0f64 / 80.0).asin();
        assert!((r.refined_deg[0] - theta_deg(b1)).abs() < 0.011, "{r:?}");
        assert_eq!(r.touches, [false, true]);
        assert_eq!(r.als_deg, [120.0, 150.0]);
        // Phalanx 2 already touches at its open bend: joint 2 stays there (θ2 = 180°).
        assert_eq!(r.refined_deg[1], 180.0);
        // A finger with no phalanx 2 to reach round: phalanx 1's end meets the wall.
        let short = |[b1, _]: [f64; 2]| {
            let end1 = -60.0 * f64::sin(b1);
            [(end1 - wall).max(0.0), f64::INFINITY]
        };
        let r = refine_finger([120.0, 150.0], &sweep, short);
        // Phalanx 1's end reaches the wall at sin b1 = 1/2: θ1 = 150°, to 0.01°; joint 2 meets
        // nothing and keeps its plan.
        assert!((r.refined_deg[0] - 150.0).abs() <= 0.011, "{r:?}");
        assert!((r.refined_deg[1] - 150.0).abs() < 1e-9, "{r:?}");
        assert_eq!(r.touches, [true, false]);
    }
}
