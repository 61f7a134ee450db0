//! The convex hull of points in the 6-D wrench space, in pure Rust.
//!
//! Input: points (wrenches). Output: the hull's simplicial facets (vertex indices into the
//! input, outward unit normal, offset), its vertices and its volume; `None` when the points
//! span fewer than six dimensions or round-off defeats every attempt.
//!
//! The method is quickhull (Barber, Dobkin and Huhdanpaa, "The Quickhull Algorithm for Convex
//! Hulls", ACM TOMS 22(4), 1996): an initial simplex, every other point assigned to a facet it
//! lies beyond (its outside set), and the farthest point of a facet's outside set added by
//! beneath–beyond (the facets it sees replaced by the cone from it over their horizon) until no
//! outside set is left.
//!
//! Wrench sets are degenerate by construction: each contact's friction-cone edges lie in one
//! 2-D affine plane of the 6-D space, and symmetric grasps put many points on one hyperplane.
//! As qhull's `QJ` option does, the input is joggled: every coordinate moves by a
//! pseudo-random amount of at most [`JOGGLE`] of the set's largest coordinate, drawn from a
//! fixed seed (so the hull is the same run after run, on any thread), which puts the points in
//! general position with probability one, so that every facet is a simplex. When round-off
//! still breaks an attempt (a horizon that does not close, a facet the interior point is not
//! inside of), the joggle grows tenfold, up to [`MAX_JOGGLE`].
//!
//! Joggled input makes thin facets (slivers: four nearly coplanar edge wrenches of one contact
//! with two other points). Their hyperplanes are defined by differences of the joggle's size,
//! so a normal taken by Gram–Schmidt in f64 can be off by `1e-16 / 1e-11` and mislead later
//! visibility tests; such a facet's normal is computed again in double-double arithmetic
//! (about 32 digits: Dekker 1971, "A floating-point technique for extending the available
//! precision"), where the joggle's differences are exact, and only then rounded.

use super::Wrench;
use std::collections::VecDeque;

const DIM: usize = 6;

/// The first joggle, relative to the set's largest absolute coordinate.
pub const JOGGLE: f64 = 1e-9;

/// The largest joggle tried before giving up (five attempts in all).
pub const MAX_JOGGLE: f64 = 1e-5;

/// A facet of the hull.
#[derive(Debug, Clone, PartialEq)]
pub struct HullFacet {
    /// Indices into the input of the facet's six vertices.
    pub vertices: [u32; DIM],
    /// Outward unit normal: the plane of the facet's vertices as given where they span it
    /// well, else the joggled facet's.
    pub normal: Wrench,
    /// `normal · x + offset = 0` through the facet's farthest vertex (negative when the origin
    /// is inside).
    pub offset: f64,
}

/// A convex hull in 6-D.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexHull {
    /// Simplicial facets.
    pub facets: Vec<HullFacet>,
    /// Indices into the input of the hull's vertices, sorted.
    pub vertices: Vec<usize>,
    /// The hull's volume, from the points as given.
    pub volume: f64,
    /// The smallest support of the input over the facets' normals, `min_f max_p n_f · p`: the
    /// distance from the origin to the nearest facet plane when the origin is inside (then
    /// positive), negative when it is outside.
    pub nearest: f64,
    /// The joggle the hull was built with, relative to the set's largest coordinate.
    pub joggle: f64,
}

/// The convex hull of `points`, or `None` when they are not finite, span fewer than six
/// dimensions, or round-off defeats every joggle up to [`MAX_JOGGLE`].
///
/// The joggle decides only which facets the hull is cut into: the volume is summed over the
/// facets' simplices with the points as given (the joggled hull's facets, unjoggled, tile the
/// true boundary, some of them flat), and [`ConvexHull::nearest`] evaluates the true support
/// function, so both are exact up to round-off rather than to the joggle.
pub fn convex_hull(points: &[Wrench]) -> Option<ConvexHull> {
    if points.len() <= DIM || !points.iter().flatten().all(|v| v.is_finite()) {
        return None;
    }
    let scale = points.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return None;
    }
    // The points as given must span six dimensions; the joggled ones then share this simplex.
    let simplex = initial_simplex(points, scale)?;
    let mut joggle = JOGGLE;
    while joggle <= MAX_JOGGLE * (1.0 + 1e-9) {
        let moved: Vec<Wrench> = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                std::array::from_fn(|k| p[k] + joggle * scale * unit_noise((i * DIM + k) as u64))
            })
            .collect();
        if let Some((facets, interior)) = quickhull(&moved, simplex, scale) {
            return Some(finish(points, &moved, &facets, interior, joggle));
        }
        joggle *= 10.0;
    }
    None
}

/// The hull's facets, vertices, volume and nearest facet from the joggled hull's simplices.
fn finish(
    points: &[Wrench],
    moved: &[Wrench],
    simplices: &[([u32; DIM], Wrench)],
    interior: [u32; DIM + 1],
    joggle: f64,
) -> ConvexHull {
    let centre = |pts: &[Wrench]| -> Wrench {
        let mut c = [0.0; DIM];
        for &i in &interior {
            for (a, b) in c.iter_mut().zip(&pts[i as usize]) {
                *a += b / (DIM + 1) as f64;
            }
        }
        c
    };
    let (c_true, c_moved) = (centre(points), centre(moved));
    let det = |pts: &[Wrench], v: &[u32; DIM], c: &Wrench| {
        nalgebra::Matrix6::from_fn(|r, k| pts[v[k] as usize][r] - c[r]).determinant()
    };
    let mut volume = 0.0;
    let mut vertices = Vec::with_capacity(simplices.len() * DIM);
    let mut facets = Vec::with_capacity(simplices.len());
    for (v, n_moved) in simplices {
        // Signed by the joggled simplex's orientation, so that a fold the joggle made (where
        // it is larger than the set's own features) cancels.
        volume += det(moved, v, &c_moved).signum() * det(points, v, &c_true) / 720.0;
        vertices.extend(v.iter().map(|&i| i as usize));
        let reach = v
            .iter()
            .map(|&q| dot(n_moved, &points[q as usize]))
            .fold(f64::MIN, f64::max);
        facets.push(HullFacet {
            vertices: *v,
            normal: *n_moved,
            offset: -reach,
        });
    }
    vertices.sort_unstable();
    vertices.dedup();
    // The nearest facet: the true support function in a facet's direction is at least that
    // facet's own reach, and the joggled normals are within the joggle of the true ones, so
    // only facets that reach less than the best found so far (plus the joggle's margin) need
    // the whole set, in their joggled direction and in that of their vertices as given where
    // these span a plane well (then exactly the true facet's).
    let support = |n: &Wrench| points.iter().map(|q| dot(n, q)).fold(f64::MIN, f64::max);
    let margin = 1e3 * joggle * points.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut order: Vec<usize> = (0..facets.len()).collect();
    order.sort_by(|&a, &b| {
        facets[b]
            .offset
            .total_cmp(&facets[a].offset)
            .then(a.cmp(&b))
    });
    let mut nearest = f64::INFINITY;
    for f in order {
        if -facets[f].offset >= nearest + margin {
            break;
        }
        nearest = nearest.min(support(&facets[f].normal));
        let p: [Wrench; DIM] = std::array::from_fn(|k| points[facets[f].vertices[k] as usize]);
        if let Some((n, thin)) = plane_normal_and_thinness(&p) {
            if thin >= 1e3 * joggle {
                let s = if dot(&n, &facets[f].normal) < 0.0 {
                    -1.0
                } else {
                    1.0
                };
                nearest = nearest.min(support(&n.map(|x| s * x)));
            }
        }
    }
    ConvexHull {
        facets,
        vertices,
        volume: volume.abs(),
        nearest,
        joggle,
    }
}

/// A pseudo-random number in `[-1, 1]` for `key` (splitmix64).
fn unit_noise(key: u64) -> f64 {
    let mut z = key.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

fn dot(a: &Wrench, b: &Wrench) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A facet under construction.
struct Facet {
    v: [u32; DIM],
    n: Wrench,
    /// `n · x = plane` on the facet.
    plane: f64,
    /// `nb[k]`: the facet across the ridge opposite `v[k]`.
    nb: [u32; DIM],
    outside: Vec<u32>,
    alive: bool,
    /// The step that last looked at this facet from a new point, and whether it saw it.
    seen: u32,
    visible: bool,
}

/// Facet `v`'s ridge opposite vertex `k`, packed (25 bits a vertex: `v` is sorted, so the
/// key is the same from either facet that shares the ridge).
fn ridge_key(v: &[u32; DIM], k: usize) -> u128 {
    v.iter()
        .enumerate()
        .filter(|&(i, _)| i != k)
        .fold(0u128, |key, (_, &x)| key << 25 | x as u128)
}

struct Builder<'a> {
    pts: &'a [Wrench],
    interior: Wrench,
    facets: Vec<Facet>,
    /// Points nearer a facet's plane than this are not beyond it.
    tol: f64,
    /// Counts the points added, to mark the facets each one has looked at.
    stamp: u32,
}

impl Builder<'_> {
    /// The facet on `v`, oriented away from the interior point; `None` when degenerate or when
    /// the interior point is not strictly inside its half-space.
    fn facet(&self, v: [u32; DIM]) -> Option<Facet> {
        let p: [Wrench; DIM] = std::array::from_fn(|k| self.pts[v[k] as usize]);
        let mut n = plane_normal(&p)?;
        let mut plane = p.iter().map(|q| dot(&n, q)).sum::<f64>() / DIM as f64;
        let c = dot(&n, &self.interior);
        if c > plane {
            n = n.map(|x| -x);
            plane = -plane;
        }
        (plane - dot(&n, &self.interior) > self.tol).then_some(Facet {
            v,
            n,
            plane,
            nb: [u32::MAX; DIM],
            outside: Vec::new(),
            alive: true,
            seen: 0,
            visible: false,
        })
    }

    fn distance(&self, f: usize, p: u32) -> f64 {
        let f = &self.facets[f];
        dot(&f.n, &self.pts[p as usize]) - f.plane
    }
}

/// The greedy initial simplex: the point of least first coordinate, then each time the point
/// farthest from the affine span of those chosen (Gram–Schmidt residual).
fn initial_simplex(pts: &[Wrench], scale: f64) -> Option<[u32; DIM + 1]> {
    let first = (0..pts.len()).min_by(|&a, &b| pts[a][0].total_cmp(&pts[b][0]))?;
    let mut chosen = vec![first];
    let mut basis: Vec<Wrench> = Vec::new();
    let origin = pts[first];
    for _ in 0..DIM {
        let mut best: Option<(f64, usize, Wrench)> = None;
        for (i, p) in pts.iter().enumerate() {
            let mut e: Wrench = std::array::from_fn(|k| p[k] - origin[k]);
            for _ in 0..2 {
                for b in &basis {
                    let c = dot(b, &e);
                    for (x, y) in e.iter_mut().zip(b) {
                        *x -= c * y;
                    }
                }
            }
            let len = dot(&e, &e).sqrt();
            if best.as_ref().is_none_or(|(l, _, _)| len > *l) {
                best = Some((len, i, e));
            }
        }
        let (len, i, e) = best?;
        if len <= 1e-9 * scale {
            return None;
        }
        chosen.push(i);
        basis.push(e.map(|x| x / len));
    }
    Some(std::array::from_fn(|k| chosen[k] as u32))
}

/// The joggled hull's simplicial facets (vertices, outward normal) and the initial simplex
/// (whose centroid is inside), or `None` on round-off.
#[allow(clippy::type_complexity)]
fn quickhull(
    pts: &[Wrench],
    mut simplex: [u32; DIM + 1],
    scale: f64,
) -> Option<(Vec<([u32; DIM], Wrench)>, [u32; DIM + 1])> {
    if pts.len() >= 1 << 25 {
        return None;
    }
    simplex.sort_unstable();
    let mut interior = [0.0; DIM];
    for &i in &simplex {
        for (a, b) in interior.iter_mut().zip(&pts[i as usize]) {
            *a += b / (DIM + 1) as f64;
        }
    }
    let mut b = Builder {
        pts,
        interior,
        facets: Vec::new(),
        tol: 2e-14 * scale,
        stamp: 0,
    };
    // The simplex's facets: each leaves out one vertex; facet k is across from simplex[k], so
    // its neighbour across the ridge opposite its vertex simplex[j] is facet j.
    for k in 0..=DIM {
        let v: [u32; DIM] = std::array::from_fn(|j| simplex[if j < k { j } else { j + 1 }]);
        let mut f = b.facet(v)?;
        for j in 0..DIM {
            f.nb[j] = if j < k { j } else { j + 1 } as u32;
        }
        b.facets.push(f);
    }
    let in_simplex: std::collections::HashSet<u32> = simplex.iter().copied().collect();
    for p in 0..pts.len() as u32 {
        if in_simplex.contains(&p) {
            continue;
        }
        if let Some(f) = (0..b.facets.len()).find(|&f| b.distance(f, p) > b.tol) {
            b.facets[f].outside.push(p);
        }
    }
    let mut queue: VecDeque<u32> = (0..b.facets.len() as u32).collect();
    // Every step adds a point for good, so the loop ends; the bound guards against a bug.
    let mut steps = 0usize;
    while let Some(f) = queue.pop_front() {
        let fi = f as usize;
        if !b.facets[fi].alive || b.facets[fi].outside.is_empty() {
            continue;
        }
        steps += 1;
        if steps > pts.len() + 1 {
            return None;
        }
        let far = *b.facets[fi].outside.iter().max_by(|&&p, &&q| {
            b.distance(fi, p)
                .total_cmp(&b.distance(fi, q))
                .then(q.cmp(&p))
        })?;
        let new = add_point(&mut b, f, far)?;
        queue.extend(new);
    }
    let simplices = b
        .facets
        .iter()
        .filter(|f| f.alive)
        .map(|f| (f.v, f.n))
        .collect();
    Some((simplices, simplex))
}

/// Adds point `p`, beyond facet `from`: the facets it sees (reached from `from`) die, the cone
/// from `p` over their horizon replaces them, and their outside points go to the new facets
/// (or are dropped, being inside). Returns the new facets' ids; `None` on round-off (a new
/// facet degenerate, or a horizon that does not close).
fn add_point(b: &mut Builder, from: u32, p: u32) -> Option<Vec<u32>> {
    let visible = visible_from(b, from, p)?;
    let first_new = b.facets.len();
    // Each new facet's ridges through `p`, to be paired with the one new facet sharing each.
    let mut open: Vec<(u128, u32, u8)> = Vec::new();
    for &f in &visible {
        for k in 0..DIM {
            let g = b.facets[f as usize].nb[k];
            if b.facets[g as usize].visible {
                continue;
            }
            // The ridge (sorted, as every facet's vertices are) with `p` put in its place.
            let (v, pos) = ridge_with(&b.facets[f as usize].v, k, p);
            let mut nf = b.facet(v)?;
            let id = b.facets.len() as u32;
            nf.nb[pos] = g;
            // The horizon neighbour now faces the new facet across the same ridge.
            let slot = b.facets[g as usize].nb.iter().position(|&x| x == f)?;
            b.facets.push(nf);
            b.facets[g as usize].nb[slot] = id;
            for j in (0..DIM).filter(|&j| j != pos) {
                open.push((ridge_key(&v, j), id, j as u8));
            }
        }
    }
    // A closed horizon pairs every ridge exactly once.
    open.sort_unstable();
    if !open.len().is_multiple_of(2) {
        return None;
    }
    for pair in open.chunks_exact(2) {
        let [(ka, a, ja), (kb, bb, jb)] = [pair[0], pair[1]];
        if ka != kb {
            return None;
        }
        b.facets[a as usize].nb[ja as usize] = bb;
        b.facets[bb as usize].nb[jb as usize] = a;
    }
    if open.windows(3).any(|w| w[0].0 == w[2].0) {
        return None;
    }
    let new: Vec<u32> = (first_new as u32..b.facets.len() as u32).collect();
    let mut orphans = Vec::new();
    for &f in &visible {
        b.facets[f as usize].alive = false;
        orphans.append(&mut b.facets[f as usize].outside);
    }
    orphans.sort_unstable();
    for q in orphans.into_iter().filter(|&q| q != p) {
        if let Some(&f) = new.iter().find(|&&f| b.distance(f as usize, q) > b.tol) {
            b.facets[f as usize].outside.push(q);
        }
    }
    Some(new)
}

/// The facets `p` is beyond, found from `from` across neighbours (each marked visible and
/// seen); `None` when `p` is coplanar with one within round-off (joggle more).
fn visible_from(b: &mut Builder, from: u32, p: u32) -> Option<Vec<u32>> {
    b.stamp += 1;
    let stamp = b.stamp;
    b.facets[from as usize].seen = stamp;
    b.facets[from as usize].visible = true;
    let mut visible = vec![from];
    let mut i = 0;
    while i < visible.len() {
        let f = visible[i];
        i += 1;
        for k in 0..DIM {
            let g = b.facets[f as usize].nb[k];
            if b.facets[g as usize].seen == stamp {
                continue;
            }
            let d = b.distance(g as usize, p);
            if d.abs() <= b.tol {
                // Coplanar within round-off: joggle more (as qhull's QJ does).
                return None;
            }
            let vis = d > b.tol;
            b.facets[g as usize].seen = stamp;
            b.facets[g as usize].visible = vis;
            if vis {
                visible.push(g);
            }
        }
    }
    Some(visible)
}

/// A facet's vertices `facet` (sorted) without the `k`-th, with `p` in its sorted place: the
/// new facet's vertices and `p`'s position among them.
fn ridge_with(facet: &[u32; DIM], k: usize, p: u32) -> ([u32; DIM], usize) {
    let mut v = [0u32; DIM];
    let mut pos = 0;
    let mut j = 0;
    for (i, &x) in facet.iter().enumerate() {
        if i == k {
            continue;
        }
        if x < p {
            v[j] = x;
            j += 1;
            pos = j;
        } else {
            v[j + 1] = x;
            j += 1;
        }
    }
    v[pos] = p;
    (v, pos)
}

/// The unit normal of the hyperplane through the six points `p`, or `None` when they span
/// fewer than five dimensions (to round-off).
pub fn plane_normal(p: &[Wrench; DIM]) -> Option<Wrench> {
    plane_normal_and_thinness(p).map(|(n, _)| n)
}

/// The unit normal through `p` and the simplex's thinness: the smallest Gram–Schmidt residual
/// of its edges from `p[0]`, relative to the longest edge coordinate. Gram–Schmidt in f64 when
/// the simplex is well shaped; in double-double arithmetic when it is thin (a residual under
/// 0.02), where f64 would lose the normal's direction across the thin side.
fn plane_normal_and_thinness(p: &[Wrench; DIM]) -> Option<(Wrench, f64)> {
    let scale = p
        .iter()
        .flat_map(|q| q.iter().zip(&p[0]).map(|(a, b)| (a - b).abs()))
        .fold(0.0f64, f64::max);
    if scale == 0.0 {
        return None;
    }
    let project_out = |basis: &[Wrench], v: &mut Wrench| {
        for q in basis {
            let c = dot(q, v);
            for (a, b) in v.iter_mut().zip(q) {
                *a -= c * b;
            }
        }
    };
    let mut basis = [[0.0; DIM]; DIM - 1];
    let mut thinnest = f64::INFINITY;
    for (j, q) in p[1..].iter().enumerate() {
        let mut e: Wrench = std::array::from_fn(|i| (q[i] - p[0][i]) / scale);
        let before = dot(&e, &e).sqrt();
        project_out(&basis[..j], &mut e);
        let mut len = dot(&e, &e).sqrt();
        if len < 0.5 * before {
            // Twice is enough (Kahan, as in Parlett's "The Symmetric Eigenvalue Problem").
            project_out(&basis[..j], &mut e);
            len = dot(&e, &e).sqrt();
        }
        if len <= 1e-14 {
            return None;
        }
        thinnest = thinnest.min(len);
        basis[j] = e.map(|x| x / len);
    }
    if thinnest < 0.02 {
        return dd::null_vector(p).map(|n| (n, thinnest));
    }
    // The coordinate axis farthest from the edges' span, projected on its complement.
    let i = (0..DIM)
        .min_by(|&a, &b| {
            let wa: f64 = basis.iter().map(|q| q[a] * q[a]).sum();
            let wb: f64 = basis.iter().map(|q| q[b] * q[b]).sum();
            wa.total_cmp(&wb)
        })
        .unwrap_or(0);
    let mut n = [0.0; DIM];
    n[i] = 1.0;
    for _ in 0..2 {
        project_out(&basis, &mut n);
        let len = dot(&n, &n).sqrt();
        if len < 0.1 {
            return None;
        }
        n = n.map(|x| x / len);
    }
    Some((n, thinnest))
}

/// Double-double arithmetic (Dekker 1971; Hida, Li and Bailey 2001), enough for the normal of a
/// thin simplex.
mod dd {
    use super::{Wrench, DIM};

    /// `hi + lo`, `|lo| ≤ ulp(hi) / 2`.
    #[derive(Debug, Clone, Copy)]
    struct Dd(f64, f64);

    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bb = s - a;
        Dd(s, (a - (s - bb)) + (b - bb))
    }

    fn quick_two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        Dd(s, b - (s - a))
    }

    fn split(a: f64) -> (f64, f64) {
        let c = 134_217_729.0 * a; // 2^27 + 1
        let hi = c - (c - a);
        (hi, a - hi)
    }

    fn two_prod(a: f64, b: f64) -> Dd {
        let p = a * b;
        let (ah, al) = split(a);
        let (bh, bl) = split(b);
        Dd(p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
    }

    impl Dd {
        fn add(self, o: Dd) -> Dd {
            let s = two_sum(self.0, o.0);
            let t = two_sum(self.1, o.1);
            let s = quick_two_sum(s.0, s.1 + t.0);
            quick_two_sum(s.0, s.1 + t.1)
        }
        fn neg(self) -> Dd {
            Dd(-self.0, -self.1)
        }
        fn sub(self, o: Dd) -> Dd {
            self.add(o.neg())
        }
        fn mul(self, o: Dd) -> Dd {
            let p = two_prod(self.0, o.0);
            quick_two_sum(p.0, p.1 + (self.0 * o.1 + self.1 * o.0))
        }
        fn div(self, o: Dd) -> Dd {
            let q1 = self.0 / o.0;
            let r = self.sub(o.mul(Dd(q1, 0.0)));
            let q2 = r.0 / o.0;
            let r = r.sub(o.mul(Dd(q2, 0.0)));
            let q3 = r.0 / o.0;
            quick_two_sum(q1, q2).add(Dd(q3, 0.0))
        }
    }

    /// A unit vector orthogonal to the five edges `p[k] − p[0]`, from Gaussian elimination with
    /// full pivoting in double-double on the exact differences; `None` when the edges have rank
    /// under five.
    pub(super) fn null_vector(p: &[Wrench; DIM]) -> Option<Wrench> {
        let mut m = [[Dd(0.0, 0.0); DIM]; DIM - 1];
        for r in 0..DIM - 1 {
            for (c, slot) in m[r].iter_mut().enumerate() {
                *slot = two_sum(p[r + 1][c], -p[0][c]);
            }
        }
        let mut cols: [usize; DIM] = std::array::from_fn(|c| c);
        for k in 0..DIM - 1 {
            // Full pivoting: the largest remaining entry.
            let (mut pr, mut pc, mut best) = (k, k, -1.0);
            for (r, row) in m.iter().enumerate().skip(k) {
                for (c, x) in row.iter().enumerate().skip(k) {
                    if x.0.abs() > best {
                        (pr, pc, best) = (r, c, x.0.abs());
                    }
                }
            }
            if best <= 0.0 {
                return None;
            }
            m.swap(k, pr);
            for row in m.iter_mut() {
                row.swap(k, pc);
            }
            cols.swap(k, pc);
            let pivot = m[k];
            for row in m.iter_mut().skip(k + 1) {
                let f = row[k].div(pivot[k]);
                for (x, y) in row.iter_mut().zip(&pivot).skip(k) {
                    *x = x.sub(f.mul(*y));
                }
            }
        }
        // The free unknown (the last column after pivoting) is 1; back-substitute.
        let mut x = [Dd(0.0, 0.0); DIM];
        x[DIM - 1] = Dd(1.0, 0.0);
        for k in (0..DIM - 1).rev() {
            let mut s = Dd(0.0, 0.0);
            for (a, b) in m[k].iter().zip(&x).skip(k + 1) {
                s = s.add(a.mul(*b));
            }
            x[k] = s.neg().div(m[k][k]);
        }
        let mut n = [0.0; DIM];
        for (k, &c) in cols.iter().enumerate() {
            n[c] = x[k].0 + x[k].1;
        }
        let len = n.iter().map(|v| v * v).sum::<f64>().sqrt();
        (len.is_finite() && len > 0.0).then(|| n.map(|v| v / len))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> Vec<Wrench> {
        (0..64u32)
            .map(|b| std::array::from_fn(|i| if b >> i & 1 == 1 { 1.0 } else { -1.0 }))
            .collect()
    }

    /// Every point of `pts` lies on or below every facet, and every facet's vertices on it.
    fn assert_valid(h: &ConvexHull, pts: &[Wrench]) {
        let scale = pts.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let slack = 10.0 * h.joggle * scale;
        for f in &h.facets {
            let len = dot(&f.normal, &f.normal).sqrt();
            assert!((len - 1.0).abs() < 1e-12, "normal length {len}");
            for p in pts {
                let d = dot(&f.normal, p) + f.offset;
                assert!(d <= slack, "a point {d} beyond a facet (slack {slack})");
            }
            for &v in &f.vertices {
                let d = dot(&f.normal, &pts[v as usize]) + f.offset;
                assert!(d.abs() <= slack, "a vertex {d} off its facet");
            }
        }
    }

    #[test]
    fn the_cube_has_its_64_corners_as_vertices_and_volume_64() {
        let pts = cube();
        let h = convex_hull(&pts).expect("a hull");
        assert_eq!(h.vertices, (0..64).collect::<Vec<_>>());
        assert!((h.volume - 64.0).abs() < 1e-8, "volume {}", h.volume);
        assert_valid(&h, &pts);
        // The facets' planes are the cube's faces: |x_i| = 1, to the joggle.
        let eps = h
            .facets
            .iter()
            .map(|f| -f.offset)
            .fold(f64::INFINITY, f64::min);
        assert!((eps - 1.0).abs() < 1e-9, "nearest facet {eps}");
    }

    #[test]
    fn interior_points_are_not_vertices_and_the_simplex_volume_is_exact() {
        // The standard simplex scaled by 3 (volume 3^6 / 6!), with points strictly inside.
        let mut pts: Vec<Wrench> = vec![[0.0; 6]];
        for i in 0..6 {
            let mut w = [0.0; 6];
            w[i] = 3.0;
            pts.push(w);
        }
        for k in 0..40 {
            let w: Wrench = std::array::from_fn(|i| 0.05 + 0.06 * ((k * 5 + i * 7) % 9) as f64);
            pts.push(w);
        }
        let h = convex_hull(&pts).expect("a hull");
        assert_eq!(h.vertices, (0..7).collect::<Vec<_>>());
        assert_eq!(h.facets.len(), 7);
        let exact = 729.0 / 720.0;
        assert!((h.volume - exact).abs() < 1e-9, "{} vs {exact}", h.volume);
        assert_valid(&h, &pts);
    }

    #[test]
    fn coplanar_friction_edges_are_hulled_and_the_same_run_after_run() {
        // Twelve contacts' octagons (each in a 2-plane), as the L1 metric makes them.
        let mut pts = Vec::new();
        for c in 0..12 {
            let a = c as f64 * 0.7;
            let n = [a.cos(), a.sin(), (c as f64 * 0.3).sin()];
            for k in 0..8 {
                let phi = std::f64::consts::TAU * k as f64 / 8.0;
                let f = [
                    n[0] + 0.3 * phi.cos(),
                    n[1] + 0.3 * phi.sin(),
                    n[2] + 0.3 * (phi.cos() - phi.sin()) * 0.5,
                ];
                let r = [
                    -n[0] * 0.8 + 0.1 * c as f64 % 0.3,
                    -n[1] * 0.8,
                    ((c % 3) as f64 - 1.0) * 0.5,
                ];
                pts.push([
                    f[0],
                    f[1],
                    f[2],
                    r[1] * f[2] - r[2] * f[1],
                    r[2] * f[0] - r[0] * f[2],
                    r[0] * f[1] - r[1] * f[0],
                ]);
            }
        }
        let h = convex_hull(&pts).expect("a hull");
        assert_valid(&h, &pts);
        assert!(h.volume > 0.0);
        assert_eq!(convex_hull(&pts), Some(h));
    }

    #[test]
    fn fewer_than_six_dimensions_give_no_hull() {
        let flat: Vec<Wrench> = (0..20)
            .map(|k| [k as f64, (k * k) as f64, 1.0, 0.0, (k % 3) as f64, 2.0])
            .collect();
        assert!(convex_hull(&flat).is_none());
        assert!(convex_hull(&[[f64::NAN; 6]; 8]).is_none());
    }

    #[test]
    fn the_double_double_normal_is_orthogonal_to_a_thin_simplex() {
        let mut p: [Wrench; 6] = [[0.0; 6]; 6];
        for (k, row) in p.iter_mut().enumerate().skip(1) {
            row[k - 1] = 1.0;
        }
        // The fifth edge nearly along the fourth: a sliver 1e-11 thick, whose normal is set by
        // the 1e-11 differences alone: (0, 0, 0, 0, -0.7, 1) normalised.
        p[5] = [0.3, 0.2, 0.0, 1.0, 1e-11, 0.7e-11];
        let n = plane_normal(&p).expect("a normal");
        let len = (1.0f64 + 0.49).sqrt();
        let expected = [0.0, 0.0, 0.0, 0.0, -0.7 / len, 1.0 / len];
        let sign = if n[5] < 0.0 { -1.0 } else { 1.0 };
        for (a, b) in n.iter().zip(expected) {
            assert!(
                (sign * a - b).abs() < 1e-12,
                "normal {n:?}, expected ~{expected:?}"
            );
        }
    }
}
