//! Labelling grasps for datasets (issue 57): many diverse candidates per object, each with its
//! hold probability and its probability of a hold as planned; and a validator for grasps
//! planned elsewhere.
//!
//! - [`object`]: one object: the planner's candidates collected once, diverse ones picked
//!   ([`pick`]), each checked (the nominal check and its perturbed samples, every check of the
//!   object spread over the cores); given grasp lines checked the same way.
//! - [`line`]: the JSON line of a labelled grasp ([`LabelRecord`]), which is also valid input to
//!   `grasp-sim check --grasps` ([`GraspLine`]).
//! - [`command`]: `grasp-sim label` over many objects (as `batch`: folders, templates, shards,
//!   a worker process per object, `--resume` grasp by grasp, `--merge`), `--npz` ([`npz`]), and
//!   `grasp-sim check --grasps`.
//!
//! A labelled grasp's line equals, bit for bit but for its `label.wall_ms`, what `check
//! --grasps` writes for that line with the same samples: both check the pose as the line writes
//! it ([`GraspLine::of_pose`] rounds it as the JSON does) through the same function.

pub mod command;
pub mod line;
pub mod npz;
pub mod object;
pub use crate::pick;

pub use line::{GraspLine, LabelInfo, LabelRecord};
pub use object::{
    check_lines, check_numbered_lines, label_object, LabelParams, Line, ObjectSummary,
};
