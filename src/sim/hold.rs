//! The hold: gravity on along one direction, the object's motion relative to the palm sampled,
//! the direction decided at the end of `duration_s` or, under the `fast` protocol, as soon as the
//! verdict can no longer change (the rest rule of [`super::early`], the drop tests of
//! [`super::flight`]); and the traces of full-length holds for the study of the rest rule.

use super::closing::Closing;
use super::contacts::touches_hand;
use super::early::{rotations, EarlyDecision, RestFrame, SAMPLE_S};
use super::flight::{clear_of_hand, hand_speed, out_of_reach, HAND_REST_M_S};
use super::outcome::{DecidedBy, DirectionOutcome, Verdict};
use super::params::SimParams;
use super::scene::{relative, Scene};
use nalgebra::{UnitQuaternion, Vector3};
use rapier3d::prelude::*;

/// Standard gravity `[m/s²]`.
const G: f64 = 9.81;

/// A full-length hold's samples (one every [`SAMPLE_S`]) and outcome, collected by [`traced`]
/// for the study of the rest rule (`examples/early_rule.rs`).
#[derive(Debug, Clone)]
pub struct HoldTrace {
    /// What the samples are measured against.
    pub frame: RestFrame,
    /// The object's pose relative to the palm, one per sample.
    pub samples: Vec<(Vector3<f64>, UnitQuaternion<f64>)>,
    /// The finger joints' angles `[deg]`, one list per sample.
    pub joints: Vec<Vec<f64>>,
    /// Four times finer ([`HoldTrace::fine_dt`]): the pose relative to the palm and how near
    /// the hand's contacts were to sliding, for the study of other rules.
    pub fine: Vec<(
        Vector3<f64>,
        UnitQuaternion<f64>,
        super::contacts::FrictionUse,
    )>,
    /// Time between fine samples `[s]`.
    pub fine_dt: f64,
    /// The hold's length `[s]`.
    pub duration_s: f64,
    /// Its outcome.
    pub outcome: DirectionOutcome,
}

thread_local! {
    static TRACES: std::cell::RefCell<Option<Vec<HoldTrace>>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `f`, collecting the trace of every full-length hold (`protocol = "full"`) it runs on
/// this thread.
pub fn traced<R>(f: impl FnOnce() -> R) -> (R, Vec<HoldTrace>) {
    TRACES.with(|t| *t.borrow_mut() = Some(Vec::new()));
    let r = f();
    let traces = TRACES.with(|t| t.borrow_mut().take()).unwrap_or_default();
    (r, traces)
}

/// Turns gravity on along `gravity` and holds, at `hold_solver_iterations` substeps a step: to
/// the end of `duration_s`, or with `early` until the verdict can no longer change. Returns the
/// outcome and the steps taken.
pub(super) fn hold(
    scene: &mut Scene,
    gravity: Vector3<f64>,
    params: &SimParams,
    closing: &Closing,
    is_revolution: bool,
    early: Option<&EarlyDecision>,
) -> (DirectionOutcome, usize) {
    let dt = params.solver.timestep_s;
    let hold_steps = (params.hold.duration_s / dt).round() as usize;
    let g = gravity * G;
    scene.world.gravity = Vector::new(g.x as f32, g.y as f32, g.z as f32);
    scene.world.integration_parameters.num_solver_iterations = params.solver.hold_substeps();
    let sample_every = ((SAMPLE_S / dt).round() as usize).max(1);
    let tracing = TRACES.with(|t| t.borrow().is_some());
    let frame = RestFrame {
        pc: closing.pc,
        qc: closing.qc,
        is_revolution,
        sample_dt: sample_every as f64 * dt,
    };
    // Samples of the object's pose relative to the palm, for the rest rule.
    let mut samples: Vec<(Vector3<f64>, UnitQuaternion<f64>)> = Vec::new();
    // The finger joints' angles at the same samples `[deg]`, for the rest rule's joint test.
    let mut joints: Vec<Vec<f64>> = Vec::new();
    let mut fine = Vec::new();
    let fine_every = (sample_every / 4).max(1);
    let mut decided: Option<Decision> = None;
    let mut watch = early.map(|rule| EarlyWatch {
        rule,
        frame,
        g,
        hold_steps,
        holds_itself: hand_holds_itself(scene, params),
        hand_was_still: false,
    });
    let mut steps = 0;
    // `closing_decides`: a failed closing is decided before any step of the hold.
    if watch.is_some() && params.hold.closing_decides && closing.failed() {
        decided = Some(Decision::Closing);
    }
    while steps < hold_steps && decided.is_none() {
        scene.world.step();
        steps += 1;
        super::closing::trace::hold(scene, closing.pc, steps, dt);
        if tracing && early.is_none() && steps % fine_every == 0 {
            let (p, q) = relative(scene);
            fine.push((p, q, super::contacts::friction_use(scene)));
        }
        if steps % sample_every != 0 || (early.is_none() && !tracing) {
            continue;
        }
        samples.push(relative(scene));
        joints.push(joint_angles_deg(scene));
        let Some(w) = watch.as_mut() else { continue };
        decided = w.decide(scene, params, closing, &samples, &joints, steps);
        if decided.is_some() {
            break;
        }
    }
    let outcome = direction_outcome(scene, gravity, params, closing, &frame, decided, hold_steps);
    if tracing && early.is_none() {
        TRACES.with(|t| {
            if let Some(v) = t.borrow_mut().as_mut() {
                v.push(HoldTrace {
                    frame,
                    samples,
                    joints,
                    fine,
                    fine_dt: fine_every as f64 * dt,
                    duration_s: hold_steps as f64 * dt,
                    outcome: outcome.clone(),
                });
            }
        });
    }
    (outcome, steps)
}

/// The early decision of one hold under the `fast` protocol: the rest rule and the drop tests,
/// and whether the hand was at rest at the previous sample.
struct EarlyWatch<'a> {
    /// The rest rule.
    rule: &'a EarlyDecision,
    /// What the samples are measured against.
    frame: RestFrame,
    /// Gravity `[m/s²]`.
    g: Vector3<f64>,
    /// The hold's length in steps.
    hold_steps: usize,
    /// [`hand_holds_itself`]: only then is [`clear_of_hand`] tried.
    holds_itself: bool,
    /// The hand was at rest at the previous sample.
    hand_was_still: bool,
}

impl EarlyWatch<'_> {
    /// What decides the direction at `steps` into the hold, with `samples` so far, if anything
    /// does: a drop out of reach, a drop clear of the resting hand, or the rest rule.
    fn decide(
        &mut self,
        scene: &Scene,
        params: &SimParams,
        closing: &Closing,
        samples: &[(Vector3<f64>, UnitQuaternion<f64>)],
        joints: &[Vec<f64>],
        steps: usize,
    ) -> Option<Decision> {
        let (rule, g, hold_steps) = (self.rule, self.g, self.hold_steps);
        // Drop: the object has left the hand's reach and its free flight never brings it back.
        if let Some(p_end) = out_of_reach(scene, g, params, hold_steps - steps) {
            return Some(Decision::OutOfReach(steps, p_end));
        }
        // Drop: the hand has come to rest, nothing touches it, and the object's free flight
        // never meets it again.
        let hand_still = self.holds_itself && hand_speed(scene) < HAND_REST_M_S;
        if hand_still && self.hand_was_still {
            if let Some((p_end, err_mm)) = clear_of_hand(scene, g, params, hold_steps - steps) {
                if (p_end - closing.pc).norm() - err_mm
                    > params.hold.hold_translation_mm / rule.margin
                {
                    return Some(Decision::ClearOfHand(steps, p_end));
                }
            }
        }
        self.hand_was_still = hand_still;
        let remaining_s = (hold_steps - steps) as f64 * params.solver.timestep_s;
        if !rule.joints_settled(joints, self.frame.sample_dt, remaining_s) {
            return None;
        }
        match rule.decide(samples, &self.frame, remaining_s, params) {
            Some(Verdict::Hold) => {}
            Some(_) if touches_hand(scene) => {}
            _ => return None,
        }
        Some(Decision::Rest(steps))
    }
}

/// The outcome of a hold that ended now, `decided` early or after `hold_steps`.
fn direction_outcome(
    scene: &Scene,
    gravity: Vector3<f64>,
    params: &SimParams,
    closing: &Closing,
    frame: &RestFrame,
    decided: Option<Decision>,
    hold_steps: usize,
) -> DirectionOutcome {
    let dt = params.solver.timestep_s;
    let (p0, pc, qc) = (closing.p0, closing.pc, closing.qc);
    let joint_errors_deg = closing.joint_errors_deg.clone();
    let joint_error_deg = joint_errors_deg
        .iter()
        .flatten()
        .copied()
        .fold(0.0f64, |w, e| if e.abs() > w.abs() { e } else { w });
    let (pe, qe) = relative(scene);
    let (rotation_deg, tilt_deg) = rotations(&qc, &qe);
    let at_decision_mm = (pe - pc).norm();
    let mut translation_mm = at_decision_mm;
    let mut in_contact = false;
    let (decided_at_s, decided_by) = match decided {
        Some(Decision::OutOfReach(n, p_end)) => {
            translation_mm = (p_end - pc).norm();
            (n as f64 * dt, DecidedBy::OutOfReach)
        }
        Some(Decision::ClearOfHand(n, p_end)) => {
            translation_mm = (p_end - pc).norm();
            (n as f64 * dt, DecidedBy::ClearOfHand)
        }
        Some(Decision::Rest(n)) => {
            in_contact = touches_hand(scene);
            (n as f64 * dt, DecidedBy::Rest)
        }
        Some(Decision::Closing) => {
            in_contact = touches_hand(scene);
            (0.0, DecidedBy::Closing)
        }
        None => {
            in_contact = touches_hand(scene);
            (hold_steps as f64 * dt, DecidedBy::End)
        }
    };
    let judged_rotation = if frame.is_revolution {
        tilt_deg
    } else {
        rotation_deg
    };
    let verdict = judged(
        decided_by,
        in_contact,
        translation_mm,
        judged_rotation,
        params,
    );
    DirectionOutcome {
        gravity: [gravity.x, gravity.y, gravity.z],
        verdict,
        translation_mm,
        rotation_deg: judged_rotation,
        full_rotation_deg: rotation_deg,
        tilt_deg,
        closing_translation_mm: (pc - p0).norm(),
        closing_rotation_deg: closing.q0.angle_to(&qc).to_degrees(),
        closing_pushed: closing.outcome.pushed,
        closing_off_plan: closing.outcome.off_plan,
        as_planned: closing.fidelity.as_planned,
        closing_penetration_mm: closing.penetration_mm,
        closed_at_s: closing.steps as f64 * dt,
        joint_error_deg,
        joint_errors_deg,
        in_contact,
        decided_at_s,
        decided_by,
        translation_at_decision_mm: at_decision_mm,
    }
}

/// The verdict on a direction decided by `decided_by`, where the object moved `translation_mm`
/// and turned `rotation_deg` (as judged) relative to the palm, touching the hand or not
/// (`in_contact`): the hold thresholds of `params` decide between hold and the rest.
fn judged(
    decided_by: DecidedBy,
    in_contact: bool,
    translation_mm: f64,
    rotation_deg: f64,
    params: &SimParams,
) -> Verdict {
    if decided_by.is_drop() {
        Verdict::Drop
    } else if decided_by == DecidedBy::Closing {
        // No hold ran (`closing_decides`): a provisional verdict by contact alone, which the
        // candidate search replaces by a full check before it reports or chooses the grasp.
        if in_contact {
            Verdict::Slip
        } else {
            Verdict::Drop
        }
    } else if translation_mm <= params.hold.hold_translation_mm
        && rotation_deg <= params.hold.hold_rotation_deg
    {
        Verdict::Hold
    } else if in_contact {
        Verdict::Slip
    } else {
        Verdict::Drop
    }
}

/// How a direction was decided before the end of the hold.
enum Decision {
    /// Left the hand's reach for good at this step; where its free flight ends (palm frame)
    /// `[mm]`.
    OutOfReach(usize, Vector3<f64>),
    /// Flies clear of the resting hand for good from this step; where its free flight ends
    /// (palm frame) `[mm]`.
    ClearOfHand(usize, Vector3<f64>),
    /// At rest relative to the palm at this step.
    Rest(usize),
    /// By the closing, before the hold (`[sim] closing_decides`).
    Closing,
}

/// True if every finger's motors hold its phalanges against gravity with four times the torque
/// to spare: joint 2's torque limit against phalanx 2, joint 1's lock against both. Then a
/// finger at rest and untouched sits where its motor's spring and gravity balance, or against a
/// contact it is pressed onto, and stays there; a motor barely stronger than gravity could
/// instead let a finger creep from rest, so [`clear_of_hand`] is not used for such a hand.
/// The lever of each phalanx about its joint is bounded by twice the farthest its colliders
/// reach from its centre of mass.
fn hand_holds_itself(scene: &Scene, params: &SimParams) -> bool {
    let w = &scene.world;
    let reach = |h: RigidBodyHandle| -> (f64, f64) {
        let b = &w.bodies[h];
        let lever = b
            .colliders()
            .iter()
            .map(|&c| {
                let c = &w.colliders[c];
                let sphere = c.shape().compute_bounding_sphere(c.position());
                f64::from((sphere.center() - b.center_of_mass()).length() + sphere.radius())
            })
            .fold(0.0, f64::max);
        (f64::from(b.mass()), 2.0 * lever)
    };
    scene.fingers.iter().all(|f| {
        let (m1, l1) = reach(f.phalanx1);
        let (m2, l2) = reach(f.phalanx2);
        params.fingers.torque_limit_nm >= 4.0 * m2 * G * l2
            && params.fingers.joint1_lock_torque_nm >= 4.0 * (m1 + m2) * G * (l1 + l2)
    })
}

/// Every finger joint's angle `[deg]`, finger by finger (joint 1, joint 2), as the closing
/// measures it against the plan: the differences between samples are the joints' motion.
fn joint_angles_deg(scene: &Scene) -> Vec<f64> {
    super::closing::joint_errors(scene).concat()
}
