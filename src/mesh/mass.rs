//! Volume, centroid and inertia tensor of a closed triangle mesh by the divergence theorem.
//!
//! The surface integrals of 1, x, y, z, x², y², z², xy, yz, zx over the enclosed solid are summed
//! triangle by triangle, following D. Eberly, "Polyhedral Mass Properties (Revisited)", Geometric
//! Tools, 2002 (itself after B. Mirtich, "Fast and Accurate Computation of Polyhedral Mass
//! Properties", 1996). Densities are 1: the volume is in mm³ and the inertia in mm⁵; multiply by a
//! density to get kg·mm².
//!
//! Coordinates are taken relative to the centre of the bounding box first, so a mesh far from the
//! origin keeps its precision.

use super::Mesh;
use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

/// Mass properties of a solid of unit density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Enclosed volume `[mm³]` (negative if the mesh is wound inside-out).
    pub volume_mm3: f64,
    /// Centroid `[mm]`.
    pub centroid: Point3<f64>,
    /// Inertia tensor about the centroid, unit density `[mm⁵]`.
    pub inertia: Matrix3<f64>,
}

/// Computes the mass properties of `mesh` (which should be closed and outward-wound).
pub fn mass_properties(mesh: &Mesh) -> MassProperties {
    mass_properties_from(mesh, surface_mass_properties(mesh))
}

/// [`mass_properties`] with `exact` standing for the surface integral (the covariant fan's,
/// for a surface whose integral about the file's origin depends on the frame): the union's
/// where several shells overlap, else `exact`.
pub fn mass_properties_from(mesh: &Mesh, exact: MassProperties) -> MassProperties {
    if exact.volume_mm3 <= 0.0 || !mesh.shells_may_overlap() {
        return exact;
    }
    // Shells whose bounds meet: the surface integral adds their volumes, counting any overlap
    // twice. Where the union (integrated over slices) is smaller by more than the integration's
    // own error, the shells overlap and the union is the object. Shells apart (an assembly's
    // parts, issue 56) keep the exact sum: the slices' error at each shell's ends would pass
    // for an overlap.
    let union = union_mass_properties(mesh, UNION_SLICES);
    if union.volume_mm3 < exact.volume_mm3 * (1.0 - OVERLAP_TOLERANCE) {
        union
    } else {
        exact
    }
}

/// Slices across the object for the union's mass properties: the midpoint rule's error on a box
/// is nil, on a sphere 1/(2 n²) of the volume (3e-6 here); tests measure it on overlapping boxes
/// and a box with a cylinder pushed into it.
const UNION_SLICES: usize = 400;

/// Shells whose summed volume exceeds their union by this share overlap.
const OVERLAP_TOLERANCE: f64 = 1e-3;

/// The union's mass properties sliced across the surface's own long axis (the area-weighted
/// covariance of its triangles, which moves and turns with the mesh whether or not it is closed),
/// open ends of a slice within [`super::load::SMALL_HOLE_MM`] joined: what a union of open shells
/// encloses no longer depends on the frame the file was written in.
pub fn union_mass_properties(mesh: &Mesh, n: usize) -> MassProperties {
    let (centre, frame) = surface_frame(mesh);
    let mut local = mesh.clone();
    local.map_vertices(|p| Point3::from(frame.transpose() * (p - centre)));
    let l = sliced_mass_properties_with(&local, n, super::load::SMALL_HOLE_MM);
    MassProperties {
        volume_mm3: l.volume_mm3,
        centroid: centre + frame * l.centroid.coords,
        inertia: frame * l.inertia * frame.transpose(),
    }
}

/// The area-weighted centroid of a surface and the eigenvectors of its area-weighted covariance
/// (columns, the largest variance last, right-handed, each with its largest component positive).
fn surface_frame(mesh: &Mesh) -> (Point3<f64>, Matrix3<f64>) {
    let mut area = 0.0;
    let mut first = Vector3::zeros();
    let tris: Vec<(f64, Vector3<f64>)> = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let w = (b - a).cross(&(c - a)).norm() / 2.0;
            (w, (a.coords + b.coords + c.coords) / 3.0)
        })
        .collect();
    for &(w, m) in &tris {
        area += w;
        first += w * m;
    }
    let centre = if area > 0.0 {
        first / area
    } else {
        Vector3::zeros()
    };
    let mut cov = Matrix3::zeros();
    for (t, &(w, _)) in tris.iter().enumerate() {
        let [a, b, c] = mesh.corners(t);
        let (a, b, c) = (a.coords - centre, b.coords - centre, c.coords - centre);
        // The second moment of a triangle of area w about the centre: w/12 (aa + bb + cc + s s)
        // with s = a + b + c, integrated exactly.
        let s = a + b + c;
        cov += w / 12.0
            * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
    }
    let eig = nalgebra::SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let mut cols: Vec<Vector3<f64>> = order
        .iter()
        .map(|&i| {
            let v = eig.eigenvectors.column(i).into_owned();
            let k = v.iamax();
            if v[k] < 0.0 {
                -v
            } else {
                v
            }
        })
        .collect();
    cols[1] = cols[2].cross(&cols[0]);
    (Point3::from(centre), Matrix3::from_columns(&cols))
}

/// Mass properties (unit density) of the solid a mesh encloses, taken as the union of its
/// shells: the areas and area moments of `n` horizontal slices (each the union of what the
/// shells cut, [`super::slice::slice`]) integrated along Z by the midpoint rule.
pub fn sliced_mass_properties(mesh: &Mesh, n: usize) -> MassProperties {
    sliced_mass_properties_with(mesh, n, 0.0)
}

/// As [`sliced_mass_properties`], open ends within `join_mm` joined in every slice.
fn sliced_mass_properties_with(mesh: &Mesh, n: usize, join_mm: f64) -> MassProperties {
    let (lo, hi) = mesh.bounds();
    let reference = nalgebra::center(&lo, &hi);
    let dz = (hi.z - lo.z) / n as f64;
    // ∫1, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z², ∫xy, ∫yz, ∫zx about `reference`.
    let mut m = [0.0f64; 10];
    // The slices are independent: cut on rayon's pool, each slice's area moments summed in
    // its own order, then added up in the slices' order, so the sum is the same bits whatever
    // the thread count.
    let moments: Vec<[f64; 6]> = (0..n)
        .into_par_iter()
        .map(|k| {
            let z_abs = lo.z + (k as f64 + 0.5) * dz;
            let plane = super::slice::Plane::horizontal(z_abs);
            let s = super::slice::slice(mesh, &plane, super::slice::SliceOptions::default())
                .joined(join_mm);
            let (mut a, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for c in s.contours.iter().filter(|c| c.is_closed) {
                let np = c.points.len();
                for i in 0..np {
                    let p = c.points[i] - reference.xy().coords;
                    let q = c.points[(i + 1) % np] - reference.xy().coords;
                    let cross = p.x * q.y - q.x * p.y;
                    a += cross / 2.0;
                    sx += (p.x + q.x) * cross / 6.0;
                    sy += (p.y + q.y) * cross / 6.0;
                    sxx += (p.x * p.x + p.x * q.x + q.x * q.x) * cross / 12.0;
                    syy += (p.y * p.y + p.y * q.y + q.y * q.y) * cross / 12.0;
                    sxy +=
                        (p.x * q.y + 2.0 * p.x * p.y + 2.0 * q.x * q.y + q.x * p.y) * cross / 24.0;
                }
            }
            [a, sx, sy, sxx, syy, sxy]
        })
        .collect();
    for (k, &[a, sx, sy, sxx, syy, sxy]) in moments.iter().enumerate() {
        let z = lo.z + (k as f64 + 0.5) * dz - reference.z;
        m[0] += a * dz;
        m[1] += sx * dz;
        m[2] += sy * dz;
        m[3] += a * z * dz;
        m[4] += sxx * dz;
        m[5] += syy * dz;
        // A slab's own thickness adds dz²/12 to ∫z² per unit of area.
        m[6] += a * (z * z + dz * dz / 12.0) * dz;
        m[7] += sxy * dz;
        m[8] += sy * z * dz;
        m[9] += sx * z * dz;
    }
    if m[0] <= 0.0 {
        m[0] = 0.0;
    }
    from_integrals(reference, &m)
}

/// Mass properties by the divergence theorem over the surface (exact for one closed shell; for
/// several shells the sum of theirs).
pub fn surface_mass_properties(mesh: &Mesh) -> MassProperties {
    let (lo, hi) = mesh.bounds();
    let reference = nalgebra::center(&lo, &hi);
    let mut intg = [0.0f64; 10];
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        let (p0, p1, p2) = (a - reference, b - reference, c - reference);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let d = e1.cross(&e2);
        let sx = subexpressions(p0.x, p1.x, p2.x);
        let sy = subexpressions(p0.y, p1.y, p2.y);
        let sz = subexpressions(p0.z, p1.z, p2.z);
        intg[0] += d.x * sx.f1;
        intg[1] += d.x * sx.f2;
        intg[2] += d.y * sy.f2;
        intg[3] += d.z * sz.f2;
        intg[4] += d.x * sx.f3;
        intg[5] += d.y * sy.f3;
        intg[6] += d.z * sz.f3;
        intg[7] += d.x * (p0.y * sx.g[0] + p1.y * sx.g[1] + p2.y * sx.g[2]);
        intg[8] += d.y * (p0.z * sy.g[0] + p1.z * sy.g[1] + p2.z * sy.g[2]);
        intg[9] += d.z * (p0.x * sz.g[0] + p1.x * sz.g[1] + p2.x * sz.g[2]);
    }
    const MULT: [f64; 10] = [
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 24.0,
        1.0 / 24.0,
        1.0 / 60.0,
        1.0 / 60.0,
        1.0 / 60.0,
        1.0 / 120.0,
        1.0 / 120.0,
        1.0 / 120.0,
    ];
    for (v, m) in intg.iter_mut().zip(MULT) {
        *v *= m;
    }
    from_integrals(reference, &intg)
}

/// Mass properties from the volume integrals about `reference`: ∫1, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z²,
/// ∫xy, ∫yz, ∫zx (unit density); the inertia is taken about the centroid. A zero volume gives
/// no centroid offset and no inertia.
fn from_integrals(reference: Point3<f64>, m: &[f64; 10]) -> MassProperties {
    let v = m[0];
    if v == 0.0 {
        return MassProperties {
            volume_mm3: 0.0,
            centroid: reference,
            inertia: Matrix3::zeros(),
        };
    }
    let c = Vector3::new(m[1], m[2], m[3]) / v;
    let xx = m[5] + m[6] - v * (c.y * c.y + c.z * c.z);
    let yy = m[4] + m[6] - v * (c.z * c.z + c.x * c.x);
    let zz = m[4] + m[5] - v * (c.x * c.x + c.y * c.y);
    let xy = -(m[7] - v * c.x * c.y);
    let yz = -(m[8] - v * c.y * c.z);
    let zx = -(m[9] - v * c.z * c.x);
    MassProperties {
        volume_mm3: v,
        centroid: reference + c,
        inertia: Matrix3::new(xx, xy, zx, xy, yy, yz, zx, yz, zz),
    }
}

struct Sub {
    f1: f64,
    f2: f64,
    f3: f64,
    g: [f64; 3],
}

fn subexpressions(w0: f64, w1: f64, w2: f64) -> Sub {
    let temp0 = w0 + w1;
    let f1 = temp0 + w2;
    let temp1 = w0 * w0;
    let temp2 = temp1 + w1 * temp0;
    let f2 = temp2 + w2 * f1;
    let f3 = w0 * temp1 + w1 * temp2 + w2 * f2;
    Sub {
        f1,
        f2,
        f3,
        g: [
            f2 + w0 * (f1 + w0),
            f2 + w1 * (f1 + w1),
            f2 + w2 * (f1 + w2),
        ],
    }
}
