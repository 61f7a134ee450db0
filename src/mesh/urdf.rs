//! Objects described by URDF (the robot description format of ROS and pybullet, in which robotics
//! asset libraries ship most of their objects): every link's geometry, placed by its `<origin>`
//! and by the joints from the root link at their zero position, becomes one mesh.
//!
//! Per link, the `<visual>` geometry is read (the object's surface as drawn); a link whose visual
//! geometry grasp-sim cannot read (a `.dae` mesh) or that has none gives its `<collision>` geometry
//! instead, with a note. The links' `<inertial>` masses, summed, are the object's mass unless a
//! scenario gives `mass_kg` or `density_kg_m3`. Meshes are STL, OBJ or PLY, with their `scale`;
//! `box`, `cylinder` and `sphere` are made into meshes. Lengths are metres, as URDF fixes them, so
//! a scenario's `units` does not apply. `package://PKG/PATH` is looked for as `PKG/PATH` and `PATH`
//! beside the URDF and in the folders above it; `file://` names a path.
//!
//! The URDF specification: <http://wiki.ros.org/urdf/XML> (link, joint, origin `xyz`/`rpy` with
//! R = Rz(yaw)·Ry(pitch)·Rx(roll)).

use super::load::{build, load_raw, LengthUnit, LoadedMesh, MeshFormat};
use super::MeshError;
use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// One piece of geometry: what it is, and where in the URDF it sits (for messages).
#[derive(Debug, Clone)]
pub(crate) enum Shape {
    /// A mesh file (resolved) and its per-axis scale.
    Mesh(PathBuf, Vector3<f64>),
    /// A box of these edge lengths `[m]`, centred.
    Box(Vector3<f64>),
    /// A cylinder along Z, centred `[m]`: radius, length.
    Cylinder(f64, f64),
    /// A sphere `[m]`: radius.
    Sphere(f64),
}

/// A piece of geometry placed in the root link's frame.
#[derive(Debug, Clone)]
pub(crate) struct Placed {
    pub(crate) shape: Shape,
    pub(crate) pose: Isometry3<f64>,
}

pub(crate) fn urdf_err(path: &Path, detail: impl Into<String>) -> MeshError {
    MeshError::Urdf {
        path: path.to_path_buf(),
        detail: detail.into(),
    }
}

/// Numbers in an attribute: `n` of them, finite.
pub(crate) fn numbers(
    path: &Path,
    node: roxmltree::Node,
    attr: &str,
    n: usize,
) -> Result<Option<Vec<f64>>, MeshError> {
    let Some(text) = node.attribute(attr) else {
        return Ok(None);
    };
    let line = crate::xml_lines::line_of(node);
    let bad = || {
        urdf_err(
            path,
            format!(
                "line {line}: <{} {attr}=\"{text}\"> needs {n} finite number{}",
                node.tag_name().name(),
                if n == 1 { "" } else { "s" }
            ),
        )
    };
    let v: Vec<f64> = text
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<Vec<f64>>>()
        .ok_or_else(bad)?;
    if v.len() != n {
        return Err(bad());
    }
    Ok(Some(v))
}

/// The pose an `<origin>` child of `node` gives (identity without one).
pub(crate) fn origin(path: &Path, node: roxmltree::Node) -> Result<Isometry3<f64>, MeshError> {
    let Some(o) = node.children().find(|c| c.has_tag_name("origin")) else {
        return Ok(Isometry3::identity());
    };
    let xyz = numbers(path, o, "xyz", 3)?.unwrap_or_else(|| vec![0.0; 3]);
    let rpy = numbers(path, o, "rpy", 3)?.unwrap_or_else(|| vec![0.0; 3]);
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2])),
    ))
}

/// Where a mesh `filename` points, relative to the URDF at `path`.
pub(crate) fn resolve(path: &Path, filename: &str) -> Option<PathBuf> {
    let dir = path.parent().unwrap_or(Path::new("."));
    if let Some(rest) = filename.strip_prefix("file://") {
        let p = PathBuf::from(rest);
        let p = if p.is_absolute() { p } else { dir.join(p) };
        return p.is_file().then_some(p);
    }
    if let Some(rest) = filename.strip_prefix("package://") {
        let without_package = rest.split_once('/').map(|(_, r)| r);
        let mut here = Some(dir);
        while let Some(d) = here {
            for candidate in [Some(rest), without_package].into_iter().flatten() {
                let p = d.join(candidate);
                if p.is_file() {
                    return Some(p);
                }
            }
            here = d.parent().filter(|p| !p.as_os_str().is_empty());
        }
        // A relative URDF path runs out of parents at its first component: the folders above
        // that are looked in through the absolute path (so `package://` finds the same mesh
        // whether the URDF was named relatively or not).
        let absolute = std::path::absolute(dir).ok()?;
        for d in absolute.ancestors() {
            for candidate in [Some(rest), without_package].into_iter().flatten() {
                let p = d.join(candidate);
                if p.is_file() {
                    return Some(p);
                }
            }
        }
        return None;
    }
    // Anything there (a folder, a FIFO, a device) is returned, so that reading it says what it
    // is rather than "not found".
    let p = dir.join(filename);
    p.exists().then_some(p)
}

/// The geometry of one `<visual>` or `<collision>` element, or why it cannot be read.
fn geometry(path: &Path, element: roxmltree::Node) -> Result<Result<Placed, String>, MeshError> {
    let pose = origin(path, element)?;
    let Some(g) = element
        .children()
        .find(|c| c.has_tag_name("geometry"))
        .and_then(|g| g.children().find(roxmltree::Node::is_element))
    else {
        return Ok(Err("no <geometry>".to_string()));
    };
    let line = crate::xml_lines::line_of(g);
    // A shape's attributes, each of `n` lengths, all given and positive.
    let lengths = |attrs: &[(&str, usize)], want: &str| -> Result<Vec<f64>, MeshError> {
        let mut v = Vec::new();
        for &(attr, n) in attrs {
            v.extend(numbers(path, g, attr, n)?.unwrap_or_default());
        }
        let count: usize = attrs.iter().map(|a| a.1).sum();
        if v.len() == count && v.iter().all(|&x| x > 0.0) {
            Ok(v)
        } else {
            Err(urdf_err(
                path,
                format!("line {line}: <{}> needs {want}", g.tag_name().name()),
            ))
        }
    };
    let shape = match g.tag_name().name() {
        "mesh" => {
            let Some(name) = g.attribute("filename") else {
                return Err(urdf_err(
                    path,
                    format!("line {line}: <mesh> without filename"),
                ));
            };
            let scale = match g.attribute("scale").map(str::split_whitespace) {
                Some(s) if s.clone().count() == 1 => {
                    let v = numbers(path, g, "scale", 1)?.unwrap_or_default();
                    Vector3::repeat(v[0])
                }
                _ => numbers(path, g, "scale", 3)?
                    .map_or_else(|| Vector3::repeat(1.0), |v| Vector3::new(v[0], v[1], v[2])),
            };
            if scale.iter().any(|&s| s == 0.0) {
                return Err(urdf_err(
                    path,
                    format!("line {line}: mesh {name} has a scale of 0"),
                ));
            }
            // A format grasp-sim does not read (a `.dae` visual) is a note, found or not: the
            // link's collision geometry may stand in.
            if MeshFormat::from_path(Path::new(name)).is_none_or(|f| f == MeshFormat::Urdf) {
                return Ok(Err(format!(
                    "mesh {name} is not a format grasp-sim reads (STL, OBJ, PLY)"
                )));
            }
            let Some(file) = resolve(path, name) else {
                return Err(urdf_err(
                    path,
                    format!("line {line}: mesh {name} not found beside the URDF or above it"),
                ));
            };
            Shape::Mesh(file, scale)
        }
        "box" => {
            let s = lengths(&[("size", 3)], "a size of three positive lengths")?;
            Shape::Box(Vector3::new(s[0], s[1], s[2]))
        }
        "cylinder" => {
            let rl = lengths(
                &[("radius", 1), ("length", 1)],
                "a positive radius and length",
            )?;
            Shape::Cylinder(rl[0], rl[1])
        }
        "sphere" => Shape::Sphere(lengths(&[("radius", 1)], "a positive radius")?[0]),
        other => return Ok(Err(format!("<{other}> is not a geometry grasp-sim reads"))),
    };
    Ok(Ok(Placed { shape, pose }))
}

/// What one `<visual>` or `<collision>` element gives: its placed shape, or why it cannot be
/// read (a note), or the URDF's error.
pub(crate) type ElementGeometry = Result<Result<Placed, String>, MeshError>;

/// [`geometry`], for the hand reader (`crate::hand::urdf_hand`).
pub(crate) fn element_geometry(path: &Path, element: roxmltree::Node) -> ElementGeometry {
    geometry(path, element)
}

/// What a URDF gives: its geometry in the root link's frame, notes on what was read instead of
/// what, and its links' inertial masses summed `[kg]` (`None` when no link gives one).
struct Read {
    placed: Vec<Placed>,
    notes: Vec<String>,
    mass_kg: Option<f64>,
}

/// The deepest element nesting read `[levels]`: a URDF needs four or five (robot, link,
/// visual, geometry, mesh); the XML parser recurses per level, and some 5000 levels of an
/// unknown element overflowed a worker thread's stack.
pub const MAX_DEPTH: usize = 256;

/// The nesting depth of `text`'s elements where it first exceeds `limit`, found by a scan of its
/// tags that does not recurse (comments, processing instructions, declarations and CDATA
/// skipped); `None` when it stays within.
pub(crate) fn nesting_deeper_than(text: &str, limit: usize) -> Option<usize> {
    let b = text.as_bytes();
    let (mut i, mut depth) = (0usize, 0usize);
    let skip_to = |from: usize, end: &[u8]| {
        b[from..]
            .windows(end.len())
            .position(|w| w == end)
            .map_or(b.len(), |k| from + k + end.len())
    };
    while i < b.len() {
        if b[i] != b'<' {
            i += 1;
            continue;
        }
        let rest = &b[i..];
        if rest.starts_with(b"<!--") {
            i = skip_to(i + 4, b"-->");
        } else if rest.starts_with(b"<![CDATA[") {
            i = skip_to(i + 9, b"]]>");
        } else if rest.starts_with(b"<?") {
            i = skip_to(i + 2, b"?>");
        } else if rest.starts_with(b"<!") {
            i = skip_to(i + 2, b">");
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            i = skip_to(i + 2, b">");
        } else {
            let end = skip_to(i + 1, b">");
            let self_closing = end >= 2 && b[end - 2] == b'/';
            if !self_closing {
                depth += 1;
                if depth > limit {
                    return Some(depth);
                }
            }
            i = end;
        }
    }
    None
}

/// Reads a URDF: every link's geometry placed in the root link's frame, with notes and mass.
fn read(path: &Path) -> Result<Read, MeshError> {
    let text =
        crate::files::read_regular_string(path, crate::files::MAX_TEXT_BYTES).map_err(|e| {
            MeshError::Io {
                path: path.to_path_buf(),
                error: e,
            }
        })?;
    if let Some(depth) = nesting_deeper_than(&text, MAX_DEPTH) {
        return Err(urdf_err(
            path,
            format!("elements nested {depth} deep; a URDF is read to at most {MAX_DEPTH} levels"),
        ));
    }
    let doc = roxmltree::Document::parse(&text)
        .map_err(|e| urdf_err(path, format!("not well-formed XML: {e}")))?;
    let _lines = crate::xml_lines::Lines::enter(&text);
    let robot = doc.root_element();
    if !robot.has_tag_name("robot") {
        return Err(urdf_err(
            path,
            format!(
                "the root element is <{}>, not <robot>",
                robot.tag_name().name()
            ),
        ));
    }
    let links: Vec<roxmltree::Node> = robot
        .children()
        .filter(|c| c.has_tag_name("link"))
        .collect();
    if links.is_empty() {
        return Err(urdf_err(path, "no <link>"));
    }
    let names: std::collections::HashSet<&str> =
        links.iter().filter_map(|l| l.attribute("name")).collect();
    let parent = joint_parents(path, robot, &names)?;
    let mut placed = Vec::new();
    let mut notes = Vec::new();
    let mut mass_kg = None;
    for link in links {
        let name = link.attribute("name").unwrap_or("");
        if let Some(v) = link_mass(path, link, name)? {
            mass_kg = Some(mass_kg.unwrap_or(0.0) + v);
        }
        let link_pose = pose_in_root(path, &parent, name)?;
        link_geometry(path, link, name, link_pose, &mut placed, &mut notes)?;
    }
    if placed.is_empty() {
        return Err(urdf_err(
            path,
            format!(
                "no geometry grasp-sim can read (meshes in STL, OBJ or PLY; box, cylinder, \
                 sphere){}",
                if notes.is_empty() {
                    String::new()
                } else {
                    format!(": {}", notes.join("; "))
                }
            ),
        ));
    }
    Ok(Read {
        placed,
        notes,
        mass_kg,
    })
}

/// Each child link's parent link and the joint's origin, from the URDF's `<joint>`s.
///
/// # Errors
/// [`MeshError::Urdf`] naming the joint's line: no parent or child, a link that is not in the
/// file, or a child that already has a parent (a link has one parent in a tree).
fn joint_parents<'a>(
    path: &Path,
    robot: roxmltree::Node<'a, '_>,
    links: &std::collections::HashSet<&str>,
) -> Result<HashMap<&'a str, (&'a str, Isometry3<f64>)>, MeshError> {
    let mut parent: HashMap<&str, (&str, Isometry3<f64>)> = HashMap::new();
    for j in robot.children().filter(|c| c.has_tag_name("joint")) {
        let link_of = |tag: &str| {
            j.children()
                .find(|c| c.has_tag_name(tag))
                .and_then(|c| c.attribute("link"))
        };
        let (Some(p), Some(c)) = (link_of("parent"), link_of("child")) else {
            let line = crate::xml_lines::line_of(j);
            return Err(urdf_err(
                path,
                format!("line {line}: <joint> without a parent or child link"),
            ));
        };
        let line = crate::xml_lines::line_of(j);
        if let Some(missing) = [p, c].into_iter().find(|l| !links.contains(l)) {
            return Err(urdf_err(
                path,
                format!(
                    "line {line}: <joint> names link `{missing}`, which the file does not have"
                ),
            ));
        }
        if let Some((first, _)) = parent.insert(c, (p, origin(path, j)?)) {
            return Err(urdf_err(
                path,
                format!("line {line}: link `{c}` has two parents (`{first}` and `{p}`); a URDF is a tree"),
            ));
        }
    }
    Ok(parent)
}

/// The pose of link `name` in the root link's frame: its joints' origins composed up the tree.
///
/// # Errors
/// [`MeshError::Urdf`] when the joints form a loop.
fn pose_in_root(
    path: &Path,
    parent: &HashMap<&str, (&str, Isometry3<f64>)>,
    name: &str,
) -> Result<Isometry3<f64>, MeshError> {
    let mut pose = Isometry3::identity();
    let mut at = name;
    for _ in 0..=parent.len() {
        match parent.get(at) {
            Some(&(p, o)) => {
                pose = o * pose;
                at = p;
            }
            None => return Ok(pose),
        }
    }
    Err(urdf_err(
        path,
        format!("the joints form a loop through link `{name}`"),
    ))
}

/// A link's `<inertial><mass value>` `[kg]` when it is positive (`None` when absent or 0).
///
/// # Errors
/// [`MeshError::Urdf`] for a malformed or negative mass.
fn link_mass(path: &Path, link: roxmltree::Node, name: &str) -> Result<Option<f64>, MeshError> {
    let Some(m) = link
        .children()
        .find(|c| c.has_tag_name("inertial"))
        .and_then(|i| i.children().find(|c| c.has_tag_name("mass")))
    else {
        return Ok(None);
    };
    let v = numbers(path, m, "value", 1)?.map_or(0.0, |v| v[0]);
    if v < 0.0 {
        let line = crate::xml_lines::line_of(m);
        return Err(urdf_err(
            path,
            format!("line {line}: link `{name}` has a negative mass ({v} kg)"),
        ));
    }
    Ok((v > 0.0).then_some(v))
}

/// Adds a link's geometry at `link_pose` to `placed`: its visual geometry when all of it is
/// read, else its collision geometry where that is complete, else what can be read of either,
/// with a note in `notes` saying what was used instead of what.
fn link_geometry(
    path: &Path,
    link: roxmltree::Node,
    name: &str,
    link_pose: Isometry3<f64>,
    placed: &mut Vec<Placed>,
    notes: &mut Vec<String>,
) -> Result<(), MeshError> {
    let read_all = |tag: &str| -> Result<(Vec<Placed>, Vec<String>), MeshError> {
        let mut ok = Vec::new();
        let mut why = Vec::new();
        for e in link.children().filter(|c| c.has_tag_name(tag)) {
            match geometry(path, e)? {
                Ok(p) => ok.push(Placed {
                    pose: link_pose * p.pose,
                    ..p
                }),
                Err(w) => why.push(w),
            }
        }
        Ok((ok, why))
    };
    let (visual, visual_why) = read_all("visual")?;
    if visual_why.is_empty() && !visual.is_empty() {
        placed.extend(visual);
        return Ok(());
    }
    let (collision, collision_why) = read_all("collision")?;
    if !visual_why.is_empty() && !collision.is_empty() && collision_why.is_empty() {
        notes.push(format!(
            "link `{name}`: its visual {}; its collision geometry is used",
            visual_why.join(", ")
        ));
        placed.extend(collision);
    } else if !visual.is_empty() {
        notes.push(format!(
            "link `{name}`: part of its visual geometry is left out: {}",
            visual_why.join(", ")
        ));
        placed.extend(visual);
    } else if !collision.is_empty() {
        if !collision_why.is_empty() {
            notes.push(format!(
                "link `{name}`: part of its collision geometry is left out: {}",
                collision_why.join(", ")
            ));
        }
        placed.extend(collision);
    } else if !visual_why.is_empty() || !collision_why.is_empty() {
        notes.push(format!(
            "link `{name}`: no geometry read: {}",
            visual_why
                .iter()
                .chain(&collision_why)
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    Ok(())
}

/// The mesh files a URDF names, as far as they can be found: what decides its object besides
/// the URDF itself (a batch's input hash reads them).
pub fn referenced_files(path: &Path) -> Vec<PathBuf> {
    read(path)
        .map(|r| {
            r.placed
                .into_iter()
                .filter_map(|p| match p.shape {
                    Shape::Mesh(f, _) => Some(f),
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default()
}

/// Triangles of a primitive in metres, centred on its frame.
fn primitive(shape: &Shape) -> Vec<[[f64; 3]; 3]> {
    use super::primitives as objects;
    let mm = |m: f64| m * 1000.0;
    let mut mesh = match *shape {
        Shape::Box(s) => {
            let mut m = objects::prism(mm(s.x), mm(s.y), mm(s.z));
            m.map_vertices(|p| p - Vector3::new(0.0, 0.0, mm(s.z) / 2.0));
            m
        }
        Shape::Cylinder(r, l) => {
            let mut m = objects::cylinder(mm(2.0 * r), mm(l));
            m.map_vertices(|p| p - Vector3::new(0.0, 0.0, mm(l) / 2.0));
            m
        }
        Shape::Sphere(r) => objects::uv_sphere(mm(r), 48),
        Shape::Mesh(..) => unreachable!("a mesh is loaded from its file"),
    };
    mesh.map_vertices(|p| p / 1000.0);
    mesh.triangles
        .iter()
        .map(|t| t.map(|i| mesh.vertices[i as usize].coords.into()))
        .collect()
}

/// The most triangles a URDF object's links may make together: 2,000,000, counted as each
/// link's geometry is made or read, before the next. A few kilobytes of URDF can name tens of
/// thousands of primitives (a box is made of 576 triangles) or one large mesh many times: 60,000
/// boxes, 13 MB, made 35 million triangles and took more than 10 GB before this bound. The
/// bound keeps the load, the planner and the check within a few GB.
pub const MAX_URDF_TRIANGLES: usize = 2_000_000;

/// Loads the object a URDF describes: its links' geometry as one mesh, in millimetres.
///
/// # Errors
/// [`MeshError::Urdf`] for XML that is not a URDF, a mesh that cannot be found, malformed
/// numbers or no readable geometry; a referenced mesh's own errors name that mesh.
pub fn load_urdf(path: &Path) -> Result<LoadedMesh, MeshError> {
    let Read {
        placed,
        notes,
        mass_kg,
    } = read(path)?;
    // Placed in millimetres (a file in millimetres at scale 0.001 keeps its very coordinates),
    // then welded, repaired and validated as one mesh.
    let mut raw: Vec<[[f32; 3]; 3]> = Vec::new();
    for p in &placed {
        let (triangles, scale) = match &p.shape {
            Shape::Mesh(file, scale) => {
                // The mesh's own error names the mesh; say which URDF asked for it too.
                let (t, _) = load_raw(file).map_err(|e| urdf_err(path, e.to_string()))?;
                let t: Vec<[[f64; 3]; 3]> = t
                    .into_iter()
                    .map(|tri| tri.map(|v| v.map(f64::from)))
                    .collect();
                (t, *scale)
            }
            s => (primitive(s), Vector3::repeat(1.0)),
        };
        if raw.len() + triangles.len() > MAX_URDF_TRIANGLES {
            return Err(urdf_err(
                path,
                format!(
                    "its links' geometry makes more than {MAX_URDF_TRIANGLES} triangles (the \
                     first {} of its {} pieces of geometry make {}): a URDF object is read up \
                     to that many",
                    placed.iter().position(|q| std::ptr::eq(q, p)).unwrap_or(0) + 1,
                    placed.len(),
                    raw.len() + triangles.len()
                ),
            ));
        }
        // A mirroring scale turns the winding inside out: swap it back.
        let mirrored = scale.x * scale.y * scale.z < 0.0;
        let at = |v: [f64; 3]| -> [f32; 3] {
            let q = p.pose * Point3::from(Vector3::from(v).component_mul(&scale));
            [
                (q.x * 1000.0) as f32,
                (q.y * 1000.0) as f32,
                (q.z * 1000.0) as f32,
            ]
        };
        for t in triangles {
            let (b, c) = if mirrored { (t[2], t[1]) } else { (t[1], t[2]) };
            raw.push([at(t[0]), at(b), at(c)]);
        }
    }
    let mut loaded = build(raw, path, LengthUnit::Mm, false, MeshFormat::Urdf)?;
    loaded.unit = LengthUnit::M;
    loaded.notes = notes;
    loaded.mass_kg = mass_kg;
    Ok(loaded)
}
