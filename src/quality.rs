//! Analytic grasp quality: the Ferrari–Canny metrics of the grasp wrench space (GWS), beside the
//! physics check (issue 18).
//!
//! Input: point contacts on the object (aligned object frame, millimetres), each with the unit
//! normal along which the hand pushes (into the object), the friction coefficient, and the
//! object's centroid and maximum radius about it. Output: epsilon (the radius of the largest
//! ball about the origin inside the GWS: the smallest disturbance wrench, per unit of contact
//! force, that can break the grasp) and the GWS volume, in two variants:
//!
//! - **L1** (Ferrari and Canny 1992; GraspIt!'s `QualEpsilon`/`QualVolume`): the convex hull of
//!   every contact's friction-cone edge wrenches, i.e. the sum of the contacts' normal forces
//!   bounded by 1.
//! - **L∞**: each contact's normal force bounded by 1 independently: the Minkowski sum of the
//!   contacts' hulls of {0, edge wrenches}. Too many vertices to hull for more than a few
//!   contacts, so epsilon comes from an expanding inner polytope checked against the sum's
//!   support function (exact to a relative 1e-9, for any number of contacts, [`linf`]); the
//!   volume by rays from the sum's centre, each an exact linear programme, with the estimate's
//!   standard error ([`rays`]).
//!
//! Conventions (GraspIt!'s): the Coulomb cone is linearised with `cone_edges` edges (8 by
//! default), each edge a force with unit normal component, `n + μ (cos φ t₁ + sin φ t₂)`;
//! a wrench is `(f, (p − c) × f / ρ)` with `c` the object's centroid and `ρ` its largest
//! distance from it, so forces and torques are commensurate and the numbers do not depend on the
//! unit of length. Epsilon is the smallest distance from the origin to a facet of the hull;
//! when the origin is not inside (not force closure) epsilon is 0 (GraspIt! reports −1) and
//! [`Quality::force_closure`] is false. A wrench set that spans fewer than six dimensions
//! (two point contacts, say) has no volume and is not force closure.
//!
//! The hull is grasp-sim's own quickhull ([`hull`], pure Rust, so that the build needs no C
//! library or libclang), on joggled input as qhull's `QJ` does, which handles the round-off of
//! the nearly coplanar edge wrenches of one contact and of nearly coincident contacts and gives
//! simplicial facets; the volume (a sum of simplices from an interior point) and epsilon (the
//! support function in the facets' directions) are then taken from the points as given, so
//! they do not depend on the joggle. It replaced qhull (issue 29): over 462 scattered grasps of
//! 3–23 contacts at μ 0.3 and 0.8 the two agreed to 3.8e-9 (epsilon) and 1.7e-9 (volume),
//! relative, about the size of qhull's own joggle.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

/// Number of friction-cone edges by default.
pub const DEFAULT_CONE_EDGES: usize = 8;

mod error;
pub mod hull;
pub mod linf;
pub mod rays;

pub use error::QualityError;

pub use crate::plan::contacts::{planned_contacts, Contact};

/// What the metric needs to know beside the contacts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QualityParams {
    /// Coulomb friction coefficient.
    pub friction: f64,
    /// Friction-cone edges.
    pub cone_edges: usize,
    /// The object's centroid, aligned frame `[mm]`.
    pub centroid_mm: Point3<f64>,
    /// The object's largest distance from its centroid `[mm]` (the torque scale).
    pub max_radius_mm: f64,
}

/// The metrics of one wrench space.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpaceMetrics {
    /// Ferrari–Canny epsilon (0 when the origin is not inside).
    pub epsilon: f64,
    /// Volume of the wrench space (6-D, in the scaled units).
    pub volume: f64,
}

/// The metrics of the L∞ wrench space.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LinfMetrics {
    /// Ferrari–Canny epsilon (0 when the origin is not inside).
    pub epsilon: f64,
    /// Volume (6-D, in the scaled units), estimated by rays ([`rays`]); `None` when a ray's
    /// programme failed (the reason in `linf_note`).
    pub volume: Option<f64>,
    /// The volume estimate's standard error, relative to it (about 0.02–0.03 at
    /// [`rays::VOLUME_RAYS`] rays).
    pub volume_rel_se: Option<f64>,
}

/// The analytic quality of a grasp.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Quality {
    /// Where the contacts come from: `sim` (the physics check at the end of closing) or
    /// `planned` (the planner's ALS and palm contacts).
    pub source: &'static str,
    /// The contacts.
    pub contacts: Vec<Contact>,
    /// L1 epsilon (GraspIt!'s), also in `l1.epsilon`.
    pub epsilon: f64,
    /// L1 volume (GraspIt!'s), also in `l1.volume`.
    pub volume: f64,
    /// True if and only if the origin lies strictly inside the wrench space.
    pub force_closure: bool,
    /// L1 wrench space: sum of normal forces ≤ 1.
    pub l1: SpaceMetrics,
    /// L∞ wrench space: each normal force ≤ 1 (`None` if the search for its epsilon did not
    /// finish, with the reason in `linf_note`).
    pub linf: Option<LinfMetrics>,
    /// Why the L∞ epsilon or volume is missing, when one is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linf_note: Option<String>,
    /// Friction-cone edges used.
    pub cone_edges: usize,
    /// Friction coefficient used.
    pub friction: f64,
    /// Torque scale: the object's largest distance from its centroid `[mm]`.
    pub torque_scale_mm: f64,
    /// Why epsilon is 0, when it is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A wrench: force, then torque over the torque scale.
pub type Wrench = [f64; 6];

/// The friction-cone edge wrenches of every contact (one `Vec` per contact).
pub fn edge_wrenches(contacts: &[Contact], params: &QualityParams) -> Vec<Vec<Wrench>> {
    let m = params.cone_edges.max(1);
    let rho = if params.max_radius_mm > 0.0 {
        params.max_radius_mm
    } else {
        1.0
    };
    contacts
        .iter()
        .filter_map(|c| {
            let n = Vector3::from(c.normal);
            let n = n.try_normalize(1e-12)?;
            let p = Point3::from(c.point_mm);
            if !p.coords.iter().all(|v| v.is_finite()) {
                return None;
            }
            // Any tangent basis: the cone is symmetric, only the edges' phase depends on it.
            let helper = if n.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            let t1 = n.cross(&helper).normalize();
            let t2 = n.cross(&t1);
            let r = (p - params.centroid_mm) / rho;
            Some(
                (0..m)
                    .map(|k| {
                        let phi = 2.0 * std::f64::consts::PI * k as f64 / m as f64;
                        let f = n + params.friction * (phi.cos() * t1 + phi.sin() * t2);
                        let t = r.cross(&f);
                        [f.x, f.y, f.z, t.x, t.y, t.z]
                    })
                    .collect(),
            )
        })
        .collect()
}

/// The quality of a grasp with `contacts`, from `source` (`sim` or `planned`).
pub fn evaluate(source: &'static str, contacts: Vec<Contact>, params: &QualityParams) -> Quality {
    let per_contact = edge_wrenches(&contacts, params);
    let points: Vec<Wrench> = per_contact.iter().flatten().copied().collect();
    // L1 (the hull) and L∞ (search and rays) are independent: side by side on rayon's threads.
    let ((l1, l1_note), l) = rayon::join(|| metrics(&points), || linf::evaluate(&per_contact));
    let linf = l.epsilon.map(|epsilon| LinfMetrics {
        epsilon,
        volume: l.volume,
        volume_rel_se: l.volume_rel_se,
    });
    // A not-force-closure L∞ space says so in `note` already (the two agree on it).
    let linf_note = l
        .note
        .filter(|n| !n.starts_with("not force closure") && n != "no contacts");
    let force_closure = l1.epsilon > 0.0;
    Quality {
        source,
        contacts,
        epsilon: l1.epsilon,
        volume: l1.volume,
        force_closure,
        l1,
        linf,
        linf_note,
        cone_edges: params.cone_edges,
        friction: params.friction,
        torque_scale_mm: params.max_radius_mm,
        note: l1_note,
    }
}

/// Epsilon and volume of the convex hull of `points`, with the reason epsilon is 0.
pub fn metrics(points: &[Wrench]) -> (SpaceMetrics, Option<String>) {
    let zero = SpaceMetrics {
        epsilon: 0.0,
        volume: 0.0,
    };
    if points.is_empty() {
        return (zero, Some("no contacts".to_string()));
    }
    let rank = affine_rank(points);
    if rank < 6 {
        return (
            zero,
            Some(format!(
                "not force closure: the wrench space spans {rank} of 6 dimensions"
            )),
        );
    }
    match hull(points) {
        Some(h) => {
            let inside = h.nearest > 0.0;
            let epsilon = if inside { h.nearest } else { 0.0 };
            let note = (!inside)
                .then(|| "not force closure: the origin is outside the wrench space".to_string());
            (
                SpaceMetrics {
                    epsilon,
                    volume: h.volume,
                },
                note,
            )
        }
        None => (zero, Some("the convex hull failed".to_string())),
    }
}

/// What the L1 metrics need of a convex hull.
struct Hull {
    volume: f64,
    /// The distance from the origin to the nearest facet (negative outside).
    nearest: f64,
    /// Indices into the input of the hull's vertices, sorted.
    vertices: Vec<usize>,
    /// The joggle the hull was built with, relative to the set's largest coordinate.
    #[cfg_attr(not(test), allow(dead_code))]
    joggle: f64,
}

/// The hull of `points` ([`hull::convex_hull`]), or `None` when it fails.
fn hull(points: &[Wrench]) -> Option<Hull> {
    let h = hull::convex_hull(points)?;
    Some(Hull {
        volume: h.volume,
        nearest: h.nearest,
        vertices: h.vertices,
        joggle: h.joggle,
    })
}

/// The dimension of the affine hull of `points` (at most 6).
fn affine_rank(points: &[Wrench]) -> usize {
    let n = points.len();
    if n < 2 {
        return 0;
    }
    let p0 = points[0];
    let m = nalgebra::DMatrix::from_fn(6, n - 1, |r, c| points[c + 1][r] - p0[r]);
    let scale = m.amax().max(1e-300);
    let sv = m.svd(false, false).singular_values;
    sv.iter().filter(|s| **s > 1e-9 * scale).count()
}

/// The object's centroid (aligned frame) and its largest distance from it `[mm]`.
pub fn torque_scale(mesh: &crate::mesh::Mesh) -> (Point3<f64>, f64) {
    let c = crate::mesh::mass_properties(mesh).centroid;
    let r = mesh
        .vertices
        .iter()
        .map(|v| (v - c).norm())
        .fold(0.0, f64::max);
    (c, r)
}

/// The contacts the physics check found at the end of closing, with the hand's finger names.
pub fn sim_contacts(
    grip: &[crate::sim::contacts::GripContact],
    hand: &crate::hand::Hand,
) -> Vec<Contact> {
    grip.iter()
        .map(|g| Contact {
            point_mm: g.point_mm,
            normal: g.normal,
            finger: g
                .finger
                .and_then(|i| hand.finger_list.get(i))
                .map_or_else(|| "palm".to_string(), |f| f.name.clone()),
            phalanx: g.phalanx,
            force_n: Some(g.force_n),
        })
        .collect()
}

/// The quality of a planned grasp on `aligned`: from the physics check's contacts at the end
/// of closing when `check` ran on it ([`of_check`]), else from the planned contacts.
pub fn of_grasp(
    grasp: &crate::plan::search::Grasp,
    aligned: &crate::mesh::AlignedObject,
    check: Option<&crate::sim::SimOutcome>,
    hand: &crate::hand::Hand,
    friction: f64,
) -> Quality {
    match check {
        Some(out) => of_check(aligned, out, hand, friction),
        None => evaluate(
            "planned",
            planned_contacts(grasp, hand),
            &params_for(aligned, friction),
        ),
    }
}

/// The quality of the grip a physics check closed on `aligned` (its contacts at the end of
/// closing), whatever the hand's pose came from (a planned grasp or `override_angles`). A
/// check whose fingers closed on nothing gets no contacts: epsilon 0, not force closure.
pub fn of_check(
    aligned: &crate::mesh::AlignedObject,
    out: &crate::sim::SimOutcome,
    hand: &crate::hand::Hand,
    friction: f64,
) -> Quality {
    let contacts = sim_contacts(&out.grip_contacts, hand);
    evaluate("sim", contacts, &params_for(aligned, friction))
}

/// The metric's settings for `aligned` at `friction`: 8 cone edges, torque over the object's
/// largest radius about its centroid.
fn params_for(aligned: &crate::mesh::AlignedObject, friction: f64) -> QualityParams {
    let (centroid_mm, max_radius_mm) = torque_scale(&aligned.mesh);
    QualityParams {
        friction,
        cone_edges: DEFAULT_CONE_EDGES,
        centroid_mm,
        max_radius_mm,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact(p: [f64; 3], n: [f64; 3]) -> Contact {
        Contact {
            point_mm: p,
            normal: n,
            finger: "f".to_string(),
            phalanx: 1,
            force_n: None,
        }
    }

    fn sphere_params(mu: f64) -> QualityParams {
        QualityParams {
            friction: mu,
            cone_edges: 8,
            centroid_mm: Point3::origin(),
            max_radius_mm: 10.0,
        }
    }

    #[test]
    fn two_opposed_contacts_are_not_force_closure() {
        let c = vec![
            contact([10.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            contact([-10.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ];
        let q = evaluate("planned", c, &sphere_params(0.5));
        assert_eq!(q.epsilon, 0.0);
        assert!(!q.force_closure);
        assert_eq!(q.volume, 0.0, "{:?}", q.note);
        assert!(
            q.note.as_deref().unwrap().contains("5 of 6"),
            "{:?}",
            q.note
        );
    }
    /// The support function of conv(points) in direction u.
    fn support(points: &[Wrench], u: &[f64; 6]) -> f64 {
        points
            .iter()
            .map(|w| w.iter().zip(u).map(|(a, b)| a * b).sum::<f64>())
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Epsilon by its definition (Ferrari and Canny 1992: the smallest support value of the
    /// wrench space over unit directions), independently of the hull: many directions from a
    /// fixed pseudo-random sequence, each refined by a shrinking random search. An upper bound
    /// that converges on epsilon from above.
    fn epsilon_by_support(points: &[Wrench]) -> f64 {
        epsilon_by_support_fn(|u| support(points, u))
    }

    /// [`epsilon_by_support`] for any support function `h`.
    fn epsilon_by_support_fn(h_of: impl Fn(&[f64; 6]) -> f64) -> f64 {
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut rand = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let unit = |v: [f64; 6]| {
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.map(|x| x / n)
        };
        let mut best = f64::INFINITY;
        for _ in 0..100 {
            let mut u = unit(std::array::from_fn(|_| rand()));
            let mut h = h_of(&u);
            let mut step = 0.5;
            while step > 1e-7 {
                let mut improved = false;
                for _ in 0..40 {
                    let v = unit(std::array::from_fn(|i| u[i] + step * rand()));
                    let hv = h_of(&v);
                    if hv < h {
                        (u, h) = (v, hv);
                        improved = true;
                    }
                }
                if !improved {
                    step *= 0.5;
                }
            }
            best = best.min(h);
        }
        best.max(0.0)
    }

    #[test]
    fn cross_polytope_and_cube_have_exact_epsilon_and_volume() {
        // conv{±e_i}: facets x·s = 1 for sign vectors s, at distance 1/√6; volume 2^6/6!.
        let mut cross = Vec::new();
        for i in 0..6 {
            for s in [1.0, -1.0] {
                let mut w = [0.0; 6];
                w[i] = s;
                cross.push(w);
            }
        }
        let (m, note) = metrics(&cross);
        assert!(
            (m.epsilon - 1.0 / 6f64.sqrt()).abs() < 1e-9,
            "epsilon {}, expected ~{}",
            m.epsilon,
            1.0 / 6f64.sqrt()
        );
        assert!(
            (m.volume - 64.0 / 720.0).abs() < 1e-9,
            "volume {}, expected ~{}",
            m.volume,
            64.0 / 720.0
        );
        assert!(note.is_none());
        // The cube [−1, 1]^6: epsilon 1, volume 64.
        let cube: Vec<Wrench> = (0..64u32)
            .map(|b| std::array::from_fn(|i| if b >> i & 1 == 1 { 1.0 } else { -1.0 }))
            .collect();
        let (m, _) = metrics(&cube);
        assert!((m.epsilon - 1.0).abs() < 1e-9, "epsilon {}", m.epsilon);
        assert!((m.volume - 64.0).abs() < 1e-6, "volume {}", m.volume);
        // Moved off the origin: the origin is outside, epsilon 0 and said so.
        let shifted: Vec<Wrench> = cube
            .iter()
            .map(|w| std::array::from_fn(|i| w[i] + if i == 0 { 1.5 } else { 0.0 }))
            .collect();
        let (m, note) = metrics(&shifted);
        assert_eq!(m.epsilon, 0.0);
        assert!((m.volume - 64.0).abs() < 1e-6);
        assert!(note.unwrap().contains("outside"));
    }

    #[test]
    fn nearly_coincident_points_keep_their_indices_under_joggled_input() {
        // Every vertex of the cube [−1, 1]^6 twice, 1e-10 apart (as rapier reports a contact
        // twice when two manifolds see it). The hull joggles a copy of the input; the hull's
        // vertices must still be given as indices into the input (a debug build used to panic
        // there), and the metrics must be the cube's.
        let cube: Vec<Wrench> = (0..64u32)
            .map(|b| std::array::from_fn(|i| if b >> i & 1 == 1 { 1.0 } else { -1.0 }))
            .collect();
        let twice: Vec<Wrench> = cube
            .iter()
            .copied()
            .chain(cube.iter().enumerate().map(|(k, w)| {
                std::array::from_fn(|i| w[i] + 1e-10 * (((k * 7 + i * 3) % 5) as f64 - 2.0))
            }))
            .collect();
        let h = hull(&twice).expect("a hull");
        assert!(h.joggle > 0.0);
        let mut corners: Vec<usize> = h.vertices.iter().map(|&i| i % 64).collect();
        corners.sort_unstable();
        corners.dedup();
        assert_eq!(corners, (0..64).collect::<Vec<_>>());
        assert!(h.vertices.iter().all(|&i| i < twice.len()));
        let (m, note) = metrics(&twice);
        assert!(note.is_none(), "{note:?}");
        assert!((m.epsilon - 1.0).abs() < 1e-6, "epsilon {}", m.epsilon);
        assert!((m.volume - 64.0).abs() < 1e-3, "volume {}", m.volume);
    }

    /// Contacts at the vertices of a regular tetrahedron (four) or on the equator 120° apart
    /// (three) of a 10 mm sphere, pushing towards its centre.
    fn symmetric(k: usize) -> Vec<Contact> {
        let dirs: Vec<Vector3<f64>> = if k == 4 {
            vec![
                Vector3::new(1.0, 1.0, 1.0),
                Vector3::new(1.0, -1.0, -1.0),
                Vector3::new(-1.0, 1.0, -1.0),
                Vector3::new(-1.0, -1.0, 1.0),
            ]
        } else {
            (0..k)
                .map(|i| {
                    let a = 2.0 * std::f64::consts::PI * i as f64 / k as f64;
                    Vector3::new(a.cos(), a.sin(), 0.0)
                })
                .collect()
        };
        dirs.iter()
            .map(|d| {
                let d = d.normalize();
                contact((d * 10.0).into(), (-d).into())
            })
            .collect()
    }

    #[test]
    fn symmetric_sphere_grasps_agree_with_the_support_function() {
        for (k, mu) in [(3, 0.5), (4, 0.3), (4, 0.5), (4, 1.0)] {
            let c = symmetric(k);
            let params = sphere_params(mu);
            let q = evaluate("planned", c.clone(), &params);
            let pts: Vec<Wrench> = edge_wrenches(&c, &params).concat();
            let independent = epsilon_by_support(&pts);
            assert!(q.force_closure, "{k} contacts, mu {mu}: {:?}", q.note);
            // The search gives an upper bound: no direction has a smaller support value than
            // epsilon, and the smallest found is within 1 % of it.
            assert!(
                q.epsilon <= independent + 1e-9 && independent <= 1.01 * q.epsilon,
                "{k} contacts, mu {mu}: epsilon {}, by the support function ~{independent}",
                q.epsilon
            );
            assert!(q.volume > 0.0);
            let linf = q.linf.expect("L-infinity computed");
            // The L1 space lies inside the L-infinity space.
            assert!(linf.epsilon >= q.epsilon - 1e-9);
            assert!(linf.volume.expect("a volume") >= q.volume);
        }
        // More friction, a larger wrench space.
        let lo = evaluate("planned", symmetric(4), &sphere_params(0.3));
        let hi = evaluate("planned", symmetric(4), &sphere_params(1.0));
        assert!(hi.epsilon > lo.epsilon && hi.volume > lo.volume);
    }

    #[test]
    fn three_frictionless_contacts_are_not_force_closure() {
        let q = evaluate("planned", symmetric(3), &sphere_params(0.0));
        assert_eq!(q.epsilon, 0.0);
        assert!(!q.force_closure);
    }

    /// The quality of contacts `c` with the object and the grasp turned by `rot` and moved by
    /// `shift` together.
    fn evaluate_moved(
        c: &[Contact],
        params: &QualityParams,
        rot: nalgebra::UnitQuaternion<f64>,
        shift: Vector3<f64>,
    ) -> Quality {
        let moved: Vec<Contact> = c
            .iter()
            .map(|k| Contact {
                point_mm: (rot * Point3::from(k.point_mm) + shift).into(),
                normal: (rot * Vector3::from(k.normal)).into(),
                ..k.clone()
            })
            .collect();
        evaluate(
            "planned",
            moved,
            &QualityParams {
                centroid_mm: rot * params.centroid_mm + shift,
                ..*params
            },
        )
    }

    /// Relative difference of `b` from `a`.
    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / a.abs().max(1e-12)
    }

    /// Asserts `a` and `b` agree to `tol` relative, naming `what`.
    fn assert_near(a: f64, b: f64, tol: f64, what: &str) {
        assert!(rel(a, b) < tol, "{what}: {a} vs {b}");
    }

    #[test]
    fn epsilon_is_invariant_under_moving_object_and_grasp_together() {
        // A translation leaves every wrench as it is: equal to round-off, L-infinity too.
        let c = symmetric(3);
        let params = sphere_params(0.4);
        let q0 = evaluate("planned", c.clone(), &params);
        let shift = Vector3::new(120.0, -35.0, 7.5);
        let q1 = evaluate_moved(&c, &params, nalgebra::UnitQuaternion::identity(), shift);
        assert_near(q0.epsilon, q1.epsilon, 1e-9, "L1 epsilon");
        assert_near(q0.volume, q1.volume, 1e-9, "L1 volume");
        let (a, b) = (q0.linf.unwrap(), q1.linf.unwrap());
        assert!(rel(a.epsilon, b.epsilon) < 1e-9);
        assert!(rel(a.volume.unwrap(), b.volume.unwrap()) < 1e-9);
        // Six contacts: the L∞ epsilon by the search, too.
        let c = scattered(6, 5);
        let q0 = evaluate("planned", c.clone(), &params);
        let q1 = evaluate_moved(&c, &params, nalgebra::UnitQuaternion::identity(), shift);
        let (a, b) = (q0.linf.unwrap().epsilon, q1.linf.unwrap().epsilon);
        assert!(a > 0.0 && rel(a, b) < 1e-9, "{a} vs {b}");
    }

    #[test]
    fn epsilon_is_invariant_under_turning_object_and_grasp_together() {
        // A rotation turns the wrench space rigidly, except that each linearised cone's edges
        // keep the phase of their tangent basis (picked from the normal alone, as GraspIt!
        // does): with 8 edges epsilon moved 2.7 % here, with 64 the cone is round to 0.1 %.
        // Both L1 and L∞.
        let c = symmetric(4);
        let params = QualityParams {
            cone_edges: 64,
            ..sphere_params(0.4)
        };
        let q0 = evaluate("planned", c.clone(), &params);
        let rot = nalgebra::UnitQuaternion::from_euler_angles(0.3, -1.2, 2.5);
        let q1 = evaluate_moved(&c, &params, rot, Vector3::new(120.0, -35.0, 7.5));
        assert_near(q0.epsilon, q1.epsilon, 5e-3, "L1 epsilon");
        assert_near(q0.volume, q1.volume, 5e-3, "L1 volume");
        let (a, b) = (q0.linf.unwrap().epsilon, q1.linf.unwrap().epsilon);
        assert!(a > q0.epsilon && rel(a, b) < 5e-3, "L-infinity {a} vs {b}");
    }

    /// The support function of the L∞ space `Σᵢ conv({0} ∪ per_contact[i])`, written out
    /// here independently of [`linf::support`].
    fn linf_h(per_contact: &[Vec<Wrench>], u: &[f64; 6]) -> f64 {
        per_contact.iter().map(|e| support(e, u).max(0.0)).sum()
    }

    /// The unit vector orthogonal to five vectors (cofactors of the 5×6 matrix), if they are
    /// independent.
    fn orthogonal_to(v: [&Wrench; 5]) -> Option<[f64; 6]> {
        let n: [f64; 6] = std::array::from_fn(|i| {
            let m = nalgebra::Matrix5::from_fn(|r, c| v[r][if c < i { c } else { c + 1 }]);
            if i % 2 == 0 {
                m.determinant()
            } else {
                -m.determinant()
            }
        });
        let len = n.iter().map(|x| x * x).sum::<f64>().sqrt();
        (len > 1e-9).then(|| n.map(|x| x / len))
    }

    /// Epsilon of a Minkowski sum of polytopes by brute force: every facet of the sum is
    /// parallel to five independent edges of the summands, so its normal is among the unit
    /// vectors orthogonal to five of `edges`; the smallest support value over all those
    /// candidates (both signs) is epsilon (each candidate's value bounds it from above).
    fn epsilon_over_edge_normals(edges: &[Wrench], h: impl Fn(&[f64; 6]) -> f64) -> f64 {
        let n = edges.len();
        let mut best = f64::INFINITY;
        let mut idx = [0usize, 1, 2, 3, 4];
        loop {
            if let Some(u) = orthogonal_to(idx.map(|i| &edges[i])) {
                best = best.min(h(&u)).min(h(&u.map(|x| -x)));
            }
            // The next 5-subset in lexicographic order.
            let mut k = 5;
            while k > 0 && idx[k - 1] == n - 5 + k - 1 {
                k -= 1;
            }
            if k == 0 {
                return best.max(0.0);
            }
            idx[k - 1] += 1;
            for j in k..5 {
                idx[j] = idx[j - 1] + 1;
            }
        }
    }

    /// The edges of each contact's pyramid conv({0} ∪ cone edges): apex to every edge
    /// wrench, and round the base.
    fn pyramid_edges(per_contact: &[Vec<Wrench>]) -> Vec<Wrench> {
        let mut out = Vec::new();
        for e in per_contact {
            for (j, w) in e.iter().enumerate() {
                out.push(*w);
                let next = e[(j + 1) % e.len()];
                out.push(std::array::from_fn(|i| next[i] - w[i]));
            }
        }
        out
    }

    /// `k` contacts on a 10 mm sphere, pushing towards its centre, at fixed pseudo-random
    /// places (deterministic), each within a cap so that the grasp closes.
    fn scattered(k: usize, seed: u64) -> Vec<Contact> {
        let mut state = seed;
        let mut rand = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let base = symmetric(4);
        (0..k)
            .map(|i| {
                let d0 = -Vector3::from(base[i % 4].normal);
                let d = (d0 + 0.3 * Vector3::new(rand(), rand(), rand())).normalize();
                contact((d * 10.0).into(), (-d).into())
            })
            .collect()
    }

    #[test]
    fn linf_epsilon_of_the_cube_from_twelve_segments() {
        // Twelve one-edge "contacts" ±e_k: their Minkowski sum is the cube [−1, 1]^6,
        // epsilon 1, volume 64.
        let per_contact: Vec<Vec<Wrench>> = (0..12)
            .map(|k| {
                let mut w = [0.0; 6];
                w[k % 6] = if k < 6 { 1.0 } else { -1.0 };
                vec![w]
            })
            .collect();
        let s = linf::epsilon(&per_contact, linf::EPA_MAX_POINTS).expect("settles");
        assert!((s.epsilon - 1.0).abs() < 1e-9, "{s:?}");
        assert!(s.bracket.1 - s.bracket.0 <= 1e-9, "{s:?}");
        let (vertices, volume) = linf::minkowski_sum(&per_contact, 1000).expect("small");
        // (the joggled input keeps some points on the cube's faces as vertices: they lie
        // in the sum all the same.)
        assert!(vertices.len() >= 64);
        // To the hull's accuracy on joggled input (as for the cube's corners twice, above).
        assert!((volume - 64.0).abs() < 1e-4, "volume {volume}");
        // A grasp's volume comes from rays, within its stated standard error.
        let l = linf::evaluate(&per_contact);
        assert!((l.epsilon.unwrap() - 1.0).abs() < 1e-9);
        let (v, se) = (l.volume.unwrap(), l.volume_rel_se.unwrap());
        assert!((v - 64.0).abs() < 3.0 * se * v, "{v} ± {se} against 64");
        assert!(l.note.is_none(), "{:?}", l.note);
    }

    #[test]
    fn linf_epsilon_of_zonotopes_matches_their_facets() {
        // Segments [−g, g] (as two one-edge contacts, g and −g) sum to a zonotope, whose
        // support function is Σ|g·u| and whose facets are orthogonal to 5 generators: epsilon
        // is the smallest support value over those normals (closed form, all 252 of them).
        let mut state: u64 = 0x1234_5678_9ABC_DEF1;
        let mut rand = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..3 {
            let gens: Vec<Wrench> = (0..10).map(|_| std::array::from_fn(|_| rand())).collect();
            let per_contact: Vec<Vec<Wrench>> = gens
                .iter()
                .flat_map(|g| [vec![*g], vec![g.map(|x| -x)]])
                .collect();
            let h = |u: &[f64; 6]| {
                gens.iter()
                    .map(|g| g.iter().zip(u).map(|(a, b)| a * b).sum::<f64>().abs())
                    .sum::<f64>()
            };
            let exact = epsilon_over_edge_normals(&gens, h);
            let s = linf::epsilon(&per_contact, linf::EPA_MAX_POINTS).expect("settles");
            assert!(rel(exact, s.epsilon) < 1e-9, "{} vs {exact}", s.epsilon);
        }
    }

    #[test]
    fn linf_epsilon_of_four_and_five_contacts_matches_brute_force_over_facet_normals() {
        // 4 cone edges, so that every 5 of the pyramids' edges can be tried (201 376 and
        // 658 008 normals): the brute force is exact and shares no code with the search.
        for (k, seed) in [(4, 7), (4, 11), (5, 13)] {
            let params = QualityParams {
                cone_edges: 4,
                ..sphere_params(0.5)
            };
            let per_contact = edge_wrenches(&scattered(k, seed), &params);
            let exact = epsilon_over_edge_normals(&pyramid_edges(&per_contact), |u| {
                linf_h(&per_contact, u)
            });
            let q = evaluate("planned", scattered(k, seed), &params);
            let linf = q.linf.expect("settles");
            assert!(q.force_closure && exact > 0.0, "{k} contacts: {:?}", q.note);
            assert!(
                rel(exact, linf.epsilon) < 1e-9,
                "{k} contacts (seed {seed}): {} vs {exact}",
                linf.epsilon
            );
            assert!(linf.epsilon >= q.epsilon, "L1 lies inside L-infinity");
        }
    }

    #[test]
    fn linf_epsilon_of_four_to_eight_contacts_agrees_with_the_support_function() {
        // 8 cone edges (the default): too many edge 5-subsets to try, so the search is held
        // against the definition, as L1 is: never above any support value found, and within
        // 1 % of the smallest.
        for (k, seed) in [(4, 3), (6, 5), (8, 9)] {
            let c = scattered(k, seed);
            let params = sphere_params(0.5);
            let per_contact = edge_wrenches(&c, &params);
            let s = linf::epsilon(&per_contact, linf::EPA_MAX_POINTS).expect("settles");
            let independent = epsilon_by_support_fn(|u| linf_h(&per_contact, u));
            assert!(
                s.epsilon <= independent + 1e-9 && independent <= 1.01 * s.epsilon,
                "{k} contacts: epsilon {}, by the support function ~{independent}",
                s.epsilon
            );
            assert!(s.bracket.1 - s.bracket.0 <= 1e-9 * s.bracket.1, "{s:?}");
            let q = evaluate("planned", c, &params);
            assert!(q.linf.unwrap().epsilon >= q.epsilon, "L1 inside L-infinity");
        }
    }

    #[test]
    fn linf_epsilon_and_volume_of_three_contacts_agree_with_the_hull_of_the_sum() {
        // Three contacts: the whole Minkowski sum (729 points) can be hulled, and its
        // smallest facet distance must be the search's epsilon.
        let c = symmetric(3);
        let params = sphere_params(0.5);
        let per_contact = edge_wrenches(&c, &params);
        let (vertices, volume) = linf::minkowski_sum(&per_contact, 1000).expect("small");
        let (by_hull, _) = metrics(&vertices);
        let q = evaluate("planned", c, &params);
        let linf = q.linf.expect("settles");
        assert!(
            rel(by_hull.epsilon, linf.epsilon) < 1e-6,
            "{} vs {}",
            by_hull.epsilon,
            linf.epsilon
        );
        assert!(rel(by_hull.volume, volume) < 1e-6);
        let (v, se) = (linf.volume.unwrap(), linf.volume_rel_se.unwrap());
        assert!(
            (v - volume).abs() < 3.0 * se * v,
            "rays {v} ± {se} against {volume}"
        );
        assert!(volume > q.volume, "L1 inside L-infinity");
    }

    #[test]
    fn linf_volume_by_rays_agrees_with_the_hull_for_three_contacts() {
        // Three contacts: the whole Minkowski sum can be hulled, so every ray's exit
        // can be checked against the hull's facets, and the estimate against the exact volume.
        let cases = [
            (symmetric(3), 0.5),
            (symmetric(3), 1.0),
            (scattered(3, 5), 0.5),
            (scattered(3, 11), 0.3),
        ];
        for (c, mu) in cases {
            let per_contact = edge_wrenches(&c, &sphere_params(mu));
            let (vertices, exact) = linf::minkowski_sum(&per_contact, 1000).expect("small");
            let facets = linf::hull_facets(&vertices).expect("a hull");
            let centre = rays::centre(&per_contact);
            for u in rays::directions(40) {
                let t = rays::ray_exit(&per_contact, &centre, &u).expect("a ray");
                // The hull's radial function from the centre: the nearest facet plane ahead.
                let by_hull = facets
                    .iter()
                    .filter_map(|(_, n, off)| {
                        let nu: f64 = n.iter().zip(&u).map(|(a, b)| a * b).sum();
                        let nc: f64 = n.iter().zip(&centre).map(|(a, b)| a * b).sum();
                        (nu > 1e-12).then(|| (-off - nc) / nu)
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    rel(t, by_hull) < 1e-6,
                    "ray {t} against the hull's {by_hull}"
                );
            }
            let v = rays::volume(&per_contact, rays::VOLUME_RAYS).expect("a volume");
            assert!(v.rel_se < 0.05, "{v:?}");
            assert!(
                (v.volume - exact).abs() < 3.0 * v.rel_se * v.volume,
                "{v:?} against the hull's {exact}"
            );
        }
    }

    #[test]
    fn linf_of_every_contact_twice_is_twice_as_large() {
        // Each contact reported twice (as rapier may): L1 is unchanged (the same hull), L∞
        // doubles exactly (P + P = 2P), with or without the merging of identical contacts.
        let c = scattered(6, 21);
        let params = sphere_params(0.4);
        let once = evaluate("planned", c.clone(), &params);
        let twice = evaluate("planned", [c.clone(), c].concat(), &params);
        assert!(rel(once.epsilon, twice.epsilon) < 1e-9);
        let (a, b) = (once.linf.unwrap().epsilon, twice.linf.unwrap().epsilon);
        assert!(rel(2.0 * a, b) < 1e-9, "{a} twice is not {b}");
        let doubled: Vec<Vec<Wrench>> = edge_wrenches(&scattered(6, 21), &params)
            .into_iter()
            .map(|e| e.into_iter().map(|w| w.map(|x| 2.0 * x)).collect())
            .collect();
        let s = linf::epsilon(&doubled, linf::EPA_MAX_POINTS).unwrap();
        assert!(rel(b, s.epsilon) < 1e-9);
        // The volume by rays scales as 2^6 to round-off: the rays and their whitening scale
        // with the space.
        let (a, b) = (once.linf.unwrap().volume, twice.linf.unwrap().volume);
        assert!(rel(64.0 * a.unwrap(), b.unwrap()) < 1e-9, "{a:?} and {b:?}");
    }

    #[test]
    fn linf_is_zero_without_force_closure_and_bounded_when_the_search_is_cut_short() {
        let opposed = vec![
            contact([10.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            contact([-10.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ];
        let q = evaluate("planned", opposed, &sphere_params(0.5));
        assert_eq!(q.linf.unwrap().epsilon, 0.0);
        let q = evaluate("planned", symmetric(3), &sphere_params(0.0));
        assert_eq!(q.linf.unwrap().epsilon, 0.0);
        // Too few support points allowed: no answer, and the reason, not a hang.
        let per_contact = edge_wrenches(&scattered(8, 9), &sphere_params(0.5));
        let err = linf::epsilon(&per_contact, 2).unwrap_err().to_string();
        assert!(err.contains("not settled after 2 support points"), "{err}");
    }

    /// The cost per grasp of L1 and L∞ beside the physics check (BENCHMARKS.md): every
    /// scenario in `$QUALITY_COST_SCENARIOS` (paths, space-separated; default the bundled
    /// scenarios and the tuning set), up to 3 candidates each, each checked with gravity
    /// `down`, then L1 and L∞ timed apart on the contacts at the end of closing. Run with
    /// `cargo test --release --lib quality::tests::cost_per_grasp -- --ignored --nocapture`.
    #[test]
    #[ignore = "a measurement (minutes), not a test"]
    fn cost_per_grasp() {
        use std::time::Instant;
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let paths: Vec<std::path::PathBuf> = match std::env::var("QUALITY_COST_SCENARIOS") {
            Ok(list) => list.split_whitespace().map(Into::into).collect(),
            Err(_) => ["scenarios", "assets/objects/train"]
                .iter()
                .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap())
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect(),
        };
        let mut paths = paths;
        paths.sort();
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        // Contacts, check, L1 and L∞ milliseconds, L∞ support points added, L∞ volume's relative
        // standard error, and the milliseconds of that volume alone.
        type Row = (usize, f64, f64, f64, usize, f64, f64);
        let mut rows: Vec<Row> = Vec::new();
        println!("scenario | candidate | contacts | check ms | L1 ms | L∞ ms | L∞ points added | epsilon L1 | epsilon L∞ | volume L∞ | its relative s.e.");
        for path in &paths {
            let sc = crate::scenario::Scenario::load(path).unwrap();
            let Ok(loaded) = crate::mesh::load_mesh(&sc.object.mesh, sc.object.units) else {
                continue;
            };
            let props = crate::mesh::mass_properties(&loaded.mesh);
            let mass_kg = sc.object.mass.mass_kg(props.volume_mm3, loaded.mass_kg);
            let no_check =
                |_: &crate::mesh::AlignedObject,
                 _: &crate::plan::search::Grasp|
                 -> crate::sim::SimOutcome { unreachable!("max_checked is None") };
            let selection = crate::select::select(
                &loaded.mesh,
                &props,
                &crate::select::SelectParams {
                    hand: &sc.hand,
                    planner: &sc.planner,
                    friction: sc.object.friction,
                    collect: 3,
                    max_checked: None,
                    check: &no_check,
                    recheck: None,
                    probe: None,
                    domains: None,
                    frame: sc.object.frame,
                    order_by_closing: None,
                    order_samples: None,
                    plan_reach: 0,
                    order_reach: 0,
                },
                &mut crate::report::StageTimings::default(),
            );
            for (k, c) in selection.candidates.iter().enumerate() {
                let axis = &selection.axes[c.axis_plan];
                let shape =
                    crate::sim::ObjectShape::from_mesh(&axis.aligned.mesh, props.volume_mm3);
                let pose = crate::sim::SimHand::from_grasp(&c.grasp, &sc.hand);
                let mut sim_params = sc.sim.clone();
                sim_params.gravity = crate::scenario::GravityMode::Down;
                let t = Instant::now();
                let down = crate::sim::check(&crate::sim::Case {
                    hand: &sc.hand,
                    pose: &pose,
                    object: &shape,
                    mass_kg,
                    friction: sc.object.friction,
                    params: &sim_params,
                });
                let ms_check = ms(t);
                let contacts = sim_contacts(&down.grip_contacts, &sc.hand);
                let (centroid_mm, max_radius_mm) = torque_scale(&axis.aligned.mesh);
                let params = QualityParams {
                    friction: sc.object.friction,
                    cone_edges: DEFAULT_CONE_EDGES,
                    centroid_mm,
                    max_radius_mm,
                };
                let per_contact = edge_wrenches(&contacts, &params);
                let points: Vec<Wrench> = per_contact.concat();
                let t = Instant::now();
                let (l1, _) = metrics(&points);
                let ms_l1 = ms(t);
                let t = Instant::now();
                let l = linf::evaluate(&per_contact);
                let ms_linf = ms(t);
                // The volume by rays again, alone.
                let merged = linf::merge_identical(&per_contact);
                let t = Instant::now();
                let _ = rays::volume(&merged, rays::VOLUME_RAYS);
                let ms_volume = ms(t);
                println!(
                    "{} | {} | {} | {ms_check:.0} | {ms_l1:.1} | {ms_linf:.1} | {} | {:.4} | {:?} | {:?} | {:?}",
                    sc.name,
                    k + 1,
                    contacts.len(),
                    l.points_added,
                    l1.epsilon,
                    l.epsilon,
                    l.volume,
                    l.volume_rel_se
                );
                assert!(l.epsilon.is_some(), "{:?}", l.note);
                rows.push((
                    contacts.len(),
                    ms_check,
                    ms_l1,
                    ms_linf,
                    l.points_added,
                    l.volume_rel_se.unwrap_or(f64::NAN),
                    ms_volume,
                ));
            }
        }
        let stats = |f: &dyn Fn(&Row) -> f64| {
            let mut v: Vec<f64> = rows.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
            format!(
                "median {:.1}, 90th percentile {:.1}, largest {:.1}",
                at(0.5),
                at(0.9),
                at(1.0)
            )
        };
        println!("{} grasps", rows.len());
        println!("contacts: {}", stats(&|r| r.0 as f64));
        println!("check ms: {}", stats(&|r| r.1));
        println!("L1 ms: {}", stats(&|r| r.2));
        println!("L-infinity ms: {}", stats(&|r| r.3));
        println!("L-infinity points added: {}", stats(&|r| r.4 as f64));
        println!("L-infinity / check: {}", stats(&|r| r.3 / r.1));
        println!(
            "L-infinity volume relative s.e. %: {}",
            stats(&|r| 100.0 * r.5)
        );
        println!(
            "L-infinity volume ms (of L-infinity ms): {}",
            stats(&|r| r.6)
        );
    }
}
