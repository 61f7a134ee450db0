//! The check's entry points by what the caller wants: a candidate's check in the candidate
//! search and its full re-check ([`search`], [`search_in_full`]), the check of the chosen grasp
//! as reported ([`reported`]), and a labelled grasp's checks one at a time ([`labelled`],
//! [`labelled_sample`]). Which of them runs in full, replays a sample or adds the samples is
//! decided here, not by the callers.
//!
//! `[sim] closing_decides` acts in [`search`] only: every other check holds every direction
//! under gravity (the perturbed samples too, [`super::robust::Perturbed`]). `[sim]
//! replay_sample` acts in [`reported`] only: the candidate search checks the case as given, so
//! that a replay checks the grasp the run without it chose.

use super::outcome::{SimOutcome, Verdict};
use super::params::{Choose, Protocol};
use super::payload::{check_with_payload, payload_bracket};
use super::protocol::check;
use super::robust::{check_sample, sample, Perturbation, Perturbed};
use super::scene::Case;

/// A candidate's check in the candidate search: the case as given (never `[sim]
/// replay_sample`'s perturbation), decided at the closing when `[sim] closing_decides` is on and
/// the closing left the plan; with `choose = "robust"` and more than one sample, the samples
/// too.
pub fn search(case: &Case) -> SimOutcome {
    let mut out = check(case);
    let rp = &case.params.robust;
    if rp.samples > 1 && rp.choose == Choose::Robust {
        out.robust = Some(sample(case));
    }
    out
}

/// The search's first check under `[sim] order_by_closing` ([`crate::select::SelectParams::probe`]):
/// [`search`], except that a closing that left the plan decides the check at once, gravity
/// never on (as under `[sim] closing_decides`): the closings' order then decides what is
/// checked, and the hold of this grasp runs only if that order comes back to it. Where the
/// closing kept the plan the hold runs as in [`search`], to the bit: the setting acts only on
/// a failed closing ([`super::hold`]). In full under the `full` protocol, and under `choose =
/// "robust"` with samples, whose success is the samples' and not the closing's.
pub fn search_probe(case: &Case) -> SimOutcome {
    let rp = &case.params.robust;
    let robust = rp.samples > 1 && rp.choose == Choose::Robust;
    if robust || case.params.protocol != Protocol::Fast {
        return search(case);
    }
    with_closing_decides(case, true, check)
}

/// [`search`] in full, whatever `[sim] closing_decides` says: the re-check of a candidate the
/// closing decided, and every check of a parameter sweep.
pub fn search_in_full(case: &Case) -> SimOutcome {
    in_full(case, search)
}

/// The closing alone, gravity off, as every check of `case` starts (`[sim] order_by_closing`):
/// its fidelity.
pub fn closing_fidelity(case: &Case) -> super::outcome::Fidelity {
    super::protocol::Closed::new(case).fidelity().clone()
}

/// Where `[sim] order_samples`'s perturbations are drawn from: sample indices this far past any
/// the hold probability draws (`[sim] samples` is at most a few hundred), so that the closings
/// that order a search never see the samples that then judge its grasp.
pub const ORDER_SAMPLE_BASE: usize = 1 << 30;

/// How many of `m` perturbed closings of `case` (`[sim] order_samples`), gravity off, kept the
/// plan: sample `ORDER_SAMPLE_BASE + j`'s perturbation for `j` in `0..m`.
pub fn sampled_closings_on_plan(case: &Case, m: usize) -> usize {
    use rayon::prelude::*;
    (0..m)
        .into_par_iter()
        .filter(|&j| {
            let p = Perturbation::draw(&case.params.robust, ORDER_SAMPLE_BASE + j);
            let perturbed = Perturbed::of(case, &p);
            closing_fidelity(&perturbed.case(case)).as_planned
        })
        .count()
}

/// The check of a chosen grasp as reported.
#[derive(Debug, Clone)]
pub struct Reported {
    /// The main check, with the samples when `[sim] samples` is above 1.
    pub outcome: SimOutcome,
    /// The payload search's bracket ([`payload_bracket`]) when asked for and the grasp held.
    pub payload: Option<(f64, Option<f64>)>,
}

/// The check of the chosen grasp `case` as reported, in full whatever `[sim] closing_decides`
/// says: under `[sim] replay_sample = k`, the check under sample k's perturbation (`replay`);
/// with `payload`, the payload search when the grasp held; with `[sim] samples` above 1, the
/// samples. `searched` is the candidate search's outcome for the same case, reused rather than
/// checked again (its payload search follows its own verdict).
pub fn reported(case: &Case, searched: Option<SimOutcome>, payload: bool) -> Reported {
    in_full(case, |case| {
        let bracket = |out: &SimOutcome| {
            (payload && out.verdict == Verdict::Hold).then(|| payload_bracket(case))
        };
        let (mut outcome, payload) = match searched {
            Some(out) => {
                let payload = bracket(&out);
                (out, payload)
            }
            None if case.params.robust.replay_sample.is_some() => {
                let out = replayed(case);
                let payload = bracket(&out);
                (out, payload)
            }
            None => check_with_payload(case, payload),
        };
        add_samples(case, &mut outcome);
        Reported { outcome, payload }
    })
}

/// The main check of a labelled grasp (`grasp-sim label`, `check --grasps`): the case as given,
/// `[sim] closing_decides` included, never `[sim] replay_sample`'s perturbation.
pub fn labelled(case: &Case) -> SimOutcome {
    check(case)
}

/// Sample `k`'s check of a labelled grasp, in full: one of the checks the samples of
/// [`reported`] run, for a caller that spreads the samples of several grasps over the cores
/// itself; [`super::robust::robust_of`] counts them.
pub fn labelled_sample(case: &Case, k: usize) -> (Perturbation, SimOutcome) {
    check_sample(case, k)
}

/// `f` of `case` with `[sim] closing_decides` off.
fn in_full<R>(case: &Case, f: impl FnOnce(&Case) -> R) -> R {
    with_closing_decides(case, false, f)
}

/// `f` of `case` with `[sim] closing_decides` set to `on`.
fn with_closing_decides<R>(case: &Case, on: bool, f: impl FnOnce(&Case) -> R) -> R {
    if case.params.hold.closing_decides == on {
        return f(case);
    }
    let mut params = case.params.clone();
    params.hold.closing_decides = on;
    f(&Case {
        params: &params,
        ..*case
    })
}

/// The main check of `case`: the protocol's, or with `[sim] replay_sample = k`, under sample
/// `k`'s perturbation (reported in `replay`).
fn replayed(case: &Case) -> SimOutcome {
    match case.params.robust.replay_sample {
        None => check(case),
        Some(k) => {
            let p = Perturbation::draw(&case.params.robust, k);
            let perturbed = Perturbed::of(case, &p);
            let mut out = check(&perturbed.case(case));
            out.replay = Some(p);
            out
        }
    }
}

/// Completes `out`, the main check of the chosen grasp `case`: with `[sim] replay_sample = k`,
/// replaces it by the check under sample k's perturbation unless it already is that (the
/// candidate search checks the case as given); then adds the samples when `[sim] samples` asks
/// for more than one and they have not run yet.
fn add_samples(case: &Case, out: &mut SimOutcome) {
    if case.params.robust.replay_sample.is_some() && out.replay.is_none() {
        let robust = out.robust.take();
        *out = replayed(case);
        out.robust = robust;
    }
    if case.params.robust.samples > 1 && out.robust.is_none() {
        out.robust = Some(sample(case));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::params::SimParams;
    use crate::sim::{ObjectShape, SimHand};
    use nalgebra::{Point3, Vector3};

    #[test]
    fn only_the_search_sees_closing_decides() {
        let hand = crate::hand::thesis_for_tests();
        let mesh = crate::objects::cylinder(40.0, 124.0);
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let object = ObjectShape::from_mesh(&mesh, volume);
        let mut params = SimParams::default();
        params.hold.closing_decides = true;
        let pose = SimHand {
            origin_mm: Point3::new(-20.0, 0.0, 62.0),
            axes: [-Vector3::x(), -Vector3::y(), Vector3::z()],
            theta_deg: vec![[72.11, 91.81]; 3],
            planned_contacts_mm: Vec::new(),
        };
        let case = Case {
            hand: &hand,
            pose: &pose,
            object: &object,
            mass_kg: 0.08,
            friction: 0.3,
            params: &params,
        };
        let seen = std::cell::Cell::new(None);
        in_full(&case, |c| seen.set(Some(c.params.hold.closing_decides)));
        assert_eq!(seen.get(), Some(false));
        assert!(case.params.hold.closing_decides);
    }
}
