//! The physics check's part of the report, owned here: what `sim.start`, `sim.collider`,
//! `sim.closing`, `sim.fidelity`, `sim.directions`, `sim.robust` and `sim.replay` (and a
//! candidate's `fidelity`) write, with the conversions from the check's own types.
//!
//! Each conversion names every field of the type it reads, so a field renamed, added or removed
//! in `sim` fails to compile here instead of changing the JSON.

use crate::sim;
use serde::Serialize;

/// What gravity did: `hold`, `slip` or `drop`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// The object stayed within the hold limits relative to the palm.
    Hold,
    /// It moved beyond them but still touches the hand.
    Slip,
    /// It left the hand.
    Drop,
}

impl Verdict {
    /// The name used in JSON.
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

impl From<sim::Verdict> for Verdict {
    fn from(v: sim::Verdict) -> Verdict {
        match v {
            sim::Verdict::Hold => Verdict::Hold,
            sim::Verdict::Slip => Verdict::Slip,
            sim::Verdict::Drop => Verdict::Drop,
        }
    }
}

/// Where the check started (`sim.start`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Start {
    /// How far the palm was backed off the collider `[mm]`.
    pub palm_backoff_mm: f64,
    /// Per finger, the margin it started open by `[deg]`.
    pub open_margin_deg: Vec<f64>,
    /// The deepest penetration of a hand collider into the object left at the start `[mm]`.
    pub penetration_mm: f64,
    /// Per finger, what the refinement by the contact did; empty when it did not run.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub refinement: Vec<FingerRefinement>,
}

impl From<&sim::scene::Start> for Start {
    fn from(s: &sim::scene::Start) -> Start {
        let sim::scene::Start {
            origin_mm: _,
            palm_backoff_mm,
            open_bend_rad: _,
            open_margin_deg,
            penetration_mm,
            theta_deg: _,
            refinement,
        } = s;
        Start {
            palm_backoff_mm: *palm_backoff_mm,
            open_margin_deg: open_margin_deg.clone(),
            penetration_mm: *penetration_mm,
            refinement: refinement.iter().map(FingerRefinement::from).collect(),
        }
    }
}

/// What the refinement by the contact did to one finger.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FingerRefinement {
    /// The planned `[θ1, θ2]` it started from `[deg]`.
    pub als_deg: [f64; 2],
    /// The refined `[θ1, θ2]` `[deg]`.
    pub refined_deg: [f64; 2],
    /// Whether phalanx 1, phalanx 2 touches the object at the refined bends.
    pub touches: [bool; 2],
}

impl From<&crate::plan::refine::FingerRefinement> for FingerRefinement {
    fn from(r: &crate::plan::refine::FingerRefinement) -> FingerRefinement {
        let crate::plan::refine::FingerRefinement {
            als_deg,
            refined_deg,
            touches,
        } = *r;
        FingerRefinement {
            als_deg,
            refined_deg,
            touches,
        }
    }
}

/// How the object's collider was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColliderKind {
    /// The convex hull of the mesh.
    ConvexHull,
    /// A convex decomposition of the mesh.
    ConvexDecomposition,
}

impl ColliderKind {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            ColliderKind::ConvexHull => "convex_hull",
            ColliderKind::ConvexDecomposition => "convex_decomposition",
        }
    }
}

impl std::fmt::Display for ColliderKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// The object's collider (`sim.collider`), written as one string: its kind and part count,
/// and why it is not the plain hull or decomposition when it is not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColliderReport {
    /// How it was made.
    pub kind: ColliderKind,
    /// Number of convex parts.
    pub parts: usize,
    /// For a hull rebuilt from its face planes: the full hull's and the rebuilt hull's vertex
    /// counts.
    pub rebuilt: Option<[usize; 2]>,
    /// For a decomposition taken because the hull lies off a planned contact: how far `[mm]`.
    pub hull_off_mm: Option<f64>,
}

impl From<&sim::ColliderReport> for ColliderReport {
    fn from(c: &sim::ColliderReport) -> ColliderReport {
        let sim::ColliderReport {
            kind,
            parts,
            rebuilt,
            hull_off_mm,
        } = *c;
        ColliderReport {
            kind: match kind {
                sim::ColliderKind::ConvexHull => ColliderKind::ConvexHull,
                sim::ColliderKind::ConvexDecomposition => ColliderKind::ConvexDecomposition,
            },
            parts,
            rebuilt: rebuilt.map(
                |sim::collider::RebuiltHull {
                     from_vertices,
                     to_vertices,
                 }| [from_vertices, to_vertices],
            ),
            hull_off_mm,
        }
    }
}

impl std::fmt::Display for ColliderReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(off) = self.hull_off_mm {
            return write!(
                f,
                "{} ({} parts, for a convex mesh whose hull lies {off:.1} mm outside a planned contact)",
                self.kind, self.parts
            );
        }
        match self.rebuilt {
            Some([from, to]) => write!(
                f,
                "{} ({} parts, rebuilt from its face planes where parry would merge bent faces: {from} vertices to {to})",
                self.kind, self.parts
            ),
            None => write!(f, "{} ({} parts)", self.kind, self.parts),
        }
    }
}

/// As its words.
impl Serialize for ColliderReport {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// What the closing did to the planned grasp (`sim.closing`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClosingOutcome {
    /// Object translation relative to the palm over the closing `[mm]`.
    pub shift_mm: f64,
    /// Object rotation relative to the palm over the closing `[deg]`.
    pub turn_deg: f64,
    /// How long the closing took `[s]`.
    pub duration_s: f64,
    /// The bound on `shift_mm` `[mm]`.
    pub max_shift_mm: f64,
    /// Whether `shift_mm` exceeds `max_shift_mm`.
    pub pushed: bool,
    /// The first hand body to touch the object, and when.
    pub first_touch: Option<FirstTouch>,
    /// Whether the palm touches the object at the end of the closing.
    pub palm_touching: bool,
    /// Per finger, in the hand's order.
    pub fingers: Vec<FingerClosing>,
    /// Phalanges that end the closing on their plan.
    pub phalanges_on_plan: usize,
    /// The least `phalanges_on_plan` for a hold of the planned grasp.
    pub min_on_plan: usize,
    /// Whether `phalanges_on_plan` is below `min_on_plan`.
    pub off_plan: bool,
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

impl From<&sim::ClosingOutcome> for ClosingOutcome {
    fn from(c: &sim::ClosingOutcome) -> ClosingOutcome {
        let sim::ClosingOutcome {
            shift_mm,
            turn_deg,
            duration_s,
            max_shift_mm,
            pushed,
            first_touch,
            palm_touching,
            fingers,
            phalanges_on_plan,
            min_on_plan,
            off_plan,
        } = c;
        ClosingOutcome {
            shift_mm: *shift_mm,
            turn_deg: *turn_deg,
            duration_s: *duration_s,
            max_shift_mm: *max_shift_mm,
            pushed: *pushed,
            first_touch: first_touch.as_ref().map(FirstTouch::from),
            palm_touching: *palm_touching,
            fingers: fingers.iter().map(FingerClosing::from).collect(),
            phalanges_on_plan: *phalanges_on_plan,
            min_on_plan: *min_on_plan,
            off_plan: *off_plan,
        }
    }
}

/// The first touch of the closing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FirstTouch {
    /// `palm`, or the finger's name.
    pub body: String,
    /// 1 or 2 for a finger's phalanx, 0 for the palm.
    pub phalanx: usize,
    /// Time into the closing `[s]`.
    pub at_s: f64,
}

impl From<&sim::FirstTouch> for FirstTouch {
    fn from(t: &sim::FirstTouch) -> FirstTouch {
        let sim::FirstTouch {
            body,
            phalanx,
            at_s,
        } = t;
        FirstTouch {
            body: body.clone(),
            phalanx: *phalanx,
            at_s: *at_s,
        }
    }
}

/// One finger's closing: planned and final joint angles.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FingerClosing {
    /// The finger's name.
    pub name: String,
    /// The `[θ1, θ2]` the check commanded `[deg]`.
    pub planned_deg: [f64; 2],
    /// The planner's `[θ1, θ2]` `[deg]`.
    pub als_deg: [f64; 2],
    /// `[θ1, θ2]` where the closing left the joints `[deg]`.
    pub final_deg: [f64; 2],
    /// Bend after closing minus the planned bend `[deg]`.
    pub error_deg: [f64; 2],
    /// Whether phalanx 1, phalanx 2 touches the object at the end of the closing.
    pub touching: [bool; 2],
    /// The gap between phalanx 1, phalanx 2 and the object's collider at the end `[mm]`.
    pub gap_mm: [f64; 2],
    /// When phalanx 1, phalanx 2 first touched the object `[s]`.
    pub first_contact_s: [Option<f64>; 2],
}

impl From<&sim::FingerClosing> for FingerClosing {
    fn from(f: &sim::FingerClosing) -> FingerClosing {
        let sim::FingerClosing {
            name,
            planned_deg,
            als_deg,
            final_deg,
            error_deg,
            touching,
            gap_mm,
            first_contact_s,
        } = f;
        FingerClosing {
            name: name.clone(),
            planned_deg: *planned_deg,
            als_deg: *als_deg,
            final_deg: *final_deg,
            error_deg: *error_deg,
            touching: *touching,
            gap_mm: *gap_mm,
            first_contact_s: *first_contact_s,
        }
    }
}

/// Why a closing did not keep the planned grasp.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FidelityReason {
    /// The closing pushed the object farther than `max_closing_shift_mm`.
    Pushed,
    /// Fewer phalanges ended on their plan than `min_on_plan_fraction` asks.
    OffPlan,
    /// A hand collider ended deeper inside the object than `max_penetration_mm`.
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

impl From<sim::FidelityReason> for FidelityReason {
    fn from(r: sim::FidelityReason) -> FidelityReason {
        match r {
            sim::FidelityReason::Pushed => FidelityReason::Pushed,
            sim::FidelityReason::OffPlan => FidelityReason::OffPlan,
            sim::FidelityReason::Penetrated => FidelityReason::Penetrated,
        }
    }
}

/// Whether the grasp the closing made is the one planned (`sim.fidelity`, a candidate's
/// `fidelity`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fidelity {
    /// Whether `reasons` is empty.
    pub as_planned: bool,
    /// Object translation relative to the palm over the closing `[mm]`.
    pub shift_mm: f64,
    /// Object rotation relative to the palm over the closing `[deg]`.
    pub turn_deg: f64,
    /// Phalanges that end the closing on their plan.
    pub phalanges_on_plan: usize,
    /// The hand's phalanges.
    pub phalanges: usize,
    /// The largest joint error against the plan, signed `[deg]`.
    pub worst_joint_error_deg: f64,
    /// Deepest penetration of a hand collider into the object at the end of the closing `[mm]`.
    pub penetration_mm: f64,
    /// Why not as planned (empty when as planned).
    pub reasons: Vec<FidelityReason>,
}

impl From<&sim::Fidelity> for Fidelity {
    fn from(f: &sim::Fidelity) -> Fidelity {
        let sim::Fidelity {
            as_planned,
            shift_mm,
            turn_deg,
            phalanges_on_plan,
            phalanges,
            worst_joint_error_deg,
            penetration_mm,
            reasons,
        } = f;
        Fidelity {
            as_planned: *as_planned,
            shift_mm: *shift_mm,
            turn_deg: *turn_deg,
            phalanges_on_plan: *phalanges_on_plan,
            phalanges: *phalanges,
            worst_joint_error_deg: *worst_joint_error_deg,
            penetration_mm: *penetration_mm,
            reasons: reasons.iter().map(|&r| r.into()).collect(),
        }
    }
}

/// What decided a direction's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DecidedBy {
    /// The direction ran the whole hold.
    End,
    /// At rest relative to the palm.
    Rest,
    /// The object left the hand's reach for good.
    OutOfReach,
    /// The object flies clear of the resting hand for good.
    ClearOfHand,
    /// The closing did not keep the planned grasp under `[sim] closing_decides`.
    Closing,
}

impl From<sim::DecidedBy> for DecidedBy {
    fn from(d: sim::DecidedBy) -> DecidedBy {
        match d {
            sim::DecidedBy::End => DecidedBy::End,
            sim::DecidedBy::Rest => DecidedBy::Rest,
            sim::DecidedBy::OutOfReach => DecidedBy::OutOfReach,
            sim::DecidedBy::ClearOfHand => DecidedBy::ClearOfHand,
            sim::DecidedBy::Closing => DecidedBy::Closing,
        }
    }
}

/// The result for one gravity direction (an entry of `sim.directions`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DirectionOutcome {
    /// Gravity direction (unit, aligned frame).
    pub gravity: [f64; 3],
    /// The verdict.
    pub verdict: Verdict,
    /// Object translation relative to the palm during the hold `[mm]`.
    pub translation_mm: f64,
    /// Object rotation relative to the palm during the hold, as judged `[deg]`.
    pub rotation_deg: f64,
    /// The full rotation relative to the palm `[deg]`.
    pub full_rotation_deg: f64,
    /// The tilt of the object's principal axis relative to the palm `[deg]`.
    pub tilt_deg: f64,
    /// Object translation relative to the palm while the fingers closed `[mm]`.
    pub closing_translation_mm: f64,
    /// Object rotation relative to the palm while the fingers closed `[deg]`.
    pub closing_rotation_deg: f64,
    /// Whether the closing pushed the object farther than `max_closing_shift_mm`.
    pub closing_pushed: bool,
    /// Whether fewer phalanges ended on their plan than `min_on_plan_fraction` asks.
    pub closing_off_plan: bool,
    /// Whether the closing this direction continued from kept the planned grasp.
    pub as_planned: bool,
    /// Deepest penetration of a finger or the palm into the object after closing `[mm]`.
    pub closing_penetration_mm: f64,
    /// How long the fingers closed before gravity came on `[s]`.
    pub closed_at_s: f64,
    /// Largest difference between a joint's bend after closing and its plan `[deg]`.
    pub joint_error_deg: f64,
    /// Per finger, the two joints' bend after closing minus the planned bend `[deg]`.
    pub joint_errors_deg: Vec<[f64; 2]>,
    /// Whether the object touches the hand at the end (at the decision).
    pub in_contact: bool,
    /// Time into the hold at which the verdict was decided `[s]`.
    pub decided_at_s: f64,
    /// What decided it.
    pub decided_by: DecidedBy,
    /// Object translation relative to the palm at the decision `[mm]`.
    pub translation_at_decision_mm: f64,
}

impl From<&sim::DirectionOutcome> for DirectionOutcome {
    fn from(d: &sim::DirectionOutcome) -> DirectionOutcome {
        let sim::DirectionOutcome {
            gravity,
            verdict,
            translation_mm,
            rotation_deg,
            full_rotation_deg,
            tilt_deg,
            closing_translation_mm,
            closing_rotation_deg,
            closing_pushed,
            closing_off_plan,
            as_planned,
            closing_penetration_mm,
            closed_at_s,
            joint_error_deg,
            joint_errors_deg,
            in_contact,
            decided_at_s,
            decided_by,
            translation_at_decision_mm,
        } = d;
        DirectionOutcome {
            gravity: *gravity,
            verdict: (*verdict).into(),
            translation_mm: *translation_mm,
            rotation_deg: *rotation_deg,
            full_rotation_deg: *full_rotation_deg,
            tilt_deg: *tilt_deg,
            closing_translation_mm: *closing_translation_mm,
            closing_rotation_deg: *closing_rotation_deg,
            closing_pushed: *closing_pushed,
            closing_off_plan: *closing_off_plan,
            as_planned: *as_planned,
            closing_penetration_mm: *closing_penetration_mm,
            closed_at_s: *closed_at_s,
            joint_error_deg: *joint_error_deg,
            joint_errors_deg: joint_errors_deg.clone(),
            in_contact: *in_contact,
            decided_at_s: *decided_at_s,
            decided_by: (*decided_by).into(),
            translation_at_decision_mm: *translation_at_decision_mm,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_collider_report_is_the_sentence_it_was() {
        let plain = ColliderReport::from(&sim::ColliderReport {
            kind: sim::ColliderKind::ConvexDecomposition,
            parts: 12,
            rebuilt: None,
            hull_off_mm: None,
        });
        assert_eq!(
            serde_json::to_string(&plain).unwrap(),
            "\"convex_decomposition (12 parts)\""
        );
        let rebuilt = ColliderReport::from(&sim::ColliderReport {
            kind: sim::ColliderKind::ConvexHull,
            parts: 1,
            rebuilt: Some(sim::collider::RebuiltHull {
                from_vertices: 1024,
                to_vertices: 296,
            }),
            hull_off_mm: None,
        });
        assert_eq!(
            rebuilt.to_string(),
            "convex_hull (1 parts, rebuilt from its face planes where parry would merge bent \
             faces: 1024 vertices to 296)"
        );
        let taken = ColliderReport::from(&sim::ColliderReport {
            kind: sim::ColliderKind::ConvexDecomposition,
            parts: 9,
            rebuilt: None,
            hull_off_mm: Some(3.605),
        });
        assert_eq!(
            taken.to_string(),
            "convex_decomposition (9 parts, for a convex mesh whose hull lies 3.6 mm outside a \
             planned contact)"
        );
        // From a shape: the prism's plain hull.
        let prism = crate::objects::prism(40.0, 100.0, 80.0);
        let v = crate::mesh::mass_properties(&prism).volume_mm3;
        let shape = sim::ObjectShape::from_mesh(&prism, v);
        let r = ColliderReport::from(&sim::ColliderReport::of(&shape));
        assert_eq!(r.to_string(), "convex_hull (1 parts)");
    }

    #[test]
    fn names_are_the_check_s_names() {
        for (d, name) in [
            (sim::DecidedBy::End, "end"),
            (sim::DecidedBy::Rest, "rest"),
            (sim::DecidedBy::OutOfReach, "out_of_reach"),
            (sim::DecidedBy::ClearOfHand, "clear_of_hand"),
            (sim::DecidedBy::Closing, "closing"),
        ] {
            assert_eq!(d.as_str(), name);
            let json = serde_json::to_string(&DecidedBy::from(d)).unwrap();
            assert_eq!(json, format!("\"{name}\""));
        }
        for v in [sim::Verdict::Hold, sim::Verdict::Slip, sim::Verdict::Drop] {
            let json = serde_json::to_string(&Verdict::from(v)).unwrap();
            assert_eq!(json, format!("\"{}\"", v.as_str()));
            assert_eq!(Verdict::named(v.as_str()), Some(v.into()));
        }
        for r in [
            sim::FidelityReason::Pushed,
            sim::FidelityReason::OffPlan,
            sim::FidelityReason::Penetrated,
        ] {
            let json = serde_json::to_string(&FidelityReason::from(r)).unwrap();
            assert_eq!(json, format!("\"{}\"", r.as_str()));
        }
    }
}
