//! Slicing, mass properties and alignment against analytic values.

use grasp_sim::mesh::{align, load_stl, mass_properties, parse_stl, LengthUnit, Mesh};
use grasp_sim::objects;
use grasp_sim::slice::{slice, Plane, SliceOptions};
use nalgebra::{Point3, Rotation3, Unit, Vector3};
use std::f64::consts::PI;
use std::path::Path;

fn rel_err(measured: f64, expected: f64) -> f64 {
    ((measured - expected) / expected).abs()
}

#[test]
fn sphere_slice_through_centre_is_one_circle_of_radius_r() {
    let r = 50.0;
    let n = 64;
    let sphere = objects::uv_sphere(r, n);
    // Tessellation error: a chord of the finest ring spans 2π/n; points on edges lie at most
    // r(1 − cos(π/n)) inside the sphere along rings and meridians, about twice that along quad
    // diagonals; never outside.
    let tol = r * (1.0 - (PI / n as f64).cos()) * 3.0;
    for plane in [
        Plane::horizontal(0.0),
        Plane::vertical(0.3),
        Plane::vertical(0.0),
    ] {
        let s = slice(&sphere, &plane, SliceOptions::default());
        assert_eq!(
            s.contours.len(),
            1,
            "one contour expected, got {}",
            s.contours.len()
        );
        let c = &s.contours[0];
        assert!(c.is_closed);
        assert_eq!(s.outermost, Some(0));
        for p in &c.points {
            let d = p.coords.norm();
            assert!(
                d <= r + 1e-9 && d >= r - tol,
                "point at radius {d}, expected {r} within {tol}"
            );
        }
        // Outward normals point away from the centre.
        for i in 0..c.segment_count() {
            let (a, b) = c.segment(i);
            let mid = nalgebra::center(&a, &b);
            assert!(
                c.normals[i].dot(&mid.coords) > 0.0,
                "normal {i} points inwards"
            );
        }
        let area = c.signed_area();
        assert!(
            rel_err(area, PI * r * r) < 0.01,
            "area {area}, expected ~{}",
            PI * r * r
        );
    }
}

#[test]
fn cylinder_slice_has_the_right_diameter_at_any_height() {
    let cyl = objects::cylinder(40.0, 124.0);
    for z in [0.5, 7.0, 33.3, 62.0, 112.0, 123.9] {
        let s = slice(&cyl, &Plane::horizontal(z), SliceOptions::default());
        assert_eq!(s.contours.len(), 1);
        let c = &s.contours[0];
        let (min, max) = c.points.iter().fold((f64::MAX, 0.0f64), |(lo, hi), p| {
            let d = p.coords.norm();
            (lo.min(d), hi.max(d))
        });
        assert!((max - 20.0).abs() < 1e-9, "max radius {max} at z = {z}");
        assert!(
            min > 20.0 * (PI / 144.0).cos() - 1e-9,
            "min radius {min} at z = {z}"
        );
    }
    // A vertical slice is the 40 × 124 rectangle.
    let s = slice(
        &cyl,
        &Plane::vertical(10f64.to_radians()),
        SliceOptions::default(),
    );
    assert_eq!(s.contours.len(), 1);
    let c = &s.contours[0];
    let xs: Vec<f64> = c.points.iter().map(|p| p.x).collect();
    let zs: Vec<f64> = c.points.iter().map(|p| p.y).collect();
    let span = |v: &[f64]| {
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    assert!((span(&xs) - 40.0).abs() < 1e-9, "width {}", span(&xs));
    assert!((span(&zs) - 124.0).abs() < 1e-9, "height {}", span(&zs));
    assert!((c.signed_area() - 40.0 * 124.0).abs() < 1e-6);
}

#[test]
fn pyramid_slices_match_fig_3_3() {
    let (a, h) = (60.0, 90.0);
    let pyr = objects::pyramid(a, h);
    // (b) vertical slice through the apex, parallel to a base edge: the triangle
    // (−a/2, 0), (a/2, 0), (0, h).
    let s = slice(&pyr, &Plane::vertical(0.0), SliceOptions::default());
    assert_eq!(s.contours.len(), 1);
    let c = &s.contours[0];
    assert!(
        (c.signed_area() - 0.5 * a * h).abs() < 1e-9,
        "area {}",
        c.signed_area()
    );
    let expected = [[-a / 2.0, 0.0], [a / 2.0, 0.0], [0.0, h]];
    for e in expected {
        assert!(
            c.points
                .iter()
                .any(|p| (p.x - e[0]).abs() < 1e-9 && (p.y - e[1]).abs() < 1e-9),
            "vertex {e:?} missing from {:?}",
            c.points
        );
    }
    // The left side slopes outwards-up with normal (-h, a/2)/|.|, the right side mirrored.
    let slope = (a / 2.0).atan2(h);
    for (i, n) in c.normals.iter().enumerate() {
        let (p, q) = c.segment(i);
        let mid = nalgebra::center(&p, &q);
        if mid.y.abs() < 1e-9 {
            assert!((n.y + 1.0).abs() < 1e-9, "base normal {n:?}");
        } else {
            assert!(
                (n.y - slope.sin()).abs() < 1e-9 && (n.x.abs() - slope.cos()).abs() < 1e-9,
                "side normal {n:?}"
            );
            assert_eq!(n.x.signum(), mid.x.signum());
        }
    }
    // (d) horizontal slice at height z: a square of side a(1 − z/h).
    for z in [10.0, 45.0, 80.0] {
        let s = slice(&pyr, &Plane::horizontal(z), SliceOptions::default());
        assert_eq!(s.contours.len(), 1);
        let side = a * (1.0 - z / h);
        let area = s.contours[0].signed_area();
        assert!(
            (area - side * side).abs() < 1e-9,
            "z = {z}: area {area}, expected {}",
            side * side
        );
    }
}

#[test]
fn a_through_hole_gives_two_contours_with_the_outer_marked() {
    let tube = objects::tube(20.0, 50.0, 40.0, 48);
    let s = slice(&tube, &Plane::horizontal(13.0), SliceOptions::default());
    assert_eq!(s.contours.len(), 2);
    let outer = s.outermost.expect("an outermost contour");
    let hole = 1 - outer;
    assert!(!s.contours[outer].is_hole());
    assert!(s.contours[hole].is_hole());
    assert!(s.contours[outer].signed_area() > 0.0 && s.contours[hole].signed_area() < 0.0);
    // Hole normals point towards the axis (out of the material, into the hole).
    let c = &s.contours[hole];
    for i in 0..c.segment_count() {
        let (a, b) = c.segment(i);
        assert!(c.normals[i].dot(&nalgebra::center(&a, &b).coords) < 0.0);
    }
    // A vertical slice through the axis cuts the wall twice: two separate parts, no hole.
    let s = slice(&tube, &Plane::vertical(0.0), SliceOptions::default());
    assert_eq!(s.contours.len(), 2);
    assert!(s.contours.iter().all(|c| c.is_closed && !c.is_hole()));
    for c in &s.contours {
        assert!(
            (c.signed_area() - 15.0 * 40.0).abs() < 1e-6,
            "wall area {}",
            c.signed_area()
        );
    }
}

#[test]
fn planes_through_vertices_edges_and_faces_still_chain() {
    // The prism has vertices every 2.5°: vertical slices at multiples of 2.5° run through vertex
    // columns, and horizontal planes at 0 and 124 lie in its caps.
    let prism = objects::prism(15.0, 30.0, 124.0);
    for deg in [0.0, 2.5, 10.0, 45.0, 63.43494882, 90.0, 137.5] {
        let s = slice(
            &prism,
            &Plane::vertical(f64::to_radians(deg)),
            SliceOptions::default(),
        );
        assert_eq!(s.contours.len(), 1, "angle {deg}");
        assert!(s.contours[0].is_closed, "angle {deg}");
        assert!(s.contours[0]
            .points
            .windows(2)
            .all(|w| (w[1] - w[0]).norm() > 1e-9));
    }
    // A plane lying in a cap, to within ON_PLANE_MM either way (the round-off of a file
    // written in another frame), is taken just below it: in the top cap it gives the whole
    // outline, in the bottom cap nothing (as just below the object). Beyond that, nothing above
    // the top and the whole outline above the bottom.
    let tie = grasp_sim::slice::ON_PLANE_MM;
    for dz in [0.0, 1e-9, -1e-9, 0.5 * tie, -0.5 * tie] {
        let s = slice(
            &prism,
            &Plane::horizontal(124.0 + dz),
            SliceOptions::default(),
        );
        assert_eq!(s.contours.len(), 1, "{dz}");
        assert!(
            (s.contours[0].signed_area() - 15.0 * 30.0).abs() < 1e-9,
            "{dz}"
        );
        let s = slice(&prism, &Plane::horizontal(dz), SliceOptions::default());
        assert!(s.is_empty(), "{dz}");
    }
    let above = Plane::horizontal(124.0 + 2.0 * tie);
    assert!(slice(&prism, &above, SliceOptions::default()).is_empty());
    let s = slice(
        &prism,
        &Plane::horizontal(2.0 * tie),
        SliceOptions::default(),
    );
    assert_eq!(s.contours.len(), 1);
    assert!((s.contours[0].signed_area() - 15.0 * 30.0).abs() < 1e-6);
}

#[test]
fn tilted_finger_plane_cuts_an_ellipse() {
    let cyl = objects::cylinder(40.0, 124.0);
    let pitch = 20f64.to_radians();
    let plane = Plane::finger(Point3::new(0.0, 0.0, 60.0), pitch);
    let s = slice(&cyl, &plane, SliceOptions::default());
    assert_eq!(s.contours.len(), 1);
    // A cylinder cut at an angle: an ellipse with semi-axes r / cos(pitch) and r.
    let expected = PI * 20.0 * 20.0 / pitch.cos();
    let area = s.contours[0].signed_area();
    assert!(
        rel_err(area, expected) < 0.001,
        "area {area}, expected {expected}"
    );
}

#[test]
fn box_and_cylinder_mass_properties_match_analytic_values() {
    let (a, b, h) = (15.0, 30.0, 124.0);
    let m = mass_properties(&objects::prism(a, b, h));
    let v = a * b * h;
    assert!(
        rel_err(m.volume_mm3, v) < 1e-12,
        "box volume {}, expected {v}",
        m.volume_mm3
    );
    let expected = [
        v * (b * b + h * h) / 12.0,
        v * (a * a + h * h) / 12.0,
        v * (a * a + b * b) / 12.0,
    ];
    for (i, e) in expected.iter().enumerate() {
        let got = m.inertia[(i, i)];
        assert!(rel_err(got, *e) < 1e-9, "box I[{i}] {got}, expected {e}");
    }
    assert!((m.centroid - Point3::new(0.0, 0.0, h / 2.0)).norm() < 1e-9);
    assert!(m.inertia[(0, 1)].abs() < 1e-6 * expected[0]);

    let (d, h) = (40.0, 124.0);
    let r = d / 2.0;
    let m = mass_properties(&objects::cylinder(d, h));
    let v = PI * r * r * h;
    assert!(
        rel_err(m.volume_mm3, v) < 0.005,
        "cylinder volume {}, expected {v}",
        m.volume_mm3
    );
    let ixx = v * (3.0 * r * r + h * h) / 12.0;
    let izz = v * r * r / 2.0;
    for (i, e) in [ixx, ixx, izz].iter().enumerate() {
        let got = m.inertia[(i, i)];
        assert!(
            rel_err(got, *e) < 0.005,
            "cylinder I[{i}] {got}, expected {e}"
        );
    }
}

fn rotated(mesh: &Mesh, rot: &Rotation3<f64>, shift: Vector3<f64>) -> Mesh {
    let mut m = mesh.clone();
    m.map_vertices(|p| rot * p + shift);
    m
}

#[test]
fn a_rotated_shifted_cylinder_is_aligned_back() {
    let base = objects::cylinder(40.0, 124.0);
    let axis = Unit::new_normalize(Vector3::new(0.3, -0.8, 0.52));
    let rot = Rotation3::from_axis_angle(&axis, 1.1);
    let moved = rotated(&base, &rot, Vector3::new(123.0, -45.5, 300.25));
    let aligned = align(&moved);
    let expected_axis = rot * Vector3::z();
    let got = aligned.principal_axis_original();
    let angle = got.dot(&expected_axis).abs().min(1.0).acos().to_degrees();
    assert!(
        angle < 0.1,
        "principal axis off by {angle} degrees: {got:?} vs ±{expected_axis:?}"
    );
    // Aligned: the axis is Z, bottom at 0, centroid on the axis.
    let (lo, hi) = aligned.mesh.bounds();
    assert!(
        lo.z.abs() < 1e-6 && (hi.z - 124.0).abs() < 1e-6,
        "z range {} .. {}",
        lo.z,
        hi.z
    );
    let c = mass_properties(&aligned.mesh).centroid;
    assert!(c.x.abs() < 1e-6 && c.y.abs() < 1e-6, "centroid {c:?}");
    // Slices after alignment equal the unrotated cylinder's (within rounding and the 0.005 mm
    // chord error: a cylinder's slices do not depend on its turn about its axis).
    for z in [7.0, 62.0, 117.0] {
        let a = slice(
            &aligned.mesh,
            &Plane::horizontal(z),
            SliceOptions::default(),
        );
        let b = slice(&base, &Plane::horizontal(z), SliceOptions::default());
        assert_eq!(a.contours.len(), 1);
        let (aa, ba) = (a.contours[0].signed_area(), b.contours[0].signed_area());
        assert!(rel_err(aa, ba) < 1e-6, "area {aa} vs {ba} at z = {z}");
        for p in &a.contours[0].points {
            let r = p.coords.norm();
            assert!(
                r <= 20.0 + 1e-6 && r >= 20.0 * (PI / 144.0).cos() - 1e-6,
                "radius {r}"
            );
        }
    }
    for deg in [0.0, 40.0, 130.0] {
        let a = slice(
            &aligned.mesh,
            &Plane::vertical(f64::to_radians(deg)),
            SliceOptions::default(),
        );
        assert_eq!(a.contours.len(), 1);
        let area = a.contours[0].signed_area();
        assert!(
            rel_err(area, 40.0 * 124.0) < 0.001,
            "vertical slice area {area}"
        );
    }
}

#[test]
fn an_aligned_object_stays_as_it_is() {
    // The prism's widest direction (30 mm) is X already; alignment must not turn it.
    let prism = objects::prism(30.0, 15.0, 124.0);
    let a = align(&prism);
    assert!(
        a.to_aligned.rotation.angle() < 1e-9,
        "rotated by {}",
        a.to_aligned.rotation.angle()
    );
    // The same prism lying on its side is stood up with the same convention.
    let rot = Rotation3::from_axis_angle(&Vector3::x_axis(), PI / 2.0);
    let b = align(&rotated(&prism, &rot, Vector3::zeros()));
    let (lo, hi) = b.mesh.bounds();
    let ext = hi - lo;
    assert!(
        (ext.x - 30.0).abs() < 1e-6 && (ext.y - 15.0).abs() < 1e-6 && (ext.z - 124.0).abs() < 1e-6,
        "{ext:?}"
    );
    // One with its thin side along X is turned a quarter turn about Z.
    let c = align(&objects::prism(15.0, 30.0, 124.0));
    let (lo, hi) = c.mesh.bounds();
    assert!(((hi - lo).x - 30.0).abs() < 1e-6, "{:?}", hi - lo);
}

#[test]
fn ascii_and_binary_forms_give_identical_results() {
    let mesh = objects::cylinder(40.0, 124.0);
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("c.stl");
    let asc = dir.path().join("c_ascii.stl");
    std::fs::write(&bin, mesh.to_binary_stl()).unwrap();
    std::fs::write(&asc, mesh.to_ascii_stl("cyl")).unwrap();
    let a = load_stl(&bin, LengthUnit::Mm).unwrap();
    let b = load_stl(&asc, LengthUnit::Mm).unwrap();
    assert!(a.is_binary && !b.is_binary);
    assert_eq!(a.mesh, b.mesh);
    let (sa, sb) = (align(&a.mesh), align(&b.mesh));
    assert_eq!(sa.mesh, sb.mesh);
    assert_eq!(sa.to_aligned, sb.to_aligned);
    let p = Plane::vertical(0.7);
    assert_eq!(
        slice(&sa.mesh, &p, SliceOptions::default()),
        slice(&sb.mesh, &p, SliceOptions::default())
    );
}

#[test]
fn units_scale_to_millimetres() {
    let mesh = objects::prism(15.0, 30.0, 124.0);
    let mut in_m = mesh.clone();
    in_m.map_vertices(|p| p / 1000.0);
    let path = Path::new("prism_m.stl");
    let a = parse_stl(&in_m.to_binary_stl(), path, LengthUnit::M).unwrap();
    let v = mass_properties(&a.mesh).volume_mm3;
    assert!(rel_err(v, 15.0 * 30.0 * 124.0) < 1e-5, "volume {v}");
    let mut in_inch = mesh;
    in_inch.map_vertices(|p| p / 25.4);
    let b = parse_stl(&in_inch.to_binary_stl(), path, LengthUnit::Inch).unwrap();
    let v = mass_properties(&b.mesh).volume_mm3;
    assert!(rel_err(v, 15.0 * 30.0 * 124.0) < 1e-5, "volume {v}");
}

#[test]
fn committed_assets_match_the_generator() {
    let thesis = objects::thesis_objects()
        .into_iter()
        .map(|(n, m)| (n.to_string(), m));
    let train = objects::training_objects()
        .into_iter()
        .map(|(n, m)| (format!("train/{n}"), m));
    for (name, mesh) in thesis.chain(train) {
        let path = crate::root().join(format!("assets/objects/{name}.stl"));
        let committed = std::fs::read(&path).unwrap();
        assert!(
            committed == mesh.to_binary_stl(),
            "{} differs from the generator: run `grasp-sim gen-assets`",
            path.display()
        );
        let loaded = load_stl(&path, LengthUnit::Mm).unwrap();
        assert!(
            loaded.topology.is_closed_manifold(),
            "{name}: {:?}",
            loaded.topology
        );
        assert_eq!(loaded.degenerate_dropped, 0, "{name}");
    }
}
