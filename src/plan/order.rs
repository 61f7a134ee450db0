//! The order the candidates are checked in, beyond the thesis (issue 58).
//!
//! The thesis orders the candidates by geometry alone: elevations by their palm grade, then
//! approach angles. Measured over labelled candidates that order is blind to what holds (a
//! lower place goes with a higher hold probability about half the time). The terms here are
//! what the physics check rewards and the thesis's grade ignores, each computed from the
//! planned grasp alone (no check) and each weighted by its own significance factor
//! (`[planner] sf_centred`, `sf_opposed`, `sf_spread`, `sf_margin`, `sf_even`). A candidate's
//! score is
//!
//! ```text
//! score = −place / found + Σ sf_k · term_k
//! ```
//!
//! with `place` its index in its axis's thesis order and `found` the feasible grasps found on
//! that axis; the candidates of an axis are checked by falling score. With every factor at 0
//! the order is the thesis's, bit for bit: the search is not even reordered.

use crate::hand::Hand;
use crate::mesh::AlignedObject;
use crate::plan::params::PlannerParams;
use crate::plan::search::Grasp;
use nalgebra::{Point3, Vector3};
use serde::Serialize;

/// The terms of one planned grasp. Each is dimensionless, and larger is meant to be better
/// (a factor may still come out negative where the data say otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OrderTerms {
    /// Minus the distance from the object's centre of mass to the centroid of the planned
    /// contacts, over the object's height. Gravity acts at the centre of mass: the farther it
    /// lies from where the hand holds, the larger the torque the contacts' friction must resist.
    pub centred: f64,
    /// Minus the length of the mean of the planned contacts' unit push directions (0: the
    /// pushes cancel, as a force-closure grasp's do; 1: all push the same way). A grasp whose
    /// pushes do not cancel drives the object while it closes.
    pub opposed: f64,
    /// The planned contacts' extent along the axis over the object's height: contacts spread
    /// along the object resist its tilting out of the hand; contacts on one ring do not.
    pub spread: f64,
    /// The smallest margin of a planned joint angle to its range's ends, over the range (0: a
    /// joint at its limit, 0.5: at mid-range). A joint at its limit cannot close further when
    /// the object settles.
    pub margin: f64,
    /// Minus the spread (largest less smallest) of the fingers' planned joint-2 bends, over
    /// joint 2's range (0: the three bent alike). The closing's predicted push: the fingers
    /// close with equal torque-limited motors, joint 2 last; fingers bent alike meet the object
    /// together and their pushes balance, while a finger bent far more or less than the others
    /// meets it early or late and pushes the object alone while the others close.
    pub even: f64,
}

/// The significance factors of the terms (`[planner] sf_*`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OrderFactors {
    /// `sf_centred`.
    pub centred: f64,
    /// `sf_opposed`.
    pub opposed: f64,
    /// `sf_spread`.
    pub spread: f64,
    /// `sf_margin`.
    pub margin: f64,
    /// `sf_even`.
    pub even: f64,
}

impl OrderFactors {
    /// The factors of `p`.
    pub fn of(p: &PlannerParams) -> OrderFactors {
        OrderFactors {
            centred: p.sf_centred,
            opposed: p.sf_opposed,
            spread: p.sf_spread,
            margin: p.sf_margin,
            even: p.sf_even,
        }
    }

    /// True if and only if every factor is 0: the thesis's order.
    pub fn is_thesis(&self) -> bool {
        self.as_array().iter().all(|&f| f == 0.0)
    }

    /// The factors in the order of [`NAMES`].
    pub fn as_array(&self) -> [f64; TERMS] {
        [
            self.centred,
            self.opposed,
            self.spread,
            self.margin,
            self.even,
        ]
    }

    /// The factors from an array in the order of [`NAMES`].
    pub fn from_array(a: [f64; TERMS]) -> OrderFactors {
        OrderFactors {
            centred: a[0],
            opposed: a[1],
            spread: a[2],
            margin: a[3],
            even: a[4],
        }
    }

    /// The score of a grasp at `place` of `found` on its axis with `terms`.
    pub fn score(&self, place: usize, found: usize, terms: &OrderTerms) -> f64 {
        let t = terms.as_array();
        let f = self.as_array();
        -(place as f64) / (found.max(1) as f64) + (0..TERMS).map(|k| f[k] * t[k]).sum::<f64>()
    }
}

/// How many terms the order has.
pub const TERMS: usize = 5;

/// The `[planner]` keys of the factors, in order.
pub const NAMES: [&str; TERMS] = [
    "sf_centred",
    "sf_opposed",
    "sf_spread",
    "sf_margin",
    "sf_even",
];

/// The largest magnitude a factor may have: the thesis term (the place, from 0 to −1) is then
/// outweighed a hundredfold; more says nothing more.
pub const MAX_FACTOR: f64 = 100.0;

impl OrderTerms {
    /// The terms in the order of [`NAMES`].
    pub fn as_array(&self) -> [f64; TERMS] {
        [
            self.centred,
            self.opposed,
            self.spread,
            self.margin,
            self.even,
        ]
    }

    /// The terms from an array in the order of [`NAMES`].
    pub fn from_array(a: [f64; TERMS]) -> OrderTerms {
        OrderTerms {
            centred: a[0],
            opposed: a[1],
            spread: a[2],
            margin: a[3],
            even: a[4],
        }
    }
}

/// The terms of `g`, planned on `aligned` for `hand`.
pub fn terms(g: &Grasp, aligned: &AlignedObject, hand: &Hand) -> OrderTerms {
    let contacts = super::contacts::planned_contacts(g, hand);
    let height = aligned.height_mm.max(1e-9);
    let com = aligned.to_aligned * Point3::from(aligned.original.centroid.coords);
    let n = contacts.len().max(1) as f64;
    let centroid: Vector3<f64> = contacts
        .iter()
        .map(|c| Vector3::from(c.point_mm))
        .sum::<Vector3<f64>>()
        / n;
    let push: Vector3<f64> = contacts
        .iter()
        .map(|c| Vector3::from(c.normal))
        .sum::<Vector3<f64>>()
        / n;
    let (lo, hi) = contacts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
            (lo.min(c.point_mm[2]), hi.max(c.point_mm[2]))
        });
    let spread = if contacts.is_empty() {
        0.0
    } else {
        (hi - lo) / height
    };
    let margin = g
        .fingers
        .iter()
        .flat_map(|f| {
            [
                (f.centre.theta1_deg, hand.joints.theta1_range_deg),
                (f.centre.theta2_deg, hand.joints.theta2_range_deg),
            ]
        })
        .map(|(t, [a, b])| {
            let (a, b) = (a.min(b), a.max(b));
            let range = (b - a).max(1e-9);
            ((t - a).min(b - t) / range).clamp(0.0, 0.5)
        })
        .fold(0.5, f64::min);
    let [a2, b2] = hand.joints.theta2_range_deg;
    let (lo2, hi2) = g
        .fingers
        .iter()
        .map(|f| f.centre.theta2_deg)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
            (lo.min(t), hi.max(t))
        });
    let even = if g.fingers.is_empty() {
        0.0
    } else {
        -(hi2 - lo2) / (b2 - a2).abs().max(1e-9)
    };
    OrderTerms {
        centred: if contacts.is_empty() {
            0.0
        } else {
            -(centroid - com.coords).norm() / height
        },
        opposed: -push.norm(),
        spread,
        margin,
        even,
    }
}

/// The thesis's order of `grasps` (all found on one axis) reordered by falling score under
/// `factors` (a stable sort: equal scores keep the thesis's order); the permutation as the
/// thesis places in the new order.
pub fn reorder(
    grasps: &[Grasp],
    aligned: &AlignedObject,
    hand: &Hand,
    factors: &OrderFactors,
) -> Vec<usize> {
    let n = grasps.len();
    let scores: Vec<f64> = grasps
        .iter()
        .enumerate()
        .map(|(i, g)| factors.score(i, n, &terms(g, aligned, hand)))
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| scores[b].total_cmp(&scores[a]));
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_at_zero_keep_the_place_alone() {
        let t = OrderTerms {
            centred: -0.3,
            opposed: -0.1,
            spread: 0.7,
            margin: 0.2,
            even: -0.1,
        };
        let f = OrderFactors::default();
        assert!(f.is_thesis());
        assert_eq!(f.score(0, 10, &t), 0.0);
        assert_eq!(f.score(5, 10, &t), -0.5);
        let g = OrderFactors::from_array([0.0, 0.0, 2.0, 0.0, 0.0]);
        assert!(!g.is_thesis());
        assert!((g.score(5, 10, &t) - (-0.5 + 1.4)).abs() < 1e-12);
    }
}
