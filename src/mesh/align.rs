//! Aligning an object with its principal axis (thesis 3.2.1; the thesis leaves this to the user).
//!
//! The aligned frame: +Z along the principal axis with the smallest moment of inertia, the
//! centroid on the Z axis, the lowest point at Z = 0.
//!
//! The eigenvectors of an inertia tensor have no preferred sign, and for a body of revolution the
//! two other axes are any orthonormal pair. grasp-sim fixes them by a rule that keeps an object
//! that is already aligned unchanged, so a user's mesh that follows the thesis's convention is not
//! turned around:
//! 1. Z is the eigenvector of the smallest moment, signed to point along the original +Z (when it
//!    is perpendicular to it, along the original +X, then +Y).
//! 2. If the two remaining moments differ (relative difference above 1e-6), X is the eigenvector of
//!    the smaller one: the object's widest direction, so a palm approaching along −X at approach
//!    angle 0 faces the object's narrow side and the fingers wrap its long side. This reproduces
//!    the thesis's prism grasp (5.1: approach 0, θ1 = 58°): with the palm on the prism's broad
//!    face, phalanx 1 passes 30 mm beyond the far face and phalanx 2 cannot reach back to it. If
//!    the moments are equal (a body of revolution), X is the original X projected onto the plane
//!    normal to Z (or the original Y, then Z, when that projection vanishes).
//! 3. X is signed to point along the original +X (then +Y, then +Z); Y = Z × X.

use super::{mass_properties, MassProperties, Mesh};
use nalgebra::{
    Isometry3, Matrix3, Point3, Rotation3, SymmetricEigen, Translation3, UnitQuaternion, Vector3,
};

/// An object in the planner's aligned frame, with the way back to the mesh's original frame.
#[derive(Debug, Clone)]
pub struct AlignedObject {
    /// The mesh in the aligned frame `[mm]`.
    pub mesh: Mesh,
    /// Maps original coordinates to aligned ones: `p_aligned = to_aligned * p_original`.
    pub to_aligned: Isometry3<f64>,
    /// Mass properties in the original frame (unit density).
    pub original: MassProperties,
    /// Principal moments (unit density) about the aligned X, Y and Z axes `[mm⁵]`.
    pub principal_moments: Vector3<f64>,
    /// Height of the aligned object along Z `[mm]`.
    pub height_mm: f64,
    /// Which principal axis is aligned +Z.
    pub axis: GraspAxis,
}

impl AlignedObject {
    /// The principal axis (aligned +Z) expressed in the original frame, unit length.
    pub fn principal_axis_original(&self) -> Vector3<f64> {
        self.to_aligned.rotation.inverse() * Vector3::z()
    }

    /// Maps a point of the aligned frame back to the mesh's original frame.
    pub fn to_original(&self, p: &Point3<f64>) -> Point3<f64> {
        self.to_aligned.inverse_transform_point(p)
    }
}

const DEGENERATE_MOMENTS: f64 = 1e-6;

/// Which principal axis becomes the grasp axis (aligned +Z), and in which sense.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub struct GraspAxis {
    /// The axis by its moment of inertia: 0 the smallest (the thesis's axis), 1 the middle one,
    /// 2 the largest.
    pub rank: usize,
    /// True if and only if the axis is turned round (the object stands on its other end).
    pub flipped: bool,
}

impl GraspAxis {
    /// The thesis's axis: the smallest moment, in the sense the alignment rule gives.
    pub const THESIS: GraspAxis = GraspAxis {
        rank: 0,
        flipped: false,
    };

    /// The order in which the planner tries the axes: the thesis's axis first (the thesis
    /// method, and the long axis of an elongated object, which the fingers wrap best), then the
    /// middle and the largest moment (a flat object is wrapped round its rim about the largest);
    /// the opposite senses last, since turning an object round changes only which end the
    /// search starts from and where gravity pulls in the check.
    pub const SEARCH_ORDER: [GraspAxis; 6] = [
        GraspAxis {
            rank: 0,
            flipped: false,
        },
        GraspAxis {
            rank: 1,
            flipped: false,
        },
        GraspAxis {
            rank: 2,
            flipped: false,
        },
        GraspAxis {
            rank: 0,
            flipped: true,
        },
        GraspAxis {
            rank: 1,
            flipped: true,
        },
        GraspAxis {
            rank: 2,
            flipped: true,
        },
    ];

    /// A short name: `least`, `middle` or `largest` (moment), with `-` when flipped.
    pub fn name(&self) -> String {
        let m = ["least", "middle", "largest"][self.rank.min(2)];
        if self.flipped {
            format!("{m}-")
        } else {
            m.to_string()
        }
    }
}

/// Aligns `mesh` with its principal axis of least moment (the thesis's axis). The mesh must
/// enclose a positive volume.
pub fn align(mesh: &Mesh) -> AlignedObject {
    align_about(mesh, GraspAxis::THESIS)
}

/// Aligns `mesh` with the principal axis `which` as +Z. For the thesis's axis this is [`align`]'s
/// rule; for another, X is the smaller-moment remaining axis (the object's widest direction
/// across the grasp axis), signed by the same rule, and a flipped axis turns the object about X.
pub fn align_about(mesh: &Mesh, which: GraspAxis) -> AlignedObject {
    align_with(mesh, &mass_properties(mesh), which)
}

/// [`align_about`] with the mesh's mass properties already computed (they do not depend on the
/// axis chosen).
pub fn align_with(mesh: &Mesh, props: &MassProperties, which: GraspAxis) -> AlignedObject {
    let props = *props;
    let eig = SymmetricEigen::new(props.inertia);
    // Sort eigenpairs by moment, ascending; ties broken by index for determinism.
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| {
        eig.eigenvalues[a]
            .total_cmp(&eig.eigenvalues[b])
            .then(a.cmp(&b))
    });
    let axis = |i: usize| -> Vector3<f64> { eig.eigenvectors.column(order[i]).into_owned() };
    let moment = |i: usize| eig.eigenvalues[order[i]];

    let rank = which.rank.min(2);
    let rest: Vec<usize> = (0..3).filter(|&i| i != rank).collect();
    let z = sign_towards(axis(rank), &[Vector3::z(), Vector3::x(), Vector3::y()]);
    let (m1, m2) = (moment(rest[0]), moment(rest[1]));
    let scale = m1.abs().max(m2.abs()).max(f64::MIN_POSITIVE);
    let x_raw = if (m2 - m1).abs() / scale > DEGENERATE_MOMENTS {
        axis(rest[0])
    } else {
        [Vector3::x(), Vector3::y(), Vector3::z()]
            .iter()
            .map(|a| a - z * z.dot(a))
            .find(|v| v.norm() > 1e-6)
            .unwrap_or_else(Vector3::x)
    };
    // Re-orthogonalise against z (eigenvectors are orthogonal only to rounding).
    let x = (x_raw - z * z.dot(&x_raw)).normalize();
    let x = sign_towards(x, &[Vector3::x(), Vector3::y(), Vector3::z()]);
    let z = if which.flipped { -z } else { z };
    let y = z.cross(&x);

    // Rows of the rotation are the new axes expressed in the original frame.
    let r = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    let c = props.centroid.coords;
    let rotated_centroid = rotation * c;
    let mut to_aligned = Isometry3::from_parts(Translation3::from(-rotated_centroid), rotation);
    let z_min = mesh
        .vertices
        .iter()
        .map(|p| (to_aligned * p).z)
        .fold(f64::INFINITY, f64::min);
    to_aligned.translation.vector.z -= z_min;

    let mut aligned = mesh.clone();
    aligned.map_vertices(|p| to_aligned * p);
    let height_mm = aligned
        .vertices
        .iter()
        .map(|p| p.z)
        .fold(f64::NEG_INFINITY, f64::max);
    AlignedObject {
        mesh: aligned,
        to_aligned,
        original: props,
        principal_moments: Vector3::new(
            x.dot(&(props.inertia * x)),
            y.dot(&(props.inertia * y)),
            z.dot(&(props.inertia * z)),
        ),
        height_mm,
        axis: which,
    }
}

/// Flips `v` so that its first non-negligible dot product with `hints` is positive.
fn sign_towards(v: Vector3<f64>, hints: &[Vector3<f64>]) -> Vector3<f64> {
    for h in hints {
        let d = v.dot(h);
        if d.abs() > 1e-9 {
            return if d < 0.0 { -v } else { v };
        }
    }
    v
}
