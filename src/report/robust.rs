//! The hold probability's part of the report, owned here: what `sim.robust` and `sim.replay`
//! write, with the conversions from the check's own types.
//!
//! Each conversion names every field of the type it reads, so a field renamed, added or removed
//! in `sim` fails to compile here instead of changing the JSON.

use super::check::Verdict;
use crate::sim::robust as sim;
use serde::Serialize;

/// One sample's perturbation (`sim.replay`, `sim.robust.first_failure.perturbation`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Perturbation {
    /// The sample's index.
    pub sample: usize,
    /// The object's translation relative to the hand before closing, aligned frame `[mm]`.
    pub offset_mm: [f64; 3],
    /// The object's rotation relative to the hand before closing, as a rotation vector `[deg]`.
    pub rotation_deg: [f64; 3],
    /// The friction coefficient's multiplier.
    pub friction_scale: f64,
    /// The object mass's multiplier.
    pub mass_scale: f64,
    /// The finger motors' torque limit's multiplier.
    pub torque_scale: f64,
}

impl From<&sim::Perturbation> for Perturbation {
    fn from(p: &sim::Perturbation) -> Perturbation {
        let sim::Perturbation {
            sample,
            offset_mm,
            rotation_deg,
            friction_scale,
            mass_scale,
            torque_scale,
        } = *p;
        Perturbation {
            sample,
            offset_mm,
            rotation_deg,
            friction_scale,
            mass_scale,
            torque_scale,
        }
    }
}

/// Counts of the verdicts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// Samples that held.
    pub hold: usize,
    /// Samples that slipped.
    pub slip: usize,
    /// Samples that dropped the object.
    pub drop: usize,
}

impl From<&sim::Counts> for Counts {
    fn from(c: &sim::Counts) -> Counts {
        let sim::Counts { hold, slip, drop } = *c;
        Counts { hold, slip, drop }
    }
}

/// The hold probability over one gravity direction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DirectionRobust {
    /// Gravity direction (unit, aligned frame).
    pub gravity: [f64; 3],
    /// The samples' verdicts under it.
    pub counts: Counts,
    /// The fraction that held.
    pub hold_probability: f64,
    /// Its 95 % Wilson interval.
    pub interval: [f64; 2],
    /// Samples that held under it with a closing that kept the planned grasp.
    pub held_as_planned: usize,
}

impl From<&sim::DirectionRobust> for DirectionRobust {
    fn from(d: &sim::DirectionRobust) -> DirectionRobust {
        let sim::DirectionRobust {
            gravity,
            counts,
            hold_probability,
            interval,
            held_as_planned,
        } = d;
        DirectionRobust {
            gravity: *gravity,
            counts: counts.into(),
            hold_probability: *hold_probability,
            interval: *interval,
            held_as_planned: *held_as_planned,
        }
    }
}

/// The first sample that did not hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FirstFailure {
    /// Its index.
    pub sample: usize,
    /// Its verdict (the worst over the directions).
    pub verdict: Verdict,
    /// The first direction that did not hold.
    pub gravity: [f64; 3],
    /// What was perturbed.
    pub perturbation: Perturbation,
}

impl From<&sim::FirstFailure> for FirstFailure {
    fn from(f: &sim::FirstFailure) -> FirstFailure {
        let sim::FirstFailure {
            sample,
            verdict,
            gravity,
            perturbation,
        } = f;
        FirstFailure {
            sample: *sample,
            verdict: (*verdict).into(),
            gravity: *gravity,
            perturbation: perturbation.into(),
        }
    }
}

/// The perturbation ranges a run drew from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ranges {
    /// `[mm]`, each coordinate.
    pub pose_offset_mm: f64,
    /// `[deg]`.
    pub pose_rotation_deg: f64,
    /// `[%]`.
    pub friction_range_pct: f64,
    /// `[%]`.
    pub mass_range_pct: f64,
    /// `[%]`.
    pub torque_range_pct: f64,
}

impl From<&sim::Ranges> for Ranges {
    fn from(r: &sim::Ranges) -> Ranges {
        let sim::Ranges {
            pose_offset_mm,
            pose_rotation_deg,
            friction_range_pct,
            mass_range_pct,
            torque_range_pct,
        } = *r;
        Ranges {
            pose_offset_mm,
            pose_rotation_deg,
            friction_range_pct,
            mass_range_pct,
            torque_range_pct,
        }
    }
}

/// The hold probability under perturbation (`sim.robust`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Robust {
    /// Perturbed checks run.
    pub samples: usize,
    /// `[sim] seed`.
    pub seed: u64,
    /// The ranges drawn from.
    pub ranges: Ranges,
    /// Each sample's verdict, the worst over its directions.
    pub counts: Counts,
    /// The fraction of samples that held in every direction.
    pub hold_probability: f64,
    /// Its 95 % Wilson interval `[lo, hi]`.
    pub interval: [f64; 2],
    /// Samples that held in every direction with a closing that kept the planned grasp.
    pub held_as_planned: usize,
    /// `held_as_planned / samples`.
    pub as_planned_probability: f64,
    /// Its 95 % Wilson interval `[lo, hi]`.
    pub as_planned_interval: [f64; 2],
    /// Per gravity direction.
    pub directions: Vec<DirectionRobust>,
    /// Each sample's verdict, in sample order.
    pub verdicts: Vec<Verdict>,
    /// Each sample's fidelity (`true`: its closing kept the planned grasp), in sample order.
    pub as_planned: Vec<bool>,
    /// The first sample that did not hold (`None`: all held).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_failure: Option<FirstFailure>,
    /// Physics steps over all samples.
    pub steps: usize,
    /// Wall time of the samples `[ms]`.
    pub wall_ms: f64,
}

impl From<&sim::Robust> for Robust {
    fn from(r: &sim::Robust) -> Robust {
        let sim::Robust {
            samples,
            seed,
            ranges,
            counts,
            hold_probability,
            interval,
            held_as_planned,
            as_planned_probability,
            as_planned_interval,
            directions,
            verdicts,
            as_planned,
            first_failure,
            steps,
            wall_ms,
            passes: _,
        } = r;
        Robust {
            samples: *samples,
            seed: *seed,
            ranges: ranges.into(),
            counts: counts.into(),
            hold_probability: *hold_probability,
            interval: *interval,
            held_as_planned: *held_as_planned,
            as_planned_probability: *as_planned_probability,
            as_planned_interval: *as_planned_interval,
            directions: directions.iter().map(DirectionRobust::from).collect(),
            verdicts: verdicts.iter().map(|&v| v.into()).collect(),
            as_planned: as_planned.clone(),
            first_failure: first_failure.as_ref().map(FirstFailure::from),
            steps: *steps,
            wall_ms: *wall_ms,
        }
    }
}

impl Robust {
    /// The summary's words: "held in 14 of 16 perturbed checks (88 %, 95 % interval 64–97 %)",
    /// and, when some of those holds were not as planned, "; as planned in 12 (75 %, 95 %
    /// interval 51–90 %)".
    pub fn in_words(&self) -> String {
        let pct = |x: f64| (100.0 * x).round();
        let mut words = format!(
            "held in {} of {} perturbed checks ({} %, 95 % interval {}–{} %)",
            self.counts.hold,
            self.samples,
            pct(self.hold_probability),
            pct(self.interval[0]),
            pct(self.interval[1])
        );
        if self.held_as_planned != self.counts.hold {
            words += &format!(
                "; as planned in {} ({} %, 95 % interval {}–{} %)",
                self.held_as_planned,
                pct(self.as_planned_probability),
                pct(self.as_planned_interval[0]),
                pct(self.as_planned_interval[1])
            );
        }
        words
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::robust::wilson;

    #[test]
    fn the_words_round_as_the_issue_writes_them() {
        let r = Robust {
            samples: 16,
            seed: 0,
            ranges: Ranges {
                pose_offset_mm: 2.0,
                pose_rotation_deg: 3.0,
                friction_range_pct: 15.0,
                mass_range_pct: 15.0,
                torque_range_pct: 10.0,
            },
            counts: Counts {
                hold: 14,
                slip: 2,
                drop: 0,
            },
            hold_probability: 14.0 / 16.0,
            interval: wilson(14, 16),
            held_as_planned: 14,
            as_planned_probability: 14.0 / 16.0,
            as_planned_interval: wilson(14, 16),
            directions: Vec::new(),
            verdicts: Vec::new(),
            as_planned: Vec::new(),
            first_failure: None,
            steps: 0,
            wall_ms: 0.0,
        };
        assert_eq!(
            r.in_words(),
            "held in 14 of 16 perturbed checks (88 %, 95 % interval 64–97 %)"
        );
        // 12 of the 14 holds as planned: 75 %, Wilson 51–90 %.
        let r = Robust {
            held_as_planned: 12,
            as_planned_probability: 12.0 / 16.0,
            as_planned_interval: wilson(12, 16),
            ..r
        };
        assert_eq!(
            r.in_words(),
            "held in 14 of 16 perturbed checks (88 %, 95 % interval 64–97 %); as planned in 12 \
             (75 %, 95 % interval 51–90 %)"
        );
    }
}
