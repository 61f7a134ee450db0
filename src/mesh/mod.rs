//! Triangle meshes: loading and validating STL, OBJ and PLY (and the objects URDF files
//! describe), mass properties, alignment with the
//! principal axis.
//!
//! Input: a mesh file (STL binary or ASCII, Wavefront OBJ, PLY ASCII or binary) in some length
//! unit. Output: a welded, validated [`Mesh`]
//! in millimetres, and from it an [`AlignedObject`] in the planner's frame (thesis 3.2.1): the
//! principal axis with the smallest moment of inertia along +Z, the lowest point at Z = 0 and the
//! centroid on the Z axis. The thesis asks the user to pre-align the mesh (its 6.2); grasp-sim does
//! it and keeps the transform, so every output can also be given in the mesh's original frame.
//!
//! Invariants of a [`Mesh`]: every coordinate is finite; every triangle has three distinct vertex
//! indices and non-zero area; vertices that are bit-identical in the file are one vertex.

mod align;
mod load;
mod mass;
mod polygon_limits;
pub mod primitives;
pub mod ring;
pub mod slice;
pub mod urdf;

pub use align::{
    align, align_about, align_with, align_with_rule, canonical_rotation, covariant_mass_properties,
    principal_axes, AlignedObject, FrameRule, GraspAxis,
};
pub use load::{
    check_planner_work, load_mesh, load_stl, parse_mesh, parse_stl, LengthUnit, LoadedMesh,
    MeshFormat,
};
pub use mass::{
    mass_properties, mass_properties_from, sliced_mass_properties, surface_mass_properties,
    MassProperties,
};

use nalgebra::{Point3, Vector3};
use std::collections::HashMap;

/// The hasher of the mesh code's tables keyed by vertex indices or coordinate bits: foldhash's
/// fast hasher with its fixed seed (foldhash is hashbrown's default hasher, already in the build).
/// SipHash's protection against chosen keys costs a quarter of loading a 15k-triangle mesh and
/// buys nothing here: no table is iterated where its order could reach an output, and a key
/// collision costs time, never a different result.
pub(crate) type FastHash = foldhash::fast::FixedState;
use std::path::PathBuf;

/// Problems with a mesh file that stop grasp-sim from using it.
///
/// Every variant carries the file, so its message names it on one line.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be opened or read.
    #[error("{path}: cannot read: {}", crate::messages::io_message(.error))]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said: not the error's `source()`, since the message
        /// already says it in a few stable words, and `{:#}` would print it twice.
        error: std::io::Error,
    },
    /// The path names a directory.
    #[error("{path}: is a directory, not a mesh file")]
    IsDirectory {
        /// The path.
        path: PathBuf,
    },
    /// The file is empty.
    #[error("{path}: empty file, not a mesh file")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The bytes are neither ASCII nor binary STL.
    #[error("{path}: not an STL file: {detail}")]
    NotStl {
        /// The file.
        path: PathBuf,
        /// Why.
        detail: String,
    },
    /// A binary STL file holds fewer bytes than its triangle count needs.
    #[error("{path}: truncated binary STL: header says {declared} triangles ({expected} bytes), file has {actual} bytes")]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Triangle count in the header.
        declared: u32,
        /// Bytes the count implies.
        expected: u64,
        /// Bytes in the file.
        actual: u64,
    },
    /// A binary STL file holds more bytes than its triangle count explains.
    #[error("{path}: binary STL has {extra} trailing bytes after the {declared} triangles its header declares")]
    TrailingBytes {
        /// The file.
        path: PathBuf,
        /// Triangle count in the header.
        declared: u32,
        /// Bytes past the last triangle.
        extra: u64,
    },
    /// The file name's extension is none of the formats grasp-sim reads.
    #[error("{path}: unknown mesh format: the name must end in .stl, .obj, .ply or .urdf")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The content is of another format than the file name says.
    #[error("{path}: named .{named} but its content looks like {found}; rename it or convert it")]
    FormatMismatch {
        /// The file.
        path: PathBuf,
        /// The extension, lower case.
        named: String,
        /// What the content looks like.
        found: String,
    },
    /// Wavefront OBJ that does not parse.
    #[error("{path}: malformed OBJ{}: {detail}", line.map(|l| format!(" at line {l}")).unwrap_or_default())]
    Obj {
        /// The file.
        path: PathBuf,
        /// One-based line, where known.
        line: Option<usize>,
        /// What is wrong.
        detail: String,
    },
    /// PLY that does not parse or lacks what a surface needs.
    #[error("{path}: malformed PLY: {detail}")]
    Ply {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// A face refers to a vertex the file does not have.
    #[error("{path}: face {face} refers to vertex {index}, but the file has {vertices} vertices")]
    FaceIndex {
        /// The file.
        path: PathBuf,
        /// One-based face number.
        face: usize,
        /// The index as written in the file.
        index: i64,
        /// Vertices in the file.
        vertices: usize,
    },
    /// ASCII STL that does not parse.
    #[error("{path}: malformed ASCII STL: {detail}")]
    Ascii {
        /// The file.
        path: PathBuf,
        /// The parser's complaint.
        detail: String,
    },
    /// The file has no triangles.
    #[error("{path}: the mesh has no triangles")]
    NoTriangles {
        /// The file.
        path: PathBuf,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("{path}: triangle {triangle} has a NaN or infinite coordinate")]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// Zero-based index of the first offending triangle.
        triangle: usize,
    },
    /// A coordinate is too large to be a physical object.
    #[error("{path}: triangle {triangle} has a coordinate of {value:e} mm, beyond the {limit:e} mm grasp-sim accepts")]
    OutOfRange {
        /// The file.
        path: PathBuf,
        /// Zero-based index of the first offending triangle.
        triangle: usize,
        /// The coordinate in millimetres.
        value: f64,
        /// The limit in millimetres.
        limit: f64,
    },
    /// Every triangle has zero area.
    #[error("{path}: all {count} triangles are degenerate (zero area)")]
    AllDegenerate {
        /// The file.
        path: PathBuf,
        /// How many triangles were read.
        count: usize,
    },
    /// A URDF that is not well-formed, names a mesh that cannot be found, or has no geometry
    /// grasp-sim reads.
    #[error("{path}: URDF: {detail}")]
    Urdf {
        /// The URDF file.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// The object is so large for the planner's steps that its slices would not fit in memory
    /// (issue 32): the planner holds a slice's crossings for every indexed elevation and every
    /// approach angle.
    #[error("{path}: the object is {extent_mm:.0} mm across: at height_step_mm = {height_step_mm} and angular_step_deg = {angular_step_deg} that is {cells} elevation-angle cells for the planner, more than the {limit} it takes (check the units, or plan in coarser steps){hint}")]
    TooLarge {
        /// The mesh file.
        path: PathBuf,
        /// The diagonal of its bounding box `[mm]`.
        extent_mm: f64,
        /// The planner's height step `[mm]`.
        height_step_mm: f64,
        /// The planner's angular step `[deg]`.
        angular_step_deg: f64,
        /// Indexed elevations (at most) times approach angles.
        cells: u64,
        /// The most cells the planner takes.
        limit: u64,
        /// `; ` and the units warning when the size is implausible for a hand (else empty).
        hint: String,
    },
    /// The surface encloses no volume, so it has no mass properties or principal axis.
    #[error("{path}: the surface encloses no volume ({volume_mm3:.3e} mm^3): not a closed solid")]
    NoVolume {
        /// The file.
        path: PathBuf,
        /// The signed volume found.
        volume_mm3: f64,
    },
}

/// Vertices of a loaded mesh closer than this fraction of its bounding-box diagonal are one
/// vertex ([`Mesh::from_triangles_welded`]). 1e-9 is far below f32's resolution of a
/// coordinate of the mesh's own size (about 6e-8 of it), so two vertices a mesh file can tell
/// apart at its own scale stay apart, while a seam whose coordinates differ by rounding near
/// zero (1e-18 m against 0) closes.
pub const WELD_TOLERANCE: f64 = 1e-9;

/// A welded triangle mesh in millimetres.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Vertex positions `[mm]`.
    pub vertices: Vec<Point3<f64>>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Edge statistics of a mesh: how far it is from a closed, consistently oriented 2-manifold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Topology {
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges used twice in the same direction (neighbouring triangles wound oppositely).
    pub misoriented_edges: usize,
}

impl Topology {
    /// Returns true if and only if every edge is shared by exactly two triangles wound
    /// consistently.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0 && self.misoriented_edges == 0
    }
}

impl Mesh {
    /// Builds a mesh from triangle soup, welding bit-identical vertices.
    ///
    /// Vertex order is the order of first appearance, so the result is deterministic.
    /// Triangles that repeat a vertex are dropped; the count of dropped triangles is returned.
    pub fn from_triangles(soup: &[[Point3<f64>; 3]]) -> (Mesh, usize) {
        let mut index: HashMap<[u64; 3], u32, FastHash> =
            HashMap::with_capacity_and_hasher(soup.len(), FastHash::default());
        let mut vertices = Vec::new();
        let mut triangles = Vec::with_capacity(soup.len());
        let mut dropped = 0;
        for tri in soup {
            let mut ids = [0u32; 3];
            for (k, p) in tri.iter().enumerate() {
                // +0.0 turns -0.0 into 0.0, so the two spellings of zero weld.
                let key = [
                    (p.x + 0.0).to_bits(),
                    (p.y + 0.0).to_bits(),
                    (p.z + 0.0).to_bits(),
                ];
                ids[k] = *index.entry(key).or_insert_with(|| {
                    vertices.push(Point3::new(p.x + 0.0, p.y + 0.0, p.z + 0.0));
                    (vertices.len() - 1) as u32
                });
            }
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                dropped += 1;
            } else {
                triangles.push(ids);
            }
        }
        (
            Mesh {
                vertices,
                triangles,
            },
            dropped,
        )
    }

    /// Builds a mesh from triangle soup, welding vertices closer than `WELD_TOLERANCE` × the
    /// soup's bounding-box diagonal (Euclidean distance): a seam written with coordinates that
    /// differ in their last bits (1e-18 m against 0) is one edge, not two boundary edges. Each
    /// vertex joins the first-appearing vertex within the tolerance, so the result is
    /// deterministic; a soup whose vertices are all further apart than that gives exactly what
    /// [`Mesh::from_triangles`] gives.
    pub fn from_triangles_welded(soup: &[[Point3<f64>; 3]]) -> (Mesh, usize) {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in soup.iter().flatten() {
            lo = lo.inf(&p.coords);
            hi = hi.sup(&p.coords);
        }
        let tol = WELD_TOLERANCE * (hi - lo).norm();
        if !(tol.is_finite() && tol > 0.0) {
            return Mesh::from_triangles(soup);
        }
        // Grid cells of side 4 tol: a vertex's weld partner lies in its cell or, along each
        // axis, in the neighbour on the side of the cell's nearer half (the far side is at least
        // 2 tol away), so 8 cells are searched rather than 27.
        let side = 4.0 * tol;
        let scaled = |p: &Point3<f64>| (p.coords - lo) / side;
        let mut grid: HashMap<[i64; 3], Vec<u32>, FastHash> =
            HashMap::with_capacity_and_hasher(soup.len(), FastHash::default());
        // A corner met again with the same bits joins what its first appearance joined: that
        // was the first-appearing vertex within the tolerance, and every vertex made since has
        // a later index. So the cell search runs once per distinct point.
        let mut seen: HashMap<[u64; 3], u32, FastHash> =
            HashMap::with_capacity_and_hasher(soup.len(), FastHash::default());
        let mut vertices: Vec<Point3<f64>> = Vec::new();
        let mut triangles = Vec::with_capacity(soup.len());
        let mut dropped = 0;
        for tri in soup {
            let mut ids = [0u32; 3];
            for (k, p) in tri.iter().enumerate() {
                let p = Point3::new(p.x + 0.0, p.y + 0.0, p.z + 0.0);
                let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                if let Some(&v) = seen.get(&key) {
                    ids[k] = v;
                    continue;
                }
                let f = scaled(&p);
                let c = [f.x.floor() as i64, f.y.floor() as i64, f.z.floor() as i64];
                let found = weld_partner(&grid, &vertices, &p, &f, c, tol);
                ids[k] = match found {
                    Some(v) => v,
                    None => {
                        vertices.push(p);
                        let v = (vertices.len() - 1) as u32;
                        grid.entry(c).or_default().push(v);
                        v
                    }
                };
                seen.insert(key, ids[k]);
            }
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                dropped += 1;
            } else {
                triangles.push(ids);
            }
        }
        (
            Mesh {
                vertices,
                triangles,
            },
            dropped,
        )
    }

    /// The three corners of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [Point3<f64>; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// The (unnormalised) normal of triangle `t` from its winding: twice its area in length.
    #[inline]
    pub fn area_normal(&self, t: usize) -> Vector3<f64> {
        let [a, b, c] = self.corners(t);
        (b - a).cross(&(c - a))
    }

    /// Axis-aligned bounds `(min, max)` of the vertices `[mm]`.
    ///
    /// # Panics
    /// If the mesh has no vertices (a validated mesh always has some).
    pub fn bounds(&self) -> (Point3<f64>, Point3<f64>) {
        let mut lo = self.vertices[0];
        let mut hi = self.vertices[0];
        for p in &self.vertices {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }

    /// Counts boundary, non-manifold and misoriented edges.
    pub fn topology(&self) -> Topology {
        // For each undirected edge: (uses in direction lo->hi, uses in direction hi->lo).
        let mut edges: HashMap<(u32, u32), (u32, u32), FastHash> =
            HashMap::with_capacity_and_hasher(self.triangles.len() * 2, FastHash::default());
        for tri in &self.triangles {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let e = edges.entry((a.min(b), a.max(b))).or_insert((0, 0));
                if a < b {
                    e.0 += 1;
                } else {
                    e.1 += 1;
                }
            }
        }
        let mut t = Topology::default();
        for &(fwd, back) in edges.values() {
            match fwd + back {
                1 => t.boundary_edges += 1,
                2 if fwd != 1 => t.misoriented_edges += 1,
                2 => {}
                _ => t.non_manifold_edges += 1,
            }
        }
        t
    }

    /// The number of shells: sets of triangles connected through shared vertices.
    pub fn shell_count(&self) -> usize {
        self.shell_bounds().len()
    }

    /// The axis-aligned bounds (low and high corner) of each shell, in no set order.
    pub fn shell_bounds(&self) -> Vec<(Point3<f64>, Point3<f64>)> {
        let mut parent: Vec<u32> = (0..self.vertices.len() as u32).collect();
        fn find(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                parent[i as usize] = parent[parent[i as usize] as usize];
                i = parent[i as usize];
            }
            i
        }
        for t in &self.triangles {
            for k in 1..3 {
                let (a, b) = (find(&mut parent, t[0]), find(&mut parent, t[k]));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
        let mut shell = vec![u32::MAX; self.vertices.len()];
        let mut bounds: Vec<(Point3<f64>, Point3<f64>)> = Vec::new();
        for t in &self.triangles {
            for &v in t {
                let root = find(&mut parent, v) as usize;
                if shell[root] == u32::MAX {
                    shell[root] = bounds.len() as u32;
                    let p = self.vertices[v as usize];
                    bounds.push((p, p));
                }
                let (lo, hi) = &mut bounds[shell[root] as usize];
                let p = &self.vertices[v as usize];
                *lo = lo.inf(p);
                *hi = hi.sup(p);
            }
        }
        bounds
    }

    /// Returns true if and only if the bounds of two shells meet, so their solids may overlap
    /// (shells apart, as the parts of an assembly, cannot). Sorted by their low x and swept,
    /// so the work is proportional to the shells and the pairs whose x ranges meet.
    pub fn shells_may_overlap(&self) -> bool {
        let mut b = self.shell_bounds();
        b.sort_by(|p, q| p.0.x.total_cmp(&q.0.x));
        for (i, (lo, hi)) in b.iter().enumerate() {
            for (lo2, hi2) in &b[i + 1..] {
                if lo2.x > hi.x {
                    break;
                }
                if lo2.y <= hi.y && lo.y <= hi2.y && lo2.z <= hi.z && lo.z <= hi2.z {
                    return true;
                }
            }
        }
        false
    }

    /// Closes every hole whose boundary loop spans at most `max_extent_mm` (the largest distance
    /// between two of its vertices) with a fan of triangles about the loop's centroid, wound to
    /// match the surface. Returns the number of holes closed. Only simple loops are closed (each
    /// boundary vertex on one boundary edge in and one out); larger openings (a cup's rim, a cut
    /// made on purpose) are left as they are.
    pub fn fill_small_holes(&mut self, max_extent_mm: f64) -> usize {
        // Directed edges of the triangles; a boundary edge has no reverse twin.
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for tri in &self.triangles {
            for k in 0..3 {
                *directed.entry((tri[k], tri[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
        let mut boundary: Vec<(u32, u32)> = directed
            .keys()
            .filter(|(a, b)| !directed.contains_key(&(*b, *a)))
            .copied()
            .collect();
        boundary.sort_unstable();
        for &(a, b) in &boundary {
            next.entry(a).or_default().push(b);
        }
        let mut used: std::collections::HashSet<(u32, u32)> = Default::default();
        let mut filled = 0;
        for &(a0, b0) in &boundary {
            if used.contains(&(a0, b0)) {
                continue;
            }
            // Follow the boundary from a0 -> b0 until it returns to a0.
            let mut lp = vec![a0];
            let mut cur = (a0, b0);
            let mut ok = true;
            loop {
                used.insert(cur);
                let (_, b) = cur;
                if b == a0 {
                    break;
                }
                lp.push(b);
                match next.get(&b).map(Vec::as_slice) {
                    Some([c]) if !used.contains(&(b, *c)) && lp.len() <= 10_000 => cur = (b, *c),
                    _ => {
                        ok = false;
                        break;
                    }
                }
            }
            if !ok || lp.len() < 3 {
                continue;
            }
            let pts: Vec<Point3<f64>> = lp.iter().map(|&v| self.vertices[v as usize]).collect();
            // The loop's extent is O(L²): measured only against a finite bound.
            if max_extent_mm < f64::INFINITY {
                let extent = pts
                    .iter()
                    .flat_map(|p| pts.iter().map(move |q| (p - q).norm()))
                    .fold(0.0, f64::max);
                if extent > max_extent_mm {
                    continue;
                }
            }
            let centre =
                Point3::from(pts.iter().map(|p| p.coords).sum::<Vector3<f64>>() / pts.len() as f64);
            self.vertices.push(centre);
            let c = (self.vertices.len() - 1) as u32;
            // The surface runs a -> b along the loop; the patch runs the other way.
            for i in 0..lp.len() {
                let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
                self.triangles.push([b, a, c]);
            }
            filled += 1;
        }
        filled
    }

    /// Applies `f` to every vertex.
    pub fn map_vertices(&mut self, f: impl Fn(&Point3<f64>) -> Point3<f64>) {
        for p in &mut self.vertices {
            *p = f(p);
        }
    }

    /// Turns the triangles wound against their neighbours, so that every edge that exactly two
    /// triangles share is walked once each way, as on a closed, outward-wound shell; returns how
    /// many were turned. Each piece (triangles joined through such edges, walked breadth-first
    /// from its first triangle) keeps the winding of most of its triangles, the first
    /// triangle's on a tie: a shell with a few faces written the wrong way round is mended, not
    /// turned inside out (the volume's sign decides that afterwards). A piece that cannot be
    /// wound consistently (a Möbius strip) keeps the winding the walk gives it. A mesh with no
    /// misoriented edge is left as it is.
    pub fn orient_consistently(&mut self) -> usize {
        let n = self.triangles.len();
        let mut users: HashMap<(u32, u32), Vec<u32>, FastHash> =
            HashMap::with_capacity_and_hasher(n * 2, FastHash::default());
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                users
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(t as u32);
            }
        }
        let walks_up = |tri: &[u32; 3], lo: u32, hi: u32| {
            (0..3).any(|k| tri[k] == lo && tri[(k + 1) % 3] == hi)
        };
        let mut flip = vec![false; n];
        let mut seen = vec![false; n];
        let mut queue = std::collections::VecDeque::new();
        for first in 0..n {
            if seen[first] {
                continue;
            }
            seen[first] = true;
            let mut piece = vec![first];
            queue.push_back(first);
            while let Some(t) = queue.pop_front() {
                let tri = self.triangles[t];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    let (lo, hi) = (a.min(b), a.max(b));
                    let [u, v] = users[&(lo, hi)][..] else {
                        continue;
                    };
                    let m = if u as usize == t { v } else { u } as usize;
                    if seen[m] {
                        continue;
                    }
                    // The neighbour must walk the shared edge the other way from `t` as wound.
                    let t_up = walks_up(&tri, lo, hi) != flip[t];
                    flip[m] = walks_up(&self.triangles[m], lo, hi) == t_up;
                    seen[m] = true;
                    piece.push(m);
                    queue.push_back(m);
                }
            }
            if 2 * piece.iter().filter(|&&t| flip[t]).count() > piece.len() {
                for &t in &piece {
                    flip[t] = !flip[t];
                }
            }
        }
        let mut turned = 0;
        for (tri, f) in self.triangles.iter_mut().zip(flip) {
            if f {
                tri.swap(1, 2);
                turned += 1;
            }
        }
        turned
    }

    /// Reverses the winding of every triangle (turns the surface inside out).
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    /// The mesh as binary STL bytes (f32 coordinates, normals from the winding).
    pub fn to_binary_stl(&self) -> Vec<u8> {
        let tris = (0..self.triangles.len()).map(|t| {
            let n = self.area_normal(t).normalize();
            let c = self.corners(t);
            let v = |p: Point3<f64>| stl_io::Vertex::new([p.x as f32, p.y as f32, p.z as f32]);
            stl_io::Triangle {
                normal: stl_io::Normal::new([n.x as f32, n.y as f32, n.z as f32]),
                vertices: [v(c[0]), v(c[1]), v(c[2])],
            }
        });
        let mut out = Vec::with_capacity(84 + 50 * self.triangles.len());
        stl_io::write_stl(&mut out, tris).expect("writing to a Vec cannot fail");
        out
    }

    /// The mesh as ASCII STL text (coordinates printed as f32, like the binary form).
    pub fn to_ascii_stl(&self, name: &str) -> String {
        use std::fmt::Write;
        let mut s = format!("solid {name}\n");
        for t in 0..self.triangles.len() {
            let n = self.area_normal(t).normalize();
            let _ = writeln!(
                s,
                "  facet normal {:e} {:e} {:e}\n    outer loop",
                n.x as f32, n.y as f32, n.z as f32
            );
            for p in self.corners(t) {
                let _ = writeln!(
                    s,
                    "      vertex {:e} {:e} {:e}",
                    p.x as f32, p.y as f32, p.z as f32
                );
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        let _ = writeln!(s, "endsolid {name}");
        s
    }
}

/// The first-appearing vertex of `vertices` within `tol` of `p`, searched in the weld grid's
/// cell `c` of `p` and, along each axis, the neighbour on the side of the cell's nearer half
/// (`f`: `p` in units of the cell side, from the grid's origin).
fn weld_partner(
    grid: &HashMap<[i64; 3], Vec<u32>, FastHash>,
    vertices: &[Point3<f64>],
    p: &Point3<f64>,
    f: &Vector3<f64>,
    c: [i64; 3],
    tol: f64,
) -> Option<u32> {
    let near = |k: usize| if f[k] - c[k] as f64 >= 0.5 { 1 } else { -1 };
    let (nx, ny, nz) = (near(0), near(1), near(2));
    let mut found: Option<u32> = None;
    for dx in [0, nx] {
        for dy in [0, ny] {
            for dz in [0, nz] {
                let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                    continue;
                };
                for &v in list {
                    if (vertices[v as usize] - p).norm() <= tol && found.is_none_or(|f| v < f) {
                        found = Some(v);
                    }
                }
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the weld must give, by testing every vertex against every earlier one: each corner
    /// joins the first-appearing vertex within the tolerance.
    fn weld_by_brute_force(soup: &[[Point3<f64>; 3]]) -> (Vec<Point3<f64>>, Vec<[u32; 3]>) {
        let (lo, hi) = soup.iter().flatten().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
        );
        let tol = WELD_TOLERANCE * (hi - lo).norm();
        let mut vertices: Vec<Point3<f64>> = Vec::new();
        let mut triangles = Vec::new();
        for tri in soup {
            let ids = tri.map(|p| {
                let p = Point3::new(p.x + 0.0, p.y + 0.0, p.z + 0.0);
                match vertices.iter().position(|v| (v - p).norm() <= tol) {
                    Some(v) => v as u32,
                    None => {
                        vertices.push(p);
                        (vertices.len() - 1) as u32
                    }
                }
            });
            if ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2] {
                triangles.push(ids);
            }
        }
        (vertices, triangles)
    }

    #[test]
    fn faces_wound_against_their_neighbours_are_turned_to_agree() {
        // A 40 × 30 × 20 mm box (12 triangles, 24,000 mm³, outward), away from the origin so
        // that every face's term of the surface integral counts.
        let mut good = primitives::prism(40.0, 30.0, 20.0);
        good.map_vertices(|p| p + Vector3::new(100.0, 100.0, 100.0));
        let volume = |m: &Mesh| surface_mass_properties(m).volume_mm3;
        assert!((volume(&good) - 24_000.0).abs() < 1e-6);
        let mut m = good.clone();
        assert_eq!(m.orient_consistently(), 0);
        assert_eq!(m.triangles, good.triangles);
        // One triangle turned (a side face's: the volume integral takes the x-components):
        // 3 misoriented edges and a volume that is not the box's. Mended, it is the box again,
        // triangle for triangle.
        let side = (0..good.triangles.len())
            .max_by(|&a, &b| {
                let x = |t: usize| good.area_normal(t).x.abs();
                x(a).total_cmp(&x(b)).then(b.cmp(&a))
            })
            .unwrap();
        let mut one = good.clone();
        one.triangles[side].swap(1, 2);
        assert_eq!(one.topology().misoriented_edges, 3);
        assert!((volume(&one) - 24_000.0).abs() > 1.0, "{}", volume(&one));
        assert_eq!(one.orient_consistently(), 1);
        assert_eq!(one.triangles, good.triangles);
        assert_eq!(one.topology().misoriented_edges, 0);
        // All but three turned: the piece keeps the winding of most of its triangles (now
        // inward), so the three are turned and the volume is the box's with its sign turned.
        let mut most = good.clone();
        for tri in most.triangles.iter_mut().skip(3) {
            tri.swap(1, 2);
        }
        assert_eq!(most.orient_consistently(), 3);
        assert_eq!(most.topology().misoriented_edges, 0);
        assert!((volume(&most) + 24_000.0).abs() < 1e-6, "{}", volume(&most));
    }

    #[test]
    fn the_weld_joins_what_testing_every_pair_joins() {
        // 600 triangles whose corners are drawn from 150 points on a 100 mm grid, each written
        // again and again with offsets of 0 to 3 tolerances in random directions (a seam written
        // in other bits), some exactly on cell boundaries of the weld's grid.
        let tol = WELD_TOLERANCE * (Vector3::new(100.0, 100.0, 100.0)).norm();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let base: Vec<Point3<f64>> = (0..150)
            .map(|_| {
                let q = |x: f64| (x * 10.0).floor() * 10.0;
                Point3::new(q(next()), q(next()), q(next()))
            })
            .chain([Point3::origin(), Point3::new(100.0, 100.0, 100.0)])
            .collect();
        let soup: Vec<[Point3<f64>; 3]> = (0..600)
            .map(|_| {
                [0, 1, 2].map(|_| {
                    let p = base[(next() * base.len() as f64) as usize];
                    let d = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                    let scale = [0.0, 0.4, 0.9, 1.5, 3.0][(next() * 5.0) as usize] * tol;
                    p + d.normalize() * scale
                })
            })
            .collect();
        let (mesh, dropped) = Mesh::from_triangles_welded(&soup);
        let (vertices, triangles) = weld_by_brute_force(&soup);
        assert_eq!(mesh.vertices, vertices);
        assert_eq!(mesh.triangles, triangles);
        assert_eq!(dropped, soup.len() - triangles.len());
        // The offsets did make the weld join points written in other bits, and keep some apart.
        assert!(
            vertices.len() > base.len() && vertices.len() < 3 * soup.len() / 2,
            "{} vertices from {} points",
            vertices.len(),
            base.len()
        );
    }
}
