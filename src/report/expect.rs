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
    ///
    /// Then, in order, each further expectation given, while all so far are met: `as_planned`
    /// (the fidelity of the check reported), `min_hold_probability` and
    /// `min_as_planned_probability` (each on its 95 % lower bound).
    pub fn judge(expect: &Expect, plan: &PlanReport, sim: &SimReport) -> ExpectReport {
        let mut report = Self::judge_verdict(expect, plan, sim);
        if expect.outcome == Outcome::Ungraspable {
            return report;
        }
        let mut further: Vec<Box<dyn Fn() -> (bool, String)>> = Vec::new();
        if expect.as_planned {
            further.push(Box::new(|| judge_as_planned(sim)));
        }
        if let Some(p) = expect.min_hold_probability {
            further.push(Box::new(move || judge_probability(p, sim, Question::Hold)));
        }
        if let Some(p) = expect.min_as_planned_probability {
            further.push(Box::new(move || {
                judge_probability(p, sim, Question::AsPlanned)
            }));
        }
        for judge in further {
            if report.met != Some(true) {
                break;
            }
            let (met, words) = judge();
            report.met = Some(met);
            report.details = format!("{}; {words}", report.details);
        }
        report
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
                met: Some(verdict.is_some() && verdict == expect.outcome.verdict().map(Into::into)),
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

/// Which probability an expectation judges.
#[derive(Clone, Copy)]
enum Question {
    /// `min_hold_probability`: the samples that held.
    Hold,
    /// `min_as_planned_probability`: the samples that held with a closing that kept the plan.
    AsPlanned,
}

/// `[expect] as_planned = true` against the check reported: its closing kept the planned grasp.
fn judge_as_planned(sim: &SimReport) -> (bool, String) {
    match &sim.fidelity {
        Some(f) if f.as_planned => (true, "as planned".to_string()),
        Some(f) => {
            let reasons: Vec<&str> = f.reasons.iter().map(|r| r.as_str()).collect();
            (
                false,
                format!(
                    "NOT as planned ({}), expected as planned",
                    reasons.join(", ")
                ),
            )
        }
        None => (
            false,
            "fidelity not measured (physics check not run); expected as planned".to_string(),
        ),
    }
}

/// `[expect] min_hold_probability = p` (or `min_as_planned_probability`) against the check:
/// the 95 % Wilson lower bound of the probability must reach `p`. With one sample (no
/// `sim.robust`) the main check is the one sample; a check that did not run cannot meet it.
fn judge_probability(p: f64, sim: &SimReport, q: Question) -> (bool, String) {
    let (what, key) = match q {
        Question::Hold => ("held", "hold probability"),
        Question::AsPlanned => ("held as planned", "probability of a hold as planned"),
    };
    let (held, n, lo) = match (&sim.robust, sim.verdict.verdict()) {
        (Some(r), _) => match q {
            Question::Hold => (r.counts.hold, r.samples, r.interval[0]),
            Question::AsPlanned => (r.held_as_planned, r.samples, r.as_planned_interval[0]),
        },
        (None, Some(v)) => {
            let as_planned = sim.fidelity.as_ref().is_some_and(|f| f.as_planned);
            let held = usize::from(
                v == super::Verdict::Hold
                    && (matches!(q, Question::Hold) || as_planned),
            );
            (held, 1, crate::sim::robust::wilson(held, 1)[0])
        }
        (None, None) => {
            return (
                false,
                format!("{key} not measured (physics check not run); expected a lower bound of at least {p}"),
            )
        }
    };
    let words = format!(
        "{what} in {held} of {n} perturbed checks, 95 % lower bound {lo:.3} (expected at least {p})"
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
        Some(v) if expected.verdict().map(super::Verdict::from) == Some(v) => {
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
