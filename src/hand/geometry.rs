//! The hand's rigid geometry and forward kinematics: the one place that says where the palm and
//! phalanx boxes are and how the joints place the phalanges. The rapier scene, the MJCF and URDF
//! exports, the glTF scenes and the figures all build on it, so that a body means the same thing
//! in each.
//!
//! Units: millimetres and radians. Frames: the palm frame of [`crate::hand`] (contact surface at
//! x = 0, x away from the object, z up along the joint axes); a phalanx's frame has its origin on
//! its joint axis and its y along the phalanx, towards the finger's side. A joint's value is its
//! bend from straight ([`bend`]), turned about `(0, 0, side)` in its parent's frame.

use super::{Finger, Hand, Side};
use nalgebra::{Matrix3, Point3, Rotation3, UnitQuaternion, Vector3};

impl Side {
    /// The side as a sign: +1 on the left (the palm frame's +y), −1 on the right.
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

/// Bend from straight of a joint at interior angle `theta_deg` `[rad]`: the joint value used by
/// the rapier scene and by the MJCF and URDF exports alike.
pub fn bend(theta_deg: f64) -> f64 {
    (180.0 - theta_deg).to_radians()
}

/// The rotation whose columns are the palm axes `[x, y, z]` (aligned frame): the palm's
/// orientation. The axes must be orthonormal and right-handed (they are not checked).
pub fn palm_rotation(axes: &[Vector3<f64>; 3]) -> UnitQuaternion<f64> {
    let [x, y, z] = axes;
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(Matrix3::from_columns(
        &[*x, *y, *z],
    )))
}

/// A box of the hand in its body's frame `[mm]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandBox {
    /// Half its extents along the body's axes.
    pub half_extents: Vector3<f64>,
    /// Its centre.
    pub centre: Vector3<f64>,
}

/// A body's pose in the aligned frame: its origin `[mm]` and orientation.
pub type BodyPose = (Point3<f64>, UnitQuaternion<f64>);

impl Hand {
    /// The palm's extent along its up axis, about the palm centre: the lowest finger's
    /// centreline less the margin to the highest's plus the margin, `[bottom, top]` `[mm]`.
    pub fn palm_z_range_mm(&self) -> [f64; 2] {
        let (h_lo, h_hi) = self.finger_height_span();
        let m = self.palm.margin_mm;
        [h_lo - m, h_hi + m]
    }

    /// The palm box in the palm frame: `offset_mm` deep behind the contact surface, as wide as
    /// the palm, and spanning [`Hand::palm_z_range_mm`].
    pub fn palm_box(&self) -> HandBox {
        let [z_lo, z_hi] = self.palm_z_range_mm();
        HandBox {
            half_extents: Vector3::new(
                self.palm.offset_mm / 2.0,
                self.palm.half_width_mm,
                (z_hi - z_lo) / 2.0,
            ),
            centre: Vector3::new(self.palm.offset_mm / 2.0, 0.0, (z_hi + z_lo) / 2.0),
        }
    }

    /// The boxes of phalanx 1 and of phalanx 2 (its contact part, then its thinned tip if it
    /// has one, thesis Fig. 3.8), each in its phalanx's frame, for a finger on `side`.
    pub fn phalanx_boxes(&self, side: Side) -> (HandBox, Vec<HandBox>) {
        let s = side.sign();
        let o = self.fingers.offset_mm;
        let (l1, l2) = (self.phalanx_1.length_mm, self.phalanx_2.length_mm);
        let l2_contact = l2 - self.phalanx_2.unusable_distal_mm;
        let p1 = HandBox {
            half_extents: Vector3::new(o, l1 / 2.0, o),
            centre: Vector3::new(0.0, s * l1 / 2.0, 0.0),
        };
        let mut p2 = vec![HandBox {
            half_extents: Vector3::new(o, l2_contact / 2.0, o),
            centre: Vector3::new(0.0, s * l2_contact / 2.0, 0.0),
        }];
        if l2 > l2_contact + 1e-9 {
            // The thinned tip: its contact side recedes to the tip thickness.
            let t = self.fingers.tip_thickness_mm;
            p2.push(HandBox {
                half_extents: Vector3::new(t / 2.0, (l2 - l2_contact) / 2.0, o),
                centre: Vector3::new(o - t / 2.0, s * (l2 + l2_contact) / 2.0, 0.0),
            });
        }
        (p1, p2)
    }

    /// Where `finger`'s joint 1 sits in the palm frame `[mm]`.
    pub fn joint1_anchor_mm(&self, finger: &Finger) -> Vector3<f64> {
        Vector3::new(
            self.joints.setback_mm,
            finger.side.sign() * self.joints.lateral_mm,
            finger.height_mm,
        )
    }

    /// Where joint 2 of a finger on `side` sits in its phalanx 1's frame `[mm]`.
    pub fn joint2_anchor_mm(&self, side: Side) -> Vector3<f64> {
        Vector3::new(0.0, side.sign() * self.phalanx_1.length_mm, 0.0)
    }

    /// Forward kinematics of one finger: the poses of its phalanx 1 and 2 with the palm at
    /// `palm` and the joints bent `bends` `[rad]`. A phalanx's frame is its parent's turned by
    /// side × bend about the palm's z, so the revolute joint's angle about `(0, 0, side)` is the
    /// bend itself.
    pub fn finger_poses(&self, finger: &Finger, palm: &BodyPose, bends: [f64; 2]) -> [BodyPose; 2] {
        let s = finger.side.sign();
        let turn = |b: f64| UnitQuaternion::from_axis_angle(&Vector3::z_axis(), s * b);
        let (origin, r_palm) = palm;
        let r1 = r_palm * turn(bends[0]);
        let j1 = origin + r_palm * self.joint1_anchor_mm(finger);
        let r2 = r1 * turn(bends[1]);
        let j2 = j1 + r1 * self.joint2_anchor_mm(finger.side);
        [(j1, r1), (j2, r2)]
    }

    /// Forward kinematics of the whole hand: the palm at `palm`, then phalanx 1 and 2 of each
    /// finger with its joints bent `bends[k]` `[rad]` (fingers beyond `bends` are left out).
    pub fn body_poses(&self, palm: &BodyPose, bends: &[[f64; 2]]) -> Vec<BodyPose> {
        let mut out = vec![*palm];
        for (f, b) in self.finger_list.iter().zip(bends) {
            out.extend(self.finger_poses(f, palm, *b));
        }
        out
    }
}
