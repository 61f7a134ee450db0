//! A hand file's own link geometry in the model's body frames (issue 37), for the physics check
//! and `--export-mjcf`: where a link of the file has a mesh, its pieces (each geometry element's
//! points) stand for the model's box of that body; elsewhere the model's boxes stay.
//!
//! Frames and units: millimetres; the palm's pieces in the model's palm frame (x away from the
//! object, the contact surface at x = 0), a phalanx's in its model body frame with the file's own
//! joint as origin: phalanx 1 about the file's joint 1 (at the finger's model height), turned as
//! the model turns it at the file's zero configuration, phalanx 2 likewise about joint 2, so each
//! link keeps its shape relative to its own joint where the model averages the joints' places.

use nalgebra::{Point3, UnitQuaternion, Vector3};

/// Pieces of collision geometry per model body `[mm]`: each piece a point set whose convex hull
/// is one collider. An empty list: the model's boxes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinkGeometry {
    /// The palm: the palm link, its fixed children and the spread links held with it.
    pub palm: Vec<Vec<Point3<f64>>>,
    /// Per finger (model order): phalanx 1's pieces, then phalanx 2's.
    pub phalanges: Vec<[Vec<Vec<Point3<f64>>>; 2]>,
}

impl LinkGeometry {
    /// True if and only if no body has pieces (every body keeps the model's boxes).
    pub fn is_empty(&self) -> bool {
        self.palm.is_empty()
            && self
                .phalanges
                .iter()
                .all(|[a, b]| a.is_empty() && b.is_empty())
    }

    /// The pieces of body `k` in [`crate::hand::Hand::body_poses`]'s order (0 the palm, then
    /// each finger's phalanx 1 and 2).
    pub fn body(&self, k: usize) -> &[Vec<Point3<f64>>] {
        if k == 0 {
            return &self.palm;
        }
        self.phalanges
            .get((k - 1) / 2)
            .map_or(&[], |p| p[(k - 1) % 2].as_slice())
    }
}

/// One geometry element of a body: its points in the frame the poses are in, and whether it is
/// a mesh.
pub(crate) type Piece = (Vec<Point3<f64>>, bool);

/// The pieces of a body, in its model frame given by `to_body` (model palm frame → body frame):
/// every piece if one of them is a mesh, else none.
pub(crate) fn body_pieces(
    pieces: Vec<Piece>,
    to_model: impl Fn(&Point3<f64>) -> Point3<f64>,
    to_body: (Point3<f64>, UnitQuaternion<f64>),
) -> Vec<Vec<Point3<f64>>> {
    if !pieces.iter().any(|(_, mesh)| *mesh) {
        return Vec::new();
    }
    let (origin, rotation) = to_body;
    pieces
        .into_iter()
        .filter(|(p, _)| !p.is_empty())
        .map(|(p, _)| {
            p.iter()
                .map(|v| Point3::from(rotation.inverse() * (to_model(v) - origin)))
                .collect()
        })
        .collect()
}

/// The rotation of a phalanx's model frame turned by `bend` `[rad]` on a finger of side sign
/// `s` from its parent's ([`crate::hand::Hand::finger_poses`]).
pub(crate) fn turn(s: f64, bend: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), s * bend)
}
