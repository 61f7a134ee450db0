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

/// The built binary, run from the repository root (bundled scenarios resolve from there).
pub fn grasp_sim() -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_grasp-sim"));
    c.current_dir(root());
    c
}

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}
