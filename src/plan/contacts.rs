//! The contacts a planned grasp is meant to make (from the plan alone): the one place the
//! planner's order, the physics check's collider and the analytic quality take them from.

use serde::Serialize;

/// A point contact between the hand and the object.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contact {
    /// Contact point, aligned object frame `[mm]`.
    pub point_mm: [f64; 3],
    /// Unit normal, aligned object frame: the direction in which the hand pushes the object.
    pub normal: [f64; 3],
    /// The finger's name, or `palm`.
    pub finger: String,
    /// 1 or 2 for a finger's phalanx, 0 for the palm.
    pub phalanx: u8,
    /// Normal force the physics check's solver applied at the end of closing `[N]` (`None` for
    /// planned contacts).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_n: Option<f64>,
}

/// The planned contacts of a grasp: the palm's contacts in the vertical slice at the approach
/// angle (pushing along the palm's normal) and, for every finger, where each ALS's phalanx 1
/// and phalanx 2 touch in its finger slice plane (top, centre, bottom), pushing along the
/// phalanx's inward normal. Under the thesis's rules each ALS touches at its own angles; under
/// the extended rules a finger touches only where it stops ([`crate::plan::finger::AlsAngles`]'s
/// `contacts`). Aligned object frame.
pub fn planned_contacts(
    grasp: &crate::plan::search::Grasp,
    hand: &crate::hand::Hand,
) -> Vec<Contact> {
    let palm = &grasp.palm;
    let mut out = Vec::new();
    let vertical = crate::slice::Plane::vertical(palm.approach_rad);
    let push = -palm.axes[0];
    for c in &palm.contacts {
        out.push(Contact {
            point_mm: vertical.to_3d(c).into(),
            normal: push.into(),
            finger: "palm".to_string(),
            phalanx: 0,
            force_n: None,
        });
    }
    let o = hand.fingers.offset_mm;
    for (f, placed) in hand.finger_list.iter().zip(&grasp.fingers) {
        for (dz, als) in [
            (o, &placed.top),
            (0.0, &placed.centre),
            (-o, &placed.bottom),
        ] {
            let plane = palm.finger_plane(f.height_mm + dz);
            for (k, (p, n)) in als
                .contacts
                .iter()
                .enumerate()
                .filter_map(|(k, c)| Some((k, (*c)?)))
            {
                let n3 = plane.u * n.x + plane.v * n.y;
                out.push(Contact {
                    point_mm: plane.to_3d(&p).into(),
                    normal: n3.into(),
                    finger: placed.name.clone(),
                    phalanx: k as u8 + 1,
                    force_n: None,
                });
            }
        }
    }
    out
}
