//! Stage 2: grading by curvature pattern (thesis 3.4.3.1, Fig. 3.12–3.15).
//!
//! For each vertical slice and indexed elevation, the finger touch points are the outermost
//! crossings on the right and left side. Around each touch point the contour is walked away from
//! it, above and below, and the angular trend on each side is the signed turn of the contour's
//! tangent, positive when the surface turns outward (towards the finger); of the running sums of
//! turns along the walk, the one of largest magnitude (a ledge that turns out and then up again
//! is still "out"). The pair of trends
//! (above, below) gives the category; the grade of a slice is the mean of its two sides, the
//! grade of an elevation the mean over slices.
//!
//! Fig. 3.15 is lost. The categories are reconstructed from the text's descriptions, with the
//! weight acting along −Z (out: the surface turns towards the finger; in: away from it):
//!
//! | category | above | below | text | grade |
//! |---|---|---|---|---|
//! | Cat_4 | out | out | a concavity, finger constrained vertically | 1.00 |
//! | Cat_2 | out | straight | under a ridge | 0.95 |
//! | Cat_7 | out | in | as Cat_2, but thinner below | 0.90 |
//! | Cat_1 | straight | straight | vertical straight line | 0.85 |
//! | Cat_5 | straight, sloped | straight | Cat_1 minus the demerit of eq. 3.1 | 0.76–0.85 |
//! | Cat_3 | straight | out | a ridge below | 0.75 |
//! | Cat_6 | in | straight | thinner above | 0.70 |
//! | Cat_9 | in | out | as Cat_6, and pushed up from below | 0.65 |
//! | Cat_8 | in | in | a protrusion | 0.60 |
//!
//! The grades keep the text's order (Cat_4, Cat_2, Cat_7, Cat_1, Cat_5, Cat_3, Cat_6, Cat_9, Cat_8
//! from best to worst) on a scale where the best is 1 (the thesis normalises grades; its chapter 4
//! shows them ×20 with a best of 19.99). The ninth combination (straight above, in below) is not
//! among the text's categories; it is graded as a demoted Cat_1 (0.80): weight moves the object
//! down past the finger, so thinning below the finger matters less than above it.
//!
//! Choices where the thesis is silent (all parameters in [`CurvatureParams`]):
//! - Segment-length rules: the walk on each side stops once it is more than the reach (below)
//!   from the touch point ("too long stops the count"); a segment at least half the reach long
//!   counts twice ("long reduces the count"); a segment shorter than a
//!   tenth of the finger offset is skipped (its turn is kept, it is not counted), at most 5
//!   times; at most `curvature_segments` (3) segments are counted.
//! - The reach is 1.5 × finger offset (10.5 mm for the thesis hand). Two facts of the thesis fix
//!   it: the prism's first candidate is index 43, 12 mm below its top, so the top end must not
//!   demote 43 but does demote 44 (9.5 mm); and in chapter 4 the base step is first felt 10 mm
//!   above it (index 7). (Its Cat_2 zone under the ridge, indices 31–35, suggests a longer reach,
//!   about 13 mm; the two cannot both hold with one reach, and the table result was preferred.)
//! - A trend's strength fades gently with the distance of its nearest significant turn, from 1 at
//!   the touch point to 0.7 at the edge of reach, so a ridge's benefit lessens as the finger moves
//!   away from it and then drops sharply beyond reach (chapter 4: grades 19.99 → 19.12 ×20 from
//!   index 35 down to 31, then a sharp drop to Cat_1).
//! - Trends within ±5° are straight. The bonus and demotion algorithm: a trend between 5° and 45°
//!   is partly its category; the grade is the bilinear blend of the four categories spanned by
//!   the two trends' strengths (0 at 5°, 1 at 45°), so an intermediate pattern is promoted or
//!   demoted towards the category it tends to, and the dominant category has the largest weight.
//! - The slope of the touched segment from vertical beyond the Vertical Deviation Range turns
//!   Cat_1 into Cat_5 with the demerit of eq. 3.1 scaled so that the grade at the friction-cone
//!   limit stays just above Cat_3; beyond the friction cone (atan μ, 17° for μ = 0.3) the touch
//!   point is ungraspable.
//! - The slope graded is the touched segment's, blended with the next segment's within 0.05 mm
//!   in height of their shared vertex (their mean at the vertex), so that a touch height on a
//!   vertex grades the same slope a micrometre above or below it (issue 30: round-off put the
//!   book's touch on one side or the other in two frames; [`blended_slope`]).
//! - A sharp curve change is ungraspable: a vertex turning by more than 45° within half a
//!   HeightStep of the touch point, or a touched segment that is itself that steep.
//! - Near the ends of the object (thesis 5.1): a walk that reaches the slice's top within reach is
//!   graded as thinning above (Cat_6 behaviour), one that reaches its bottom as a ridge below
//!   (Cat_3 behaviour), at least as strongly as a 90° turn at that distance.
//! - The contour graded is the hand's (issue 30, beyond the thesis): stage 1's vertical slices
//!   with dents shallower than the hand's relief filled and vertical gaps narrower than a finger
//!   filled ([`crate::slice::Slice::filled_vertically`]), so a finger is not graded on teeth,
//!   threads or grooves it cannot enter. The thesis objects have no such gap but the chapter 4
//!   object's acute wedge above its base step and under its ridge (grades move by at most
//!   0.011, the grasp by 1e-7 mm); the thesis table is unchanged.
//! - An elevation is ungraspable if it is ungraspable in any slice (the palm may approach from
//!   any angle, and the search must not waste time on a level with a sharp edge somewhere).

use super::domain::SLICE_END_MM;
use super::PlannerParams;
use super::{Domain, Grade, Touch};
use crate::hand::Hand;
use crate::slice::Contour;
use nalgebra::Vector2;
use std::f64::consts::PI;

/// Knobs of the curvature grading; [`CurvatureParams::from_planner`] gives the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvatureParams {
    /// Segments counted on each side (thesis: 3).
    pub segments: usize,
    /// How far along the contour a walk looks `[mm]` (default: 1.5 × finger offset, see the
    /// module docs).
    pub reach_mm: f64,
    /// A segment at least this long counts twice `[mm]`.
    pub long_mm: f64,
    /// A segment shorter than this is skipped `[mm]`.
    pub short_mm: f64,
    /// Most segments skipped per walk.
    pub max_skips: usize,
    /// Trends smaller than this are straight `[deg]`.
    pub deadzone_deg: f64,
    /// Trends at least this strong are fully their category `[deg]`.
    pub full_trend_deg: f64,
    /// Strength factor of a turn at the edge of reach (1 at the touch point).
    pub edge_weight: f64,
    /// Vertical Deviation Range `[deg]`.
    pub vertical_deviation_deg: f64,
    /// Friction cone half-angle atan(μ) `[deg]`.
    pub friction_cone_deg: f64,
    /// A turn sharper than this is a sharp curve change `[deg]`.
    pub sharp_turn_deg: f64,
    /// A sharp turn this close to the touch point makes it ungraspable `[mm]`.
    pub sharp_distance_mm: f64,
    /// The grade of a touch point the thesis calls ungraspable, under the extended rules (a
    /// score below every category, 0.6–1.0, instead of a rejection); `None` under the thesis's.
    pub ungraspable_grade: Option<f64>,
}

impl CurvatureParams {
    /// Defaults tied to the finger thickness and the planner parameters.
    pub fn from_planner(p: &PlannerParams, hand: &Hand, friction: f64) -> CurvatureParams {
        CurvatureParams {
            segments: p.curvature_segments,
            reach_mm: 1.5 * hand.fingers.offset_mm,
            long_mm: 0.75 * hand.fingers.offset_mm,
            short_mm: hand.fingers.offset_mm / 10.0,
            max_skips: 5,
            deadzone_deg: 5.0,
            full_trend_deg: 45.0,
            edge_weight: 0.7,
            vertical_deviation_deg: p.vertical_deviation_deg,
            friction_cone_deg: friction.atan().to_degrees(),
            sharp_turn_deg: 45.0,
            sharp_distance_mm: p.height_step_mm / 2.0,
            ungraspable_grade: None,
        }
    }
}

/// The curvature categories (thesis Fig. 3.15, reconstructed; see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Category {
    /// Vertical straight line.
    Cat1,
    /// Under a ridge.
    Cat2,
    /// A ridge below.
    Cat3,
    /// A concavity.
    Cat4,
    /// Straight but sloped beyond the Vertical Deviation Range.
    Cat5,
    /// Thinner above.
    Cat6,
    /// Under a ridge, thinner below.
    Cat7,
    /// A protrusion.
    Cat8,
    /// Thinner above, pushed up from below.
    Cat9,
    /// Straight above, thinner below: a demoted Cat_1 (not a thesis category).
    Cat1Demoted,
}

impl Category {
    /// The grade of the pure category.
    pub fn grade(self) -> f64 {
        match self {
            Category::Cat4 => 1.00,
            Category::Cat2 => 0.95,
            Category::Cat7 => 0.90,
            Category::Cat1 => 0.85,
            Category::Cat1Demoted => 0.80,
            // Cat_5 is Cat_1 minus a demerit; this is its floor.
            Category::Cat5 => 0.76,
            Category::Cat3 => 0.75,
            Category::Cat6 => 0.70,
            Category::Cat9 => 0.65,
            Category::Cat8 => 0.60,
        }
    }

    /// The category of a pair of trend signs (−1 in, 0 straight, +1 out), above and below.
    pub fn from_signs(above: i8, below: i8) -> Category {
        match (above.signum(), below.signum()) {
            (1, 1) => Category::Cat4,
            (1, 0) => Category::Cat2,
            (1, _) => Category::Cat7,
            (0, 0) => Category::Cat1,
            (0, 1) => Category::Cat3,
            (0, _) => Category::Cat1Demoted,
            (_, 0) => Category::Cat6,
            (_, 1) => Category::Cat9,
            _ => Category::Cat8,
        }
    }
}

/// Why a touch point is ungraspable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ungraspable {
    /// The touched surface is steeper than the friction cone allows `[deg]`.
    Slope(f64),
    /// A sharp curve change at or next to the touch point.
    SharpChange,
    /// The elevation does not cut the slice.
    NoContact,
}

/// The grade of one touch point, with the numbers behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SideGrade {
    /// The grade, or why it is ungraspable.
    pub grade: Result<f64, Ungraspable>,
    /// The dominant category (the largest weight of the blend).
    pub category: Category,
    /// Trend above the touch point, outward positive `[deg]`.
    pub trend_above_deg: f64,
    /// Trend below the touch point, outward positive `[deg]`.
    pub trend_below_deg: f64,
    /// Slope of the touched segment from vertical, outward-leaning upwards positive `[deg]`.
    pub slope_deg: f64,
}

/// Curvature grades of every indexed elevation: `None` where ungraspable.
pub fn grade_elevations(domain: &Domain, p: &CurvatureParams) -> Vec<Grade> {
    grade_elevations_marked(domain, p).0
}

/// [`grade_elevations`], and per elevation whether a touch point the thesis calls ungraspable
/// was graded with `p.ungraspable_grade` instead (always false when that is `None`).
pub fn grade_elevations_marked(domain: &Domain, p: &CurvatureParams) -> (Vec<Grade>, Vec<bool>) {
    domain
        .crossings
        .iter()
        .map(|row| {
            let mut sum = 0.0;
            let mut floored = false;
            for ((s, touches), &[lo, hi]) in
                domain.slices.iter().zip(row).zip(&domain.slice_z_range_mm)
            {
                let Some((left, right)) = touches else {
                    return (None, false);
                };
                let zr = (lo, hi);
                let l = grade_side(&s.contours[left.contour], left, SliceSide::Left, zr, p).grade;
                let r =
                    grade_side(&s.contours[right.contour], right, SliceSide::Right, zr, p).grade;
                let g = p.ungraspable_grade;
                floored |= l.is_err() || r.is_err();
                match (l.ok().or(g), r.ok().or(g)) {
                    (Some(l), Some(r)) => sum += 0.5 * (l + r),
                    _ => return (None, false),
                }
            }
            let grade = (!domain.slices.is_empty()).then(|| sum / domain.slices.len() as f64);
            (grade, floored && grade.is_some())
        })
        .unzip()
}

/// Which side of a vertical slice a touch point is on: outward is +s on the right, −s on the
/// left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SliceSide {
    /// The side of smaller s.
    Left,
    /// The side of larger s.
    Right,
}

impl SliceSide {
    /// The outward sense of s: −1 on the left, +1 on the right.
    fn outward(self) -> f64 {
        match self {
            SliceSide::Left => -1.0,
            SliceSide::Right => 1.0,
        }
    }
}

/// Which way a walk goes in elevation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Vertical {
    Up,
    Down,
}

/// Grades one touch point on `side`; `z_range` is the slice's lowest and highest elevation.
pub fn grade_side(
    c: &Contour,
    touch: &Touch,
    side: SliceSide,
    z_range: (f64, f64),
    p: &CurvatureParams,
) -> SideGrade {
    let (a, b) = c.segment(touch.segment);
    let dz = b.y - a.y;
    // Which way along the contour is up on this segment.
    let forward_is_up = dz > 0.0;
    let up_dir = if forward_is_up { b - a } else { a - b };
    let slope = blended_slope(
        c,
        touch,
        forward_is_up,
        side,
        angle_of(up_dir, side, Vertical::Up),
    );
    let slope_deg = slope.to_degrees();
    let mut out = SideGrade {
        grade: Err(Ungraspable::SharpChange),
        category: Category::Cat1,
        trend_above_deg: 0.0,
        trend_below_deg: 0.0,
        slope_deg,
    };
    if dz == 0.0 || slope_deg.abs() > p.sharp_turn_deg {
        return out;
    }
    if slope_deg.abs() > p.friction_cone_deg {
        out.grade = Err(Ungraspable::Slope(slope_deg));
        return out;
    }
    let from = WalkStart {
        contour: c,
        touch,
        side,
    };
    let above = from.walk(forward_is_up, Vertical::Up, z_range.1, p);
    let below = from.walk(!forward_is_up, Vertical::Down, z_range.0, p);
    if above.sharp || below.sharp {
        return out;
    }
    // Reaching an end of the object: thinning above (Cat_6), a ridge below (Cat_3).
    let (mut ta, mut da) = (above.trend, above.nearest_turn);
    let (mut tb, mut db) = (below.trend, below.nearest_turn);
    if let Some(d) = above.reached_end {
        ta = -ta.abs().max(PI / 2.0);
        da = da.min(d);
    }
    if let Some(d) = below.reached_end {
        tb = tb.abs().max(PI / 2.0);
        db = db.min(d);
    }
    out.trend_above_deg = ta.to_degrees();
    out.trend_below_deg = tb.to_degrees();

    let (grade, category) = blended_grade(p, slope_deg, (ta, da), (tb, db));
    out.category = category;
    out.grade = Ok(grade);
    out
}

/// The grade of a side and its dominant category from the trends above and below (each a trend
/// `[rad]` and the distance to its nearest turn `[mm]`): the four categories their signs make,
/// blended by how strong each trend is, the straight one (Cat_1, or Cat_5 when sloped) graded
/// by the slope `slope_deg`.
fn blended_grade(
    p: &CurvatureParams,
    slope_deg: f64,
    (ta, da): (f64, f64),
    (tb, db): (f64, f64),
) -> (f64, Category) {
    let strength = |t: f64, d: f64| -> (i8, f64) {
        let deg = t.to_degrees();
        let k =
            ((deg.abs() - p.deadzone_deg) / (p.full_trend_deg - p.deadzone_deg)).clamp(0.0, 1.0);
        let fade = 1.0 - (1.0 - p.edge_weight) * (d / p.reach_mm).clamp(0.0, 1.0);
        if k > 0.0 {
            (deg.signum() as i8, k * fade)
        } else {
            (0, 0.0)
        }
    };
    let (sa, ka) = strength(ta, da);
    let (sb, kb) = strength(tb, db);
    // Cat_1, or Cat_5 when sloped: eq. 3.1 with the demerit scaled to stay above Cat_3 at the
    // friction-cone limit.
    let excess = slope_deg.abs() - p.vertical_deviation_deg;
    let straight = if excess > 0.0 {
        let span = (p.friction_cone_deg - p.vertical_deviation_deg).max(1e-9);
        Category::Cat1.grade()
            - (Category::Cat1.grade() - Category::Cat5.grade()) * (excess / span).min(1.0)
    } else {
        Category::Cat1.grade()
    };
    let g = |a: i8, b: i8| {
        if a == 0 && b == 0 {
            straight
        } else {
            Category::from_signs(a, b).grade()
        }
    };
    let weights = [
        ((0, 0), (1.0 - ka) * (1.0 - kb)),
        ((sa, 0), ka * (1.0 - kb)),
        ((0, sb), (1.0 - ka) * kb),
        ((sa, sb), ka * kb),
    ];
    let grade: f64 = weights.iter().map(|&((x, y), w)| w * g(x, y)).sum();
    let ((da, db), _) =
        weights.iter().copied().fold(
            ((0, 0), -1.0),
            |best, (cat, w)| if w > best.1 { (cat, w) } else { best },
        );
    let category = if da == 0 && db == 0 && excess > 0.0 {
        Category::Cat5
    } else {
        Category::from_signs(da, db)
    };
    (grade, category)
}

/// A touch height closer than this to an end of its segment `[mm]` grades a slope blended with
/// the neighbouring segment's (see [`blended_slope`]).
const VERTEX_BLEND_MM: f64 = 0.05;

/// The slope at `touch` (`own`, its segment's `[rad]`), made continuous across the segment's
/// ends: within [`VERTEX_BLEND_MM`] in height of an end, the mean of the two segments' slopes
/// at the vertex itself, fading to the segment's own at that distance. A touch height on a
/// vertex otherwise took the segment above in one frame and the one below in another, by 1 µm
/// of round-off (the book's #52: 26.8° or 13.8°, issue 30). An end where the contour turns
/// back down (an extremum) keeps the segment's own slope.
fn blended_slope(
    c: &Contour,
    touch: &Touch,
    forward_is_up: bool,
    side: SliceSide,
    own: f64,
) -> f64 {
    let k = touch.segment;
    let Some(k1) = next_vertex(c, k, true) else {
        return own;
    };
    let (upper, lower) = if forward_is_up { (k1, k) } else { (k, k1) };
    let z = touch.point.y;
    let (d_up, d_low) = (c.points[upper].y - z, z - c.points[lower].y);
    // The nearer end, and the upward direction of the segment beyond it.
    let (d, beyond) = if d_up <= d_low {
        let next = next_vertex(c, upper, forward_is_up);
        (d_up, next.map(|n| c.points[n] - c.points[upper]))
    } else {
        let prev = next_vertex(c, lower, !forward_is_up);
        (d_low, prev.map(|n| c.points[lower] - c.points[n]))
    };
    let d = d.max(0.0);
    let Some(dir) = beyond.filter(|v| v.y > 0.0 && d < VERTEX_BLEND_MM) else {
        return own;
    };
    let w = 0.5 * (1.0 - d / VERTEX_BLEND_MM);
    (1.0 - w) * own + w * angle_of(dir, side, Vertical::Up)
}

/// Angle of a direction from "straight on" along the walk, outward positive: `atan2(ds, dz)`
/// with `ds` the outward component and `dz` the component along the walk's vertical sense.
fn angle_of(v: Vector2<f64>, side: SliceSide, vertical: Vertical) -> f64 {
    let ds = side.outward() * v.x;
    let dz = match vertical {
        Vertical::Up => v.y,
        Vertical::Down => -v.y,
    };
    ds.atan2(dz)
}

/// A walk's vertex this far beyond the reach still counts `[mm]`: an object whose height is a
/// whole number of HeightSteps puts an elevation exactly one reach below its top (10.5 mm =
/// 100 mm − 7 mm − 33 × 2.5 mm), and round-off in another frame would put the top corner just
/// outside it, grading the elevation Cat_1 there and as thinning above here (issue 30).
const REACH_TIE_MM: f64 = 1e-4;

struct Walk {
    /// The walk's largest excursion: the partial sum of outward turns of largest magnitude, so
    /// that a ledge (out, then up again) still reads as out `[rad]`.
    trend: f64,
    cumulative: f64,
    /// Distance of the nearest turn larger than the dead zone `[mm]`.
    nearest_turn: f64,
    sharp: bool,
    reached_end: Option<f64>,
}

/// Where the walks of one touch point start: its contour, the touch point and its side.
struct WalkStart<'a> {
    contour: &'a Contour,
    touch: &'a Touch,
    side: SliceSide,
}

impl WalkStart<'_> {
    /// Walks from the touch point along the contour (`forward`: increasing index), measuring the
    /// weighted outward turn, going `vertical`; `z_end` is the slice's top (for an upward walk)
    /// or bottom.
    fn walk(&self, forward: bool, vertical: Vertical, z_end: f64, p: &CurvatureParams) -> Walk {
        let WalkStart {
            contour: c, side, ..
        } = *self;
        let up = vertical == Vertical::Up;
        let seg_count = c.segment_count();
        let mut result = Walk {
            trend: 0.0,
            cumulative: 0.0,
            nearest_turn: f64::INFINITY,
            sharp: false,
            reached_end: None,
        };
        let (mut vertex, mut prev, mut dist) = self.first_step(forward, vertical);
        let mut counted = 0usize;
        let mut skips = 0usize;
        // Within SLICE_END_MM of the slice's end: a flat bottom's two corners lie 1e-5 mm apart
        // in a file written in another frame, and at 1e-9 the walk met the end at one corner
        // and not at the other (a hexagonal prism's lowest graded elevation, issue 30).
        let is_end = |z: f64| {
            if up {
                z >= z_end - SLICE_END_MM
            } else {
                z <= z_end + SLICE_END_MM
            }
        };
        for _ in 0..seg_count {
            if dist > p.reach_mm + REACH_TIE_MM || counted >= p.segments {
                break;
            }
            if is_end(c.points[vertex].y) && result.reached_end.is_none() {
                result.reached_end = Some(dist);
            }
            // The segment leaving `vertex` in the walk's direction.
            let Some(next) = next_vertex(c, vertex, forward) else {
                break;
            };
            let v = c.points[next] - c.points[vertex];
            let len = v.norm();
            if len < p.short_mm && skips < p.max_skips {
                skips += 1;
                dist += len;
                vertex = next;
                continue;
            }
            let psi = angle_of(v, side, vertical);
            let turn = wrap(psi - prev);
            if turn.abs().to_degrees() > p.sharp_turn_deg && dist <= p.sharp_distance_mm {
                result.sharp = true;
            }
            result.cumulative += turn;
            if result.cumulative.abs() > result.trend.abs() {
                result.trend = result.cumulative;
            }
            if turn.abs().to_degrees() > p.deadzone_deg {
                result.nearest_turn = result.nearest_turn.min(dist);
            }
            prev = psi;
            counted += if len >= p.long_mm { 2 } else { 1 };
            dist += len;
            vertex = next;
        }
        result
    }

    /// The walk's first step, from the touch point along the touched segment: the first vertex
    /// reached, the direction's angle there (the segment's own where the touch is on that
    /// vertex) and the distance walked `[mm]`.
    fn first_step(&self, forward: bool, vertical: Vertical) -> (usize, f64, f64) {
        let WalkStart {
            contour: c,
            touch,
            side,
        } = *self;
        let n = c.points.len();
        // The first vertex reached, and the direction of travel along the touched segment.
        let (vertex, first_dir) = if forward {
            let v = (touch.segment + 1) % n;
            (v, c.points[v] - touch.point)
        } else {
            (touch.segment, c.points[touch.segment] - touch.point)
        };
        let (a, b) = c.segment(touch.segment);
        let seg_dir = if forward { b - a } else { a - b };
        let prev = angle_of(
            if first_dir.norm() > 0.0 {
                first_dir
            } else {
                seg_dir
            },
            side,
            vertical,
        );
        (vertex, prev, first_dir.norm())
    }
}

/// The vertex after `vertex` along `c` (backwards unless `forward`); `None` at an open
/// contour's end.
fn next_vertex(c: &Contour, vertex: usize, forward: bool) -> Option<usize> {
    let n = c.points.len();
    if forward {
        if !c.is_closed && vertex + 1 >= n {
            return None;
        }
        Some((vertex + 1) % n)
    } else {
        if !c.is_closed && vertex == 0 {
            return None;
        }
        Some((vertex + n - 1) % n)
    }
}

fn wrap(a: f64) -> f64 {
    let mut a = a % (2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    } else if a <= -PI {
        a += 2.0 * PI;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;

    fn params() -> CurvatureParams {
        CurvatureParams {
            segments: 3,
            reach_mm: 10.5,
            long_mm: 5.25,
            short_mm: 0.7,
            max_skips: 5,
            deadzone_deg: 5.0,
            full_trend_deg: 45.0,
            edge_weight: 0.7,
            vertical_deviation_deg: 12.0,
            friction_cone_deg: 0.3f64.atan().to_degrees(),
            sharp_turn_deg: 45.0,
            sharp_distance_mm: 1.25,
            ungraspable_grade: None,
        }
    }

    /// A closed counter-clockwise contour whose right side is `profile` (points (s, z) from
    /// bottom to top, s > 0) and whose left side mirrors it, so the same pattern is seen on both
    /// sides. Normals are not used by the curvature grading.
    fn contour(profile: &[(f64, f64)]) -> Contour {
        let mut pts: Vec<Point2<f64>> = profile.iter().map(|&(s, z)| Point2::new(s, z)).collect();
        pts.extend(
            profile
                .iter()
                .rev()
                .filter(|&&(s, _)| s != 0.0)
                .map(|&(s, z)| Point2::new(-s, z)),
        );
        let normals = vec![Vector2::x(); pts.len()];
        Contour {
            points: pts,
            normals,
            is_closed: true,
        }
    }

    /// Grades the right and left touch points at `z`; asserts they agree (mirror symmetry).
    fn grade_at(profile: &[(f64, f64)], z: f64) -> SideGrade {
        let c = contour(profile);
        let (l, r) = crate::plan::domain::outermost_crossings(std::slice::from_ref(&c), z)
            .expect("the line cuts the contour");
        let [lo, hi] = crate::plan::domain::z_range(std::slice::from_ref(&c));
        let zr = (lo, hi);
        let right = grade_side(&c, &r, SliceSide::Right, zr, &params());
        let left = grade_side(&c, &l, SliceSide::Left, zr, &params());
        assert_eq!(
            right.category, left.category,
            "mirror: {right:?} vs {left:?}"
        );
        match (right.grade, left.grade) {
            (Ok(a), Ok(b)) => assert!((a - b).abs() < 1e-12, "mirror grades {a} vs {b}"),
            (a, b) => assert_eq!(a.is_err(), b.is_err(), "mirror: {a:?} vs {b:?}"),
        }
        right
    }

    // Profiles span z = 0..100 with the feature near z = 50, far from both ends.
    const STRAIGHT: &[(f64, f64)] = &[(0.0, 0.0), (20.0, 0.0), (20.0, 100.0), (0.0, 100.0)];

    #[test]
    fn a_touch_on_a_vertex_grades_the_same_slope_a_micrometre_either_side() {
        // The right side leans out 10° below z = 50 and 30° above it (the friction cone is
        // 17°). A touch 1 µm below or above the vertex grades the same slope, the two
        // segments' mean (20°: ungraspable both ways), not 10° on one side and 30° on the
        // other; 0.05 mm away and beyond, each its own segment's.
        let (t10, t30) = (10f64.to_radians().tan(), 30f64.to_radians().tan());
        let p = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0 + 50.0 * t10, 50.0),
            (20.0 + 50.0 * t10 + 50.0 * t30, 100.0),
            (0.0, 100.0),
        ];
        let slope_at = |z: f64| grade_at(&p, z).slope_deg;
        let (below, above) = (slope_at(50.0 - 1e-6), slope_at(50.0 + 1e-6));
        assert!((below - above).abs() < 1e-3, "{below} against {above}");
        assert!((below.abs() - 20.0).abs() < 1e-3, "{below}");
        assert!(grade_at(&p, 50.0 - 1e-6).grade.is_err());
        assert!(grade_at(&p, 50.0 + 1e-6).grade.is_err());
        assert!((slope_at(49.9).abs() - 10.0).abs() < 1e-9);
        assert!(grade_at(&p, 49.9).grade.is_ok());
        assert!((slope_at(50.1).abs() - 30.0).abs() < 1e-9);
        // Halfway into the blend, three quarters its own: 15°, graspable.
        assert!(
            (slope_at(49.975).abs() - 15.0).abs() < 1e-6,
            "{}",
            slope_at(49.975)
        );
        assert!(grade_at(&p, 49.975).grade.is_ok());
    }

    #[test]
    fn straight_vertical_is_cat_1() {
        let g = grade_at(STRAIGHT, 50.0);
        assert_eq!(g.category, Category::Cat1);
        assert!((g.grade.unwrap() - 0.85).abs() < 1e-12);
    }

    #[test]
    fn a_concavity_is_cat_4() {
        // A groove with a flat bottom and 45° walls; the finger touches its bottom.
        let p = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, 44.0),
            (17.0, 47.0),
            (17.0, 53.0),
            (20.0, 56.0),
            (20.0, 100.0),
            (0.0, 100.0),
        ];
        let g = grade_at(&p, 50.0);
        assert_eq!(g.category, Category::Cat4, "{g:?}");
        assert!(
            (g.trend_above_deg - 45.0).abs() < 1e-9 && (g.trend_below_deg - 45.0).abs() < 1e-9,
            "{g:?}"
        );
    }

    #[test]
    fn under_a_ridge_is_cat_2_and_fades_with_distance() {
        // A ledge sticking out above z = 52.
        let p = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, 52.0),
            (30.0, 52.0),
            (30.0, 60.0),
            (0.0, 60.0),
        ];
        let near = grade_at(&p, 50.0);
        assert_eq!(near.category, Category::Cat2, "{near:?}");
        // 2 mm from the ledge: strength 1 − 0.3 × 2 / 10.5 of the way from Cat_1 to Cat_2.
        let expected = 0.85 + 0.10 * (1.0 - 0.3 * 2.0 / 10.5);
        assert!(
            (near.grade.unwrap() - expected).abs() < 1e-9,
            "{near:?}, expected {expected}"
        );
        let farther = grade_at(&p, 45.0);
        let far = grade_at(&p, 30.0);
        assert!(near.grade.unwrap() > farther.grade.unwrap());
        assert!(farther.grade.unwrap() > far.grade.unwrap());
        assert_eq!(far.category, Category::Cat1, "beyond reach: {far:?}");
    }

    #[test]
    fn a_ridge_above_and_thinning_below_is_cat_7() {
        let p = [
            (0.0, 0.0),
            (14.0, 0.0),
            (14.0, 47.0),
            (20.0, 48.0),
            (20.0, 52.0),
            (30.0, 52.0),
            (30.0, 60.0),
            (0.0, 60.0),
        ];
        let g = grade_at(&p, 50.0);
        assert_eq!(g.category, Category::Cat7, "{g:?}");
    }

    #[test]
    fn a_ridge_below_is_cat_3() {
        let p = [
            (0.0, 0.0),
            (30.0, 0.0),
            (30.0, 48.0),
            (20.0, 48.0),
            (20.0, 100.0),
            (0.0, 100.0),
        ];
        let g = grade_at(&p, 50.0);
        assert_eq!(g.category, Category::Cat3, "{g:?}");
        assert!(g.grade.unwrap() < Category::Cat5.grade());
    }

    #[test]
    fn thinning_above_is_cat_6() {
        let p = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, 52.0),
            (12.0, 53.0),
            (12.0, 100.0),
            (0.0, 100.0),
        ];
        let g = grade_at(&p, 50.0);
        assert_eq!(g.category, Category::Cat6, "{g:?}");
    }

    #[test]
    fn thinning_above_and_a_ridge_below_is_cat_9() {
        let p = [
            (0.0, 0.0),
            (30.0, 0.0),
            (30.0, 48.0),
            (20.0, 48.0),
            (20.0, 52.0),
            (12.0, 53.0),
            (12.0, 100.0),
            (0.0, 100.0),
        ];
        let g = grade_at(&p, 50.0);
        assert_eq!(g.category, Category::Cat9, "{g:?}");
    }

    #[test]
    fn a_protrusion_is_cat_8() {
        // A flat-topped bump with 45° flanks; the finger touches its crown.
        let p = [
            (0.0, 0.0),
            (14.0, 0.0),
            (14.0, 44.0),
            (17.0, 47.0),
            (17.0, 53.0),
            (14.0, 56.0),
            (14.0, 100.0),
            (0.0, 100.0),
        ];
        let g = grade_at(&p, 50.0);
        assert_eq!(g.category, Category::Cat8, "{g:?}");
        assert!(
            g.trend_above_deg < -40.0 && g.trend_below_deg < -40.0,
            "{g:?}"
        );
    }

    #[test]
    fn slopes_inside_the_deviation_range_are_vertical() {
        // 8° taper, inside ±12°.
        let t = 8f64.to_radians().tan() * 100.0;
        let p = [(0.0, 0.0), (20.0, 0.0), (20.0 + t, 100.0), (0.0, 100.0)];
        let g = grade_at(&p, 50.0);
        assert_eq!(g.category, Category::Cat1, "{g:?}");
        assert!((g.slope_deg - 8.0).abs() < 1e-9);
        assert!((g.grade.unwrap() - 0.85).abs() < 1e-12);
    }

    #[test]
    fn slopes_between_deviation_and_friction_cone_are_cat_5_with_demerit() {
        let grade = |deg: f64| {
            let t = deg.to_radians().tan() * 100.0;
            let p = [(0.0, 0.0), (20.0, 0.0), (20.0 + t, 100.0), (0.0, 100.0)];
            grade_at(&p, 50.0)
        };
        let g14 = grade(14.0);
        let g16 = grade(16.0);
        assert_eq!(g14.category, Category::Cat5);
        let (a, b) = (g14.grade.unwrap(), g16.grade.unwrap());
        assert!(a < 0.85 && b < a && b > Category::Cat3.grade(), "{a} {b}");
        // Inward-leaning slopes count by magnitude too (eq. 3.1 uses abs(ang)).
        let t = 14f64.to_radians().tan() * 100.0;
        let inward = grade_at(
            &[(0.0, 0.0), (20.0 + t, 0.0), (20.0, 100.0), (0.0, 100.0)],
            50.0,
        );
        assert!((inward.grade.unwrap() - a).abs() < 1e-9);
    }

    #[test]
    fn slopes_beyond_the_friction_cone_are_ungraspable() {
        let t = 20f64.to_radians().tan() * 100.0;
        let p = [(0.0, 0.0), (20.0, 0.0), (20.0 + t, 100.0), (0.0, 100.0)];
        let g = grade_at(&p, 50.0);
        assert!(
            matches!(g.grade, Err(Ungraspable::Slope(s)) if (s - 20.0).abs() < 1e-9),
            "{g:?}"
        );
    }

    #[test]
    fn a_steep_groove_wall_is_ungraspable_by_slope() {
        let p = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, 45.0),
            (16.0, 50.0),
            (20.0, 55.0),
            (20.0, 100.0),
            (0.0, 100.0),
        ];
        let g = grade_at(&p, 48.0);
        assert!(matches!(g.grade, Err(Ungraspable::Slope(_))), "{g:?}");
    }

    #[test]
    fn sharp_edges_and_steps_are_ungraspable() {
        let ledge = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, 52.0),
            (30.0, 52.0),
            (30.0, 60.0),
            (0.0, 60.0),
        ];
        // Half a millimetre below the ledge's corner.
        assert_eq!(grade_at(&ledge, 51.5).grade, Err(Ungraspable::SharpChange));
        // On the ledge's horizontal underside.
        assert_eq!(grade_at(&ledge, 52.0).grade, Err(Ungraspable::SharpChange));
    }

    #[test]
    fn nearness_to_the_ends_grades_as_cat_6_at_the_top_and_cat_3_at_the_bottom() {
        let top = grade_at(STRAIGHT, 93.0);
        assert_eq!(top.category, Category::Cat6, "{top:?}");
        let bottom = grade_at(STRAIGHT, 7.0);
        assert_eq!(bottom.category, Category::Cat3, "{bottom:?}");
        assert!(top.grade.unwrap() < 0.85 && bottom.grade.unwrap() < 0.85);
    }

    #[test]
    fn short_segments_are_skipped_and_do_not_change_a_straight_line() {
        let mut p = vec![(0.0, 0.0), (20.0, 0.0)];
        for k in 1..40 {
            let z = 40.0 + k as f64 * 0.5;
            p.push((20.0, z));
        }
        p.extend([(20.0, 100.0), (0.0, 100.0)]);
        let g = grade_at(&p, 50.2);
        assert_eq!(g.category, Category::Cat1, "{g:?}");
    }

    #[test]
    fn the_order_of_the_categories_is_the_thesis_order() {
        use Category::*;
        let order = [Cat4, Cat2, Cat7, Cat1, Cat5, Cat3, Cat6, Cat9, Cat8];
        for w in order.windows(2) {
            assert!(w[0].grade() > w[1].grade(), "{:?} !> {:?}", w[0], w[1]);
        }
    }
}
