//! Deterministic generators for the thesis's test objects and for geometry test fixtures.
//!
//! Every thesis object (chapters 4 and 5) is star-shaped about its axis, so one builder serves
//! them all: a [`radial_solid`] is a stack of rings, each ring a radius per angle at one height,
//! closed by flat caps. Sharp steps (the base's top, the horizontal ridge's faces) are two rings at
//! the same height. The angles always include every 2.5°, so each vertical slice the planner makes
//! at its 10° AngularStep passes exactly through mesh vertices — the slicer's hardest case.
//!
//! Output is a [`Mesh`] in millimetres, aligned already (principal axis +Z, bottom at Z = 0).

pub mod hard;

pub use crate::mesh::primitives::{
    cylinder, frustum, prism, radial_solid, uniform_angles, uv_sphere, with_angles, Ring,
    RING_SEGMENTS,
};

pub(crate) use crate::mesh::primitives::{rectangle_corners, rectangle_radius};
use crate::mesh::Mesh;
use nalgebra::Point3;
use std::f64::consts::{PI, TAU};

/// Dimensions of the rebuilt chapter 4 test object `[mm]` (thesis 4.2–4.3, Fig. 4.1 lost).
///
/// From the text: total height 175; a prismatic base whose top edge is ungraspable at Z = 12; a
/// tapered cylinder narrowing towards the base; a horizontal ridge whose sharp edges are at about
/// Z = 95 and 107 (the palm-blocked band of Fig. 4.7 starts at 94.5 and ends at 157 = 107 + 50);
/// an untapered cylinder above; a vertical ridge. Chosen here (not in the text): the diameters,
/// set so the palm pitch on the taper is about the reported 7.3° and the joint angles fall in the
/// cup's range; the vertical ridge faces +X (approach angle 0), so it must push the approach
/// angle away from 0.
#[derive(Debug, Clone, Copy)]
pub struct Chapter4Dims {
    /// Side of the square base.
    pub base_side: f64,
    /// Height of the base's top.
    pub base_top: f64,
    /// Tapered cylinder diameter at the base's top.
    pub taper_bottom_diameter: f64,
    /// Tapered cylinder diameter at the ridge.
    pub taper_top_diameter: f64,
    /// Horizontal ridge bottom and top heights.
    pub ridge_z: (f64, f64),
    /// Horizontal ridge diameter.
    pub ridge_diameter: f64,
    /// Upper (untapered) cylinder diameter.
    pub upper_diameter: f64,
    /// Total height.
    pub height: f64,
    /// Vertical ridge: angle of its centre from +X (degrees), half-width of its flat top
    /// (degrees), and how far it stands out from the surface below it.
    pub rib_angle_deg: f64,
    /// Half-width of the vertical ridge's flat top `[deg]`.
    pub rib_half_width_deg: f64,
    /// Height of the vertical ridge above the surface.
    pub rib_height: f64,
}

impl Default for Chapter4Dims {
    fn default() -> Self {
        Chapter4Dims {
            base_side: 90.0,
            base_top: 12.0,
            taper_bottom_diameter: 64.0,
            taper_top_diameter: 86.0,
            ridge_z: (95.0, 107.0),
            ridge_diameter: 100.0,
            upper_diameter: 80.0,
            height: 175.0,
            rib_angle_deg: 0.0,
            rib_half_width_deg: 5.0,
            rib_height: 8.0,
        }
    }
}

/// The chapter 4 test object rebuilt from the text (see [`Chapter4Dims`]).
pub fn chapter4(d: &Chapter4Dims) -> Mesh {
    let rib_c = d.rib_angle_deg.to_radians();
    let half = d.rib_half_width_deg.to_radians();
    // The rib's sides slope over 1° so that no two rings coincide at its edges.
    let foot = half + 1f64.to_radians();
    let angles = with_angles(
        uniform_angles(RING_SEGMENTS),
        &[rib_c - foot, rib_c - half, rib_c + half, rib_c + foot]
            .into_iter()
            .chain(rectangle_corners(d.base_side, d.base_side))
            .collect::<Vec<_>>(),
    );
    let rib = |t: f64| -> f64 {
        let delta = ((t - rib_c + PI).rem_euclid(TAU) - PI).abs();
        if delta <= half + 1e-12 {
            d.rib_height
        } else if delta < foot {
            d.rib_height * (foot - delta) / (foot - half)
        } else {
            0.0
        }
    };
    let round = |z: f64, radius: f64| Ring {
        z,
        radii: angles.iter().map(|&t| radius + rib(t)).collect(),
    };
    let square = |z: f64| Ring {
        z,
        radii: angles
            .iter()
            .map(|&t| rectangle_radius(d.base_side, d.base_side, t))
            .collect(),
    };
    radial_solid(
        &angles,
        &[
            square(0.0),
            square(d.base_top),
            round(d.base_top, d.taper_bottom_diameter / 2.0),
            round(d.ridge_z.0, d.taper_top_diameter / 2.0),
            round(d.ridge_z.0, d.ridge_diameter / 2.0),
            round(d.ridge_z.1, d.ridge_diameter / 2.0),
            round(d.ridge_z.1, d.upper_diameter / 2.0),
            round(d.height, d.upper_diameter / 2.0),
        ],
    )
}

/// A tube (a cylinder with a coaxial through-hole) standing on Z = 0 `[mm]`.
pub fn tube(inner_diameter: f64, outer_diameter: f64, height: f64, n: usize) -> Mesh {
    let (ri, ro) = (inner_diameter / 2.0, outer_diameter / 2.0);
    let at = |r: f64, k: usize, z: f64| {
        let t = TAU * (k % n) as f64 / n as f64;
        Point3::new(r * t.cos(), r * t.sin(), z)
    };
    let mut soup = Vec::new();
    for k in 0..n {
        let k1 = k + 1;
        // Outer wall, outward.
        soup.push([at(ro, k, 0.0), at(ro, k1, 0.0), at(ro, k1, height)]);
        soup.push([at(ro, k, 0.0), at(ro, k1, height), at(ro, k, height)]);
        // Inner wall, facing the axis.
        soup.push([at(ri, k, 0.0), at(ri, k1, height), at(ri, k1, 0.0)]);
        soup.push([at(ri, k, 0.0), at(ri, k, height), at(ri, k1, height)]);
        // Top annulus (+Z) and bottom annulus (−Z).
        soup.push([at(ri, k, height), at(ro, k, height), at(ro, k1, height)]);
        soup.push([at(ri, k, height), at(ro, k1, height), at(ri, k1, height)]);
        soup.push([at(ri, k, 0.0), at(ro, k1, 0.0), at(ro, k, 0.0)]);
        soup.push([at(ri, k, 0.0), at(ri, k1, 0.0), at(ro, k1, 0.0)]);
    }
    Mesh::from_triangles(&soup).0
}

/// A square pyramid with base side `a` on Z = 0 and apex at height `h` (thesis Fig. 3.3).
pub fn pyramid(a: f64, h: f64) -> Mesh {
    let s = a / 2.0;
    let b = [
        Point3::new(s, s, 0.0),
        Point3::new(-s, s, 0.0),
        Point3::new(-s, -s, 0.0),
        Point3::new(s, -s, 0.0),
    ];
    let apex = Point3::new(0.0, 0.0, h);
    let mut soup = vec![[b[0], b[2], b[1]], [b[0], b[3], b[2]]];
    for k in 0..4 {
        soup.push([b[k], b[(k + 1) % 4], apex]);
    }
    Mesh::from_triangles(&soup).0
}

/// The thesis objects by their asset names, as written by `grasp-sim gen-assets`.
pub fn thesis_objects() -> Vec<(&'static str, Mesh)> {
    vec![
        // Widest side along X, as grasp-sim's alignment puts it (see mesh::align).
        ("prism", prism(30.0, 15.0, 124.0)),
        ("cylinder_d10", cylinder(10.0, 124.0)),
        ("cylinder_d40", cylinder(40.0, 124.0)),
        ("cylinder_d60", cylinder(60.0, 124.0)),
        ("cup", frustum(56.0, 80.0, 110.0)),
        ("cup_inverted", frustum(80.0, 56.0, 110.0)),
        ("chapter4", chapter4(&Chapter4Dims::default())),
    ]
}

/// A solid of revolution through `(z, diameter)` profile points, bottom to top `[mm]`
/// (consecutive points at one height make a horizontal step).
pub fn revolved(profile: &[(f64, f64)]) -> Mesh {
    let angles = uniform_angles(RING_SEGMENTS);
    let rings: Vec<Ring> = profile
        .iter()
        .map(|&(z, d)| Ring {
            z,
            radii: vec![d / 2.0; angles.len()],
        })
        .collect();
    radial_solid(&angles, &rings)
}

/// A smooth bulge: `(z, diameter)` samples of `d0 + (d1 − d0)·sin(π·t)` over `[z0, z1]`.
fn bulge(z0: f64, z1: f64, d0: f64, d1: f64, n: usize) -> Vec<(f64, f64)> {
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            (z0 + t * (z1 - z0), d0 + (d1 - d0) * (PI * t).sin())
        })
        .collect()
}

/// The tuning set (issue 6): objects that separate planner settings — necks and shoulders,
/// bulges, tapers both ways, ridges and grooves, knobs, and sizes near both ends of the thesis
/// hand's graspable range (17.4–117.4 mm). Written by `grasp-sim gen-assets` into
/// `assets/objects/train/`, each with a scenario.
pub fn training_objects() -> Vec<(&'static str, Mesh)> {
    let mut vase = vec![(0.0, 50.0)];
    vase.extend(bulge(0.0, 130.0, 50.0, 80.0, 16).into_iter().skip(1));
    vase.push((150.0, 56.0));
    let box_angles = with_angles(
        uniform_angles(RING_SEGMENTS),
        &rectangle_corners(40.0, 40.0),
    );
    let square = |z: f64, side: f64| Ring {
        z,
        radii: box_angles
            .iter()
            .map(|&t| rectangle_radius(side, side, t))
            .collect(),
    };
    vec![
        (
            "bottle",
            revolved(&[
                (0.0, 60.0),
                (115.0, 60.0),
                (135.0, 30.0),
                (145.0, 26.0),
                (180.0, 26.0),
            ]),
        ),
        ("vase", revolved(&vase)),
        (
            "tapered_box",
            radial_solid(&box_angles, &[square(0.0, 40.0), square(120.0, 60.0)]),
        ),
        (
            "ridged_cylinder",
            revolved(&[
                (0.0, 45.0),
                (40.0, 45.0),
                (40.0, 55.0),
                (44.0, 55.0),
                (44.0, 45.0),
                (80.0, 45.0),
                (80.0, 55.0),
                (84.0, 55.0),
                (84.0, 45.0),
                (140.0, 45.0),
            ]),
        ),
        (
            "grooved_cylinder",
            revolved(&[
                (0.0, 50.0),
                (50.0, 50.0),
                (50.0, 42.0),
                (56.0, 42.0),
                (56.0, 50.0),
                (90.0, 50.0),
                (90.0, 42.0),
                (96.0, 42.0),
                (96.0, 50.0),
                (140.0, 50.0),
            ]),
        ),
        (
            "knob",
            revolved(&[
                (0.0, 20.0),
                (60.0, 20.0),
                (60.0, 44.0),
                (100.0, 50.0),
                (120.0, 40.0),
            ]),
        ),
        ("thin_rod", cylinder(19.0, 120.0)),
        ("wide_drum", cylinder(110.0, 100.0)),
    ]
}

/// A torus about Z, its tube's centre line `big` from the axis and its tube `small` in radius
/// `[mm]`, `around` segments about the axis and `across` about the tube (closed, manifold): a
/// ring, which the planner searches on arcs of its tube first ([`crate::mesh::ring`]).
pub fn torus(big: f64, small: f64, around: u32, across: u32) -> Mesh {
    let (n, m) = (around.max(3), across.max(3));
    let mut vertices = Vec::new();
    for i in 0..n {
        let a = f64::from(i) / f64::from(n) * std::f64::consts::TAU;
        for j in 0..m {
            let b = f64::from(j) / f64::from(m) * std::f64::consts::TAU;
            let r = big + small * b.cos();
            vertices.push(Point3::new(r * a.cos(), r * a.sin(), small * b.sin()));
        }
    }
    let v = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    Mesh {
        vertices,
        triangles,
    }
}
