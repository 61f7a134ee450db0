//! A hand's MJCF (MuJoCo's XML) read into a [`Tree`] (issue 37).
//!
//! Read: `<compiler angle meshdir eulerseq>`, `<asset><mesh name file scale>` (STL, OBJ, PLY),
//! the `<worldbody>`'s nested `<body pos quat euler axisangle>`, one `<joint>` (hinge; `slide`,
//! `ball` and `<freejoint>` are named if a finger needs them) per body with `pos axis range`,
//! `<geom type size pos quat euler fromto mesh>` (box, sphere, cylinder, capsule, mesh; planes
//! are left out), `<equality><joint joint1 joint2 polycoef>` as a coupling and `<connect>` or
//! `<weld>` as a closed loop. Not read: `<default>` classes (a geom or joint must give its own
//! attributes) and `<include>`. Lengths are metres, angles degrees unless
//! `<compiler angle="radian">`, as MuJoCo's defaults are.

use super::import::{err, FileCoupling, Geom, GeomShape, Joint, JointKind, Link, Tree};
use super::HandError;
use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

const MM_PER_M: f64 = 1000.0;

use crate::xml_lines::line_of;

/// What the compiler settings and assets say.
struct Context<'a> {
    path: &'a Path,
    degrees: bool,
    eulerseq: String,
    /// Mesh assets by name: file and scale.
    meshes: HashMap<String, (PathBuf, Vector3<f64>)>,
}

impl Context<'_> {
    /// `n` finite numbers of attribute `attr`, or `None` when absent.
    fn numbers(
        &self,
        node: roxmltree::Node,
        attr: &str,
        n: usize,
    ) -> Result<Option<Vec<f64>>, HandError> {
        let Some(text) = node.attribute(attr) else {
            return Ok(None);
        };
        let v: Option<Vec<f64>> = text
            .split_whitespace()
            .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
            .collect();
        match v {
            Some(v) if v.len() >= n => Ok(Some(v)),
            _ => Err(err(
                self.path,
                format!(
                    "line {}: <{} {attr}=\"{text}\"> needs {n} finite number{}",
                    line_of(node),
                    node.tag_name().name(),
                    if n == 1 { "" } else { "s" }
                ),
            )),
        }
    }

    fn angle(&self, a: f64) -> f64 {
        if self.degrees {
            a.to_radians()
        } else {
            a
        }
    }

    /// The orientation `quat`, `euler` or `axisangle` give (identity without).
    fn rotation(&self, node: roxmltree::Node) -> Result<UnitQuaternion<f64>, HandError> {
        if let Some(q) = self.numbers(node, "quat", 4)? {
            let q = nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]);
            if q.norm() < 1e-12 {
                return Err(err(
                    self.path,
                    format!("line {}: a zero quat", line_of(node)),
                ));
            }
            return Ok(UnitQuaternion::from_quaternion(q));
        }
        if let Some(a) = self.numbers(node, "axisangle", 4)? {
            let axis = Vector3::new(a[0], a[1], a[2]);
            if axis.norm() < 1e-12 {
                return Err(err(
                    self.path,
                    format!("line {}: a zero axisangle axis", line_of(node)),
                ));
            }
            return Ok(UnitQuaternion::from_axis_angle(
                &Unit::new_normalize(axis),
                self.angle(a[3]),
            ));
        }
        if let Some(e) = self.numbers(node, "euler", 3)? {
            let mut q = UnitQuaternion::identity();
            for (k, c) in self.eulerseq.chars().take(3).enumerate() {
                let axis = match c.to_ascii_lowercase() {
                    'x' => Vector3::x_axis(),
                    'y' => Vector3::y_axis(),
                    _ => Vector3::z_axis(),
                };
                let r = UnitQuaternion::from_axis_angle(&axis, self.angle(e[k]));
                // Lower case: intrinsic (each turn about the turned axes); upper: extrinsic.
                q = if c.is_ascii_lowercase() { q * r } else { r * q };
            }
            return Ok(q);
        }
        Ok(UnitQuaternion::identity())
    }

    /// `pos` and the orientation, in millimetres.
    fn pose(&self, node: roxmltree::Node) -> Result<Isometry3<f64>, HandError> {
        let p = self
            .numbers(node, "pos", 3)?
            .unwrap_or_else(|| vec![0.0; 3]);
        Ok(Isometry3::from_parts(
            Translation3::new(p[0] * MM_PER_M, p[1] * MM_PER_M, p[2] * MM_PER_M),
            self.rotation(node)?,
        ))
    }
}

/// A geom, or `None` for a plane or a shape that bounds no part of the hand.
fn geom(cx: &Context, g: roxmltree::Node) -> Result<Option<Geom>, HandError> {
    let line = line_of(g);
    let kind = g.attribute("type").unwrap_or("sphere");
    let size = cx.numbers(g, "size", 1)?.unwrap_or_default();
    let need = |n: usize| -> Result<Vec<f64>, HandError> {
        if size.len() >= n && size.iter().take(n).all(|&s| s > 0.0) {
            Ok(size.iter().map(|s| s * MM_PER_M).collect())
        } else {
            Err(err(
                cx.path,
                format!("line {line}: <geom type=\"{kind}\"> needs {n} positive size values"),
            ))
        }
    };
    let mut pose = cx.pose(g)?;
    let mut half_length = None;
    if let Some(ft) = cx.numbers(g, "fromto", 6)? {
        let a = Vector3::new(ft[0], ft[1], ft[2]) * MM_PER_M;
        let b = Vector3::new(ft[3], ft[4], ft[5]) * MM_PER_M;
        let d = b - a;
        let rot = UnitQuaternion::rotation_between(&Vector3::z(), &d).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
        });
        pose = Isometry3::from_parts(Translation3::from((a + b) / 2.0), rot);
        half_length = Some(d.norm() / 2.0);
    }
    let shape = match kind {
        "box" => {
            let s = need(3)?;
            GeomShape::Box(Vector3::new(s[0], s[1], s[2]))
        }
        "sphere" => GeomShape::Sphere(need(1)?[0]),
        "cylinder" | "capsule" => {
            let s = need(if half_length.is_some() { 1 } else { 2 })?;
            let hl = half_length.unwrap_or_else(|| s[1]);
            if kind == "cylinder" {
                GeomShape::Cylinder(s[0], hl)
            } else {
                GeomShape::Capsule(s[0], hl)
            }
        }
        "mesh" => {
            let name = g.attribute("mesh").unwrap_or("");
            let Some((file, scale)) = cx.meshes.get(name) else {
                return Err(err(
                    cx.path,
                    format!("line {line}: <geom mesh=\"{name}\"> names no <mesh> of the <asset>s"),
                ));
            };
            let loaded = crate::mesh::load_mesh(file, crate::mesh::LengthUnit::M)
                .map_err(|e| err(cx.path, e.to_string()))?;
            GeomShape::Points(
                loaded
                    .mesh
                    .vertices
                    .iter()
                    .map(|v| Point3::from(v.coords.component_mul(scale)))
                    .collect(),
            )
        }
        _ => return Ok(None),
    };
    Ok(Some(Geom { shape, pose }))
}

/// The `<asset>` meshes: name → (file, scale), each file found beside the MJCF (or its meshdir).
fn assets(cx: &mut Context, root: roxmltree::Node, meshdir: &Path) -> Result<(), HandError> {
    for m in root
        .children()
        .filter(|c| c.has_tag_name("asset"))
        .flat_map(|a| a.children().filter(|c| c.has_tag_name("mesh")))
    {
        let line = line_of(m);
        let Some(file) = m.attribute("file") else {
            return Err(err(cx.path, format!("line {line}: <mesh> without a file")));
        };
        let name = m.attribute("name").map_or_else(
            || {
                Path::new(file)
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            },
            str::to_string,
        );
        let p = meshdir.join(file);
        if !p.is_file() {
            return Err(err(
                cx.path,
                format!(
                    "line {line}: mesh {file} not found (looked for {})",
                    p.display()
                ),
            ));
        }
        let s = cx.numbers(m, "scale", 3)?.unwrap_or_else(|| vec![1.0; 3]);
        cx.meshes.insert(name, (p, Vector3::new(s[0], s[1], s[2])));
    }
    Ok(())
}

/// A body's joint from its parent (a fixed one without `<joint>`).
fn body_joint(
    cx: &Context,
    b: roxmltree::Node,
    parent: usize,
    child: usize,
    name: &str,
) -> Result<Joint, HandError> {
    let joints: Vec<roxmltree::Node> = b
        .children()
        .filter(|c| c.has_tag_name("joint") || c.has_tag_name("freejoint"))
        .collect();
    let origin = cx.pose(b)?;
    let fixed = Joint {
        name: name.to_string(),
        line: line_of(b),
        kind: JointKind::Fixed,
        parent,
        child,
        origin,
        anchor: Point3::origin(),
        axis: Vector3::z_axis(),
        limits: None,
    };
    let j = match joints.as_slice() {
        [] => return Ok(fixed),
        [j] => *j,
        [_, second, ..] => {
            return Err(err(
                cx.path,
                format!(
                    "line {}: body `{name}` has {} joints: expected one hinge per body",
                    line_of(*second),
                    joints.len()
                ),
            ))
        }
    };
    let kind = match (j.tag_name().name(), j.attribute("type").unwrap_or("hinge")) {
        ("freejoint", _) => JointKind::Other("free".into()),
        (_, "hinge") => JointKind::Revolute,
        (_, other) => JointKind::Other(other.to_string()),
    };
    let p = cx.numbers(j, "pos", 3)?.unwrap_or_else(|| vec![0.0; 3]);
    let a = cx
        .numbers(j, "axis", 3)?
        .unwrap_or_else(|| vec![0.0, 0.0, 1.0]);
    let axis = Vector3::new(a[0], a[1], a[2]);
    if axis.norm() < 1e-12 {
        return Err(err(
            cx.path,
            format!("line {}: a zero joint axis", line_of(j)),
        ));
    }
    let limited = j.attribute("limited") != Some("false");
    let limits = match cx.numbers(j, "range", 2)? {
        Some(r) if limited && r[0] < r[1] => Some((cx.angle(r[0]), cx.angle(r[1]))),
        _ => None,
    };
    Ok(Joint {
        name: j.attribute("name").unwrap_or(name).to_string(),
        line: line_of(j),
        kind,
        anchor: Point3::new(p[0], p[1], p[2]) * MM_PER_M,
        axis: Unit::new_normalize(axis),
        limits,
        ..fixed
    })
}

/// Adds `b` and its descendants under link `parent`.
fn add_body(
    cx: &Context,
    b: roxmltree::Node,
    parent: usize,
    tree: &mut Tree,
) -> Result<(), HandError> {
    let index = tree.links.len();
    let name = b
        .attribute("name")
        .map_or_else(|| format!("body{index}"), str::to_string);
    let mut geoms = Vec::new();
    for g in b.children().filter(|c| c.has_tag_name("geom")) {
        geoms.extend(geom(cx, g)?);
    }
    tree.links.push(Link {
        name: name.clone(),
        line: line_of(b),
        geoms,
    });
    let j = body_joint(cx, b, parent, index, &name)?;
    tree.joints.push(j);
    for c in b.children().filter(|c| c.has_tag_name("body")) {
        add_body(cx, c, index, tree)?;
    }
    Ok(())
}

/// `<equality>`: joint couplings, and the first closed loop.
fn equality(cx: &Context, root: roxmltree::Node, tree: &mut Tree) -> Result<(), HandError> {
    for e in root
        .children()
        .filter(|c| c.has_tag_name("equality"))
        .flat_map(|e| e.children().filter(roxmltree::Node::is_element))
    {
        let line = line_of(e);
        match e.tag_name().name() {
            "joint" => {
                let c = cx
                    .numbers(e, "polycoef", 1)?
                    .unwrap_or_else(|| vec![0.0, 1.0]);
                let (Some(f), Some(l)) = (e.attribute("joint1"), e.attribute("joint2")) else {
                    continue;
                };
                if !tree.joints.iter().any(|j| j.name == l)
                    || !tree.joints.iter().any(|j| j.name == f)
                {
                    return Err(err(
                        cx.path,
                        format!("line {line}: <equality><joint> names joint `{f}` or `{l}`, which the file does not have"),
                    ));
                }
                tree.couplings.push(FileCoupling {
                    follower: f.to_string(),
                    leader: l.to_string(),
                    multiplier: c.get(1).copied().unwrap_or(0.0),
                    offset: c[0],
                    line,
                    kind: "equality",
                });
            }
            "connect" | "weld" if tree.loop_line.is_none() => {
                tree.loop_line = Some((line, format!("<equality><{}>", e.tag_name().name())));
            }
            _ => {}
        }
    }
    Ok(())
}

/// Reads a hand's MJCF into a tree.
///
/// # Errors
/// [`HandError::Parse`] naming the file and the line: unreadable, too deep, not XML, not
/// `<mujoco>`, no `<worldbody>`, a body with two joints, a mesh that is not there, malformed
/// numbers.
pub fn read(path: &Path) -> Result<Tree, HandError> {
    let text = super::import::read_xml_text(path, "an MJCF")?;
    let doc = roxmltree::Document::parse(&text)
        .map_err(|e| err(path, format!("not well-formed XML: {e}")))?;
    let _lines = crate::xml_lines::Lines::enter(&text);
    let root = doc.root_element();
    if !root.has_tag_name("mujoco") {
        return Err(err(
            path,
            format!(
                "the root element is <{}>: expected MJCF's <mujoco>",
                root.tag_name().name()
            ),
        ));
    }
    let compiler = root.children().find(|c| c.has_tag_name("compiler"));
    let attr = |a: &str| compiler.and_then(|c| c.attribute(a));
    let dir = path.parent().unwrap_or(Path::new("."));
    let meshdir = dir.join(attr("meshdir").or(attr("assetdir")).unwrap_or(""));
    let mut cx = Context {
        path,
        degrees: attr("angle") != Some("radian"),
        eulerseq: attr("eulerseq").unwrap_or("xyz").to_string(),
        meshes: HashMap::new(),
    };
    assets(&mut cx, root, &meshdir)?;
    let Some(world) = root.children().find(|c| c.has_tag_name("worldbody")) else {
        return Err(err(
            path,
            "no <worldbody>: expected the hand's bodies in one",
        ));
    };
    // The world and its bodies, counted before any is read.
    let bodies = world
        .descendants()
        .filter(|c| c.has_tag_name("body"))
        .count();
    super::import::check_link_count(path, 1 + bodies)?;
    let mut tree = Tree {
        file: path.to_path_buf(),
        name: root.attribute("model").unwrap_or("hand").to_string(),
        links: vec![Link {
            name: "world".to_string(),
            line: line_of(world),
            geoms: Vec::new(),
        }],
        joints: Vec::new(),
        couplings: Vec::new(),
        loop_line: None,
    };
    for b in world.children().filter(|c| c.has_tag_name("body")) {
        add_body(&cx, b, 0, &mut tree)?;
    }
    equality(&cx, root, &mut tree)?;
    Ok(tree)
}
