//! Primitive solids in millimetres: the radial solid (a stack of rings about Z) and what it
//! builds (cylinder, frustum, prism), and the UV sphere.
//!
//! They live here, below the test objects of [`crate::objects`] (which re-exports them), because
//! a URDF's `<box>`, `<cylinder>` and `<sphere>` are meshed with them when a URDF is loaded.
//! Every solid is closed and outward-wound; the radial ones stand on Z = 0, centred on the Z axis.

use super::Mesh;
use nalgebra::Point3;
use std::f64::consts::{PI, TAU};

/// Angular samples around the axis: every 2.5°, the finest vertical slicing the planner uses by
/// default divides this evenly, and the chord error on a 40 mm cylinder is 0.005 mm.
pub const RING_SEGMENTS: usize = 144;

/// One ring of a radial solid: its height and radius at each of the solid's angles.
#[derive(Debug, Clone)]
pub struct Ring {
    /// Height `[mm]`.
    pub z: f64,
    /// Radius at each angle `[mm]`, all positive.
    pub radii: Vec<f64>,
}

/// Builds a closed, outward-wound solid from rings over shared `angles` (radians, increasing,
/// within one turn). Rings must have non-decreasing heights; consecutive rings at one height make
/// a horizontal step and must differ in radius at every angle.
///
/// # Panics
/// If a ring has the wrong number of radii or fewer than two rings are given.
pub fn radial_solid(angles: &[f64], rings: &[Ring]) -> Mesh {
    assert!(rings.len() >= 2, "a radial solid needs two rings");
    let n = angles.len();
    let pts: Vec<Vec<Point3<f64>>> = rings
        .iter()
        .map(|r| {
            assert_eq!(r.radii.len(), n, "ring radii must match the angles");
            angles
                .iter()
                .zip(&r.radii)
                .map(|(&a, &rad)| Point3::new(rad * a.cos(), rad * a.sin(), r.z))
                .collect()
        })
        .collect();
    let mut soup = Vec::new();
    let bottom = Point3::new(0.0, 0.0, rings[0].z);
    let top = Point3::new(0.0, 0.0, rings[rings.len() - 1].z);
    for k in 0..n {
        let k1 = (k + 1) % n;
        soup.push([bottom, pts[0][k1], pts[0][k]]);
        let last = &pts[pts.len() - 1];
        soup.push([top, last[k], last[k1]]);
        for j in 0..pts.len() - 1 {
            let (a, b) = (&pts[j], &pts[j + 1]);
            soup.push([a[k], a[k1], b[k1]]);
            soup.push([a[k], b[k1], b[k]]);
        }
    }
    Mesh::from_triangles(&soup).0
}

/// `count` angles evenly around a turn, starting at 0.
pub fn uniform_angles(count: usize) -> Vec<f64> {
    (0..count).map(|k| TAU * k as f64 / count as f64).collect()
}

/// Merges extra angles (radians, any turn) into a sorted angle list, dropping near-duplicates.
pub fn with_angles(mut base: Vec<f64>, extra: &[f64]) -> Vec<f64> {
    base.extend(extra.iter().map(|a| a.rem_euclid(TAU)));
    base.sort_by(f64::total_cmp);
    base.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    if base.len() > 1 && (TAU - base[base.len() - 1] + base[0]).abs() < 1e-9 {
        base.pop();
    }
    base
}

/// A frustum (a cylinder when the diameters are equal) standing on Z = 0 `[mm]`.
pub fn frustum(bottom_diameter: f64, top_diameter: f64, height: f64) -> Mesh {
    let angles = uniform_angles(RING_SEGMENTS);
    let ring = |z: f64, d: f64| Ring {
        z,
        radii: vec![d / 2.0; angles.len()],
    };
    radial_solid(
        &angles,
        &[ring(0.0, bottom_diameter), ring(height, top_diameter)],
    )
}

/// A cylinder of diameter `d` and height `h` standing on Z = 0 `[mm]`.
pub fn cylinder(d: f64, h: f64) -> Mesh {
    frustum(d, d, h)
}

/// Radius of an axis-centred rectangle `a × b` (along X × Y) at `angle`.
pub(crate) fn rectangle_radius(a: f64, b: f64, angle: f64) -> f64 {
    let (s, c) = angle.sin_cos();
    let rx = if c.abs() > 1e-15 {
        a / 2.0 / c.abs()
    } else {
        f64::INFINITY
    };
    let ry = if s.abs() > 1e-15 {
        b / 2.0 / s.abs()
    } else {
        f64::INFINITY
    };
    rx.min(ry)
}

/// The angles of an axis-centred rectangle `a × b`'s corners, counter-clockwise from +X.
pub(crate) fn rectangle_corners(a: f64, b: f64) -> [f64; 4] {
    let c = (b / 2.0).atan2(a / 2.0);
    [c, PI - c, PI + c, TAU - c]
}

/// A rectangular prism `a × b × h` (along X, Y, Z) standing on Z = 0, centred on the Z axis.
///
/// Its side faces are exact planes (extra vertices on them are collinear), with vertices at
/// every [`RING_SEGMENTS`] angle like the other objects.
pub fn prism(a: f64, b: f64, h: f64) -> Mesh {
    let angles = with_angles(uniform_angles(RING_SEGMENTS), &rectangle_corners(a, b));
    let radii: Vec<f64> = angles.iter().map(|&t| rectangle_radius(a, b, t)).collect();
    radial_solid(
        &angles,
        &[
            Ring {
                z: 0.0,
                radii: radii.clone(),
            },
            Ring { z: h, radii },
        ],
    )
}

/// A UV sphere of radius `r` centred at the origin, `n` segments around and `n / 2` from pole to
/// pole. Every vertex lies exactly on the sphere.
pub fn uv_sphere(r: f64, n: usize) -> Mesh {
    let stacks = n / 2;
    let mut soup = Vec::new();
    let p = |i: usize, k: usize| {
        let phi = PI * i as f64 / stacks as f64;
        let th = TAU * (k % n) as f64 / n as f64;
        Point3::new(
            r * phi.sin() * th.cos(),
            r * phi.sin() * th.sin(),
            r * phi.cos(),
        )
    };
    for i in 0..stacks {
        for k in 0..n {
            let (a, b, c, d) = (p(i, k), p(i, k + 1), p(i + 1, k + 1), p(i + 1, k));
            if i != 0 {
                soup.push([a, d, b]);
            }
            if i != stacks - 1 {
                soup.push([b, d, c]);
            }
        }
    }
    // Poles are single points: snap the zero-radius rings so the welding merges them.
    for t in &mut soup {
        for q in t.iter_mut() {
            if q.x.abs() < 1e-12 && q.y.abs() < 1e-12 {
                *q = Point3::new(0.0, 0.0, q.z.signum() * r);
            }
        }
    }
    Mesh::from_triangles(&soup).0
}
