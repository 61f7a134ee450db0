//! A hand's URDF read into a [`Tree`] (issue 37), with the object reader's XML handling
//! (`crate::mesh::urdf`: the depth limit, `package://` and `file://`, shapes and meshes, line
//! numbers in errors).
//!
//! Per link, its `<collision>` geometry (what touches), or its `<visual>` geometry when it has
//! none. Joints: `revolute` and `continuous` turn, `fixed` is rigid, anything else is named in
//! the error if a finger needs it. `<mimic>` is a coupling. Lengths are metres (URDF's), read
//! into millimetres.

use super::import::{err, FileCoupling, Geom, GeomShape, Joint, JointKind, Link, Tree};
use super::HandError;
use crate::mesh::urdf::{element_geometry, numbers, origin, Shape};
use crate::mesh::MeshError;
use nalgebra::{Isometry3, Point3, Translation3, Unit, Vector3};
use std::path::Path;

/// Metres to millimetres.
const MM_PER_M: f64 = 1000.0;

/// A mesh error as a hand file's: the URDF's own message stays one line naming the URDF.
fn from_mesh(path: &Path, e: MeshError) -> HandError {
    match e {
        MeshError::Urdf { detail, .. } => err(path, detail),
        other => err(path, other.to_string()),
    }
}

use crate::xml_lines::line_of;

/// A pose in metres as one in millimetres.
fn to_mm(p: Isometry3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(p.translation.vector * MM_PER_M),
        p.rotation,
    )
}

/// A shape of the object reader in millimetres (a mesh's vertices loaded and scaled).
pub(super) fn shape_mm(path: &Path, shape: &Shape) -> Result<GeomShape, HandError> {
    Ok(match shape {
        Shape::Box(s) => GeomShape::Box(s * (MM_PER_M / 2.0)),
        Shape::Cylinder(r, l) => GeomShape::Cylinder(r * MM_PER_M, l * MM_PER_M / 2.0),
        Shape::Sphere(r) => GeomShape::Sphere(r * MM_PER_M),
        Shape::Mesh(file, scale) => {
            let loaded = crate::mesh::load_mesh(file, crate::mesh::LengthUnit::M)
                .map_err(|e| from_mesh(path, e))?;
            GeomShape::Points(
                loaded
                    .mesh
                    .vertices
                    .iter()
                    .map(|v| Point3::from(v.coords.component_mul(scale)))
                    .collect(),
            )
        }
    })
}

/// A link's geometry: its collision elements, or its visual ones when it has none.
fn link_geoms(path: &Path, link: roxmltree::Node) -> Result<Vec<Geom>, HandError> {
    for tag in ["collision", "visual"] {
        let mut out = Vec::new();
        for e in link.children().filter(|c| c.has_tag_name(tag)) {
            match element_geometry(path, e).map_err(|e| from_mesh(path, e))? {
                Ok(placed) => out.push(Geom {
                    shape: shape_mm(path, &placed.shape)?,
                    pose: to_mm(placed.pose),
                }),
                // A `.dae` or an unknown shape: the other element kind may stand in.
                Err(_) => continue,
            }
        }
        if !out.is_empty() {
            return Ok(out);
        }
    }
    Ok(Vec::new())
}

/// A `<limit>`'s `(lower, upper)` `[rad]`, `None` when they leave no range.
fn limit(path: &Path, l: roxmltree::Node) -> Result<Option<(f64, f64)>, HandError> {
    let get = |a: &str| numbers(path, l, a, 1).map_err(|e| from_mesh(path, e));
    let lo = get("lower")?.map_or(0.0, |v| v[0]);
    let hi = get("upper")?.map_or(0.0, |v| v[0]);
    // Reversed limits are a mistake to name, not a joint without limits (issue 56).
    if lo > hi {
        return Err(err(
            path,
            format!(
                "line {}: <limit> lower=\"{lo}\" is above upper=\"{hi}\" (radians): the limits are reversed; swap them",
                line_of(l)
            ),
        ));
    }
    Ok((lo < hi).then_some((lo, hi)))
}

/// A `<mimic>` of joint `name`.
fn mimic(path: &Path, m: roxmltree::Node, name: &str) -> Result<FileCoupling, HandError> {
    let get = |a: &str, d: f64| -> Result<f64, HandError> {
        Ok(numbers(path, m, a, 1)
            .map_err(|e| from_mesh(path, e))?
            .map_or(d, |v| v[0]))
    };
    Ok(FileCoupling {
        follower: name.to_string(),
        leader: m.attribute("joint").unwrap_or("").to_string(),
        multiplier: get("multiplier", 1.0)?,
        offset: get("offset", 0.0)?,
        line: line_of(m),
        kind: "mimic",
    })
}

/// One `<joint>`.
fn joint(
    path: &Path,
    j: roxmltree::Node,
    links: &[Link],
    couplings: &mut Vec<FileCoupling>,
) -> Result<Joint, HandError> {
    let line = line_of(j);
    let name = j.attribute("name").unwrap_or("").to_string();
    let link_of = |tag: &str| {
        j.children()
            .find(|c| c.has_tag_name(tag))
            .and_then(|c| c.attribute("link"))
    };
    let (Some(p), Some(c)) = (link_of("parent"), link_of("child")) else {
        return Err(err(
            path,
            format!("line {line}: joint `{name}` has no parent or child link: expected both"),
        ));
    };
    let index = |l: &str| {
        links.iter().position(|k| k.name == l).ok_or_else(|| {
            err(
                path,
                format!(
                    "line {line}: joint `{name}` names link `{l}`, which the file does not have"
                ),
            )
        })
    };
    let kind = match j.attribute("type").unwrap_or("") {
        "revolute" | "continuous" => JointKind::Revolute,
        "fixed" => JointKind::Fixed,
        other => JointKind::Other(other.to_string()),
    };
    let child = |tag: &str| j.children().find(|c| c.has_tag_name(tag));
    let axis = match child("axis") {
        Some(a) => numbers(path, a, "xyz", 3)
            .map_err(|e| from_mesh(path, e))?
            .unwrap_or_else(|| vec![1.0, 0.0, 0.0]),
        None => vec![1.0, 0.0, 0.0],
    };
    let axis = Vector3::new(axis[0], axis[1], axis[2]);
    if kind == JointKind::Revolute && axis.norm() < 1e-9 {
        return Err(err(
            path,
            format!("line {line}: joint `{name}` has a zero axis"),
        ));
    }
    let limits = match (child("limit"), j.attribute("type")) {
        (Some(l), Some("revolute")) => limit(path, l)?,
        _ => None,
    };
    if let Some(m) = child("mimic") {
        couplings.push(mimic(path, m, &name)?);
    }
    let (parent, child) = (index(p)?, index(c)?);
    Ok(Joint {
        name,
        line,
        kind,
        parent,
        child,
        origin: to_mm(origin(path, j).map_err(|e| from_mesh(path, e))?),
        anchor: Point3::origin(),
        axis: Unit::new_normalize(if axis.norm() < 1e-9 {
            Vector3::x()
        } else {
            axis
        }),
        limits,
    })
}

/// Reads a hand's URDF into a tree.
///
/// # Errors
/// [`HandError::Parse`] naming the file and the line: unreadable, too deep, not XML, not a
/// `<robot>`, a joint without links or naming a missing one, a link with two parents, a mesh
/// that is not there, malformed numbers.
pub fn read(path: &Path) -> Result<Tree, HandError> {
    let text = super::import::read_xml_text(path, "a URDF")?;
    let doc = roxmltree::Document::parse(&text)
        .map_err(|e| err(path, format!("not well-formed XML: {e}")))?;
    let _lines = crate::xml_lines::Lines::enter(&text);
    let robot = doc.root_element();
    if !robot.has_tag_name("robot") {
        return Err(err(
            path,
            format!(
                "the root element is <{}>: expected a URDF's <robot>",
                robot.tag_name().name()
            ),
        ));
    }
    let count = robot.children().filter(|c| c.has_tag_name("link")).count();
    super::import::check_link_count(path, count)?;
    let mut links = Vec::new();
    for l in robot.children().filter(|c| c.has_tag_name("link")) {
        links.push(Link {
            name: l.attribute("name").unwrap_or("").to_string(),
            line: line_of(l),
            geoms: link_geoms(path, l)?,
        });
    }
    let mut joints: Vec<Joint> = Vec::new();
    let mut couplings = Vec::new();
    for j in robot.children().filter(|c| c.has_tag_name("joint")) {
        let jt = joint(path, j, &links, &mut couplings)?;
        if let Some(first) = joints.iter().find(|k| k.child == jt.child) {
            return Err(err(
                path,
                format!(
                    "line {}: link `{}` has two parent joints (`{}` and `{}`): a closed loop; \
                     expected a tree of links",
                    jt.line, links[jt.child].name, first.name, jt.name
                ),
            ));
        }
        joints.push(jt);
    }
    for c in &couplings {
        if !joints.iter().any(|j| j.name == c.leader) {
            return Err(err(
                path,
                format!(
                    "line {}: joint `{}` mimics joint `{}`, which the file does not have",
                    c.line, c.follower, c.leader
                ),
            ));
        }
    }
    Ok(Tree {
        file: path.to_path_buf(),
        name: robot.attribute("name").unwrap_or("hand").to_string(),
        links,
        joints,
        couplings,
        loop_line: None,
    })
}
