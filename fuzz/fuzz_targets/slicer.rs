//! Random planes through the thesis objects (closed manifolds): every contour closes, its points
//! are finite and lie on the plane, its normals are unit vectors.
#![no_main]
use grasp_sim::objects::thesis_objects;
use grasp_sim::slice::{slice, Plane, SliceOptions};
use libfuzzer_sys::fuzz_target;
use nalgebra::{Point3, Vector3};
use std::sync::OnceLock;

fuzz_target!(|data: &[u8]| {
    static OBJECTS: OnceLock<Vec<grasp_sim::mesh::Mesh>> = OnceLock::new();
    let objects = OBJECTS.get_or_init(|| thesis_objects().into_iter().map(|(_, m)| m).collect());
    if data.len() < 1 + 9 * 4 {
        return;
    }
    let mesh = &objects[data[0] as usize % objects.len()];
    let f: Vec<f64> = data[1..37]
        .chunks(4)
        .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
        .collect();
    if f.iter().any(|v| !v.is_finite() || v.abs() > 1e4) {
        return;
    }
    let u = Vector3::new(f[3], f[4], f[5]);
    let v = Vector3::new(f[6], f[7], f[8]);
    if u.norm() < 1e-3 || v.norm() < 1e-3 || u.normalize().cross(&v.normalize()).norm() < 1e-3 {
        return;
    }
    let plane = Plane::new(Point3::new(f[0], f[1], f[2]), u, v);
    let s = slice(mesh, &plane, SliceOptions::default());
    for c in &s.contours {
        assert!(c.is_closed, "a closed manifold gives closed contours");
        assert_eq!(c.points.len(), c.normals.len());
        for p in &c.points {
            assert!(p.x.is_finite() && p.y.is_finite());
            let d = plane.distance(&plane.to_3d(p)).abs();
            assert!(d < 1e-6, "off the plane by {d}");
        }
        for n in &c.normals {
            assert!((n.norm() - 1.0).abs() < 1e-9, "normal {n:?}");
        }
    }
});
