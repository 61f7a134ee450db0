//! Judging a scenario's `[expect]`: the planning part (status and reference values within
//! their tolerances), then the physics check's verdict against the expected outcome.

use super::{ExpectReport, GraspReport, GraspSource, PlanReport, SimReport, SimVerdict};
use crate::scenario::{Expect, Outcome};

impl ExpectReport {
    /// The report when there is no expectation: nothing judged.
    pub fn none() -> ExpectReport {
        ExpectReport {
            outcome: None,
            met: None,
            details: "no expectation given ([expect] absent): nothing judged".to_string(),
        }
    }

    /// Returns true if and only if there was an expectation to judge.
    pub fn is_given(&self) -> bool {
        self.outcome.is_some()
    }

    /// The expected outcome's name, or `none`.
    pub fn outcome_name(&self) -> &'static str {
        self.outcome.map_or("none", Outcome::as_str)
    }

    /// Judges `[expect]`: the planning part (status and reference values), then, when the
    /// physics check ran, its verdict against the expected outcome. A scenario that fixes the
    /// joint angles (`override_angles`) or checks a given grasp is judged on the verdict alone.
    pub fn judge(expect: &Expect, plan: &PlanReport, sim: &SimReport) -> ExpectReport {
        let report = Self::judge_verdict(expect, plan, sim);
        match (expect.min_hold_probability, report.met) {
            (Some(p), Some(true)) if expect.outcome != Outcome::Ungraspable => {
                let (met, words) = judge_probability(p, sim);
                ExpectReport {
                    met: Some(met),
                    details: format!("{}; {words}", report.details),
                    ..report
                }
            }
            _ => report,
        }
    }

    /// [`ExpectReport::judge`] without `min_hold_probability`.
    fn judge_verdict(expect: &Expect, plan: &PlanReport, sim: &SimReport) -> ExpectReport {
        let outcome = Some(expect.outcome);
        let sim_only = match sim.grasp_source {
            Some(GraspSource::OverrideAngles) => Some("override_angles"),
            Some(GraspSource::Given) => Some("given grasp"),
            _ => None,
        };
        if let Some(why) = sim_only {
            let verdict = sim.verdict.verdict();
            return ExpectReport {
                outcome,
                met: Some(verdict.is_some() && verdict == expect.outcome.verdict()),
                details: format!("sim-only ({why}): verdict {}", sim.verdict),
            };
        }
        let (met, details) = match (expect.outcome, &plan.grasp) {
            (Outcome::Ungraspable, None) => (true, "planner: ungraspable, as expected".to_string()),
            (Outcome::Ungraspable, Some(_)) => (
                false,
                "planner found a feasible grasp; expected ungraspable".to_string(),
            ),
            (_, None) => (false, format!("planner: {}; expected a grasp", plan.status)),
            (_, Some(g)) => {
                let misses = planning_misses(expect, g);
                if !misses.is_empty() {
                    let misses = misses.join("; ");
                    (false, format!("planning part not met: {misses}"))
                } else {
                    judge_check(expect.outcome, &sim.verdict)
                }
            }
        };
        ExpectReport {
            outcome,
            met: Some(met),
            details,
        }
    }
}

/// `[expect] min_hold_probability = p` against the check: the 95 % Wilson lower bound of the
/// hold probability must reach `p`. With one sample (no `sim.robust`) the main check is the one
/// sample; a check that did not run cannot meet it.
fn judge_probability(p: f64, sim: &SimReport) -> (bool, String) {
    let (held, n, lo) = match (&sim.robust, sim.verdict.verdict()) {
        (Some(r), _) => (r.counts.hold, r.samples, r.interval[0]),
        (None, Some(v)) => {
            let held = usize::from(v == crate::sim::Verdict::Hold);
            (held, 1, crate::sim::robust::wilson(held, 1)[0])
        }
        (None, None) => {
            return (
                false,
                format!("hold probability not measured (physics check not run); expected a lower bound of at least {p}"),
            )
        }
    };
    let words = format!(
        "held in {held} of {n} perturbed checks, 95 % lower bound {lo:.3} (expected at least {p})"
    );
    (lo >= p, words)
}

/// Once the planning part is met: the physics check's verdict against the expected outcome.
fn judge_check(expected: Outcome, verdict: &SimVerdict) -> (bool, String) {
    match verdict.verdict() {
        None => (
            true,
            "planning part met (feasible, reference values within tolerance); physics check \
             not run"
                .to_string(),
        ),
        Some(v) if expected.verdict() == Some(v) => {
            (true, format!("planning part met; physics check: {v}"))
        }
        Some(v) => (
            false,
            format!("physics check: {v}, expected {}", expected.as_str()),
        ),
    }
}

/// The reference values of `expect` that the grasp misses, each in words.
fn planning_misses(expect: &Expect, g: &GraspReport) -> Vec<String> {
    let mut misses = Vec::new();
    if let Some(a) = expect.approach_angle_deg {
        if (g.approach_angle_deg - a).abs() > 1e-9 {
            misses.push(format!(
                "approach {} deg (expected {a})",
                g.approach_angle_deg
            ));
        }
    }
    if let Some(p) = expect.palm_pitch_deg {
        if (g.palm_pitch_deg - p).abs() > expect.pitch_tolerance_deg {
            misses.push(format!(
                "pitch {:.1} deg (expected {p} +- {})",
                g.palm_pitch_deg, expect.pitch_tolerance_deg
            ));
        }
    }
    if let Some(i) = expect.elevation_index {
        if (g.elevation_index as i64 - i).abs() > expect.index_tolerance {
            misses.push(format!(
                "index {} (expected {i} +- {})",
                g.elevation_index, expect.index_tolerance
            ));
        }
    }
    if let Some(t) = &expect.theta_deg {
        let tol2 = expect
            .theta2_tolerance_deg
            .unwrap_or(expect.theta_tolerance_deg);
        for (f, [t1, t2]) in g.fingers.iter().zip(t) {
            for (got, want, which, tol) in [
                (f.theta1_deg, *t1, "theta1", expect.theta_tolerance_deg),
                (f.theta2_deg, *t2, "theta2", tol2),
            ] {
                if (got - want).abs() > tol {
                    misses.push(format!(
                        "{} {which} {got:.1} (expected {want} +- {tol})",
                        f.name
                    ));
                }
            }
        }
    }
    misses
}
