//! Stage 2: grading by Effective Diameter (thesis 3.4.3.2, Fig. 3.16).
//!
//! The thickness of a vertical slice at an indexed elevation is the distance between its outermost
//! left and right crossings (found once, by stage 1: [`Domain::crossings`]); the Effective Diameter
//! is its mean over the slices. An elevation whose Effective Diameter lies outside the graspable
//! range is ungraspable. The others are graded by the smallest graspable Effective Diameter among
//! them divided by their own, so the thinnest graspable elevation grades 1 and thicker ones less
//! ("normalised by their least graspable value"; smaller is better for an enveloping grasp).

use super::{Domain, Grade};

/// Effective Diameter grades of the indexed elevations.
#[derive(Debug, Clone, PartialEq)]
pub struct DiameterGrades {
    /// Effective Diameter per indexed elevation `[mm]` (NaN where no slice is cut).
    pub diameters_mm: Vec<f64>,
    /// Grade per indexed elevation; `None` when out of the graspable range.
    pub grades: Vec<Grade>,
}

/// Grades every indexed elevation of `domain` against the graspable `range` `[min, max]` `[mm]`.
pub fn grade_elevations(domain: &Domain, range: [f64; 2]) -> DiameterGrades {
    let diameters_mm: Vec<f64> = domain
        .crossings
        .iter()
        .map(|row| {
            let mut sum = 0.0;
            let mut n = 0usize;
            for (l, r) in row.iter().flatten() {
                sum += r.point.x - l.point.x;
                n += 1;
            }
            if n == domain.slices.len() && n > 0 {
                sum / n as f64
            } else {
                f64::NAN
            }
        })
        .collect();
    let in_range = |d: f64| d.is_finite() && d >= range[0] && d <= range[1];
    let least = diameters_mm
        .iter()
        .copied()
        .filter(|&d| in_range(d))
        .fold(f64::INFINITY, f64::min);
    let grades = diameters_mm
        .iter()
        .map(|&d| in_range(d).then(|| least / d))
        .collect();
    DiameterGrades {
        diameters_mm,
        grades,
    }
}
