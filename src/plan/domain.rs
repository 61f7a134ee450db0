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

use super::PlannerParams;
use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::slice::{slice, Contour, Plane, Slice, SliceOptions};
use nalgebra::Point2;
use rayon::prelude::*;

/// The reduced search domain of stage 1.
#[derive(Debug, Clone)]
pub struct Domain {
    /// Vertical slices, one per AngularStep in [0°, 180°), bridged as a finger meets them
    /// ([`Slice::bridged_prepared`]), or only cut where [`cannot_grade`] shows that no slices
    /// could make the object graspable.
    pub slices: Vec<Slice>,
    /// Their angles from +X `[deg]`.
    pub angles_deg: Vec<f64>,
    /// Effective Elevation `[lo, hi]` `[mm]`.
    pub effective: [f64; 2],
    /// Indexed Elevations `[mm]`: `elevations[i - 1]` is index `i`.
    pub elevations: Vec<f64>,
    /// HeightStep `[mm]`.
    pub height_step_mm: f64,
    /// The elevations every vertical slice spans (the thesis's Effective Elevation before the
    /// finger offset is taken off) `[mm]`.
    pub span_mm: [f64; 2],
    /// Each slice's lowest and highest elevation `[lo, hi]` `[mm]`, in the order of `slices`.
    pub slice_z_range_mm: Vec<[f64; 2]>,
    /// The outermost crossings of each indexed elevation with each slice, found once here for
    /// every stage that grades by them: `crossings[i][k]` is [`Domain::touches`]`(k,
    /// elevations[i])`, or `None` where the elevation is within [`SLICE_END_MM`] of the
    /// slice's lowest or highest point.
    pub crossings: Vec<Vec<Option<(Touch, Touch)>>>,
    /// Outward directions of the object's large flat side faces, as angles from +X `[deg]`
    /// (see [`face_directions_deg`]); the palm approaching at such an angle lies flat on the face.
    pub face_directions_deg: Vec<f64>,
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
        Domain::build_with(mesh, params, hand, hand.fingers.offset_mm)
    }

    /// Stage 1 with the Effective Elevation shrunk by `shrink_mm` at both ends instead of the
    /// finger offset: 0 under the extended rules, whose outer fingers may touch the object
    /// beyond the thesis's Effective Elevation (see [`super::palm_grade::rank_with`]).
    pub fn build_with(mesh: &Mesh, params: &PlannerParams, hand: &Hand, shrink_mm: f64) -> Domain {
        let step = params.angular_step_deg;
        let count = (180.0 / step).round().max(1.0) as usize;
        let angles_deg: Vec<f64> = (0..count).map(|k| k as f64 * step).collect();
        let hopeless = cannot_grade(mesh, params, hand, &angles_deg);
        // The vertical slices are independent, so they are cut and bridged on rayon's pool;
        // `collect` keeps the angles' order, so the domain is the same whatever the thread count.
        let slices: Vec<Slice> = angles_deg
            .par_iter()
            .map(|a| {
                let plane = Plane::vertical(a.to_radians());
                if hopeless {
                    slice(mesh, &plane, SliceOptions::default().unrepaired())
                } else {
                    // The slice as the hand meets it (issue 30): pieces closer than a finger
                    // bridged, dents shallower than the relief filled, gaps narrower than a
                    // finger filled; curvature is graded on this contour.
                    let (w, relief) = (hand.finger_width_mm(), hand.relief_mm());
                    slice(mesh, &plane, SliceOptions::default())
                        .bridged_prepared(w, relief)
                        .simplified(relief)
                        .filled_vertically(w)
                }
            })
            .collect();
        Domain::from_slices(mesh, params, slices, angles_deg, shrink_mm)
    }

    /// Stage 1 shrunk by `shrink_mm` on the vertical slices of `other`, a domain of the same
    /// mesh, AngularStep and hand (the slices do not depend on the shrink): what another rule
    /// set's domain of the same axis costs without cutting and bridging them again (issue 30).
    pub fn reshrunk(other: &Domain, mesh: &Mesh, params: &PlannerParams, shrink_mm: f64) -> Domain {
        let (slices, angles) = (other.slices.clone(), other.angles_deg.clone());
        Domain::from_slices(mesh, params, slices, angles, shrink_mm)
    }

    /// Stage 1 from its vertical slices at `angles_deg`.
    fn from_slices(
        mesh: &Mesh,
        params: &PlannerParams,
        slices: Vec<Slice>,
        angles_deg: Vec<f64>,
        shrink_mm: f64,
    ) -> Domain {
        let slice_z_range_mm: Vec<[f64; 2]> = slices.iter().map(|s| z_range(&s.contours)).collect();
        let mut lo = f64::NEG_INFINITY;
        let mut hi = f64::INFINITY;
        for [a, b] in &slice_z_range_mm {
            lo = lo.max(*a);
            hi = hi.min(*b);
        }
        let effective = [lo + shrink_mm, hi - shrink_mm];
        let h = params.height_step_mm;
        let mut elevations = Vec::new();
        if effective[0].is_finite() && effective[1] >= effective[0] {
            // An end landing on a step is kept within [`SLICE_END_MM`]: the file's frame rounds
            // the span by some 1e-5 mm, and a tolerance of 1e-9 steps kept the top elevation of
            // a 40 mm plate (50 mm under the extended rules, 20 steps) in one frame and not in
            // another, and with it a sorted index and 40 candidates (issue 30).
            let n = ((effective[1] - effective[0] + SLICE_END_MM) / h).floor() as usize + 1;
            elevations = (0..n).map(|i| effective[0] + i as f64 * h).collect();
        }
        let crossings = elevations
            .iter()
            .map(|&z| {
                slices
                    .iter()
                    .zip(&slice_z_range_mm)
                    .map(|(s, &[a, b])| {
                        // Within SLICE_END_MM of the slice's lowest or highest point the line
                        // meets only its end: a flat bottom cut at its own height, whose
                        // chord is all of it in the file's frame and a sliver or nothing in
                        // another (issue 30). The extended rules' elevations may land there
                        // exactly (the finger offset less the overlap, a whole number of steps).
                        if z <= a + SLICE_END_MM || z >= b - SLICE_END_MM {
                            None
                        } else {
                            outermost_crossings(&s.contours, z)
                        }
                    })
                    .collect()
            })
            .collect();
        Domain {
            slices,
            slice_z_range_mm,
            crossings,
            angles_deg,
            effective,
            elevations,
            height_step_mm: h,
            span_mm: [lo, hi],
            face_directions_deg: face_directions_deg(mesh, params.vertical_deviation_deg),
        }
    }

    /// The outermost crossings of the horizontal line at `z` with slice `k`: `(left, right)`,
    /// the touch points with the smallest and largest `s`. `None` when the line misses the slice.
    pub fn touches(&self, k: usize, z: f64) -> Option<(Touch, Touch)> {
        outermost_crossings(&self.slices[k].contours, z)
    }
}

/// Returns true if no palm position on `mesh` can have a finger that must sit on a graded elevation
/// (every rule set's inner finger) on one, whatever its vertical slices at `angles_deg` turn out to
/// be; false when that is not known without them (issue 30: a cheap necessary condition, before the
/// slices are cut, united and bridged, which on a degenerate mesh can cost a minute in i_overlay).
/// Two bounds, from the vertices alone:
/// - the object is shorter than twice the finger offset: the thesis's Effective Elevation is
///   empty, and under the extended rules so is the range the inner fingers must lie in
///   (a slice spans at most the vertices' elevations);
/// - the mean over the slice angles of the object's width across each slice plane (its
///   vertices' extent along the plane's horizontal axis, which bounds every chord of that
///   slice, bridged or not: the bridging stays within the cut's convex hull) is below the
///   smallest graspable diameter: every Effective Diameter is too thin.
///
/// A hand whose fingers are all outer ones (at two heights only) is never rejected here: the
/// extended rules place outer fingers on ungraded elevations. Neither bound depends on the
/// shrink of the Effective Elevation, so [`Domain::reshrunk`] may reuse slices cut either way.
pub fn cannot_grade(mesh: &Mesh, params: &PlannerParams, hand: &Hand, angles_deg: &[f64]) -> bool {
    let offsets = super::palm_grade::finger_offsets(hand, params.height_step_mm);
    let (hi, lo) = (
        offsets.iter().copied().max().unwrap_or(0),
        offsets.iter().copied().min().unwrap_or(0),
    );
    let has_inner = hi == lo || offsets.iter().any(|&o| o != hi && o != lo);
    if !has_inner || mesh.vertices.is_empty() || angles_deg.is_empty() {
        return false;
    }
    // A margin far above round-off and far below anything a hand can feel `[mm]`.
    const MARGIN_MM: f64 = 1e-6;
    let (z_lo, z_hi) = mesh
        .vertices
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.z), b.max(p.z))
        });
    if z_hi - z_lo + MARGIN_MM < 2.0 * hand.fingers.offset_mm {
        return true;
    }
    let width = |a: f64| {
        let (s, c) = a.to_radians().sin_cos();
        let (l, r) = mesh
            .vertices
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, r), p| {
                let u = c * p.x + s * p.y;
                (l.min(u), r.max(u))
            });
        r - l
    };
    let mean = angles_deg.iter().map(|&a| width(a)).sum::<f64>() / angles_deg.len() as f64;
    let min = super::kinematics::graspable_range_with(hand, params.magnify_factor).used()[0];
    mean + MARGIN_MM < min
}

/// How near a slice's lowest or highest point an elevation counts as missing that slice
/// `[mm]`: far above the round-off of a file written in single precision in another frame
/// (some 1e-5 mm on an object 500 mm from its origin), far below anything a finger feels.
pub const SLICE_END_MM: f64 = 1e-4;

/// The lowest and highest elevation of `contours`' points, `[lo, hi]` `[mm]` (`[∞, −∞]` when
/// there are none).
pub fn z_range(contours: &[Contour]) -> [f64; 2] {
    let (lo, hi) = contours
        .iter()
        .flat_map(|c| c.points.iter())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.y), b.max(p.y))
        });
    [lo, hi]
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

/// A flat face counts as large when it holds at least this share of the side area.
const LARGE_FACE_SHARE: f64 = 0.05;

/// The outward directions (angles from +X in `[0, 360)` `[deg]`) of the object's large flat side
/// faces: triangles whose normal is within the Vertical Deviation Range of horizontal, grouped
/// by azimuth where neighbours differ by at most 0.5°, each group at least 5 % of the side area
/// (a cylinder's facets, 2.5° apart and under 1 % each, are not faces), as its area-weighted
/// mean azimuth rounded to 1e-6°. The thesis's AngularStep grid depends on where the alignment
/// happened to put X; these directions do not.
pub fn face_directions_deg(mesh: &Mesh, vertical_deviation_deg: f64) -> Vec<f64> {
    let max_z = vertical_deviation_deg.to_radians().sin();
    let mut side: Vec<(f64, f64)> = Vec::new();
    for t in 0..mesh.triangles.len() {
        let n = mesh.area_normal(t);
        let area = 0.5 * n.norm();
        if area <= 0.0 || (n.z / (2.0 * area)).abs() > max_z {
            continue;
        }
        side.push((n.y.atan2(n.x).to_degrees().rem_euclid(360.0), area));
    }
    let total: f64 = side.iter().map(|s| s.1).sum();
    if side.is_empty() || total <= 0.0 {
        return Vec::new();
    }
    side.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    // Start the groups after the widest gap in azimuth, so no group straddles 0°/360°.
    let n = side.len();
    let start = (0..n)
        .max_by(|&i, &j| {
            let gap = |k: usize| (side[(k + 1) % n].0 - side[k].0).rem_euclid(360.0);
            gap(i).total_cmp(&gap(j)).then(j.cmp(&i))
        })
        .map_or(0, |i| (i + 1) % n);
    let mut faces = Vec::new();
    let mut group: Vec<(f64, f64)> = Vec::new();
    let mut flush = |group: &mut Vec<(f64, f64)>| {
        let area: f64 = group.iter().map(|g| g.1).sum();
        if area >= LARGE_FACE_SHARE * total {
            let a0 = group[0].0;
            let mean = group
                .iter()
                .map(|(a, _)| (a - a0 + 180.0).rem_euclid(360.0) - 180.0 + a0)
                .zip(group.iter().map(|g| g.1))
                .map(|(a, w)| a * w)
                .sum::<f64>()
                / area;
            faces.push((mean.rem_euclid(360.0) * 1e6).round() / 1e6);
        }
        group.clear();
    };
    for k in 0..n {
        let cur = side[(start + k) % n];
        if let Some(last) = group.last() {
            if (cur.0 - last.0).rem_euclid(360.0) > 0.5 {
                flush(&mut group);
            }
        }
        group.push(cur);
    }
    flush(&mut group);
    faces.sort_by(f64::total_cmp);
    faces.dedup();
    faces
}
