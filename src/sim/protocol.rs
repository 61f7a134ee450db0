//! The hold test: close, gravity on, hold, measure, judge.
//!
//! Two protocols (`[sim] protocol`, docs/SIM.md): `full`, the reference, builds and closes a
//! fresh scene for every gravity direction and payload multiplier and holds each direction for
//! the whole `duration_s`; `fast` (the default) closes once, continues every direction and
//! payload multiplier from a copy of the closed scene ([`Scene::branch`]), ends a direction as
//! soon as its verdict can no longer change ([`EarlyDecision`]), and runs the directions in
//! parallel (each on its own copy, so the result does not depend on the number of threads).

use super::convert;
use super::scene::{build, Case, Scene};
use crate::scenario::{GravityMode, Protocol, SimParams};
use nalgebra::{UnitQuaternion, Vector3};
use rapier3d::prelude::*;
use rayon::prelude::*;
use std::time::Instant;

/// The verdict of the hold test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// The object stayed within the thresholds, no hand collider ended the closing deeper
    /// inside it than `max_penetration_mm`, and the closing pushed it no farther than
    /// `max_closing_shift_mm`.
    Hold,
    /// It moved beyond them but still touches the hand, or it stayed but a finger ended the
    /// closing deeper inside it than `max_penetration_mm` (not a grasp a real hand makes), or
    /// the closing pushed it farther than `max_closing_shift_mm` (not the grasp planned).
    Slip,
    /// It left the hand.
    Drop,
}

impl Verdict {
    /// The name used in JSON and TOML.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Hold => "hold",
            Verdict::Slip => "slip",
            Verdict::Drop => "drop",
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// The result for one gravity direction (reported as is in the JSON's `sim.directions`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DirectionOutcome {
    /// Gravity direction (unit, aligned frame).
    pub gravity: [f64; 3],
    /// The verdict.
    pub verdict: Verdict,
    /// Object translation relative to the palm during the hold `[mm]`.
    pub translation_mm: f64,
    /// Object rotation relative to the palm during the hold, as judged: the tilt of the
    /// principal axis for a body of revolution, the full rotation otherwise `[deg]`.
    pub rotation_deg: f64,
    /// The full rotation relative to the palm `[deg]`.
    pub full_rotation_deg: f64,
    /// The tilt of the object's principal axis (aligned Z) relative to the palm `[deg]`.
    pub tilt_deg: f64,
    /// Object translation relative to the palm while the fingers closed `[mm]`.
    pub closing_translation_mm: f64,
    /// Object rotation relative to the palm while the fingers closed `[deg]` (the full
    /// rotation).
    pub closing_rotation_deg: f64,
    /// True if and only if the closing pushed the object farther than `max_closing_shift_mm`:
    /// then the verdict is not `hold` (issue 33), whatever the hold did.
    pub closing_pushed: bool,
    /// Deepest penetration of a finger or the palm into the object at the end of closing `[mm]`
    /// (rapier's contact depth): a grasp that holds only because a finger passed into the object
    /// shows here (issue 14).
    pub closing_penetration_mm: f64,
    /// How long the fingers closed before gravity came on `[s]`: `close_duration_s`, or less
    /// under the `fast` protocol when the hand and the object stopped sooner.
    pub closed_at_s: f64,
    /// Largest difference between a joint's bend after closing and its planned bend `[deg]`
    /// (negative: stopped short of the plan, i.e. contact earlier than planned).
    pub joint_error_deg: f64,
    /// Per finger, the two joints' bend after closing minus the planned bend `[deg]`.
    pub joint_errors_deg: Vec<[f64; 2]>,
    /// True if and only if the object touches the hand at the end (at the decision, for a
    /// direction decided early).
    pub in_contact: bool,
    /// Time into the hold at which the verdict was decided `[s]`: `duration_s` when the
    /// direction ran to the end.
    pub decided_at_s: f64,
    /// What decided it: `end` (ran the whole hold), `rest` (at rest relative to the palm, the
    /// remaining motion cannot bring it across a threshold: within them, `hold`; slid beyond
    /// one and resting on the hand, `slip`), `out_of_reach` (left the hand's reach for good) or
    /// `clear_of_hand` (flies clear of the resting hand for good): both `drop`.
    pub decided_by: &'static str,
    /// Object translation relative to the palm at the decision `[mm]`. For `out_of_reach`,
    /// `translation_mm` is this continued in free flight to the end of the hold.
    pub translation_at_decision_mm: f64,
}

/// The physics check's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutcome {
    /// The worst verdict over the gravity directions.
    pub verdict: Verdict,
    /// The worst direction's translation `[mm]`.
    pub translation_mm: f64,
    /// The worst direction's rotation `[deg]`.
    pub rotation_deg: f64,
    /// Per gravity direction.
    pub directions: Vec<DirectionOutcome>,
    /// Simulated time, all directions `[s]`.
    pub simulated_s: f64,
    /// Steps taken, all directions.
    pub steps: usize,
    /// Wall time `[ms]`.
    pub wall_ms: f64,
    /// Where the first gravity direction's run left the bodies (aligned frame, metres): the
    /// palm, phalanx 1 and 2 of each finger, then the object.
    pub final_poses: Vec<(Vector3<f64>, nalgebra::UnitQuaternion<f64>)>,
    /// The contacts that carried the grip at the end of closing (gravity still off; the first
    /// direction's closing under the `full` protocol): [`super::contacts::grip_contacts`].
    pub grip_contacts: Vec<super::contacts::GripContact>,
    /// What the closing did (the first direction's closing under the `full` protocol).
    pub closing: ClosingOutcome,
    /// Where the closing left the bodies, gravity still off (aligned frame, metres): the
    /// palm, phalanx 1 and 2 of each finger, then the object.
    pub closed_poses: Vec<super::BodyPose>,
}

/// What the closing did to the planned grasp (issue 33, docs/SIM.md "What the closing does"):
/// how far it pushed the object, where each joint stopped against its plan, and which phalanx
/// touched the object first. Reported as `sim.closing`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClosingOutcome {
    /// Object translation relative to the palm from the start of the closing to its end `[mm]`.
    pub shift_mm: f64,
    /// Object rotation relative to the palm over the closing `[deg]` (the full rotation).
    pub turn_deg: f64,
    /// How long the closing took `[s]`.
    pub duration_s: f64,
    /// The bound on `shift_mm` (`[sim] max_closing_shift_mm`) `[mm]`.
    pub max_shift_mm: f64,
    /// True if and only if `shift_mm` exceeds `max_shift_mm`: the grasp that held (if it did)
    /// is not the one planned, and the verdict is not `hold`.
    pub pushed: bool,
    /// The first hand body to touch the object, and when; `None` if nothing touched it.
    pub first_touch: Option<FirstTouch>,
    /// True if and only if the palm touches the object at the end of the closing.
    pub palm_touching: bool,
    /// Per finger, in the hand's order.
    pub fingers: Vec<FingerClosing>,
    /// Phalanges that end the closing touching the object within [`WITHIN_PLAN_DEG`] of their
    /// planned bend.
    pub phalanges_on_plan: usize,
}

/// A phalanx ends the closing "on its plan" when it touches the object and its joint is within
/// this of the planned bend `[deg]` (the thesis's Joint Angular Deviation, 5°).
pub const WITHIN_PLAN_DEG: f64 = 5.0;

/// The first touch of the closing.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FirstTouch {
    /// `palm`, or the finger's name.
    pub body: String,
    /// 1 or 2 for a finger's phalanx, 0 for the palm.
    pub phalanx: usize,
    /// Time into the closing `[s]`.
    pub at_s: f64,
}

/// One finger's closing: planned and final joint angles, in the thesis's interior angles.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FingerClosing {
    /// The finger's name.
    pub name: String,
    /// Planned `[θ1, θ2]` `[deg]` (the Grasp Parameter Set).
    pub planned_deg: [f64; 2],
    /// `[θ1, θ2]` where the closing left the joints `[deg]`: the set a hand would be commanded
    /// to reach this grasp.
    pub final_deg: [f64; 2],
    /// Bend after closing minus the planned bend `[deg]` (negative: stopped short of the plan,
    /// more open than planned; `final_deg = planned_deg − error_deg`).
    pub error_deg: [f64; 2],
    /// True if and only if phalanx 1, phalanx 2 touches the object at the end of the closing
    /// (a contact rapier's solver holds: within its prediction distance, 0.2 mm).
    pub touching: [bool; 2],
    /// The gap between phalanx 1, phalanx 2 and the object's collider at the end of the closing
    /// `[mm]` (0 when touching or inside).
    pub gap_mm: [f64; 2],
    /// When phalanx 1, phalanx 2 first touched the object `[s]` (`None`: never).
    pub first_contact_s: [Option<f64>; 2],
}

impl ClosingOutcome {
    /// The finger joint furthest from its plan: (finger name, joint 1 or 2, error `[deg]`).
    pub fn worst_joint(&self) -> Option<(&str, usize, f64)> {
        let mut worst: Option<(&str, usize, f64)> = None;
        for f in &self.fingers {
            for (j, e) in f.error_deg.iter().enumerate() {
                if worst.is_none_or(|w| e.abs() > w.2.abs()) {
                    worst = Some((&f.name, j + 1, *e));
                }
            }
        }
        worst
    }
}

/// Standard gravity `[m/s²]`.
const G: f64 = 9.81;

/// The early-decision rule of the `fast` protocol (docs/SIM.md, "Deciding early").
#[derive(Debug, Clone, Copy)]
pub struct EarlyDecision {
    /// The window over which its motion is measured, and the least time held before a `rest`
    /// decision `[s]`.
    pub window_s: f64,
    /// The fastest motion seen in the window is projected to the end of the hold at this many
    /// times its speed.
    pub safety: f64,
    /// The projected further motion must also stay within what the numbers reported at the
    /// decision may differ from the full protocol's: this `[mm]` ...
    pub report_mm: f64,
    /// ... or `[deg]` ...
    pub report_deg: f64,
    /// ... or this fraction of the value reported, whichever is larger.
    pub report_fraction: f64,
    /// A rest decision keeps the object within this fraction of the hold thresholds, motion to
    /// come included: an object near a threshold runs to the end of the hold.
    pub margin: f64,
}

impl EarlyDecision {
    /// The rule with the scenario's `rest_window_s` and `rest_safety`.
    pub fn from_params(params: &SimParams) -> EarlyDecision {
        EarlyDecision {
            window_s: params.rest_window_s,
            safety: params.rest_safety,
            report_mm: 0.5,
            report_deg: 0.5,
            report_fraction: 0.1,
            margin: params.rest_margin,
        }
    }
}

/// The object's pose relative to the palm is sampled this often during a hold `[s]`.
pub const SAMPLE_S: f64 = 1.0 / 48.0;

/// What the samples of a hold are measured against: the pose after closing, and how the
/// rotation is judged.
#[derive(Debug, Clone, Copy)]
pub struct RestFrame {
    /// Object translation relative to the palm after closing `[mm]`.
    pub pc: Vector3<f64>,
    /// Object rotation relative to the palm after closing.
    pub qc: UnitQuaternion<f64>,
    /// Only the tilt of the principal axis is judged (a body of revolution).
    pub is_revolution: bool,
    /// Time between samples `[s]`.
    pub sample_dt: f64,
}

impl RestFrame {
    /// The judged rotation between two orientations `[deg]`.
    pub fn judged(&self, a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
        let (full, tilt) = rotations(a, b);
        if self.is_revolution {
            tilt
        } else {
            full
        }
    }
}

/// What the rest rule measures over its window: where the object is now and how much further
/// it may go by the end of the hold.
#[derive(Debug, Clone, Copy)]
struct Settling {
    /// Translation and judged rotation relative to the pose after closing, now `[mm]`, `[deg]`.
    now_mm: f64,
    now_deg: f64,
    /// `safety` × (drift × time left + spread) `[mm]`, `[deg]`.
    more_mm: f64,
    more_deg: f64,
}

impl EarlyDecision {
    /// The last `window_s` of `samples` measured: `None` while the hold is shorter than the
    /// window.
    fn settling(
        &self,
        samples: &[(Vector3<f64>, UnitQuaternion<f64>)],
        frame: &RestFrame,
        remaining_s: f64,
    ) -> Option<Settling> {
        let window = ((self.window_s / frame.sample_dt).round() as usize).max(1);
        if samples.len() <= window {
            return None;
        }
        let recent = &samples[samples.len() - window - 1..];
        let window_s = window as f64 * frame.sample_dt;
        let (first, last) = (recent[0], recent[window]);
        let mut spread_mm = 0.0f64;
        let mut spread_deg = 0.0f64;
        for (i, a) in recent.iter().enumerate() {
            for b in &recent[i + 1..] {
                spread_mm = spread_mm.max((a.0 - b.0).norm());
                spread_deg = spread_deg.max(frame.judged(&a.1, &b.1));
            }
        }
        let drift_mm = (last.0 - first.0).norm() / window_s;
        let drift_deg = frame.judged(&first.1, &last.1) / window_s;
        Some(Settling {
            now_mm: (last.0 - frame.pc).norm(),
            now_deg: frame.judged(&frame.qc, &last.1),
            more_mm: self.safety * (drift_mm * remaining_s + spread_mm),
            more_deg: self.safety * (drift_deg * remaining_s + spread_deg),
        })
    }

    /// True when the further motion bound is within what the numbers reported now may differ
    /// from the full protocol's.
    fn reportable(&self, s: &Settling) -> bool {
        s.more_mm <= self.report_mm.max(self.report_fraction * s.now_mm)
            && s.more_deg <= self.report_deg.max(self.report_fraction * s.now_deg)
    }

    /// The rest rules (docs/SIM.md, "Deciding early"): what the motion of the last `window_s`
    /// of `samples` (the poses relative to the palm so far, one every `frame.sample_dt`), its
    /// mean drift and its spread at `safety` times their size continued for `remaining_s`,
    /// decides now, provided it keeps the numbers reported now within what they may differ from
    /// the full protocol's:
    /// - `Hold` when the object stays within `margin` of the hold thresholds (a hold by motion;
    ///   the verdict is `slip` all the same if the closing left a finger too deep);
    /// - `Slip` when it cannot come back within `1 / margin` of a threshold (the distance to the
    ///   pose after closing moves by no more than the object does, and so does the judged
    ///   rotation), or, for a grasp the closing left too deep in the object (`penetrated`),
    ///   wherever it is: such a grasp is `slip` whatever it does while on the hand;
    /// - `None` otherwise.
    ///
    /// A `Slip` holds only for an object on the hand, which the caller checks.
    pub fn decide(
        &self,
        samples: &[(Vector3<f64>, UnitQuaternion<f64>)],
        frame: &RestFrame,
        remaining_s: f64,
        params: &SimParams,
        penetrated: bool,
    ) -> Option<Verdict> {
        let s = self.settling(samples, frame, remaining_s)?;
        if !self.reportable(&s) {
            return None;
        }
        if s.now_mm + s.more_mm <= self.margin * params.hold_translation_mm
            && s.now_deg + s.more_deg <= self.margin * params.hold_rotation_deg
        {
            return Some(Verdict::Hold);
        }
        let beyond = s.now_mm - s.more_mm >= params.hold_translation_mm / self.margin
            || s.now_deg - s.more_deg >= params.hold_rotation_deg / self.margin;
        (beyond || penetrated).then_some(Verdict::Slip)
    }
}

/// A full-length hold's samples (one every [`SAMPLE_S`]) and outcome, collected by [`traced`]
/// for the study of the rest rule (`examples/early_rule.rs`).
#[derive(Debug, Clone)]
pub struct HoldTrace {
    /// What the samples are measured against.
    pub frame: RestFrame,
    /// The object's pose relative to the palm, one per sample.
    pub samples: Vec<(Vector3<f64>, UnitQuaternion<f64>)>,
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

/// The end of a closing phase with `close_until_stalled` (docs/SIM.md, "Closing until the hand
/// stops"): every joint, and the object relative to the palm, slower than these for
/// `window_s`.
#[derive(Debug, Clone, Copy)]
pub struct Stall {
    /// Fastest joint `[rad/s]`.
    pub joint_rad_s: f64,
    /// Fastest object translation `[mm/s]`.
    pub object_mm_s: f64,
    /// Fastest object rotation `[rad/s]`.
    pub object_rad_s: f64,
    /// How long all of them must stay below `[s]`.
    pub window_s: f64,
}

/// The rule, for rapier and the MuJoCo replay (`protocol.json`).
pub const STALL: Stall = Stall {
    joint_rad_s: 0.02,
    object_mm_s: 0.5,
    object_rad_s: 0.01,
    window_s: 0.02,
};

impl Stall {
    /// True if `(joint, object translation, object rotation)` speeds are all below the rule's.
    fn quiet(&self, (joint, object_mm_s, object_rad_s): (f64, f64, f64)) -> bool {
        joint < self.joint_rad_s
            && object_mm_s < self.object_mm_s
            && object_rad_s < self.object_rad_s
    }
}

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

/// Where the closing left the object, and how it got there.
#[derive(Debug, Clone)]
struct Closing {
    /// Object translation relative to the palm at the start `[mm]`.
    p0: Vector3<f64>,
    /// Object rotation relative to the palm at the start.
    q0: UnitQuaternion<f64>,
    /// What the closing did, as reported.
    outcome: ClosingOutcome,
    /// Where it left the bodies.
    poses: Vec<super::BodyPose>,
    /// ... and after closing `[mm]`.
    pc: Vector3<f64>,
    /// Object rotation relative to the palm after closing.
    qc: UnitQuaternion<f64>,
    /// Per finger, joint bend after closing minus the plan `[deg]`.
    joint_errors_deg: Vec<[f64; 2]>,
    /// Deepest penetration of a hand collider into the object after closing `[mm]`.
    penetration_mm: f64,
    /// Steps taken.
    steps: usize,
    /// The contacts carrying the grip when closing ended.
    contacts: Vec<super::contacts::GripContact>,
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

/// The `full` protocol: a fresh scene per direction, closed, held for the whole `duration_s`.
fn check_full(case: &Case) -> SimOutcome {
    let params = case.params;
    let t0 = Instant::now();
    let mut outcomes = Vec::new();
    let mut steps = 0;
    let mut final_poses = Vec::new();
    let mut first_closing: Option<Closing> = None;
    for g in directions(params.gravity) {
        let mut scene = build(case);
        let closing = close(&mut scene, case);
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
        translation_mm: worst.translation_mm,
        rotation_deg: worst.rotation_deg,
        simulated_s: steps as f64 * params.timestep_s,
        steps,
        directions: outcomes,
        wall_ms: t0.elapsed().as_secs_f64() * 1000.0,
        final_poses,
        grip_contacts: Vec::new(),
        closing: ClosingOutcome {
            shift_mm: 0.0,
            turn_deg: 0.0,
            duration_s: 0.0,
            max_shift_mm: params.max_closing_shift_mm,
            pushed: false,
            first_touch: None,
            palm_touching: false,
            fingers: Vec::new(),
            phalanges_on_plan: 0,
        },
        closed_poses: Vec::new(),
    }
}

/// The palm, phalanx 1 and 2 of each finger, then the object (aligned frame, metres).
fn poses(scene: &Scene) -> Vec<super::BodyPose> {
    let mut handles = vec![scene.palm];
    for f in &scene.fingers {
        handles.push(f.phalanx1);
        handles.push(f.phalanx2);
    }
    handles.push(scene.object);
    handles
        .iter()
        .map(|h| {
            let p = scene.world.bodies[*h].position();
            (
                convert::vector_mm(p.translation) * convert::M_PER_MM,
                convert::unit_quaternion(p.rotation),
            )
        })
        .collect()
}

/// The object's pose relative to the palm: (translation in mm, rotation).
fn relative(scene: &Scene) -> (Vector3<f64>, UnitQuaternion<f64>) {
    let palm = scene.world.bodies[scene.palm].position();
    let obj = scene.world.bodies[scene.object].position();
    let rel = palm.inverse() * *obj;
    (
        convert::vector_mm(rel.translation),
        convert::unit_quaternion(rel.rotation),
    )
}

/// Closes the hand, gravity off: joint 1 first, then joint 2, each for half `close_duration_s`
/// or, with `close_until_stalled`, until the hand and the object have stopped ([`STALL`]).
fn close(scene: &mut Scene, case: &Case) -> Closing {
    let params = case.params;
    let stall = params.close_until_stalled.then_some(&STALL);
    let dt = params.timestep_s;
    let close_steps = (params.close_duration_s / dt).round() as usize;
    let (p0, q0) = relative(scene);
    let mut first_contact = FirstContacts::new(scene.fingers.len());
    // Joint 1 closes for at most half the closing time, joint 2 for the rest.
    let phases = [close_steps / 2, close_steps - close_steps / 2];
    let mut steps = 0;
    // `together`: fingers held where they touched, until all have or the hand has stopped.
    let mut waiting = params.approach == crate::scenario::Approach::Together;
    let mut held = vec![false; scene.fingers.len()];
    for (phase, max_steps) in phases.into_iter().enumerate() {
        if phase == 1 {
            if waiting {
                release_held(scene, &mut held);
                waiting = false;
            }
            scene.release_joint2();
        }
        let mut quiet_steps = 0;
        for _ in 0..max_steps {
            scene.world.step();
            steps += 1;
            let now = touching(scene);
            first_contact.update(&now, steps as f64 * dt);
            if waiting {
                for (k, t) in now.fingers.iter().enumerate() {
                    if (t[0] || t[1]) && !held[k] {
                        scene.hold_joint1(k, true);
                        held[k] = true;
                    }
                }
                if held.iter().all(|h| *h) {
                    release_held(scene, &mut held);
                    waiting = false;
                    quiet_steps = 0;
                }
            }
            let Some(rule) = stall else { continue };
            if rule.quiet(motion(scene)) {
                quiet_steps += 1;
                if quiet_steps as f64 * dt >= rule.window_s {
                    if waiting {
                        // A finger that stopped without touching: the others squeeze now.
                        release_held(scene, &mut held);
                        waiting = false;
                        quiet_steps = 0;
                        continue;
                    }
                    break;
                }
            } else {
                quiet_steps = 0;
            }
        }
    }
    let (pc, qc) = relative(scene);
    let joint_errors_deg = joint_errors(scene);
    let outcome = closing_outcome(
        case,
        &first_contact,
        &touching(scene),
        &gaps_mm(scene),
        &joint_errors_deg,
        ((pc - p0).norm(), q0.angle_to(&qc).to_degrees()),
        steps as f64 * dt,
    );
    Closing {
        p0,
        q0,
        pc,
        qc,
        penetration_mm: penetration_mm(scene),
        joint_errors_deg,
        steps,
        contacts: super::contacts::grip_contacts(scene),
        outcome,
        poses: poses(scene),
    }
}

/// Per finger, the gap between phalanx 1, phalanx 2 (its nearest collider) and the object's
/// collider now `[mm]`, 0 when they touch or overlap.
fn gaps_mm(scene: &Scene) -> Vec<[f64; 2]> {
    let w = &scene.world;
    let object = &w.colliders[scene.object_collider];
    let gap = |body: RigidBodyHandle| -> f64 {
        w.bodies[body]
            .colliders()
            .iter()
            .filter_map(|&h| {
                let c = &w.colliders[h];
                rapier3d::parry::query::distance(
                    c.position(),
                    c.shape(),
                    object.position(),
                    object.shape(),
                )
                .ok()
            })
            .map(|d| f64::from(d.distance) * 1000.0)
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    };
    scene
        .fingers
        .iter()
        .map(|f| [gap(f.phalanx1), gap(f.phalanx2)])
        .collect()
}

/// Sends every held finger's joint 1 on to its squeeze target.
fn release_held(scene: &mut Scene, held: &mut [bool]) {
    for (k, h) in held.iter_mut().enumerate() {
        if *h {
            scene.hold_joint1(k, false);
        }
        *h = false;
    }
}

/// Which hand bodies touch the object now: the palm, and phalanx 1 and 2 of each finger.
struct Touching {
    palm: bool,
    fingers: Vec<[bool; 2]>,
}

/// When each hand body first touched the object during the closing `[s]`.
struct FirstContacts {
    palm: Option<f64>,
    fingers: Vec<[Option<f64>; 2]>,
}

impl FirstContacts {
    fn new(fingers: usize) -> FirstContacts {
        FirstContacts {
            palm: None,
            fingers: vec![[None; 2]; fingers],
        }
    }

    /// Records the bodies of `now` that touch for the first time at `t`.
    fn update(&mut self, now: &Touching, t: f64) {
        if now.palm && self.palm.is_none() {
            self.palm = Some(t);
        }
        for (first, touch) in self.fingers.iter_mut().zip(&now.fingers) {
            for j in 0..2 {
                if touch[j] && first[j].is_none() {
                    first[j] = Some(t);
                }
            }
        }
    }

    /// The earliest first touch: (`palm` or the finger's name, phalanx, time); the palm, then
    /// the fingers in order, on a tie.
    fn first(&self, names: &[String]) -> Option<FirstTouch> {
        let mut best: Option<FirstTouch> = self.palm.map(|t| FirstTouch {
            body: "palm".to_string(),
            phalanx: 0,
            at_s: t,
        });
        for (name, first) in names.iter().zip(&self.fingers) {
            for (j, t) in first.iter().enumerate() {
                if let Some(t) = *t {
                    if best.as_ref().is_none_or(|b| t < b.at_s) {
                        best = Some(FirstTouch {
                            body: name.clone(),
                            phalanx: j + 1,
                            at_s: t,
                        });
                    }
                }
            }
        }
        best
    }
}

/// The hand bodies in contact with the object now (a solver contact: within rapier's
/// prediction distance, 0.2 mm at the scene's length unit).
fn touching(scene: &Scene) -> Touching {
    let w = &scene.world;
    let mut now = Touching {
        palm: false,
        fingers: vec![[false; 2]; scene.fingers.len()],
    };
    for pair in w.narrow_phase.contact_pairs_with(scene.object_collider) {
        if !pair.has_any_active_contact() {
            continue;
        }
        let other = if pair.collider1 == scene.object_collider {
            pair.collider2
        } else {
            pair.collider1
        };
        let Some(body) = w.colliders.get(other).and_then(|c| c.parent()) else {
            continue;
        };
        if body == scene.palm {
            now.palm = true;
        }
        for (k, f) in scene.fingers.iter().enumerate() {
            if body == f.phalanx1 {
                now.fingers[k][0] = true;
            }
            if body == f.phalanx2 {
                now.fingers[k][1] = true;
            }
        }
    }
    now
}

/// The report of a closing: `shift` is the object's (translation `[mm]`, rotation `[deg]`)
/// relative to the palm over the closing, `duration_s` its length.
fn closing_outcome(
    case: &Case,
    first: &FirstContacts,
    end: &Touching,
    gaps: &[[f64; 2]],
    errors: &[[f64; 2]],
    (shift_mm, turn_deg): (f64, f64),
    duration_s: f64,
) -> ClosingOutcome {
    let names: Vec<String> = case
        .hand
        .finger_list
        .iter()
        .map(|f| f.name.clone())
        .collect();
    let fingers: Vec<FingerClosing> = names
        .iter()
        .zip(&case.pose.theta_deg)
        .zip(errors)
        .zip(end.fingers.iter().zip(&first.fingers).zip(gaps))
        .map(
            |(((name, planned), error), ((touching, first), gap))| FingerClosing {
                name: name.clone(),
                planned_deg: *planned,
                final_deg: [planned[0] - error[0], planned[1] - error[1]],
                error_deg: *error,
                touching: *touching,
                gap_mm: *gap,
                first_contact_s: *first,
            },
        )
        .collect();
    let phalanges_on_plan = fingers
        .iter()
        .flat_map(|f| (0..2).map(move |j| f.touching[j] && f.error_deg[j].abs() <= WITHIN_PLAN_DEG))
        .filter(|on| *on)
        .count();
    let max_shift_mm = case.params.max_closing_shift_mm;
    ClosingOutcome {
        shift_mm,
        turn_deg,
        duration_s,
        max_shift_mm,
        pushed: shift_mm > max_shift_mm,
        first_touch: first.first(&names),
        palm_touching: end.palm,
        fingers,
        phalanges_on_plan,
    }
}

/// The hand's and the object's motion relative to the palm: (fastest joint `[rad/s]`, object
/// speed `[mm/s]`, object angular speed `[rad/s]`).
fn motion(scene: &Scene) -> (f64, f64, f64) {
    let b = &scene.world.bodies;
    let n = |v: Vector| f64::from(v.length());
    let mut joint = 0.0f64;
    for f in &scene.fingers {
        let w1 = b[f.phalanx1].angvel();
        let w2 = b[f.phalanx2].angvel();
        joint = joint.max(n(w1)).max(n(w2 - w1));
    }
    let o = &b[scene.object];
    (joint, n(o.linvel()) * 1000.0, n(o.angvel()))
}

/// The deepest penetration of a hand collider into the object now `[mm]` (0 when none).
fn penetration_mm(scene: &Scene) -> f64 {
    let mut depth = 0.0f64;
    for pair in scene
        .world
        .narrow_phase
        .contact_pairs_with(scene.object_collider)
    {
        if !(scene.hand_colliders.contains(&pair.collider1)
            || scene.hand_colliders.contains(&pair.collider2))
        {
            continue;
        }
        if let rapier3d::geometry::PairContacts::Rigid(r) = &pair.contacts {
            for m in &r.manifolds {
                for p in &m.points {
                    depth = depth.max(-f64::from(p.dist));
                }
            }
        }
    }
    depth * 1000.0
}

/// True if and only if the object touches the hand.
fn touches_hand(scene: &Scene) -> bool {
    scene
        .world
        .narrow_phase
        .contact_pairs_with(scene.object_collider)
        .any(|pair| {
            pair.has_any_active_contact()
                && (scene.hand_colliders.contains(&pair.collider1)
                    || scene.hand_colliders.contains(&pair.collider2))
        })
}

/// The object's judged rotation and its parts: (full rotation, tilt of the principal axis),
/// both `[deg]`, relative to `qc`.
fn rotations(qc: &UnitQuaternion<f64>, q: &UnitQuaternion<f64>) -> (f64, f64) {
    let full = qc.angle_to(q).to_degrees();
    let tilt = (qc * Vector3::z()).angle(&(q * Vector3::z())).to_degrees();
    (full, tilt)
}

/// Turns gravity on along `gravity` and holds: to the end of `duration_s`, or with `early`
/// until the verdict can no longer change. Returns the outcome and the steps taken.
fn hold(
    scene: &mut Scene,
    gravity: Vector3<f64>,
    params: &SimParams,
    closing: &Closing,
    is_revolution: bool,
    early: Option<&EarlyDecision>,
) -> (DirectionOutcome, usize) {
    let dt = params.timestep_s;
    let hold_steps = (params.duration_s / dt).round() as usize;
    let Closing { p0, pc, qc, .. } = closing.clone();
    let joint_errors_deg = closing.joint_errors_deg.clone();
    let joint_error_deg = joint_errors_deg
        .iter()
        .flatten()
        .copied()
        .fold(0.0f64, |w, e| if e.abs() > w.abs() { e } else { w });
    let g = gravity * G;
    scene.world.gravity = Vector::new(g.x as f32, g.y as f32, g.z as f32);
    let judged = |full: f64, tilt: f64| if is_revolution { tilt } else { full };
    let sample_every = ((SAMPLE_S / dt).round() as usize).max(1);
    let tracing = TRACES.with(|t| t.borrow().is_some());
    let frame = RestFrame {
        pc,
        qc,
        is_revolution,
        sample_dt: sample_every as f64 * dt,
    };
    // Samples of the object's pose relative to the palm, for the rest rule.
    let mut samples: Vec<(Vector3<f64>, UnitQuaternion<f64>)> = Vec::new();
    let mut fine = Vec::new();
    let fine_every = (sample_every / 4).max(1);
    let mut decided: Option<Decision> = None;
    let mut hand_was_still = false;
    let holds_itself = hand_holds_itself(scene, params);
    let mut steps = 0;
    while steps < hold_steps {
        scene.world.step();
        steps += 1;
        if tracing && early.is_none() && steps % fine_every == 0 {
            let (p, q) = relative(scene);
            fine.push((p, q, super::contacts::friction_use(scene)));
        }
        if steps % sample_every != 0 || (early.is_none() && !tracing) {
            continue;
        }
        samples.push(relative(scene));
        let Some(rule) = early else { continue };
        // Drop: the object has left the hand's reach and its free flight never brings it back.
        if let Some(p_end) = out_of_reach(scene, g, params, hold_steps - steps) {
            decided = Some(Decision::OutOfReach(steps, p_end));
            break;
        }
        // Drop: the hand has come to rest, nothing touches it, and the object's free flight
        // never meets it again.
        let hand_still = holds_itself && hand_speed(scene) < HAND_REST_M_S;
        if hand_still && hand_was_still {
            if let Some((p_end, err_mm)) = clear_of_hand(scene, g, params, hold_steps - steps) {
                if (p_end - pc).norm() - err_mm > params.hold_translation_mm / rule.margin {
                    decided = Some(Decision::ClearOfHand(steps, p_end));
                    break;
                }
            }
        }
        hand_was_still = hand_still;
        let remaining_s = (hold_steps - steps) as f64 * dt;
        // A grasp the closing left too deep in the object, or pushed too far, is `slip`
        // whatever it does while on the hand.
        let penetrated = closing.penetration_mm > params.max_penetration_mm;
        match rule.decide(
            &samples,
            &frame,
            remaining_s,
            params,
            penetrated || closing.outcome.pushed,
        ) {
            Some(Verdict::Hold) => {}
            Some(_) if touches_hand(scene) => {}
            _ => continue,
        }
        decided = Some(Decision::Rest(steps));
        break;
    }
    let (pe, qe) = relative(scene);
    let (rotation_deg, tilt_deg) = rotations(&qc, &qe);
    let at_decision_mm = (pe - pc).norm();
    let mut translation_mm = at_decision_mm;
    let mut in_contact = false;
    let (decided_at_s, decided_by) = match decided {
        Some(Decision::OutOfReach(n, p_end)) => {
            translation_mm = (p_end - pc).norm();
            (n as f64 * dt, "out_of_reach")
        }
        Some(Decision::ClearOfHand(n, p_end)) => {
            translation_mm = (p_end - pc).norm();
            (n as f64 * dt, "clear_of_hand")
        }
        Some(Decision::Rest(n)) => {
            in_contact = touches_hand(scene);
            (n as f64 * dt, "rest")
        }
        None => {
            in_contact = touches_hand(scene);
            (hold_steps as f64 * dt, "end")
        }
    };
    let judged_rotation = judged(rotation_deg, tilt_deg);
    let verdict = if decided_by == "out_of_reach" || decided_by == "clear_of_hand" {
        Verdict::Drop
    } else if translation_mm <= params.hold_translation_mm
        && judged_rotation <= params.hold_rotation_deg
        && closing.penetration_mm <= params.max_penetration_mm
        && !closing.outcome.pushed
    {
        Verdict::Hold
    } else if in_contact {
        Verdict::Slip
    } else {
        Verdict::Drop
    };
    let outcome = DirectionOutcome {
        gravity: [gravity.x, gravity.y, gravity.z],
        verdict,
        translation_mm,
        rotation_deg: judged_rotation,
        full_rotation_deg: rotation_deg,
        tilt_deg,
        closing_translation_mm: (pc - p0).norm(),
        closing_rotation_deg: closing.q0.angle_to(&qc).to_degrees(),
        closing_pushed: closing.outcome.pushed,
        closing_penetration_mm: closing.penetration_mm,
        closed_at_s: closing.steps as f64 * dt,
        joint_error_deg,
        joint_errors_deg,
        in_contact,
        decided_at_s,
        decided_by,
        translation_at_decision_mm: at_decision_mm,
    };
    if tracing && early.is_none() {
        TRACES.with(|t| {
            if let Some(v) = t.borrow_mut().as_mut() {
                v.push(HoldTrace {
                    frame,
                    samples,
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
}

/// If the object is out of the hand's reach and its free flight under `g` `[m/s²]` for the
/// remaining `steps` keeps it out, its translation relative to the palm at the end of that
/// flight (relative position, palm frame) `[mm]`; `None` otherwise.
///
/// Out of reach: the sphere about the object's centre of mass that holds the object does not
/// meet the sphere about the palm origin that holds the hand at any joint angle, with rapier's
/// prediction distance to spare. Nothing else is in the scene, so out of reach the object flies
/// freely: rapier's integration (per substep: velocity plus gravity, capped at the largest
/// linear velocity, then position plus velocity) is continued here to the end of the hold, and
/// the spheres must stay apart at every substep, with the distance one substep can travel to
/// spare.
fn out_of_reach(
    scene: &Scene,
    g: Vector3<f64>,
    params: &SimParams,
    steps: usize,
) -> Option<Vector3<f64>> {
    let bodies = &scene.world.bodies;
    let palm = bodies[scene.palm].position();
    let obj = &bodies[scene.object];
    let v3 = |v: Vector| Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z));
    let palm_at = v3(palm.translation);
    let com0 = v3(obj.center_of_mass());
    let ip = &scene.world.integration_parameters;
    let clearance = scene.reach_m + scene.object_radius_m + f64::from(ip.prediction_distance());
    if (com0 - palm_at).norm() <= clearance {
        return None;
    }
    if touches_hand(scene) {
        return None;
    }
    let substeps = params.solver_iterations.max(1);
    let h = params.timestep_s / substeps as f64;
    let v_max = f64::from(ip.max_linear_velocity());
    let mut v = v3(obj.linvel());
    let mut x = com0;
    for _ in 0..steps * substeps {
        let speed = flight_substep(&mut x, &mut v, g, h, v_max);
        if (x - palm_at).norm() <= clearance + v_max.min(speed) * h {
            return None;
        }
    }
    Some(flight_end_mm(scene, x - com0))
}

/// One substep of free flight as rapier integrates a free body: velocity plus `g`·`h`, capped at
/// `v_max`, then position plus velocity·`h`. Returns the speed before the cap.
fn flight_substep(
    x: &mut Vector3<f64>,
    v: &mut Vector3<f64>,
    g: Vector3<f64>,
    h: f64,
    v_max: f64,
) -> f64 {
    *v += g * h;
    let speed = v.norm();
    if speed > v_max {
        *v *= v_max / speed;
    }
    *x += *v * h;
    speed
}

/// The object's translation relative to the palm (palm frame) `[mm]` once its centre of mass
/// has moved by `shift` `[m]` in free flight: the body frame is carried with the centre of mass,
/// its rotation now kept.
fn flight_end_mm(scene: &Scene, shift: Vector3<f64>) -> Vector3<f64> {
    let bodies = &scene.world.bodies;
    let palm = bodies[scene.palm].position();
    let origin = bodies[scene.object].position().translation;
    let end = |o: f32, p: f32, d: f64| (f64::from(o) + d - f64::from(p)) as f32;
    let rel = palm.rotation.inverse()
        * rapier3d::math::Vector::new(
            end(origin.x, palm.translation.x, shift.x),
            end(origin.y, palm.translation.y, shift.y),
            end(origin.z, palm.translation.z, shift.z),
        );
    convert::vector_mm(rel)
}

/// The hand counts as at rest when no point of any hand collider moves faster than this
/// `[m/s]` (1 mm/s), at two samples running.
const HAND_REST_M_S: f64 = 1e-3;

/// The fastest any point of a hand collider moves `[m/s]`: per collider, its body's speed plus
/// its angular speed times the farthest its collider reaches from the body's centre of mass.
fn hand_speed(scene: &Scene) -> f64 {
    let w = &scene.world;
    scene
        .hand_colliders
        .iter()
        .filter_map(|&h| {
            let c = &w.colliders[h];
            let b = &w.bodies[c.parent()?];
            let sphere = c.shape().compute_bounding_sphere(c.position());
            let lever = (sphere.center() - b.center_of_mass()).length() + sphere.radius();
            Some(f64::from(b.linvel().length()) + f64::from(b.angvel().length() * lever))
        })
        .fold(0.0, f64::max)
}

/// If the object flies clear of the hand for the remaining `steps` under `g` `[m/s²]`, its
/// translation relative to the palm at the end of that flight (palm frame) `[mm]`; `None`
/// otherwise (docs/SIM.md, "Deciding early").
///
/// Called only when the hand has been at rest at two samples running ([`HAND_REST_M_S`]):
/// untouched, under constant gravity and motor targets, it stays where it is, and every hand
/// collider is taken where it is now, widened by the distance the rest speed would carry it to
/// the end of the hold, twice over. Nothing else is in the scene, so while it touches nothing the
/// object flies freely: its centre of mass as rapier integrates it (see [`out_of_reach`]), its
/// orientation unknown but turning no faster than its angular momentum allows (`|ω| ≤ |L| /
/// I_min`: rapier's gyroscopic step keeps `|L|`, though not the energy). The distance to the
/// hand is bounded below at times along
/// the flight by the larger of (a) the distance from the object, at its present orientation and
/// carried with its centre of mass, less the most its rotation since now can move a point of it,
/// and (b) the distance from its centre of mass less the radius of the sphere that holds it; from
/// each such time the flight is advanced by as long as its speed bound (speed now plus gravity,
/// plus rotation, plus the lead of rapier's velocity-first update) cannot close that distance
/// (conservative advancement). If the bound stays positive to the end of the hold, the object
/// never touches the hand again. Also returned: how far the reported end may be from the true
/// one `[mm]`, since the body frame is carried with the centre of mass without its turn.
fn clear_of_hand(
    scene: &Scene,
    g: Vector3<f64>,
    params: &SimParams,
    steps: usize,
) -> Option<(Vector3<f64>, f64)> {
    if touches_hand(scene) {
        return None;
    }
    let w = &scene.world;
    let obj = &w.bodies[scene.object];
    let obj_collider = &w.colliders[scene.object_collider];
    let v3 = |v: Vector| Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z));
    let ip = &w.integration_parameters;
    let substeps = params.solver_iterations.max(1);
    let h = params.timestep_s / substeps as f64;
    let total = steps * substeps;
    let remaining_s = total as f64 * h;
    let margin = 2.0 * HAND_REST_M_S * remaining_s + f64::from(ip.prediction_distance());
    let v_max = f64::from(ip.max_linear_velocity());
    // The bound on the object's angular speed in free flight.
    let mprops = &obj.mass_properties().local_mprops;
    let inertia = v3(mprops.principal_inertia());
    let frame = obj.position().rotation * mprops.principal_inertia_local_frame;
    let w_local = v3(frame.inverse() * obj.angvel());
    let i_min = inertia.min().max(f64::MIN_POSITIVE);
    // rapier's gyroscopic step keeps |L| (it rescales the angular momentum to its length before
    // the step) but not the energy, which grows for a spin near the largest axis: the bound is
    // |L| / I_min, with 1 % for f32 rounding.
    let l = inertia.component_mul(&w_local).norm();
    let omega = 1.01 * l / i_min;
    let r_obj = scene.object_radius_m;
    let com0 = v3(obj.center_of_mass());
    let pose0 = *obj_collider.position();
    let hand: Vec<(&Collider, Pose)> = scene
        .hand_colliders
        .iter()
        .map(|&h| (&w.colliders[h], *w.colliders[h].position()))
        .collect();
    let g_norm = g.norm();
    let mut x = com0;
    let mut v = v3(obj.linvel());
    let mut k = 0usize;
    for _ in 0..10_000 {
        // (a) and (b) at substep k.
        let shift = x - com0;
        let mut at = pose0;
        at.translation += Vector::new(shift.x as f32, shift.y as f32, shift.z as f32);
        let turned = omega * k as f64 * h * r_obj;
        let centre = Vector::new(x.x as f32, x.y as f32, x.z as f32);
        let mut lower = f64::INFINITY;
        for (c, pose) in &hand {
            let d_sphere = f64::from(c.shape().distance_to_point(pose, centre, true)) - r_obj;
            let d_shape = if turned < r_obj {
                let d =
                    rapier3d::parry::query::distance(&at, obj_collider.shape(), pose, c.shape())
                        .ok()?;
                // parry's convex distance stops within about 1.1e-3 of the true one, from above.
                f64::from(d.distance) * (1.0 - 2e-3) - turned
            } else {
                f64::NEG_INFINITY
            };
            lower = lower.min(d_sphere.max(d_shape));
        }
        let gap = lower - margin;
        if gap <= 0.0 {
            return None;
        }
        if k >= total {
            break;
        }
        // The longest advance over which speed (now plus gravity) and rotation cannot close
        // the gap: ½·g·Δ² + (|v| + ω·r + ½·g·h)·Δ = gap.
        // rapier updates the velocity before the position: over n substeps that leads the
        // continuous motion by up to ½·g·h·Δ.
        let b = v.norm() + omega * r_obj + 0.5 * g_norm * h;
        let dt_safe = if g_norm > 0.0 {
            (-b + (b * b + 2.0 * g_norm * gap).sqrt()) / g_norm
        } else {
            gap / b.max(f64::MIN_POSITIVE)
        };
        let n = ((dt_safe / h).floor() as usize).min(total - k);
        if n == 0 {
            return None;
        }
        for _ in 0..n {
            flight_substep(&mut x, &mut v, g, h, v_max);
        }
        k += n;
    }
    if k < total {
        return None;
    }
    // The body frame is carried with the centre of mass, its rotation at the decision kept:
    // its origin may end elsewhere by the turn since then (at most half a turn) times its
    // distance from the centre of mass.
    let origin_off = (v3(obj.position().translation) - com0).norm();
    let err_mm = (omega * remaining_s).min(2.0) * origin_off / convert::M_PER_MM;
    Some((flight_end_mm(scene, x - com0), err_mm))
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
        params.torque_limit_nm >= 4.0 * m2 * G * l2
            && params.joint1_lock_torque_nm >= 4.0 * (m1 + m2) * G * (l1 + l2)
    })
}

/// Per finger, each joint's bend minus its planned bend `[deg]`.
fn joint_errors(scene: &Scene) -> Vec<[f64; 2]> {
    let bodies = &scene.world.bodies;
    let rp = *bodies[scene.palm].rotation();
    scene
        .fingers
        .iter()
        .map(|f| {
            let [t1, t2] = f.planned_bend_rad;
            let r1 = *bodies[f.phalanx1].rotation();
            let r2 = *bodies[f.phalanx2].rotation();
            let bend = |parent: Rotation, child: Rotation| {
                convert::unit_quaternion(parent.inverse() * child).angle()
            };
            [
                (bend(rp, r1) - t1).to_degrees(),
                (bend(r1, r2) - t2).to_degrees(),
            ]
        })
        .collect()
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
