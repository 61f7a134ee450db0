//! The hold test: close, gravity on, hold, measure, judge.
//!
//! Two protocols (`[sim] protocol`, docs/SIM.md): `full`, the reference, builds and closes a
//! fresh scene for every gravity direction and payload multiplier and holds each direction for
//! the whole `duration_s`; `fast` (the default) closes once, continues every direction and
//! payload multiplier from a copy of the closed scene ([`Scene::branch`]), ends a direction as
//! soon as its verdict can no longer change ([`EarlyDecision`]), and runs the directions in
//! parallel (each on its own copy, so the result does not depend on the number of threads).
//!
//! This file holds the two protocols' drivers; the parts are in [`super::closing`],
//! [`super::hold`] (with [`super::early`] and [`super::flight`]), [`super::payload`], and the
//! types reported in [`super::outcome`].

use super::closing::{close, Closing};
use super::hold::hold;
use super::outcome::{ClosingOutcome, DirectionOutcome, SimOutcome};
use super::params::{GravityMode, Protocol, SimParams};
use super::scene::{build, poses, Case, Scene};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::time::Instant;

pub use super::closing::{Stall, STALL};
pub use super::early::{EarlyDecision, RestFrame, SAMPLE_S};
pub use super::hold::{traced, HoldTrace};
pub use super::outcome::{DecidedBy, FingerClosing, FirstTouch, Verdict, WITHIN_PLAN_DEG};
pub use super::payload::{check_with_payload, payload_bracket, payload_margin};

/// The gravity directions of `mode` (unit, aligned frame).
fn directions(mode: GravityMode) -> Vec<Vector3<f64>> {
    match mode {
        GravityMode::Down => vec![-Vector3::z()],
        GravityMode::Six => vec![
            Vector3::x(),
            -Vector3::x(),
            Vector3::y(),
            -Vector3::y(),
            Vector3::z(),
            -Vector3::z(),
        ],
    }
}

/// A scene with the hand closed on the object and gravity still off: the state every gravity
/// direction and payload multiplier of the `fast` protocol continues from.
pub struct Closed {
    scene: Scene,
    closing: Closing,
}

impl Closed {
    /// Builds the scene of `case` and closes the hand.
    pub fn new(case: &Case) -> Closed {
        let mut scene = build(case);
        let closing = close(&mut scene, case);
        Closed { scene, closing }
    }

    /// The steps the closing took.
    pub fn steps(&self) -> usize {
        self.closing.steps
    }

    /// What the closing did to the plan.
    pub fn fidelity(&self) -> &super::outcome::Fidelity {
        &self.closing.fidelity
    }
}

/// Runs the hold test for every gravity direction of `params.gravity`, by `params.protocol`.
///
/// The rotation judged is the full rotation relative to the palm, except for an object that is
/// (inertially) a body of revolution about its principal axis (`object.is_revolution`): a spin
/// about that axis leaves it occupying the same space in the hand, so only the tilt of the axis
/// counts.
pub fn check(case: &Case) -> SimOutcome {
    match case.params.protocol {
        Protocol::Full => check_full(case),
        Protocol::Fast => {
            let t0 = Instant::now();
            let closed = Closed::new(case);
            check_closed(&closed, case, 1.0, t0)
        }
    }
}

/// The `full` protocol: a fresh scene per direction, closed, held for the whole `duration_s`.
pub(super) fn check_full(case: &Case) -> SimOutcome {
    let params = case.params;
    let t0 = Instant::now();
    let mut outcomes = Vec::new();
    let mut steps = 0;
    let mut final_poses = Vec::new();
    let mut first_closing: Option<Closing> = None;
    let mut fidelity: Option<super::outcome::Fidelity> = None;
    for g in directions(params.gravity) {
        let mut scene = build(case);
        let closing = close(&mut scene, case);
        match fidelity.as_mut() {
            None => fidelity = Some(closing.fidelity.clone()),
            Some(f) => f.merge(&closing.fidelity),
        }
        first_closing.get_or_insert_with(|| closing.clone());
        let (o, n) = hold(
            &mut scene,
            g,
            params,
            &closing,
            case.object.is_revolution,
            None,
        );
        if final_poses.is_empty() {
            final_poses = poses(&scene);
        }
        outcomes.push(o);
        steps += closing.steps + n;
    }
    let closing = first_closing.expect("at least one direction");
    SimOutcome {
        grip_contacts: closing.contacts,
        closing: closing.outcome,
        closed_poses: closing.poses,
        fidelity: fidelity.expect("at least one direction"),
        ..summarise(outcomes, steps, params, t0, final_poses)
    }
}

/// The `fast` protocol from a closed scene, with the object's mass multiplied by `k`: each
/// direction on its own copy of the closed scene, decided early, in parallel.
pub fn check_closed(closed: &Closed, case: &Case, k: f64, t0: Instant) -> SimOutcome {
    let params = case.params;
    let rule = EarlyDecision::from_params(params);
    let runs: Vec<(DirectionOutcome, usize, Vec<super::BodyPose>)> = directions(params.gravity)
        .into_par_iter()
        .map(|g| {
            let mut scene = closed.scene.branch();
            if k != 1.0 {
                scene.set_object_mass(case.mass_kg * k);
            }
            let (o, n) = hold(
                &mut scene,
                g,
                params,
                &closed.closing,
                case.object.is_revolution,
                Some(&rule),
            );
            (o, n, poses(&scene))
        })
        .collect();
    let steps = closed.closing.steps + runs.iter().map(|r| r.1).sum::<usize>();
    let final_poses = runs[0].2.clone();
    SimOutcome {
        grip_contacts: closed.closing.contacts.clone(),
        closing: closed.closing.outcome.clone(),
        closed_poses: closed.closing.poses.clone(),
        fidelity: closed.closing.fidelity.clone(),
        ..summarise(
            runs.into_iter().map(|r| r.0).collect(),
            steps,
            params,
            t0,
            final_poses,
        )
    }
}

fn summarise(
    outcomes: Vec<DirectionOutcome>,
    steps: usize,
    params: &SimParams,
    t0: Instant,
    final_poses: Vec<super::BodyPose>,
) -> SimOutcome {
    let worst = outcomes
        .iter()
        .max_by(|a, b| {
            a.verdict
                .cmp(&b.verdict)
                .then(a.translation_mm.total_cmp(&b.translation_mm))
        })
        .expect("at least one direction")
        .clone();
    SimOutcome {
        verdict: worst.verdict,
        fidelity: super::outcome::Fidelity {
            as_planned: true,
            shift_mm: 0.0,
            turn_deg: 0.0,
            phalanges_on_plan: 0,
            phalanges: 0,
            worst_joint_error_deg: 0.0,
            penetration_mm: 0.0,
            reasons: Vec::new(),
        },
        translation_mm: worst.translation_mm,
        rotation_deg: worst.rotation_deg,
        simulated_s: steps as f64 * params.solver.timestep_s,
        steps,
        directions: outcomes,
        wall_ms: t0.elapsed().as_secs_f64() * 1000.0,
        final_poses,
        grip_contacts: Vec::new(),
        closing: ClosingOutcome {
            shift_mm: 0.0,
            turn_deg: 0.0,
            duration_s: 0.0,
            max_shift_mm: params.hold.max_closing_shift_mm,
            pushed: false,
            first_touch: None,
            palm_touching: false,
            fingers: Vec::new(),
            phalanges_on_plan: 0,
            min_on_plan: 0,
            off_plan: false,
        },
        closed_poses: Vec::new(),
        robust: None,
        replay: None,
    }
}
