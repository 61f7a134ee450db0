//! The one place that knows both math libraries: nalgebra (f64, millimetres) for the planner
//! and glam (f32, metres) for rapier3d 0.36 / parry3d 0.31.

use nalgebra::{Point3, UnitQuaternion, Vector3};
use rapier3d::math::{Pose, Rotation, Vector};

/// Metres per millimetre.
pub const M_PER_MM: f64 = 1e-3;

/// A point in millimetres to a rapier vector in metres.
pub fn point_m(p: &Point3<f64>) -> Vector {
    Vector::new(
        (p.x * M_PER_MM) as f32,
        (p.y * M_PER_MM) as f32,
        (p.z * M_PER_MM) as f32,
    )
}

/// A displacement in millimetres to a rapier vector in metres.
pub fn vector_m(v: &Vector3<f64>) -> Vector {
    point_m(&Point3::from(*v))
}

/// A rotation to rapier's quaternion.
pub fn rotation(q: &UnitQuaternion<f64>) -> Rotation {
    Rotation::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize()
}

/// A rapier pose from a point in millimetres and a rotation.
pub fn pose(origin_mm: &Point3<f64>, q: &UnitQuaternion<f64>) -> Pose {
    Pose::from_parts(point_m(origin_mm), rotation(q))
}

/// A rapier vector in metres to millimetres.
pub fn vector_mm(v: Vector) -> Vector3<f64> {
    Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z)) / M_PER_MM
}

/// rapier's quaternion to nalgebra's.
pub fn unit_quaternion(r: Rotation) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        f64::from(r.w),
        f64::from(r.x),
        f64::from(r.y),
        f64::from(r.z),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_keep_f32_precision() {
        let p = Point3::new(12.5, -40.0, 117.25);
        let back = vector_mm(point_m(&p));
        assert!((back - p.coords).norm() < 1e-4, "{back:?}");
        let q = UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0);
        let r = unit_quaternion(rotation(&q));
        assert!(q.angle_to(&r) < 1e-6);
    }
}
