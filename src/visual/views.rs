//! Three rendered views of the grasp (issue 33, as the thesis's Figs. 4.17–4.19 show its
//! chapter 4 grasp): the planned hand and the hand where the closing left it, over the object,
//! drawn by grasp-sim itself as SVG, so that the report needs no viewer, no network and no
//! script.
//!
//! Input: the object's aligned mesh `[mm]`, the hand, the bodies' planned poses and, when the
//! physics check ran, where its closing left them (both in the aligned frame, metres, in the
//! order palm, phalanx 1 and 2 of each finger, then for the closed set the object). Output: one
//! SVG string per view. Each view is an orthographic projection along a direction fixed in the
//! palm's frame (so a view means the same thing whatever the approach angle): `top` looks down
//! the palm's up axis onto the finger planes, `side` along the palm's width, `oblique` from
//! above, behind and to one side. Faces are painted far to near (painter's algorithm on face
//! centres, ties by input order), shaded by the angle to a light from the viewer's upper left.
//! The closed hand and the object where the closing left it are filled; the planned hand is a
//! dashed outline, and where the object was at the start of the closing a dashed silhouette.

use crate::hand::{BodyPose, Hand, HandBox};
use crate::mesh::Mesh;
use crate::sim::convert::M_PER_MM;
use nalgebra::{Point3, UnitQuaternion, Vector3};
use std::fmt::Write;

/// A view: its file stem (`view_<name>.svg`), title, and direction in the palm frame (the
/// viewer looks along `look`, with `up` up on the page).
struct View {
    name: &'static str,
    title: &'static str,
    look: Vector3<f64>,
    up: Vector3<f64>,
}

fn views() -> [View; 3] {
    [
        View {
            name: "top",
            title: "from above (down the palm's up axis): the finger planes",
            look: Vector3::new(0.0, 0.0, -1.0),
            up: Vector3::new(-1.0, 0.0, 0.0),
        },
        View {
            name: "side",
            title: "from the side (along the palm's width)",
            look: Vector3::new(0.0, -1.0, 0.0),
            up: Vector3::new(0.0, 0.0, 1.0),
        },
        View {
            name: "oblique",
            title: "oblique (from above, beyond the object and to one side)",
            look: Vector3::new(0.9, -1.0, -0.8),
            up: Vector3::new(0.0, 0.0, 1.0),
        },
    ]
}

/// A dashed line in view coordinates `[mm]` and its colour.
type Segment = ((f64, f64), (f64, f64), &'static str);

/// One filled polygon in view coordinates: its points (page x right, y up, `[mm]`), depth of
/// its centre along the look direction, fill colour and opacity.
struct Face {
    points: Vec<(f64, f64)>,
    depth: f64,
    fill: String,
    opacity: f64,
}

/// The view's projection: page coordinates and depth `[mm]` of a point of the aligned frame.
struct Projection {
    right: Vector3<f64>,
    up: Vector3<f64>,
    look: Vector3<f64>,
}

impl Projection {
    fn new(view: &View, palm: &UnitQuaternion<f64>) -> Projection {
        let look = (palm * view.look).normalize();
        let up0 = palm * view.up;
        let up = (up0 - look * up0.dot(&look)).normalize();
        let right = look.cross(&up);
        Projection { right, up, look }
    }

    fn page(&self, p: &Point3<f64>) -> (f64, f64) {
        (p.coords.dot(&self.right), p.coords.dot(&self.up))
    }

    fn depth(&self, p: &Point3<f64>) -> f64 {
        p.coords.dot(&self.look)
    }
}

/// The eight corners of `b` posed by `pose` (origin `[mm]`), corner k taking the +x half
/// extent when bit 0 of k is set, +y for bit 1, +z for bit 2.
fn corners(b: &HandBox, pose: &BodyPose) -> [Point3<f64>; 8] {
    let h = b.half_extents;
    std::array::from_fn(|k| {
        let s = |bit: usize| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
        let local = b.centre + Vector3::new(s(0) * h.x, s(1) * h.y, s(2) * h.z);
        pose.0 + pose.1 * local
    })
}

/// A box's six faces as corner indices, wound outward.
const BOX_FACES: [[usize; 4]; 6] = [
    [0, 2, 6, 4],
    [1, 5, 7, 3],
    [0, 4, 5, 1],
    [2, 3, 7, 6],
    [0, 1, 3, 2],
    [4, 6, 7, 5],
];

/// A box's twelve edges as corner indices.
const BOX_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [2, 3],
    [4, 5],
    [6, 7],
    [0, 2],
    [1, 3],
    [4, 6],
    [5, 7],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];

/// Every box of the hand with the body it belongs to (0 palm, then phalanx 1 and 2 of each
/// finger, as in the poses).
fn hand_boxes(hand: &Hand) -> Vec<(usize, HandBox)> {
    let mut out = vec![(0, hand.palm_box())];
    for (k, f) in hand.finger_list.iter().enumerate() {
        let (p1, p2) = hand.phalanx_boxes(f.side);
        out.push((1 + 2 * k, p1));
        for b in p2 {
            out.push((2 + 2 * k, b));
        }
    }
    out
}

/// Poses in metres (as the sim reports them) to millimetres.
fn to_mm(poses: &[crate::sim::BodyPose]) -> Vec<BodyPose> {
    poses
        .iter()
        .map(|(t, r)| (Point3::from(t / M_PER_MM), *r))
        .collect()
}

/// Grey shaded by how squarely a face with unit `normal` faces the light.
fn shade(normal: &Vector3<f64>, light: &Vector3<f64>, base: [f64; 3]) -> String {
    let k = 0.45 + 0.55 * normal.dot(light).abs();
    let c = |v: f64| ((v * k).clamp(0.0, 1.0) * 255.0).round() as u8;
    format!("#{:02x}{:02x}{:02x}", c(base[0]), c(base[1]), c(base[2]))
}

/// What the views draw.
pub struct Scene<'a> {
    /// The object's aligned mesh `[mm]`.
    pub mesh: &'a Mesh,
    /// The hand.
    pub hand: &'a Hand,
    /// The planned poses of the hand's bodies `[m]`.
    pub planned: &'a [crate::sim::BodyPose],
    /// Where the closing left the hand's bodies and the object `[m]` (`None`: not checked).
    pub closed: Option<&'a [crate::sim::BodyPose]>,
    /// The one-line legend's figures: the closing's shift `[mm]` and turn `[deg]`.
    pub shift: Option<(f64, f64)>,
}

/// The three views as `(file stem, SVG)`: `view_top`, `view_side`, `view_oblique`.
pub fn render(scene: &Scene) -> Vec<(String, String)> {
    views()
        .iter()
        .map(|v| (format!("view_{}", v.name), render_one(scene, v)))
        .collect()
}

/// One view of the scene as SVG.
fn render_one(scene: &Scene, view: &View) -> String {
    let planned = to_mm(scene.planned);
    let palm_rotation = planned.first().map_or(UnitQuaternion::identity(), |p| p.1);
    let proj = Projection::new(view, &palm_rotation);
    let light = (proj.up * 0.6 - proj.right * 0.5 - proj.look * 0.8).normalize();
    let boxes = hand_boxes(scene.hand);
    let n_hand = planned.len();
    let closed = scene.closed.map(to_mm).filter(|c| c.len() == n_hand + 1);
    let object_pose: BodyPose = closed
        .as_ref()
        .map_or((Point3::origin(), UnitQuaternion::identity()), |c| {
            c[n_hand]
        });
    // The object, where the closing left it (at its planned place when not checked).
    let mut faces = object_faces(scene.mesh, &object_pose, &proj, &light);
    // The hand where the closing left it (or as planned when not checked), filled.
    let hand_poses = closed.as_ref().map_or(&planned[..], |c| &c[..n_hand]);
    faces.extend(hand_faces(&boxes, hand_poses, &proj, &light));
    // Far to near; a stable sort keeps input order on ties, so the page is the same each run.
    faces.sort_by(|a, b| b.depth.total_cmp(&a.depth));
    // The planned hand's edges, and the object's silhouette where the closing started from.
    let mut dashed: Vec<Segment> = Vec::new();
    for (body, b) in &boxes {
        let Some(pose) = planned.get(*body) else {
            continue;
        };
        let c = corners(b, pose);
        for [i, j] in BOX_EDGES {
            dashed.push((proj.page(&c[i]), proj.page(&c[j]), "#1f4fbf"));
        }
    }
    if closed.is_some() && scene.shift.is_some_and(|(s, t)| s > 0.5 || t > 1.0) {
        for (a, b) in silhouette(scene.mesh, &proj.look) {
            dashed.push((proj.page(&a), proj.page(&b), "#555555"));
        }
    }
    draw(scene, view, &faces, &dashed)
}

/// The object's triangles posed by `pose`, projected and shaded (degenerate ones left out).
fn object_faces(
    mesh: &Mesh,
    pose: &BodyPose,
    proj: &Projection,
    light: &Vector3<f64>,
) -> Vec<Face> {
    let place = |p: &Point3<f64>| pose.0 + pose.1 * p.coords;
    let moved: Vec<Point3<f64>> = mesh.vertices.iter().map(place).collect();
    let mut faces = Vec::with_capacity(mesh.triangles.len());
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| {
            moved
                .get(i as usize)
                .copied()
                .unwrap_or_else(Point3::origin)
        });
        let n = (b - a).cross(&(c - a));
        let Some(n) = n.try_normalize(1e-12) else {
            continue;
        };
        faces.push(Face {
            points: vec![proj.page(&a), proj.page(&b), proj.page(&c)],
            depth: proj.depth(&Point3::from((a.coords + b.coords + c.coords) / 3.0)),
            fill: shade(&n, light, [0.82, 0.82, 0.78]),
            opacity: 1.0,
        });
    }
    faces
}

/// The faces of the hand's `boxes` at `poses`, projected and shaded: the palm blue, the
/// phalanges red.
fn hand_faces(
    boxes: &[(usize, HandBox)],
    poses: &[BodyPose],
    proj: &Projection,
    light: &Vector3<f64>,
) -> Vec<Face> {
    let mut faces = Vec::new();
    for (body, b) in boxes {
        let Some(pose) = poses.get(*body) else {
            continue;
        };
        let c = corners(b, pose);
        let base = if *body == 0 {
            [0.35, 0.55, 0.9]
        } else {
            [0.9, 0.4, 0.3]
        };
        for f in BOX_FACES {
            let pts: Vec<Point3<f64>> = f.iter().map(|&i| c[i]).collect();
            let n = (pts[1] - pts[0]).cross(&(pts[2] - pts[0]));
            let n = n.try_normalize(1e-12).unwrap_or_else(Vector3::z);
            let centre = pts.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / 4.0;
            faces.push(Face {
                points: pts.iter().map(|p| proj.page(p)).collect(),
                depth: proj.depth(&Point3::from(centre)),
                fill: shade(&n, light, base),
                opacity: 0.92,
            });
        }
    }
    faces
}

/// The mesh's silhouette edges seen along `look` (at its planned place): edges between a face
/// turned towards the viewer and one turned away, and open edges of faces turned towards it.
fn silhouette(mesh: &Mesh, look: &Vector3<f64>) -> Vec<(Point3<f64>, Point3<f64>)> {
    use std::collections::BTreeMap;
    let v = &mesh.vertices;
    let facing = |t: &[u32; 3]| -> Option<bool> {
        let [a, b, c] = t.map(|i| v.get(i as usize));
        let (a, b, c) = (a?, b?, c?);
        Some((b - a).cross(&(c - a)).dot(look) < 0.0)
    };
    let mut edges: BTreeMap<(u32, u32), (usize, usize)> = BTreeMap::new();
    for t in &mesh.triangles {
        let Some(front) = facing(t) else { continue };
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = edges.entry((a.min(b), a.max(b))).or_insert((0, 0));
            if front {
                e.0 += 1;
            } else {
                e.1 += 1;
            }
        }
    }
    edges
        .into_iter()
        .filter(|(_, (front, back))| *front > 0 && (*back > 0 || *front == 1))
        .filter_map(|((a, b), _)| Some((*v.get(a as usize)?, *v.get(b as usize)?)))
        .collect()
}

/// The page's size `[px]` and its fit of the drawing: view coordinates `[mm]` to pixels.
struct Page {
    w: f64,
    h: f64,
    top: f64,
    bottom: f64,
    scale: f64,
    centre: (f64, f64),
}

impl Page {
    /// The page that fits every face and dashed line, centred (a unit square when there is
    /// nothing to draw).
    fn fitting(faces: &[Face], dashed: &[Segment]) -> Page {
        let (mut lo, mut hi) = (
            (f64::INFINITY, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        let mut grow = |p: &(f64, f64)| {
            lo = (lo.0.min(p.0), lo.1.min(p.1));
            hi = (hi.0.max(p.0), hi.1.max(p.1));
        };
        faces.iter().flat_map(|f| &f.points).for_each(&mut grow);
        dashed.iter().for_each(|(a, b, _)| {
            grow(a);
            grow(b);
        });
        if !(lo.0.is_finite() && hi.0.is_finite()) {
            lo = (-1.0, -1.0);
            hi = (1.0, 1.0);
        }
        let (w, h): (f64, f64) = (420.0, 440.0);
        let (top, bottom): (f64, f64) = (30.0, 48.0);
        let span = (hi.0 - lo.0).max(hi.1 - lo.1).max(1e-6);
        Page {
            w,
            h,
            top,
            bottom,
            scale: (w - 20.0).min(h - top - bottom) / span,
            centre: ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0),
        }
    }

    /// The pixel of view point `p` (page y down).
    fn px(&self, p: &(f64, f64)) -> (f64, f64) {
        (
            self.w / 2.0 + (p.0 - self.centre.0) * self.scale,
            self.top + (self.h - self.top - self.bottom) / 2.0 - (p.1 - self.centre.1) * self.scale,
        )
    }
}

/// The SVG page: title, the faces, the dashed lines, a 10 mm scale bar and the legend.
fn draw(scene: &Scene, view: &View, faces: &[Face], dashed: &[Segment]) -> String {
    let page = Page::fitting(faces, dashed);
    let (w, h) = (page.w, page.h);
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\">"
    );
    let _ = write!(s, "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>");
    let _ = write!(
        s,
        "<text x=\"8\" y=\"18\" font-size=\"13\">{}</text>",
        view.title
    );
    let _ = write!(s, "<g stroke-linejoin=\"round\">");
    for f in faces {
        let pts: Vec<String> = f
            .points
            .iter()
            .map(|p| {
                let (x, y) = page.px(p);
                format!("{x:.1},{y:.1}")
            })
            .collect();
        let _ = write!(
            s,
            "<polygon points=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"0.3\" fill-opacity=\"{}\"/>",
            pts.join(" "),
            f.fill,
            f.fill,
            f.opacity
        );
    }
    let _ = write!(
        s,
        "</g><g fill=\"none\" stroke-width=\"1.2\" stroke-dasharray=\"4 3\">"
    );
    for (a, b, colour) in dashed {
        let (a, b) = (page.px(a), page.px(b));
        let _ = write!(
            s,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{colour}\"/>",
            a.0, a.1, b.0, b.1
        );
    }
    let _ = write!(s, "</g>");
    // A 10 mm scale bar.
    let bar = 10.0 * page.scale;
    let y = h - page.bottom + 14.0;
    let _ = write!(
        s,
        "<line x1=\"8\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"black\" stroke-width=\"2\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\">10 mm</text>",
        8.0 + bar,
        12.0 + bar,
        y + 4.0
    );
    let _ = write!(
        s,
        "<text x=\"8\" y=\"{:.1}\" font-size=\"10\">{}</text></svg>",
        h - 10.0,
        legend(scene)
    );
    s
}

/// The report page's one-line legend under the three views.
pub fn page_legend(scene: &Scene) -> String {
    match (scene.closed, scene.shift) {
        (Some(_), Some((shift, turn))) => format!(
            "Filled: the hand and the object where the closing left them (gravity still off); dashed blue: the planned hand; dashed grey: the object's outline before the closing (drawn when it moved). The closing shifted the object {shift:.1} mm and turned it {turn:.1} deg."
        ),
        _ => legend(scene),
    }
}

/// The views' own one-line legend: what is drawn how, and the closing's shift.
pub fn legend(scene: &Scene) -> String {
    match (scene.closed, scene.shift) {
        (Some(_), Some((shift, turn))) => format!(
            "filled: after closing; dashed: as planned; closing shift {shift:.1} mm, turn {turn:.1} deg"
        ),
        _ => "filled: the planned hand on the object (not checked in physics)".to_string(),
    }
}
