//! A hand read from its URDF or MJCF (issue 37): the file's kinematic tree, the mapping of its
//! joints onto grasp-sim's hand model (three fingers of two flexion joints, the thumb opposing
//! the other two), and the model derived from it.
//!
//! Units: the tree is held in millimetres and radians (the readers convert); the derived model
//! is a regular [`Hand`] in millimetres and degrees.
//!
//! The derivation, in the palm link's frame with every flexion joint at 0 and every spread joint
//! at its mapping value:
//! - the palm frame's z is the flexion axes' common direction; the thumb is the finger that
//!   closes the other way about it; y runs from the thumb's joint-1 axis to the other two's,
//!   x = y × z points away from the object; the contact surface is the palm geometry's face at
//!   its smallest x, and the palm centre the middle of its extent;
//! - per finger: joint 1's place (setback, lateral), its height (the middle of phalanx 1's
//!   geometry along z), phalanx 1's length (joint 1 to joint 2 in the flexion plane), phalanx
//!   2's (from joint 2 along the direction of its geometry's centroid to the geometry's farthest
//!   extent), the interior angles at the file's zero and the sense in which each joint closes,
//!   so that the file's limits become the model's interior-angle ranges;
//! - the finger offset is phalanx 1's geometry from its centreline to its contact face; the
//!   width its extent along z (reported; the model's section is square);
//! - what no file says (unusable lengths, tip thickness) takes the thesis hand's proportions:
//!   5/61 of phalanx 1 at each end, 2/20 of phalanx 2 next to joint 2, a tip 4/7 of the offset.
//!   A scenario's `[hand] overrides` set them.
//!
//! The model is one finger geometry for three fingers: where the fingers differ, the mean is
//! used and the difference is a note.

use super::{Coupling, Hand, HandError};
use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A piece of link geometry in its link's frame `[mm]`.
#[derive(Debug, Clone)]
pub struct Geom {
    /// What it is.
    pub shape: GeomShape,
    /// Where it is in its link's frame.
    pub pose: Isometry3<f64>,
}

/// The shapes a hand file's geometry may have `[mm]`.
#[derive(Debug, Clone)]
pub enum GeomShape {
    /// A box of these half extents.
    Box(Vector3<f64>),
    /// A cylinder along z: radius, half length.
    Cylinder(f64, f64),
    /// A capsule along z: radius, half length of its cylinder.
    Capsule(f64, f64),
    /// A sphere: radius.
    Sphere(f64),
    /// A mesh's vertices, scaled.
    Points(Vec<Point3<f64>>),
}

/// A link (URDF) or body (MJCF).
#[derive(Debug, Clone)]
pub struct Link {
    /// Its name.
    pub name: String,
    /// Its line in the file.
    pub line: u32,
    /// Its collision geometry (or its visual geometry when it has none).
    pub geoms: Vec<Geom>,
}

/// How a joint moves.
#[derive(Debug, Clone, PartialEq)]
pub enum JointKind {
    /// Rigid.
    Fixed,
    /// A revolute (or hinge, or continuous) joint.
    Revolute,
    /// Anything else (prismatic, ball, free, floating, planar), by its file's name.
    Other(String),
}

/// A joint from a parent link to a child link.
#[derive(Debug, Clone)]
pub struct Joint {
    /// Its name (an MJCF body without a joint gets `<body>`'s name and [`JointKind::Fixed`]).
    pub name: String,
    /// Its line.
    pub line: u32,
    /// How it moves.
    pub kind: JointKind,
    /// Parent link (index).
    pub parent: usize,
    /// Child link (index).
    pub child: usize,
    /// The child frame in the parent's at the joint's zero `[mm]`.
    pub origin: Isometry3<f64>,
    /// A point of the axis in the child frame `[mm]` (URDF: the origin).
    pub anchor: Point3<f64>,
    /// The axis in the child frame.
    pub axis: Unit<Vector3<f64>>,
    /// Its limits `[rad]`, if it has any.
    pub limits: Option<(f64, f64)>,
}

/// A coupling the file states: `follower = multiplier × leader + offset` (URDF `mimic`, MJCF
/// `<equality><joint>`), in the file's joint values `[rad]`.
#[derive(Debug, Clone)]
pub struct FileCoupling {
    /// The joint that follows.
    pub follower: String,
    /// The joint it follows.
    pub leader: String,
    /// The multiplier.
    pub multiplier: f64,
    /// The offset `[rad]`.
    pub offset: f64,
    /// Where the file states it.
    pub line: u32,
    /// `mimic` or `equality`.
    pub kind: &'static str,
}

/// A hand file read into a tree.
#[derive(Debug, Clone)]
pub struct Tree {
    /// The file.
    pub file: PathBuf,
    /// The robot's (model's) name.
    pub name: String,
    /// Links or bodies; index 0 is not special.
    pub links: Vec<Link>,
    /// Joints.
    pub joints: Vec<Joint>,
    /// Couplings.
    pub couplings: Vec<FileCoupling>,
    /// A closed loop the file states (an MJCF `connect` or `weld`), by its line.
    pub loop_line: Option<(u32, String)>,
}

/// The `[hand.mapping]` section of a scenario: which link is the palm, which joints flex which
/// finger, where the spread joints are held. Everything is optional: what is left out is found
/// from the tree.
#[derive(Debug, Clone, Default, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Mapping {
    /// The palm link (or body).
    pub palm: Option<String>,
    /// finger_1's joints 1 and 2.
    pub finger_1: Option<[String; 2]>,
    /// The thumb's (finger_2's) joints 1 and 2.
    #[serde(alias = "finger_2")]
    pub thumb: Option<[String; 2]>,
    /// finger_3's joints 1 and 2.
    pub finger_3: Option<[String; 2]>,
    /// Spread joints and the value each is held at `[deg]` (default 0).
    #[serde(default)]
    pub spread: BTreeMap<String, f64>,
}

/// What deriving found besides the model: for `hand show` and the run's notes.
#[derive(Debug, Clone)]
pub struct Derived {
    /// The model.
    pub hand: Hand,
    /// The palm link.
    pub palm: String,
    /// Per finger (model order): its joints 1 and 2 and its spread joint, if any.
    pub joints: Vec<([String; 2], Option<String>)>,
    /// Couplings, said in words.
    pub couplings: Vec<String>,
    /// What a user should know (differences between fingers, clamped ranges, defaults).
    pub notes: Vec<String>,
    /// Every body's geometry points in the model's palm frame at the file's zero `[mm]`, with
    /// the body's role (`palm`, a finger's `name/1` or `name/2`, `spread`, `other`).
    pub bodies: Vec<(String, Vec<Point3<f64>>)>,
    /// Per finger: the joint values `[deg]` at the file's zero (interior angles θ1, θ2).
    pub zero_theta_deg: Vec<[f64; 2]>,
}

/// A hand file's text, read as a regular file under the text cap and refused when its elements
/// nest deeper than the URDF reader's limit; `kind` names the format in the message (`a URDF`).
pub(crate) fn read_xml_text(path: &Path, kind: &str) -> Result<String, HandError> {
    use crate::mesh::urdf::{nesting_deeper_than, MAX_DEPTH};
    let text =
        crate::files::read_regular_string(path, crate::files::MAX_TEXT_BYTES).map_err(|e| {
            HandError::Io {
                path: path.to_path_buf(),
                error: e,
            }
        })?;
    if let Some(depth) = nesting_deeper_than(&text, MAX_DEPTH) {
        return Err(err(
            path,
            format!("elements nested {depth} deep; {kind} is read to at most {MAX_DEPTH} levels"),
        ));
    }
    Ok(text)
}

/// Refuses a hand of more than [`MAX_HAND_LINKS`] links: checked by the readers before any
/// link is read, as the file's elements are counted, and again on the tree.
pub(crate) fn check_link_count(path: &Path, links: usize) -> Result<(), HandError> {
    if links > MAX_HAND_LINKS {
        return Err(err(
            path,
            format!("{links} links, more than the {MAX_HAND_LINKS} a hand may have"),
        ));
    }
    Ok(())
}

pub(crate) fn err(path: &Path, message: impl Into<String>) -> HandError {
    HandError::Parse {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Sample points of a shape in its own frame, enough for its extents along any direction to
/// within 1.5 % (a box's corners exactly).
fn shape_points(shape: &GeomShape) -> Vec<Point3<f64>> {
    let ring = |r: f64, z: f64, out: &mut Vec<Point3<f64>>| {
        for k in 0..32 {
            let a = f64::from(k) * std::f64::consts::TAU / 32.0;
            out.push(Point3::new(r * a.cos(), r * a.sin(), z));
        }
    };
    let mut out = Vec::new();
    match shape {
        GeomShape::Box(h) => {
            for k in 0..8 {
                let s = |bit: i32| if k & bit == 0 { -1.0 } else { 1.0 };
                out.push(Point3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z));
            }
        }
        GeomShape::Cylinder(r, hl) => {
            ring(*r, -hl, &mut out);
            ring(*r, *hl, &mut out);
        }
        GeomShape::Sphere(r) | GeomShape::Capsule(r, _) => {
            let hl = match shape {
                GeomShape::Capsule(_, hl) => *hl,
                _ => 0.0,
            };
            for k in 0..=8 {
                let polar = f64::from(k) * std::f64::consts::PI / 8.0;
                let (z, rr) = (r * polar.cos(), r * polar.sin());
                let shift = if z >= 0.0 { hl } else { -hl };
                ring(rr, z + shift, &mut out);
                if k == 4 && hl > 0.0 {
                    ring(rr, -hl, &mut out);
                }
            }
        }
        GeomShape::Points(p) => out.clone_from(p),
    }
    out
}

/// The most links a hand's URDF or MJCF may have: a hand is tens of links (the bundled BH8 has
/// 11); thousands behind fixed joints (issue 56) are no hand.
pub const MAX_HAND_LINKS: usize = 2000;

impl Tree {
    /// For each link, the joint whose child it is (the first, as the file lists them): a
    /// table built once per walk, so that the walks are linear in the tree's size (each was a
    /// scan of every joint per link, and the paths to every link cubic in their number:
    /// thousands of fixed links, issue 56).
    fn parents(&self) -> Vec<Option<usize>> {
        let mut out = vec![None; self.links.len()];
        for (k, j) in self.joints.iter().enumerate() {
            if let Some(slot) = out.get_mut(j.child) {
                slot.get_or_insert(k);
            }
        }
        out
    }

    /// For each link, the joints whose parent it is, in file order.
    fn children(&self) -> Vec<Vec<usize>> {
        let mut out = vec![Vec::new(); self.links.len()];
        for (k, j) in self.joints.iter().enumerate() {
            if let Some(list) = out.get_mut(j.parent) {
                list.push(k);
            }
        }
        out
    }

    /// The joint named `name`.
    fn joint_named(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The links reached from `link` through fixed joints only, `link` first.
    fn rigid_subtree(&self, link: usize) -> Vec<usize> {
        let children = self.children();
        let mut out = vec![link];
        let mut k = 0;
        while k < out.len() {
            let at = out[k];
            for &j in children.get(at).map(Vec::as_slice).unwrap_or_default() {
                if self.joints[j].kind == JointKind::Fixed {
                    out.push(self.joints[j].child);
                }
            }
            k += 1;
        }
        out
    }

    /// The movable joints leaving the rigid body of `links`.
    fn movable_from(&self, links: &[usize]) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&j| {
                self.joints[j].kind != JointKind::Fixed && links.contains(&self.joints[j].parent)
            })
            .collect()
    }

    /// The root link: the one link without a parent joint.
    ///
    /// # Errors
    /// None (every link has a parent: a loop) or several roots.
    fn root(&self) -> Result<usize, HandError> {
        let parents = self.parents();
        let roots: Vec<usize> = (0..self.links.len())
            .filter(|&l| parents[l].is_none())
            .collect();
        match roots.as_slice() {
            [r] => Ok(*r),
            [] => Err(err(
                &self.file,
                "the joints form a loop (every link has a parent): expected a tree of links",
            )),
            [a, b, ..] => Err(err(
                &self.file,
                format!(
                    "line {}: links `{}` and `{}` both have no parent: expected one tree (a \
                     hand mounted on one root link)",
                    self.links[*b].line, self.links[*a].name, self.links[*b].name
                ),
            )),
        }
    }

    /// The chain of links from the root to `link` (root first), or a loop error.
    fn path_to(&self, link: usize) -> Result<Vec<usize>, HandError> {
        let parents = self.parents();
        let mut out = vec![link];
        let mut on_path = std::collections::HashSet::from([link]);
        let mut at = link;
        while let Some(j) = parents.get(at).copied().flatten() {
            at = self.joints[j].parent;
            if !on_path.insert(at) {
                return Err(err(
                    &self.file,
                    format!(
                        "line {}: the joints form a loop through link `{}`: expected a tree",
                        self.joints[j].line, self.links[at].name
                    ),
                ));
            }
            out.push(at);
        }
        out.reverse();
        Ok(out)
    }
}

/// The pose of every link in the frame of link `base` with the joints at `q` (by joint index,
/// 0 where absent), following the tree from `base` down (links not below it are left `None`).
fn poses_below(tree: &Tree, base: usize, q: &BTreeMap<usize, f64>) -> Vec<Option<Isometry3<f64>>> {
    let mut pose = vec![None; tree.links.len()];
    pose[base] = Some(Isometry3::identity());
    let children = tree.children();
    let mut stack = vec![base];
    while let Some(at) = stack.pop() {
        let Some(p) = pose[at] else { continue };
        for &k in &children[at] {
            let j = &tree.joints[k];
            if pose[j.child].is_some() {
                continue;
            }
            let value = q.get(&k).copied().unwrap_or(0.0);
            let turn = if j.kind == JointKind::Revolute {
                let a = Translation3::from(j.anchor.coords);
                a * UnitQuaternion::from_axis_angle(&j.axis, value) * a.inverse()
            } else {
                Isometry3::identity()
            };
            pose[j.child] = Some(p * j.origin * turn);
            stack.push(j.child);
        }
    }
    pose
}

/// One finger as the tree has it.
struct Chain {
    /// Joint 1 and joint 2 (indices).
    flex: [usize; 2],
    /// The spread joint at its base, if any.
    spread: Option<usize>,
    /// The mapping's slot that names it (0 finger_1, 1 the thumb, 2 finger_3), if one does.
    slot: Option<usize>,
}

/// True if and only if the axes of joints `a` and `b` are parallel (either sense) within 1°, at
/// the poses given.
fn parallel(tree: &Tree, pose: &[Option<Isometry3<f64>>], a: usize, b: usize) -> bool {
    let dir = |j: usize| {
        let jt = &tree.joints[j];
        pose[jt.child].map(|p| p.rotation * jt.axis.into_inner())
    };
    match (dir(a), dir(b)) {
        (Some(x), Some(y)) => x.cross(&y).norm() < 1f64.to_radians().sin(),
        _ => false,
    }
}

/// The palm link and the joints that start the fingers on it.
///
/// # Errors
/// No movable joint, a named palm link the file does not have.
fn find_palm(tree: &Tree, mapping: &Mapping) -> Result<(usize, Vec<usize>), HandError> {
    if let Some(name) = &mapping.palm {
        let Some(p) = tree.links.iter().position(|l| &l.name == name) else {
            return Err(err(
                &tree.file,
                format!("[hand.mapping] palm = \"{name}\": the file has no link of that name"),
            ));
        };
        return Ok((p, tree.movable_from(&tree.rigid_subtree(p))));
    }
    let mut at = tree.root()?;
    loop {
        let body = tree.rigid_subtree(at);
        let starts = tree.movable_from(&body);
        match starts.len() {
            0 => {
                return Err(err(
                    &tree.file,
                    format!(
                        "no movable joint below link `{}`: expected a hand of three fingers \
                         with two revolute joints each",
                        tree.links[at].name
                    ),
                ))
            }
            // A wrist or a free joint in front of the palm: held at 0.
            1 => at = tree.joints[starts[0]].child,
            _ => {
                // The palm is the deepest link of this rigid body above every finger.
                let paths: Vec<Vec<usize>> = starts
                    .iter()
                    .map(|&j| tree.path_to(tree.joints[j].parent))
                    .collect::<Result<_, _>>()?;
                let mut palm = at;
                for (k, l) in paths[0].iter().enumerate() {
                    if paths.iter().all(|p| p.get(k) == Some(l)) {
                        palm = *l;
                    }
                }
                return Ok((palm, starts));
            }
        }
    }
}

/// Follows a finger from its first joint: the chain of movable joints to its tip.
///
/// # Errors
/// A fork, more than three or fewer than two joints, a joint that is not revolute, a finger
/// whose first two joints are not parallel but whose last two are not either.
fn follow_chain(tree: &Tree, start: usize) -> Result<Vec<usize>, HandError> {
    let mut chain = vec![start];
    loop {
        let last = *chain.last().unwrap_or(&start);
        let body = tree.rigid_subtree(tree.joints[last].child);
        let next = tree.movable_from(&body);
        match next.as_slice() {
            [] => break,
            [j] => chain.push(*j),
            many => {
                let names: Vec<&str> = many.iter().map(|&j| tree.joints[j].name.as_str()).collect();
                return Err(err(
                    &tree.file,
                    format!(
                        "line {}: the finger of joint `{}` forks at link `{}` (joints {}): \
                         expected a chain of two flexion joints per finger",
                        tree.joints[many[1]].line,
                        tree.joints[start].name,
                        tree.links[tree.joints[last].child].name,
                        names.join(", ")
                    ),
                ));
            }
        }
        if chain.len() > 8 {
            break;
        }
    }
    for &j in &chain {
        if let JointKind::Other(kind) = &tree.joints[j].kind {
            return Err(err(
                &tree.file,
                format!(
                    "line {}: joint `{}` is {kind}: expected revolute finger joints",
                    tree.joints[j].line, tree.joints[j].name
                ),
            ));
        }
    }
    Ok(chain)
}

/// Splits a finger's chain into its spread joint and its two flexion joints (auto mapping).
fn classify_chain(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    chain: &[usize],
) -> Result<Chain, HandError> {
    let names = || {
        chain
            .iter()
            .map(|&j| format!("`{}`", tree.joints[j].name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let line = tree.joints[chain[0]].line;
    match *chain {
        [a, b] => Ok(Chain {
            flex: [a, b],
            spread: None,
            slot: None,
        }),
        [s, a, b] if !parallel(tree, pose, s, a) => Ok(Chain {
            flex: [a, b],
            spread: Some(s),
            slot: None,
        }),
        [_, _, _] => Err(err(
            &tree.file,
            format!(
                "line {line}: the finger {} has three parallel flexion joints: expected two \
                 (and an optional spread joint at its base); name two in [hand.mapping]",
                names()
            ),
        )),
        _ => Err(err(
            &tree.file,
            format!(
                "line {line}: the finger {} has {} joints: expected two flexion joints and an \
                 optional spread joint at its base",
                names(),
                chain.len()
            ),
        )),
    }
}

/// The finger chains with the mapping's names applied: three chains, each with its flexion
/// joints and spread joint.
fn chains(
    tree: &Tree,
    mapping: &Mapping,
    starts: &[usize],
    pose: &[Option<Isometry3<f64>>],
    palm: usize,
) -> Result<Vec<Chain>, HandError> {
    if starts.len() != 3 {
        let names: Vec<&str> = starts
            .iter()
            .map(|&j| tree.joints[j].name.as_str())
            .collect();
        return Err(err(
            &tree.file,
            format!(
                "line {}: palm link `{}` carries {} fingers (joints {}): expected three",
                tree.links[palm].line,
                tree.links[palm].name,
                starts.len(),
                names.join(", ")
            ),
        ));
    }
    let raw: Vec<Vec<usize>> = starts
        .iter()
        .map(|&s| follow_chain(tree, s))
        .collect::<Result<_, _>>()?;
    let named = [&mapping.finger_1, &mapping.thumb, &mapping.finger_3];
    for pair in named.iter().flat_map(|n| n.iter()) {
        for name in pair {
            if tree.joint_named(name).is_none() {
                return Err(err(
                    &tree.file,
                    format!("[hand.mapping] names joint `{name}`, which the file does not have"),
                ));
            }
        }
    }
    let mut out = Vec::new();
    for chain in &raw {
        // A mapping that names this chain's joints decides; else the chain's shape does.
        let given = named.iter().enumerate().find_map(|(slot, n)| {
            n.as_ref()
                .filter(|pair| {
                    pair.iter()
                        .any(|name| tree.joint_named(name).is_some_and(|j| chain.contains(&j)))
                })
                .map(|pair| (slot, pair))
        });
        let c = match given {
            Some((slot, pair)) => Chain {
                slot: Some(slot),
                ..mapped_chain(tree, mapping, chain, pair)?
            },
            None => classify_chain(tree, pose, chain)?,
        };
        out.push(c);
    }
    Ok(out)
}

/// A chain whose flexion joints the mapping names: both in it, in order, and at most one other
/// joint, before joint 1 (its spread joint).
fn mapped_chain(
    tree: &Tree,
    mapping: &Mapping,
    chain: &[usize],
    pair: &[String; 2],
) -> Result<Chain, HandError> {
    let find = |name: &str| {
        tree.joint_named(name)
            .and_then(|j| chain.iter().position(|&c| c == j))
            .ok_or_else(|| {
                err(
                    &tree.file,
                    format!(
                        "[hand.mapping] joints `{}` and `{}` are not one finger's chain in the \
                         file: expected joint 1 and joint 2 of one finger",
                        pair[0], pair[1]
                    ),
                )
            })
    };
    let (a, b) = (find(&pair[0])?, find(&pair[1])?);
    if a >= b {
        return Err(err(
            &tree.file,
            format!(
                "[hand.mapping] `{}` comes after `{}` in its finger: name joint 1 first",
                pair[0], pair[1]
            ),
        ));
    }
    let mut spread = None;
    for (k, &j) in chain.iter().enumerate() {
        if k != a && k != b {
            let name = &tree.joints[j].name;
            // The one joint before joint 1 is the finger's spread joint (held at the
            // mapping's value, 0 by default); any other is a joint the model has no place for.
            if (k > a && !mapping.spread.contains_key(name)) || spread.is_some() {
                return Err(err(
                    &tree.file,
                    format!(
                        "line {}: joint `{name}` of the finger of `{}` is neither one of its two \
                         flexion joints nor its spread joint: expected one spread joint before \
                         joint 1",
                        tree.joints[j].line, pair[0]
                    ),
                ));
            }
            spread = Some(j);
        }
    }
    Ok(Chain {
        flex: [chain[a], chain[b]],
        spread,
        slot: None,
    })
}

/// The configuration the model is read at: flexion joints 0, spread joints at their mapping
/// values (and their followers where a coupling says so) `[rad]`.
fn held_values(tree: &Tree, mapping: &Mapping) -> Result<BTreeMap<usize, f64>, HandError> {
    let mut q = BTreeMap::new();
    for (name, deg) in &mapping.spread {
        let Some(j) = tree.joint_named(name) else {
            return Err(err(
                &tree.file,
                format!("[hand.mapping] spread names joint `{name}`, which the file does not have"),
            ));
        };
        q.insert(j, deg.to_radians());
    }
    for c in &tree.couplings {
        if let (Some(f), Some(l)) = (tree.joint_named(&c.follower), tree.joint_named(&c.leader)) {
            if let Some(v) = q.get(&l).copied() {
                q.entry(f).or_insert(c.multiplier * v + c.offset);
            }
        }
    }
    Ok(q)
}

/// Geometry points of the rigid body of `link` (its fixed descendants), in the frame the poses
/// are in.
pub(crate) fn points_of_body(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    link: usize,
) -> Vec<Point3<f64>> {
    let mut out = Vec::new();
    for l in tree.rigid_subtree(link) {
        let Some(p) = pose[l] else { continue };
        for g in &tree.links[l].geoms {
            out.extend(shape_points(&g.shape).iter().map(|v| p * (g.pose * v)));
        }
    }
    out
}

/// The geometry elements of the rigid body of `link`, each as its points in the frame the poses
/// are in, with whether it is a mesh (for [`super::link_geometry`]).
pub(crate) fn pieces_of_body(
    tree: &Tree,
    pose: &[Option<Isometry3<f64>>],
    link: usize,
) -> Vec<super::link_geometry::Piece> {
    let mut out = Vec::new();
    for l in tree.rigid_subtree(link) {
        let Some(p) = pose[l] else { continue };
        for g in &tree.links[l].geoms {
            let points = shape_points(&g.shape)
                .iter()
                .map(|v| p * (g.pose * v))
                .collect();
            out.push((points, matches!(g.shape, GeomShape::Points(_))));
        }
    }
    out
}

/// A finger's joints in the palm link's frame.
pub(crate) struct FingerAxes {
    /// Joint 1: a point, the axis.
    j1: (Point3<f64>, Vector3<f64>),
    /// Joint 2: a point, the axis.
    j2: (Point3<f64>, Vector3<f64>),
}

fn finger_axes(tree: &Tree, pose: &[Option<Isometry3<f64>>], c: &Chain) -> FingerAxes {
    let at = |j: usize| {
        let jt = &tree.joints[j];
        let p = pose[jt.child].unwrap_or_else(Isometry3::identity);
        (p * jt.anchor, p.rotation * jt.axis.into_inner())
    };
    FingerAxes {
        j1: at(c.flex[0]),
        j2: at(c.flex[1]),
    }
}

/// Derives the hand model from a tree.
///
/// # Errors
/// [`HandError::Parse`] naming the file (and the line where there is one) and what was
/// expected: not three fingers, a fork, a loop, a joint of the wrong kind or without limits,
/// fingers that do not flex in parallel planes, no finger opposing the others, no geometry
/// where a length must come from it; then the derived model's own validation.
pub fn derive(
    tree: &Tree,
    mapping: &Mapping,
    overrides: &[(String, f64)],
) -> Result<Derived, HandError> {
    if let Some((line, what)) = &tree.loop_line {
        return Err(err(
            &tree.file,
            format!("line {line}: {what} closes a loop: expected a tree of links (open chains)"),
        ));
    }
    check_link_count(&tree.file, tree.links.len())?;
    let parents = tree.parents();
    for l in 0..tree.links.len() {
        // The loop check of `path_to`, on the table built once.
        let mut on_path = std::collections::HashSet::from([l]);
        let mut at = l;
        while let Some(j) = parents[at] {
            at = tree.joints[j].parent;
            if !on_path.insert(at) {
                tree.path_to(l)?;
                break;
            }
        }
    }
    let (palm, starts) = find_palm(tree, mapping)?;
    let q = held_values(tree, mapping)?;
    let pose = poses_below(tree, palm, &q);
    let chains = chains(tree, mapping, &starts, &pose, palm)?;
    let axes: Vec<FingerAxes> = chains.iter().map(|c| finger_axes(tree, &pose, c)).collect();
    let frame = super::import_frame::palm_frame(tree, &pose, palm, &chains_info(&chains), &axes)?;
    super::import_frame::build(
        tree,
        &pose,
        palm,
        &chains_info(&chains),
        &axes,
        frame,
        overrides,
    )
}

/// The chains as `(joint 1, joint 2, spread, mapping slot)`.
fn chains_info(chains: &[Chain]) -> Vec<(usize, usize, Option<usize>, Option<usize>)> {
    chains
        .iter()
        .map(|c| (c.flex[0], c.flex[1], c.spread, c.slot))
        .collect()
}

/// Reads a hand file (`.urdf`: URDF; `.xml` or `.mjcf`: MJCF) and derives its model.
///
/// # Errors
/// As [`derive`], and the readers' own errors; an extension that is neither is an error.
pub fn load(
    path: &Path,
    mapping: &Mapping,
    overrides: &[(String, f64)],
) -> Result<Derived, HandError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let tree = match ext.as_str() {
        "urdf" => super::urdf_hand::read(path)?,
        "xml" | "mjcf" => super::mjcf_hand::read(path)?,
        _ => {
            return Err(err(
                path,
                "is not a hand file grasp-sim reads: expected a URDF (.urdf) or an MJCF (.xml)",
            ))
        }
    };
    derive(&tree, mapping, overrides)
}

pub(crate) type FingerAxesRef = FingerAxes;

/// A finger's joints as `[(point, axis) of joint 1, of joint 2]`.
pub(crate) fn axes_of(a: &FingerAxes) -> [(Point3<f64>, Vector3<f64>); 2] {
    [a.j1, a.j2]
}

/// A coupling in model terms for the hand: converts the file's joint relation into one between
/// interior angles, given each joint's interior angle at 0 and closing sense.
pub(crate) fn model_coupling(
    c: &FileCoupling,
    follower: ((usize, usize), f64, f64),
    leader: ((usize, usize), f64, f64),
) -> Coupling {
    // θ = θ0 − s·q (degrees): q = (θ0 − θ)/s.
    let ((ff, fj), f0, fs) = follower;
    let ((lf, lj), l0, ls) = leader;
    let a = fs * c.multiplier / ls;
    let b = f0 - a * l0 - fs * c.offset.to_degrees();
    Coupling {
        follower: [ff + 1, fj],
        leader: [lf + 1, lj],
        multiplier: a,
        offset_deg: b,
        source: format!(
            "{} `{}` follows `{}` (line {})",
            c.kind, c.follower, c.leader, c.line
        ),
    }
}
