//! The physics check (DESIGN.md section 5, beyond the thesis, which stops at kinematics: its 6.2):
//! does the planned grasp hold the object under gravity?
//!
//! Units: SI (metres, kilograms, seconds, newton-metres) inside rapier; the interface takes the
//! planner's millimetres and degrees and [`convert`] converts once. The scene is built in the
//! aligned object frame, where the thesis's weight acts along −Z.
//!
//! Files: [`entry`] (the entry points by purpose: which check runs in full, replays a sample or
//! adds the samples), [`params`] (the `[sim]` table), [`scene`] (the rapier scene and where it
//! starts), [`collider`] (the object's collision shape), [`protocol`] (the two protocols'
//! drivers), [`closing`], [`hold`] with [`early`] (the rest rule) and [`flight`] (drop
//! detection), [`payload`], [`robust`] (the hold probability under perturbation), [`outcome`]
//! (what is reported), [`contacts`] (the grip's contacts) and [`convert`] (nalgebra to glam,
//! millimetres to metres).
//!
//! Scene ([`scene`]): the palm is a fixed box at the planned pose; each phalanx is a dynamic box
//! (finger width and thickness 2 × finger offset; phalanx 2's thinned tip as a thinner box); joints
//! are revolute on the finger joint axes with the hand's limits, as multibody (reduced-coordinate)
//! joints: a 10 g phalanx pressing a 0.2 kg object is a mass ratio that makes impulse joints
//! stretch and drift under load, while a multibody chain cannot come apart (`[sim] hand_joints =
//! "impulse"` builds them as impulse joints instead, [`impulse_hand`], measured and not adopted:
//! docs/SIM.md). Each joint has a force-based position motor (stiffness, damping) whose torque is
//! capped by the torque limit, driving towards the planned angle closed further by the squeeze
//! overshoot, so the torque limit, not the target, bounds the grip. The object is a dynamic body
//! with the scenario's mass and friction; its collider is the convex hull of the aligned mesh when
//! the mesh is convex (hull volume within 2 % of the mesh's), a convex decomposition otherwise (a
//! bare triangle mesh has no inside and lets fingers sink in).
//!
//! Protocol ([`protocol`]): fingers start open (each joint `open_margin_deg` short of its plan),
//! gravity off; joint 1 closes first, then joint 2 (thesis 3.6.2 fixes phalanx 1 before phalanx
//! 2; closing both at once lets phalanx 2's tip, which sweeps the larger arc, reach the object
//! first and hold phalanx 1 off it), each phase until the hand and the object stop
//! (`close_until_stalled`) and at most half of `close_duration_s`; gravity turns on (`down`:
//! −Z; `six`: ±X, ±Y, ±Z, as DexGraspNet and BODex test) for `duration_s`, or under the `fast`
//! protocol until the verdict can no longer change. The object's motion
//! relative to the palm during the hold gives the verdict: `hold` within the thresholds, `slip`
//! beyond them while still touching the hand, `drop` when it has left the hand.

pub mod closing;
pub mod collider;
pub mod collider_cache;
pub mod contacts;
pub mod convert;
pub mod dispatcher;
pub mod early;
pub mod entry;
pub mod fast_hull;
pub mod flight;
pub mod hand_shapes;
pub mod hold;
pub mod impulse_hand;
pub mod outcome;
pub mod params;
pub mod payload;
pub mod protocol;
pub mod refine;
pub mod robust;
pub mod scene;

pub use closing::{Stall, RAMP_S, RESEAT_RAD_S, STALL};
pub use collider::{
    collider_inertia, object_mass_properties, ColliderKind, ColliderReport, MeshMass, ObjectShape,
};
pub use early::EarlyDecision;
pub use outcome::{
    ClosingOutcome, DecidedBy, DirectionOutcome, Fidelity, FidelityReason, FingerClosing,
    FirstTouch, SimOutcome, Verdict,
};
pub use payload::{check_with_payload, payload_bracket, payload_margin};
pub use protocol::{check, check_closed, Closed};
pub use robust::{Perturbation, Robust};
pub use scene::{Case, SimHand};

/// A body's pose: position `[m]` and orientation, aligned object frame.
pub type BodyPose = (nalgebra::Vector3<f64>, nalgebra::UnitQuaternion<f64>);
