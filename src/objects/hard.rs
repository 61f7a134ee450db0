//! Hard meshes for the planner's time and scale (issue 30): relief a finger cannot feel, many
//! overlapping shells, non-manifold edges, square sections, scan-sized triangle counts, and
//! objects too big for the hand. Every one is generated here, deterministically (the same bytes
//! every time: no randomness but a fixed integer hash), in millimetres, in no particular
//! alignment (the planner aligns them).
//!
//! `grasp-sim gen-assets --hard DIR` writes them as binary STL (not committed: the largest is
//! 12 MB); `scripts/plan_bench.py` plans them.

use crate::mesh::Mesh;
use nalgebra::{Point3, Vector3};
use std::f64::consts::TAU;

use super::{radial_solid, rectangle_radius, uniform_angles, Ring};

/// A triangle soup.
type Soup = Vec<[Point3<f64>; 3]>;

/// A deterministic value in [−1, 1] for the integer pair `(a, b)` (splitmix64).
fn hash_unit(a: u64, b: u64) -> f64 {
    let mut z = a
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(b.wrapping_mul(0xBF58_476D_1CE4_E5B9))
        .wrapping_add(0x94D0_49BB_1331_11EB);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// The soup of a mesh.
fn soup_of(mesh: &Mesh) -> Soup {
    (0..mesh.triangles.len()).map(|t| mesh.corners(t)).collect()
}

/// A box with centre `c` and half-extent vectors `ax`, `ay`, `az` (mutually orthogonal),
/// wound outward.
fn oriented_box(c: Point3<f64>, ax: Vector3<f64>, ay: Vector3<f64>, az: Vector3<f64>) -> Soup {
    let corner = |i: i32, j: i32, k: i32| c + ax * i as f64 + ay * j as f64 + az * k as f64;
    let mut soup = Vec::new();
    // Each face: its outward direction and four corners in order round it.
    type Face = (Vector3<f64>, [(i32, i32, i32); 4]);
    let faces: [Face; 6] = [
        (ax, [(1, -1, -1), (1, 1, -1), (1, 1, 1), (1, -1, 1)]),
        (-ax, [(-1, -1, -1), (-1, -1, 1), (-1, 1, 1), (-1, 1, -1)]),
        (ay, [(-1, 1, -1), (-1, 1, 1), (1, 1, 1), (1, 1, -1)]),
        (-ay, [(-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1)]),
        (az, [(-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]),
        (-az, [(-1, -1, -1), (-1, 1, -1), (1, 1, -1), (1, -1, -1)]),
    ];
    for (out, q) in faces {
        let p = q.map(|(i, j, k)| corner(i, j, k));
        let (a, b, cc, d) = (p[0], p[1], p[2], p[3]);
        if (b - a).cross(&(cc - a)).dot(&out) > 0.0 {
            soup.push([a, b, cc]);
            soup.push([a, cc, d]);
        } else {
            soup.push([a, cc, b]);
            soup.push([a, d, cc]);
        }
    }
    soup
}

/// An axis-aligned box from `lo` to `hi`.
fn cuboid(lo: Point3<f64>, hi: Point3<f64>) -> Soup {
    let c = nalgebra::center(&lo, &hi);
    let h = (hi - lo) / 2.0;
    oriented_box(
        c,
        Vector3::x() * h.x,
        Vector3::y() * h.y,
        Vector3::z() * h.z,
    )
}

/// A helical spur gear: `teeth` teeth `depth` deep on a disc of outer diameter `d` and
/// thickness `t`, the teeth turning `helix_deg` over the thickness; `per_tooth` angular samples
/// per tooth and `layers` layers through the thickness.
pub fn helical_gear(
    d: f64,
    t: f64,
    teeth: usize,
    depth: f64,
    helix_deg: f64,
    per_tooth: usize,
    layers: usize,
) -> Mesh {
    let angles = uniform_angles(teeth * per_tooth);
    let r_out = d / 2.0;
    let rings: Vec<Ring> = (0..=layers)
        .map(|j| {
            let z = t * j as f64 / layers as f64;
            let twist = helix_deg.to_radians() * z / t;
            Ring {
                z,
                radii: angles
                    .iter()
                    .map(|&a| {
                        // A trapezoidal tooth: flank, land, flank, root, a quarter each.
                        let phase = ((a - twist) * teeth as f64 / TAU).rem_euclid(1.0);
                        let lift = match phase {
                            p if p < 0.25 => p / 0.25,
                            p if p < 0.5 => 1.0,
                            p if p < 0.75 => 1.0 - (phase - 0.5) / 0.25,
                            _ => 0.0,
                        };
                        r_out - depth * (1.0 - lift)
                    })
                    .collect(),
            }
        })
        .collect();
    radial_solid(&angles, &rings)
}

/// A thin-walled cylindrical cage `d` across and `h` high: `bars` vertical bars `wall` thick
/// and `rings` horizontal hoops, each a closed box or tube overlapping its neighbours (many
/// shells, as a cage modelled in parts is shipped).
pub fn cage(d: f64, h: f64, bars: usize, rings: usize, wall: f64) -> Mesh {
    let mut soup = Vec::new();
    let r = d / 2.0 - wall / 2.0;
    for k in 0..bars {
        let a = TAU * k as f64 / bars as f64;
        let (s, c) = a.sin_cos();
        let radial = Vector3::new(c, s, 0.0);
        let tangent = Vector3::new(-s, c, 0.0);
        soup.extend(oriented_box(
            Point3::new(r * c, r * s, h / 2.0),
            radial * (wall / 2.0),
            tangent * (wall / 2.0 + 0.4),
            Vector3::z() * (h / 2.0),
        ));
    }
    for j in 0..rings {
        let z0 = (h - wall) * j as f64 / (rings - 1).max(1) as f64;
        let mut hoop = super::tube(d - 2.0 * wall, d, wall, 96);
        hoop.map_vertices(|p| Point3::new(p.x, p.y, p.z + z0));
        soup.extend(soup_of(&hoop));
    }
    // A floor, so the cage is a basket.
    soup.extend(soup_of(&super::cylinder(d - wall, wall)));
    Mesh::from_triangles(&soup).0
}

/// A toy brick `a × b × h` with `nx × ny` studs (diameter 4.8 mm, 1.7 mm tall) standing on its
/// top face as separate shells, and a zero-thickness fin along one bottom edge that makes that
/// edge and the fin's own edges non-manifold (as a raw scan or a careless export has them).
pub fn studded_brick(a: f64, b: f64, h: f64, nx: usize, ny: usize) -> Mesh {
    let mut soup = cuboid(Point3::new(0.0, 0.0, 0.0), Point3::new(a, b, h));
    let (px, py) = (a / nx as f64, b / ny as f64);
    for i in 0..nx {
        for j in 0..ny {
            let mut stud = super::cylinder(4.8, 1.7);
            let (cx, cy) = (px * (i as f64 + 0.5), py * (j as f64 + 0.5));
            stud.map_vertices(|p| Point3::new(p.x + cx, p.y + cy, p.z + h));
            soup.extend(soup_of(&stud));
        }
    }
    // The fin: two triangles back to back on the edge y = 0, z = 0 of the box, hanging below.
    let (e0, e1) = (Point3::new(0.0, 0.0, 0.0), Point3::new(a, 0.0, 0.0));
    let tip = Point3::new(a / 2.0, 0.0, -1.5);
    soup.push([e0, e1, tip]);
    soup.push([e1, e0, tip]);
    Mesh::from_triangles(&soup).0
}

/// A square bar `side × side × length`, lying along X (as a file may have it), each face
/// divided into `cells × cells` quads.
pub fn square_bar(side: f64, length: f64, cells: usize) -> Mesh {
    let mut soup = Vec::new();
    let n = cells.max(1);
    let (hs, hl) = (side / 2.0, length / 2.0);
    // Six faces of the box [−hl, hl] × [−hs, hs]²: origin corner, two edge vectors (their cross
    // product points out).
    let faces = [
        (
            Point3::new(hl, -hs, -hs),
            Vector3::new(0.0, side, 0.0),
            Vector3::new(0.0, 0.0, side),
        ),
        (
            Point3::new(-hl, -hs, -hs),
            Vector3::new(0.0, 0.0, side),
            Vector3::new(0.0, side, 0.0),
        ),
        (
            Point3::new(-hl, hs, -hs),
            Vector3::new(0.0, 0.0, side),
            Vector3::new(length, 0.0, 0.0),
        ),
        (
            Point3::new(-hl, -hs, -hs),
            Vector3::new(length, 0.0, 0.0),
            Vector3::new(0.0, 0.0, side),
        ),
        (
            Point3::new(-hl, -hs, hs),
            Vector3::new(length, 0.0, 0.0),
            Vector3::new(0.0, side, 0.0),
        ),
        (
            Point3::new(-hl, -hs, -hs),
            Vector3::new(0.0, side, 0.0),
            Vector3::new(length, 0.0, 0.0),
        ),
    ];
    for (o, u, v) in faces {
        let p = |i: usize, j: usize| o + u * (i as f64 / n as f64) + v * (j as f64 / n as f64);
        for i in 0..n {
            for j in 0..n {
                soup.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                soup.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
    }
    Mesh::from_triangles(&soup).0
}

/// A scan-like solid of revolution: a bottle's profile sampled on `around × up` vertices with a
/// deterministic surface noise of `noise_mm` (a scanner's), `around × up × 2` triangles.
pub fn scan_bottle(around: usize, up: usize, noise_mm: f64) -> Mesh {
    let angles = uniform_angles(around);
    let profile = |z: f64| -> f64 {
        // Body 66 mm across up to 120 mm, shoulder to a 28 mm neck at 150, neck to 190.
        match z {
            z if z < 120.0 => 33.0,
            z if z < 150.0 => {
                let s = (z - 120.0) / 30.0;
                33.0 - 19.0 * (0.5 - 0.5 * (std::f64::consts::PI * s).cos())
            }
            _ => 14.0,
        }
    };
    let rings: Vec<Ring> = (0..up)
        .map(|j| {
            let z = 190.0 * j as f64 / (up - 1) as f64;
            Ring {
                z,
                radii: (0..around)
                    .map(|k| profile(z) + noise_mm * hash_unit(j as u64, k as u64))
                    .collect(),
            }
        })
        .collect();
    radial_solid(&angles, &rings)
}

/// A scan-like box `a × b × h` (a cereal box as a scanner sees it): `around × up` samples of
/// its rectangular section with surface noise `noise_mm`.
pub fn scan_box(a: f64, b: f64, h: f64, around: usize, up: usize, noise_mm: f64) -> Mesh {
    let angles = uniform_angles(around);
    let rings: Vec<Ring> = (0..up)
        .map(|j| Ring {
            z: h * j as f64 / (up - 1) as f64,
            radii: angles
                .iter()
                .enumerate()
                .map(|(k, &t)| {
                    rectangle_radius(a, b, t) + noise_mm * hash_unit(1000 + j as u64, k as u64)
                })
                .collect(),
        })
        .collect();
    radial_solid(&angles, &rings)
}

/// A ring gear: an annulus of outer diameter `d_out` with `teeth` internal trapezoidal teeth
/// `depth` deep on a root diameter `d_root`, `t` thick, `per_tooth` samples per tooth and
/// `layers` layers (closed and manifold).
pub fn ring_gear(
    d_out: f64,
    d_root: f64,
    t: f64,
    teeth: usize,
    depth: f64,
    per_tooth: usize,
    layers: usize,
) -> Mesh {
    let n = teeth * per_tooth;
    let inner = |k: usize| {
        let phase = (k % per_tooth) as f64 / per_tooth as f64;
        let lift = match phase {
            p if p < 0.25 => p / 0.25,
            p if p < 0.5 => 1.0,
            p if p < 0.75 => 1.0 - (p - 0.5) / 0.25,
            _ => 0.0,
        };
        d_root / 2.0 - depth * lift
    };
    let at = |r: f64, k: usize, z: f64| {
        let a = TAU * (k % n) as f64 / n as f64;
        Point3::new(r * a.cos(), r * a.sin(), z)
    };
    let ro = d_out / 2.0;
    let mut soup = Vec::new();
    let zs: Vec<f64> = (0..=layers).map(|j| t * j as f64 / layers as f64).collect();
    for k in 0..n {
        let k1 = k + 1;
        let (ri, ri1) = (inner(k), inner(k1 % n));
        for w in zs.windows(2) {
            let (z0, z1) = (w[0], w[1]);
            soup.push([at(ro, k, z0), at(ro, k1, z0), at(ro, k1, z1)]);
            soup.push([at(ro, k, z0), at(ro, k1, z1), at(ro, k, z1)]);
            // The inner wall, facing the axis.
            soup.push([at(ri, k, z0), at(ri1, k1, z1), at(ri1, k1, z0)]);
            soup.push([at(ri, k, z0), at(ri, k, z1), at(ri1, k1, z1)]);
        }
        soup.push([at(ri, k, t), at(ro, k, t), at(ro, k1, t)]);
        soup.push([at(ri, k, t), at(ro, k1, t), at(ri1, k1, t)]);
        soup.push([at(ri, k, 0.0), at(ro, k1, 0.0), at(ro, k, 0.0)]);
        soup.push([at(ri, k, 0.0), at(ri1, k1, 0.0), at(ro, k1, 0.0)]);
    }
    Mesh::from_triangles(&soup).0
}

/// A lattice plate: `nx` bars along X and `ny` along Y, `bar` wide and `t` thick, overlapping
/// where they cross (`nx + ny` shells), a perforated plate `a × b` in effect.
pub fn lattice_plate(a: f64, b: f64, t: f64, nx: usize, ny: usize, bar: f64) -> Mesh {
    let mut soup = Vec::new();
    for i in 0..nx {
        let y = (b - bar) * i as f64 / (nx - 1).max(1) as f64;
        soup.extend(cuboid(Point3::new(0.0, y, 0.0), Point3::new(a, y + bar, t)));
    }
    for j in 0..ny {
        let x = (a - bar) * j as f64 / (ny - 1).max(1) as f64;
        soup.extend(cuboid(
            Point3::new(x, 0.0, 0.0),
            Point3::new(x + bar, b, t + 0.5),
        ));
    }
    Mesh::from_triangles(&soup).0
}

/// The hard set, by file name: what each is for is in its generator's docs.
pub fn hard_objects() -> Vec<(&'static str, Mesh)> {
    vec![
        // 50 mm across, 24 mm thick, 40 teeth 1.5 mm deep turning 20°: 43k triangles.
        (
            "helical_gear_50",
            helical_gear(50.0, 24.0, 40, 1.5, 20.0, 18, 30),
        ),
        // 46 mm across, 60 high, 24 bars and 4 hoops 1.5 mm thick, a floor.
        ("cage_46", cage(46.0, 60.0, 24, 4, 1.5)),
        // A 3 × 4 toy brick, 32 × 24 × 19.2 mm, studs as shells, a non-manifold fin.
        ("studded_brick_32", studded_brick(32.0, 24.0, 19.2, 4, 3)),
        ("square_bar_20", square_bar(20.0, 150.0, 1)),
        ("square_bar_29", square_bar(29.0, 150.0, 1)),
        // The 29 mm bar with finely divided faces (40k triangles), as a remeshed CAD part has them.
        ("square_bar_29_fine", square_bar(29.0, 150.0, 58)),
        ("square_bar_35", square_bar(35.0, 150.0, 1)),
        // 600 × 100 samples: 120k triangles.
        ("scan_bottle_120k", scan_bottle(600, 100, 0.15)),
        // 1000 × 125 samples: 250k triangles.
        (
            "scan_box_250k",
            scan_box(100.0, 60.0, 150.0, 1000, 125, 0.15),
        ),
        // 106 mm across, 14 mm thick, 72 internal teeth: 58k triangles.
        (
            "ring_gear_106",
            ring_gear(106.0, 92.0, 14.0, 72, 2.0, 20, 8),
        ),
        // 150 mm across: far beyond the hand's largest grasp (117.4 mm).
        ("ring_150", ring_gear(150.0, 130.0, 15.0, 90, 1.0, 8, 2)),
        // 120 × 80 × 3 mm, 12 + 16 overlapping bars.
        (
            "lattice_plate",
            lattice_plate(120.0, 80.0, 3.0, 12, 16, 2.0),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hard_set_is_what_its_docs_say() {
        let set = hard_objects();
        let by = |n: &str| &set.iter().find(|(m, _)| *m == n).unwrap().1;
        let tris = |n: &str| by(n).triangles.len();
        let extent = |n: &str| {
            let (lo, hi) = by(n).bounds();
            hi - lo
        };
        assert!(
            tris("scan_bottle_120k") >= 100_000,
            "{}",
            tris("scan_bottle_120k")
        );
        let big = tris("scan_box_250k");
        assert!((200_000..=250_000).contains(&big), "{big}");
        let g = extent("helical_gear_50");
        assert!((g.x - 50.0).abs() < 0.5 && (g.z - 24.0).abs() < 1e-9, "{g}");
        assert!(tris("helical_gear_50") >= 20_000);
        assert!(tris("ring_gear_106") >= 20_000);
        for n in [
            "ring_gear_106",
            "ring_150",
            "helical_gear_50",
            "scan_box_250k",
        ] {
            assert!(by(n).topology().is_closed_manifold(), "{n}");
        }
        assert!(by("studded_brick_32").topology().non_manifold_edges > 0);
        for n in ["cage_46", "studded_brick_32", "lattice_plate"] {
            assert!(by(n).shell_count() > 1, "{n}");
        }
        let bar = extent("square_bar_29");
        assert_eq!([bar.x, bar.y, bar.z], [150.0, 29.0, 29.0]);
        // Deterministic: generated twice, the same bytes.
        assert_eq!(
            by("scan_bottle_120k").to_binary_stl(),
            hard_objects()[7].1.to_binary_stl()
        );
    }
}
