//! Significance factors (thesis 3.4.3.3) and stage 3 of search-domain reduction (3.4.4).
//!
//! - Elevation grade = Sf_c × curvature + (1 − Sf_c) × diameter (eq. 3.4); an elevation
//!   ungraspable in either is marked ungraspable in both.
//! - First palm approach check (3.4.4.1): the Largest Span Height (the largest vertical distance
//!   between two consecutive ungraspable indexed elevations, the ends of the Effective Elevation
//!   counting as ungraspable one step beyond) must exceed the distance between the outermost
//!   fingers' centrelines, or the object is ungraspable.
//! - Palm grade (3.4.4.2), assigned to Finger_1's index: the mean of the elevation grades at the
//!   fingers' indices. A palm position is blocked when any index from Finger_1's to the lowest
//!   finger's is ungraspable or outside the Effective Elevation. (The thesis describes this as a
//!   scan from the top that moves Finger_1 below each ungraspable elevation and marks the skipped
//!   positions ungraspable; the set of positions that survive is exactly this one.)
//! - Sorting (3.4.4.3): by palm grade, best first; equal grades (to 1e-4) from the higher
//!   elevation to the lower.

use super::diameter::DiameterGrades;
use super::kinematics::GraspableRange;
use super::PlannerParams;
use super::RuleSet;
use super::{Domain, Grade};
use crate::hand::Hand;

/// Per-index grade vectors (index i at position i − 1), `None` where ungraspable.
#[derive(Debug, Clone, PartialEq)]
pub struct Grades {
    /// Curvature pattern grades (after marking, stage 2).
    pub curvature: Vec<Grade>,
    /// Effective Diameter grades (after marking).
    pub diameter: Vec<Grade>,
    /// Combined with the significance factors.
    pub combined: Vec<Grade>,
    /// Palm grades at Finger_1's index (stage 3).
    pub palm: Vec<Grade>,
}

/// The graded, sorted search domain: the output of stages 1–3.
#[derive(Debug, Clone)]
pub struct GradedDomain {
    /// Stage 1.
    pub domain: Domain,
    /// Every grade vector.
    pub grades: Grades,
    /// Effective Diameter per index `[mm]`.
    pub diameters_mm: Vec<f64>,
    /// The hand's graspable diameter range.
    pub range: GraspableRange,
    /// Index offsets of each finger below Finger_1, in hand order (Finger_1's is 0).
    pub finger_offsets: Vec<i64>,
    /// The Largest Span Height `[mm]`.
    pub largest_span_mm: f64,
    /// Candidate Finger_1 indices, best first.
    pub sorted_indices: Vec<usize>,
    /// Why nothing survived, when `sorted_indices` is empty.
    pub reason: Option<String>,
    /// Per index, true where a curvature grade used the extended rules' floor for a touch
    /// point the thesis calls ungraspable (all false under the thesis's rules).
    pub curvature_relaxed: Vec<bool>,
}

/// Stage 3: combine, check the palm span, grade palm positions and sort them.
pub fn rank(
    domain: Domain,
    curvature: Vec<Grade>,
    diameter: DiameterGrades,
    range: GraspableRange,
    params: &PlannerParams,
    hand: &Hand,
) -> GradedDomain {
    rank_with(
        domain,
        curvature,
        diameter,
        range,
        params,
        hand,
        RuleSet::Thesis,
    )
}

/// Stage 3 under a rule set. Under [`RuleSet::Extended`] the domain spans the whole object
/// ([`Domain::build_with`] with no shrink); the inner fingers must still sit on graded indices
/// within the thesis's Effective Elevation, the outer (highest and lowest) fingers may sit on
/// any index of the object, graded or not (an ungraded one counts 0 in the palm grade), and the
/// Largest Span Height check is not made (see [`super::Relaxation::OuterFingerBeyondElevation`]).
pub fn rank_with(
    domain: Domain,
    curvature: Vec<Grade>,
    diameter: DiameterGrades,
    range: GraspableRange,
    params: &PlannerParams,
    hand: &Hand,
    rules: RuleSet,
) -> GradedDomain {
    let n = domain.elevations.len();
    let step = domain.height_step_mm;
    let mut curv = curvature;
    let mut diam = diameter.grades;
    for i in 0..n {
        if curv[i].is_none() || diam[i].is_none() {
            curv[i] = None;
            diam[i] = None;
        }
    }
    let sf = params.sf_c;
    let combined: Vec<Grade> = (0..n)
        .map(|i| Some(sf * curv[i]? + (1.0 - sf) * diam[i]?))
        .collect();

    let finger_offsets = finger_offsets(hand, step);
    let spread = *finger_offsets.iter().max().unwrap_or(&0);
    let low = *finger_offsets.iter().min().unwrap_or(&0);

    // Largest Span Height between consecutive ungraspable indices (ends count one step out).
    let largest = largest_span_steps(&combined);
    let largest_span_mm = largest as f64 * step;
    let finger_span_mm = (spread - low) as f64 * step;

    let palm = if rules.is_extended() {
        extended_palm_grades(&domain, &combined, &finger_offsets, hand.fingers.offset_mm)
    } else if largest_span_mm > finger_span_mm {
        thesis_palm_grades(&combined, &finger_offsets)
    } else {
        vec![None; n]
    };
    let sorted_indices = sorted_by_grade(&palm);

    let reason = sorted_indices.is_empty().then(|| {
        explain(
            &domain,
            &diameter.diameters_mm,
            &curv,
            &combined,
            range,
            largest_span_mm,
            finger_span_mm,
        )
    });
    GradedDomain {
        domain,
        grades: Grades {
            curvature: curv,
            diameter: diam,
            combined,
            palm,
        },
        diameters_mm: diameter.diameters_mm,
        range,
        finger_offsets,
        largest_span_mm,
        sorted_indices,
        reason,
        curvature_relaxed: vec![false; n],
    }
}

/// Each finger's index offset below Finger_1's, in hand order, for a HeightStep of `step_mm`.
pub fn finger_offsets(hand: &Hand, step_mm: f64) -> Vec<i64> {
    let top = hand.finger_list.first().map_or(0.0, |f| f.height_mm);
    hand.finger_list
        .iter()
        .map(|f| ((top - f.height_mm) / step_mm).round() as i64)
        .collect()
}

/// The number of steps of the Largest Span Height: the longest run between consecutive
/// ungraspable indices of `combined`, the ends counting one step out (thesis 3.4.4).
fn largest_span_steps(combined: &[Grade]) -> i64 {
    let n = combined.len();
    let mut last_bad: i64 = 0;
    let mut largest = 0i64;
    for i in 1..=n as i64 + 1 {
        if i == n as i64 + 1 || combined[(i - 1) as usize].is_none() {
            largest = largest.max(i - last_bad);
            last_bad = i;
        }
    }
    largest
}

/// Palm grades under the extended rules: every finger on an index of the object, the inner
/// fingers on graded indices within the Effective Elevation (`offset_mm`, the finger offset,
/// inside the domain's span), the outer ones anywhere (an ungraded one counts 0).
fn extended_palm_grades(
    domain: &Domain,
    combined: &[Grade],
    finger_offsets: &[i64],
    offset_mm: f64,
) -> Vec<Grade> {
    let n = combined.len();
    let spread = *finger_offsets.iter().max().unwrap_or(&0);
    let low = *finger_offsets.iter().min().unwrap_or(&0);
    let mut palm: Vec<Grade> = vec![None; n];
    let o = offset_mm;
    let inner_range = [domain.span_mm[0] + o, domain.span_mm[1] - o];
    for (i0, slot) in palm.iter_mut().enumerate() {
        let i = i0 as i64;
        let mut sum = 0.0;
        let mut ok = true;
        for &off in finger_offsets {
            let j = i - off;
            if j < 0 || j >= n as i64 {
                ok = false;
                break;
            }
            let g = combined[j as usize];
            let is_outer = spread != low && (off == spread || off == low);
            let z = domain.elevations[j as usize];
            let inside = z >= inner_range[0] - 1e-9 && z <= inner_range[1] + 1e-9;
            if !is_outer && (g.is_none() || !inside) {
                ok = false;
                break;
            }
            sum += g.unwrap_or(0.0);
        }
        if ok {
            *slot = Some(sum / finger_offsets.len() as f64);
        }
    }
    palm
}

/// Palm grades under the thesis's rules: the mean combined grade of the fingers' indices where
/// every index the fingers span is graded.
fn thesis_palm_grades(combined: &[Grade], finger_offsets: &[i64]) -> Vec<Grade> {
    let n = combined.len();
    let spread = *finger_offsets.iter().max().unwrap_or(&0);
    let low = *finger_offsets.iter().min().unwrap_or(&0);
    let mut palm: Vec<Grade> = vec![None; n];
    for (i0, slot) in palm.iter_mut().enumerate() {
        let i = i0 as i64;
        let (lo, hi) = (i - spread, i - low);
        if lo < 0 || hi >= n as i64 {
            continue;
        }
        if (lo..=hi).any(|j| combined[j as usize].is_none()) {
            continue;
        }
        let sum: f64 = finger_offsets
            .iter()
            .map(|&o| combined[(i - o) as usize].unwrap_or(0.0))
            .sum();
        *slot = Some(sum / finger_offsets.len() as f64);
    }
    palm
}

/// Palm grades are sorted in units of one over this: grades closer than 1e-4 are equal.
const GRADE_RESOLUTION: f64 = 1e4;

/// The 1-based indices with a palm grade, best first (ties, to 1e-4: the higher index first).
fn sorted_by_grade(palm: &[Grade]) -> Vec<usize> {
    let mut sorted: Vec<(i64, usize)> = palm
        .iter()
        .enumerate()
        // Grades are compared at 1e-4: two elevations a symmetry makes equal differ by
        // round-off (1e-13), and a tapering handle's grades by 1e-7 a step, as much as a file
        // written in single precision in another frame moves them; neither must decide their
        // order in one frame and not another (issue 30).
        .filter_map(|(i, g)| g.map(|g| ((g * GRADE_RESOLUTION).round() as i64, i + 1)))
        .collect();
    sorted.sort_by(|a, b| b.0.cmp(&a.0).then(b.1.cmp(&a.1)));
    sorted.into_iter().map(|(_, i)| i).collect()
}

fn explain(
    domain: &Domain,
    diameters: &[f64],
    curvature: &[Grade],
    combined: &[Grade],
    range: GraspableRange,
    span: f64,
    finger_span: f64,
) -> String {
    let n = domain.elevations.len();
    if n == 0 {
        return "the effective elevation is empty: the object is shorter than twice the finger offset".to_string();
    }
    let [lo, hi] = range.used();
    let thin = diameters.iter().filter(|&&d| d < lo).count();
    let thick = diameters.iter().filter(|&&d| d > hi).count();
    let sharp = curvature.iter().filter(|g| g.is_none()).count();
    let bad = combined.iter().filter(|g| g.is_none()).count();
    if thin == n {
        let max = diameters.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        return format!(
            "too thin: every indexed elevation's effective diameter (at most {max:.1} mm) is below the smallest graspable diameter {lo:.1} mm"
        );
    }
    if thick == n {
        let min = diameters.iter().copied().fold(f64::INFINITY, f64::min);
        return format!(
            "too thick: every indexed elevation's effective diameter (at least {min:.1} mm) is above the largest graspable diameter {hi:.1} mm"
        );
    }
    if span <= finger_span {
        return format!(
            "first palm approach check failed: largest span height {span:.1} mm does not exceed the {finger_span:.1} mm between the outer fingers ({bad} of {n} elevations ungraspable: {thin} too thin, {thick} too thick, {sharp} by curvature)"
        );
    }
    format!(
        "no palm position has all its fingers on graspable elevations ({bad} of {n} ungraspable: {thin} too thin, {thick} too thick, {sharp} by curvature)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::kinematics::graspable_range;

    use crate::hand::thesis_for_tests as thesis_hand;

    /// Stage 3 on the D40 × 124 cylinder's domain (45 indexed elevations, 2.5 mm apart; the
    /// fingers 10 indices apart) with the given curvature and diameter grades per index.
    fn ranked(
        curvature: impl Fn(usize) -> Grade,
        diameter: impl Fn(usize) -> Grade,
    ) -> GradedDomain {
        let hand = thesis_hand();
        let params = PlannerParams::default();
        let domain = Domain::build(&crate::objects::cylinder(40.0, 124.0), &params, &hand);
        let n = domain.elevations.len();
        assert_eq!(n, 45);
        let diameter = DiameterGrades {
            diameters_mm: vec![40.0; n],
            grades: (1..=n).map(diameter).collect(),
        };
        let curvature = (1..=n).map(curvature).collect();
        rank(
            domain,
            curvature,
            diameter,
            graspable_range(&hand),
            &params,
            &hand,
        )
    }

    #[test]
    fn palm_positions_are_sorted_and_blocked() {
        type Case = (
            &'static str,
            fn(usize) -> Grade,
            fn(usize) -> Grade,
            Vec<usize>,
        );
        let table: [Case; 4] = [
            // Equal grades: every position with all three fingers inside, the higher first.
            (
                "uniform",
                |_| Some(1.0),
                |_| Some(1.0),
                (21..=45).rev().collect(),
            ),
            // Index 30 ungraspable: Finger_1 from 30 to 45 would put a finger on it or across it.
            (
                "one hole",
                |i| (i != 30).then_some(1.0),
                |_| Some(1.0),
                (21..=29).rev().collect(),
            ),
            // Thinner lower down grades better: the lowest position first.
            (
                "graded",
                |_| Some(1.0),
                |i| Some(1.0 / i as f64),
                (21..=45).collect(),
            ),
            // Ungraspable at 20 and 40: no span between them exceeds the fingers' 50 mm.
            (
                "no span",
                |i| (i != 20 && i != 40).then_some(1.0),
                |_| Some(1.0),
                vec![],
            ),
        ];
        for (name, curvature, diameter, expected) in table {
            let g = ranked(curvature, diameter);
            assert_eq!(g.sorted_indices, expected, "{name}");
            assert_eq!(g.finger_offsets, vec![0, 10, 20], "{name}");
            assert_eq!(
                g.reason.is_some(),
                expected.is_empty(),
                "{name}: {:?}",
                g.reason
            );
        }
    }

    #[test]
    fn grades_combine_with_the_significance_factor_and_palm_grades_average_the_fingers() {
        let g = ranked(|_| Some(1.0), |i| Some(i as f64 / 100.0));
        let sf = PlannerParams::default().sf_c;
        for i in [1, 21, 45] {
            let combined = sf + (1.0 - sf) * i as f64 / 100.0;
            let got = g.grades.combined[i - 1].unwrap();
            assert!(
                (got - combined).abs() < 1e-12,
                "index {i}: {got}, expected {combined}"
            );
        }
        // Finger_1 at 30: the fingers on 30, 20 and 10.
        let mean = [30.0, 20.0, 10.0]
            .iter()
            .map(|i| sf + (1.0 - sf) * i / 100.0)
            .sum::<f64>()
            / 3.0;
        let got = g.grades.palm[29].unwrap();
        assert!((got - mean).abs() < 1e-12, "{got}, expected {mean}");
        assert_eq!(g.grades.palm[19], None);
    }
}
