//! The search over the sorted domain (thesis 3.7, Fig. 3.23): for each candidate Finger_1
//! elevation, best first, try approach angles 0, AngularStep, 2 × AngularStep, …; place the palm,
//! then the fingers in order; the first failure rejects the candidate. The first feasible grasp
//! ends the search (or the first `max_grasps`, beyond the thesis, for ranking by simulation).

use super::finger::{place_finger, FingerPlacement, FingerRejection};
use super::palm::{place_palm, PalmPlacement, PalmRejection};
use super::GradedDomain;
use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::scenario::PlannerParams;
use std::collections::BTreeMap;

/// A kinematically feasible enveloping grasp: the thesis's Grasp Parameter Set.
#[derive(Debug, Clone, PartialEq)]
pub struct Grasp {
    /// Finger_1's elevation index.
    pub elevation_index: usize,
    /// Finger_1's elevation `[mm]`.
    pub elevation_mm: f64,
    /// Approach angle `[deg]`.
    pub approach_angle_deg: f64,
    /// The placed palm.
    pub palm: PalmPlacement,
    /// The fingers, in hand order.
    pub fingers: Vec<FingerPlacement>,
}

/// What rejected a candidate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Rejection {
    /// Palm placement failed.
    Palm(PalmRejection),
    /// A finger failed (its index in the hand).
    Finger(usize, FingerRejection),
}

/// The outcome of the search.
#[derive(Debug, Clone)]
pub struct SearchResult {
    /// Feasible grasps in search order (at most the number asked for).
    pub grasps: Vec<Grasp>,
    /// Candidates (elevation × approach angle) tried.
    pub candidates_tried: usize,
    /// How often each constraint rejected a candidate.
    pub rejections: BTreeMap<Rejection, usize>,
}

impl Rejection {
    /// A short description in the thesis's terms.
    pub fn describe(&self, hand: &Hand) -> String {
        match self {
            Rejection::Palm(PalmRejection::NoContact) => "palm finds no contact".into(),
            Rejection::Palm(PalmRejection::PitchOutOfRange) => "palm pitch out of range".into(),
            Rejection::Palm(PalmRejection::Penetration) => {
                "palm penetrates the object (vertical plane)".into()
            }
            Rejection::Finger(k, r) => {
                let name = &hand.finger_list[*k].name;
                let what = match r {
                    FingerRejection::PalmPenetration => "palm penetrates the object in its plane",
                    FingerRejection::Phalanx1NoContact => "phalanx 1 meets nothing",
                    FingerRejection::Theta1OutOfRange => "theta1 out of range",
                    FingerRejection::Phalanx1Penetration => "phalanx 1 penetrates the object",
                    FingerRejection::Phalanx2NoContact => "phalanx 2 meets nothing",
                    FingerRejection::Theta2OutOfRange => "theta2 out of range",
                    FingerRejection::Phalanx2Penetration => {
                        "phalanx 2 or its tip penetrates the object"
                    }
                    FingerRejection::JointDeviation => "ALS exceed the joint angular deviation",
                };
                format!("{name}: {what}")
            }
        }
    }
}

/// Walks the sorted domain and returns up to `max_grasps` feasible grasps.
pub fn search(
    mesh: &Mesh,
    hand: &Hand,
    graded: &GradedDomain,
    params: &PlannerParams,
    max_grasps: usize,
) -> SearchResult {
    let mut result = SearchResult {
        grasps: Vec::new(),
        candidates_tried: 0,
        rejections: BTreeMap::new(),
    };
    let steps = (360.0 / params.angular_step_deg).round() as usize;
    let deviation = [
        params.joint_deviation_theta1_deg,
        params.joint_deviation_theta2_deg,
    ];
    for &index in &graded.sorted_indices {
        let z1 = graded.domain.elevations[index - 1];
        for k in 0..steps {
            if result.grasps.len() >= max_grasps {
                return result;
            }
            let approach_deg = k as f64 * params.angular_step_deg;
            result.candidates_tried += 1;
            match try_candidate(mesh, hand, z1, approach_deg, params, deviation) {
                Ok((palm, fingers)) => result.grasps.push(Grasp {
                    elevation_index: index,
                    elevation_mm: z1,
                    approach_angle_deg: approach_deg,
                    palm,
                    fingers,
                }),
                Err(r) => *result.rejections.entry(r).or_insert(0) += 1,
            }
        }
    }
    result
}

fn try_candidate(
    mesh: &Mesh,
    hand: &Hand,
    z1: f64,
    approach_deg: f64,
    params: &PlannerParams,
    deviation: [f64; 2],
) -> Result<(PalmPlacement, Vec<FingerPlacement>), Rejection> {
    let palm = place_palm(
        mesh,
        hand,
        z1,
        approach_deg.to_radians(),
        params.pitch_range_deg.to_radians(),
    )
    .map_err(Rejection::Palm)?;
    let fingers = (0..hand.finger_list.len())
        .map(|k| place_finger(mesh, hand, &palm, k, deviation).map_err(|r| Rejection::Finger(k, r)))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((palm, fingers))
}
