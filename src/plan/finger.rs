//! Finger positioning with the Articulated Line Segment model (thesis 3.6).
//!
//! Each finger is three ALS (top, centre, bottom: its centreline and its two edges, a finger
//! offset either side), each placed on its own finger slice plane (3.6.2.1). In a plane, in the
//! palm's 2D frame of [`super::kinematics`] (palm surface x = 0 facing −x, joint 1 at
//! `(setback, ±lateral)`; a right-side finger is handled as a mirrored left one):
//!
//! 1. Gap Space: the palm must not take in the object in this plane (its outline, the palm
//!    width by the palm offset, is checked); the gap between the palm surface and the object is
//!    recorded.
//! 2. Phalanx 1 (3.6.2.2): search domain = contour vertices within reach of its contact surface
//!    (the disk swept by the surface's far end); for each, the joint-1 angle at which the contact
//!    line (a finger offset inside the centreline, between the unusable lengths) passes through
//!    it; the contact is the widest angle — the first point met while closing from open. The
//!    angle must lie in joint 1's range, and the phalanx body must not take in the object.
//! 3. Phalanx 2 (3.6.2.3): the same about joint 2, with contour segments cut at the domain's
//!    border so the end of the contact line can touch (tip contact, Fig. 3.22); beyond the
//!    contact line the fingertip is thinned (Fig. 3.8) and its outline is checked too.
//! 4. The three ALS of a finger must agree within the Joint Angular Deviation (Table 3.2).

use super::geom2::ConvexPolygon;
use super::kinematics::{inward_normal, phalanx1_direction};
use super::palm::{PalmPlacement, PENETRATION_TOL_MM};
use super::{Relaxation, RuleSet};
use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::slice::{Slice, SliceIndex, SliceOptions};
use nalgebra::{Point2, Rotation2, Vector2};
use std::f64::consts::PI;

/// A contact in a finger slice plane's 2D coordinates `[mm]`, with the unit direction in which
/// the phalanx pushes.
pub type PlaneContact = (Point2<f64>, Vector2<f64>);

/// The joint angles of one ALS `[deg]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlsAngles {
    /// Joint 1, interior, relative to the palm.
    pub theta1_deg: f64,
    /// Joint 2, interior, relative to phalanx 1.
    pub theta2_deg: f64,
    /// True if and only if phalanx 2 touches with the end of its contact line (tip contact).
    pub is_tip_contact: bool,
    /// Gap Space between the palm surface and the object in this plane `[mm]`.
    pub gap_mm: f64,
    /// Where phalanx 1 and phalanx 2 touch, in the finger slice plane's 2D coordinates
    /// `[mm]`, each with the unit direction in which the phalanx pushes (its contact surface's
    /// inward normal), phalanx 1 then phalanx 2; `None` for a phalanx that touches nothing: both
    /// for an ALS reported with its finger's angles because it met nothing, phalanx 1 for an ALS
    /// placed by [`place_als_distal`] (extended rules). Under the extended rules (but a pinch)
    /// these are the *finger's* contacts in this ALS's plane, at the finger's angles, not at the
    /// ALS's own: a phalanx touches in the planes whose first contact stopped it, and nowhere
    /// else.
    pub contacts: [Option<PlaneContact>; 2],
}

/// A positioned finger: its three ALS.
#[derive(Debug, Clone, PartialEq)]
pub struct FingerPlacement {
    /// Finger name.
    pub name: String,
    /// Top ALS.
    pub top: AlsAngles,
    /// Centre ALS (the finger's reported angles).
    pub centre: AlsAngles,
    /// Bottom ALS.
    pub bottom: AlsAngles,
    /// The thesis rules this finger's placement relaxed (extended rules only; else empty).
    pub relaxations: Vec<Relaxation>,
}

/// Why a finger could not be placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FingerRejection {
    /// The palm takes in the object in a finger plane.
    PalmPenetration,
    /// Phalanx 1 meets nothing while closing.
    Phalanx1NoContact,
    /// Phalanx 1's contact angle is out of joint 1's range.
    Theta1OutOfRange,
    /// Phalanx 1's body takes in the object.
    Phalanx1Penetration,
    /// Phalanx 2 meets nothing while closing.
    Phalanx2NoContact,
    /// Phalanx 2's contact angle is out of joint 2's range.
    Theta2OutOfRange,
    /// Phalanx 2's body or fingertip takes in the object.
    Phalanx2Penetration,
    /// The three ALS disagree by more than the Joint Angular Deviation.
    JointDeviation,
}

/// Positions finger `k` of `hand` on a placed palm: all three ALS and their agreement.
///
/// Under [`RuleSet::Pinch`], an ALS the thesis's placement rejects (but for the palm) closes
/// until phalanx 2 touches ([`place_als_distal`], [`Relaxation::DistalContactOnly`]; if that
/// fails too, the first rejection stands). Under either extended rule set, an ALS that meets
/// nothing is allowed while another touches
/// ([`Relaxation::AlsOffObject`]), and the finger stops where its first ALS touches: joint 1 at
/// the most open θ1 over the ALS that touch, joint 2 where phalanx 2 then first touches
/// ([`place_finger_extended`]), with a deviation beyond the Joint Angular Deviation recorded
/// ([`Relaxation::JointDeviationRecorded`]) instead of rejected. An ALS off the object
/// is reported with the finger's angles. Every other rejection (range, penetration) stands.
pub fn place_finger(
    mesh: &Mesh,
    index: &SliceIndex,
    hand: &Hand,
    palm: &PalmPlacement,
    k: usize,
    deviation_deg: [f64; 2],
    rules: RuleSet,
) -> Result<FingerPlacement, FingerRejection> {
    let f = &hand.finger_list[k];
    let o = hand.fingers.offset_mm;
    let mirror = f.side.sign();
    let slice = |dz: f64| {
        let plane = palm.finger_plane(f.height_mm + dz);
        let options = SliceOptions::indexed(index)
            .within(hand.relief_mm())
            .bridged(2.0 * o);
        crate::slice::slice(mesh, &plane, options)
    };
    // Each plane is built once (its segments copied, the palm's outline checked: a
    // `PalmPenetration`, which no rule set relaxes) and its ALS placed on it.
    let plane = |dz: f64| FingerPlane::new(&slice(dz), hand, mirror);
    let als = |plane: &FingerPlane| -> Result<AlsAngles, FingerRejection> {
        match als_on(plane, hand) {
            Err(e) if rules.pinches() => als_distal_on(plane, hand).map_err(|_| e),
            placed => placed,
        }
    };
    if rules.is_extended() {
        // Centre, top, bottom, each placed only while the others leave the finger possible
        // (a slice of a many-shell mesh is costly).
        let mut placed = Vec::with_capacity(3);
        let mut planes = Vec::with_capacity(3);
        for dz in [0.0, o, -o] {
            let p = plane(dz)?;
            let r = als(&p);
            if let Err(e) = r {
                if !is_off_object(e) {
                    return Err(e);
                }
            }
            placed.push(r);
            planes.push(p);
        }
        let [centre, top, bottom]: [_; 3] = placed.try_into().expect("three ALS");
        let planes: [_; 3] = planes.try_into().ok().expect("three planes");
        return place_finger_extended(
            f.name.clone(),
            [centre, top, bottom],
            &planes,
            hand,
            deviation_deg,
        );
    }
    let centre = als(&plane(0.0)?)?;
    let top = als(&plane(o)?)?;
    let bottom = als(&plane(-o)?)?;
    for other in [&top, &bottom] {
        if (other.theta1_deg - centre.theta1_deg).abs() > deviation_deg[0]
            || (other.theta2_deg - centre.theta2_deg).abs() > deviation_deg[1]
        {
            return Err(FingerRejection::JointDeviation);
        }
    }
    Ok(FingerPlacement {
        name: f.name.clone(),
        top,
        centre,
        bottom,
        relaxations: Vec::new(),
    })
}

/// True for the rejections that mean an ALS meets nothing: allowed under the extended rules
/// while another ALS of the finger touches.
fn is_off_object(r: FingerRejection) -> bool {
    matches!(
        r,
        FingerRejection::Phalanx1NoContact | FingerRejection::Phalanx2NoContact
    )
}

/// The extended rules' finger (see [`place_finger`]); `als` is centre, top, bottom, and
/// `planes` their finger slice planes.
///
/// Joint 1 stops where the first ALS's phalanx 1 touches (the most open θ1). Phalanx 2 then
/// closes about joint 2 with phalanx 1 *there*, so its θ2 is the first contact of phalanx 2,
/// with phalanx 1 at the finger's θ1, in the planes of the ALS that touch (each ALS's own θ2
/// was found with its own θ1: taking the most open of those put the Adroit ball's phalanx 2
/// 1.7 mm clear of the ball, 7° short of where it touches). The plane of an ALS that meets
/// nothing is left out, as it is from θ1: the finger's edge is off the object there, and
/// phalanx 2 would meet at most the edge of a face the curvature rules did not grade (a
/// tapered box's, which its grasp then drops). A pinch keeps the most open θ2 of its ALS.
///
/// The finger's contacts are where it stops: phalanx 1 in the plane(s) of the ALS whose
/// θ1 it took, phalanx 2 in the plane(s) where it first touched; each ALS carries those in its
/// plane (a pinch keeps each ALS's own).
fn place_finger_extended(
    name: String,
    als: [Result<AlsAngles, FingerRejection>; 3],
    planes: &[FingerPlane; 3],
    hand: &Hand,
    deviation_deg: [f64; 2],
) -> Result<FingerPlacement, FingerRejection> {
    let mut relaxations = Vec::new();
    for r in &als {
        match r {
            Err(e) if !is_off_object(*e) => return Err(*e),
            Err(_) => relaxations.push(Relaxation::AlsOffObject),
            Ok(_) => {}
        }
    }
    let touching: Vec<&AlsAngles> = als.iter().filter_map(|r| r.as_ref().ok()).collect();
    if touching.iter().any(|a| a.contacts[0].is_none()) {
        relaxations.push(Relaxation::DistalContactOnly);
    }
    let first = touching
        .iter()
        .copied()
        .max_by(|a, b| a.theta1_deg.total_cmp(&b.theta1_deg))
        .ok_or_else(|| *als[0].as_ref().expect_err("no ALS touched"))?;
    // Each ALS's own contacts (a pinch's), or the finger's where it stops (below).
    let mut contacts = als
        .each_ref()
        .map(|a| a.as_ref().map_or([None, None], |a| a.contacts));
    let (theta2, is_tip_contact) = if relaxations.contains(&Relaxation::DistalContactOnly) {
        // A pinch's θ1 is where joint 1's search first let phalanx 2 reach the object in
        // one plane, not a contact; its phalanx 2 keeps the most open of the ALS's own.
        let theta2 = touching
            .iter()
            .map(|a| a.theta2_deg)
            .fold(f64::NEG_INFINITY, f64::max);
        (theta2, first.is_tip_contact)
    } else {
        phalanx2_stop(&als, planes, hand, first.theta1_deg, &mut contacts)?
    };
    let finger = AlsAngles {
        theta2_deg: theta2,
        is_tip_contact,
        contacts: contacts[0],
        ..*first
    };
    if touching.iter().any(|a| {
        (a.theta1_deg - finger.theta1_deg).abs() > deviation_deg[0]
            || (a.theta2_deg - finger.theta2_deg).abs() > deviation_deg[1]
    }) {
        relaxations.push(Relaxation::JointDeviationRecorded);
    }
    relaxations.sort();
    relaxations.dedup();
    let pick = |k: usize| match &als[k] {
        Ok(a) => AlsAngles {
            contacts: contacts[k],
            ..*a
        },
        Err(_) => AlsAngles {
            contacts: [None, None],
            ..finger
        },
    };
    Ok(FingerPlacement {
        name,
        top: pick(1),
        centre: finger,
        bottom: pick(2),
        relaxations,
    })
}

/// Where phalanx 2 stops with phalanx 1 at `theta1_deg` (the finger's, set by the ALS that
/// closed joint 1 the furthest), in the planes of the ALS that touch: `(θ2, is_tip_contact)`.
/// `contacts` (each ALS's own, on entry) become the finger's at its own angles: phalanx 1 in
/// the planes whose ALS set θ1 (the others' phalanx 1 would touch only further closed),
/// phalanx 2 where it stops.
fn phalanx2_stop(
    als: &[Result<AlsAngles, FingerRejection>; 3],
    planes: &[FingerPlane; 3],
    hand: &Hand,
    theta1_deg: f64,
    contacts: &mut [[Option<PlaneContact>; 2]; 3],
) -> Result<(f64, bool), FingerRejection> {
    let touched: Vec<(usize, &FingerPlane)> = planes
        .iter()
        .enumerate()
        .zip(als)
        .filter(|(_, a)| a.is_ok())
        .map(|(p, _)| p)
        .collect();
    let p2 = phalanx2_at(&touched, hand, theta1_deg)?;
    for (c, a) in contacts.iter_mut().zip(als) {
        let sets_theta1 = a
            .as_ref()
            .is_ok_and(|a| theta1_deg - a.theta1_deg <= SAME_THETA1_DEG);
        *c = [if sets_theta1 { c[0] } else { None }, None];
    }
    for (k, c) in p2.contacts {
        contacts[k][1] = Some(c);
    }
    Ok((p2.theta2_deg, p2.is_tip_contact))
}

/// One finger slice plane, ready for the phalanges: the contour's segments in the palm's 2D
/// frame (mirrored for a right finger) and the Gap Space.
struct FingerPlane {
    segments: Vec<(Point2<f64>, Point2<f64>)>,
    gap_mm: f64,
    mirror: f64,
}

impl FingerPlane {
    /// The plane's segments, with the palm's outline checked (step 1).
    fn new(s: &Slice, hand: &Hand, mirror: f64) -> Result<FingerPlane, FingerRejection> {
        let segments: Vec<(Point2<f64>, Point2<f64>)> = s
            .contours
            .iter()
            .flat_map(|c| {
                (0..c.segment_count()).map(move |i| {
                    let (a, b) = c.segment(i);
                    (
                        Point2::new(a.x, mirror * a.y),
                        Point2::new(b.x, mirror * b.y),
                    )
                })
            })
            .collect();
        let hw = hand.palm.half_width_mm;
        let palm = ConvexPolygon::new(vec![
            Point2::new(0.0, -hw),
            Point2::new(hand.palm.offset_mm, -hw),
            Point2::new(hand.palm.offset_mm, hw),
            Point2::new(0.0, hw),
        ]);
        let plane = FingerPlane {
            gap_mm: -segments
                .iter()
                .map(|(a, _)| *a)
                .filter(|p| p.y.abs() <= hw)
                .map(|p| p.x)
                .fold(f64::NEG_INFINITY, f64::max),
            segments,
            mirror,
        };
        if plane.hits(&palm) {
            return Err(FingerRejection::PalmPenetration);
        }
        Ok(plane)
    }

    /// True if the object takes in part of `poly`.
    fn hits(&self, poly: &ConvexPolygon) -> bool {
        // A segment that misses the outline's bounding box cannot reach inside it: the same
        // answer as testing every segment, at a compare or two for most of them.
        let (lo, hi) = poly.corners.iter().fold(
            (
                Point2::new(f64::INFINITY, f64::INFINITY),
                Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        self.segments.iter().any(|(a, b)| {
            a.x.max(b.x) >= lo.x
                && a.x.min(b.x) <= hi.x
                && a.y.max(b.y) >= lo.y
                && a.y.min(b.y) <= hi.y
                && poly.is_penetrated_by(*a, *b, PENETRATION_TOL_MM)
        })
    }

    /// Phalanx 2's search domain about joint 2 at `j2`: the contour's vertices within `reach`
    /// and the points where its segments cross the circle of that radius, so the end of the
    /// contact line can touch a segment (tip contact, Fig. 3.22).
    fn phalanx2_domain(&self, j2: Point2<f64>, reach: f64) -> Vec<Point2<f64>> {
        let mut domain = Vec::new();
        for (a, b) in &self.segments {
            if (a - j2).norm() <= reach {
                domain.push(*a);
            }
            domain.extend(circle_crossings(*a, *b, j2, reach));
        }
        domain
    }

    /// A contact on a contact line in the palm's frame, mirrored back to the plane's.
    fn unmirror(&self, p: Point2<f64>, n: Vector2<f64>) -> (Point2<f64>, Vector2<f64>) {
        (
            Point2::new(p.x, self.mirror * p.y),
            Vector2::new(n.x, self.mirror * n.y),
        )
    }
}

/// Phalanx 2 closing about joint 2 at `j2`, phalanx 1 pointing along `d1` (step 3): its
/// contact's θ2 `[deg]`, the contact point and its inward normal, and whether it is a tip
/// contact.
fn place_phalanx2(
    plane: &FingerPlane,
    hand: &Hand,
    j2: Point2<f64>,
    d1: Vector2<f64>,
) -> Result<(f64, Point2<f64>, Vector2<f64>, bool), FingerRejection> {
    let o = hand.fingers.offset_mm;
    let p2 = &hand.phalanx_2;
    let usable2 = (
        p2.unusable_proximal_mm,
        p2.length_mm - p2.unusable_distal_mm,
    );
    let domain2 = plane.phalanx2_domain(j2, usable2.1.hypot(o));
    let (bend2, along2) =
        first_contact(&domain2, j2, d1, usable2, o).ok_or(FingerRejection::Phalanx2NoContact)?;
    let theta2 = 180.0 - bend2.to_degrees();
    let [lo2, hi2] = hand.joints.theta2_range_deg;
    if !(lo2..=hi2).contains(&theta2) {
        return Err(FingerRejection::Theta2OutOfRange);
    }
    let e = Rotation2::new(bend2) * d1;
    let n_e = inward_normal(&e);
    let (body2, tip) = phalanx2_outline(hand, j2, e);
    if plane.hits(&body2) || tip.as_ref().is_some_and(|t| plane.hits(t)) {
        return Err(FingerRejection::Phalanx2Penetration);
    }
    let is_tip_contact = along2 >= usable2.1 - 1e-6;
    Ok((theta2, j2 + e * along2 + n_e * o, n_e, is_tip_contact))
}

/// Phalanx 2's outline pivoting at `j2` along `e`: its body up to the end of the contact line
/// and, if the phalanx reaches beyond it, the thinned tip (Fig. 3.8) from there to the tip's
/// front corner.
fn phalanx2_outline(
    hand: &Hand,
    j2: Point2<f64>,
    e: Vector2<f64>,
) -> (ConvexPolygon, Option<ConvexPolygon>) {
    let o = hand.fingers.offset_mm;
    let p2 = &hand.phalanx_2;
    let usable_end = p2.length_mm - p2.unusable_distal_mm;
    let n_e = inward_normal(&e);
    let body2 = ConvexPolygon::strip(j2, e, usable_end, -o, o);
    let tip_front = hand.fingers.tip_thickness_mm - o;
    let tip = (p2.length_mm > usable_end).then(|| {
        ConvexPolygon::new(vec![
            j2 + e * usable_end - n_e * o,
            j2 + e * p2.length_mm - n_e * o,
            j2 + e * p2.length_mm + n_e * tip_front,
            j2 + e * usable_end + n_e * o,
        ])
    });
    (body2, tip)
}

/// Where phalanx 2 of an extended-rule finger touches: its θ2 `[deg]`, whether it is a tip
/// contact, and its contacts: in every plane it meets at that θ2 (each plane's index among
/// the finger's, the contact in its coordinates with the phalanx's inward normal).
struct Phalanx2Contact {
    theta2_deg: f64,
    is_tip_contact: bool,
    contacts: Vec<(usize, PlaneContact)>,
}

/// An ALS whose θ1 is this close to its finger's `[deg]` touches with phalanx 1 where the
/// finger stops.
const SAME_THETA1_DEG: f64 = 1e-9;

/// Two first contacts this close in bend `[rad]` are the same contact in two planes (the
/// planes of a prism cut the same contour).
const SAME_BEND_RAD: f64 = 1e-9;

/// Phalanx 2 of a finger whose joint 1 stands at `theta1_deg`, closing about joint 2 until it
/// first touches the object in any of `planes` (each with its index among the finger's). The
/// contact must lie in joint 2's range, and phalanx 2's body and tip must be clear of every
/// plane at that θ2.
fn phalanx2_at(
    planes: &[(usize, &FingerPlane)],
    hand: &Hand,
    theta1_deg: f64,
) -> Result<Phalanx2Contact, FingerRejection> {
    let o = hand.fingers.offset_mm;
    let j1 = Point2::new(hand.joints.setback_mm, hand.joints.lateral_mm);
    let d1 = phalanx1_direction(theta1_deg.to_radians());
    let j2 = j1 + d1 * hand.phalanx_1.length_mm;
    let p2 = &hand.phalanx_2;
    let usable2 = (
        p2.unusable_proximal_mm,
        p2.length_mm - p2.unusable_distal_mm,
    );
    let firsts: Vec<_> = planes
        .iter()
        .filter_map(|&(k, p)| {
            first_contact(
                &p.phalanx2_domain(j2, usable2.1.hypot(o)),
                j2,
                d1,
                usable2,
                o,
            )
            .map(|c| (c, (k, p)))
        })
        .collect();
    let (bend2, along2) = firsts
        .iter()
        .map(|(c, _)| *c)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or(FingerRejection::Phalanx2NoContact)?;
    let theta2 = 180.0 - bend2.to_degrees();
    let [lo2, hi2] = hand.joints.theta2_range_deg;
    if !(lo2..=hi2).contains(&theta2) {
        return Err(FingerRejection::Theta2OutOfRange);
    }
    let e = Rotation2::new(bend2) * d1;
    let (body2, tip) = phalanx2_outline(hand, j2, e);
    if planes
        .iter()
        .any(|(_, p)| p.hits(&body2) || tip.as_ref().is_some_and(|t| p.hits(t)))
    {
        return Err(FingerRejection::Phalanx2Penetration);
    }
    let n_e = inward_normal(&e);
    Ok(Phalanx2Contact {
        theta2_deg: theta2,
        is_tip_contact: along2 >= usable2.1 - 1e-6,
        contacts: firsts
            .iter()
            .filter(|((b, _), _)| b - bend2 <= SAME_BEND_RAD)
            .map(|&((_, along), (k, p))| (k, p.unmirror(j2 + e * along + n_e * o, n_e)))
            .collect(),
    })
}

/// Places one ALS on its finger slice plane. `mirror` is +1 for a left finger (joint at +y) and
/// −1 for a right one (the contour is mirrored so the finger is handled as a left one).
pub fn place_als(s: &Slice, hand: &Hand, mirror: f64) -> Result<AlsAngles, FingerRejection> {
    als_on(&FingerPlane::new(s, hand, mirror)?, hand)
}

/// [`place_als`] on a finger plane already built.
fn als_on(plane: &FingerPlane, hand: &Hand) -> Result<AlsAngles, FingerRejection> {
    let o = hand.fingers.offset_mm;

    // Phalanx 1.
    let p1 = &hand.phalanx_1;
    let j1 = Point2::new(hand.joints.setback_mm, hand.joints.lateral_mm);
    let usable1 = (
        p1.unusable_proximal_mm,
        p1.length_mm - p1.unusable_distal_mm,
    );
    let reach1 = usable1.1.hypot(o);
    let straight1 = phalanx1_direction(PI);
    let domain1: Vec<Point2<f64>> = plane
        .segments
        .iter()
        .map(|(a, _)| *a)
        .filter(|p| (p - j1).norm() <= reach1)
        .collect();
    let (bend1, along1) = first_contact(&domain1, j1, straight1, usable1, o)
        .ok_or(FingerRejection::Phalanx1NoContact)?;
    let theta1 = 180.0 - bend1.to_degrees();
    let [lo1, hi1] = hand.joints.theta1_range_deg;
    if !(lo1..=hi1).contains(&theta1) {
        return Err(FingerRejection::Theta1OutOfRange);
    }
    let d1 = Rotation2::new(bend1) * straight1;
    if plane.hits(&ConvexPolygon::strip(j1, d1, p1.length_mm, -o, o)) {
        return Err(FingerRejection::Phalanx1Penetration);
    }

    // Phalanx 2, with segments cut at its domain's border.
    let (theta2, c2, n2, is_tip_contact) = place_phalanx2(plane, hand, j1 + d1 * p1.length_mm, d1)?;
    // The contacts on the contact lines, a finger offset inside the centrelines, mirrored back.
    let n_d1 = inward_normal(&d1);
    Ok(AlsAngles {
        theta1_deg: theta1,
        theta2_deg: theta2,
        is_tip_contact,
        gap_mm: plane.gap_mm,
        contacts: [
            Some(plane.unmirror(j1 + d1 * along1 + n_d1 * o, n_d1)),
            Some(plane.unmirror(c2, n2)),
        ],
    })
}

/// Joint 1's step while a finger whose phalanx 1 meets nothing closes `[deg]`.
const DISTAL_STEP_DEG: f64 = 0.25;

/// An ALS whose phalanx 1 meets nothing (the extended rules' [`Relaxation::DistalContactOnly`]):
/// joint 1 closes from its most open angle in `DISTAL_STEP_DEG` steps and, at each, phalanx 2
/// closes from straight; the ALS stops at the first joint-1 angle at which phalanx 2 meets the
/// object within joint 2's range (a contact beyond the range is passed over, closing on). Phalanx
/// 1's body meeting the object first, or phalanx 2's body or tip inside it at its contact, is a
/// rejection. This is a thin object pinched by the fingertips with the palm on its narrow face (a
/// book held by its spine): phalanx 1 reaches past it and only phalanx 2 can come back to it.
pub fn place_als_distal(s: &Slice, hand: &Hand, mirror: f64) -> Result<AlsAngles, FingerRejection> {
    als_distal_on(&FingerPlane::new(s, hand, mirror)?, hand)
}

/// [`place_als_distal`] on a finger plane already built.
fn als_distal_on(plane: &FingerPlane, hand: &Hand) -> Result<AlsAngles, FingerRejection> {
    let o = hand.fingers.offset_mm;
    let p1 = &hand.phalanx_1;
    let j1 = Point2::new(hand.joints.setback_mm, hand.joints.lateral_mm);
    let [lo1, hi1] = hand.joints.theta1_range_deg;
    let steps = ((hi1 - lo1) / DISTAL_STEP_DEG).floor() as usize;
    let mut last = FingerRejection::Phalanx2NoContact;
    for k in 0..=steps {
        let theta1 = hi1 - k as f64 * DISTAL_STEP_DEG;
        let d1 = phalanx1_direction(theta1.to_radians());
        if plane.hits(&ConvexPolygon::strip(j1, d1, p1.length_mm, -o, o)) {
            return Err(FingerRejection::Phalanx1Penetration);
        }
        match place_phalanx2(plane, hand, j1 + d1 * p1.length_mm, d1) {
            Ok((theta2, c2, n2, is_tip_contact)) => {
                return Ok(AlsAngles {
                    theta1_deg: theta1,
                    theta2_deg: theta2,
                    is_tip_contact,
                    gap_mm: plane.gap_mm,
                    contacts: [None, Some(plane.unmirror(c2, n2))],
                })
            }
            Err(FingerRejection::Theta2OutOfRange) => {
                last = FingerRejection::Theta2OutOfRange;
            }
            Err(FingerRejection::Phalanx2NoContact) => {}
            Err(e) => return Err(e),
        }
    }
    Err(last)
}

/// The smallest bend from `straight` (radians, counter-clockwise, in [0, π]) at which the
/// contact line of a link pivoting at `pivot` (offset `o` to the inside, between `usable.0` and
/// `usable.1` along the link) passes through one of `points`, with the contact's position along
/// the link. `None` when none is met.
fn first_contact(
    points: &[Point2<f64>],
    pivot: Point2<f64>,
    straight: Vector2<f64>,
    usable: (f64, f64),
    o: f64,
) -> Option<(f64, f64)> {
    let n0 = inward_normal(&straight);
    let mut best: Option<(f64, f64)> = None;
    for p in points {
        let q = p - pivot;
        let (qd, qn) = (q.dot(&straight), q.dot(&n0));
        let r = q.norm();
        if r < o {
            continue;
        }
        // q·n(φ) = −qd sin φ + qn cos φ = r cos(φ + γ), with r cos γ = qn, r sin γ = qd.
        let gamma = qd.atan2(qn);
        let delta = (o / r).clamp(-1.0, 1.0).acos();
        for root in [-gamma + delta, -gamma - delta] {
            let phi = root.rem_euclid(2.0 * PI);
            if phi > PI + 1e-12 {
                continue;
            }
            // Position along the link: q·e(φ).
            let t = qd * phi.cos() + qn * phi.sin();
            if t >= usable.0 - 1e-9 && t <= usable.1 + 1e-9 && best.is_none_or(|b| phi < b.0) {
                best = Some((phi, t));
            }
        }
    }
    best
}

/// Points where segment a–b crosses the circle of radius r about c.
fn circle_crossings(a: Point2<f64>, b: Point2<f64>, c: Point2<f64>, r: f64) -> Vec<Point2<f64>> {
    let d = b - a;
    let f = a - c;
    let (qa, qb, qc) = (d.dot(&d), 2.0 * f.dot(&d), f.dot(&f) - r * r);
    let disc = qb * qb - 4.0 * qa * qc;
    if qa == 0.0 || disc < 0.0 {
        return Vec::new();
    }
    let s = disc.sqrt();
    [(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)]
        .into_iter()
        .filter(|t| (0.0..=1.0).contains(t))
        .map(|t| a + d * t)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::palm::place_palm;

    use crate::hand::thesis_for_tests as thesis_hand;

    #[test]
    fn fingers_wrap_the_d40_cylinder_at_the_thesis_angles() {
        // Thesis 5.2: θ1 72.2°, θ2 90° on the D40 cylinder, within the 3° a scenario's `[expect]`
        // allows by default. This mesh (144 facets) gives 72.11° and 91.81°, phalanx 2 touching
        // with its tip; every finger and each of its three ALS alike (the wall is straight).
        let hand = thesis_hand();
        let mesh = crate::objects::cylinder(40.0, 124.0);
        let palm = place_palm(&mesh, &hand, 80.0, 0.0, 0.2).unwrap();
        for k in 0..hand.finger_list.len() {
            let f = place_finger(
                &mesh,
                &SliceIndex::new(&mesh),
                &hand,
                &palm,
                k,
                [5.0, 5.0],
                RuleSet::Thesis,
            )
            .unwrap();
            assert_eq!(f.name, hand.finger_list[k].name);
            assert!(f.relaxations.is_empty());
            for als in [f.top, f.centre, f.bottom] {
                let (t1, t2) = (als.theta1_deg, als.theta2_deg);
                assert!(
                    (t1 - 72.2).abs() < 3.0 && (t2 - 90.0).abs() < 3.0,
                    "finger {k}: ({t1:.3}, {t2:.3}), thesis (72.2, 90)"
                );
                assert!(
                    (t1 - 72.11).abs() < 0.01 && (t2 - 91.81).abs() < 0.01,
                    "finger {k}: ({t1:.3}, {t2:.3}), expected (72.11, 91.81)"
                );
                assert!(als.is_tip_contact, "finger {k}");
                assert_eq!(als.gap_mm, 0.0, "finger {k}");
            }
        }
    }

    #[test]
    fn a_thin_box_is_pinched_by_phalanx_2_where_its_reach_first_meets_the_face() {
        // The palm on the 30 mm face of a 100 x 30 mm box (x in [-100, 0], |y| <= 15 in the palm's
        // frame). The thesis's phalanx 1 meets a vertex of the broad face first, with its body
        // already through the box's corner: rejected. Closing joint 1 from 135°, joint 2 sits at y
        // = 36.7 - 61 cos θ1, and the end of phalanx 2's contact line reaches hypot(20, 7) = 21.19
        // mm from it: the face y = 15 comes within reach at cos θ1 = (36.7 - 15 - 21.19) / 61, θ1 =
        // 89.52°, so the first 0.25° step there is 89.5°: joint 2 at (−55.20, 36.17), and the end
        // of phalanx 2's contact line meets the face 0.96 mm further out, at x = −56.16, with
        // phalanx 2 bent 67.6° from phalanx 1 (θ2 = 112.4°).
        let hand = thesis_hand();
        let prism = crate::objects::prism(100.0, 30.0, 124.0);
        let s = crate::slice::slice(
            &prism,
            &crate::slice::Plane {
                origin: nalgebra::Point3::new(50.0, 0.0, 62.0),
                u: nalgebra::Vector3::x(),
                v: nalgebra::Vector3::y(),
            },
            crate::slice::SliceOptions::default(),
        );
        assert_eq!(
            place_als(&s, &hand, 1.0),
            Err(FingerRejection::Phalanx1Penetration)
        );
        for mirror in [1.0, -1.0] {
            let a = place_als_distal(&s, &hand, mirror).unwrap();
            assert_eq!(a.theta1_deg, 89.5);
            assert!((a.theta2_deg - 112.4).abs() < 0.05, "{a:?}");
            assert!(a.is_tip_contact);
            assert!(a.contacts[0].is_none());
            let (p, n) = a.contacts[1].unwrap();
            assert!((p.y - mirror * 15.0).abs() < 1e-9, "{p:?}");
            assert!((p.x + 56.16).abs() < 0.01, "{p:?}");
            // The push is phalanx 2's inward normal (the planner's convention for a contact):
            // partly towards the other face.
            assert!(n.y * mirror < -0.3, "{n:?}");
        }
    }

    #[test]
    fn a_finger_rejects_what_it_cannot_wrap() {
        // A D10 rod is thinner than the smallest graspable diameter (17.4 mm): phalanx 1 would
        // have to close beyond joint 1's 45° to reach it.
        let hand = thesis_hand();
        let rod = crate::objects::cylinder(10.0, 124.0);
        let palm = place_palm(&rod, &hand, 80.0, 0.0, 0.2).unwrap();
        let r = place_finger(
            &rod,
            &SliceIndex::new(&rod),
            &hand,
            &palm,
            0,
            [5.0, 5.0],
            RuleSet::Thesis,
        );
        assert_eq!(r, Err(FingerRejection::Theta1OutOfRange));
    }
    #[test]
    fn phalanx_2_closes_from_where_joint_1_stopped() {
        // A 70 mm ball, the palm with finger_1 20 mm above its equator (the Adroit ball's grasp).
        // Finger_1's bottom ALS (7 mm lower, a larger circle) meets the ball first, with phalanx
        // 1 at θ1 90.02° and phalanx 2 at θ2 122.29°; the centre ALS at 82.39° and 126.22°, the
        // top ALS (a smaller circle) only at 69.34° and 127.34°. Joint 1 stops at the first
        // touch, 90.02°; with phalanx 1 there, phalanx 2 meets the bottom plane's circle first,
        // at 122.29°. The most open θ2 of the three, the top ALS's 127.34°, would leave phalanx
        // 2 off the ball: 1.7 mm clear on the Adroit ball, which the check closed 3° past
        // without touching.
        let hand = thesis_hand();
        let r: f64 = 35.0;
        let profile: Vec<(f64, f64)> = (0..=72)
            .map(|k| {
                let z = -r + 2.0 * r * f64::from(k) / 72.0;
                (z + r, 2.0 * (r * r - z * z).max(0.0).sqrt())
            })
            .collect();
        let ball = crate::objects::revolved(&profile);
        let palm = place_palm(&ball, &hand, 60.0, 0.0, 0.2).unwrap();
        let f = place_finger(
            &ball,
            &SliceIndex::new(&ball),
            &hand,
            &palm,
            0,
            [5.0, 5.0],
            RuleSet::Extended,
        )
        .unwrap();
        let (top, centre, bottom) = (f.top, f.centre, f.bottom);
        assert!((top.theta1_deg - 69.34).abs() < 0.01, "{top:?}");
        assert!((top.theta2_deg - 127.34).abs() < 0.01, "{top:?}");
        assert!((bottom.theta1_deg - 90.02).abs() < 0.01, "{bottom:?}");
        assert!((bottom.theta2_deg - 122.29).abs() < 0.01, "{bottom:?}");
        // The finger's angles (reported as its centre ALS's).
        assert_eq!(
            (centre.theta1_deg, centre.theta2_deg),
            (bottom.theta1_deg, bottom.theta2_deg)
        );
        assert!(f.relaxations.contains(&Relaxation::JointDeviationRecorded));

        // The finger's contacts are where it stops: phalanx 1 and phalanx 2 both in the bottom
        // plane, on the ball. The top and centre ALS's own contacts, at their own angles, are
        // not the finger's (they were among the planned contacts `--quality` used).
        assert_eq!(top.contacts, [None, None]);
        assert_eq!(centre.contacts, [None, None]);
        let o = hand.fingers.offset_mm;
        let plane = palm.finger_plane(hand.finger_list[0].height_mm - o);
        for (p, n) in bottom
            .contacts
            .map(|c| c.expect("a contact in the bottom plane"))
        {
            let q = plane.to_3d(&p) - nalgebra::Point3::new(0.0, 0.0, r);
            // On the ball (its 72-step profile revolved: within 0.3 mm), pushing inwards: towards
            // the centre of the ball's circle in the plane.
            assert!(
                (q.norm() - r).abs() < 0.3,
                "{} mm from the centre",
                q.norm()
            );
            let in_plane = nalgebra::Vector2::new(q.dot(&plane.u), q.dot(&plane.v));
            assert!(
                n.dot(&in_plane) < -0.99 * in_plane.norm(),
                "{n:?} at {in_plane:?}"
            );
        }
    }
}
