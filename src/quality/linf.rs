//! The L∞ grasp wrench space: each contact's normal force bounded by 1 independently.
//!
//! The space is the Minkowski sum `W = Σᵢ Pᵢ` of the contacts' sets `Pᵢ = conv({0} ∪ edgesᵢ)`.
//! Its vertices grow as (edges + 1)^contacts before pruning (each `Pᵢ` spans its own 3-D
//! subspace of the 6-D wrench space, so the sum of a few contacts is already a product of
//! pyramids), which is why the hull of the whole sum is only feasible for a handful of
//! contacts. Epsilon does not need the whole hull:
//!
//! - **Epsilon** by an expanding polytope (EPA, as in collision detection): `W` is known through
//!   its support function `h(u) = Σᵢ max(0, maxⱼ eᵢⱼ·u)`, each evaluation a sum over the
//!   contacts' edges. An inner polytope `Q ⊂ W` (support points of `W`, so vertices of `W`)
//!   with the origin inside is grown where it is nearest the origin: its nearest facet (normal
//!   `u`, distance `d`) is tested against `h(u)`; if `W` reaches further in that direction,
//!   the support point is added to `Q` (beneath–beyond), else the search stops. Then
//!   `d ≤ ε ≤ h(u)`: `Q ⊂ W` gives the lower bound (every point of `W`'s boundary lies outside
//!   `Q`'s interior, so at least `d` from the origin) and the supporting half-space
//!   `u·x ≤ h(u)` the upper. The search stops when the two agree to [`EPS_REL_TOL`], so epsilon
//!   is exact up to round-off, not sampled. It ends: each step adds a vertex of `W` not yet in
//!   `Q`, and `W` has finitely many; [`EPA_MAX_POINTS`] bounds it all the same.
//! - **Volume** by rays from the sum's centre, each an exact small linear programme, integrated
//!   over a fixed set of directions ([`super::rays`]), with its standard error. The whole hull
//!   ([`minkowski_sum`]: the incremental sum pruned to its hull's vertices by [`super::hull`]) is
//!   exact but feasible only up to 3 contacts at 8 cone edges; it is the reference the rays are
//!   tested against.
//!
//! Contacts whose edge wrenches agree (rapier can report one contact twice) are merged first:
//! `P + P = 2P` exactly for a convex `P`.

use super::{QualityError, Wrench};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

/// The search stops when the upper and lower bounds on epsilon agree to this, relative.
pub const EPS_REL_TOL: f64 = 1e-9;

/// The search gives up (epsilon `None`, with the reason) after adding this many support
/// points to the inner polytope (docs/QUALITY.md: the 179 grasps measured needed at most 84).
pub const EPA_MAX_POINTS: usize = 1_000;

const DIM: usize = 6;

/// The result for one grasp's L∞ wrench space.
#[derive(Debug, Clone, PartialEq)]
pub struct Linf {
    /// Epsilon (0 when the origin is not inside), `None` when the search did not finish.
    pub epsilon: Option<f64>,
    /// The bracket `[lower, upper]` the search ended with (`lower == epsilon`).
    pub bracket: (f64, f64),
    /// Support points added to the initial polytope.
    pub points_added: usize,
    /// Volume by rays ([`super::rays`]), `None` when a ray's programme failed (with the note).
    pub volume: Option<f64>,
    /// The volume's standard error relative to it.
    pub volume_rel_se: Option<f64>,
    /// Why epsilon is 0 or `None`, or why the volume is `None`.
    pub note: Option<String>,
}

fn dot(a: &Wrench, b: &Wrench) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The contacts' edge wrenches with contacts whose edges agree to `1e-12` of the set's width
/// merged, each set scaled by how many times it occurs (`P + P = 2P`).
pub fn merge_identical(per_contact: &[Vec<Wrench>]) -> Vec<Vec<Wrench>> {
    let width = per_contact
        .iter()
        .flatten()
        .flat_map(|w| w.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let tol = 1e-12 * width.max(1e-300);
    let mut out: Vec<(Vec<Wrench>, f64)> = Vec::new();
    for edges in per_contact.iter().filter(|e| !e.is_empty()) {
        let same = out.iter_mut().find(|(o, _)| {
            o.len() == edges.len()
                && o.iter()
                    .zip(edges)
                    .all(|(a, b)| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol))
        });
        match same {
            Some((_, k)) => *k += 1.0,
            None => out.push((edges.clone(), 1.0)),
        }
    }
    out.into_iter()
        .map(|(e, k)| e.into_iter().map(|w| w.map(|v| v * k)).collect())
        .collect()
}

/// The support function of `W` in direction `u` and a support point (a vertex of `W` when
/// `u` is generic).
pub fn support(per_contact: &[Vec<Wrench>], u: &Wrench) -> (f64, Wrench) {
    let mut h = 0.0;
    let mut s = [0.0; DIM];
    for edges in per_contact {
        let mut best = 0.0;
        let mut arg: Option<&Wrench> = None;
        for e in edges {
            let v = dot(e, u);
            if v > best {
                best = v;
                arg = Some(e);
            }
        }
        if let Some(e) = arg {
            h += best;
            for (a, b) in s.iter_mut().zip(e) {
                *a += b;
            }
        }
    }
    (h, s)
}

/// A simplicial facet of the inner polytope.
#[derive(Debug, Clone)]
struct Facet {
    /// Indices into the point list.
    v: [u32; DIM],
    /// Unit normal, away from the origin.
    n: Wrench,
    /// The plane's offset, `n·v[0]`.
    plane: f64,
    /// A lower bound on the distance from the origin to the facet: `min_k n·v[k]`.
    lower: f64,
    /// `nb[k]`: the facet across the ridge opposite `v[k]`.
    nb: [u32; DIM],
    alive: bool,
}

/// The unit normal of the hyperplane through `p[0..6]`, or `None` when they span less than 5
/// dimensions. Gram–Schmidt with reorthogonalisation on the edges from `p[0]`, then the unit
/// vector with the largest part outside their span, projected out twice: the normal is
/// orthogonal to every edge to round-off, however thin the simplex.
fn normal_through(p: &[Wrench; DIM]) -> Option<Wrench> {
    let scale = p
        .iter()
        .flat_map(|q| q.iter().zip(&p[0]).map(|(a, b)| (a - b).abs()))
        .fold(0.0f64, f64::max);
    if scale == 0.0 {
        return None;
    }
    let project_out = |basis: &[Wrench], v: &mut Wrench| {
        for _ in 0..2 {
            for q in basis {
                let c = dot(q, v);
                for (a, b) in v.iter_mut().zip(q) {
                    *a -= c * b;
                }
            }
        }
    };
    let mut basis: Vec<Wrench> = Vec::with_capacity(DIM - 1);
    for q in &p[1..] {
        let mut e: Wrench = std::array::from_fn(|i| (q[i] - p[0][i]) / scale);
        project_out(&basis, &mut e);
        let len = dot(&e, &e).sqrt();
        if len <= 1e-12 {
            return None;
        }
        basis.push(e.map(|x| x / len));
    }
    let n = (0..DIM)
        .map(|i| {
            let mut v = [0.0; DIM];
            v[i] = 1.0;
            project_out(&basis, &mut v);
            v
        })
        .max_by(|a, b| dot(a, a).total_cmp(&dot(b, b)))?;
    let mut n = n.map(|x| x / dot(&n, &n).sqrt());
    project_out(&basis, &mut n);
    let len = dot(&n, &n).sqrt();
    (len > 0.5).then(|| n.map(|x| x / len))
}

/// Orders the heap by a facet's lower bound, smallest first.
#[derive(PartialEq)]
struct ByLower(f64, u32);
impl Eq for ByLower {}
impl PartialOrd for ByLower {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for ByLower {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

/// The inner polytope: its points, facets and the heap of facets by distance.
struct Polytope {
    points: Vec<Wrench>,
    facets: Vec<Facet>,
    heap: BinaryHeap<ByLower>,
}

impl Polytope {
    /// A facet on vertices `v`, oriented away from the origin; `None` when degenerate (and no
    /// `fallback` normal is given) or when the origin is not strictly inside its half-space.
    /// Its `lower` bound holds for any unit normal: every vertex, so the whole simplex, lies
    /// at least that far along it.
    fn facet(&self, v: [u32; DIM], fallback: Option<Wrench>) -> Option<Facet> {
        let p: [Wrench; DIM] = std::array::from_fn(|k| self.points[v[k] as usize]);
        let mut n = normal_through(&p).or(fallback)?;
        let plane = p.iter().map(|q| dot(&n, q)).sum::<f64>() / DIM as f64;
        if plane < 0.0 {
            n = n.map(|x| -x);
        }
        let plane = plane.abs();
        let lower = p.iter().map(|q| dot(&n, q)).fold(f64::INFINITY, f64::min);
        (lower > 0.0).then_some(Facet {
            v,
            n,
            plane,
            lower,
            nb: [u32::MAX; DIM],
            alive: true,
        })
    }

    /// The polytope from simplicial facets given by vertex indices, neighbours found by their
    /// shared ridges. `None` when a facet is degenerate or the ridges do not pair up.
    fn from_facets(points: Vec<Wrench>, facets: &[([u32; DIM], Wrench)]) -> Option<Polytope> {
        let mut poly = Polytope {
            points,
            facets: Vec::with_capacity(facets.len()),
            heap: BinaryHeap::new(),
        };
        let mut ridges: HashMap<[u32; DIM - 1], (u32, usize)> = HashMap::new();
        for (v, fallback) in facets {
            let f = poly.facet(*v, Some(*fallback))?;
            let id = poly.facets.len() as u32;
            poly.facets.push(f);
            for k in 0..DIM {
                let key = ridge_key(v, k);
                match ridges.remove(&key) {
                    Some((g, j)) => {
                        poly.facets[id as usize].nb[k] = g;
                        poly.facets[g as usize].nb[j] = id;
                    }
                    None => {
                        ridges.insert(key, (id, k));
                    }
                }
            }
        }
        if !ridges.is_empty() {
            return None;
        }
        for (i, f) in poly.facets.iter().enumerate() {
            poly.heap.push(ByLower(f.lower, i as u32));
        }
        Some(poly)
    }

    /// Adds point `s`, seen from facet `from` (beneath–beyond): the facets `s` is beyond,
    /// reached from `from`, are replaced by the cone from `s` over their horizon. `None` when
    /// the result would not be a closed surface around the origin (round-off), leaving the
    /// polytope as it was.
    fn add(&mut self, s: Wrench, from: u32, tol: f64) -> Option<()> {
        let si = self.points.len() as u32;
        self.points.push(s);
        let mut visible = vec![from];
        let mut seen: HashMap<u32, bool> = HashMap::from([(from, true)]);
        let mut i = 0;
        while i < visible.len() {
            let f = visible[i];
            i += 1;
            for &g in &self.facets[f as usize].nb {
                if let std::collections::hash_map::Entry::Vacant(e) = seen.entry(g) {
                    let fg = &self.facets[g as usize];
                    let vis = dot(&fg.n, &s) - fg.plane > tol;
                    e.insert(vis);
                    if vis {
                        visible.push(g);
                    }
                }
            }
        }
        // The cone over the horizon.
        let first_new = self.facets.len();
        let mut open: HashMap<[u32; DIM - 1], (u32, usize)> = HashMap::new();
        let mut ok = true;
        'horizon: for &f in &visible {
            for k in 0..DIM {
                let g = self.facets[f as usize].nb[k];
                if seen[&g] {
                    continue;
                }
                let mut v = self.facets[f as usize].v;
                v[k] = si;
                let Some(mut nf) = self.facet(v, None) else {
                    ok = false;
                    break 'horizon;
                };
                let id = self.facets.len() as u32;
                nf.nb[k] = g;
                self.facets.push(nf);
                for j in (0..DIM).filter(|&j| j != k) {
                    let key = ridge_key(&v, j);
                    match open.remove(&key) {
                        Some((h, l)) => {
                            self.facets[id as usize].nb[j] = h;
                            self.facets[h as usize].nb[l] = id;
                        }
                        None => {
                            open.insert(key, (id, j));
                        }
                    }
                }
            }
        }
        if !ok || !open.is_empty() {
            self.facets.truncate(first_new);
            self.points.pop();
            return None;
        }
        // Commit: the outer neighbours point at the new facets, the visible ones die.
        for id in first_new..self.facets.len() {
            let k = self.facets[id].v.iter().position(|&x| x == si).unwrap_or(0);
            let g = self.facets[id].nb[k] as usize;
            let ridge = ridge_key(&self.facets[id].v, k);
            let slot = (0..DIM).find(|&j| ridge_key(&self.facets[g].v, j) == ridge)?;
            self.facets[g].nb[slot] = id as u32;
            self.heap.push(ByLower(self.facets[id].lower, id as u32));
        }
        for &f in &visible {
            self.facets[f as usize].alive = false;
        }
        Some(())
    }
}

impl Polytope {
    /// The hull of `points` ([`super::hull`]; they must contain the origin strictly inside).
    fn hull(points: Vec<Wrench>) -> Option<Polytope> {
        let facets: Vec<([u32; DIM], Wrench)> = hull_facets(&points)?
            .into_iter()
            .map(|(v, n, _)| (v, n))
            .collect();
        Polytope::from_facets(points, &facets)
    }
}

/// The sorted vertex indices of a facet's ridge opposite vertex `k`.
fn ridge_key(v: &[u32; DIM], k: usize) -> [u32; DIM - 1] {
    let mut r = [0u32; DIM - 1];
    let mut j = 0;
    for (i, &x) in v.iter().enumerate() {
        if i != k {
            r[j] = x;
            j += 1;
        }
    }
    r.sort_unstable();
    r
}

/// How the search for epsilon ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    /// Epsilon: the lower bound the search ended with (0 when the origin is not inside).
    pub epsilon: f64,
    /// `[lower, upper]`: `upper` is the support function in the nearest facet's direction.
    pub bracket: (f64, f64),
    /// Support points added to the initial polytope.
    pub points_added: usize,
    /// Facets made (alive or not): the search's memory.
    pub facets: usize,
    /// Times the inner polytope was hulled again after round-off in an update.
    pub rebuilds: usize,
    /// Why epsilon is 0.
    pub note: Option<String>,
}

/// Epsilon of `W = Σᵢ conv({0} ∪ per_contact[i])` by the expanding polytope, adding at most
/// `max_points` support points (`Err` with the reason beyond, or when round-off stops it).
pub fn epsilon(per_contact: &[Vec<Wrench>], max_points: usize) -> Result<Search, QualityError> {
    let outside = |note: String| Search {
        epsilon: 0.0,
        bracket: (0.0, 0.0),
        points_added: 0,
        facets: 0,
        rebuilds: 0,
        note: Some(note),
    };
    let width = per_contact
        .iter()
        .flatten()
        .map(|w| dot(w, w).sqrt())
        .fold(0.0f64, f64::max);
    if width == 0.0 {
        return Ok(outside("no contacts".to_string()));
    }
    let mut poly = match initial(per_contact, width)? {
        Start::Polytope(p) => p,
        Start::Outside(note) => return Ok(outside(note)),
    };
    let tol_vis = 1e-12 * width;
    let mut upper = f64::INFINITY;
    let mut added = 0;
    let mut facets = poly.facets.len();
    let mut rebuilds = 0;
    while let Some(ByLower(lower, f)) = poly.heap.pop() {
        if !poly.facets[f as usize].alive {
            continue;
        }
        let n = poly.facets[f as usize].n;
        let (h, s) = support(per_contact, &n);
        upper = upper.min(h);
        if upper - lower <= EPS_REL_TOL * upper {
            return Ok(Search {
                epsilon: lower,
                bracket: (lower, upper),
                points_added: added,
                facets: facets + poly.facets.len(),
                rebuilds,
                note: None,
            });
        }
        if added >= max_points {
            return Err(QualityError::NotSettled {
                added,
                lower,
                upper,
            });
        }
        let beyond = dot(&n, &s) - poly.facets[f as usize].plane;
        if beyond <= tol_vis {
            return Err(QualityError::RoundOff { lower, upper });
        }
        if poly.add(s, f, tol_vis).is_none() {
            // Round-off in the beneath–beyond step (a new facet nearly flat): the hull is taken of
            // the points again, the new one with them.
            facets += poly.facets.len();
            let mut points = std::mem::take(&mut poly.points);
            points.push(s);
            poly = Polytope::hull(points).ok_or(QualityError::InnerHull { lower, upper })?;
            rebuilds += 1;
        }
        added += 1;
    }
    Err(QualityError::FacetsLost)
}

enum Start {
    Polytope(Polytope),
    /// The origin is not inside `W`, with the reason.
    Outside(String),
}

/// The initial inner polytope: the hull of support points of `W`, grown (in the
/// directions of the facets the origin is beyond) until the origin is strictly inside; or the
/// proof that it cannot be (a direction in which `W` does not reach past the origin).
fn initial(per_contact: &[Vec<Wrench>], width: f64) -> Result<Start, QualityError> {
    let all: Vec<Wrench> = per_contact.iter().flatten().copied().collect();
    let rank = super::affine_rank(&all.iter().copied().chain([[0.0; DIM]]).collect::<Vec<_>>());
    if rank < DIM {
        return Ok(Start::Outside(format!(
            "not force closure: the wrench space spans {rank} of 6 dimensions"
        )));
    }
    let mut points: Vec<Wrench> = Vec::new();
    let push = |points: &mut Vec<Wrench>, s: Wrench| {
        if !points.iter().any(|p| {
            p.iter()
                .zip(&s)
                .all(|(a, b)| (a - b).abs() <= 1e-12 * width)
        }) {
            points.push(s);
        }
    };
    for i in 0..DIM {
        for sign in [1.0, -1.0] {
            let mut u = [0.0; DIM];
            u[i] = sign;
            push(&mut points, support(per_contact, &u).1);
        }
    }
    let margin = 1e-9 * width;
    for _ in 0..200 {
        if super::affine_rank(&points) < DIM {
            // Directions off the points' span: the singular vectors of the rest.
            let p0 = points[0];
            let m = nalgebra::DMatrix::from_fn(DIM, points.len(), |r, c| points[c][r] - p0[r]);
            let svd = m.svd(true, false);
            let u = svd.u.ok_or(QualityError::Svd)?;
            let mut grew = false;
            for (k, sv) in svd.singular_values.iter().enumerate() {
                if *sv <= 1e-9 * width * (points.len() as f64).sqrt() {
                    let d: Wrench = std::array::from_fn(|r| u[(r, k)]);
                    for d in [d, d.map(|x| -x)] {
                        let before = points.len();
                        push(&mut points, support(per_contact, &d).1);
                        grew |= points.len() > before;
                    }
                }
            }
            if !grew {
                return Err(QualityError::SupportSpan);
            }
            continue;
        }
        let facets = hull_facets(&points).ok_or(QualityError::InitialHull)?;
        // Facets the origin is not strictly inside of: W must reach past the origin there.
        let mut grew = false;
        for (n, offset) in facets.iter().map(|f| (f.1, f.2)) {
            if -offset <= margin {
                let (h, s) = support(per_contact, &n);
                if h <= margin {
                    return Ok(Start::Outside(
                        "not force closure: the origin is outside the wrench space".to_string(),
                    ));
                }
                let before = points.len();
                push(&mut points, s);
                grew |= points.len() > before;
            }
        }
        if !grew {
            return Polytope::hull(points)
                .map(Start::Polytope)
                .ok_or(QualityError::InitialDegenerate);
        }
    }
    Err(QualityError::NoInitialPolytope)
}

/// The hull's simplicial facets of `points` ([`super::hull`]): vertex indices, unit normal,
/// offset (`n·x + offset = 0` on the facet, negative offset when the origin is inside).
#[allow(clippy::type_complexity)]
pub(crate) fn hull_facets(points: &[Wrench]) -> Option<Vec<([u32; DIM], Wrench, f64)>> {
    let h = super::hull::convex_hull(points)?;
    Some(
        h.facets
            .into_iter()
            .map(|f| (f.vertices, f.normal, f.offset))
            .collect(),
    )
}

/// The vertices and volume of `W`: the Minkowski sum over contacts, pruned to its hull's
/// vertices after each contact once it is full-dimensional; `None` when a hull would need more
/// than `max_points` input points (or the hull fails). The volume is 0 below 6 dimensions.
pub fn minkowski_sum(per_contact: &[Vec<Wrench>], max_points: usize) -> Option<(Vec<Wrench>, f64)> {
    let mut set: Vec<Wrench> = vec![[0.0; DIM]];
    let mut volume = 0.0;
    for edges in per_contact {
        if set.len() * (edges.len() + 1) > max_points {
            return None;
        }
        let mut next = Vec::with_capacity(set.len() * (edges.len() + 1));
        for s in &set {
            next.push(*s);
            for e in edges {
                next.push(std::array::from_fn(|i| s[i] + e[i]));
            }
        }
        // Exact repeats (sums that meet, as in a cube) go before the hull.
        next.sort_by(|a, b| {
            a.iter()
                .zip(b)
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(Ordering::Equal)
        });
        next.dedup();
        if super::affine_rank(&next) == DIM {
            let h = super::hull(&next)?;
            next = h.vertices.iter().map(|&i| next[i]).collect();
            volume = h.volume;
        }
        set = next;
    }
    Some((set, volume))
}

/// The L∞ metrics of a grasp's edge wrenches (one `Vec` per contact).
pub fn evaluate(per_contact: &[Vec<Wrench>]) -> Linf {
    let merged = merge_identical(per_contact);
    let (epsilon, bracket, points_added, mut note) = match epsilon(&merged, EPA_MAX_POINTS) {
        Ok(s) => (Some(s.epsilon), s.bracket, s.points_added, s.note),
        Err(why) => (
            None,
            (0.0, f64::INFINITY),
            EPA_MAX_POINTS,
            Some(format!("L-infinity epsilon not computed: {why}")),
        ),
    };
    // The volume by rays for any number of contacts (the hull of the whole sum is exact but
    // costs 0.5–1.2 s at 3 contacts and is out of reach past them: it stays the reference the
    // rays are tested against).
    let (volume, volume_rel_se) = match super::rays::volume(&merged, super::rays::VOLUME_RAYS) {
        Ok(v) => (Some(v.volume), Some(v.rel_se)),
        Err(why) => {
            if note.is_none() {
                note = Some(format!("L-infinity volume not computed: {why}"));
            }
            (None, None)
        }
    };
    Linf {
        epsilon,
        bracket,
        points_added,
        volume,
        volume_rel_se,
        note,
    }
}
