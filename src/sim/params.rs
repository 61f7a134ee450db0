//! The physics check's parameters (DESIGN.md section 5), as a scenario's `[sim]` table gives
//! them, and their validation. Units in the names: seconds, newton-metres, millimetres, degrees.
//!
//! [`SimParams`] groups them by concern (solver, fingers, closing, hold, early decision,
//! selection, input); the `[sim]` table stays flat, its keys the fields' names: it is read into
//! a flat view (the private `flat::SimParams`, the same name so that serde's messages and the
//! `Debug` text are the flat table's) and converted. serde's `flatten` cannot be used here: it
//! does not work with `deny_unknown_fields`, which names a mistyped key.
//!
//! The table is declared once, in the `sim_table!` invocation: each key with its type and group,
//! from which the flat struct and both conversions are made. A new key is a field of its group
//! (its doc comment and default there), a row at the end of the table, and its validation.

use crate::messages::keyed;
use serde::Deserialize;

/// Gravity directions for the hold test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GravityMode {
    /// −Z of the aligned object frame (the thesis's weight direction).
    Down,
    /// ±X, ±Y, ±Z in turn (as DexGraspNet and BODex test).
    Six,
}

impl GravityMode {
    /// The name used in TOML and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            GravityMode::Down => "down",
            GravityMode::Six => "six",
        }
    }
}

/// How the physics check runs the hold test (docs/SIM.md, "Protocols").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Protocol {
    /// Close the hand once, branch a copy of the closed scene per gravity direction and payload
    /// multiplier, end each direction as soon as its verdict can no longer change, and run the
    /// directions in parallel.
    Fast,
    /// The reference: a fresh scene closed again for every direction and payload multiplier,
    /// each direction held for the whole `duration_s`, one after another.
    Full,
}

/// How the hand's phalanges are joined in rapier (docs/SIM.md, "The impulse-joint hand").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum HandJoints {
    /// A multibody (reduced-coordinate articulation) per finger, the first rooted at the fixed
    /// palm and the others at fixed bases at its pose (the default).
    Multibody,
    /// Free rigid bodies held by revolute impulse joints, solved with the contacts.
    Impulse,
}

impl HandJoints {
    /// True for the default, the multibody hand.
    pub fn is_multibody(&self) -> bool {
        *self == HandJoints::Multibody
    }
}

/// The default of `[sim] max_closing_shift_mm` `[mm]` (docs/SIM.md, "What the closing does").
pub const DEFAULT_MAX_CLOSING_SHIFT_MM: f64 = 5.0;

/// The default of `[sim] min_on_plan_fraction`: half the hand's phalanges (docs/SIM.md, "A
/// closing that leaves most phalanges off their plan").
pub const DEFAULT_MIN_ON_PLAN_FRACTION: f64 = 0.5;

/// Physics check parameters (DESIGN.md section 5); used by the physics check. Each field of a
/// group is the `[sim]` key of the same name.
#[derive(Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(from = "flat::SimParams")]
pub struct SimParams {
    /// Gravity direction(s).
    pub gravity: GravityMode,
    /// `fast` (default) or `full`, the reference protocol the fast one is compared with.
    pub protocol: Protocol,
    /// The rapier solver: timestep, iterations and contact stiffness.
    pub solver: SolverParams,
    /// How the fingers are driven (motor torques, gains, squeeze) and how heavy they are.
    pub fingers: FingerParams,
    /// How the fingers close before gravity comes on (docs/SIM.md, "What the closing does").
    pub closing: ClosingParams,
    /// The hold: how long each gravity direction is held, and the thresholds of a `hold`.
    pub hold: HoldParams,
    /// The `fast` protocol's rest rule (docs/SIM.md, "Deciding early").
    pub early: EarlyParams,
    /// The candidate search's policy: how many planned grasps a run checks.
    pub selection: SelectionParams,
    /// Where the grasp comes from: the planner, or joint angles fixed by the scenario.
    pub input: InputParams,
    /// The hold probability under perturbation (issue 34, docs/SIM.md "Hold probability"):
    /// how many perturbed checks, drawn how. Left out of the serialised parameters when all at
    /// their defaults, so a scenario that does not use it keeps its batch input hash.
    #[serde(skip_serializing_if = "RobustParams::is_default")]
    pub robust: RobustParams,
}

/// How the candidate search picks among the candidates it checked (`[sim] choose`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Choose {
    /// The first candidate that holds in the main check (the check before issue 34).
    First,
    /// The first candidate whose hold probability's lower bound reaches
    /// `choose_min_lower_bound`; if none of the `max_checked` does, the one with the highest
    /// lower bound. Needs `samples` of at least 2.
    Robust,
}

/// The hold probability under perturbation (`[sim]` keys of the same names; docs/SIM.md,
/// "Hold probability").
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RobustParams {
    /// Perturbed checks of the chosen grasp (1: none, the main check only).
    pub samples: usize,
    /// The seed the perturbations are drawn from.
    pub seed: u64,
    /// Each coordinate of the object's offset relative to the hand before closing is uniform
    /// within ± this `[mm]`.
    pub pose_offset_mm: f64,
    /// The object's rotation relative to the hand before closing: about an axis uniform on the
    /// sphere, by an angle uniform up to this `[deg]`.
    pub pose_rotation_deg: f64,
    /// Friction is multiplied by a factor uniform within 1 ± this `[%]`.
    pub friction_range_pct: f64,
    /// The object's mass is multiplied by a factor uniform within 1 ± this `[%]`.
    pub mass_range_pct: f64,
    /// The finger motors' torque limit is multiplied by a factor uniform within 1 ± this `[%]`.
    pub torque_range_pct: f64,
    /// Run the main check under this sample's perturbation (to replay a failure reported in
    /// `sim.robust.first_failure`).
    pub replay_sample: Option<usize>,
    /// How the candidate search picks (`first` or `robust`).
    pub choose: Choose,
    /// `choose = "robust"`: the lower bound a candidate's hold probability must reach.
    pub choose_min_lower_bound: f64,
}

impl Default for RobustParams {
    fn default() -> Self {
        RobustParams {
            samples: 1,
            seed: 0,
            pose_offset_mm: 2.0,
            pose_rotation_deg: 3.0,
            friction_range_pct: 15.0,
            mass_range_pct: 15.0,
            torque_range_pct: 10.0,
            replay_sample: None,
            choose: Choose::First,
            choose_min_lower_bound: 0.8,
        }
    }
}

impl RobustParams {
    /// Returns true if and only if every value is its default.
    pub fn is_default(&self) -> bool {
        *self == RobustParams::default()
    }
}

/// The rapier solver: timestep, iterations and contact stiffness.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SolverParams {
    /// Physics timestep `[s]`.
    pub timestep_s: f64,
    /// Constraint solver iterations (substeps) per step.
    pub solver_iterations: usize,
    /// PGS sweeps per solver iteration.
    pub pgs_iterations: usize,
    /// Stabilisation (position correction) sweeps per solver iteration.
    pub stabilization_iterations: usize,
    /// Natural frequency of contacts `[Hz]`: their stiffness relative to the bodies' masses.
    pub contact_stiffness_hz: f64,
    /// The finger joints' kind: `multibody` (default) or `impulse`. Left out of the serialised
    /// parameters at its default, so a scenario that does not use it keeps its batch input hash.
    #[serde(skip_serializing_if = "HandJoints::is_multibody")]
    pub hand_joints: HandJoints,
    /// Constraint solver iterations (substeps) per step during the hold, once the fingers have
    /// closed (the closing has `solver_iterations`). 12 by default: at 8 a held object creeps
    /// under the solver, so the rest rule waits for it (a median of 0.5 s into a hold on the
    /// real-object set); at 12 the same holds rest at once, and a check takes 0.68 of the steps
    /// (docs/studies/2026-12-07-hold-substeps.md). Fewer than 8 let holds creep more.
    pub hold_solver_iterations: usize,
}

impl SolverParams {
    /// The substeps per step of the hold (`hold_solver_iterations`).
    pub fn hold_substeps(&self) -> usize {
        self.hold_solver_iterations
    }
}

impl Default for SolverParams {
    fn default() -> Self {
        SolverParams {
            timestep_s: 1.0 / 960.0,
            solver_iterations: 8,
            pgs_iterations: 8,
            stabilization_iterations: 2,
            contact_stiffness_hz: 10000.0,
            hand_joints: HandJoints::Multibody,
            hold_solver_iterations: 12,
        }
    }
}

/// How the fingers are driven (motor torques, gains, squeeze) and how heavy they are.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FingerParams {
    /// Joint 1's motor target closes this far past its planned angle `[deg]` (3°, 10° before
    /// 2026-12-03, ff19c34: docs/SIM.md "The closing, adopted").
    pub squeeze_deg: f64,
    /// Joint 2's motor target closes this far past its planned angle `[deg]`.
    pub squeeze2_deg: f64,
    /// Joint motor torque limit `[N·m]`.
    pub torque_limit_nm: f64,
    /// Torque a stalled joint 1 holds once joint 2 closes (a worm drive's lock) `[N·m]`.
    pub joint1_lock_torque_nm: f64,
    /// Joint motor stiffness `[N·m/rad]`: torque per radian short of the target, up to the limit.
    pub motor_stiffness_nm_per_rad: f64,
    /// Joint motor damping `[N·m·s/rad]`.
    pub motor_damping_nms_per_rad: f64,
    /// Density of the phalanges `[kg/m³]` (the hand file gives no masses).
    pub finger_density_kg_m3: f64,
    /// Each finger's motors are capped at `torque_limit_nm` times the number of fingers on the
    /// palm's less crowded side over the number on its own side, so that the two sides squeeze
    /// the object equally (issue 33: with equal torques the thesis hand's two fingers push the
    /// object across towards its one thumb until the contacts' angles balance them);
    /// `false`: every finger at `torque_limit_nm`.
    pub balanced_squeeze: bool,
}

impl Default for FingerParams {
    fn default() -> Self {
        FingerParams {
            squeeze_deg: 3.0,
            squeeze2_deg: 3.0,
            torque_limit_nm: 1.0,
            joint1_lock_torque_nm: 10.0,
            motor_stiffness_nm_per_rad: 20.0,
            motor_damping_nms_per_rad: 0.2,
            finger_density_kg_m3: 1000.0,
            balanced_squeeze: true,
        }
    }
}

/// How the fingers close before gravity comes on (docs/SIM.md, "What the closing does").
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClosingParams {
    /// Time the fingers get to close before gravity is turned on `[s]`: with
    /// `close_until_stalled`, the longest they get; `reseat` adds at most another half.
    pub close_duration_s: f64,
    /// Each closing phase (joint 1, then joint 2) ends as soon as the hand and the object have
    /// stopped (`sim::STALL`), at most at half `close_duration_s`, and the reseat once no
    /// joint 1 moves on and the object has stopped; `false`: each phase takes its half of
    /// `close_duration_s` (the check before issue 15).
    pub close_until_stalled: bool,
    /// The fingers start this much more open than planned at each joint `[deg]`.
    pub open_margin_deg: f64,
    /// How joint 1 closes: `squeeze` (each finger straight to its target, the default before
    /// ff19c34), `together` (the default: a finger that touches the object stops there until
    /// every finger has touched, or the others have stopped, then all squeeze at once) or `timed`
    /// (every finger's target ramps to its planned bend in the same time, then the squeeze).
    pub approach: Approach,
    /// Refine the planned joint angles by the real contact before closing (`sim::refine`,
    /// docs/SIM.md "Refining the plan by the contact"): each joint is commanded the bend at
    /// which its phalanx first touches the object's collider, plus the squeeze. Never applied
    /// to `override_angles`, which are commanded as given. Off by default: on the real-object
    /// set it moved the phalanges on their plan from 53 % to 56 % only, while MuJoCo's
    /// agreement fell (docs/SIM.md). Left out of the serialised parameters when off, so a
    /// scenario that does not use it keeps its batch input hash.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub refine_contacts: bool,
    /// After joint 2 has closed, each locked joint 1 whose phalanx 1 does not touch the object
    /// moves on under its lock until it touches or reaches its squeeze target (`sim::closing`,
    /// docs/SIM.md "Why the phalanges miss their plan"): phalanx 1 comes back onto an object
    /// that joint 2 seated away from it. On by default since ff19c34. Left out of the
    /// serialised parameters when off.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub reseat: bool,
    /// The reseat moves on only a joint 1 whose phalanx 1 touched the object earlier in the
    /// closing and is off it now (a phalanx lifted off by joint 2's squeeze), not one whose
    /// phalanx 1 never reached the object (its finger stopped on phalanx 2): driven on under
    /// its lock, such a joint crushes the object through phalanx 2 (docs/studies/
    /// 2026-12-05-three-disagreements.md). On by default since the five runs of
    /// docs/studies/2026-12-05-reseat-only-lifted.md. Left out of the serialised parameters
    /// when on.
    #[serde(skip_serializing_if = "is_true")]
    pub reseat_only_lifted: bool,
}

/// `serde`'s test for a field left out at its default of `true`.
fn is_true(b: &bool) -> bool {
    *b
}

impl Default for ClosingParams {
    fn default() -> Self {
        ClosingParams {
            close_duration_s: 0.5,
            close_until_stalled: true,
            open_margin_deg: 20.0,
            approach: Approach::Together,
            refine_contacts: false,
            reseat: true,
            reseat_only_lifted: true,
        }
    }
}

/// The hold: how long each gravity direction is held, and the thresholds of a `hold`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HoldParams {
    /// Hold time per gravity direction `[s]`.
    pub duration_s: f64,
    /// Largest translation relative to the palm that still counts as `hold` `[mm]`.
    pub hold_translation_mm: f64,
    /// Largest rotation relative to the palm that still counts as `hold` `[deg]`.
    pub hold_rotation_deg: f64,
    /// Deepest a finger or the palm may be inside the object at the end of closing for the
    /// grasp to count as a hold `[mm]`: a grasp that holds only because a finger passed into
    /// the object is not a hold (issue 14). Beyond it the verdict is `slip` (the object stays
    /// in the hand, but not by a grasp a real hand could make).
    pub max_penetration_mm: f64,
    /// Farthest the closing may push the object relative to the palm for the grasp to count
    /// as a hold of the planned grasp `[mm]` (issue 33): beyond it the object was pushed across
    /// until the other fingers caught it, a different grasp from the one planned, and the
    /// verdict is `slip` (`closing_pushed`), so the candidate search moves on as for a slip.
    pub max_closing_shift_mm: f64,
    /// Least share of the hand's phalanges that must end the closing on the object within
    /// 5° of their planned bend (`phalanges_on_plan`) for the grasp to count as a hold of the
    /// planned grasp (issue 33): with fewer, the object was caught by a different grasp from
    /// the one planned, and the verdict is `slip` (`closing_off_plan`), so the candidate search
    /// moves on as for a slip. 0 turns the rule off; 1 asks for every phalanx.
    pub min_on_plan_fraction: f64,
    /// Under the `fast` protocol, a closing that pushed the object beyond
    /// `max_closing_shift_mm` or left a finger deeper than `max_penetration_mm` decides the
    /// check at once (`[sim] closing_decides`, issue 35; off by default): no direction is
    /// held, each is `slip` if the object touches the hand after the closing, else `drop`,
    /// `decided_by = "closing"`. Neither can be a `hold`; the holds would only tell `slip` from
    /// `drop`, which is most of a dataset's time (docs/SIM.md, "Failed closings decided at
    /// once"). The pipeline uses it for the candidate search's checks only; the check it
    /// reports, the samples and `tune` run in full.
    pub closing_decides: bool,
}

impl Default for HoldParams {
    fn default() -> Self {
        HoldParams {
            duration_s: 2.0,
            hold_translation_mm: 5.0,
            hold_rotation_deg: 5.0,
            max_penetration_mm: 2.0,
            max_closing_shift_mm: DEFAULT_MAX_CLOSING_SHIFT_MM,
            min_on_plan_fraction: DEFAULT_MIN_ON_PLAN_FRACTION,
            closing_decides: false,
        }
    }
}

/// The `fast` protocol's rest rule (docs/SIM.md, "Deciding early").
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EarlyParams {
    /// `fast` protocol: the window over which the object's motion relative to the palm is
    /// measured before a direction can be decided `hold` or `slip` at rest, and the least hold
    /// time `[s]`.
    pub rest_window_s: f64,
    /// `fast` protocol: the fastest motion of that window is projected to the end of the hold
    /// at this many times its speed.
    pub rest_safety: f64,
    /// `fast` protocol: a `hold` is decided early only if the object stays within this
    /// fraction of `hold_translation_mm` and `hold_rotation_deg`, the projected motion included;
    /// a `slip` only if it stays beyond one of them divided by this.
    pub rest_margin: f64,
    /// `fast` protocol: a direction is decided at rest only when every finger joint has
    /// settled too: its drift over the window continued to the end of the hold plus its
    /// spread, at `rest_safety` times their size, within this `[deg]`. A finger whose motor
    /// gives way creeps while the object it presses still looks at rest, before a slip.
    pub rest_joint_deg: f64,
}

impl Default for EarlyParams {
    fn default() -> Self {
        EarlyParams {
            rest_window_s: 0.05,
            rest_safety: 2.0,
            rest_margin: 0.8,
            rest_joint_deg: 1.0,
        }
    }
}

/// The candidate search's policy: how many planned grasps a run checks.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SelectionParams {
    /// A run checks the planner's candidates in search order until one holds or this many have
    /// been checked (1: only the first grasp, as the thesis would give it).
    pub max_checked: usize,
    /// Before the candidate search, up to this many candidates, picked for diversity as `label`
    /// picks them (the first always among them), and as many of the later rule sets' when the
    /// first rule set gave fewer than `max_checked` (what the search would go on to), are
    /// closed with gravity off, and the search checks them first, in the order their closings give: as planned, then the closing
    /// shift in whole millimetres, then the search order (issue 58: the closing predicts the
    /// hold where the plan's geometry does not); only when the first candidate's own closing
    /// leaves its plan. 0: the search order alone.
    #[serde(skip_serializing_if = "is_default_order_by_closing")]
    pub order_by_closing: usize,
    /// Under `order_by_closing`, each candidate it closes is also closed this many times more,
    /// perturbed as the hold probability's samples are but drawn apart from them, and the
    /// closings that kept the plan are counted: one nominal closing says little of how a grasp
    /// fares off its nominal pose, which is what its hold probability measures. The first
    /// candidate is then checked first only if every one of its closings kept the plan. 0: the
    /// nominal closing alone. 4 by default: the first candidate holds more often with one
    /// check on five of six object sets and as often on the sixth (docs/studies/2026-12-07-order-samples.md).
    #[serde(skip_serializing_if = "is_default_order_samples")]
    pub order_samples: usize,
    /// Under `order_by_closing`, while none of the candidates it closed keeps its plan, it
    /// picks on among the first rule set's candidates, as many again and then twice as many,
    /// until this many have been picked, and a further pick joins the order only if most of its
    /// closings (the nominal one and the `order_samples` perturbed) keep the plan: on an object
    /// whose first picks all leave their plan, a grasp that keeps it is what holds (the closing
    /// study, docs/studies/2026-12-06-order-ceiling.md). At most `order_by_closing`: no further
    /// picks.
    #[serde(skip_serializing_if = "is_default_order_reach")]
    pub order_reach: usize,
}

/// True at the default (a field serialised only when set otherwise).
fn is_default_order_reach(n: &usize) -> bool {
    *n == DEFAULT_ORDER_REACH
}

/// `order_reach`'s default: four times `order_by_closing`'s. 128 holds the first candidate a
/// little more often on three of eight object sets and a little less on one, and costs a
/// random-shape set's default batch 27 % more CPU (docs/studies/2026-12-07-order-reach.md).
pub const DEFAULT_ORDER_REACH: usize = 64;

/// The most candidates `order_reach` may pick.
pub const MAX_ORDER_REACH: usize = 1024;

/// True at the default (a field serialised only when set otherwise).
fn is_default_order_samples(n: &usize) -> bool {
    *n == DEFAULT_ORDER_SAMPLES
}

/// `order_samples`'s default.
pub const DEFAULT_ORDER_SAMPLES: usize = 4;

/// The most perturbed closings `order_samples` may add per candidate.
pub const MAX_ORDER_SAMPLES: usize = 64;

/// True at the default (a field serialised only when set otherwise).
fn is_default_order_by_closing(n: &usize) -> bool {
    *n == DEFAULT_ORDER_BY_CLOSING
}

/// `order_by_closing`'s default: the 16 diverse candidates `label` labels by default.
pub const DEFAULT_ORDER_BY_CLOSING: usize = 16;

/// The most candidates `order_by_closing` may close.
pub const MAX_ORDER_BY_CLOSING: usize = 256;

impl Default for SelectionParams {
    fn default() -> Self {
        SelectionParams {
            max_checked: crate::DEFAULT_MAX_CHECKED,
            order_by_closing: DEFAULT_ORDER_BY_CLOSING,
            order_samples: DEFAULT_ORDER_SAMPLES,
            order_reach: DEFAULT_ORDER_REACH,
        }
    }
}

/// Where the grasp comes from: the planner, or joint angles fixed by the scenario.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct InputParams {
    /// Skip the planner and close the fingers to these `[θ1, θ2]` per finger `[deg]`, with the
    /// palm upright at Finger_1's `override_index` (a sim-only scenario).
    pub override_angles: Option<Vec<[f64; 2]>>,
    /// Finger_1's elevation index for `override_angles` (default: the middle of the domain).
    pub override_index: Option<usize>,
}

/// How the fingers' joint 1 close (`[sim] approach`, docs/SIM.md "What the closing does").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Approach {
    /// Every finger closes straight to its squeeze target (the default before ff19c34).
    Squeeze,
    /// A finger stops where it touches until every finger has touched (or the hand has
    /// stopped), then all squeeze together (the default).
    Together,
    /// Every finger's joint 1 target moves from its open bend to its planned bend in the same
    /// time (`sim::closing::RAMP_S`), so the fingers arrive together, each at a speed set by
    /// its distance to its planned contact; then the squeeze.
    Timed,
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            gravity: GravityMode::Down,
            protocol: Protocol::Fast,
            solver: SolverParams::default(),
            fingers: FingerParams::default(),
            closing: ClosingParams::default(),
            hold: HoldParams::default(),
            early: EarlyParams::default(),
            selection: SelectionParams::default(),
            input: InputParams::default(),
            robust: RobustParams::default(),
        }
    }
}

/// The `Debug` text is the flat `[sim]` table's, as before the fields were grouped (the batch
/// input hash reads it).
impl std::fmt::Debug for SimParams {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        flat::SimParams::from(self.clone()).fmt(f)
    }
}

/// Declares the `[sim]` table once, as rows `key: Type => group` (`=> group` left out for a
/// key of [`SimParams`] itself), and makes of it the private `flat` module: the flat struct
/// `flat::SimParams`, one field per key in the rows' order, which serde reads the table into,
/// and the conversions both ways, each key moved to or from the field of the same name in its
/// group. The key's doc comment is on that field; the row's type must be the field's (the
/// compiler checks it), and a group field with no row fails the test `every_group_field_is_a_key`.
macro_rules! sim_table {
    ($($key:ident : $ty:ty $(=> $group:ident)?),+ $(,)?) => {
        /// The `[sim]` table as written: one field per key, in the rows' order.
        mod flat {
            use super::*;

            /// The flat `[sim]` table (see the module docs of [`super`]).
            #[derive(Debug, Clone, PartialEq, Deserialize)]
            #[serde(deny_unknown_fields, default)]
            pub(super) struct SimParams {
                $(pub(super) $key: $ty,)+
            }

            /// Every key, in the rows' order.
            #[cfg(test)]
            pub(super) const KEYS: &[&str] = &[$(stringify!($key)),+];

            impl Default for SimParams {
                fn default() -> Self {
                    super::SimParams::default().into()
                }
            }

            impl From<SimParams> for super::SimParams {
                fn from(s: SimParams) -> Self {
                    let mut p = super::SimParams::default();
                    $(p.$($group.)?$key = s.$key;)+
                    p
                }
            }

            impl From<super::SimParams> for SimParams {
                fn from(s: super::SimParams) -> Self {
                    SimParams {
                        $($key: s.$($group.)?$key,)+
                    }
                }
            }
        }
    };
}

// The `[sim]` keys in the order serde's messages list them and the `Debug` text prints them
// (the batch input hash reads it: a new key goes at the end). Each key's doc comment is on its
// group's field of the same name. The groups stay declared apart from the table: their fields'
// order is that of the serialised parameters, which the batch input hash reads too, and is not
// the table's (`approach` comes before `refine_contacts` in `closing`, after it here).
sim_table! {
    gravity: GravityMode,
    protocol: Protocol,
    rest_window_s: f64 => early,
    rest_safety: f64 => early,
    rest_margin: f64 => early,
    duration_s: f64 => hold,
    timestep_s: f64 => solver,
    squeeze_deg: f64 => fingers,
    squeeze2_deg: f64 => fingers,
    torque_limit_nm: f64 => fingers,
    joint1_lock_torque_nm: f64 => fingers,
    hold_translation_mm: f64 => hold,
    hold_rotation_deg: f64 => hold,
    close_duration_s: f64 => closing,
    close_until_stalled: bool => closing,
    solver_iterations: usize => solver,
    pgs_iterations: usize => solver,
    stabilization_iterations: usize => solver,
    motor_stiffness_nm_per_rad: f64 => fingers,
    motor_damping_nms_per_rad: f64 => fingers,
    finger_density_kg_m3: f64 => fingers,
    contact_stiffness_hz: f64 => solver,
    hand_joints: HandJoints => solver,
    hold_solver_iterations: usize => solver,
    open_margin_deg: f64 => closing,
    refine_contacts: bool => closing,
    reseat: bool => closing,
    reseat_only_lifted: bool => closing,
    override_angles: Option<Vec<[f64; 2]>> => input,
    override_index: Option<usize> => input,
    max_checked: usize => selection,
    max_penetration_mm: f64 => hold,
    max_closing_shift_mm: f64 => hold,
    min_on_plan_fraction: f64 => hold,
    closing_decides: bool => hold,
    balanced_squeeze: bool => fingers,
    approach: Approach => closing,
    samples: usize => robust,
    seed: u64 => robust,
    pose_offset_mm: f64 => robust,
    pose_rotation_deg: f64 => robust,
    friction_range_pct: f64 => robust,
    mass_range_pct: f64 => robust,
    torque_range_pct: f64 => robust,
    replay_sample: Option<usize> => robust,
    choose: Choose => robust,
    choose_min_lower_bound: f64 => robust,
    rest_joint_deg: f64 => early,
    order_by_closing: usize => selection,
    order_samples: usize => selection,
    order_reach: usize => selection,
}

/// `[("sim.<field>", s.<group>.<field>), ...]`: each grouped value with its `[sim]` key.
macro_rules! sim_keyed {
    ($s:expr; $($group:ident . $field:ident),+ $(,)?) => {
        [$((concat!("sim.", stringify!($field)), $s.$group.$field)),+]
    };
}

/// A key and what is wrong with its value.
type Invalid = (&'static str, String);

/// One number's allowed range: `(key, value, low, low included, high, unit)`.
type NumberRange = (&'static str, f64, f64, bool, f64, &'static str);

/// The range `(0, hi]` of `key`, whose value is `v`: a positive number up to `hi`.
fn positive(key: &'static str, v: f64, hi: f64, unit: &'static str) -> NumberRange {
    (key, v, 0.0, false, hi, unit)
}

/// `Ok` when the value is finite and within its range; else the key and a message stating
/// the range.
fn check_range((key, v, lo, closed, hi, unit): NumberRange) -> Result<(), Invalid> {
    let above = if closed { v >= lo } else { v > lo };
    if !(v.is_finite() && above && v <= hi) {
        let open = if closed { '[' } else { '(' };
        return Err((key, format!("must be in {open}{lo}, {hi}]{unit}, got {v}")));
    }
    Ok(())
}

impl SimParams {
    /// Checks every value's range, and `override_angles` against a hand of `fingers` fingers:
    /// the key and the problem of the first one out of range.
    ///
    /// # Errors
    /// `(key, problem)`.
    pub fn validate(&self, fingers: usize) -> Result<(), Invalid> {
        self.validate_positive()?;
        self.validate_counts()?;
        self.validate_bounds()?;
        self.validate_work()?;
        self.input.validate(fingers)?;
        self.fingers.validate_squeeze()?;
        self.robust.validate()
    }

    /// Every number's physical range (issue 56: a contact stiffness of 1e300 Hz overflowed the
    /// f32 solver, and an object that never moved was judged `drop`): each value must be
    /// finite and within its range, which the message states. The lower bounds are exclusive
    /// (0: the value must be positive) or inclusive where zero means "none".
    fn validate_positive(&self) -> Result<(), Invalid> {
        let s = self;
        let ranges: [NumberRange; 17] = [
            positive("sim.duration_s", s.hold.duration_s, 3600.0, " s"),
            positive("sim.timestep_s", s.solver.timestep_s, 0.05, " s"),
            positive(
                "sim.torque_limit_nm",
                s.fingers.torque_limit_nm,
                1000.0,
                " N·m",
            ),
            positive(
                "sim.joint1_lock_torque_nm",
                s.fingers.joint1_lock_torque_nm,
                10_000.0,
                " N·m",
            ),
            positive(
                "sim.hold_translation_mm",
                s.hold.hold_translation_mm,
                1000.0,
                " mm",
            ),
            positive(
                "sim.hold_rotation_deg",
                s.hold.hold_rotation_deg,
                180.0,
                "°",
            ),
            positive(
                "sim.close_duration_s",
                s.closing.close_duration_s,
                600.0,
                " s",
            ),
            positive(
                "sim.motor_stiffness_nm_per_rad",
                s.fingers.motor_stiffness_nm_per_rad,
                1e6,
                " N·m/rad",
            ),
            positive(
                "sim.finger_density_kg_m3",
                s.fingers.finger_density_kg_m3,
                100_000.0,
                " kg/m³",
            ),
            (
                "sim.contact_stiffness_hz",
                s.solver.contact_stiffness_hz,
                1.0,
                true,
                1e6,
                " Hz",
            ),
            positive("sim.open_margin_deg", s.closing.open_margin_deg, 90.0, "°"),
            positive("sim.rest_window_s", s.early.rest_window_s, 10.0, " s"),
            positive("sim.rest_joint_deg", s.early.rest_joint_deg, 360.0, "°"),
            positive("sim.rest_safety", s.early.rest_safety, 100.0, ""),
            positive("sim.rest_margin", s.early.rest_margin, 1.0, ""),
            positive(
                "sim.max_penetration_mm",
                s.hold.max_penetration_mm,
                1000.0,
                " mm",
            ),
            positive(
                "sim.max_closing_shift_mm",
                s.hold.max_closing_shift_mm,
                1000.0,
                " mm",
            ),
        ];
        ranges.into_iter().try_for_each(check_range)
    }

    /// The iteration counts and `max_checked`: 1 to 100.
    fn validate_counts(&self) -> Result<(), Invalid> {
        let s = self;
        for (key, v) in sim_keyed!(s;
            solver.solver_iterations,
            solver.pgs_iterations,
            solver.stabilization_iterations,
            solver.hold_solver_iterations,
            selection.max_checked,
        ) {
            if !(1..=100).contains(&v) {
                return Err((key, format!("must be in 1..=100, got {v}")));
            }
        }
        let n = s.selection.order_by_closing;
        if n > MAX_ORDER_BY_CLOSING {
            return Err((
                "sim.order_by_closing",
                format!("must be in 0..={MAX_ORDER_BY_CLOSING}, got {n}"),
            ));
        }
        let r = s.selection.order_reach;
        if r > MAX_ORDER_REACH {
            return Err((
                "sim.order_reach",
                format!("must be in 0..={MAX_ORDER_REACH}, got {r}"),
            ));
        }
        let m = s.selection.order_samples;
        if m > MAX_ORDER_SAMPLES {
            return Err((
                "sim.order_samples",
                format!("must be in 0..={MAX_ORDER_SAMPLES}, got {m}"),
            ));
        }
        Ok(())
    }

    /// The damping (zero allowed), the rest margin (a fraction) and the timestep against the
    /// hold.
    fn validate_bounds(&self) -> Result<(), Invalid> {
        let damping = self.fingers.motor_damping_nms_per_rad;
        if !(damping.is_finite() && (0.0..=10_000.0).contains(&damping)) {
            return Err((
                "sim.motor_damping_nms_per_rad",
                format!("must be in [0, 10000] N·m·s/rad, got {damping}"),
            ));
        }
        let share = self.hold.min_on_plan_fraction;
        if !(0.0..=1.0).contains(&share) {
            return Err((
                "sim.min_on_plan_fraction",
                format!("must be in 0..=1 (a share of the hand's phalanges), got {share}"),
            ));
        }
        if self.hold.closing_decides && self.protocol == Protocol::Full {
            return Err((
                "sim.closing_decides",
                "needs protocol = \"fast\" (the full protocol holds every direction to its end)"
                    .to_string(),
            ));
        }
        let timestep_s = self.solver.timestep_s;
        if timestep_s > 0.05 || timestep_s * 10.0 > self.hold.duration_s {
            return Err((
                "sim.timestep_s",
                format!("must be at most 0.05 s and a tenth of duration_s, got {timestep_s}"),
            ));
        }
        Ok(())
    }
}

/// The most physics steps one gravity direction's check may take, closing included: 83 times
/// the defaults' 2400 (0.5 s of closing and 2 s of hold at 960 Hz), some 10 s of this machine's
/// time per direction. A setting past it (a timestep of 1e-12 s, a hold of 1e9 s) would run for
/// ever; it is refused, the limit stated.
pub const MAX_STEPS_PER_DIRECTION: f64 = 200_000.0;

impl SimParams {
    /// The work the settings imply: the steps of one direction's check, at most
    /// [`MAX_STEPS_PER_DIRECTION`].
    fn validate_work(&self) -> Result<(), Invalid> {
        let t = self.solver.timestep_s;
        let steps = (self.closing.close_duration_s + self.hold.duration_s) / t;
        if steps > MAX_STEPS_PER_DIRECTION {
            return Err((
                "sim.timestep_s",
                format!(
                    "close_duration_s + duration_s = {} s at a timestep of {t} s is {steps:.3e} steps per gravity direction; at most {MAX_STEPS_PER_DIRECTION} (lengthen the timestep or shorten the durations)",
                    self.closing.close_duration_s + self.hold.duration_s
                ),
            ));
        }
        Ok(())
    }
}

impl InputParams {
    /// `override_angles` against a hand of `fingers` fingers, and `override_index` only with
    /// them.
    fn validate(&self, fingers: usize) -> Result<(), Invalid> {
        if let Some(a) = &self.override_angles {
            if a.len() != fingers {
                return Err((
                    "sim.override_angles",
                    format!("has {} fingers, the hand has {fingers}", a.len()),
                ));
            }
            if a.iter()
                .flatten()
                .any(|v| !(v.is_finite() && *v > 0.0 && *v <= 180.0))
            {
                return Err((
                    "sim.override_angles",
                    "angles must be in (0, 180] degrees".to_string(),
                ));
            }
        }
        if self.override_index == Some(0) {
            return Err((
                "sim.override_index",
                "must be at least 1 (indexed elevations count from 1; at most the object's \
                 count, checked once it is planned), got 0"
                    .to_string(),
            ));
        }
        if self.override_index.is_some() && self.override_angles.is_none() {
            return Err((
                "sim.override_index",
                "applies only with override_angles (the planner places the palm otherwise)"
                    .to_string(),
            ));
        }
        Ok(())
    }
}

/// The most perturbed checks a run may ask for.
pub const MAX_SAMPLES: usize = 1000;

impl RobustParams {
    /// The sample count, the ranges (zero allowed; the multipliers' below 100 %), the replayed
    /// sample and the choice's lower bound.
    fn validate(&self) -> Result<(), Invalid> {
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err((
                "sim.samples",
                format!("must be in 1..={MAX_SAMPLES}, got {}", self.samples),
            ));
        }
        for (key, v, max) in [
            ("sim.pose_offset_mm", self.pose_offset_mm, 50.0),
            ("sim.pose_rotation_deg", self.pose_rotation_deg, 45.0),
            ("sim.friction_range_pct", self.friction_range_pct, 90.0),
            ("sim.mass_range_pct", self.mass_range_pct, 90.0),
            ("sim.torque_range_pct", self.torque_range_pct, 90.0),
        ] {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err((key, format!("must be in [0, {max}], got {v}")));
            }
        }
        if let Some(k) = self.replay_sample {
            if k >= MAX_SAMPLES {
                return Err((
                    "sim.replay_sample",
                    format!("must be below {MAX_SAMPLES}, got {k}"),
                ));
            }
        }
        let lb = self.choose_min_lower_bound;
        if !(lb.is_finite() && (0.0..=1.0).contains(&lb)) {
            return Err((
                "sim.choose_min_lower_bound",
                format!("must be in [0, 1], got {lb}"),
            ));
        }
        if self.choose == Choose::Robust && self.samples < 2 {
            return Err((
                "sim.choose",
                "\"robust\" needs samples of at least 2 (the hold probability it chooses by)"
                    .to_string(),
            ));
        }
        Ok(())
    }
}

impl FingerParams {
    /// The squeeze overshoots: zero or positive.
    fn validate_squeeze(&self) -> Result<(), Invalid> {
        for (key, v) in keyed!("sim", self; squeeze_deg, squeeze2_deg) {
            if !(v.is_finite() && (0.0..=90.0).contains(&v)) {
                return Err((key, format!("must be in [0, 90]°, got {v}")));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flat_sim_table_fills_the_groups() {
        let p: SimParams = toml::from_str(
            "torque_limit_nm = 0.5\nrest_margin = 0.5\nmax_checked = 3\napproach = \"together\"\n\
             override_angles = [[90.0, 80.0]]",
        )
        .unwrap();
        assert_eq!(p.fingers.torque_limit_nm, 0.5);
        assert_eq!(p.early.rest_margin, 0.5);
        assert_eq!(p.selection.max_checked, 3);
        assert_eq!(p.closing.approach, Approach::Together);
        assert_eq!(p.input.override_angles, Some(vec![[90.0, 80.0]]));
        // Everything else at its default.
        let mut expected = SimParams::default();
        expected.fingers.torque_limit_nm = 0.5;
        expected.early.rest_margin = 0.5;
        expected.selection.max_checked = 3;
        expected.closing.approach = Approach::Together;
        expected.input.override_angles = Some(vec![[90.0, 80.0]]);
        assert_eq!(p, expected);
        assert_eq!(
            toml::from_str::<SimParams>("").unwrap(),
            SimParams::default()
        );
    }

    #[test]
    fn messages_and_debug_text_are_the_flat_tables() {
        let err = toml::from_str::<SimParams>("torque_limt_nm = 1.0").unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains(
                "unknown field `torque_limt_nm`, expected one of `gravity`, `protocol`, \
                 `rest_window_s`"
            ),
            "{msg}"
        );
        let err = toml::from_str::<SimParams>("duration_s = \"long\"").unwrap_err();
        assert!(err.to_string().contains("expected f64"), "{err}");
        let debug = format!("{:?}", SimParams::default());
        assert!(
            debug.starts_with(
                "SimParams { gravity: Down, protocol: Fast, rest_window_s: 0.05, rest_safety: 2.0,"
            ),
            "{debug}"
        );
        assert!(
            debug.contains("balanced_squeeze: true, approach: Together, samples: 1, seed: 0,"),
            "{debug}"
        );
    }

    #[test]
    fn validation_reports_the_first_key_in_the_old_order() {
        let check = |toml: &str| {
            toml::from_str::<SimParams>(toml)
                .unwrap()
                .validate(3)
                .map_err(|(key, _)| key)
        };
        assert_eq!(check(""), Ok(()));
        // duration_s before timestep_s before the counts before the damping.
        assert_eq!(
            check("duration_s = 0.0\ntimestep_s = 0.0\nmax_checked = 0"),
            Err("sim.duration_s")
        );
        assert_eq!(
            check("max_checked = 0\nmotor_damping_nms_per_rad = -1.0"),
            Err("sim.max_checked")
        );
        assert_eq!(check("timestep_s = 0.5"), Err("sim.timestep_s"));
        assert_eq!(check("rest_margin = 1.5"), Err("sim.rest_margin"));
        assert_eq!(check("min_on_plan_fraction = 1.0"), Ok(()));
        assert_eq!(check("min_on_plan_fraction = 0.0"), Ok(()));
        for bad in ["1.5", "-0.1", "nan"] {
            assert_eq!(
                check(&format!("min_on_plan_fraction = {bad}")),
                Err("sim.min_on_plan_fraction")
            );
        }
        assert_eq!(check("override_index = 2"), Err("sim.override_index"));
        assert_eq!(
            check("override_angles = [[90.0, 90.0]]\nsqueeze2_deg = -1.0"),
            Err("sim.override_angles")
        );
        assert_eq!(check("squeeze2_deg = -1.0"), Err("sim.squeeze2_deg"));
        assert_eq!(
            check("hold_solver_iterations = 0"),
            Err("sim.hold_solver_iterations")
        );
        assert_eq!(check("order_by_closing = 256"), Ok(()));
        assert_eq!(check("order_by_closing = 257"), Err("sim.order_by_closing"));
        assert_eq!(check("order_samples = 64"), Ok(()));
        assert_eq!(check("order_samples = 65"), Err("sim.order_samples"));
        assert_eq!(check("order_reach = 1024"), Ok(()));
        assert_eq!(check("order_reach = 1025"), Err("sim.order_reach"));
        let mut p = SimParams::default();
        p.solver.timestep_s = 0.5;
        assert_eq!(
            p.validate(3),
            Err((
                "sim.timestep_s",
                "must be in (0, 0.05] s, got 0.5".to_string()
            ))
        );
        p.solver.timestep_s = 0.04;
        p.hold.duration_s = 0.2;
        assert_eq!(
            p.validate(3),
            Err((
                "sim.timestep_s",
                "must be at most 0.05 s and a tenth of duration_s, got 0.04".to_string()
            ))
        );
        // Every number has a physical range, stated (issue 56).
        let mut p = SimParams::default();
        p.solver.contact_stiffness_hz = 1e300;
        let (key, problem) = p.validate(3).unwrap_err();
        assert_eq!(key, "sim.contact_stiffness_hz");
        assert!(
            problem.starts_with("must be in [1, 1000000] Hz, got 1000"),
            "{problem}"
        );
        assert_eq!(
            check(
                "override_angles = [[90.0, 90.0], [90.0, 90.0], [90.0, 90.0]]\noverride_index = 0"
            ),
            Err("sim.override_index")
        );
    }

    /// A value with every group away from its defaults, the fields serialised only when not at
    /// their defaults included.
    fn non_default() -> SimParams {
        let mut p = SimParams {
            gravity: GravityMode::Six,
            protocol: Protocol::Full,
            ..SimParams::default()
        };
        p.solver.hand_joints = HandJoints::Impulse;
        p.fingers.balanced_squeeze = false;
        p.closing.refine_contacts = true;
        p.closing.reseat = false;
        p.closing.reseat_only_lifted = false;
        p.closing.approach = Approach::Timed;
        p.hold.closing_decides = true;
        p.early.rest_margin = 0.75;
        p.early.rest_joint_deg = 2.5;
        p.selection.order_by_closing = 0;
        p.selection.order_samples = 0;
        p.selection.order_reach = 0;
        p.selection.max_checked = 4;
        p.input.override_angles = Some(vec![[90.0, 80.5], [45.0, 30.0]]);
        p.input.override_index = Some(7);
        p.robust.samples = 8;
        p.robust.replay_sample = Some(3);
        p.robust.choose = Choose::Robust;
        p
    }

    /// The `Debug` text, as the batch input hash reads it, pinned: the flat `[sim]` table's
    /// fields in their order.
    #[test]
    fn debug_text_is_pinned() {
        assert_eq!(
            format!("{:?}", SimParams::default()),
            "SimParams { gravity: Down, protocol: Fast, rest_window_s: 0.05, rest_safety: 2.0, \
            rest_margin: 0.8, duration_s: 2.0, timestep_s: 0.0010416666666666667, \
            squeeze_deg: 3.0, squeeze2_deg: 3.0, torque_limit_nm: 1.0, \
            joint1_lock_torque_nm: 10.0, hold_translation_mm: 5.0, hold_rotation_deg: 5.0, \
            close_duration_s: 0.5, close_until_stalled: true, solver_iterations: 8, \
            pgs_iterations: 8, stabilization_iterations: 2, \
            motor_stiffness_nm_per_rad: 20.0, motor_damping_nms_per_rad: 0.2, \
            finger_density_kg_m3: 1000.0, contact_stiffness_hz: 10000.0, \
            hand_joints: Multibody, hold_solver_iterations: 12, open_margin_deg: 20.0, \
            refine_contacts: false, reseat: true, \
            reseat_only_lifted: true, \
            override_angles: None, \
            override_index: None, max_checked: 8, max_penetration_mm: 2.0, \
            max_closing_shift_mm: 5.0, min_on_plan_fraction: 0.5, closing_decides: false, \
            balanced_squeeze: true, approach: Together, samples: 1, seed: 0, \
            pose_offset_mm: 2.0, pose_rotation_deg: 3.0, friction_range_pct: 15.0, \
            mass_range_pct: 15.0, torque_range_pct: 10.0, replay_sample: None, \
            choose: First, choose_min_lower_bound: 0.8, \
            rest_joint_deg: 1.0, order_by_closing: 16, order_samples: 4, order_reach: 64 }"
        );
        assert_eq!(
            format!("{:?}", non_default()),
            "SimParams { gravity: Six, protocol: Full, rest_window_s: 0.05, rest_safety: 2.0, \
            rest_margin: 0.75, duration_s: 2.0, timestep_s: 0.0010416666666666667, \
            squeeze_deg: 3.0, squeeze2_deg: 3.0, torque_limit_nm: 1.0, \
            joint1_lock_torque_nm: 10.0, hold_translation_mm: 5.0, hold_rotation_deg: 5.0, \
            close_duration_s: 0.5, close_until_stalled: true, solver_iterations: 8, \
            pgs_iterations: 8, stabilization_iterations: 2, \
            motor_stiffness_nm_per_rad: 20.0, motor_damping_nms_per_rad: 0.2, \
            finger_density_kg_m3: 1000.0, contact_stiffness_hz: 10000.0, \
            hand_joints: Impulse, hold_solver_iterations: 12, open_margin_deg: 20.0, \
            refine_contacts: true, reseat: false, \
            reseat_only_lifted: false, \
            override_angles: Some([[90.0, 80.5], \
            [45.0, 30.0]]), override_index: Some(7), max_checked: 4, \
            max_penetration_mm: 2.0, max_closing_shift_mm: 5.0, min_on_plan_fraction: 0.5, \
            closing_decides: true, balanced_squeeze: false, approach: Timed, samples: 8, \
            seed: 0, pose_offset_mm: 2.0, pose_rotation_deg: 3.0, friction_range_pct: 15.0, \
            mass_range_pct: 15.0, torque_range_pct: 10.0, replay_sample: Some(3), \
            choose: Robust, choose_min_lower_bound: 0.8, \
            rest_joint_deg: 2.5, order_by_closing: 0, order_samples: 0, order_reach: 0 }"
        );
    }

    /// The serialised parameters (a scenario's JSON, which the batch input hash reads), pinned:
    /// the groups' nesting, their fields' order, and the fields left out at their defaults.
    #[test]
    fn serialised_parameters_are_pinned() {
        assert_eq!(
            serde_json::to_string(&SimParams::default()).unwrap(),
            concat!(
                r#"{"gravity":"down","#,
                r#""protocol":"fast","#,
                r#""solver":{"timestep_s":0.0010416666666666667,"solver_iterations":8,"#,
                r#""pgs_iterations":8,"stabilization_iterations":2,"#,
                r#""contact_stiffness_hz":10000.0,"#,
                r#""hold_solver_iterations":12},"#,
                r#""fingers":{"squeeze_deg":3.0,"squeeze2_deg":3.0,"torque_limit_nm":1.0,"#,
                r#""joint1_lock_torque_nm":10.0,"motor_stiffness_nm_per_rad":20.0,"#,
                r#""motor_damping_nms_per_rad":0.2,"finger_density_kg_m3":1000.0,"#,
                r#""balanced_squeeze":true},"#,
                r#""closing":{"close_duration_s":0.5,"close_until_stalled":true,"#,
                r#""open_margin_deg":20.0,"approach":"together","reseat":true},"#,
                r#""hold":{"duration_s":2.0,"hold_translation_mm":5.0,"hold_rotation_deg":5.0,"#,
                r#""max_penetration_mm":2.0,"max_closing_shift_mm":5.0,"#,
                r#""min_on_plan_fraction":0.5,"#,
                r#""closing_decides":false},"#,
                r#""early":{"rest_window_s":0.05,"rest_safety":2.0,"rest_margin":0.8,"#,
                r#""rest_joint_deg":1.0},"#,
                r#""selection":{"max_checked":8},"#,
                r#""input":{"override_angles":null,"override_index":null}}"#,
            )
        );
        assert_eq!(
            serde_json::to_string(&non_default()).unwrap(),
            concat!(
                r#"{"gravity":"six","#,
                r#""protocol":"full","#,
                r#""solver":{"timestep_s":0.0010416666666666667,"solver_iterations":8,"#,
                r#""pgs_iterations":8,"stabilization_iterations":2,"#,
                r#""contact_stiffness_hz":10000.0,"#,
                r#""hand_joints":"impulse","hold_solver_iterations":12},"#,
                r#""fingers":{"squeeze_deg":3.0,"squeeze2_deg":3.0,"torque_limit_nm":1.0,"#,
                r#""joint1_lock_torque_nm":10.0,"motor_stiffness_nm_per_rad":20.0,"#,
                r#""motor_damping_nms_per_rad":0.2,"finger_density_kg_m3":1000.0,"#,
                r#""balanced_squeeze":false},"#,
                r#""closing":{"close_duration_s":0.5,"close_until_stalled":true,"#,
                r#""open_margin_deg":20.0,"approach":"timed","refine_contacts":true,"#,
                r#""reseat_only_lifted":false},"#,
                r#""hold":{"duration_s":2.0,"hold_translation_mm":5.0,"hold_rotation_deg":5.0,"#,
                r#""max_penetration_mm":2.0,"max_closing_shift_mm":5.0,"#,
                r#""min_on_plan_fraction":0.5,"#,
                r#""closing_decides":true},"#,
                r#""early":{"rest_window_s":0.05,"rest_safety":2.0,"rest_margin":0.75,"#,
                r#""rest_joint_deg":2.5},"#,
                r#""selection":{"max_checked":4,"order_by_closing":0,"order_samples":0,"order_reach":0},"#,
                r#""input":{"override_angles":[[90.0,80.5],[45.0,30.0]],"override_index":7},"#,
                r#""robust":{"samples":8,"seed":0,"pose_offset_mm":2.0,"pose_rotation_deg":3.0,"#,
                r#""friction_range_pct":15.0,"mass_range_pct":15.0,"torque_range_pct":10.0,"#,
                r#""replay_sample":3,"choose":"robust","choose_min_lower_bound":0.8}}"#,
            )
        );
    }

    /// Every field of every group is a row of the `[sim]` table (a field left out of it would
    /// be neither read nor printed), and the conversions lose nothing.
    #[test]
    fn every_group_field_is_a_key() {
        // The leaf names of the serialised groups: the fields left out at their defaults are
        // in one of the two values.
        let mut fields = std::collections::BTreeSet::new();
        for p in [SimParams::default(), non_default()] {
            let serde_json::Value::Object(top) = serde_json::to_value(p).unwrap() else {
                panic!("not an object");
            };
            for (name, value) in top {
                match value {
                    serde_json::Value::Object(group) => fields.extend(group.keys().cloned()),
                    _ => {
                        fields.insert(name);
                    }
                }
            }
        }
        let keys: std::collections::BTreeSet<String> =
            flat::KEYS.iter().map(|k| k.to_string()).collect();
        assert_eq!(fields, keys);
        assert_eq!(
            SimParams::from(flat::SimParams::from(non_default())),
            non_default()
        );
    }

    /// serde's messages for a mistyped key (every key, in the table's order) and a wrong type.
    #[test]
    fn parse_messages_are_pinned() {
        let err = toml::from_str::<SimParams>("torque_limt_nm = 1.0").unwrap_err();
        assert!(
            err.to_string().ends_with(
                "unknown field `torque_limt_nm`, expected one of `gravity`, `protocol`, \
                `rest_window_s`, `rest_safety`, `rest_margin`, `duration_s`, `timestep_s`, \
                `squeeze_deg`, `squeeze2_deg`, `torque_limit_nm`, `joint1_lock_torque_nm`, \
                `hold_translation_mm`, `hold_rotation_deg`, `close_duration_s`, \
                `close_until_stalled`, `solver_iterations`, `pgs_iterations`, \
                `stabilization_iterations`, `motor_stiffness_nm_per_rad`, \
                `motor_damping_nms_per_rad`, `finger_density_kg_m3`, `contact_stiffness_hz`, \
                `hand_joints`, `hold_solver_iterations`, `open_margin_deg`, \
                `refine_contacts`, `reseat`, `reseat_only_lifted`, \
                `override_angles`, \
                `override_index`, \
                `max_checked`, `max_penetration_mm`, `max_closing_shift_mm`, \
                `min_on_plan_fraction`, `closing_decides`, `balanced_squeeze`, `approach`, \
                `samples`, `seed`, `pose_offset_mm`, `pose_rotation_deg`, \
                `friction_range_pct`, `mass_range_pct`, `torque_range_pct`, `replay_sample`, \
                `choose`, `choose_min_lower_bound`, `rest_joint_deg`, `order_by_closing`, \
                `order_samples`, `order_reach`\n"
            ),
            "{err}"
        );
        let err = toml::from_str::<SimParams>("duration_s = \"long\"").unwrap_err();
        assert!(
            err.to_string()
                .ends_with("invalid type: string \"long\", expected f64\n"),
            "{err}"
        );
    }
}
