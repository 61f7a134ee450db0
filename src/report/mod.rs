//! The run report: the JSON contract of DESIGN.md section 6 and the human summary.
//!
//! Field names are a contract that outside scripts read: add fields, never rename. A physics
//! check that has not run is reported as such (`"verdict": "not_run"` and its `reason`), never
//! with invented numbers. Outcomes are enums in Rust whose JSON names are the strings scripts
//! read (`feasible`, `hold`, `not_run`, `override_angles`, ...).
//!
//! - [`contract`]: the report's types, as written to JSON, and [`RecordView`], a line read back.
//! - [`check`] and [`robust`]: the physics check's part of them, converted from `sim`'s types.
//! - [`expect`]: judging a scenario's `[expect]`.
//! - [`summary`]: the human summary.
//! - [`json`]: the JSON text, figures rounded.

pub mod check;
pub mod contract;
pub mod expect;
pub mod json;
pub mod robust;
pub mod summary;

pub use check::{
    ClosingOutcome, ColliderKind, ColliderReport, DecidedBy, DirectionOutcome, Fidelity,
    FidelityReason, FingerClosing, FingerRefinement, FirstTouch, Start, Verdict,
};
pub use contract::{
    AlsReport, AxisReport, BatchView, CandidateCheck, CandidateRobust, ClosingOrder, DiameterBasis,
    DirectionView, ErrorView, ExpectReport, ExpectView, FingerReport, GradesReport, GraspQuality,
    GraspReport, GraspSource, HoldLimits, IndexScale, ObjectReport, PlanReport, PlanStatus,
    PlanView, PoseReport, RecordView, RobustView, RunReport, SimReport, SimVerdict, SimView,
    StageTimings,
};
pub use json::{
    round_significant, to_rounded_json, to_rounded_json_pretty, JSON_SIGNIFICANT_DIGITS,
    JSON_ZERO_BELOW,
};
pub use robust::{Counts, DirectionRobust, FirstFailure, Perturbation, Ranges, Robust};
pub use summary::{closing_line, fmt_signed};
