//! `grasp-sim hand show FILE` (issue 37): the model derived from a hand's URDF or MJCF, as a
//! table and as a figure of the model's boxes over the file's link geometry, so that a user can
//! see the mapping is right.
//!
//! The figure (SVG) has two views side by side, both with the object side up (−x of the palm
//! frame): the flexion plane (the palm frame's y across) and the side (z across), the file's
//! links filled grey (their outlines' convex hulls), the model's palm and phalanx boxes drawn
//! over them in blue at the file's zero pose, the joint axes as dots.

use crate::hand::import::Derived;
use crate::hand::{bend, HandBox};
use crate::visual::svg::Plot;
use nalgebra::{Point3, UnitQuaternion, Vector3};
use std::fmt::Write;

/// The derived model as a table (plain text, one row per quantity).
pub fn table(d: &Derived, file: &str) -> String {
    let h = &d.hand;
    let mut s = String::new();
    let _ = writeln!(s, "hand `{}` from {file} (palm link `{}`)", h.name, d.palm);
    let _ = writeln!(
        s,
        "{:<9} {:<22} {:<22} {:<16} {:>5} {:>10} {:>16}",
        "finger", "joint 1", "joint 2", "spread", "side", "height mm", "θ1/θ2 at zero"
    );
    for ((f, (j, spread)), t) in h.finger_list.iter().zip(&d.joints).zip(&d.zero_theta_deg) {
        let _ = writeln!(
            s,
            "{:<9} {:<22} {:<22} {:<16} {:>5} {:>10.2} {:>16}",
            f.name,
            j[0],
            j[1],
            spread.as_deref().unwrap_or("-"),
            if f.side.sign() > 0.0 { "left" } else { "right" },
            f.height_mm,
            format!("{:.1}/{:.1}", t[0], t[1])
        );
    }
    let range = crate::hand::kinematics::graspable_range(h);
    let rows = [
        ("palm.offset_mm", h.palm.offset_mm),
        ("palm.margin_mm", h.palm.margin_mm),
        ("palm.half_width_mm", h.palm.half_width_mm),
        ("joints.lateral_mm", h.joints.lateral_mm),
        ("joints.setback_mm", h.joints.setback_mm),
        ("fingers.gap_mm", h.fingers.gap_mm),
        ("fingers.offset_mm", h.fingers.offset_mm),
        ("fingers.tip_thickness_mm", h.fingers.tip_thickness_mm),
        ("phalanx_1.length_mm", h.phalanx_1.length_mm),
        (
            "phalanx_1.unusable_proximal_mm",
            h.phalanx_1.unusable_proximal_mm,
        ),
        (
            "phalanx_1.unusable_distal_mm",
            h.phalanx_1.unusable_distal_mm,
        ),
        ("phalanx_2.length_mm", h.phalanx_2.length_mm),
        (
            "phalanx_2.unusable_proximal_mm",
            h.phalanx_2.unusable_proximal_mm,
        ),
        (
            "phalanx_2.unusable_distal_mm",
            h.phalanx_2.unusable_distal_mm,
        ),
    ];
    for (k, v) in rows {
        let _ = writeln!(s, "{k:<31} {v:>9.3}");
    }
    if let Some(v) = h.palm.standoff_max_mm {
        let _ = writeln!(s, "{:<31} {v:>9.3}", "palm.standoff_max_mm");
    }
    for (k, [lo, hi]) in [
        ("joints.theta1_range_deg", h.joints.theta1_range_deg),
        ("joints.theta2_range_deg", h.joints.theta2_range_deg),
    ] {
        let _ = writeln!(s, "{k:<31} [{lo:.2}, {hi:.2}]");
    }
    let [lo, hi] = range.used();
    let _ = writeln!(s, "{:<31} [{lo:.1}, {hi:.1}]", "graspable diameter mm");
    for c in &d.couplings {
        let _ = writeln!(s, "coupling: {c}");
    }
    if !h.coupling.is_empty() {
        let _ = writeln!(
            s,
            "couplings are checked, not refused: a plan is reported with how far it breaks each"
        );
    }
    for n in &d.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}

/// Convex hull of 2-D points (monotone chain), counter-clockwise.
fn hull(mut p: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    p.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut out: Vec<(f64, f64)> = Vec::new();
    for pass in 0..2 {
        let start = out.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while out.len() >= start + 2 && cross(out[out.len() - 2], out[out.len() - 1], q) <= 0.0
            {
                out.pop();
            }
            out.push(q);
        }
        out.pop();
    }
    out
}

/// The corners of a box at a pose, in the palm frame.
fn corners(b: &HandBox, pose: &(Point3<f64>, UnitQuaternion<f64>)) -> Vec<Point3<f64>> {
    (0..8)
        .map(|k| {
            let s = |bit: i32| if k & bit == 0 { -1.0 } else { 1.0 };
            let local = b.centre
                + Vector3::new(
                    s(1) * b.half_extents.x,
                    s(2) * b.half_extents.y,
                    s(4) * b.half_extents.z,
                );
            pose.0 + pose.1 * local
        })
        .collect()
}

/// The model's boxes at the file's zero pose, each as its corners in the palm frame, and the
/// joint axes' points.
fn model_boxes(d: &Derived) -> (Vec<Vec<Point3<f64>>>, Vec<Point3<f64>>) {
    let h = &d.hand;
    let palm = (Point3::origin(), UnitQuaternion::identity());
    let mut boxes = vec![corners(&h.palm_box(), &palm)];
    let mut joints = Vec::new();
    for (f, t) in h.finger_list.iter().zip(&d.zero_theta_deg) {
        let [p1, p2] = h.finger_poses(f, &palm, [bend(t[0]), bend(t[1])]);
        let (b1, b2) = h.phalanx_boxes(f.side);
        boxes.push(corners(&b1, &p1));
        for b in &b2 {
            boxes.push(corners(b, &p2));
        }
        joints.push(p1.0);
        joints.push(p2.0);
    }
    (boxes, joints)
}

/// A projection of the palm frame onto the figure's plane.
type View = Box<dyn Fn(&Point3<f64>) -> (f64, f64)>;

/// The figure: the flexion plane and the side view, the file's links under the model's boxes.
pub fn figure(d: &Derived) -> String {
    let (boxes, joints) = model_boxes(d);
    let all: Vec<&Point3<f64>> = d
        .bodies
        .iter()
        .flat_map(|(_, p)| p.iter())
        .chain(boxes.iter().flatten())
        .collect();
    let lo = |k: usize| all.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
    let hi = |k: usize| all.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
    // The side view sits right of the flexion plane, 20 mm clear of it.
    let shift = hi(1) - lo(2) + 20.0;
    let views: [View; 2] = [
        Box::new(|p: &Point3<f64>| (p.y, -p.x)),
        Box::new(move |p: &Point3<f64>| (p.z + shift, -p.x)),
    ];
    let pad = 10.0;
    let mut plot = Plot::new(
        &format!(
            "hand `{}`: model (blue) over the file's links (grey); left: flexion plane (y), right: side (z)",
            d.hand.name
        ),
        "palm y [mm] | palm z + offset [mm]",
        "towards the object, -x [mm]",
        (lo(1).min(lo(2) + shift) - pad, hi(2) + shift + pad),
        (-hi(0) - pad, -lo(0) + pad),
        true,
    );
    for view in &views {
        for (role, pts) in &d.bodies {
            let outline = hull(pts.iter().map(view.as_ref()).collect());
            let color = if role == "palm" { "#999999" } else { "#bbbbbb" };
            plot.fill(&outline, color, 0.6, "link");
        }
        for b in &boxes {
            let outline = hull(b.iter().map(view.as_ref()).collect());
            plot.polyline(&outline, "#1f5fbf", 1.5, true, "model");
        }
        for j in &joints {
            plot.dot(view(j), 2.5, "#c03030", "joint");
        }
    }
    plot.legend("file's link geometry", "#bbbbbb");
    plot.legend("model (palm, phalanges)", "#1f5fbf");
    plot.legend("joint axes", "#c03030");
    plot.finish()
}

/// A hand file to show: a URDF or MJCF itself, a scenario whose `[hand]` names one (then with
/// its mapping and overrides), or a hand TOML (its model alone).
///
/// # Errors
/// The hand file's or the scenario's error, naming the file.
pub fn derive_for_show(file: &std::path::Path) -> Result<Derived, crate::hand::HandError> {
    use crate::hand::import::{err, load, Mapping};
    let is_toml = file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    if !is_toml {
        return load(file, &Mapping::default(), &[]);
    }
    let text =
        crate::files::read_regular_string(file, crate::files::MAX_TEXT_BYTES).map_err(|e| {
            crate::hand::HandError::Io {
                path: file.to_path_buf(),
                error: e,
            }
        })?;
    #[derive(serde::Deserialize)]
    struct Section {
        urdf: Option<std::path::PathBuf>,
        mjcf: Option<std::path::PathBuf>,
        #[serde(default)]
        mapping: Mapping,
        #[serde(default)]
        overrides: std::collections::BTreeMap<String, f64>,
    }
    let table: toml::Table =
        toml::from_str(&text).map_err(|e| err(file, e.message().replace('\n', " ")))?;
    if table.contains_key("palm") && !table.contains_key("hand") {
        // A hand TOML itself: its model, without a file's links to draw under it.
        let hand = crate::hand::Hand::parse(&text, file, &[])?;
        let n = hand.finger_list.len();
        return Ok(Derived {
            palm: "-".to_string(),
            joints: vec![(["-".to_string(), "-".to_string()], None); n],
            couplings: hand.coupling.iter().map(|c| c.describe()).collect(),
            notes: Vec::new(),
            bodies: Vec::new(),
            zero_theta_deg: vec![[180.0, 180.0]; n],
            hand,
        });
    }
    let section: Section = table
        .get("hand")
        .cloned()
        .ok_or_else(|| {
            err(
                file,
                "has no [hand] section: expected one naming `urdf` or `mjcf`",
            )
        })?
        .try_into()
        .map_err(|e: toml::de::Error| err(file, format!("[hand]: {}", e.message())))?;
    let Some(robot) = section.urdf.or(section.mjcf) else {
        return Err(err(
            file,
            "[hand] names no `urdf` or `mjcf`: expected a hand file to show",
        ));
    };
    let dir = file.parent().unwrap_or(std::path::Path::new("."));
    let overrides: Vec<(String, f64)> = section.overrides.into_iter().collect();
    load(&dir.join(robot), &section.mapping, &overrides)
}

/// `grasp-sim hand show FILE [--svg OUT]`: prints the table, writes the figure (default
/// `<FILE's stem>.hand.svg` in the current folder); returns the exit status.
///
/// # Errors
/// The hand file's error (one line naming it), or the figure that could not be written.
pub fn run(file: &std::path::Path, svg: Option<&std::path::Path>) -> anyhow::Result<u8> {
    let d = derive_for_show(file)?;
    print!("{}", table(&d, &file.display().to_string()));
    let out = svg.map_or_else(
        || {
            let stem = file.file_stem().unwrap_or_default().to_string_lossy();
            std::path::PathBuf::from(format!("{stem}.hand.svg"))
        },
        std::path::Path::to_path_buf,
    );
    crate::files::write_replacing(&out, figure(&d).as_bytes()).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot write: {}",
            out.display(),
            crate::messages::io_message(&e)
        )
    })?;
    println!("figure: {}", out.display());
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::hull;

    #[test]
    fn hull_of_a_square_with_an_inside_point() {
        let h = hull(vec![
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (0.5, 0.5),
        ]);
        assert_eq!(h.len(), 4);
        assert!(!h.contains(&(0.5, 0.5)));
    }
}
