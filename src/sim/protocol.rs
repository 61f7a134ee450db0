//! The hold test: close, gravity on, hold, measure, judge.

use super::convert;
use super::scene::{build, Case, Scene};
use crate::scenario::{GravityMode, SimParams};
use nalgebra::Vector3;
use rapier3d::prelude::*;
use std::time::Instant;

/// The verdict of the hold test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// The object stayed within the thresholds.
    Hold,
    /// It moved beyond them but still touches the hand.
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
    /// Largest difference between a joint's bend after closing and its planned bend `[deg]`
    /// (negative: stopped short of the plan, i.e. contact earlier than planned).
    pub joint_error_deg: f64,
    /// Per finger, the two joints' bend after closing minus the planned bend `[deg]`.
    pub joint_errors_deg: Vec<[f64; 2]>,
    /// True if and only if the object touches the hand at the end.
    pub in_contact: bool,
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
}

/// Standard gravity `[m/s²]`.
const G: f64 = 9.81;

/// Runs the hold test for every gravity direction of `params.gravity`.
///
/// The rotation judged is the full rotation relative to the palm, except for an object that is
/// (inertially) a body of revolution about its principal axis (`object.is_revolution`): a spin
/// about that axis leaves it occupying the same space in the hand, so only the tilt of the axis
/// counts.
pub fn check(case: &Case) -> SimOutcome {
    let params = case.params;
    let t0 = Instant::now();
    let directions: Vec<Vector3<f64>> = match params.gravity {
        GravityMode::Down => vec![-Vector3::z()],
        GravityMode::Six => vec![
            Vector3::x(),
            -Vector3::x(),
            Vector3::y(),
            -Vector3::y(),
            Vector3::z(),
            -Vector3::z(),
        ],
    };
    let mut outcomes = Vec::new();
    let mut steps = 0;
    let mut final_poses = Vec::new();
    for g in directions {
        let mut scene = build(case);
        let (o, n) = run_one(&mut scene, g, params, case.object.is_revolution);
        if final_poses.is_empty() {
            let mut handles = vec![scene.palm];
            for &(b1, b2, _, _) in &scene.fingers {
                handles.push(b1);
                handles.push(b2);
            }
            handles.push(scene.object);
            final_poses = handles
                .iter()
                .map(|h| {
                    let p = scene.world.bodies[*h].position();
                    (
                        convert::vector_mm(p.translation) * convert::M_PER_MM,
                        convert::unit_quaternion(p.rotation),
                    )
                })
                .collect();
        }
        outcomes.push(o);
        steps += n;
    }
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
    }
}

/// The object's pose relative to the palm: (translation in mm, rotation).
fn relative(scene: &Scene) -> (Vector3<f64>, nalgebra::UnitQuaternion<f64>) {
    let palm = scene.world.bodies[scene.palm].position();
    let obj = scene.world.bodies[scene.object].position();
    let rel = palm.inverse() * *obj;
    (
        convert::vector_mm(rel.translation),
        convert::unit_quaternion(rel.rotation),
    )
}

fn run_one(
    scene: &mut Scene,
    gravity: Vector3<f64>,
    params: &SimParams,
    is_revolution: bool,
) -> (DirectionOutcome, usize) {
    let dt = params.timestep_s;
    let close_steps = (params.close_duration_s / dt).round() as usize;
    let hold_steps = (params.duration_s / dt).round() as usize;
    let (p0, q0) = relative(scene);
    // Joint 1 closes first; joint 2 follows halfway through the closing time.
    for i in 0..close_steps {
        if i == close_steps / 2 {
            scene.release_joint2();
        }
        scene.world.step();
    }
    let (pc, qc) = relative(scene);
    let joint_errors_deg = joint_errors(scene);
    let joint_error_deg = joint_errors_deg
        .iter()
        .flatten()
        .copied()
        .fold(0.0f64, |w, e| if e.abs() > w.abs() { e } else { w });
    let g = gravity * G;
    scene.world.gravity = Vector::new(g.x as f32, g.y as f32, g.z as f32);
    for _ in 0..hold_steps {
        scene.world.step();
    }
    let (pe, qe) = relative(scene);
    let translation_mm = (pe - pc).norm();
    let rotation_deg = qc.angle_to(&qe).to_degrees();
    let tilt_deg = (qc * Vector3::z()).angle(&(qe * Vector3::z())).to_degrees();
    let in_contact = scene
        .world
        .narrow_phase
        .contact_pairs_with(scene.object_collider)
        .any(|pair| {
            pair.has_any_active_contact()
                && (scene.hand_colliders.contains(&pair.collider1)
                    || scene.hand_colliders.contains(&pair.collider2))
        });
    let judged_rotation = if is_revolution {
        tilt_deg
    } else {
        rotation_deg
    };
    let verdict = if translation_mm <= params.hold_translation_mm
        && judged_rotation <= params.hold_rotation_deg
    {
        Verdict::Hold
    } else if in_contact {
        Verdict::Slip
    } else {
        Verdict::Drop
    };
    let _ = (p0, q0);
    (
        DirectionOutcome {
            gravity: [gravity.x, gravity.y, gravity.z],
            verdict,
            translation_mm,
            rotation_deg: judged_rotation,
            full_rotation_deg: rotation_deg,
            tilt_deg,
            closing_translation_mm: (pc - p0).norm(),
            joint_error_deg,
            joint_errors_deg,
            in_contact,
        },
        close_steps + hold_steps,
    )
}

/// Per finger, each joint's bend minus its planned bend `[deg]`.
fn joint_errors(scene: &Scene) -> Vec<[f64; 2]> {
    let bodies = &scene.world.bodies;
    let rp = *bodies[scene.palm].rotation();
    scene
        .fingers
        .iter()
        .map(|&(b1, b2, t1, t2)| {
            let r1 = *bodies[b1].rotation();
            let r2 = *bodies[b2].rotation();
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
/// the grasp held at 64×.
pub fn payload_bracket(case: &Case) -> (f64, Option<f64>) {
    let holds = |k: f64| check(&case.heavier(k)).verdict == Verdict::Hold;
    let mut lo = 1.0;
    let mut hi = None;
    let mut k = 2.0;
    while k <= 64.0 {
        if holds(k) {
            lo = k;
            k *= 2.0;
        } else {
            hi = Some(k);
            break;
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
