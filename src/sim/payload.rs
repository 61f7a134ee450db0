//! The payload search (`--payload`): the largest multiple of the object's mass, up to 64, at
//! which the grasp still holds, by doubling then bisection to 5 %; under the `fast` protocol
//! every multiplier continues from one closing (docs/SIM.md, "Payload from one closing").

use super::outcome::{SimOutcome, Verdict};
use super::params::Protocol;
use super::protocol::{check, check_closed, check_full, Closed};
use super::scene::Case;
use std::time::Instant;

/// The physics check and, if `payload`, the payload search of [`payload_bracket`] (only when
/// the grasp holds), sharing one closing under the `fast` protocol.
pub fn check_with_payload(case: &Case, payload: bool) -> (SimOutcome, Option<(f64, Option<f64>)>) {
    match case.params.protocol {
        Protocol::Full => {
            let out = check_full(case);
            let bracket = (payload && out.verdict == Verdict::Hold).then(|| payload_bracket(case));
            (out, bracket)
        }
        Protocol::Fast => {
            let t0 = Instant::now();
            let closed = Closed::new(case);
            let out = check_closed(&closed, case, 1.0, t0);
            let bracket = (payload && out.verdict == Verdict::Hold)
                .then(|| payload_bracket_closed(&closed, case));
            (out, bracket)
        }
    }
}

/// The largest mass multiplier, up to 64, at which the grasp still holds: doubling until it
/// fails, then bisecting to a relative 5 %. Returns 64 if it holds at 64×.
pub fn payload_margin(case: &Case) -> f64 {
    payload_bracket(case).0
}

/// The payload search of [`payload_margin`], with the bracket it ends on: the largest
/// multiplier seen to hold and the one seen to fail just above it (within 5 %), or `None` if
/// the grasp held at 64×. Under the `full` protocol every multiplier builds and closes a fresh
/// scene with the heavier object; under `fast` every multiplier continues from one closing
/// with the scenario's mass, the object made heavier as gravity comes on (the grasp as it was
/// made, loaded: docs/SIM.md, "Payload from one closing").
pub fn payload_bracket(case: &Case) -> (f64, Option<f64>) {
    match case.params.protocol {
        Protocol::Full => search(|k| check(&case.heavier(k)).verdict),
        Protocol::Fast => payload_bracket_closed(&Closed::new(case), case),
    }
}

/// [`payload_bracket`] under the `fast` protocol, from a closed scene.
fn payload_bracket_closed(closed: &Closed, case: &Case) -> (f64, Option<f64>) {
    search(|k| check_closed(closed, case, k, Instant::now()).verdict)
}

/// Doubling from 2× until `verdict` is not `hold` (or 64× holds), then bisection to 5 %.
///
/// The doubling evaluates two multipliers at once (k and 2k, on rayon's threads) and reads them
/// in order, as the one-at-a-time search would: 2k is wasted when k fails. `verdict` of a
/// multiplier does not depend on what else runs, so the bracket is the sequential search's.
fn search(verdict: impl Fn(f64) -> Verdict + Sync) -> (f64, Option<f64>) {
    let holds = |k: f64| verdict(k) == Verdict::Hold;
    let mut lo = 1.0;
    let mut hi = None;
    let mut k = 2.0;
    while k <= 64.0 {
        let (at_k, at_2k) = if 2.0 * k <= 64.0 {
            let (a, b) = rayon::join(|| holds(k), || holds(2.0 * k));
            (a, Some(b))
        } else {
            (holds(k), None)
        };
        if !at_k {
            hi = Some(k);
            break;
        }
        lo = k;
        match at_2k {
            Some(true) => {
                lo = 2.0 * k;
                k *= 4.0;
            }
            Some(false) => {
                hi = Some(2.0 * k);
                break;
            }
            None => k *= 2.0,
        }
    }
    let Some(mut hi) = hi else {
        return (64.0, None);
    };
    while hi / lo > 1.05 {
        let mid = (lo * hi).sqrt();
        if holds(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, Some(hi))
}
