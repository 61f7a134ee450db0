//! The thesis's figures for any object (SVG strings): Fig. 4.3 (effective elevation), 4.4–4.7
//! (grades), 4.8–4.10 (palm domain, contact line, outline), 4.11 (finger slice planes) and
//! 4.12–4.16 (a finger's slice with palm, joints, phalanx search domains and the placed ALS).

use super::svg::Plot;
use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::plan::kinematics::{inward_normal, phalanx1_direction};
use crate::plan::search::Grasp;
use crate::plan::GradedDomain;
use crate::slice::{slice, Slice, SliceOptions};
use nalgebra::{Point2, Rotation2, Vector2};

const OBJECT: &str = "#333";
const PALM: &str = "#1f77b4";
const FINGER: &str = "#d62728";
const DOMAIN: &str = "#2ca02c";
const BAND: &str = "#ff7f0e";

fn bounds(s: &Slice) -> ((f64, f64), (f64, f64)) {
    let mut x = (f64::INFINITY, f64::NEG_INFINITY);
    let mut y = (f64::INFINITY, f64::NEG_INFINITY);
    for c in &s.contours {
        for p in &c.points {
            x = (x.0.min(p.x), x.1.max(p.x));
            y = (y.0.min(p.y), y.1.max(p.y));
        }
    }
    (x, y)
}

fn pad(r: (f64, f64), by: f64) -> (f64, f64) {
    (r.0 - by, r.1 + by)
}

fn draw_slice(p: &mut Plot, s: &Slice, mirror: f64) {
    for c in &s.contours {
        let pts: Vec<(f64, f64)> = c.points.iter().map(|q| (q.x, mirror * q.y)).collect();
        p.polyline(&pts, OBJECT, 1.5, c.is_closed, "object");
    }
}

/// A plot of a vertical slice with equal scales and room around it, the slice drawn.
fn slice_plot(title: &str, s: &Slice, extra_right: f64) -> (Plot, (f64, f64)) {
    let (x, y) = bounds(s);
    let mut p = Plot::new(
        title,
        "s [mm]",
        "Z [mm]",
        pad((x.0, x.1 + extra_right), 20.0),
        pad(y, 10.0),
        true,
    );
    draw_slice(&mut p, s, 1.0);
    (p, x)
}

/// Fig. 4.3: the vertical slice at approach angle 0 with the Effective Elevation and the
/// Indexed Elevations.
pub fn effective_elevation(g: &GradedDomain) -> String {
    let (mut p, x) = slice_plot(
        "Effective Elevation over the vertical slice at 0 deg (Fig. 4.3)",
        &g.domain.slices[0],
        0.0,
    );
    let [lo, hi] = g.domain.effective;
    let right = x.1 + 12.0;
    p.line(
        (right, lo),
        (right, hi),
        BAND,
        4.0,
        false,
        "effective-elevation",
    );
    for z in [lo, hi] {
        p.line(
            (x.0, z),
            (x.1, z),
            BAND,
            1.0,
            true,
            "effective-elevation-limit",
        );
    }
    for z in &g.domain.elevations {
        p.line(
            (right - 3.0, *z),
            (right + 3.0, *z),
            BAND,
            1.0,
            false,
            "indexed-elevation",
        );
    }
    p.legend("object (vertical slice)", OBJECT);
    p.legend(&format!("effective elevation {lo:.1}-{hi:.1} mm"), BAND);
    p.finish()
}

/// Figs. 4.4–4.7: one grade vector as horizontal bars against elevation; ungraspable
/// elevations as short red bars to the left of zero.
pub fn grades(g: &GradedDomain, which: &str) -> String {
    let v = match which {
        "curvature" => &g.grades.curvature,
        "diameter" => &g.grades.diameter,
        "combined" => &g.grades.combined,
        _ => &g.grades.palm,
    };
    let e = &g.domain.elevations;
    let (lo, hi) = (
        e.first().copied().unwrap_or(0.0) - 2.5,
        e.last().copied().unwrap_or(1.0) + 2.5,
    );
    let title = match which {
        "curvature" => "Curvature grades (Fig. 4.4)",
        "diameter" => "Effective Diameter grades (Fig. 4.5)",
        "combined" => "Grades with significance factors (Fig. 4.6)",
        _ => "Palm grades after the third stage (Fig. 4.7)",
    };
    let mut p = Plot::new(title, "grade", "Z [mm]", (-0.15, 1.1), (lo, hi), false);
    let step = g.domain.height_step_mm;
    for (z, grade) in e.iter().zip(v) {
        match grade {
            Some(x) => p.hbar(*z, *x, step * 0.7, PALM, "grade"),
            None => p.hbar(*z, -0.1, step * 0.7, FINGER, "ungraspable"),
        }
    }
    p.legend("grade", PALM);
    p.legend("ungraspable", FINGER);
    p.finish()
}

/// Figs. 4.8–4.10: the vertical slice at the approach angle with the palm domain, the contact
/// points and the palm outline.
pub fn palm(g: &Grasp, hand: &Hand) -> String {
    let (mut p, _) = slice_plot(
        &format!(
            "Palm on the vertical slice at {:.0} deg: contacts and outline (Figs. 4.8-4.10)",
            g.approach_angle_deg
        ),
        &g.palm.slice,
        hand.palm.offset_mm,
    );
    let pitch = g.palm.pitch_rad;
    let up = Vector2::new(-pitch.sin(), pitch.cos());
    let back = Vector2::new(pitch.cos(), pitch.sin());
    let o3 = g.palm.origin;
    let c = Point2::new(
        o3.x * g.palm.approach_rad.cos() + o3.y * g.palm.approach_rad.sin(),
        o3.z,
    );
    let [z_lo, z_hi] = hand.palm_z_range_mm();
    let corners = [
        c + up * z_lo,
        c + up * z_hi,
        c + up * z_hi + back * hand.palm.offset_mm,
        c + up * z_lo + back * hand.palm.offset_mm,
    ];
    let pts: Vec<(f64, f64)> = corners.iter().map(|q| (q.x, q.y)).collect();
    p.fill(&pts, PALM, 0.25, "palm-outline");
    p.polyline(&pts, PALM, 1.0, true, "palm-outline");
    p.line(
        (corners[0].x, corners[0].y),
        (corners[1].x, corners[1].y),
        PALM,
        3.0,
        false,
        "palm-contact-line",
    );
    for q in &g.palm.contacts {
        p.dot((q.x, q.y), 4.0, FINGER, "palm-contact");
    }
    p.legend("object", OBJECT);
    p.legend(&format!("palm (pitch {:.1} deg)", pitch.to_degrees()), PALM);
    p.legend("contact points", FINGER);
    p.finish()
}

/// Fig. 4.11: the nine finger slice planes seen edge-on in the vertical slice.
pub fn finger_planes(g: &Grasp, hand: &Hand) -> String {
    let (mut p, x) = slice_plot(
        "Finger slice planes, seen edge-on (Fig. 4.11)",
        &g.palm.slice,
        0.0,
    );
    let a = g.palm.approach_rad;
    let to2 = |v: nalgebra::Vector3<f64>| Vector2::new(v.x * a.cos() + v.y * a.sin(), v.z);
    let origin = to2(g.palm.origin.coords);
    let (xp, zp) = (to2(g.palm.axes[0]), to2(g.palm.axes[2]));
    let o = hand.fingers.offset_mm;
    for (k, f) in hand.finger_list.iter().enumerate() {
        for (d, dash) in [(o, true), (0.0, false), (-o, true)] {
            let c = origin + zp * (f.height_mm + d);
            let (p0, p1) = (c + xp * 10.0, c - xp * (x.1 - x.0 + 20.0));
            p.line(
                (p0.x, p0.y),
                (p1.x, p1.y),
                FINGER,
                1.0,
                dash,
                "finger-plane",
            );
        }
        let c = origin + zp * f.height_mm;
        p.text((c.x, c.y), &f.name, 11.0);
        let _ = k;
    }
    p.legend("object", OBJECT);
    p.legend("top, centre and bottom plane of each finger", FINGER);
    p.finish()
}

/// Figs. 4.12–4.16: finger `k`'s centre plane with the palm, the joints, the phalanges' search
/// domains (the disks their contact surfaces sweep) and the placed ALS. Right-side fingers are
/// drawn mirrored, as the planner handles them.
pub fn finger(g: &Grasp, hand: &Hand, mesh: &Mesh, k: usize) -> String {
    let f = &hand.finger_list[k];
    let mirror = f.side.sign();
    let s = slice(
        mesh,
        &g.palm.finger_plane(f.height_mm),
        SliceOptions::default(),
    );
    let (x, y) = bounds(&s);
    let als = &g.fingers[k].centre;
    let c = FingerChain::new(hand, als.theta1_deg, als.theta2_deg);
    let xs = [x.0, x.1, c.j1.x, c.j2.x, c.tip.x, hand.palm.offset_mm];
    let ys = [
        mirror * y.0,
        mirror * y.1,
        c.j1.y,
        c.j2.y,
        c.tip.y,
        -hand.palm.half_width_mm,
    ];
    let xr = (
        xs.iter().cloned().fold(f64::INFINITY, f64::min),
        xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    );
    let yr = (
        ys.iter().cloned().fold(f64::INFINITY, f64::min),
        ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    );
    let mut p = Plot::new(
        &format!(
            "{}: centre ALS fixed, theta1 {:.1} deg, theta2 {:.1} deg (Figs. 4.12-4.16)",
            f.name, als.theta1_deg, als.theta2_deg
        ),
        "x (away from the object) [mm]",
        "y (sideways) [mm]",
        pad(xr, 15.0),
        pad(yr, 15.0),
        true,
    );
    draw_slice(&mut p, &s, mirror);
    let hw = hand.palm.half_width_mm;
    let po = hand.palm.offset_mm;
    let palm = [(0.0, -hw), (po, -hw), (po, hw), (0.0, hw)];
    p.fill(&palm, PALM, 0.25, "palm-outline");
    p.line((0.0, -hw), (0.0, hw), PALM, 3.0, false, "palm-contact-line");
    draw_finger_chain(&mut p, hand, &c);
    p.legend("object (finger plane slice)", OBJECT);
    p.legend("palm", PALM);
    p.legend("phalanx search domains", DOMAIN);
    p.legend("ALS contact lines", FINGER);
    p.finish()
}

/// A finger in its centre plane `[mm]`: joint 1, phalanx 1's direction, joint 2, phalanx 2's
/// direction and the fingertip.
struct FingerChain {
    j1: Point2<f64>,
    d1: Vector2<f64>,
    j2: Point2<f64>,
    e: Vector2<f64>,
    tip: Point2<f64>,
}

impl FingerChain {
    /// The chain of `hand`'s finger at joint angles `theta1_deg`, `theta2_deg`.
    fn new(hand: &Hand, theta1_deg: f64, theta2_deg: f64) -> FingerChain {
        let j1 = Point2::new(hand.joints.setback_mm, hand.joints.lateral_mm);
        let d1 = phalanx1_direction(theta1_deg.to_radians());
        let j2 = j1 + d1 * hand.phalanx_1.length_mm;
        let e = Rotation2::new((180.0 - theta2_deg).to_radians()) * d1;
        let tip = j2 + e * hand.phalanx_2.length_mm;
        FingerChain { j1, d1, j2, e, tip }
    }
}

/// The finger `c` on `p`: each phalanx's search domain, the centreline, the ALS contact lines
/// and the joints.
fn draw_finger_chain(p: &mut Plot, hand: &Hand, c: &FingerChain) {
    let FingerChain { j1, d1, j2, e, tip } = *c;
    let o = hand.fingers.offset_mm;
    let p1 = &hand.phalanx_1;
    let p2 = &hand.phalanx_2;
    p.circle(
        (j1.x, j1.y),
        (p1.length_mm - p1.unusable_distal_mm).hypot(o),
        DOMAIN,
        "phalanx-1-domain",
    );
    p.circle(
        (j2.x, j2.y),
        (p2.length_mm - p2.unusable_distal_mm).hypot(o),
        DOMAIN,
        "phalanx-2-domain",
    );
    let n1 = inward_normal(&d1);
    let ne = inward_normal(&e);
    p.line(
        (j1.x, j1.y),
        (j2.x, j2.y),
        FINGER,
        1.0,
        true,
        "finger-centreline",
    );
    p.line(
        (j2.x, j2.y),
        (tip.x, tip.y),
        FINGER,
        1.0,
        true,
        "finger-centreline",
    );
    let c1a = j1 + n1 * o + d1 * p1.unusable_proximal_mm;
    let c1b = j1 + n1 * o + d1 * (p1.length_mm - p1.unusable_distal_mm);
    let c2a = j2 + ne * o + e * p2.unusable_proximal_mm;
    let c2b = j2 + ne * o + e * (p2.length_mm - p2.unusable_distal_mm);
    p.line((c1a.x, c1a.y), (c1b.x, c1b.y), FINGER, 3.0, false, "als");
    p.line((c2a.x, c2a.y), (c2b.x, c2b.y), FINGER, 3.0, false, "als");
    p.dot((j1.x, j1.y), 4.0, PALM, "joint");
    p.dot((j2.x, j2.y), 4.0, PALM, "joint");
}

/// For an object with no grasp: what decided it. Each constraint that rejected candidates as a
/// bar of its count, most first (the grade figures show which elevations were graded out);
/// with no candidate tried (the grades left none), the planner's reason in words.
pub fn rejections(report: &crate::report::RunReport) -> String {
    let p = &report.plan;
    let mut counts: Vec<(&String, usize)> = p.rejections.iter().map(|(k, n)| (k, *n)).collect();
    counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    let n = counts.len().max(1) as f64;
    let max = counts.iter().map(|c| c.1).max().unwrap_or(1).max(1) as f64;
    let mut plot = Plot::new(
        &if counts.is_empty() {
            "Why no grasp: no candidate left to try".to_string()
        } else {
            format!(
                "Why no grasp: {} tried, rejected by",
                crate::messages::plural(p.candidates_tried, "candidate")
            )
        },
        "candidates rejected",
        "",
        (0.0, max * 1.05),
        (0.0, n),
        false,
    );
    for (k, (what, count)) in counts.iter().enumerate() {
        let y = n - k as f64 - 0.5;
        plot.hbar(y - 0.15, *count as f64, 0.35, FINGER, "rejection");
        plot.text((0.0, y + 0.05), &format!("{what} ({count})"), 12.0);
    }
    if counts.is_empty() {
        let reason = p.reason.as_deref().unwrap_or("no candidate");
        // Wrapped by words into lines of about 80 characters.
        let mut lines = vec![String::new()];
        for word in reason.split_whitespace() {
            if lines.last().is_some_and(|l| l.len() + word.len() > 80) {
                lines.push(String::new());
            }
            let l = lines.last_mut().expect("one line at least");
            if !l.is_empty() {
                l.push(' ');
            }
            l.push_str(word);
        }
        for (k, line) in lines.iter().enumerate() {
            plot.text((0.0, 0.8 - 0.12 * k as f64), line, 12.0);
        }
    }
    plot.legend("candidates rejected by this constraint", FINGER);
    plot.finish()
}
