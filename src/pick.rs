//! Picking diverse grasps among the planner's candidates (issues 57 and 58: `label`'s picks and
//! `[sim] order_by_closing`'s): farthest-point sampling over
//! the palm pose and the finger contacts, so that near-copies (the cup's first twelve candidates
//! differ only in the approach angle) are not labelled twice.
//!
//! Each candidate is a point of a feature space in the object file's frame, so that candidates
//! about different principal axes compare: the palm's centre `[mm]`, its three axes scaled by
//! [`ROTATION_SCALE_MM`] (a turn of θ moves them by about `√2 · θ ·` that many millimetres), and
//! the centroid of each finger's planned contacts `[mm]`. The first pick is the planner's first
//! candidate; each next pick is the candidate farthest from every pick so far (ties to the
//! earlier in search order). Deterministic: the same candidates give the same picks.

use crate::mesh::AlignedObject;
use crate::plan::search::Grasp;
use nalgebra::{Matrix3, Vector3};

/// The default `--candidates`: more than the planner's candidate budget finds on any object of
/// the real-object set, so that the picks cover the whole search.
pub const DEFAULT_CANDIDATES: usize = 4000;

/// The length that makes a palm turn comparable with a palm shift `[mm]`: a turn by 1 rad moves
/// the scaled axes as far as a shift by about this times √2 (50 mm, a palm's half width).
pub const ROTATION_SCALE_MM: f64 = 50.0;

/// One candidate's place in the feature space.
#[derive(Debug, Clone, PartialEq)]
pub struct Feature {
    /// The palm's centre, file frame `[mm]`.
    pub palm_mm: Vector3<f64>,
    /// The palm's rotation in the file frame (columns its x, y, z axes).
    pub palm_rotation: Matrix3<f64>,
    /// Per finger, the centroid of its planned contacts, file frame `[mm]` (the palm's centre for
    /// a finger planned to touch nothing).
    pub fingers_mm: Vec<Vector3<f64>>,
}

impl Feature {
    /// The distance between two candidates in the feature space `[mm]`.
    pub fn distance(&self, other: &Feature) -> f64 {
        let mut d2 = (self.palm_mm - other.palm_mm).norm_squared();
        d2 += ((self.palm_rotation - other.palm_rotation) * ROTATION_SCALE_MM).norm_squared();
        for (a, b) in self.fingers_mm.iter().zip(&other.fingers_mm) {
            d2 += (a - b).norm_squared();
        }
        d2.sqrt()
    }

    /// The palm poses' distance: (translation `[mm]`, rotation angle `[deg]`).
    pub fn palm_distance(&self, other: &Feature) -> (f64, f64) {
        let r = self.palm_rotation.transpose() * other.palm_rotation;
        let cos = ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
        (
            (self.palm_mm - other.palm_mm).norm(),
            cos.acos().to_degrees(),
        )
    }
}

/// The feature of a planned grasp for [`farthest_points`], in the file's frame.
pub fn feature_of(g: &Grasp, aligned: &AlignedObject, hand: &crate::hand::Hand) -> Feature {
    let back = aligned.to_aligned.rotation.inverse().to_rotation_matrix();
    let contacts = crate::plan::contacts::planned_contacts(g, hand);
    let fingers_mm = hand
        .finger_list
        .iter()
        .map(|f| {
            let pts: Vec<Vector3<f64>> = contacts
                .iter()
                .filter(|c| c.finger == f.name)
                .map(|c| {
                    aligned
                        .to_original(&nalgebra::Point3::from(c.point_mm))
                        .coords
                })
                .collect();
            if pts.is_empty() {
                aligned.to_original(&g.palm.origin).coords
            } else {
                pts.iter().sum::<Vector3<f64>>() / pts.len() as f64
            }
        })
        .collect();
    Feature {
        palm_mm: aligned.to_original(&g.palm.origin).coords,
        palm_rotation: back.matrix() * Matrix3::from_columns(&g.palm.axes),
        fingers_mm,
    }
}

/// The indices of `k` diverse candidates among `features` (in search order), by farthest-point
/// sampling from the first; all of them when there are at most `k`. Returned in search order.
pub fn farthest_points(features: &[Feature], k: usize) -> Vec<usize> {
    let n = features.len();
    if n <= k {
        return (0..n).collect();
    }
    if k == 0 {
        return Vec::new();
    }
    let mut picked = vec![0usize];
    let mut nearest: Vec<f64> = features.iter().map(|f| f.distance(&features[0])).collect();
    nearest[0] = f64::NEG_INFINITY;
    while picked.len() < k {
        // The farthest from every pick; the earliest in search order on a tie.
        let (next, _) =
            nearest
                .iter()
                .enumerate()
                .fold((usize::MAX, f64::NEG_INFINITY), |best, (i, &d)| {
                    if d > best.1 {
                        (i, d)
                    } else {
                        best
                    }
                });
        if next == usize::MAX {
            break;
        }
        picked.push(next);
        nearest[next] = f64::NEG_INFINITY;
        for (i, f) in features.iter().enumerate() {
            if nearest[i] > f64::NEG_INFINITY {
                nearest[i] = nearest[i].min(f.distance(&features[next]));
            }
        }
    }
    picked.sort_unstable();
    picked
}

/// [`farthest_points`] among the candidates `among` (indices into `features`, in search order):
/// the indices of `k` of them, the first of `among` always included, in search order.
pub fn farthest_among(features: &[Feature], among: &[usize], k: usize) -> Vec<usize> {
    let f: Vec<Feature> = among.iter().map(|&i| features[i].clone()).collect();
    farthest_points(&f, k)
        .into_iter()
        .map(|j| among[j])
        .collect()
}

/// How spread a set of candidates is: the mean over its pairs of the palm poses' distance, as
/// (translation `[mm]`, rotation `[deg]`); `(0, 0)` for fewer than two.
pub fn mean_pairwise(features: &[&Feature]) -> (f64, f64) {
    let mut sum = (0.0, 0.0);
    let mut pairs = 0usize;
    for (i, a) in features.iter().enumerate() {
        for b in &features[i + 1..] {
            let (t, r) = a.palm_distance(b);
            sum.0 += t;
            sum.1 += r;
            pairs += 1;
        }
    }
    if pairs == 0 {
        (0.0, 0.0)
    } else {
        (sum.0 / pairs as f64, sum.1 / pairs as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f64, turn_deg: f64) -> Feature {
        Feature {
            palm_mm: Vector3::new(x, 0.0, 0.0),
            palm_rotation: *nalgebra::Rotation3::from_axis_angle(
                &Vector3::z_axis(),
                turn_deg.to_radians(),
            )
            .matrix(),
            fingers_mm: vec![Vector3::new(x, 10.0, 0.0)],
        }
    }

    #[test]
    fn the_farthest_point_picks_skip_near_copies() {
        // Ten near-copies of the first candidate (0.1 mm apart), then two far ones: the picks are
        // the first and the two far ones, not the copies.
        let mut f: Vec<Feature> = (0..10).map(|i| at(0.1 * f64::from(i), 0.0)).collect();
        f.push(at(100.0, 0.0));
        f.push(at(50.0, 90.0));
        assert_eq!(farthest_points(&f, 3), [0, 10, 11]);
        // The first is always picked; all are picked when there are few.
        assert_eq!(farthest_points(&f, 1), [0]);
        assert_eq!(farthest_points(&f[..2], 5), [0, 1]);
        assert!(farthest_points(&f, 0).is_empty());
        // Deterministic, and ties go to the earlier candidate: two equally far copies.
        let g = vec![at(0.0, 0.0), at(10.0, 0.0), at(10.0, 0.0)];
        assert_eq!(farthest_points(&g, 2), [0, 1]);
    }

    #[test]
    fn a_palm_turn_counts_as_a_shift_of_its_scale() {
        // A quarter turn moves the scaled x and y axes by √2 · 50 mm each: 100 mm in all.
        let d = at(0.0, 0.0).distance(&at(0.0, 90.0));
        assert!((d - 100.0).abs() < 1e-9, "{d}");
        let (t, r) = at(0.0, 0.0).palm_distance(&at(3.0, 30.0));
        assert!(
            (t - 3.0).abs() < 1e-12 && (r - 30.0).abs() < 1e-9,
            "{t} {r}"
        );
        let (t, r) = mean_pairwise(&[&at(0.0, 0.0), &at(3.0, 0.0), &at(6.0, 0.0)]);
        assert!((t - 4.0).abs() < 1e-12 && r.abs() < 1e-6, "{t} {r}");
    }
}
