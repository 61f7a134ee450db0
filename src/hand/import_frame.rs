//! The second half of deriving a hand from its file ([`super::import`]): the model's palm frame
//! found from the finger axes and the palm geometry, then the model's numbers measured in it.
//!
//! Units: millimetres and degrees (the tree's radians converted here). A finger's numbers are
//! measured mirrored onto the +y side (y → side × y), where every finger closes by turning
//! about +z, as [`super::kinematics`] works.

use super::import::{axes_of, err, model_coupling, points_of_body, Derived, Tree};
use super::{Coupling, Hand, HandError};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector2, Vector3};

/// One finger: its joints 1 and 2 and its spread joint (tree indices), and the mapping's slot
/// that names it (0 finger_1, 1 the thumb, 2 finger_3).
type ChainInfo = (usize, usize, Option<usize>, Option<usize>);

/// The model's palm frame in the palm link's frame.
pub(super) struct Frame {
    /// The model's axes x, y, z in the palm link's frame.
    axes: [Vector3<f64>; 3],
    /// The model's origin (the palm centre on the contact surface) in the palm link's frame.
    origin: Point3<f64>,
    /// The fingers in model order (finger_1, the thumb, finger_3), as chain indices.
    order: [usize; 3],
}

impl Frame {
    /// A point of the palm link's frame in the model's palm frame.
    fn to_model(&self, p: &Point3<f64>) -> Point3<f64> {
        let d = p - self.origin;
        Point3::new(
            self.axes[0].dot(&d),
            self.axes[1].dot(&d),
            self.axes[2].dot(&d),
        )
    }
}

fn flat(v: &Vector3<f64>, z: &Vector3<f64>) -> Vector3<f64> {
    v - z * v.dot(z)
}

/// The joint's limits, or the error that it has none.
fn limits(tree: &Tree, j: usize) -> Result<(f64, f64), HandError> {
    tree.joints[j].limits.ok_or_else(|| {
        err(
            &tree.file,
            format!(
                "line {}: joint `{}` has no limits: expected a finger joint's range",
                tree.joints[j].line, tree.joints[j].name
            ),
        )
    })
}

/// Checks the flexion axes are parallel; returns the first one's direction.
fn common_axis(
    tree: &Tree,
    chains: &[ChainInfo],
    axes: &[[(Point3<f64>, Vector3<f64>); 2]],
) -> Result<Vector3<f64>, HandError> {
    let z = axes[0][0].1.normalize();
    for (c, a) in chains.iter().zip(axes) {
        for (k, (_, dir)) in a.iter().enumerate() {
            let angle = dir.normalize().cross(&z).norm().asin().to_degrees();
            if angle > 2.0 {
                let j = if k == 0 { c.0 } else { c.1 };
                return Err(err(
                    &tree.file,
                    format!(
                        "line {}: joint `{}` turns {angle:.1}° off joint `{}`'s axis: expected \
                         every finger to flex in parallel planes (hold the spread joints where \
                         they are parallel: [hand.mapping] spread)",
                        tree.joints[j].line, tree.joints[j].name, tree.joints[chains[0].0].name
                    ),
                ));
            }
        }
    }
    Ok(z)
}

/// The model's palm frame: z along the flexion axes, the thumb the finger closing the other
/// way, y from the thumb's joint 1 to the others', x = y × z away from the object.
///
/// # Errors
/// Joint limits missing, axes not parallel, no thumb, no palm geometry.
pub(super) fn palm_frame(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    palm: usize,
    chains: &[ChainInfo],
    finger_axes: &[super::import::FingerAxesRef],
) -> Result<Frame, HandError> {
    let axes: Vec<[(Point3<f64>, Vector3<f64>); 2]> = finger_axes.iter().map(axes_of).collect();
    let z0 = common_axis(tree, chains, &axes)?;
    // Where the fingers reach at mid-range: in front of the palm.
    let mut front = Vector3::zeros();
    for (c, a) in chains.iter().zip(&axes) {
        let (lo, hi) = limits(tree, c.0)?;
        limits(tree, c.1)?;
        let u1 = flat(&(a[1].0 - a[0].0), &z0);
        let turn = UnitQuaternion::from_axis_angle(
            &nalgebra::Unit::new_normalize(a[0].1),
            0.5 * (lo + hi),
        );
        front += flat(&(turn * u1), &z0).normalize();
    }
    let centre: Vector3<f64> = axes.iter().map(|a| a[0].0.coords).sum::<Vector3<f64>>() / 3.0;
    let senses: Vec<f64> = axes
        .iter()
        .map(|a| {
            let out = flat(&(a[0].0.coords - centre), &z0);
            out.cross(&front).dot(&z0).signum()
        })
        .collect();
    let thumb = (0..3).find(|&k| senses.iter().filter(|&&s| s == senses[k]).count() == 1);
    let Some(thumb) = thumb.filter(|_| front.norm() > 1e-6) else {
        return Err(err(
            &tree.file,
            "no finger closes against the other two: expected a thumb opposing two fingers \
             (three fingers flexing towards one palm)",
        ));
    };
    let others: Vec<usize> = (0..3).filter(|&k| k != thumb).collect();
    let z = z0 * senses[others[0]];
    let mean_others = (axes[others[0]][0].0.coords + axes[others[1]][0].0.coords) / 2.0;
    let y = flat(&(mean_others - axes[thumb][0].0.coords), &z).normalize();
    let x = y.cross(&z);
    let palm_points = points_of_body(tree, pose, palm);
    if palm_points.is_empty() || !y.iter().all(|v| v.is_finite()) {
        return Err(err(
            &tree.file,
            format!(
                "line {}: palm link `{}` has no geometry: expected its collision geometry (the \
                 palm's contact plane and extent)",
                tree.links[palm].line, tree.links[palm].name
            ),
        ));
    }
    let range = |axis: &Vector3<f64>| {
        palm_points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(axis.dot(&p.coords)), hi.max(axis.dot(&p.coords)))
            })
    };
    let x0 = range(&x).0;
    let y0 = 0.5 * (y.dot(&mean_others) + y.dot(&axes[thumb][0].0.coords));
    let (zl, zh) = range(&z);
    let origin = Point3::from(x * x0 + y * y0 + z * (0.5 * (zl + zh)));
    let heights: Vec<f64> = axes.iter().map(|a| z.dot(&a[0].0.coords)).collect();
    let order = finger_order(tree, chains, thumb, [others[0], others[1]], &heights)?;
    Ok(Frame {
        axes: [x, y, z],
        origin,
        order,
    })
}

/// The fingers in model order (finger_1, the thumb, finger_3): as the mapping names them, else
/// finger_1 the higher of the two along z (by joint 1's height).
///
/// # Errors
/// A mapping whose thumb is not the finger closing against the other two.
fn finger_order(
    tree: &Tree,
    chains: &[ChainInfo],
    thumb: usize,
    others: [usize; 2],
    heights: &[f64],
) -> Result<[usize; 3], HandError> {
    if let Some(k) = (0..3).find(|&k| chains[k].3 == Some(1) && k != thumb) {
        return Err(err(
            &tree.file,
            format!(
                "[hand.mapping] thumb names joint `{}`, but the finger closing against the other \
                 two is that of joint `{}`: expected the opposing finger",
                tree.joints[chains[k].0].name, tree.joints[chains[thumb].0].name
            ),
        ));
    }
    let named = |k: usize, slot: usize| chains[others[k]].3 == Some(slot);
    let first = if named(0, 0) || named(1, 2) {
        true
    } else if named(1, 0) || named(0, 2) {
        false
    } else {
        heights[others[0]] >= heights[others[1]]
    };
    Ok(if first {
        [others[0], thumb, others[1]]
    } else {
        [others[1], thumb, others[0]]
    })
}

/// One finger measured in the model frame (mirrored to +y).
struct Measured {
    setback: f64,
    lateral: f64,
    height: f64,
    l1: f64,
    l2: f64,
    offset: f64,
    width: f64,
    /// Interior angles at the file's zero `[deg]`.
    theta0: [f64; 2],
    /// +1 where the joint's positive value closes it.
    sense: [f64; 2],
    /// Ranges as interior angles `[deg]`.
    ranges: [[f64; 2]; 2],
}

/// The extent of `points` along `dir` from `from`: (most against it, most along it).
fn extent(points: &[Vector2<f64>], from: Vector2<f64>, dir: Vector2<f64>) -> (f64, f64) {
    points.iter().fold((0.0f64, 0.0f64), |(lo, hi), p| {
        let t = (p - from).dot(&dir);
        (lo.min(t), hi.max(t))
    })
}

/// Phalanx 2's direction from joint 2 (towards its geometry's centroid) and its length (the
/// geometry's farthest extent along it), in the flexion plane.
fn tip(
    tree: &Tree,
    joint: usize,
    points: &[Point3<f64>],
    at: Vector2<f64>,
) -> Result<(Vector2<f64>, f64), HandError> {
    let flat2: Vec<Vector2<f64>> = points.iter().map(|p| Vector2::new(p.x, p.y)).collect();
    let centroid = flat2.iter().sum::<Vector2<f64>>() / flat2.len() as f64;
    let toward = centroid - at;
    if toward.norm() < 1.0 {
        let link = &tree.links[tree.joints[joint].child];
        return Err(err(
            &tree.file,
            format!(
                "line {}: link `{}`'s geometry does not reach out from joint `{}`: expected the \
                 fingertip link to extend from its joint",
                link.line, link.name, tree.joints[joint].name
            ),
        ));
    }
    let u2 = toward.normalize();
    Ok((u2, extent(&flat2, at, u2).1))
}

fn measure(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    frame: &Frame,
    chain: ChainInfo,
    side: f64,
    axes: &[(Point3<f64>, Vector3<f64>); 2],
) -> Result<Measured, HandError> {
    let mirror = |p: Point3<f64>| {
        let m = frame.to_model(&p);
        Point3::new(m.x, side * m.y, m.z)
    };
    let xy = |p: &Point3<f64>| Vector2::new(p.x, p.y);
    let (p1, p2) = (mirror(axes[0].0), mirror(axes[1].0));
    let u1 = (xy(&p2) - xy(&p1)).normalize();
    let l1 = (xy(&p2) - xy(&p1)).norm();
    let body = |j: usize| -> Vec<Point3<f64>> {
        points_of_body(tree, pose, tree.joints[j].child)
            .into_iter()
            .map(mirror)
            .collect()
    };
    let (b1, b2) = (body(chain.0), body(chain.1));
    let no_geometry = |j: usize| {
        err(
            &tree.file,
            format!(
                "line {}: link `{}` has no geometry: expected the phalanx's collision geometry \
                 (its extent gives the fingertip and the finger's thickness)",
                tree.links[tree.joints[j].child].line, tree.links[tree.joints[j].child].name
            ),
        )
    };
    if b1.is_empty() {
        return Err(no_geometry(chain.0));
    }
    if b2.is_empty() {
        return Err(no_geometry(chain.1));
    }
    let (u2, l2) = tip(tree, chain.1, &b2, xy(&p2))?;
    let n1 = Vector2::new(-u1.y, u1.x);
    let flat1: Vec<Vector2<f64>> = b1.iter().map(xy).collect();
    let offset = extent(&flat1, xy(&p1), n1).1;
    let (zl, zh) = b1
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.z), h.max(p.z))
        });
    // Bends from straight out along the palm ((0, 1), mirrored), in the closing sense.
    let theta1 = 180.0 - (-u1.x).atan2(u1.y).to_degrees();
    let bend2 = (u1.x * u2.y - u1.y * u2.x).atan2(u1.dot(&u2)).to_degrees();
    let theta0 = [theta1, 180.0 - bend2];
    let sense = [
        (frame.axes[2].dot(&axes[0].1)).signum() * side,
        (frame.axes[2].dot(&axes[1].1)).signum() * side,
    ];
    let ranges = interior_ranges(tree, chain, theta0, sense)?;
    Ok(Measured {
        setback: p1.x,
        lateral: p1.y,
        height: 0.5 * (zl + zh),
        l1,
        l2,
        offset,
        width: zh - zl,
        theta0,
        sense,
        ranges,
    })
}

/// The joints' limits as interior-angle ranges `[deg]`: θ = θ0 − sense × q.
fn interior_ranges(
    tree: &Tree,
    chain: ChainInfo,
    theta0: [f64; 2],
    sense: [f64; 2],
) -> Result<[[f64; 2]; 2], HandError> {
    let mut ranges = [[0.0; 2]; 2];
    for (k, j) in [chain.0, chain.1].into_iter().enumerate() {
        let (lo, hi) = limits(tree, j)?;
        let a = theta0[k] - sense[k] * lo.to_degrees();
        let b = theta0[k] - sense[k] * hi.to_degrees();
        ranges[k] = [a.min(b), a.max(b)];
    }
    Ok(ranges)
}

/// The palm's extents in the model frame: x (depth), y, z ranges.
fn palm_extents(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    palm: usize,
    frame: &Frame,
) -> [(f64, f64); 3] {
    let pts: Vec<Point3<f64>> = points_of_body(tree, pose, palm)
        .iter()
        .map(|p| frame.to_model(p))
        .collect();
    let mut out = [(f64::INFINITY, f64::NEG_INFINITY); 3];
    for p in &pts {
        for (k, r) in out.iter_mut().enumerate() {
            *r = (r.0.min(p[k]), r.1.max(p[k]));
        }
    }
    out
}

/// Mean of `f` over the fingers, and a note when they differ by more than `tol`.
fn agreed(
    m: &[Measured],
    what: &str,
    tol: f64,
    notes: &mut Vec<String>,
    f: impl Fn(&Measured) -> f64,
) -> f64 {
    let v: Vec<f64> = m.iter().map(f).collect();
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let spread = v.iter().fold(0.0f64, |s, x| s.max((x - mean).abs()));
    if spread > tol {
        notes.push(format!(
            "the fingers' {what} differ ({}): the model uses their mean, {mean:.2}",
            v.iter()
                .map(|x| format!("{x:.2}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    mean
}

/// The joint ranges the three fingers share, clamped into the model's (0, 180] with a note.
fn shared_range(m: &[Measured], k: usize, notes: &mut Vec<String>) -> [f64; 2] {
    let lo = m
        .iter()
        .map(|f| f.ranges[k][0])
        .fold(f64::NEG_INFINITY, f64::max);
    let hi = m
        .iter()
        .map(|f| f.ranges[k][1])
        .fold(f64::INFINITY, f64::min);
    let clamped = [lo.max(1.0), hi.min(180.0)];
    if (clamped[0] - lo).abs() > 1e-6 || (clamped[1] - hi).abs() > 1e-6 {
        notes.push(format!(
            "joint {} turns over [{lo:.1}°, {hi:.1}°] as an interior angle: the model's range \
             is clamped to [{:.1}°, {:.1}°] (180° is straight out, 0° folded onto the palm)",
            k + 1,
            clamped[0],
            clamped[1]
        ));
    }
    clamped
}

/// Measures the model in `frame` and validates it (with the scenario's overrides).
pub(super) fn build(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    palm: usize,
    chains: &[ChainInfo],
    finger_axes: &[super::import::FingerAxesRef],
    frame: Frame,
    overrides: &[(String, f64)],
) -> Result<Derived, HandError> {
    let sides = [1.0, -1.0, 1.0];
    let mut m = Vec::new();
    for (k, &c) in frame.order.iter().enumerate() {
        let f = measure(
            tree,
            pose,
            &frame,
            chains[c],
            sides[k],
            &axes_of(&finger_axes[c]),
        )?;
        if f.lateral <= 0.0 {
            return Err(err(
                &tree.file,
                format!(
                    "line {}: joint `{}` is not on its finger's side of the palm: expected the \
                     thumb opposite the other two",
                    tree.joints[chains[c].0].line, tree.joints[chains[c].0].name
                ),
            ));
        }
        m.push(f);
    }
    let mut notes = Vec::new();
    let setback = agreed(&m, "joint-1 setbacks [mm]", 0.5, &mut notes, |f| f.setback);
    let lateral = agreed(&m, "joint-1 lateral places [mm]", 0.5, &mut notes, |f| {
        f.lateral
    });
    let l1 = agreed(&m, "phalanx 1 lengths [mm]", 0.5, &mut notes, |f| f.l1);
    let l2 = agreed(&m, "phalanx 2 lengths [mm]", 0.5, &mut notes, |f| f.l2);
    let offset = agreed(&m, "finger offsets [mm]", 0.5, &mut notes, |f| f.offset);
    let width = agreed(&m, "finger widths [mm]", 0.5, &mut notes, |f| f.width);
    if (width - 2.0 * offset).abs() > 1.0 {
        notes.push(format!(
            "the fingers are {width:.1} mm wide and {offset:.1} mm from centreline to contact \
             face: the model's section is square ({:.1} mm wide)",
            2.0 * offset
        ));
    }
    let r1 = shared_range(&m, 0, &mut notes);
    let r2 = shared_range(&m, 1, &mut notes);
    let ext = palm_extents(tree, pose, palm, &frame);
    let heights: Vec<f64> = m.iter().map(|f| f.height).collect();
    let hand = model(
        tree,
        &ext,
        &heights,
        (setback, lateral, l1, l2, offset),
        [r1, r2],
    );
    let mut derived = finish(tree, pose, palm, chains, &frame, &m, hand, notes, overrides)?;
    let geometry = link_geometry(tree, pose, palm, chains, &frame, &m, finger_axes);
    if !geometry.is_empty() {
        derived.notes.push(
            "links with meshes: the convex hull of each of their geometry elements stands for the \
             model's box of that body in the physics check and --export-mjcf"
                .to_string(),
        );
        derived.hand.link_geometry = Some(std::sync::Arc::new(geometry));
    }
    Ok(derived)
}

/// The file's own geometry per model body ([`super::link_geometry`]): the palm's (with the
/// spread links, held with it) in the palm frame, each phalanx's about its own joint.
fn link_geometry(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    palm: usize,
    chains: &[ChainInfo],
    frame: &Frame,
    m: &[Measured],
    finger_axes: &[super::import::FingerAxesRef],
) -> super::link_geometry::LinkGeometry {
    use super::import::pieces_of_body;
    use super::link_geometry::{body_pieces, turn};
    let to_model = |p: &Point3<f64>| frame.to_model(p);
    let mut palm_pieces = pieces_of_body(tree, pose, palm);
    for &c in &frame.order {
        if let Some(s) = chains[c].2 {
            palm_pieces.extend(pieces_of_body(tree, pose, tree.joints[s].child));
        }
    }
    let identity = (Point3::origin(), UnitQuaternion::identity());
    let sides = [1.0, -1.0, 1.0];
    let phalanges = frame
        .order
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let a = axes_of(&finger_axes[c]);
            let at = |p: &Point3<f64>| {
                let q = frame.to_model(p);
                Point3::new(q.x, q.y, m[k].height)
            };
            let r1 = turn(sides[k], super::bend(m[k].theta0[0]));
            let r2 = r1 * turn(sides[k], super::bend(m[k].theta0[1]));
            let (j1, j2) = (chains[c].0, chains[c].1);
            [
                body_pieces(
                    pieces_of_body(tree, pose, tree.joints[j1].child),
                    to_model,
                    (at(&a[0].0), r1),
                ),
                body_pieces(
                    pieces_of_body(tree, pose, tree.joints[j2].child),
                    to_model,
                    (at(&a[1].0), r2),
                ),
            ]
        })
        .collect();
    super::link_geometry::LinkGeometry {
        palm: body_pieces(palm_pieces, to_model, identity),
        phalanges,
    }
}

/// The model's numbers as a [`Hand`] (unvalidated), with the thesis hand's proportions for
/// what no file gives.
fn model(
    tree: &Tree,
    ext: &[(f64, f64); 3],
    heights: &[f64],
    (setback, lateral, l1, l2, offset): (f64, f64, f64, f64, f64),
    [r1, r2]: [[f64; 2]; 2],
) -> Hand {
    let names = ["finger_1", "finger_2", "finger_3"];
    let sides = [1.0, -1.0, 1.0];
    let (h_lo, h_hi) = heights
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    let margin = 0.5 * ((ext[2].1 - h_hi) + (h_lo - ext[2].0));
    Hand {
        name: tree.name.clone(),
        palm: super::Palm {
            offset_mm: ext[0].1 - ext[0].0,
            margin_mm: margin.max(0.0),
            half_width_mm: 0.5 * (ext[1].1 - ext[1].0),
            standoff_max_mm: None,
        },
        joints: super::Joints {
            lateral_mm: lateral,
            setback_mm: setback,
            theta1_range_deg: r1,
            theta2_range_deg: r2,
        },
        fingers: super::FingerGeometry {
            gap_mm: 0.5 * (h_hi - h_lo),
            offset_mm: offset,
            tip_thickness_mm: offset * 4.0 / 7.0,
            relief_mm: None,
        },
        phalanx_1: super::Phalanx {
            length_mm: l1,
            unusable_proximal_mm: l1 * 5.0 / 61.0,
            unusable_distal_mm: l1 * 5.0 / 61.0,
        },
        phalanx_2: super::Phalanx {
            length_mm: l2,
            unusable_proximal_mm: l2 * 2.0 / 20.0,
            unusable_distal_mm: 0.0,
        },
        link_geometry: None,
        finger_list: names
            .iter()
            .zip(heights)
            .zip(sides)
            .map(|((n, h), s)| super::Finger {
                name: n.to_string(),
                side: if s > 0.0 {
                    super::Side::Left
                } else {
                    super::Side::Right
                },
                height_mm: *h,
            })
            .collect(),
        coupling: Vec::new(),
    }
}

/// A hand that wraps, resting on its palm, no object narrower than the span between its
/// opposing joint-1 axes (a distal joint that closes at most 90° against a long phalanx 1, as the
/// Schunk SDH-2's: it wraps nothing under 92 mm on its palm, its axes 57 mm apart) is given a
/// palm stand-off: the planner may hold the object in front of the palm, between the
/// phalanges, up to half phalanx 1's length out (so that phalanx 1 still reaches round it), and
/// the note says so. A hand that wraps such objects on its palm (the thesis hand, the BH8)
/// keeps the thesis's model.
fn standoff_if_needed(hand: &mut Hand, notes: &mut Vec<String>) {
    let span = 2.0 * hand.joints.lateral_mm;
    let smallest = super::kinematics::graspable_circle_radii(hand).map(|(lo, _)| 2.0 * lo);
    if hand.palm.standoff_max_mm.is_some() || smallest.is_some_and(|d| d <= span) {
        return;
    }
    let max = (0.5 * hand.phalanx_1.length_mm).floor();
    let mut with = hand.clone();
    with.palm.standoff_max_mm = Some(max);
    if let Some((lo, _)) = super::kinematics::graspable_circle_radii(&with) {
        *hand = with;
        let on_palm = smallest.map_or("no object".to_string(), |d| {
            format!("no object under {d:.1} mm")
        });
        notes.push(format!(
            "resting on the palm the fingers wrap {on_palm} (joint 2 closes to at most \
             {:.1}°), and the opposing joint-1 axes are {span:.1} mm apart: objects are also \
             held in front of the palm, between the phalanges, up to {max:.0} mm out \
             (palm.standoff_max_mm, half phalanx 1; wrapped from {:.1} mm across)",
            hand.joints.theta2_range_deg[0],
            2.0 * lo
        ));
    }
}

/// Couplings, the bodies for the figure, validation.
#[allow(clippy::too_many_arguments)]
fn finish(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    palm: usize,
    chains: &[ChainInfo],
    frame: &Frame,
    m: &[Measured],
    mut hand: Hand,
    mut notes: Vec<String>,
    overrides: &[(String, f64)],
) -> Result<Derived, HandError> {
    // Which finger and joint (model order) each flexion joint is, with its zero and sense.
    let place = |j: usize| -> Option<((usize, usize), f64, f64)> {
        frame.order.iter().enumerate().find_map(|(k, &c)| {
            let (a, b, _, _) = chains[c];
            [a, b]
                .iter()
                .position(|&x| x == j)
                .map(|n| ((k, n + 1), m[k].theta0[n], m[k].sense[n]))
        })
    };
    let mut couplings = Vec::new();
    for c in &tree.couplings {
        let joint = |name: &str| tree.joints.iter().position(|j| j.name == name);
        let (f, l) = (joint(&c.follower), joint(&c.leader));
        match (f.and_then(place), l.and_then(place)) {
            (Some(fp), Some(lp)) => {
                let mc: Coupling = model_coupling(c, fp, lp);
                couplings.push(mc.describe());
                hand.coupling.push(mc);
            }
            _ => couplings.push(format!(
                "{} `{}` follows `{}` (line {}): not a flexion joint of the model, held where \
                 the spread is held",
                c.kind, c.follower, c.leader, c.line
            )),
        }
    }
    standoff_if_needed(&mut hand, &mut notes);
    let text = toml::to_string(&hand).map_err(|e| err(&tree.file, e.to_string()))?;
    let hand = Hand::parse(&text, &tree.file, overrides)?;
    let model = |p: &Point3<f64>| frame.to_model(p);
    let mut bodies = vec![(
        "palm".to_string(),
        points_of_body(tree, pose, palm).iter().map(model).collect(),
    )];
    let mut joints = Vec::new();
    for (k, &c) in frame.order.iter().enumerate() {
        let (a, b, s, _) = chains[c];
        let name = &hand.finger_list[k].name;
        for (n, j) in [(1, a), (2, b)] {
            let pts = points_of_body(tree, pose, tree.joints[j].child);
            bodies.push((format!("{name}/{n}"), pts.iter().map(model).collect()));
        }
        if let Some(s) = s {
            let pts = points_of_body(tree, pose, tree.joints[s].child);
            bodies.push(("spread".to_string(), pts.iter().map(model).collect()));
        }
        joints.push((
            [tree.joints[a].name.clone(), tree.joints[b].name.clone()],
            s.map(|s| tree.joints[s].name.clone()),
        ));
    }
    notes.push(
        "unusable lengths and the tip's thickness are not in the file: the thesis hand's \
         proportions are used ([hand] overrides set them)"
            .to_string(),
    );
    Ok(Derived {
        hand,
        palm: tree.links[palm].name.clone(),
        joints,
        couplings,
        notes,
        bodies,
        zero_theta_deg: m.iter().map(|f| f.theta0).collect(),
    })
}
