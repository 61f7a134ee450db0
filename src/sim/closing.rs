//! Closing the hand on the object, gravity off (docs/SIM.md, "What the closing does"): joint 1
//! first, then joint 2, each until the hand and the object stop ([`STALL`]) or for its share of
//! `close_duration_s`, then with `reseat` the locked joint 1s that are off the object, until
//! they touch and the object stops (at most another half); and what the closing did: the
//! object's shift, the joints' errors against the plan, which phalanx touched first, the
//! penetration left. Units: millimetres and degrees in what it reports, SI inside rapier.

use super::convert;
use super::outcome::{ClosingOutcome, Fidelity, FingerClosing, FirstTouch, WITHIN_PLAN_DEG};
use super::scene::{poses, relative, Case, Scene};
use nalgebra::{UnitQuaternion, Vector3};
use rapier3d::prelude::*;

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

/// Where the closing left the object, and how it got there.
#[derive(Debug, Clone)]
pub(super) struct Closing {
    /// Object translation relative to the palm at the start `[mm]`.
    pub(super) p0: Vector3<f64>,
    /// Object rotation relative to the palm at the start.
    pub(super) q0: UnitQuaternion<f64>,
    /// What the closing did, as reported.
    pub(super) outcome: ClosingOutcome,
    /// Where it left the bodies.
    pub(super) poses: Vec<super::BodyPose>,
    /// ... and after closing `[mm]`.
    pub(super) pc: Vector3<f64>,
    /// Object rotation relative to the palm after closing.
    pub(super) qc: UnitQuaternion<f64>,
    /// Per finger, joint bend after closing minus the plan `[deg]`.
    pub(super) joint_errors_deg: Vec<[f64; 2]>,
    /// Deepest penetration of a hand collider into the object after closing `[mm]`.
    pub(super) penetration_mm: f64,
    /// Steps taken.
    pub(super) steps: usize,
    /// The contacts carrying the grip when closing ended.
    pub(super) contacts: Vec<super::contacts::GripContact>,
    /// Whether the closing kept the planned grasp.
    pub(super) fidelity: Fidelity,
}

impl Closing {
    /// True if the closing did not keep the planned grasp: it pushed the object beyond
    /// `max_closing_shift_mm`, left fewer phalanges on their plan than `min_on_plan_fraction`
    /// asks, or left a finger deeper than `max_penetration_mm` (or a depth that is no number).
    /// Gravity's verdict does not depend on it; the fidelity reports it.
    pub(super) fn failed(&self) -> bool {
        !self.fidelity.as_planned
    }
}

/// How long the `timed` approach (`[sim] approach = "timed"`) takes to move every finger's
/// joint 1 target from its open bend to its planned bend `[s]`: the fingers arrive together.
pub const RAMP_S: f64 = 0.1;

/// Closes the hand, gravity off: joint 1 first, then joint 2, each for half `close_duration_s`
/// or, with `close_until_stalled`, until the hand and the object have stopped ([`STALL`]); with
/// `reseat`, the locked joint 1s move on until their phalanx 1 touches (for at most another
/// half).
pub(super) fn close(scene: &mut Scene, case: &Case) -> Closing {
    let params = case.params;
    let dt = params.solver.timestep_s;
    let close_steps = (params.closing.close_duration_s / dt).round() as usize;
    let (p0, q0) = relative(scene);
    trace::start(case);
    let mut run = Phases {
        p0,
        stall: params.closing.close_until_stalled.then_some(&STALL),
        dt,
        steps: 0,
        first_contact: FirstContacts::new(scene.fingers.len()),
        together: Together {
            waiting: params.closing.approach == super::params::Approach::Together,
            held: vec![false; scene.fingers.len()],
        },
        ramp: (params.closing.approach == super::params::Approach::Timed)
            .then(|| Ramp::new(scene, case, (RAMP_S / dt).round().max(1.0) as usize)),
    };
    // Joint 1 closes for at most half the closing time, joint 2 for the rest.
    run.phase(scene, close_steps / 2);
    trace::phase_end(scene, case, p0, 0, run.steps);
    if run.together.waiting {
        run.together.release(scene);
    }
    if let Some(ramp) = run.ramp.take() {
        ramp.finish(scene);
    }
    scene.release_joint2();
    run.phase(scene, close_steps - close_steps / 2);
    trace::phase_end(scene, case, p0, 1, run.steps);
    if params.closing.reseat {
        reseat(scene, case, &mut run, close_steps / 2);
        trace::phase_end(scene, case, p0, 2, run.steps);
    }
    closed(scene, case, (p0, q0), &run.first_contact, run.steps)
}

/// The closing's running state: its stall rule, the steps taken, the first contacts, and the
/// approach's state.
struct Phases<'a> {
    /// The object's position relative to the palm at the start `[mm]` (for the trace).
    p0: Vector3<f64>,
    stall: Option<&'a Stall>,
    dt: f64,
    steps: usize,
    first_contact: FirstContacts,
    together: Together,
    ramp: Option<Ramp>,
}

impl Phases<'_> {
    /// Steps one closing phase: at most `max_steps`, or until the hand and the object stop.
    fn phase(&mut self, scene: &mut Scene, max_steps: usize) {
        let mut quiet_steps = 0;
        for _ in 0..max_steps {
            if let Some(ramp) = &mut self.ramp {
                ramp.advance(scene);
            }
            scene.world.step();
            self.steps += 1;
            trace::every_10_ms(scene, self.p0, self.steps, self.dt);
            let now = touching(scene);
            self.first_contact.update(&now, self.steps as f64 * self.dt);
            if self.together.hold_touching(scene, &now) {
                quiet_steps = 0;
            }
            let Some(rule) = self.stall else { continue };
            if self.ramp.as_ref().is_some_and(|r| !r.done()) || !rule.quiet(motion(scene)) {
                quiet_steps = 0;
                continue;
            }
            quiet_steps += 1;
            if quiet_steps as f64 * self.dt >= rule.window_s {
                if self.together.waiting {
                    // A finger that stopped without touching: the others squeeze now.
                    self.together.release(scene);
                    quiet_steps = 0;
                    continue;
                }
                break;
            }
        }
    }
}

/// The `timed` approach: every finger's joint 1 target moves from where it starts to its planned
/// bend over the same number of steps, then to its squeeze target.
struct Ramp {
    /// Per finger, joint 1's bend at the start `[rad]`.
    open: Vec<f32>,
    /// Steps taken, and the steps the ramp lasts.
    step: usize,
    steps: usize,
    /// The motors' stiffness and damping.
    gains: (f32, f32),
}

impl Ramp {
    fn new(scene: &Scene, case: &Case, steps: usize) -> Ramp {
        let open = scene
            .fingers
            .iter()
            .map(|f| f.joint1.angle(&scene.world).unwrap_or(0.0))
            .collect();
        Ramp {
            open,
            step: 0,
            steps,
            gains: motor_gains(case),
        }
    }

    /// True once every target has reached its planned bend.
    fn done(&self) -> bool {
        self.step >= self.steps
    }

    /// Moves every target one step on; at the end of the ramp, on to the squeeze targets.
    fn advance(&mut self, scene: &mut Scene) {
        if self.done() {
            return;
        }
        self.step += 1;
        if self.done() {
            return self.finish(scene);
        }
        let s = self.step as f32 / self.steps as f32;
        for (k, open) in self.open.iter().enumerate() {
            let planned = scene.fingers[k].planned_bend_rad[0] as f32;
            self.target(scene, k, open + (planned - open) * s);
        }
    }

    /// Every finger's joint 1 on to its squeeze target.
    fn finish(&self, scene: &mut Scene) {
        for k in 0..self.open.len() {
            self.target(scene, k, scene.fingers[k].joint1_target);
        }
    }

    /// Finger `k`'s joint 1 motor aims at `bend` `[rad]` (its torque limit kept).
    fn target(&self, scene: &mut Scene, k: usize, bend: f32) {
        let f = scene.fingers[k];
        f.joint1.set_motor(&mut scene.world, bend, self.gains, None);
    }
}

/// The finger motors' (stiffness, damping) of `case`.
fn motor_gains(case: &Case) -> (f32, f32) {
    let fingers = &case.params.fingers;
    (
        fingers.motor_stiffness_nm_per_rad as f32,
        fingers.motor_damping_nms_per_rad as f32,
    )
}

/// How fast `[sim] reseat` moves a locked joint 1 on towards its squeeze target `[rad/s]`
/// (20°/s: a phalanx lifted 0.5 mm off at 50 mm is back on in 30 ms).
pub const RESEAT_RAD_S: f64 = 0.349_065_850_398_865_9;

/// `[sim] reseat`, after joint 2 has closed: every locked joint 1 whose phalanx 1 does not
/// touch the object moves on, position-controlled by its lock (its stiffness, its torque), at
/// [`RESEAT_RAD_S`] until its phalanx touches or it reaches its squeeze target. The phase ends
/// when no joint moves on any more and the object has stopped ([`STALL`]'s object speeds, for
/// its window), or after `max_steps`: a joint 2 whose phase ended at its time cap rather than
/// stalled may still be moving then.
fn reseat(scene: &mut Scene, case: &Case, run: &mut Phases, max_steps: usize) {
    let (k, d) = motor_gains(case);
    let lock = Some(case.params.fingers.joint1_lock_torque_nm as f32);
    let step_rad = (RESEAT_RAD_S * run.dt) as f32;
    let mut at: Vec<f32> = scene
        .fingers
        .iter()
        .map(|f| f.joint1.angle(&scene.world).unwrap_or(f.joint1_target))
        .collect();
    let mut quiet_steps = 0;
    for _ in 0..max_steps {
        let now = touching(scene);
        let mut moving = false;
        for (i, (f, (a, t))) in scene
            .fingers
            .iter()
            .zip(at.iter_mut().zip(&now.fingers))
            .enumerate()
        {
            let lifted = !case.params.closing.reseat_only_lifted
                || run.first_contact.fingers[i][0].is_some();
            if !t[0] && lifted && *a < f.joint1_target {
                *a = (*a + step_rad).min(f.joint1_target);
                f.joint1
                    .set_motor(&mut scene.world, *a, (k * 10.0, d), lock);
                moving = true;
            }
        }
        scene.world.step();
        run.steps += 1;
        trace::every_10_ms(scene, run.p0, run.steps, run.dt);
        run.first_contact
            .update(&touching(scene), run.steps as f64 * run.dt);
        let Some(rule) = run.stall else { continue };
        // The object's speeds only: every joint 1 is locked where it was commanded, and a
        // seated finger's joint 2, pressing at its torque limit, chatters at 0.01-0.04 rad/s
        // (about the rule's 0.02) for as long as the phase lasts (the D40's thumb: the whole
        // 0.25 s), which says nothing about where the grasp is.
        let (_, object_mm_s, object_rad_s) = motion(scene);
        if moving || !rule.quiet((0.0, object_mm_s, object_rad_s)) {
            quiet_steps = 0;
        } else {
            quiet_steps += 1;
            if quiet_steps as f64 * run.dt >= rule.window_s {
                break;
            }
        }
    }
}

/// Where the closing left the hand and the object after `steps`, from the object's pose
/// relative to the palm at the start, `(p0, q0)`, and the first contacts.
fn closed(
    scene: &Scene,
    case: &Case,
    (p0, q0): (Vector3<f64>, UnitQuaternion<f64>),
    first_contact: &FirstContacts,
    steps: usize,
) -> Closing {
    let dt = case.params.solver.timestep_s;
    let (pc, qc) = relative(scene);
    let joint_errors_deg = joint_errors(scene);
    // The set the check commanded: the plan, refined by the contact unless that is off.
    let commanded: Vec<[f64; 2]> = scene
        .fingers
        .iter()
        .map(|f| f.planned_bend_rad.map(crate::plan::refine::theta_deg))
        .collect();
    let outcome = closing_outcome(
        case,
        first_contact,
        &touching(scene),
        &gaps_mm(scene),
        (&commanded, &joint_errors_deg),
        ((pc - p0).norm(), q0.angle_to(&qc).to_degrees()),
        steps as f64 * dt,
    );
    let penetration_mm = penetration_mm(scene);
    let fidelity = Fidelity::of(
        &outcome,
        penetration_mm,
        case.params.hold.max_penetration_mm,
    );
    Closing {
        p0,
        q0,
        pc,
        qc,
        penetration_mm,
        fidelity,
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
                super::contacts::separation_m(
                    c.position(),
                    c.shape(),
                    object.position(),
                    object.shape(),
                )
            })
            .map(|d| d * 1000.0)
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    };
    scene
        .fingers
        .iter()
        .map(|f| [gap(f.phalanx1), gap(f.phalanx2)])
        .collect()
}

/// The `together` approach (`[sim] approach`): fingers held where they touched, until all have
/// or the hand has stopped.
struct Together {
    /// True while fingers wait for the others (always false under `squeeze`).
    waiting: bool,
    /// Per finger, true if and only if it is held.
    held: Vec<bool>,
}

impl Together {
    /// While waiting, holds every finger that touches the object `now` and is not held yet;
    /// once all are held, sends them on together. Returns true if and only if it did now.
    fn hold_touching(&mut self, scene: &mut Scene, now: &Touching) -> bool {
        if !self.waiting {
            return false;
        }
        for (k, t) in now.fingers.iter().enumerate() {
            if (t[0] || t[1]) && !self.held[k] {
                scene.hold_joint1(k, true);
                self.held[k] = true;
            }
        }
        if self.held.iter().all(|h| *h) {
            self.release(scene);
            return true;
        }
        false
    }

    /// Sends every held finger on to its squeeze target, and stops waiting.
    fn release(&mut self, scene: &mut Scene) {
        release_held(scene, &mut self.held);
        self.waiting = false;
    }
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
    (commanded, errors): (&[[f64; 2]], &[[f64; 2]]),
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
        .zip(commanded.iter().zip(&case.pose.theta_deg))
        .zip(errors)
        .zip(end.fingers.iter().zip(&first.fingers).zip(gaps))
        .map(
            |(((name, (planned, als)), error), ((touching, first), gap))| FingerClosing {
                name: name.clone(),
                planned_deg: *planned,
                als_deg: *als,
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
    let max_shift_mm = case.params.hold.max_closing_shift_mm;
    let min_on_plan = min_on_plan(case.params.hold.min_on_plan_fraction, 2 * fingers.len());
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
        min_on_plan,
        off_plan: phalanges_on_plan < min_on_plan,
    }
}

/// The least number of `phalanges` that must end on their plan: `fraction` of them, rounded
/// up (half of six is three; a hair over half is four).
pub(super) fn min_on_plan(fraction: f64, phalanges: usize) -> usize {
    // A fraction times a count is exact for the fractions a user writes (0.5 × 6 = 3); the
    // tolerance keeps 1/3 × 6 at 2 rather than 3.
    ((fraction * phalanges as f64) - 1e-9).ceil().max(0.0) as usize
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

/// Per finger, each joint's bend minus its planned bend `[deg]`.
pub(super) fn joint_errors(scene: &Scene) -> Vec<[f64; 2]> {
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

/// `GRASP_SIM_TRACE_CLOSING=1`: rapier's closing on stderr, in the format of
/// `scripts/mujoco_replay.py --trace` (the object's shift from its start relative to the palm
/// every 10 ms, each joint's bend minus its plan, the bodies touching the object; at the end of
/// each phase every contact carrying force, in the palm frame). A diagnostic: the check's
/// result is the same with or without it.
pub(super) mod trace {
    use super::{joint_errors, relative, touching, Case, Scene};
    use nalgebra::Vector3;
    use std::sync::OnceLock;

    fn on() -> bool {
        static ON: OnceLock<bool> = OnceLock::new();
        *ON.get_or_init(|| std::env::var_os("GRASP_SIM_TRACE_CLOSING").is_some_and(|v| v == "1"))
    }

    fn line(scene: &Scene, p0: Vector3<f64>, stamp: &str) {
        let (pc, _) = relative(scene);
        let d = pc - p0;
        let errors: Vec<String> = joint_errors(scene)
            .iter()
            .flat_map(|e| e.map(|x| format!("{x:+.1}")))
            .collect();
        let now = touching(scene);
        let mut names = Vec::new();
        if now.palm {
            names.push("palm".to_string());
        }
        for (k, t) in now.fingers.iter().enumerate() {
            for (j, on) in t.iter().enumerate() {
                if *on {
                    names.push(format!("finger_{}_phalanx_{}", k + 1, j + 1));
                }
            }
        }
        eprintln!(
            "{stamp}: shift {:.2} mm [{:.2} {:.2} {:.2}], bend - plan [deg] {}, touching {:?}",
            d.norm(),
            d.x,
            d.y,
            d.z,
            errors.join(" "),
            names
        );
    }

    /// During the hold: the object's translation from where the closing left it, every 50 ms.
    pub(in crate::sim) fn hold(scene: &Scene, pc: Vector3<f64>, steps: usize, dt: f64) {
        if on() && steps.is_multiple_of(((0.05 / dt).round() as usize).max(1)) {
            line(scene, pc, &format!("hold t={:.3} s", steps as f64 * dt));
        }
    }

    pub(super) fn start(case: &Case) {
        if on() {
            eprintln!("closing: theta planned {:?} deg", case.pose.theta_deg);
        }
    }

    pub(super) fn every_10_ms(scene: &Scene, p0: Vector3<f64>, steps: usize, dt: f64) {
        if on() && steps.is_multiple_of(((0.01 / dt).round() as usize).max(1)) {
            line(scene, p0, &format!("t={:.3} s", steps as f64 * dt));
        }
    }

    pub(super) fn phase_end(
        scene: &Scene,
        case: &Case,
        p0: Vector3<f64>,
        phase: usize,
        steps: usize,
    ) {
        if !on() {
            return;
        }
        let dt = case.params.solver.timestep_s;
        line(
            scene,
            p0,
            &format!("end of phase {phase} (t={:.3} s)", steps as f64 * dt),
        );
        let (pc, qc) = relative(scene);
        for c in super::super::contacts::grip_contacts(scene) {
            let p = qc * Vector3::from(c.point_mm) + pc;
            let n = qc * Vector3::from(c.normal);
            let body = match c.finger {
                None => "palm".to_string(),
                Some(k) => format!("finger_{}_phalanx_{}", k + 1, c.phalanx),
            };
            eprintln!(
                "    {body:20} at [{:.1} {:.1} {:.1}] mm, normal (hand on object) [{:.2} {:.2} {:.2}], {:.2} N normal",
                p.x, p.y, p.z, n.x, n.y, n.z, c.force_n
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_on_plan_is_the_fraction_of_the_phalanges_rounded_up() {
        assert_eq!(min_on_plan(0.5, 6), 3);
        assert_eq!(min_on_plan(0.51, 6), 4);
        assert_eq!(min_on_plan(1.0 / 3.0, 6), 2);
        assert_eq!(min_on_plan(0.0, 6), 0);
        assert_eq!(min_on_plan(1.0, 6), 6);
        assert_eq!(min_on_plan(0.5, 8), 4);
        assert_eq!(min_on_plan(0.5, 5), 3);
    }

    #[test]
    fn the_stall_rule_needs_every_speed_below_its_bound() {
        // 0.02 rad/s for the joints, 0.5 mm/s and 0.01 rad/s for the object.
        assert!(STALL.quiet((0.019, 0.49, 0.009)));
        assert!(!STALL.quiet((0.02, 0.0, 0.0)));
        assert!(!STALL.quiet((0.0, 0.5, 0.0)));
        assert!(!STALL.quiet((0.0, 0.0, 0.01)));
    }

    #[test]
    fn the_first_touch_is_the_earliest_the_palm_first_on_a_tie() {
        let names = ["finger_1".to_string(), "thumb".to_string()];
        let touch = |palm, fingers: Vec<[bool; 2]>| Touching { palm, fingers };
        let mut first = FirstContacts::new(2);
        assert_eq!(first.first(&names), None);
        first.update(&touch(false, vec![[false, false], [false, true]]), 0.10);
        // A later touch of the same phalanx keeps its first time.
        first.update(&touch(false, vec![[true, false], [false, true]]), 0.15);
        assert_eq!(first.fingers, vec![[Some(0.15), None], [None, Some(0.10)]]);
        let t = first.first(&names).unwrap();
        assert_eq!((t.body.as_str(), t.phalanx, t.at_s), ("thumb", 2, 0.10));
        // The palm at the same time as a finger comes first.
        let mut tie = FirstContacts::new(2);
        tie.update(&touch(true, vec![[true, false], [false, false]]), 0.2);
        let t = tie.first(&names).unwrap();
        assert_eq!((t.body.as_str(), t.phalanx), ("palm", 0));
    }
}
