//! Stage 1 of search-domain reduction (thesis 3.4.2, Fig. 3.9–3.11).
//!
//! Input: the aligned mesh. Output: the vertical slices through the principal axis at every
//! AngularStep in [0°, 180°) (a plane through the axis shows both sides, so the half turn covers
//! the whole object; the thesis's effective diameter of 23 mm for the 15 × 30 prism, 5.1, is the
//! mean chord over exactly these slices), the Effective Elevation (the maximum of the slices'
//! lowest points to the minimum of their highest points, shrunk by the finger offset at both
//! ends), and the Indexed Elevations every HeightStep from its bottom, index 1 the lowest.
//!
//! The slices are computed once here and reused by every later stage (and by a tuner sweeping
//! parameters that do not change them).

use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::scenario::PlannerParams;
use crate::slice::{slice, Contour, Plane, Slice};
use nalgebra::Point2;

/// The reduced search domain of stage 1.
#[derive(Debug, Clone)]
pub struct Domain {
    /// Vertical slices, one per AngularStep in [0°, 180°).
    pub slices: Vec<Slice>,
    /// Their angles from +X `[deg]`.
    pub angles_deg: Vec<f64>,
    /// Effective Elevation `[lo, hi]` `[mm]`.
    pub effective: [f64; 2],
    /// Indexed Elevations `[mm]`: `elevations[i - 1]` is index `i`.
    pub elevations: Vec<f64>,
    /// HeightStep `[mm]`.
    pub height_step_mm: f64,
}

/// Where a horizontal line at one elevation touches a slice's outline on one side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    /// Which contour of the slice.
    pub contour: usize,
    /// Which segment of that contour.
    pub segment: usize,
    /// The touch point `(s, z)` `[mm]`.
    pub point: Point2<f64>,
}

impl Domain {
    /// Runs stage 1.
    pub fn build(mesh: &Mesh, params: &PlannerParams, hand: &Hand) -> Domain {
        let step = params.angular_step_deg;
        let count = (180.0 / step).round().max(1.0) as usize;
        let angles_deg: Vec<f64> = (0..count).map(|k| k as f64 * step).collect();
        let slices: Vec<Slice> = angles_deg
            .iter()
            .map(|a| slice(mesh, &Plane::vertical(a.to_radians())))
            .collect();
        let mut lo = f64::NEG_INFINITY;
        let mut hi = f64::INFINITY;
        for s in &slices {
            let (a, b) = s
                .contours
                .iter()
                .flat_map(|c| c.points.iter())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                    (a.min(p.y), b.max(p.y))
                });
            lo = lo.max(a);
            hi = hi.min(b);
        }
        let offset = hand.fingers.offset_mm;
        let effective = [lo + offset, hi - offset];
        let h = params.height_step_mm;
        let mut elevations = Vec::new();
        if effective[0].is_finite() && effective[1] >= effective[0] {
            // A tiny tolerance so that an end landing exactly on a step is kept despite rounding.
            let n = ((effective[1] - effective[0]) / h + 1e-9).floor() as usize + 1;
            elevations = (0..n).map(|i| effective[0] + i as f64 * h).collect();
        }
        Domain {
            slices,
            angles_deg,
            effective,
            elevations,
            height_step_mm: h,
        }
    }

    /// The outermost crossings of the horizontal line at `z` with slice `k`: `(left, right)`,
    /// the touch points with the smallest and largest `s`. `None` when the line misses the slice.
    pub fn touches(&self, k: usize, z: f64) -> Option<(Touch, Touch)> {
        outermost_crossings(&self.slices[k].contours, z)
    }
}

/// The crossings of the line at height `z` with the smallest and largest horizontal coordinate.
pub fn outermost_crossings(contours: &[Contour], z: f64) -> Option<(Touch, Touch)> {
    let mut left: Option<Touch> = None;
    let mut right: Option<Touch> = None;
    for (ci, c) in contours.iter().enumerate() {
        for si in 0..c.segment_count() {
            let (a, b) = c.segment(si);
            // Half-open in z so a vertex exactly at z is counted once; a horizontal segment at
            // z counts at both of its ends.
            let crosses = (a.y <= z && z < b.y) || (b.y <= z && z < a.y) || (a.y == z && b.y == z);
            if !crosses {
                continue;
            }
            let candidates = if a.y == b.y {
                [a.x, b.x]
            } else {
                let t = (z - a.y) / (b.y - a.y);
                let s = a.x + t * (b.x - a.x);
                [s, s]
            };
            for s in candidates {
                let touch = Touch {
                    contour: ci,
                    segment: si,
                    point: Point2::new(s, z),
                };
                if left.is_none_or(|l| s < l.point.x) {
                    left = Some(touch);
                }
                if right.is_none_or(|r| s > r.point.x) {
                    right = Some(touch);
                }
            }
        }
    }
    Some((left?, right?))
}
