//! Integration tests, one binary so the suite links once.

mod batch;
mod cli;
mod export;
mod geometry;
mod planner;
mod sim;
mod thesis_table;
mod tune;
mod visual;

use std::path::PathBuf;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}
