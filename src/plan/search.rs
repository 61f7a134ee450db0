//! The search over the sorted domain (thesis 3.7, Fig. 3.23): for each candidate Finger_1
//! elevation, best first, try approach angles 0, AngularStep, 2 × AngularStep, …; place the palm,
//! then the fingers in order; the first failure rejects the candidate. The first feasible grasp
//! ends the search (or the first `max_grasps`, beyond the thesis, for ranking by simulation).

use super::finger::{place_finger, FingerPlacement, FingerRejection};
use super::palm::{
    penetration_depth_of, place_palm_on, vertical_slice, PalmPlacement, PalmRejection,
    PENETRATION_TOL_MM,
};
use super::PlannerParams;
use super::{GradedDomain, Relaxation, RuleSet};
use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::slice::{cut_segments_indexed, Slice, SliceIndex};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// The search tries this many candidates one at a time before it tries them in blocks on
/// rayon's threads (most objects with a grasp find it sooner, and a block would be wasted work).
const SEARCH_SEQUENTIAL: usize = 64;

/// The largest block of candidates the search tries at once on rayon's threads.
const SEARCH_BLOCK: usize = 32;

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
    /// The rule set that produced it.
    pub rules: RuleSet,
    /// The thesis rules it relaxed (sorted, each once): empty under the thesis's rules.
    pub relaxations: Vec<Relaxation>,
}

/// What rejected a candidate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Rejection {
    /// Palm placement failed.
    Palm(PalmRejection),
    /// A finger failed (its index in the hand).
    Finger(usize, FingerRejection),
    /// Under the rules beyond the thesis, the planned contacts together push the object along
    /// the axis beyond the friction cone ([`crate::plan::squeeze`]).
    NetPush,
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
            Rejection::Palm(PalmRejection::WithinPitchRange) => {
                "palm within the pitch range (tried by the rules before)".into()
            }
            Rejection::Palm(PalmRejection::Penetration) => {
                "palm penetrates the object (vertical plane)".into()
            }
            Rejection::NetPush => {
                "the contacts' net push along the axis leaves the friction cone".into()
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
    let mut grasps = Vec::new();
    let (candidates_tried, rejections) = search_with(
        mesh,
        hand,
        graded,
        params,
        RuleSet::Thesis,
        usize::MAX,
        |g| {
            grasps.push(g);
            grasps.len() < max_grasps
        },
    );
    SearchResult {
        grasps,
        candidates_tried,
        rejections,
    }
}

/// The approach angles tried at each elevation `[deg]`: the AngularStep grid 0, AngularStep, …
/// (thesis 3.7), then the directions normal to the object's large flat side faces that the grid
/// misses, so that a box is approached square to its faces however the alignment turned it
/// about the axis (see `face_directions_deg`).
pub fn approach_angles_deg(graded: &GradedDomain, params: &PlannerParams) -> Vec<f64> {
    let steps = (360.0 / params.angular_step_deg).round() as usize;
    let mut angles: Vec<f64> = (0..steps)
        .map(|k| k as f64 * params.angular_step_deg)
        .collect();
    let grid = angles.clone();
    for a in &graded.domain.face_directions_deg {
        let on_grid = grid.iter().any(|g| {
            let d = (a - g).rem_euclid(360.0);
            d.min(360.0 - d) < 0.01
        });
        if !on_grid {
            angles.push(*a);
        }
    }
    angles
}

/// Walks the sorted domain, handing each feasible grasp to `on_grasp` in search order until it
/// returns false, the domain is exhausted or `budget` candidates have been tried. Returns the
/// candidates tried and the rejections.
pub fn search_with(
    mesh: &Mesh,
    hand: &Hand,
    graded: &GradedDomain,
    params: &PlannerParams,
    rules: RuleSet,
    budget: usize,
    on_grasp: impl FnMut(Grasp) -> bool,
) -> (usize, BTreeMap<Rejection, usize>) {
    let schedule = (SEARCH_SEQUENTIAL, SEARCH_BLOCK);
    search_scheduled(
        mesh, hand, graded, params, rules, schedule, budget, on_grasp,
    )
}

/// The number of candidates (elevation × approach angle) the search would try on `graded`.
pub fn candidate_count(graded: &GradedDomain, params: &PlannerParams) -> usize {
    graded.sorted_indices.len() * approach_angles_deg(graded, params).len()
}

/// [`search_with`], trying the first `sequential` candidates one at a time and then blocks
/// doubling from 2 up to `max_block` (the tests compare schedules).
#[allow(clippy::too_many_arguments)]
fn search_scheduled(
    mesh: &Mesh,
    hand: &Hand,
    graded: &GradedDomain,
    params: &PlannerParams,
    rules: RuleSet,
    (sequential, max_block): (usize, usize),
    budget: usize,
    mut on_grasp: impl FnMut(Grasp) -> bool,
) -> (usize, BTreeMap<Rejection, usize>) {
    let mut tried = 0;
    let mut rejections = BTreeMap::new();
    let deviation = [
        params.joint_deviation_theta1_deg,
        params.joint_deviation_theta2_deg,
    ];
    let angles = approach_angles_deg(graded, params);
    // The palm's vertical slice depends on the approach angle only: cut once per angle, when
    // the search first needs it (by whichever thread gets there first).
    let vslices: Vec<OnceLock<Slice>> = angles.iter().map(|_| OnceLock::new()).collect();
    let candidates = candidate_order(graded, angles.len(), budget);
    // Every finger plane of every candidate is cut through one index of the mesh's triangles,
    // built when the first candidate needs it (an axis with no candidates costs none).
    let index = OnceLock::new();
    let evaluate = |&(index_z, a): &(usize, usize)| {
        let index = index.get_or_init(|| SliceIndex::new(mesh));
        let approach_deg = angles[a];
        let vslice =
            vslices[a].get_or_init(|| vertical_slice(mesh, hand, approach_deg.to_radians()));
        let candidate = Candidate {
            z1: graded.domain.elevations[index_z - 1],
            approach_deg,
            vslice,
        };
        try_candidate(mesh, index, hand, &candidate, params, deviation, rules)
    };
    // Candidates are tried in blocks on rayon's threads, each block's results taken in search
    // order: the grasps, the count tried and the rejections are the sequential search's (an
    // outcome depends on the candidate alone). The first SEARCH_SEQUENTIAL go one at a time (a
    // grasp found early costs no more), then blocks doubling from 2 up to SEARCH_BLOCK: a long
    // search wastes at most one block beyond its last grasp.
    let mut start = 0;
    let mut block = 2.min(max_block.max(1));
    while start < candidates.len() {
        let end = (start + if start < sequential { 1 } else { block }).min(candidates.len());
        let results: Vec<_> = if end - start == 1 {
            vec![evaluate(&candidates[start])]
        } else {
            candidates[start..end].par_iter().map(evaluate).collect()
        };
        for (&(index, a), result) in candidates[start..end].iter().zip(results) {
            tried += 1;
            match result {
                Ok((palm, fingers)) => {
                    let relaxations = relaxations_of(graded, index, hand, rules, &palm, &fingers);
                    let go_on = on_grasp(Grasp {
                        elevation_index: index,
                        elevation_mm: graded.domain.elevations[index - 1],
                        approach_angle_deg: angles[a],
                        palm,
                        fingers,
                        rules,
                        relaxations,
                    });
                    if !go_on {
                        return (tried, rejections);
                    }
                }
                // The leaning pass's own skip: the rule sets before it placed that palm.
                Err(Rejection::Palm(PalmRejection::WithinPitchRange)) => {}
                Err(r) => *rejections.entry(r).or_insert(0) += 1,
            }
        }
        if start >= sequential {
            block = (2 * block).min(max_block);
        }
        start = end;
    }
    (tried, rejections)
}

/// The relaxations of the extended rules a grasp at elevation `index` uses, sorted, once each:
/// its fingers' own, a finger on an index whose curvature grade was relaxed, a backed-off palm,
/// an outer finger beyond the Effective Elevation.
fn relaxations_of(
    graded: &GradedDomain,
    index: usize,
    hand: &Hand,
    rules: RuleSet,
    palm: &PalmPlacement,
    fingers: &[FingerPlacement],
) -> Vec<Relaxation> {
    let mut relaxations: Vec<Relaxation> = fingers
        .iter()
        .flat_map(|f| f.relaxations.iter().copied())
        .collect();
    if finger_indices(graded, index).any(|j| graded.curvature_relaxed.get(j - 1) == Some(&true)) {
        relaxations.push(Relaxation::CurvatureGraded);
    }
    if palm.backed_off_mm > 0.0 {
        relaxations.push(Relaxation::PalmBackedOff);
    }
    if rules == RuleSet::Leaning {
        // The only palms the leaning pass places.
        relaxations.push(Relaxation::PalmPitchClamped);
    }
    if rules.is_extended() && uses_outer_elevation(graded, index, hand) {
        relaxations.push(Relaxation::OuterFingerBeyondElevation);
    }
    relaxations.sort();
    relaxations.dedup();
    relaxations
}

/// The search's candidates in order, at most `budget`: each sorted elevation index (1-based)
/// with each of the `angle_count` approach angles.
fn candidate_order(
    graded: &GradedDomain,
    angle_count: usize,
    budget: usize,
) -> Vec<(usize, usize)> {
    graded
        .sorted_indices
        .iter()
        .flat_map(|&index| (0..angle_count).map(move |a| (index, a)))
        .take(budget)
        .collect()
}

/// One candidate of the search: Finger_1's elevation and the approach angle, with the palm's
/// vertical slice at that angle.
struct Candidate<'a> {
    z1: f64,
    approach_deg: f64,
    vslice: &'a Slice,
}

fn try_candidate(
    mesh: &Mesh,
    index: &SliceIndex,
    hand: &Hand,
    candidate: &Candidate,
    params: &PlannerParams,
    deviation: [f64; 2],
    rules: RuleSet,
) -> Result<(PalmPlacement, Vec<FingerPlacement>), Rejection> {
    let extended = rules.is_extended();
    let mut palm = place_palm_on(
        candidate.vslice,
        hand,
        candidate.z1,
        candidate.approach_deg.to_radians(),
        params.pitch_range_deg.to_radians(),
        rules,
    )
    .map_err(Rejection::Palm)?;
    if extended {
        // The palm stops at its first contact in any finger plane, not only in the vertical
        // plane it was placed in.
        let depth = palm_backoff_in_finger_planes(mesh, index, hand, &palm);
        if depth > PENETRATION_TOL_MM {
            palm.origin += palm.axes[0] * depth;
            palm.backed_off_mm += depth;
        }
    }
    // The palm on the object (the thesis), then for a hand with a palm stand-off
    // (issue 37) held off it in steps, the object between the phalanges: the nearest that
    // places every finger. A failure reports the rejection with the palm on the object.
    let mut first = None;
    let mut at = 0.0;
    for standoff in hand.palm_standoffs_mm() {
        if standoff != at {
            palm.origin += palm.axes[0] * (standoff - at);
            palm.standoff_mm = standoff;
            at = standoff;
        }
        let fingers = (0..hand.finger_list.len())
            .map(|k| {
                place_finger(mesh, index, hand, &palm, k, deviation, rules)
                    .map_err(|r| Rejection::Finger(k, r))
            })
            .collect::<Result<Vec<_>, _>>();
        match fingers {
            Ok(fingers) => return Ok((palm, fingers)),
            Err(r) => {
                first.get_or_insert(r);
            }
        }
    }
    Err(first.unwrap_or(Rejection::Palm(PalmRejection::NoContact)))
}

/// Returns true if and only if a finger of the grasp at Finger_1's `index` sits on an elevation
/// the thesis would not use: outside its Effective Elevation (the extended domain is the whole
/// object) or graded ungraspable.
fn uses_outer_elevation(graded: &GradedDomain, index: usize, hand: &Hand) -> bool {
    let o = hand.fingers.offset_mm;
    let d = &graded.domain;
    let inner = [d.span_mm[0] + o, d.span_mm[1] - o];
    graded.finger_offsets.len() != finger_indices(graded, index).count()
        || finger_indices(graded, index).any(|j| {
            let z = d.elevations[j - 1];
            graded.grades.combined[j - 1].is_none() || z < inner[0] - 1e-9 || z > inner[1] + 1e-9
        })
}

/// The indices (1-based) of the fingers for Finger_1 at `index`, those inside the domain.
fn finger_indices(graded: &GradedDomain, index: usize) -> impl Iterator<Item = usize> + '_ {
    let n = graded.domain.elevations.len() as i64;
    graded
        .finger_offsets
        .iter()
        .map(move |&off| index as i64 - off)
        .filter(move |&j| j >= 1 && j <= n)
        .map(|j| j as usize)
}

/// How far the palm must move back along its normal so that its outline touches but does not
/// take in the object in any finger slice plane (the three ALS planes of every finger) `[mm]`.
///
/// Measured on the planes' exact cuts (their segments, [`cut_segments_indexed`], not chained:
/// the maximum needs no contours, and chaining them was half of a many-candidate search), not
/// on the bridged slices the
/// fingers are then placed on (issue 30): the bridging of a many-shell or open mesh was most of
/// an extended candidate's cost, and it reaches no further towards the palm than the cut except
/// where a bridge or a joint crosses the edge of the palm's band. A candidate whose palm then
/// still takes in a bridge in a finger's plane is rejected when that finger is placed
/// ("palm penetrates the object in its plane").
fn palm_backoff_in_finger_planes(
    mesh: &Mesh,
    index: &SliceIndex,
    hand: &Hand,
    palm: &PalmPlacement,
) -> f64 {
    let o = hand.fingers.offset_mm;
    let hw = hand.palm.half_width_mm;
    let mut depth = f64::NEG_INFINITY;
    for f in &hand.finger_list {
        for dz in [-o, 0.0, o] {
            let cut = cut_segments_indexed(mesh, index, &palm.finger_plane(f.height_mm + dz));
            // Finger-plane coordinates: x away from the object (contact surface at 0), y sideways.
            depth = depth.max(penetration_depth_of(
                cut,
                nalgebra::Point2::origin(),
                nalgebra::Vector2::y(),
                nalgebra::Vector2::x(),
                [-hw, hw],
            ));
        }
    }
    depth
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::StageTimings;

    #[test]
    fn every_schedule_gives_the_one_at_a_time_search() {
        // A flat box under the pinch rules: 96 candidates, 24 grasps. One at a time (the
        // reference) against blocks from the first candidate, odd blocks, and the default, each
        // run to the end and stopped after the first few grasps (a stop inside a block): the
        // same grasps, the same count tried, the same rejections.
        let hand = Hand::load(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/hands/thesis.toml"),
            &[],
        )
        .unwrap();
        let aligned = crate::mesh::align(&crate::objects::prism(100.0, 30.0, 150.0));
        // A coarse grid keeps the test short: some 200 candidates.
        let params = PlannerParams {
            angular_step_deg: 45.0,
            height_step_mm: 10.0,
            ..PlannerParams::default()
        };
        let rules = RuleSet::Pinch;
        let mut t = StageTimings::default();
        let graded =
            super::super::grade_domain_with(&aligned.mesh, &hand, &params, 0.3, rules, &mut t);
        let run = |schedule: (usize, usize), stop_after: usize| {
            let mut grasps = Vec::new();
            let (tried, rejections) = search_scheduled(
                &aligned.mesh,
                &hand,
                &graded,
                &params,
                rules,
                schedule,
                usize::MAX,
                |g| {
                    grasps.push(g);
                    grasps.len() < stop_after
                },
            );
            (tried, rejections, grasps)
        };
        let whole = run((usize::MAX, 1), usize::MAX);
        assert!(whole.0 > 64, "{} candidates", whole.0);
        assert!(whole.2.len() >= 3, "{} grasps", whole.2.len());
        // Stops early, and late (past the 64 tried one at a time by default).
        for stop_after in [usize::MAX, 1, 2, 3, whole.2.len() - 2] {
            let reference = if stop_after == usize::MAX {
                whole.clone()
            } else {
                run((usize::MAX, 1), stop_after)
            };
            for schedule in [(0, 3), (0, 32), (5, 7), (SEARCH_SEQUENTIAL, SEARCH_BLOCK)] {
                assert_eq!(
                    run(schedule, stop_after),
                    reference,
                    "schedule {schedule:?}, stopped after {stop_after} grasps"
                );
            }
        }
    }
}
