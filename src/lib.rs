//! grasp-sim: kinematic enveloping grasp planning for a three-fingered hand, after S. Salimi's
//! thesis "Kinematic Enveloping Grasp Planning Method for Robotic Dexterous Hands and
//! Three-Dimensional Objects" (McMaster University), checked in a rapier3d physics scene.
//!
//! Data flow (each stage a plain function, so tests, benches and the tuner can call one alone;
//! [`pipeline`] runs them for one input, and the command line, `batch` and `tune` call it):
//!
//! ```text
//! scenario.toml → scenario::Scenario → prepared::PreparedObject (mesh::load_mesh, mass, collider)
//!   → select::select: for each rule set (thesis, extended, pinch) and axis: mesh::align →
//!     plan (stages 1–3 on slice::slice, then the search) → each candidate's sim check
//!   → quality (optional) → report::RunReport (JSON, summary; expectations judged)
//!   → pipeline::write_outputs (--report, --export-mjcf, --export-urdf)
//! ```
//!
//! Units: the mesh, slicer and planner work in millimetres and degrees in the aligned object frame
//! (principal axis +Z, bottom at Z = 0), as the thesis does; the physics check works in SI units,
//! converted once at its boundary ([`sim::convert`]).
//!
//! Math types: the planner uses nalgebra (f64). rapier3d 0.36 and parry3d 0.31 use glam types
//! (`Vec3`, `Pose3`, f32 by default); the conversion between the two lives in [`sim::convert`],
//! the only module that knows both.

#![warn(missing_docs)]

pub mod assets;
pub mod batch;
pub mod export;
pub mod files;
pub mod hand;
pub mod hand_show;
pub mod label;
pub mod mesh;
mod messages;
pub mod objects;
pub mod pick;
pub mod pipeline;
pub mod plan;
pub mod prepared;
pub mod quality;
pub mod report;
pub mod scenario;
pub mod select;
pub mod sim;
pub mod slice;
pub mod summarize;
pub mod tune;
pub mod visual;
mod xml_lines;

pub use pipeline::{run, Error, GivenGrasp, RunFlags, RunOptions, DEFAULT_MAX_CHECKED};
