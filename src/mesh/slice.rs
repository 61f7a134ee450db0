//! Plane ∩ mesh: closed contours with projected outward normals (thesis 3.3.1, Fig. 3.2–3.4).
//!
//! Input: a [`Mesh`] and a [`Plane`]. Output: a [`Slice`], every contour as an ordered polyline in
//! the plane's 2D coordinates `(u, v)` `[mm]`, with the outward normal of each segment: the
//! triangle's normal projected onto the plane and normalised (thesis 3.3.1).
//!
//! Robust chaining (why not parry's `intersection_with_local_plane`: the planner also needs each
//! segment's outward normal and the contour orientation):
//! - A vertex exactly on the plane counts as above it (symbolic perturbation), so every triangle
//!   is cut by zero or two of its edges and no case is special. In effect the cut is taken an
//!   infinitesimal distance on the plane's negative side: a plane lying in a face facing its
//!   normal (a top cap) gives that face's outline; one lying in a face facing away (a bottom cap)
//!   gives nothing, as a plane just below the object would.
//! - A crossing point is identified by its mesh edge, and computed from the edge's vertices in
//!   index order, so the two triangles sharing an edge produce the bit-identical point.
//! - A segment is oriented by the triangle's winding, not by geometry, so a zero-length segment
//!   (a vertex on the plane) still chains; zero-length segments are removed afterwards.
//!
//! Orientation: seen from the plane's normal side, an outer boundary runs counter-clockwise
//! (positive signed area, outward normals on its right) and a hole clockwise.

mod fill;

use crate::mesh::Mesh;
use nalgebra::{Point2, Point3, Vector2, Vector3};
use std::collections::{HashMap, HashSet};

/// A cutting plane with an orthonormal in-plane frame.
///
/// 2D coordinates are `((p - origin)·u, (p - origin)·v)`; the normal is `u × v`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point on the plane `[mm]`.
    pub origin: Point3<f64>,
    /// First in-plane axis (unit).
    pub u: Vector3<f64>,
    /// Second in-plane axis (unit, orthogonal to `u`).
    pub v: Vector3<f64>,
}

impl Plane {
    /// A plane through `origin` spanned by `u` and `v` (orthonormalised: `v` is made orthogonal
    /// to `u`).
    ///
    /// # Panics
    /// If `u` and `v` are parallel or zero.
    pub fn new(origin: Point3<f64>, u: Vector3<f64>, v: Vector3<f64>) -> Plane {
        let u = u.normalize();
        let v = (v - u * u.dot(&v)).normalize();
        assert!(
            u.iter().chain(v.iter()).all(|c| c.is_finite()),
            "degenerate plane frame"
        );
        Plane { origin, u, v }
    }

    /// The vertical plane through the Z axis at `angle_rad` from +X (thesis 3.4.2, Fig. 3.10).
    ///
    /// `u = (cos a, sin a, 0)` points to the slice's right side, `v = +Z` up, so 2D coordinates
    /// are (signed distance from the axis, elevation).
    pub fn vertical(angle_rad: f64) -> Plane {
        let (s, c) = angle_rad.sin_cos();
        Plane {
            origin: Point3::origin(),
            u: Vector3::new(c, s, 0.0),
            v: Vector3::z(),
        }
    }

    /// The horizontal plane at height `z_mm`; 2D coordinates are (x, y).
    pub fn horizontal(z_mm: f64) -> Plane {
        Plane {
            origin: Point3::new(0.0, 0.0, z_mm),
            u: Vector3::x(),
            v: Vector3::y(),
        }
    }

    /// A finger slice plane (thesis 3.6.2.1): the plane in which a finger line turns about its
    /// joint axes, through `through`, normal to the palm's up axis after pitching by `pitch_rad`.
    ///
    /// The palm approaches along −X; its up axis is `(−sin p, 0, cos p)`, so a negative pitch
    /// leans the palm's top away from the object (as on the cup, thesis 5.3: −7°). In-plane
    /// axes: `u` is the pitched +X, `v` is +Y; at zero pitch this is [`Plane::horizontal`].
    pub fn finger(through: Point3<f64>, pitch_rad: f64) -> Plane {
        let (s, c) = pitch_rad.sin_cos();
        Plane {
            origin: through,
            u: Vector3::new(c, 0.0, s),
            v: Vector3::y(),
        }
    }

    /// The unit normal `u × v`.
    pub fn normal(&self) -> Vector3<f64> {
        self.u.cross(&self.v)
    }

    /// Signed distance of `p` from the plane along the normal `[mm]`.
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        (p - self.origin).dot(&self.normal())
    }

    /// The 2D coordinates of `p` (projected onto the plane).
    pub fn to_2d(&self, p: &Point3<f64>) -> Point2<f64> {
        let d = p - self.origin;
        Point2::new(d.dot(&self.u), d.dot(&self.v))
    }

    /// The 3D point of 2D coordinates `q`.
    pub fn to_3d(&self, q: &Point2<f64>) -> Point3<f64> {
        self.origin + self.u * q.x + self.v * q.y
    }
}

/// One connected piece of a slice: an ordered polyline with per-segment outward normals.
#[derive(Debug, Clone, PartialEq)]
pub struct Contour {
    /// Vertices in order `[mm]`. A closed contour does not repeat its first point.
    pub points: Vec<Point2<f64>>,
    /// Outward unit normal of segment `i` (from `points[i]` to `points[i + 1]`, wrapping when
    /// closed): `points.len()` normals when closed, one fewer when open.
    pub normals: Vec<Vector2<f64>>,
    /// True if and only if the contour closes on itself (always, for a closed manifold mesh).
    pub is_closed: bool,
}

impl Contour {
    /// Number of segments.
    pub fn segment_count(&self) -> usize {
        self.normals.len()
    }

    /// Segment `i` as its two endpoints.
    pub fn segment(&self, i: usize) -> (Point2<f64>, Point2<f64>) {
        let n = self.points.len();
        (self.points[i], self.points[(i + 1) % n])
    }

    /// Shoelace signed area `[mm²]`: positive for a counter-clockwise (outer) boundary, negative
    /// for a hole; for an open contour, the area closed by the chord.
    pub fn signed_area(&self) -> f64 {
        let n = self.points.len();
        let mut a = 0.0;
        for i in 0..n {
            let (p, q) = (self.points[i], self.points[(i + 1) % n]);
            a += p.x * q.y - q.x * p.y;
        }
        0.5 * a
    }

    /// Returns true if and only if the contour is closed and clockwise: the boundary of a hole.
    pub fn is_hole(&self) -> bool {
        self.is_closed && self.signed_area() < 0.0
    }

    /// Total length `[mm]`.
    pub fn length(&self) -> f64 {
        (0..self.segment_count())
            .map(|i| {
                let (a, b) = self.segment(i);
                (b - a).norm()
            })
            .sum()
    }
}

/// The result of cutting a mesh with a plane.
#[derive(Debug, Clone, PartialEq)]
pub struct Slice {
    /// The cutting plane.
    pub plane: Plane,
    /// Every contour, sorted by decreasing absolute area (ties by first point).
    pub contours: Vec<Contour>,
    /// Index of the outermost contour: the closed, counter-clockwise contour of largest area;
    /// `None` when the plane misses the mesh or no contour closes.
    pub outermost: Option<usize>,
}

impl Slice {
    /// Returns true if and only if the plane missed the mesh.
    pub fn is_empty(&self) -> bool {
        self.contours.is_empty()
    }
}

/// A mesh edge as its two vertex indices, smaller first.
type Edge = (u32, u32);

/// A cut through one triangle: it enters the triangle across `from` and leaves across `to`.
#[derive(Debug, Clone, Copy)]
struct Segment {
    from: Edge,
    to: Edge,
    triangle: usize,
}

/// Contour segments shorter than this are merged away `[mm]`.
const TINY_SEGMENT_MM: f64 = 1e-9;

/// A vertex this near the cutting plane is on it `[mm]`: its distance is taken as 0, so the
/// plane crosses there or not by the other vertices alone. A face the plane lies in (a flat
/// bottom at a finger plane's height, which HeightSteps put there on a box a whole number of
/// steps tall) is cut as in the file's own frame whatever frame rounded its vertices 1e-5 mm
/// to either side: left out, its rim the cut where the object lies on the other side (issue 30).
pub const ON_PLANE_MM: f64 = 1e-4;

/// `plane`'s signed distance to `p`, 0 within [`ON_PLANE_MM`].
fn snapped_distance(plane: &Plane, p: &Point3<f64>) -> f64 {
    let d = plane.distance(p);
    if d.abs() <= ON_PLANE_MM {
        0.0
    } else {
        d
    }
}

/// How [`slice()`] cuts: where it finds the triangles the plane may cut, and how far it repairs
/// and bridges the raw cut. [`SliceOptions::default()`] is the exact cut, repaired, through
/// every triangle.
#[derive(Debug, Clone, Copy)]
pub struct SliceOptions<'a> {
    /// Finds the triangles the plane may cut through this index, which must have been built
    /// from the mesh cut ([`SliceIndex::new`]): the same slice, bit for bit, at a cost that
    /// grows with the triangles cut rather than with the mesh (a search slices thousands of
    /// finger planes of one mesh). `None`: every triangle is tried.
    pub index: Option<&'a SliceIndex>,
    /// Joins the raw cut's open ends and unites its overlapping pieces (the default). `false`:
    /// the contours as they come (chained, but not joined, united nor bridged: open chains stay
    /// open, overlapping shells overlap), for a domain whose slices only need to show that
    /// nothing is graspable ([`crate::plan::domain::cannot_grade`]).
    pub repair: bool,
    /// Simplifies the raw cut within this tolerance `[mm]` ([`Contour::simplified`]) before its
    /// open ends are joined and its overlapping pieces united, where it has any: the union and
    /// the joining cost grow with the points, and a slice of a many-shell or open mesh has many.
    /// A slice in closed pieces that do not overlap is the exact cut. 0: no simplification.
    /// Only a repaired cut is simplified.
    pub tol_mm: f64,
    /// Bridges the repaired slice for a finger of this width `[mm]`
    /// ([`Slice::bridged_within`]`(gap_mm, tol_mm)`). With an index and repairing, through the
    /// index's plane cache: a plane cut in several frames is repaired and bridged once, in a
    /// canonical frame, and re-expressed in each frame asked for.
    pub bridge_gap_mm: Option<f64>,
}

impl Default for SliceOptions<'_> {
    fn default() -> Self {
        SliceOptions {
            index: None,
            repair: true,
            tol_mm: 0.0,
            bridge_gap_mm: None,
        }
    }
}

impl<'a> SliceOptions<'a> {
    /// The exact cut, repaired, with the triangles found through `index`.
    pub fn indexed(index: &'a SliceIndex) -> SliceOptions<'a> {
        SliceOptions {
            index: Some(index),
            ..SliceOptions::default()
        }
    }

    /// These options with the raw cut simplified within `tol_mm` before repairing.
    pub fn within(self, tol_mm: f64) -> SliceOptions<'a> {
        SliceOptions { tol_mm, ..self }
    }

    /// These options with the slice bridged for a finger of width `gap_mm`.
    pub fn bridged(self, gap_mm: f64) -> SliceOptions<'a> {
        SliceOptions {
            bridge_gap_mm: Some(gap_mm),
            ..self
        }
    }

    /// These options with the raw cut left unrepaired.
    pub fn unrepaired(self) -> SliceOptions<'a> {
        SliceOptions {
            repair: false,
            ..self
        }
    }
}

/// Cuts `mesh` with `plane`, as `options` say ([`SliceOptions`]).
pub fn slice(mesh: &Mesh, plane: &Plane, options: SliceOptions) -> Slice {
    match (options.index, options.bridge_gap_mm) {
        (Some(index), Some(gap_mm)) if options.repair => {
            bridged_through_cache(mesh, index, plane, gap_mm, options.tol_mm)
        }
        (_, Some(gap_mm)) => cut_by(mesh, plane, options).bridged_within(gap_mm, options.tol_mm),
        (_, None) => cut_by(mesh, plane, options),
    }
}

/// The cut of `mesh` by `plane` as `options` say, without bridging: the triangles found through
/// the index (each distance taken afresh: a few flops, the same bits each time, cheaper than a
/// table) or all of them (the distances tabulated once), then repaired or only finished.
fn cut_by(mesh: &Mesh, plane: &Plane, options: SliceOptions) -> Slice {
    let made = |contours: Vec<Contour>| {
        if options.repair {
            repair(*plane, contours, options.tol_mm)
        } else {
            finish(*plane, contours)
        }
    };
    match options.index {
        Some(index) => {
            let tris = index.candidates(plane);
            let dist = |i: u32| snapped_distance(plane, &mesh.vertices[i as usize]);
            made(raw_contours(mesh, plane, tris.into_iter(), &dist))
        }
        None => {
            let dist: Vec<f64> = mesh
                .vertices
                .iter()
                .map(|p| snapped_distance(plane, p))
                .collect();
            let d = |i: u32| dist[i as usize];
            made(raw_contours(mesh, plane, 0..mesh.triangles.len(), &d))
        }
    }
}

/// The slice with the triangles found through `index`, simplified within `tol_mm`, then
/// [`Slice::bridged_within`]`(gap_mm, tol_mm)`: what a finger of width `gap_mm` meets in
/// `plane`. A search cuts the same plane in many frames (a level palm's finger planes are the
/// horizontal planes at the candidates' heights, whatever the approach angle), so a slice that
/// needs repairing or bridging (a many-shell or open mesh: the costly ones) is made once per
/// plane, in the plane's canonical frame ([`canonical_plane`]: the normal rounded to 1e-9, the
/// offset to 1e-6 mm), and re-expressed in `plane`'s frame ([`Slice::in_frame_of`]). A plane
/// whose cut is one closed piece is cut in `plane` itself, as by slicing and bridging
/// directly. A re-expressed slice differs from the direct one by what the direct ones differ
/// between frames themselves (i_overlay's rings start where its grid puts them, the one-sided
/// simplification splits a contour at its first point, and the closing's bevels move with the
/// vertices kept: 1.4 mm in the tests). Either way the slice depends only on the mesh, the
/// plane and the two lengths, never on which planes were cut before nor on threads.
fn bridged_through_cache(
    mesh: &Mesh,
    index: &SliceIndex,
    plane: &Plane,
    gap_mm: f64,
    tol_mm: f64,
) -> Slice {
    let direct = || {
        cut_by(mesh, plane, SliceOptions::indexed(index).within(tol_mm))
            .bridged_within(gap_mm, tol_mm)
    };
    let Some(key) = plane_key(plane, gap_mm, tol_mm) else {
        return direct();
    };
    let canonical = || {
        let c = canonical_plane(&key);
        let tris = index.candidates(&c);
        let dist = |i: u32| snapped_distance(&c, &mesh.vertices[i as usize]);
        let raw = raw_contours(mesh, &c, tris.into_iter(), &dist);
        (!is_simple_cut(&raw)).then(|| repair(c, raw, tol_mm).bridged_within(gap_mm, tol_mm))
    };
    let entry = {
        let mut guard = index
            .planes
            .entries
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let (map, points) = &mut *guard;
        match map.get(&key) {
            Some(e) => Some(e.clone()),
            None if *points < PLANE_CACHE_POINTS => {
                let e = PlaneEntry::default();
                map.insert(key, e.clone());
                Some(e)
            }
            None => None,
        }
    };
    let found = match &entry {
        Some(e) => {
            let mut fresh = false;
            let v = e.get_or_init(|| {
                fresh = true;
                canonical()
            });
            if fresh {
                let n: usize = v
                    .iter()
                    .flat_map(|s| &s.contours)
                    .map(|c| c.points.len())
                    .sum();
                index
                    .planes
                    .entries
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .1 += n;
            }
            v.as_ref().map(|s| s.in_frame_of(plane))
        }
        None => canonical().map(|s| s.in_frame_of(plane)),
    };
    found.unwrap_or_else(direct)
}

/// The key of `plane` in a [`SliceIndex`]'s plane cache; `None` for a plane too far out to key.
fn plane_key(plane: &Plane, gap_mm: f64, tol_mm: f64) -> Option<PlaneKey> {
    let n = plane.normal();
    let q = |x: f64, unit: f64| {
        let k = (x / unit).round();
        (k.abs() < 4e18).then_some(k as i64)
    };
    let offset = n.dot(&plane.origin.coords);
    Some((
        [
            q(n.x, PLANE_KEY_NORMAL)?,
            q(n.y, PLANE_KEY_NORMAL)?,
            q(n.z, PLANE_KEY_NORMAL)?,
        ],
        q(offset, PLANE_KEY_OFFSET_MM)?,
        gap_mm.to_bits(),
        tol_mm.to_bits(),
    ))
}

/// The plane a [`PlaneKey`] stands for, in its canonical frame: the rounded normal (made unit)
/// `n`, origin `n × offset`, `u` the unit part of +X (or +Y, for a normal within 26° of ±X)
/// normal to `n`, `v = n × u`, so `u × v = n`.
fn canonical_plane(key: &PlaneKey) -> Plane {
    let ([nx, ny, nz], off, _, _) = *key;
    let n = Vector3::new(nx as f64, ny as f64, nz as f64).normalize();
    let a = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = (a - n * n.dot(&a)).normalize();
    Plane {
        origin: Point3::from(n * (off as f64 * PLANE_KEY_OFFSET_MM)),
        u,
        v: n.cross(&u),
    }
}

impl Slice {
    /// The slice re-expressed in the 2D frame of `plane`, a plane through the same points (up to
    /// the rounding of [`bridged_through_cache`]'s key) with the same normal: every point and
    /// normal mapped through 3D, the contours sorted again ([`finish`]).
    pub fn in_frame_of(&self, plane: &Plane) -> Slice {
        let from = &self.plane;
        let d = from.origin - plane.origin;
        let (uu, vu) = (from.u.dot(&plane.u), from.v.dot(&plane.u));
        let (uv, vv) = (from.u.dot(&plane.v), from.v.dot(&plane.v));
        let (du, dv) = (d.dot(&plane.u), d.dot(&plane.v));
        let contours = self
            .contours
            .iter()
            .map(|c| Contour {
                points: c
                    .points
                    .iter()
                    .map(|p| Point2::new(p.x * uu + p.y * vu + du, p.x * uv + p.y * vv + dv))
                    .collect(),
                normals: c
                    .normals
                    .iter()
                    .map(|m| Vector2::new(m.x * uu + m.y * vu, m.x * uv + m.y * vv).normalize())
                    .collect(),
                is_closed: c.is_closed,
            })
            .collect();
        finish(*plane, contours)
    }
}

/// The slicer's edge tables hash with [`super::FastHash`]: SipHash's protection against chosen
/// keys is not needed for mesh edges, and it was a fifth of the search's time. Only lookups use
/// these tables, never their iteration order, so results do not depend on the hasher.
type EdgeBuild = super::FastHash;

/// A bounding-volume hierarchy over a mesh's triangles: which triangles a plane may cut.
///
/// Built once per mesh (O(n log n)); a query visits the boxes the plane crosses, about the
/// square root of the triangle count for a plane through a closed surface. Deterministic: the
/// split is a median by centroid with ties broken by triangle index.
#[derive(Debug)]
pub struct SliceIndex {
    nodes: Vec<BvhNode>,
    order: Vec<u32>,
    triangles: usize,
    /// Bridged slices of the planes [`slice()`] has cut and bridged through this index, by
    /// [`PlaneKey`].
    planes: PlaneCache,
}

impl Clone for SliceIndex {
    /// The same index, with an empty plane cache (the cache changes only the time taken).
    fn clone(&self) -> SliceIndex {
        SliceIndex {
            nodes: self.nodes.clone(),
            order: self.order.clone(),
            triangles: self.triangles,
            planes: PlaneCache::default(),
        }
    }
}

/// A plane as a set of points, whatever its in-plane frame: its unit normal's components in
/// units of [`PLANE_KEY_NORMAL`] and its offset along the normal in units of
/// [`PLANE_KEY_OFFSET_MM`], with the bridging gap and the simplification tolerance it was asked
/// with (their bits).
type PlaneKey = ([i64; 3], i64, u64, u64);

/// What a plane's cut is, once known: `None` when the cut in the plane's canonical frame is one
/// closed piece (with its holes), cut afresh in each frame asked for; else the bridged slice in
/// the canonical frame ([`canonical_plane`]), re-expressed in each frame asked for.
type PlaneEntry = std::sync::Arc<std::sync::OnceLock<Option<Slice>>>;

/// The plane cache of a [`SliceIndex`]: entries and the contour points they hold.
#[derive(Debug, Default)]
struct PlaneCache {
    entries: std::sync::Mutex<(HashMap<PlaneKey, PlaneEntry>, usize)>,
}

/// The unit of a [`PlaneKey`]'s normal components: planes whose normals differ by less (the
/// finger planes of palms whose pitch differs by round-off) are cut as one, at most 1e-9 rad
/// apart, some 1e-7 mm over a 100 mm object.
const PLANE_KEY_NORMAL: f64 = 1e-9;

/// The unit of a [`PlaneKey`]'s offset `[mm]`.
const PLANE_KEY_OFFSET_MM: f64 = 1e-6;

/// The cache stops taking slices once it holds this many contour points (some 100 MB): beyond
/// it, slices are cut afresh. Only the time taken depends on it, never a slice.
const PLANE_CACHE_POINTS: usize = 3_000_000;

#[derive(Debug, Clone)]
struct BvhNode {
    min: Vector3<f64>,
    max: Vector3<f64>,
    /// Leaf: `order[start..start + count]`; inner: children at `start` and `start + 1`.
    start: u32,
    count: u32,
}

/// Triangles per leaf of a [`SliceIndex`].
const BVH_LEAF: usize = 8;

impl SliceIndex {
    /// Builds the index of `mesh`'s triangles.
    pub fn new(mesh: &Mesh) -> SliceIndex {
        let boxes: Vec<(Vector3<f64>, Vector3<f64>)> = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.vertices[i as usize].coords);
                (a.inf(&b).inf(&c), a.sup(&b).sup(&c))
            })
            .collect();
        let mut order: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
        let mut nodes = vec![BvhNode {
            min: Vector3::zeros(),
            max: Vector3::zeros(),
            start: 0,
            count: 0,
        }];
        // Iterative build: (node, range of `order`).
        let mut stack = vec![(0usize, 0usize, order.len())];
        while let Some((node, lo, hi)) = stack.pop() {
            let (mut bmin, mut bmax) = (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            );
            let (mut cmin, mut cmax) = (bmin, bmax);
            for &t in &order[lo..hi] {
                let (a, b) = &boxes[t as usize];
                bmin = bmin.inf(a);
                bmax = bmax.sup(b);
                let c = (a + b) * 0.5;
                cmin = cmin.inf(&c);
                cmax = cmax.sup(&c);
            }
            nodes[node].min = bmin;
            nodes[node].max = bmax;
            if hi - lo <= BVH_LEAF {
                nodes[node].start = lo as u32;
                nodes[node].count = (hi - lo) as u32;
                continue;
            }
            let ext = cmax - cmin;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let key = |t: &u32| {
                let (a, b) = &boxes[*t as usize];
                a[axis] + b[axis]
            };
            let mid = lo + (hi - lo) / 2;
            order[lo..hi]
                .select_nth_unstable_by(mid - lo, |x, y| key(x).total_cmp(&key(y)).then(x.cmp(y)));
            let first = nodes.len();
            for _ in 0..2 {
                nodes.push(BvhNode {
                    min: Vector3::zeros(),
                    max: Vector3::zeros(),
                    start: 0,
                    count: 0,
                });
            }
            nodes[node].start = first as u32;
            nodes[node].count = 0;
            stack.push((first, lo, mid));
            stack.push((first + 1, mid, hi));
        }
        SliceIndex {
            nodes,
            order,
            triangles: mesh.triangles.len(),
            planes: PlaneCache::default(),
        }
    }

    /// The triangles whose bounding box `plane` crosses (a superset of those it cuts), in
    /// increasing index order.
    fn candidates(&self, plane: &Plane) -> Vec<usize> {
        let mut out = self.candidates_unsorted(plane);
        out.sort_unstable();
        out
    }

    /// [`SliceIndex::candidates`] in the order the tree gives them.
    fn candidates_unsorted(&self, plane: &Plane) -> Vec<usize> {
        let n = plane.normal();
        let na = n.abs();
        let o = plane.origin.coords;
        let mut out = Vec::new();
        if self.triangles == 0 {
            return out;
        }
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i];
            let c = (node.min + node.max) * 0.5;
            let e = (node.max - node.min) * 0.5;
            let d = n.dot(&(c - o));
            let r = na.dot(&e);
            // Generous slack: the exact side test is made per vertex afterwards.
            let slack = 1e-6 * (1.0 + r + d.abs()) + ON_PLANE_MM;
            if d - r > slack || d + r < -slack {
                continue;
            }
            if node.count > 0 {
                let (s, k) = (node.start as usize, node.count as usize);
                out.extend(self.order[s..s + k].iter().map(|&t| t as usize));
            } else {
                stack.push(node.start as usize);
                stack.push(node.start as usize + 1);
            }
        }
        out
    }
}

/// The contours `plane` cuts from the triangles `tris`, chained but not repaired: open chains
/// stay open and overlapping shells overlap ([`repair`] joins and unites them).
fn raw_contours(
    mesh: &Mesh,
    plane: &Plane,
    tris: impl Iterator<Item = usize>,
    dist: &impl Fn(u32) -> f64,
) -> Vec<Contour> {
    let n = plane.normal();
    let above = |i: u32| dist(i) >= 0.0;

    let segments = crossing_segments(mesh, tris, above);

    let point = |e: Edge| edge_point(mesh, e, dist);

    // Open chains first (from segments nothing leads into), then the closed loops that remain.
    let mut contours: Vec<Contour> = chains(&segments)
        .into_iter()
        .map(|(chain, is_closed)| {
            build_contour(&chain, &segments, &point, mesh, plane, &n, is_closed)
        })
        .collect();
    contours.retain(|c| c.points.len() >= 2 && !c.normals.is_empty());
    contours
}

/// Where the plane whose signed distances are `dist` crosses the mesh edge `e` (a vertex on
/// the plane is itself the crossing). An edge is keyed with its lower index first, so the two
/// triangles that share it get the same point, bit for bit.
fn edge_point(mesh: &Mesh, e: Edge, dist: &impl Fn(u32) -> f64) -> Point3<f64> {
    let (i, j) = e;
    let (di, dj) = (dist(i), dist(j));
    let (pi, pj) = (mesh.vertices[i as usize], mesh.vertices[j as usize]);
    if di == 0.0 {
        pi
    } else if dj == 0.0 {
        pj
    } else {
        let t = di / (di - dj);
        pi + (pj - pi) * t
    }
}

/// The segments `plane` cuts from `mesh` (the triangles `index` finds), each from its crossing
/// of one edge to its crossing of another in the plane's 2D coordinates, in no particular
/// order and not chained: what a maximum over the cut needs (the palm's penetration), at a
/// fraction of the cost of chaining them into contours. The points are the raw cut's, bit for
/// bit; the raw cut's contours also drop segments under [`TINY_SEGMENT_MM`] (1e-9 mm) and
/// pieces of a single point, which these keep.
pub fn cut_segments_indexed(
    mesh: &Mesh,
    index: &SliceIndex,
    plane: &Plane,
) -> Vec<(Point2<f64>, Point2<f64>)> {
    let tris = index.candidates_unsorted(plane);
    let dist = |i: u32| snapped_distance(plane, &mesh.vertices[i as usize]);
    crossing_segments(mesh, tris.into_iter(), |i| dist(i) >= 0.0)
        .iter()
        .map(|s| {
            (
                plane.to_2d(&edge_point(mesh, s.from, &dist)),
                plane.to_2d(&edge_point(mesh, s.to, &dist)),
            )
        })
        .collect()
}

/// Returns true if and only if raw contours need no repair and no bridging: every one closed,
/// fewer than two outer pieces (so none overlap).
fn is_simple_cut(contours: &[Contour]) -> bool {
    contours.iter().all(|c| c.is_closed)
        && contours.iter().filter(|c| c.signed_area() > 0.0).count() < 2
}

/// Raw contours made a slice: simplified within `tol_mm` first where they need joining or
/// uniting, their open ends joined, overlapping shells united.
fn repair(plane: Plane, mut contours: Vec<Contour>, tol_mm: f64) -> Slice {
    if tol_mm > 0.0 && (contours.iter().any(|c| !c.is_closed) || has_overlapping_outers(&contours))
    {
        contours = contours.iter().map(|c| c.simplified(tol_mm)).collect();
    }
    // A closed single-shell mesh never takes this path, so its slices are exactly the cut.
    let mut repaired = false;
    if contours.iter().any(|c| !c.is_closed) {
        let tol = join_tolerance(&contours);
        repaired = join_open(&mut contours, tol);
    }
    if repaired || has_overlapping_outers(&contours) {
        contours = union_closed(contours);
    }
    finish(plane, contours)
}

/// The segments the plane cuts from the triangles `tris`, each oriented by its triangle's
/// winding (`above` says which side of the plane a vertex is on, a vertex on it counting above).
fn crossing_segments(
    mesh: &Mesh,
    tris: impl Iterator<Item = usize>,
    above: impl Fn(u32) -> bool,
) -> Vec<Segment> {
    let mut segments: Vec<Segment> = Vec::new();
    for t in tris {
        let tri = &mesh.triangles[t];
        let s = [above(tri[0]), above(tri[1]), above(tri[2])];
        if s[0] == s[1] && s[1] == s[2] {
            continue;
        }
        // The lone vertex: the one whose side differs from both others.
        let k = if s[1] == s[2] {
            0
        } else if s[0] == s[2] {
            1
        } else {
            2
        };
        let (a, next, prev) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
        let e_next = edge(a, next);
        let e_prev = edge(prev, a);
        // Lone vertex above: the segment runs from the edge to `next` to the edge from `prev`;
        // below, the other way. This makes the direction n × (triangle normal).
        let (from, to) = if s[k] {
            (e_next, e_prev)
        } else {
            (e_prev, e_next)
        };
        segments.push(Segment {
            from,
            to,
            triangle: t,
        });
    }
    segments
}

/// The segments chained end to start: open chains first (from segments nothing leads into),
/// then the closed loops that remain; each as its segment indices and whether it closes.
fn chains(segments: &[Segment]) -> Vec<(Vec<usize>, bool)> {
    let mut by_from: HashMap<Edge, usize, EdgeBuild> =
        HashMap::with_capacity_and_hasher(segments.len(), EdgeBuild::default());
    let mut ends: HashSet<Edge, EdgeBuild> =
        HashSet::with_capacity_and_hasher(segments.len(), EdgeBuild::default());
    for (i, s) in segments.iter().enumerate() {
        by_from.entry(s.from).or_insert(i);
        ends.insert(s.to);
    }

    let mut used = vec![false; segments.len()];
    let mut out = Vec::new();
    let has_predecessor = |i: usize| ends.contains(&segments[i].from);
    let starts = (0..segments.len())
        .filter(|&i| !has_predecessor(i))
        .chain(0..segments.len());
    for first in starts {
        if used[first] {
            continue;
        }
        let mut chain = Vec::new();
        let mut cur = first;
        let mut is_closed = false;
        loop {
            used[cur] = true;
            chain.push(cur);
            match by_from.get(&segments[cur].to) {
                Some(&nx) if nx == first => {
                    is_closed = true;
                    break;
                }
                Some(&nx) if !used[nx] => cur = nx,
                _ => break,
            }
        }
        out.push((chain, is_closed));
    }
    out
}

/// Sorts contours (decreasing absolute area, ties by first point) and finds the outermost.
fn finish(plane: Plane, mut contours: Vec<Contour>) -> Slice {
    contours.sort_by(|a, b| {
        b.signed_area()
            .abs()
            .total_cmp(&a.signed_area().abs())
            .then(a.points[0].x.total_cmp(&b.points[0].x))
            .then(a.points[0].y.total_cmp(&b.points[0].y))
    });
    let outermost = contours
        .iter()
        .position(|c| c.is_closed && c.signed_area() > 0.0);
    Slice {
        plane,
        contours,
        outermost,
    }
}

fn edge(a: u32, b: u32) -> Edge {
    (a.min(b), a.max(b))
}

#[allow(clippy::too_many_arguments)]
fn build_contour(
    chain: &[usize],
    segments: &[Segment],
    point: &impl Fn(Edge) -> Point3<f64>,
    mesh: &Mesh,
    plane: &Plane,
    n: &Vector3<f64>,
    is_closed: bool,
) -> Contour {
    let mut points: Vec<Point2<f64>> = Vec::with_capacity(chain.len() + 1);
    let mut normals: Vec<Vector2<f64>> = Vec::with_capacity(chain.len());
    for &s in chain {
        let seg = segments[s];
        points.push(plane.to_2d(&point(seg.from)));
        let m = mesh.area_normal(seg.triangle);
        let m2 = Vector2::new(m.dot(&plane.u), m.dot(&plane.v));
        normals.push(if m2.norm() > 1e-12 * m.norm() {
            m2.normalize()
        } else {
            // A triangle almost parallel to the plane: its projection says nothing; use the
            // perpendicular of the travel direction, which is outward by construction.
            let dir = n.cross(&m);
            Vector2::new(dir.dot(&plane.v), -dir.dot(&plane.u))
                .try_normalize(0.0)
                .unwrap_or_else(Vector2::x)
        });
    }
    if !is_closed {
        let last = *chain.last().expect("a chain has a segment");
        points.push(plane.to_2d(&point(segments[last].to)));
    }
    // Merge tiny segments: drop segment i and one of its two end points, keeping the indexing
    // of points and normals aligned (segment i runs from points[i] to the next point).
    let mut i = 0;
    while normals.len() > 1 && i < normals.len() {
        let np = points.len();
        let j = if is_closed { (i + 1) % np } else { i + 1 };
        if (points[j] - points[i]).norm() <= TINY_SEGMENT_MM {
            normals.remove(i);
            // Removing the start of the contour, or the end of an open one, would shift the
            // segment numbering; remove the (coincident) other end point instead.
            if j == 0 || (!is_closed && j == np - 1) {
                points.remove(i);
            } else {
                points.remove(j);
            }
        } else {
            i += 1;
        }
    }
    Contour {
        points,
        normals,
        is_closed,
    }
}

impl Contour {
    /// A contour from a polyline, with each segment's outward normal taken from the geometry:
    /// the material lies on the left of the direction of travel (counter-clockwise outer
    /// boundaries, clockwise holes), so the outward normal is the travel direction turned
    /// clockwise. For a cut through a triangle this is the triangle's projected normal (the
    /// segment lies in the triangle, so the normal's projection is perpendicular to it).
    pub fn from_polyline(points: Vec<Point2<f64>>, is_closed: bool) -> Contour {
        let n = points.len();
        let segments = if is_closed { n } else { n.saturating_sub(1) };
        let normals = (0..segments)
            .map(|i| {
                let d = points[(i + 1) % n] - points[i];
                Vector2::new(d.y, -d.x)
                    .try_normalize(0.0)
                    .unwrap_or_else(Vector2::x)
            })
            .collect();
        Contour {
            points,
            normals,
            is_closed,
        }
    }

    /// Axis-aligned bounds `(min, max)` of the points.
    fn bounds(&self) -> (Point2<f64>, Point2<f64>) {
        self.points.iter().fold(
            (
                Point2::new(f64::INFINITY, f64::INFINITY),
                Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        )
    }
}

/// How far apart two open ends of a slice may be and still be joined `[mm]`: twice the upper
/// quartile of the slice's own segment lengths, the mesh's resolution in this plane (a quad cut
/// through its diagonal gives one long and one short segment, hence the quartile rather than
/// the median). A missing triangle leaves a gap about one segment long; a real opening (a cup's
/// rim, a slot cut on purpose) is many segments wide. (A triangle's edges are no measure here: a
/// cylinder's side triangles may be as tall as the object.)
fn join_tolerance(contours: &[Contour]) -> f64 {
    let mut lengths: Vec<f64> = contours
        .iter()
        .flat_map(|c| {
            (0..c.segment_count()).map(move |i| {
                let (a, b) = c.segment(i);
                (b - a).norm()
            })
        })
        .collect();
    if lengths.is_empty() {
        return 0.0;
    }
    let q = (3 * lengths.len()) / 4;
    let (_, quartile, _) = lengths.select_nth_unstable_by(q, f64::total_cmp);
    2.0 * *quartile
}

/// Joins open contours end to start where an end lies within `tol` of a start (its own start
/// closes it), nearest pairs first; the gap becomes a straight segment. Returns true if and
/// only if anything was joined. Contours that stay open are kept as they are, so the caller
/// can report them.
pub fn join_open(contours: &mut Vec<Contour>, tol: f64) -> bool {
    let open: Vec<usize> = (0..contours.len())
        .filter(|&i| !contours[i].is_closed)
        .collect();
    if open.is_empty()
        || tol.is_nan()
        || tol <= 0.0
        || !super::polygon_limits::join_allowed(open.len())
    {
        return false;
    }
    let Some((next, has_prev)) = links(contours, &open, tol) else {
        return false;
    };
    // Follow the links: paths from chains with no predecessor, then the cycles left.
    let mut done: HashSet<usize> = HashSet::new();
    let mut joined: Vec<Contour> = Vec::new();
    let starts = open
        .iter()
        .copied()
        .filter(|i| !has_prev.contains(i))
        .chain(open.iter().copied());
    for s in starts {
        if done.contains(&s) {
            continue;
        }
        let mut points: Vec<Point2<f64>> = Vec::new();
        let mut cur = s;
        let mut is_closed = false;
        loop {
            done.insert(cur);
            for p in &contours[cur].points {
                // A link that closes no gap (the end is the next start) adds no point twice.
                if points
                    .last()
                    .is_none_or(|q: &Point2<f64>| (q - p).norm() > TINY_SEGMENT_MM)
                {
                    points.push(*p);
                }
            }
            match next.get(&cur) {
                Some(&n) if n == s => {
                    is_closed = true;
                    break;
                }
                Some(&n) if !done.contains(&n) => cur = n,
                _ => break,
            }
        }
        if is_closed
            && points.len() > 1
            && (points[0] - points[points.len() - 1]).norm() <= TINY_SEGMENT_MM
        {
            points.pop();
        }
        if points.len() >= 2 {
            joined.push(Contour::from_polyline(points, is_closed));
        }
    }
    contours.retain(|c| c.is_closed);
    contours.extend(joined);
    true
}

/// The links that join the `open` contours end to start within `tol`, nearest first (each end
/// and each start used once): each contour's successor, and the contours with a predecessor.
/// `None` when no ends are that close.
fn links(
    contours: &[Contour],
    open: &[usize],
    tol: f64,
) -> Option<(HashMap<usize, usize>, HashSet<usize>)> {
    let first = |i: usize| contours[i].points[0];
    let last = |i: usize| *contours[i].points.last().expect("a contour has points");
    // Candidate links (end of a → start of b), nearest first; ties broken by index so the
    // result is deterministic.
    let (ends, starts): (Vec<[f64; 2]>, Vec<[f64; 2]>) = open
        .iter()
        .map(|&i| ([last(i).x, last(i).y], [first(i).x, first(i).y]))
        .unzip();
    let pairs: Vec<(f64, usize, usize)> = super::polygon_limits::pairs_within(&ends, &starts, tol)?
        .into_iter()
        .map(|(d, a, b)| (d, open[a], open[b]))
        .collect();
    if pairs.is_empty() {
        return None;
    }
    let mut next: HashMap<usize, usize> = HashMap::new();
    let mut has_prev: HashSet<usize> = HashSet::new();
    for &(_, a, b) in &pairs {
        if next.contains_key(&a) || has_prev.contains(&b) {
            continue;
        }
        next.insert(a, b);
        has_prev.insert(b);
    }
    Some((next, has_prev))
}

/// Returns true if and only if two closed outer (counter-clockwise) contours have overlapping
/// bounds: overlapping or nested shells, whose union must be taken. The contours of one closed
/// shell never overlap, except an island inside a hole, which the union leaves as it is.
fn has_overlapping_outers(contours: &[Contour]) -> bool {
    let outers: Vec<(Point2<f64>, Point2<f64>)> = contours
        .iter()
        .filter(|c| c.is_closed && c.signed_area() > 0.0)
        .map(Contour::bounds)
        .collect();
    outers.iter().enumerate().any(|(i, a)| {
        outers[i + 1..]
            .iter()
            .any(|b| a.0.x <= b.1.x && b.0.x <= a.1.x && a.0.y <= b.1.y && b.0.y <= a.1.y)
    })
}

/// The union of the closed contours by the non-zero winding rule (i_overlay): overlapping
/// shells become one outline, a hole stays a hole where no other shell fills it. Open contours
/// are kept as they are.
fn union_closed(contours: Vec<Contour>) -> Vec<Contour> {
    map_closed(contours, super::polygon_limits::union_rings)
}

/// Applies a polygon operation of i_overlay to the closed contours (as float rings) and turns
/// its output back into contours with geometric normals; open contours are kept as they are.
fn map_closed(
    contours: Vec<Contour>,
    op: impl FnOnce(Vec<Vec<[f64; 2]>>) -> Vec<Vec<Vec<[f64; 2]>>>,
) -> Vec<Contour> {
    let (closed, open): (Vec<Contour>, Vec<Contour>) =
        contours.into_iter().partition(|c| c.is_closed);
    let rings: Vec<Vec<[f64; 2]>> = closed
        .iter()
        .map(|c| c.points.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    let mut out: Vec<Contour> = op(rings)
        .into_iter()
        .flatten()
        .filter(|ring| ring.len() >= 3)
        .map(|ring| {
            Contour::from_polyline(
                ring.into_iter().map(|[x, y]| Point2::new(x, y)).collect(),
                true,
            )
        })
        // A ring thinner than TOUCH_MM on average is a sliver of round-off, which the union
        // leaves in one frame and not in another (rs_milk's fin, issue 30): it would count as
        // a piece to bridge.
        .filter(|c| c.signed_area().abs() > TOUCH_MM * c.length())
        .collect();
    out.extend(open);
    out
}

impl Slice {
    /// The slice with open ends within `tol_mm` of each other joined (straight across the gap)
    /// and the closed contours then united; unchanged when nothing joins. Unlike [`Self::bridged`]
    /// no gap between closed pieces is filled: the area stays the cut's.
    pub fn joined(self, tol_mm: f64) -> Slice {
        let mut contours = self.contours;
        if join_open(&mut contours, tol_mm) {
            finish(self.plane, union_closed(contours))
        } else {
            Slice { contours, ..self }
        }
    }

    /// Returns the number of contours that do not close.
    pub fn open_count(&self) -> usize {
        self.contours.iter().filter(|c| !c.is_closed).count()
    }

    /// The slice as a finger of width `gap_mm` meets it: open ends within `gap_mm` of each other
    /// joined, and, where the slice is in several pieces, every gap narrower than `gap_mm`
    /// between pieces filled (a morphological closing: the region grown by `gap_mm / 2` and
    /// shrunk back, so concave corners get a bevel of that size and convex ones stay). A
    /// finger cannot enter a perforation or a slot narrower than itself, so for the planner it
    /// is solid. A slice in one closed piece is returned unchanged.
    pub fn bridged(self, gap_mm: f64) -> Slice {
        self.bridged_within(gap_mm, 0.0)
    }

    /// [`Slice::bridged`], then [`Slice::simplified`] within `tol_mm`; a slice that needs its
    /// pieces bridged or its ends joined is simplified before as well (the morphological closing
    /// costs by the point, and closes nothing a finger could feel). A slice in one closed piece
    /// is only simplified.
    pub fn bridged_within(self, gap_mm: f64, tol_mm: f64) -> Slice {
        self.bridged_prepared(gap_mm, tol_mm).simplified(tol_mm)
    }

    /// [`Slice::bridged`], the slice simplified within `tol_mm` first if (and only if) it needs
    /// its pieces bridged or its ends joined: a slice in one closed piece is the exact cut.
    pub fn bridged_prepared(self, gap_mm: f64, tol_mm: f64) -> Slice {
        let needs_overlay = self.contours.iter().any(|c| !c.is_closed)
            || self
                .contours
                .iter()
                .filter(|c| c.is_closed && c.signed_area() > 0.0)
                .count()
                >= 2;
        let s = if needs_overlay && tol_mm > 0.0 {
            self.simplified(tol_mm)
        } else {
            self
        };
        s.bridged_exact(gap_mm, tol_mm)
    }

    /// [`Slice::bridged`], where the pieces are many, the dents of their grown union within
    /// `tol_mm` filled before it is shrunk back ([`close_gaps`]).
    fn bridged_exact(self, gap_mm: f64, tol_mm: f64) -> Slice {
        let plane = self.plane;
        let outermost = self.outermost;
        let mut contours = self.contours;
        let joined = join_open(&mut contours, gap_mm);
        let pieces = contours
            .iter()
            .filter(|c| c.is_closed && c.signed_area() > 0.0)
            .count();
        if pieces < 2 || gap_mm.is_nan() || gap_mm <= 0.0 {
            return if joined {
                finish(plane, union_closed(contours))
            } else {
                Slice {
                    plane,
                    contours,
                    outermost,
                }
            };
        }
        if pieces_touch(&contours) {
            // Pieces that touch to round-off (two shells meeting face to face) are one piece,
            // as the union makes them where their edges coincide: merged, not bridged.
            return finish(plane, close_gaps(contours, TOUCH_MM, 0.0));
        }
        finish(plane, close_gaps(contours, 0.5 * gap_mm, tol_mm))
    }
}

/// Two closed pieces of a slice this close `[mm]` touch: one piece. Shells that meet face to
/// face cut pieces whose shared edges coincide to round-off, which i_overlay's union merges in
/// one frame and leaves as two in another (single precision at 500 mm from the origin is 3e-5
/// mm); one piece was left as it is and two were bridged, with bevels a finger's width wide
/// at every concave corner (mw_golf_club, issue 30).
const TOUCH_MM: f64 = 1e-3;

/// Axis-aligned bounds `(min, max)` of a contour.
type Bounds = (Point2<f64>, Point2<f64>);

/// Returns true if and only if the closed outer contours are two or more and each touches
/// another (within [`TOUCH_MM`]) so that together they are one connected piece.
fn pieces_touch(contours: &[Contour]) -> bool {
    let outers: Vec<(&Contour, Bounds)> = contours
        .iter()
        .filter(|c| c.is_closed && c.signed_area() > 0.0)
        .map(|c| (c, c.bounds()))
        .collect();
    let n = outers.len();
    if n < 2 {
        return false;
    }
    let near = |(a, ab): &(&Contour, Bounds), (b, bb): &(&Contour, Bounds)| {
        let t = TOUCH_MM;
        if ab.0.x > bb.1.x + t || bb.0.x > ab.1.x + t || ab.0.y > bb.1.y + t || bb.0.y > ab.1.y + t
        {
            return false;
        }
        // A point of one within TOUCH_MM of a segment of the other (each tested only near
        // the other's bounds).
        let close = |p: &Contour, q: &Contour, (lo, hi): Bounds| {
            p.points
                .iter()
                .filter(|x| {
                    x.x >= lo.x - t && x.x <= hi.x + t && x.y >= lo.y - t && x.y <= hi.y + t
                })
                .any(|&x| {
                    (0..q.segment_count()).any(|i| {
                        let (s, e) = q.segment(i);
                        x.x >= s.x.min(e.x) - t
                            && x.x <= s.x.max(e.x) + t
                            && x.y >= s.y.min(e.y) - t
                            && x.y <= s.y.max(e.y) + t
                            && point_segment_distance(x, s, e) <= t
                    })
                })
        };
        close(a, b, *bb) || close(b, a, *ab)
    };
    // Connected components by a flood from the first piece.
    let mut reached = vec![false; n];
    reached[0] = true;
    let mut stack = vec![0];
    while let Some(i) = stack.pop() {
        for j in 0..n {
            if !reached[j] && near(&outers[i], &outers[j]) {
                reached[j] = true;
                stack.push(j);
            }
        }
    }
    reached.iter().all(|&r| r)
}

/// The distance from `p` to the segment `a`–`b` `[mm]`.
fn point_segment_distance(p: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let d = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + d * t)).norm()
}

impl Slice {
    /// The slice with every contour simplified within `tol_mm` ([`Contour::simplified`]): what a
    /// finger that does not feel relief shallower than `tol_mm` meets (issue 30), and far fewer
    /// segments for the search to test on a finely meshed or scanned object. `tol_mm <= 0`
    /// returns the slice unchanged.
    pub fn simplified(self, tol_mm: f64) -> Slice {
        if tol_mm.is_nan() || tol_mm <= 0.0 || self.contours.iter().all(|c| c.points.len() <= 3) {
            return self;
        }
        let contours = self.contours.iter().map(|c| c.simplified(tol_mm)).collect();
        finish(self.plane, contours)
    }
}

impl Contour {
    /// The contour with the dents a finger does not feel filled: Douglas–Peucker, one-sided.
    /// A point is dropped where it lies on the material's side of the simplified polyline by
    /// at most `tol_mm` (a tooth gap, a groove, a scanner's pit shallower than that), or off it
    /// by at most [`COLLINEAR_MM`] (the vertices of a finely divided flat face); a point that
    /// stands out beyond the polyline is never dropped, so the contour never moves into the
    /// object (a convex arc keeps every vertex, and the finger meets what is there). Points
    /// kept are original points. A closed contour is split at its first point and the point
    /// farthest from it, and keeps at least three points; an open one keeps its ends. Normals
    /// are taken from the geometry ([`Contour::from_polyline`]: material on the left of the
    /// direction of travel, the slicer's orientation). A contour with nothing to drop is
    /// returned as it is.
    pub fn simplified(&self, tol_mm: f64) -> Contour {
        let n = self.points.len();
        if n <= 3 || tol_mm.is_nan() || tol_mm <= 0.0 {
            return self.clone();
        }
        let p = &self.points;
        let mut keep = vec![false; n];
        // Spans (i, j) of indices to simplify, j > i, indices taken modulo n.
        let mut spans = Vec::new();
        if self.is_closed {
            let far = (1..n)
                .max_by(|&a, &b| {
                    (p[a] - p[0])
                        .norm_squared()
                        .total_cmp(&(p[b] - p[0]).norm_squared())
                        .then(b.cmp(&a))
                })
                .unwrap_or(1);
            keep[0] = true;
            keep[far] = true;
            spans.push((0, far));
            spans.push((far, n));
        } else {
            keep[0] = true;
            keep[n - 1] = true;
            spans.push((0, n - 1));
        }
        while let Some((i, j)) = spans.pop() {
            if j <= i + 1 {
                continue;
            }
            let (a, b) = (p[i % n], p[j % n]);
            let (mut worst, mut at) = (0.0, i);
            for k in i + 1..j {
                // Positive outward (right of the travel a → b), negative into the material.
                let s = outward_offset(p[k % n], a, b);
                let excess = (s - COLLINEAR_MM).max(-s - tol_mm);
                if excess > worst {
                    worst = excess;
                    at = k;
                }
            }
            if worst > 0.0 {
                keep[at % n] = true;
                spans.push((i, at));
                spans.push((at, j));
            }
        }
        let kept = keep.iter().filter(|&&k| k).count();
        if kept == n {
            return self.clone();
        }
        if self.is_closed && kept < 3 {
            return self.clone();
        }
        let points: Vec<Point2<f64>> = (0..n).filter(|&k| keep[k]).map(|k| p[k]).collect();
        Contour::from_polyline(points, self.is_closed)
    }
}

/// How far off a straight line a point may be dropped on the outer side of a contour `[mm]`:
/// the vertices of a finely divided flat face, written in any frame, are this close to it. A
/// file in single precision moves a vertex by up to 2⁻²⁴ of its distance from the origin, 3e-5
/// mm at 500 mm; at 1e-6 mm, a flat panel's cut kept a point in one frame and dropped it in
/// another, which moved the join tolerance of an open ball's slices (twice the upper quartile
/// of their segment lengths) across a gap between its panels (issue 30).
pub const COLLINEAR_MM: f64 = 1e-4;

/// The signed distance of `q` from the line through `a` and `b`, positive on the right of the
/// direction `a → b` (outside the material) `[mm]`; the distance to `a` when `a = b`.
fn outward_offset(q: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let d = b - a;
    let len = d.norm();
    if len == 0.0 {
        return (q - a).norm();
    }
    let w = q - a;
    -(d.x * w.y - d.y * w.x) / len
}

/// Morphological closing of the closed contours by a polygon of inradius `r` (i_overlay's outline
/// offset, grown then shrunk), where the contours are many the dents of the grown union within
/// `dent_mm` filled before the shrink ([`super::polygon_limits::close_rings`]: a bound on the
/// shrink's work); open contours are kept as they are.
fn close_gaps(contours: Vec<Contour>, r: f64, dent_mm: f64) -> Vec<Contour> {
    // Bevel joins: the structuring element is then a polygon rather than a disc (convex corners
    // come back exactly, a bridged gap's edge is straight to within r (1 - cos(turn / 2))), and
    // the offset makes no arc points, which on a slice of many pieces costs several times more
    // than the rest of the planner.
    map_closed(contours, |rings| {
        super::polygon_limits::close_rings(rings, r, |grown| fill_ring_dents(grown, dent_mm))
    })
}

/// Each ring with its dents within `tol_mm` filled ([`Contour::simplified`]: points are only
/// dropped where that moves the outline outward, into the empty side); `tol_mm <= 0` keeps
/// the rings as they are.
fn fill_ring_dents(rings: Vec<Vec<[f64; 2]>>, tol_mm: f64) -> Vec<Vec<[f64; 2]>> {
    if tol_mm.is_nan() || tol_mm <= 0.0 {
        return rings;
    }
    rings
        .into_iter()
        .map(|ring| {
            let points = ring.iter().map(|&[x, y]| Point2::new(x, y)).collect();
            let c = Contour::from_polyline(points, true).simplified(tol_mm);
            c.points.iter().map(|p| [p.x, p.y]).collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::objects::{cylinder, prism};
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn pieces_that_touch_are_merged_not_bridged_and_slivers_dropped() {
        // An L of two closed pieces that share an edge to 1e-5 mm (two shells meeting face to
        // face, as the union leaves them in one frame and merges them in another): one piece,
        // its concave corner kept, not bevelled by the 14 mm closing. Apart by 2 mm, they are
        // bridged: the 2 mm gap filled (20 mm²) and the concave corner bevelled.
        let square = |x0: f64, y0: f64, w: f64, h: f64| {
            Contour::from_polyline(
                vec![
                    Point2::new(x0, y0),
                    Point2::new(x0 + w, y0),
                    Point2::new(x0 + w, y0 + h),
                    Point2::new(x0, y0 + h),
                ],
                true,
            )
        };
        let l_shape = |gap: f64| {
            finish(
                Plane::horizontal(0.0),
                vec![
                    square(0.0, 0.0, 10.0, 30.0),
                    square(10.0 + gap, 0.0, 30.0, 10.0),
                ],
            )
        };
        let area = |s: &Slice| s.contours.iter().map(Contour::signed_area).sum::<f64>();
        let touching = l_shape(1e-5).bridged(14.0);
        assert_eq!(touching.contours.len(), 1, "{touching:?}");
        assert!((area(&touching) - 600.0).abs() < 0.1, "{}", area(&touching));
        let apart = l_shape(2.0).bridged(14.0);
        assert_eq!(apart.contours.len(), 1);
        assert!(area(&apart) > 620.0, "{}", area(&apart));
        // A ring thinner than TOUCH_MM on average is not a piece.
        let sliver = finish(
            Plane::horizontal(0.0),
            vec![square(0.0, 0.0, 10.0, 30.0), square(50.0, 0.0, 20.0, 1e-5)],
        );
        assert_eq!(union_closed(sliver.contours).len(), 1);
    }

    #[test]
    fn planes_map_points_both_ways() {
        let p = Point3::new(3.0, 4.0, 5.0);
        let table = [
            (Plane::vertical(0.0), Point2::new(3.0, 5.0), -4.0),
            (Plane::vertical(FRAC_PI_2), Point2::new(4.0, 5.0), 3.0),
            (Plane::horizontal(2.0), Point2::new(3.0, 4.0), 3.0),
        ];
        for (plane, q, distance) in table {
            assert!((plane.to_2d(&p) - q).norm() < 1e-12, "{plane:?}");
            assert!((plane.distance(&p) - distance).abs() < 1e-12, "{plane:?}");
            let back = plane.to_3d(&plane.to_2d(&p));
            assert!((plane.distance(&back)).abs() < 1e-12, "{plane:?}");
        }
    }

    #[test]
    fn a_box_cut_three_ways() {
        // 40 (x) × 100 (y) × 80 (z) mm about the z axis.
        let b = prism(40.0, 100.0, 80.0);
        // (plane, contours, area, length): a cut across the middle, two vertical cuts through the
        // axis (s along x, then along y) and a plane above the box.
        let table = [
            (Plane::horizontal(40.0), 1, 4000.0, 280.0),
            (Plane::vertical(0.0), 1, 3200.0, 240.0),
            (Plane::vertical(FRAC_PI_2), 1, 8000.0, 360.0),
            (Plane::horizontal(90.0), 0, 0.0, 0.0),
        ];
        for (plane, count, area, length) in table {
            let s = slice(&b, &plane, SliceOptions::default());
            assert_eq!(s.contours.len(), count, "{plane:?}");
            assert_eq!(s.open_count(), 0, "{plane:?}");
            let a: f64 = s.contours.iter().map(Contour::signed_area).sum();
            let l: f64 = s.contours.iter().map(Contour::length).sum();
            assert!(
                (a - area).abs() < 1e-6,
                "{plane:?}: area {a}, expected {area}"
            );
            assert!(
                (l - length).abs() < 1e-6,
                "{plane:?}: length {l}, expected {length}"
            );
            assert!(s.contours.iter().all(|c| !c.is_hole()));
        }
    }

    #[test]
    fn an_indexed_slice_is_the_plain_slice_bit_for_bit() {
        // Planes at every tilt and height through a cup (many triangles, open top) and the
        // chapter 4 object, including planes through vertices (Z = 0, the top) and planes that
        // miss: the index must hand over exactly the triangles the plain cut uses.
        for mesh in [
            crate::objects::frustum(56.0, 80.0, 110.0),
            crate::objects::chapter4(&crate::objects::Chapter4Dims::default()),
            crate::objects::uv_sphere(30.0, 24),
        ] {
            let index = SliceIndex::new(&mesh);
            let (lo, hi) = mesh.bounds();
            let mut planes = 0;
            for k in 0..=24 {
                let z = lo.z - 1.0 + (hi.z - lo.z + 2.0) * k as f64 / 24.0;
                for pitch_deg in [-12.0f64, 0.0, 7.0, 30.0, 90.0] {
                    let plane = Plane::finger(Point3::new(3.0, -2.0, z), pitch_deg.to_radians());
                    assert_eq!(
                        slice(&mesh, &plane, SliceOptions::indexed(&index)),
                        slice(&mesh, &plane, SliceOptions::default()),
                        "z {z}, pitch {pitch_deg}"
                    );
                    planes += 1;
                }
            }
            for z in [lo.z, hi.z] {
                let plane = Plane::horizontal(z);
                assert_eq!(
                    slice(&mesh, &plane, SliceOptions::indexed(&index)),
                    slice(&mesh, &plane, SliceOptions::default())
                );
            }
            assert_eq!(planes, 125);
        }
    }

    /// Two boxes overlapping in a cross and a cylinder beside them, 10 mm apart: three shells,
    /// so every finger-height plane needs uniting and bridging.
    fn three_shells() -> Mesh {
        let mut soup = Vec::new();
        let mut add = |m: Mesh, dx: f64| {
            for t in &m.triangles {
                soup.push(t.map(|i| m.vertices[i as usize] + Vector3::new(dx, 0.0, 0.0)));
            }
        };
        add(prism(60.0, 20.0, 80.0), 0.0);
        // A quarter millimetre off the first, so that no vertex of one is welded to the other's.
        add(prism(20.0, 60.0, 80.0), 0.25);
        add(cylinder(16.0, 80.0), 48.0);
        Mesh::from_triangles(&soup).0
    }

    /// `plane`'s points in another in-plane frame: `u` and `v` turned by `turn` about the
    /// normal and the origin moved by `(du, dv)` within the plane.
    fn reframed(plane: &Plane, turn: f64, du: f64, dv: f64) -> Plane {
        let (s, c) = turn.sin_cos();
        Plane {
            origin: plane.origin + plane.u * du + plane.v * dv,
            u: plane.u * c + plane.v * s,
            v: plane.v * c - plane.u * s,
        }
    }

    /// The largest distance of a point of `a` from the nearest segment of `b` `[mm]`.
    fn farthest_from(a: &Slice, b: &Slice) -> f64 {
        let to_segment = |p: Point2<f64>, (s, t): (Point2<f64>, Point2<f64>)| {
            let d = t - s;
            let k = ((p - s).dot(&d) / d.norm_squared().max(1e-300)).clamp(0.0, 1.0);
            (p - (s + d * k)).norm()
        };
        let near = |p: Point2<f64>| {
            b.contours
                .iter()
                .flat_map(|c| (0..c.segment_count()).map(move |i| c.segment(i)))
                .map(|seg| to_segment(p, seg))
                .fold(f64::INFINITY, f64::min)
        };
        a.contours
            .iter()
            .flat_map(|c| c.points.iter())
            .map(|&p| near(p))
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_bridged_plane_is_the_same_whatever_its_frame_and_the_cache() {
        // Finger planes through three shells at five pitches and four heights, each asked for
        // in three frames of the same plane: the cached slice, re-expressed, is the direct one
        // (slice, then bridge) within 2 mm, outline to outline; and a fresh index (a cold cache)
        // gives the same bits as one that cut the plane in another frame before.
        let (gap, tol) = (14.0, 0.5);
        let mesh = three_shells();
        assert_eq!(mesh.shell_count(), 3);
        let warm = SliceIndex::new(&mesh);
        let mut united = 0;
        for z in [5.0, 31.0, 40.0, 77.5] {
            for pitch_deg in [-12.0f64, -0.2, 0.0, 3.0, 20.0] {
                let base = Plane::finger(Point3::new(40.0, 3.0, z), pitch_deg.to_radians());
                for (turn, du, dv) in [(0.0, 0.0, 0.0), (0.7, -12.5, 4.0), (2.9, 30.0, -8.0)] {
                    let plane = reframed(&base, turn, du, dv);
                    let direct = slice(&mesh, &plane, SliceOptions::indexed(&warm).within(tol))
                        .bridged_within(gap, tol);
                    let cached = slice(
                        &mesh,
                        &plane,
                        SliceOptions::indexed(&warm).within(tol).bridged(gap),
                    );
                    let cold = slice(
                        &mesh,
                        &plane,
                        SliceOptions::indexed(&SliceIndex::new(&mesh))
                            .within(tol)
                            .bridged(gap),
                    );
                    assert_eq!(cached, cold, "z {z}, pitch {pitch_deg}, turn {turn}");
                    // The direct slice itself moves with the frame: i_overlay's rings start
                    // where its grid puts them, the one-sided simplification splits a contour at
                    // its first point, so which dents under the relief are filled depends on the
                    // frame, and the closing's bevels in concave corners move with the vertices
                    // kept (1.4 mm measured). A wrong mapping would be tens of millimetres off.
                    assert_eq!(cached.contours.len(), direct.contours.len(), "z {z}");
                    let off = farthest_from(&cached, &direct).max(farthest_from(&direct, &cached));
                    assert!(
                        off < 2.0,
                        "{off} mm apart, z {z}, pitch {pitch_deg}, turn {turn}"
                    );
                    // The three shells are one piece, bridged.
                    united += usize::from(cached.contours.len() == 1);
                }
            }
        }
        assert!(united >= 20, "{united} of 60 planes one piece");
    }

    #[test]
    fn a_plane_cut_in_one_piece_is_the_direct_cut_bit_for_bit() {
        // One closed shell: the cache keeps nothing, every frame is cut afresh, bits and all.
        let mesh = crate::objects::frustum(56.0, 80.0, 110.0);
        let index = SliceIndex::new(&mesh);
        for z in [0.0, 20.0, 55.5, 109.0] {
            for pitch_deg in [-7.0f64, 0.0, 6.5] {
                let base = Plane::finger(Point3::new(30.0, 0.0, z), pitch_deg.to_radians());
                for (turn, du, dv) in [(0.0, 0.0, 0.0), (1.1, 5.0, -3.0)] {
                    let plane = reframed(&base, turn, du, dv);
                    assert_eq!(
                        slice(
                            &mesh,
                            &plane,
                            SliceOptions::indexed(&index).within(0.5).bridged(14.0)
                        ),
                        slice(&mesh, &plane, SliceOptions::indexed(&index).within(0.5))
                            .bridged_within(14.0, 0.5)
                    );
                }
            }
        }
    }

    #[test]
    fn a_cut_as_loose_segments_is_the_raw_cut_unrepaired() {
        // Through the three shells at mid-height: the boxes' two rectangles and the cylinder's
        // circle, overlapping and apart as cut; the repaired slice unites the cross. The loose
        // segments the palm's backoff takes are the raw contours' segments, bit for bit.
        let mesh = three_shells();
        let index = SliceIndex::new(&mesh);
        let plane = Plane::horizontal(40.0);
        let dist = |i: u32| plane.distance(&mesh.vertices[i as usize]);
        let tris = index.candidates(&plane);
        let raw = raw_contours(&mesh, &plane, tris.into_iter(), &dist);
        assert_eq!(raw.len(), 3);
        assert!(raw.iter().all(|c| c.is_closed));
        let areas: Vec<f64> = raw.iter().map(|c| c.signed_area()).collect();
        assert!((areas[0] - 1200.0).abs() < 1e-6 && (areas[1] - 1200.0).abs() < 1e-6);
        let circle = std::f64::consts::PI * 64.0;
        assert!(areas[2] < circle && areas[2] > 0.98 * circle, "{areas:?}");
        let repaired = slice(&mesh, &plane, SliceOptions::indexed(&index));
        assert_eq!(repaired.contours.len(), 2);
        assert!((repaired.contours[0].signed_area() - 2000.0).abs() < 1e-3);
        let key = |(a, b): (Point2<f64>, Point2<f64>)| [a.x, a.y, b.x, b.y].map(f64::to_bits);
        let mut from_contours: Vec<[u64; 4]> = raw
            .iter()
            .flat_map(|c| (0..c.segment_count()).map(|i| key(c.segment(i))))
            .collect();
        let mut loose: Vec<[u64; 4]> = cut_segments_indexed(&mesh, &index, &plane)
            .into_iter()
            .map(key)
            .collect();
        from_contours.sort_unstable();
        loose.sort_unstable();
        assert_eq!(loose, from_contours);
    }

    #[test]
    fn a_cylinder_cut_across_is_nearly_a_circle() {
        let c = cylinder(40.0, 124.0);
        let s = slice(&c, &Plane::horizontal(62.0), SliceOptions::default());
        assert_eq!(s.contours.len(), 1);
        let area = s.contours[0].signed_area();
        let circle = PI * 20.0 * 20.0;
        assert!(
            area < circle && area > 0.99 * circle,
            "area {area}, circle {circle}"
        );
        // Every outward normal points away from the axis.
        let c0 = &s.contours[0];
        for i in 0..c0.segment_count() {
            let (a, b) = c0.segment(i);
            let mid = (a.coords + b.coords) / 2.0;
            assert!(c0.normals[i].dot(&mid) > 0.0, "segment {i}");
        }
    }

    #[test]
    fn polylines_count_their_segments() {
        let square = vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.0, 1.0),
        ];
        let table = [(true, 4, 1.0, 4.0), (false, 3, 1.0, 3.0)];
        for (closed, segments, area, length) in table {
            let c = Contour::from_polyline(square.clone(), closed);
            assert_eq!(c.segment_count(), segments);
            assert_eq!(c.signed_area(), area);
            assert_eq!(c.length(), length);
        }
        // Counter-clockwise: the first segment's outward normal points down (−y).
        let c = Contour::from_polyline(square.clone(), true);
        assert_eq!(c.normals[0], Vector2::new(0.0, -1.0));
        let mut reversed = square;
        reversed.reverse();
        assert!(Contour::from_polyline(reversed, true).is_hole());
    }
}
