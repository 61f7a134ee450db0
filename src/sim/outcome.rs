//! What the physics check reports: the verdict, the outcome per gravity direction and over all of
//! them, what the closing did to the planned grasp, and whether the grasp that held is the one
//! planned (its fidelity). Units as in the JSON: millimetres, degrees, seconds.
//!
//! Two questions, two fields (issue 55): the [`Verdict`] says what gravity did (the hold
//! thresholds alone); the [`Fidelity`] says whether the closing kept the planned grasp
//! (`max_closing_shift_mm`, `min_on_plan_fraction`, `max_penetration_mm`), with the continuous
//! figures that decided it.

use nalgebra::Vector3;

/// The verdict of the hold test: what gravity did to the object in the hand, judged by the hold
/// thresholds alone (`hold_translation_mm`, `hold_rotation_deg`). Whether the grasp that held
/// is the one planned is the [`Fidelity`]'s question, not this one's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verdict {
    /// The object stayed within the thresholds relative to the palm.
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

    /// The verdict whose name ([`Verdict::as_str`]) is `name`; `None` for any other string.
    pub fn named(name: &str) -> Option<Verdict> {
        [Verdict::Hold, Verdict::Slip, Verdict::Drop]
            .into_iter()
            .find(|v| v.as_str() == name)
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// The result for one gravity direction (the JSON's `sim.directions` reports it as
/// `report::DirectionOutcome`).
#[derive(Debug, Clone, PartialEq)]
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
    /// True if and only if the closing pushed the object farther than `max_closing_shift_mm`
    /// (the grasp is then not as planned; the verdict is gravity's alone).
    pub closing_pushed: bool,
    /// True if and only if fewer phalanges ended the closing on their plan than
    /// `min_on_plan_fraction` asks (the grasp is then not as planned).
    pub closing_off_plan: bool,
    /// True if and only if the closing this direction continued from kept the planned grasp
    /// ([`Fidelity::as_planned`]).
    pub as_planned: bool,
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
    pub decided_by: DecidedBy,
    /// Object translation relative to the palm at the decision `[mm]`. For `out_of_reach`,
    /// `translation_mm` is this continued in free flight to the end of the hold.
    pub translation_at_decision_mm: f64,
}

/// What decided a direction's verdict (`decided_by` in the JSON's `sim.directions`; docs/SIM.md,
/// "Deciding early").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecidedBy {
    /// The direction ran the whole hold.
    End,
    /// At rest relative to the palm: the remaining motion cannot bring the object across a
    /// threshold (within them, `hold`; slid beyond one and resting on the hand, `slip`).
    Rest,
    /// The object left the hand's reach for good: `drop`.
    OutOfReach,
    /// The object flies clear of the resting hand for good: `drop`.
    ClearOfHand,
    /// The closing did not keep the planned grasp ([`Fidelity::as_planned`] false) and `[sim]
    /// closing_decides` is on: no hold was run, so the verdict (`slip` if the object touches
    /// the hand after the closing, else `drop`) is provisional, not gravity's. The candidate
    /// search checks such a candidate again in full before it reports or chooses it.
    Closing,
}

impl DecidedBy {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            DecidedBy::End => "end",
            DecidedBy::Rest => "rest",
            DecidedBy::OutOfReach => "out_of_reach",
            DecidedBy::ClearOfHand => "clear_of_hand",
            DecidedBy::Closing => "closing",
        }
    }

    /// Returns true if and only if the object was decided to have left the hand: a `drop`
    /// whatever else the hold measured.
    pub fn is_drop(self) -> bool {
        matches!(self, DecidedBy::OutOfReach | DecidedBy::ClearOfHand)
    }
}

impl std::fmt::Display for DecidedBy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// The physics check's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutcome {
    /// The worst verdict over the gravity directions.
    pub verdict: Verdict,
    /// Whether the grasp that held is the one planned (the first direction's closing; under
    /// the `full` protocol, `as_planned` only if every direction's closing kept the plan).
    pub fidelity: Fidelity,
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
    /// The hold probability under `[sim] samples` perturbations, when they ran.
    pub robust: Option<super::robust::Robust>,
    /// The perturbation this check ran under (`[sim] replay_sample`); `None`: the scenario's
    /// case as given.
    pub replay: Option<super::robust::Perturbation>,
}

impl SimOutcome {
    /// Returns true if and only if the check counts as a success for the candidate search: the
    /// lower bound of the probability of a hold as planned reaches `[sim]
    /// choose_min_lower_bound` when the samples ran for it (`choose = "robust"`), else the main
    /// check held as planned.
    pub fn succeeded(&self) -> bool {
        match &self.robust {
            Some(r) => r.passes,
            None => self.held_as_planned(),
        }
    }

    /// Returns true if and only if the main check's verdict is `hold` and its closing kept the
    /// planned grasp.
    pub fn held_as_planned(&self) -> bool {
        self.verdict == Verdict::Hold && self.fidelity.as_planned
    }

    /// The candidate search's preference (issue 55), best first: 0 held as planned, 1 held
    /// (not as planned), 2 slip, 3 drop.
    pub fn preference(&self) -> u8 {
        match self.verdict {
            Verdict::Hold if self.fidelity.as_planned => 0,
            Verdict::Hold => 1,
            Verdict::Slip => 2,
            Verdict::Drop => 3,
        }
    }

    /// Returns true if and only if a failed closing decided the check without a hold (`[sim]
    /// closing_decides`): its `slip` or `drop` says only whether the object touched the hand
    /// when the closing ended, not whether it would stay there under gravity.
    pub fn decided_by_closing(&self) -> bool {
        self.directions
            .iter()
            .any(|d| d.decided_by == DecidedBy::Closing)
    }
}

/// What the closing did to the planned grasp (issue 33, docs/SIM.md "What the closing does"):
/// how far it pushed the object, where each joint stopped against its plan, and which phalanx
/// touched the object first. Reported as `sim.closing`.
#[derive(Debug, Clone, PartialEq)]
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
    /// The least `phalanges_on_plan` for a hold of the planned grasp: `[sim]
    /// min_on_plan_fraction` of the hand's phalanges, rounded up.
    pub min_on_plan: usize,
    /// True if and only if `phalanges_on_plan` is below `min_on_plan`: the object was caught
    /// by a different grasp from the one planned, and the verdict is not `hold`.
    pub off_plan: bool,
}

/// A phalanx ends the closing "on its plan" when it touches the object and its joint is within
/// this of the planned bend `[deg]` (the thesis's Joint Angular Deviation, 5°).
pub const WITHIN_PLAN_DEG: f64 = 5.0;

/// The first touch of the closing.
#[derive(Debug, Clone, PartialEq)]
pub struct FirstTouch {
    /// `palm`, or the finger's name.
    pub body: String,
    /// 1 or 2 for a finger's phalanx, 0 for the palm.
    pub phalanx: usize,
    /// Time into the closing `[s]`.
    pub at_s: f64,
}

/// One finger's closing: planned and final joint angles, in the thesis's interior angles.
#[derive(Debug, Clone, PartialEq)]
pub struct FingerClosing {
    /// The finger's name.
    pub name: String,
    /// Planned `[θ1, θ2]` `[deg]`: the set the check commanded (plus its squeeze), the Grasp
    /// Parameter Set refined by the contact (`[sim] refine_contacts`, `sim::refine`), or the
    /// planner's own when the refinement is off.
    pub planned_deg: [f64; 2],
    /// The planner's `[θ1, θ2]` `[deg]` (the thesis's ALS angles, `plan.grasp.fingers`), before
    /// any refinement.
    pub als_deg: [f64; 2],
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

/// Why a closing did not keep the planned grasp: one entry of [`Fidelity::reasons`], named in
/// the JSON by the key that bounds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FidelityReason {
    /// The closing pushed the object farther than `max_closing_shift_mm`.
    Pushed,
    /// Fewer phalanges ended on their plan than `min_on_plan_fraction` asks.
    OffPlan,
    /// A hand collider ended the closing deeper inside the object than `max_penetration_mm`
    /// (or at a depth that is no number): not a grip a real hand makes.
    Penetrated,
}

impl FidelityReason {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            FidelityReason::Pushed => "pushed",
            FidelityReason::OffPlan => "off_plan",
            FidelityReason::Penetrated => "penetrated",
        }
    }
}

impl std::fmt::Display for FidelityReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// Whether the grasp the closing made is the one planned (issue 55; `sim.fidelity` in the JSON,
/// also per candidate): the bounds as a yes or no, and the continuous figures that decided it,
/// for an engine comparison or a tuning to use.
#[derive(Debug, Clone, PartialEq)]
pub struct Fidelity {
    /// True if and only if `reasons` is empty: the closing pushed the object no farther than
    /// `max_closing_shift_mm`, left at least `min_on_plan_fraction` of the phalanges on their
    /// plan and no hand collider deeper in the object than `max_penetration_mm`.
    pub as_planned: bool,
    /// Object translation relative to the palm over the closing `[mm]`.
    pub shift_mm: f64,
    /// Object rotation relative to the palm over the closing `[deg]`.
    pub turn_deg: f64,
    /// Phalanges that end the closing touching the object within [`WITHIN_PLAN_DEG`] of their
    /// planned bend.
    pub phalanges_on_plan: usize,
    /// The hand's phalanges.
    pub phalanges: usize,
    /// The largest joint error against the plan, by magnitude, signed (negative: stopped
    /// short of the plan) `[deg]`; 0 for a hand without fingers.
    pub worst_joint_error_deg: f64,
    /// Deepest penetration of a hand collider into the object at the end of the closing `[mm]`.
    pub penetration_mm: f64,
    /// Why not as planned, in the order pushed, off plan, penetrated (empty when as planned).
    pub reasons: Vec<FidelityReason>,
}

impl Fidelity {
    /// The fidelity of `closing`, which left a hand collider `penetration_mm` deep, judged by
    /// `max_penetration_mm` and the closing's own bounds (`pushed`, `off_plan`).
    pub fn of(closing: &ClosingOutcome, penetration_mm: f64, max_penetration_mm: f64) -> Fidelity {
        let mut reasons = Vec::new();
        if closing.pushed {
            reasons.push(FidelityReason::Pushed);
        }
        if closing.off_plan {
            reasons.push(FidelityReason::OffPlan);
        }
        if penetration_mm.is_nan() || penetration_mm > max_penetration_mm {
            reasons.push(FidelityReason::Penetrated);
        }
        Fidelity {
            as_planned: reasons.is_empty(),
            shift_mm: closing.shift_mm,
            turn_deg: closing.turn_deg,
            phalanges_on_plan: closing.phalanges_on_plan,
            phalanges: 2 * closing.fingers.len(),
            worst_joint_error_deg: closing.worst_joint().map_or(0.0, |w| w.2),
            penetration_mm,
            reasons,
        }
    }

    /// Adds what another closing of the same check (another direction under the `full`
    /// protocol) did: not as planned if either was not, every reason of either.
    pub fn merge(&mut self, other: &Fidelity) {
        for r in &other.reasons {
            if !self.reasons.contains(r) {
                self.reasons.push(*r);
            }
        }
        self.reasons.sort();
        self.as_planned = self.reasons.is_empty();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_verdict_is_named_by_its_own_name_only() {
        for v in [Verdict::Hold, Verdict::Slip, Verdict::Drop] {
            assert_eq!(Verdict::named(v.as_str()), Some(v));
        }
        for other in ["", "Hold", "HOLD", " hold", "hold ", "held", "error"] {
            assert_eq!(Verdict::named(other), None, "{other:?}");
        }
    }

    #[test]
    fn decided_by_is_named_and_tells_a_drop() {
        assert_eq!(DecidedBy::OutOfReach.as_str(), "out_of_reach");
        assert_eq!(DecidedBy::ClearOfHand.to_string(), "clear_of_hand");
        assert!(DecidedBy::OutOfReach.is_drop() && DecidedBy::ClearOfHand.is_drop());
        assert!(!DecidedBy::Rest.is_drop() && !DecidedBy::End.is_drop());
    }

    #[test]
    fn the_worst_joint_is_the_largest_error_either_way() {
        let finger = |name: &str, error_deg| FingerClosing {
            name: name.to_string(),
            planned_deg: [90.0, 90.0],
            als_deg: [90.0, 90.0],
            final_deg: [90.0, 90.0],
            error_deg,
            touching: [true, true],
            gap_mm: [0.0, 0.0],
            first_contact_s: [None, None],
        };
        let c = ClosingOutcome {
            shift_mm: 0.0,
            turn_deg: 0.0,
            duration_s: 0.1,
            max_shift_mm: 5.0,
            pushed: false,
            first_touch: None,
            palm_touching: false,
            fingers: vec![finger("finger_1", [1.0, -3.5]), finger("thumb", [3.0, 2.0])],
            phalanges_on_plan: 4,
            min_on_plan: 2,
            off_plan: false,
        };
        assert_eq!(c.worst_joint(), Some(("finger_1", 2, -3.5)));
        assert_eq!(
            ClosingOutcome {
                fingers: vec![],
                ..c
            }
            .worst_joint(),
            None
        );
    }
}
