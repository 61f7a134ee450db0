//! Palm positioning (thesis 3.5): palm domain, placing the palm onto the object, pitch, and the
//! penetration check in the vertical plane.
//!
//! The palm approaches along −u, where u = (cos a, sin a, 0) for approach angle a: the thesis turns
//! the object by the approach angle and always approaches along −X; turning the approach instead
//! is the same thing seen from the object. The analysis runs in the vertical slice at angle a,
//! whose right side (s > 0) faces the palm.
//!
//! - Palm range: the palm's vertical extent at zero pitch, from the lowest finger's centreline
//!   minus the palm margin to Finger_1's plus the margin, with Finger_1 at the candidate
//!   elevation. Palm domain (3.5.1): the right-side contour points in that range, with the points
//!   where contour segments cross its top and bottom (so a long segment is not missed).
//! - First contact: the palm line moved towards the object touches the domain point with the
//!   largest s.
//! - Pitch (3.5.2): the palm turns about the first contact until it meets a second one, in the
//!   other half of the palm (the half rule of the thesis); at the midpoint, the second-outermost
//!   point decides. No second point within the pitch range: the palm stays upright on one
//!   contact if none is closer than the range allows, and the candidate is rejected if the only
//!   second contacts need more pitch than allowed.
//! - Pitch sign: positive when the palm's top leans towards the object (thesis 5.4: +6.5° on
//!   the inverted cup; 5.3: −7° on the cup).
//! - Penetration (3.5.3): the palm outline (contact line and palm offset behind it) must not
//!   take in any piece of the slice contour.

use super::geom2::ConvexPolygon;
use super::RuleSet;
use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::slice::{slice, Plane, Slice, SliceOptions};
use nalgebra::{Point2, Point3, Vector2, Vector3};

/// Tolerance for penetration tests `[mm]`: well under a facet's chord error for the bundled
/// meshes (0.005 mm for D40) doubled, and far under any finger dimension.
pub const PENETRATION_TOL_MM: f64 = 0.05;

/// A placed palm.
#[derive(Debug, Clone, PartialEq)]
pub struct PalmPlacement {
    /// Approach angle `[rad]`.
    pub approach_rad: f64,
    /// Pitch `[rad]`, positive when the top leans towards the object.
    pub pitch_rad: f64,
    /// The palm centre on its contact surface (aligned frame) `[mm]`.
    pub origin: Point3<f64>,
    /// Palm frame axes in the aligned frame: x away from the object (the contact surface's
    /// back), y sideways (the "left" fingers' side), z up (parallel to the joint axes).
    pub axes: [Vector3<f64>; 3],
    /// Contact points in the vertical slice `(s, z)` `[mm]`.
    pub contacts: Vec<Point2<f64>>,
    /// The vertical slice at the approach angle.
    pub slice: Slice,
    /// How far the palm was moved back from its thesis position so as not to take in the
    /// object (extended rules only; else 0) `[mm]`.
    pub backed_off_mm: f64,
    /// How far the palm stands off the object beyond that, the object held between the
    /// phalanges (issue 37: a hand with `palm.standoff_max_mm`; else 0) `[mm]`.
    pub standoff_mm: f64,
}

/// Why a palm placement failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PalmRejection {
    /// No contour point in the palm range on the approach side.
    NoContact,
    /// The only second contacts need more pitch than the pitch range.
    PitchOutOfRange,
    /// The palm outline takes in part of the object in the vertical plane.
    Penetration,
    /// Under [`RuleSet::Leaning`]: the palm's second contact is within the pitch range, a
    /// placement the rule sets before it tried.
    WithinPitchRange,
}

/// Places the palm with Finger_1 at elevation `z1` and approach angle `approach_rad`.
pub fn place_palm(
    mesh: &Mesh,
    hand: &Hand,
    z1: f64,
    approach_rad: f64,
    pitch_range_rad: f64,
) -> Result<PalmPlacement, PalmRejection> {
    let vslice = vertical_slice(mesh, hand, approach_rad);
    place_palm_on(
        &vslice,
        hand,
        z1,
        approach_rad,
        pitch_range_rad,
        RuleSet::Thesis,
    )
}

/// The vertical slice the palm is placed in at approach angle `approach_rad`, bridged to the
/// finger width: it depends on the angle only, so a search cuts it once per angle and hands it
/// to [`place_palm_on`] for every elevation.
pub fn vertical_slice(mesh: &Mesh, hand: &Hand, approach_rad: f64) -> Slice {
    slice(
        mesh,
        &Plane::vertical(approach_rad),
        SliceOptions::default(),
    )
    .bridged_within(hand.finger_width_mm(), hand.relief_mm())
}

/// [`place_palm`] in `vslice`, the [`vertical_slice`] at `approach_rad`, under `rules`. Under
/// the extended rules a palm outline that takes in part of the object in the vertical plane is
/// moved back along its normal until it only touches ([`super::Relaxation::PalmBackedOff`])
/// instead of being rejected. Under [`RuleSet::Leaning`] a second contact beyond the pitch
/// range leaves the palm leaning at the range's limit on its first contact alone
/// ([`super::Relaxation::PalmPitchClamped`]), and a palm within the range is not placed (the
/// rule sets before it placed it).
pub fn place_palm_on(
    vslice: &Slice,
    hand: &Hand,
    z1: f64,
    approach_rad: f64,
    pitch_range_rad: f64,
    rules: RuleSet,
) -> Result<PalmPlacement, PalmRejection> {
    let extended = rules.is_extended();
    let plane = Plane::vertical(approach_rad);
    let h1 = hand.finger_list[0].height_mm;
    let (h_lo, h_hi) = hand.finger_height_span();
    let m = hand.palm.margin_mm;
    let centre_z = z1 - h1;
    let (z_lo, z_hi) = (centre_z + h_lo - m, centre_z + h_hi + m);

    // Palm domain: right-side points in range, plus crossings of the range's ends.
    let domain = palm_domain(vslice, z_lo, z_hi);
    let first = outermost(domain.iter()).ok_or(PalmRejection::NoContact)?;

    let (second, pitch) = pitch_within_range(&domain, first, centre_z, pitch_range_rad, rules)?;

    // Up axis of the palm in the slice, and its outward normal (away from the object).
    let up = Vector2::new(-pitch.sin(), pitch.cos());
    let back = Vector2::new(pitch.cos(), pitch.sin());
    // Finger_1's point on the contact line at elevation z1, then the palm centre.
    let t = (z1 - first.y) / up.y;
    let p1 = first + up * t;
    let mut centre = p1 - up * h1;
    let mut backed_off_mm = 0.0;
    if extended {
        let depth = penetration_depth(vslice, centre, up, back, hand.palm_z_range_mm());
        if depth > PENETRATION_TOL_MM {
            centre += back * depth;
            backed_off_mm = depth;
        }
    }
    let [p_lo, p_hi] = hand.palm_z_range_mm();
    let outline = ConvexPolygon::new(vec![
        centre + up * p_lo,
        centre + up * p_hi,
        centre + up * p_hi + back * hand.palm.offset_mm,
        centre + up * p_lo + back * hand.palm.offset_mm,
    ]);
    if is_penetrated(vslice, &outline) {
        return Err(PalmRejection::Penetration);
    }

    let u = plane.u;
    let z = Vector3::z();
    let x_p = u * pitch.cos() + z * pitch.sin();
    let z_p = -u * pitch.sin() + z * pitch.cos();
    let y_p = z_p.cross(&x_p);
    let mut contacts = vec![first];
    contacts.extend(second);
    Ok(PalmPlacement {
        approach_rad,
        pitch_rad: pitch,
        origin: plane.to_3d(&centre),
        axes: [x_p, y_p, z_p],
        contacts,
        slice: vslice.clone(),
        backed_off_mm,
        standoff_mm: 0.0,
    })
}

/// The palm's second contact and its pitch `[rad]` from `first` ([`second_contact`]) within the
/// Pitch Range: beyond it the candidate is rejected, except under the leaning rules, which lean
/// the palm at the range's limit on `first` alone and place no palm within the range.
fn pitch_within_range(
    domain: &[Point2<f64>],
    first: Point2<f64>,
    centre_z: f64,
    pitch_range_rad: f64,
    rules: RuleSet,
) -> Result<(Option<Point2<f64>>, f64), PalmRejection> {
    let (second, pitch) = second_contact(domain, first, centre_z);
    if pitch.abs() > pitch_range_rad + 1e-12 {
        if second.is_some() && domain.len() > 1 {
            if rules != RuleSet::Leaning {
                return Err(PalmRejection::PitchOutOfRange);
            }
            // A rounded profile curves away from its outermost point faster than the range
            // lets the palm follow (an egg's or a star's shoulder): a palm turned less than the
            // second contact needs reaches no point of the other half, and rests on the first.
            Ok((None, pitch_range_rad.copysign(pitch)))
        } else {
            Ok((None, 0.0))
        }
    } else if rules == RuleSet::Leaning {
        Err(PalmRejection::WithinPitchRange)
    } else {
        Ok((second, pitch))
    }
}

/// Points this close to the axis `[mm]` count as on the object's right side: a vertex the
/// aligned frame puts on the axis (a diamond's corner, a pole, a bottom's centre) lies 1e-14 mm
/// to one side or the other as the file's frame rounds it, and counting it by its sign let the
/// palm pitch onto it (and the candidate fail the pitch range) in some frames and stand upright
/// in others (issue 30). The same as [`OUTERMOST_TIE_MM`].
const AXIS_TIE_MM: f64 = OUTERMOST_TIE_MM;

/// The palm domain in `vslice`: the points on the object's right side (x > −[`AXIS_TIE_MM`])
/// between heights `z_lo` and `z_hi`, and where a contour crosses those heights there.
fn palm_domain(vslice: &Slice, z_lo: f64, z_hi: f64) -> Vec<Point2<f64>> {
    let mut domain: Vec<Point2<f64>> = Vec::new();
    for c in &vslice.contours {
        for (i, p) in c.points.iter().enumerate() {
            if p.x > -AXIS_TIE_MM && p.y >= z_lo && p.y <= z_hi {
                domain.push(*p);
            }
            if i < c.segment_count() {
                let (a, b) = c.segment(i);
                for z in [z_lo, z_hi] {
                    if (a.y - z) * (b.y - z) < 0.0 {
                        let t = (z - a.y) / (b.y - a.y);
                        let q = a + (b - a) * t;
                        if q.x > -AXIS_TIE_MM {
                            domain.push(q);
                        }
                    }
                }
            }
        }
    }
    domain
}

/// Points this close to the outermost `[mm]` are as far out as it for the palm's contacts: a
/// face the aligned frame makes vertical has its vertices at the same x to round-off, which the
/// file's own frame sets (1e-5 to 4e-3 mm, docs/FRAMES.md); comparing them exactly let the
/// round-off pick the face's top in one frame and its bottom in another, the palm pivoting on
/// another point (issue 30). A fifth of [`PENETRATION_TOL_MM`], so that the true outermost
/// point stays within the tolerance of the palm line.
const OUTERMOST_TIE_MM: f64 = 0.01;

/// The outermost of `points` (the largest x), and of those within [`OUTERMOST_TIE_MM`] of it
/// the lowest (then the outermost): the palm's first contact. `None` when there are none.
fn outermost<'a>(points: impl Iterator<Item = &'a Point2<f64>> + Clone) -> Option<Point2<f64>> {
    let max_x = points
        .clone()
        .map(|p| p.x)
        .fold(f64::NEG_INFINITY, f64::max);
    points
        .filter(|p| p.x >= max_x - OUTERMOST_TIE_MM)
        .min_by(|a, b| a.y.total_cmp(&b.y).then(b.x.total_cmp(&a.x)))
        .copied()
}

/// The palm's second contact and its pitch `[rad]` about the first contact `first`, among the
/// `domain` points (the palm centre at height `centre_z`): with the first at the midpoint, the
/// second-outermost point; else the point on the other half the palm line reaches first.
/// `(None, 0)` when there is none.
fn second_contact(
    domain: &[Point2<f64>],
    first: Point2<f64>,
    centre_z: f64,
) -> (Option<Point2<f64>>, f64) {
    // The rotation about `first` that brings the palm line onto point p (≥ 0 when p is not
    // outside the line).
    let angle_to = |p: &Point2<f64>| (first.x - p.x).atan2((first.y - p.y).abs());
    let eps = 1e-9;
    if (first.y - centre_z).abs() <= eps {
        // Midpoint: the second-outermost point, either half.
        let second = outermost(domain.iter().filter(|p| (**p - first).norm() > eps));
        match second {
            Some(p) => {
                let phi = angle_to(&p);
                (Some(p), if p.y < centre_z { -phi } else { phi })
            }
            None => (None, 0.0),
        }
    } else {
        let top_first = first.y > centre_z;
        let other: Vec<&Point2<f64>> = domain
            .iter()
            .filter(|p| {
                if top_first {
                    p.y < centre_z
                } else {
                    p.y > centre_z
                }
            })
            .collect();
        let best = other
            .iter()
            .map(|p| (angle_to(p), **p))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.y.total_cmp(&b.1.y)));
        match best {
            // Top contact first: the bottom swings in, the top leans away (negative pitch).
            Some((phi, p)) => (Some(p), if top_first { -phi } else { phi }),
            None => (None, 0.0),
        }
    }
}

/// Returns true if and only if a segment of `vslice` enters the palm `outline` by more than
/// [`PENETRATION_TOL_MM`].
fn is_penetrated(vslice: &Slice, outline: &ConvexPolygon) -> bool {
    for c in &vslice.contours {
        for i in 0..c.segment_count() {
            let (a, b) = c.segment(i);
            if outline.is_penetrated_by(a, b, PENETRATION_TOL_MM) {
                return true;
            }
        }
    }
    false
}

impl PalmPlacement {
    /// The finger slice plane at `height` above the palm centre along the palm's up axis
    /// (thesis 3.6.2.1): 2D coordinates are (x away from the object, y sideways), with the palm
    /// contact surface at x = 0, as in [`super::kinematics`].
    pub fn finger_plane(&self, height: f64) -> Plane {
        Plane {
            origin: self.origin + self.axes[2] * height,
            u: self.axes[0],
            v: self.axes[1],
        }
    }
}

/// How far the object reaches past a palm contact line `[mm]`: the largest `(p − origin)·back`
/// over the slice's contours where `(p − origin)·up` lies in `band` (segments clipped to the
/// band, so a long segment counts where it crosses it); 0 or negative when nothing reaches past.
/// `up` and `back` are orthonormal.
pub fn penetration_depth(
    s: &Slice,
    origin: Point2<f64>,
    up: Vector2<f64>,
    back: Vector2<f64>,
    band: [f64; 2],
) -> f64 {
    let segments = s
        .contours
        .iter()
        .flat_map(|c| (0..c.segment_count()).map(|i| c.segment(i)));
    penetration_depth_of(segments, origin, up, back, band)
}

/// [`penetration_depth`] over loose segments (a cut not chained into contours,
/// [`crate::slice::cut_segments_indexed`]): the maximum is the same whatever their order.
pub fn penetration_depth_of(
    segments: impl IntoIterator<Item = (Point2<f64>, Point2<f64>)>,
    origin: Point2<f64>,
    up: Vector2<f64>,
    back: Vector2<f64>,
    band: [f64; 2],
) -> f64 {
    let mut depth = f64::NEG_INFINITY;
    for (a, b) in segments {
        let (ua, ub) = ((a - origin).dot(&up), (b - origin).dot(&up));
        let (da, db) = ((a - origin).dot(&back), (b - origin).dot(&back));
        // Clip the segment's parameter range to the band.
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        if (ub - ua).abs() < 1e-12 {
            if ua < band[0] || ua > band[1] {
                continue;
            }
        } else {
            let ta = (band[0] - ua) / (ub - ua);
            let tb = (band[1] - ua) / (ub - ua);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
            if t0 > t1 {
                continue;
            }
        }
        depth = depth.max(da + (db - da) * t0).max(da + (db - da) * t1);
    }
    depth
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slice::Contour;
    use std::f64::consts::FRAC_PI_2;

    use crate::hand::thesis_for_tests as thesis_hand;

    #[test]
    fn round_off_does_not_pick_the_end_of_a_vertical_face_the_palm_pivots_on() {
        // A face from y = 100 to 130 at x = 13, its ends apart by a file's round-off (1e-5 mm)
        // either way, and a point further in: the palm pivots on the face's lower end in both
        // (the golf club's head, issue 30: its top in three frames of six, backed 3.5 mm off).
        for tilt in [1e-5, -1e-5] {
            let points = [
                Point2::new(13.0 + tilt, 130.0),
                Point2::new(13.0, 100.0),
                Point2::new(3.4, 63.0),
            ];
            assert_eq!(outermost(points.iter()), Some(Point2::new(13.0, 100.0)));
        }
        // A point further out than the tie wins however high it is.
        let points = [Point2::new(13.02, 130.0), Point2::new(13.0, 100.0)];
        assert_eq!(outermost(points.iter()), Some(Point2::new(13.02, 130.0)));
        assert_eq!(outermost([].iter()), None);
    }

    #[test]
    fn the_palm_lies_flat_on_a_cylinder_from_any_side() {
        // The D40 cylinder has a vertex every 2.5°, so at these angles the wall is 20 mm out.
        let hand = thesis_hand();
        let mesh = crate::objects::cylinder(40.0, 124.0);
        let table = [
            (0.0, [20.0, 0.0]),
            (FRAC_PI_2, [0.0, 20.0]),
            (-FRAC_PI_2, [0.0, -20.0]),
        ];
        for (approach, [x, y]) in table {
            let p = place_palm(&mesh, &hand, 80.0, approach, 10f64.to_radians()).unwrap();
            assert_eq!(p.pitch_rad, 0.0, "{approach}");
            assert!(
                (p.origin - Point3::new(x, y, 55.0)).norm() < 1e-9,
                "{approach}: {}",
                p.origin
            );
            let u = Vector3::new(approach.cos(), approach.sin(), 0.0);
            assert!((p.axes[0] - u).norm() < 1e-12, "{approach}");
            assert!((p.axes[2] - Vector3::z()).norm() < 1e-12, "{approach}");
            assert!(
                (p.axes[1] - Vector3::z().cross(&u)).norm() < 1e-12,
                "{approach}"
            );
            assert_eq!(p.backed_off_mm, 0.0);
        }
    }

    #[test]
    fn the_palm_pitches_onto_a_cone_and_rejects_what_it_cannot_reach() {
        let hand = thesis_hand();
        // A cup: 56 mm across at the bottom, 80 at the top, 110 tall; its wall leans out by
        // atan(12 / 110) = 6.2° (thesis 5.3: the palm pitches −7° with its own geometry).
        let cup = crate::objects::frustum(56.0, 80.0, 110.0);
        let lean = (12.0f64 / 110.0).atan();
        let p = place_palm(&cup, &hand, 80.0, 0.0, 10f64.to_radians()).unwrap();
        assert!(
            (p.pitch_rad + lean).abs() < 1e-3,
            "pitch {}",
            p.pitch_rad.to_degrees()
        );
        assert_eq!(p.contacts.len(), 2);
        // (elevation, pitch range, rejection): above the object; a pitch range too small for
        // the wall's lean.
        let table = [
            (400.0, 0.2, PalmRejection::NoContact),
            (80.0, 1f64.to_radians(), PalmRejection::PitchOutOfRange),
        ];
        for (z1, range, rejection) in table {
            assert_eq!(
                place_palm(&cup, &hand, z1, 0.0, range),
                Err(rejection),
                "{z1} {range}"
            );
        }
        // The leaning rules lean the palm by the whole 1° instead, on the first contact alone,
        // and take in nothing of the cup; the extended rules reject it as the thesis does.
        // Within the range the extended rules place the thesis's palm, the leaning rules none.
        let vslice = vertical_slice(&cup, &hand, 0.0);
        let place =
            |range: f64, rules| place_palm_on(&vslice, &hand, 80.0, 0.0, range.to_radians(), rules);
        let clamped = place(1.0, RuleSet::Leaning).unwrap();
        assert!((clamped.pitch_rad + 1f64.to_radians()).abs() < 1e-12);
        assert_eq!(clamped.contacts.len(), 1);
        assert_eq!(clamped.backed_off_mm, 0.0);
        let rejected = Err(PalmRejection::PitchOutOfRange);
        assert_eq!(place(1.0, RuleSet::Extended), rejected);
        assert_eq!(place(10.0, RuleSet::Extended), Ok(p));
        let within = Err(PalmRejection::WithinPitchRange);
        assert_eq!(place(10.0, RuleSet::Leaning), within);
    }

    #[test]
    fn penetration_depth_measures_past_the_contact_line_within_the_band() {
        // A 13 × 10 mm rectangle reaching 3 mm past the line x = 0, from y = −5 to 5.
        let rect = Contour::from_polyline(
            vec![
                Point2::new(-10.0, -5.0),
                Point2::new(3.0, -5.0),
                Point2::new(3.0, 5.0),
                Point2::new(-10.0, 5.0),
            ],
            true,
        );
        let s = Slice {
            plane: Plane::horizontal(0.0),
            contours: vec![rect],
            outermost: Some(0),
        };
        let (up, back) = (Vector2::y(), Vector2::x());
        let table = [
            (Point2::origin(), [-1.0, 1.0], 3.0),
            (Point2::new(1.0, 0.0), [-1.0, 1.0], 2.0),
            (Point2::new(5.0, 0.0), [-20.0, 20.0], -2.0),
            (Point2::origin(), [10.0, 20.0], f64::NEG_INFINITY),
        ];
        for (origin, band, depth) in table {
            assert_eq!(
                penetration_depth(&s, origin, up, back, band),
                depth,
                "{origin} {band:?}"
            );
        }
    }
}
