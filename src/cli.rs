//! Command-line flags, as typed (clap derive).

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// Plan enveloping grasps for a three-fingered hand and check them in a physics scene.
///
/// Exit status: 0 every expectation met (or none stated), 1 an expectation not met, 2 bad input
/// (the other inputs still run and print; the worst status wins).
#[derive(Debug, Parser)]
#[command(
    name = "grasp-sim",
    version,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Cli {
    /// Scenario files (TOML) or bare meshes (STL, OBJ, PLY) to run, in order. A bare mesh runs
    /// with the bundled thesis hand and the defaults, and judges nothing.
    #[arg(required = true, value_name = "SCENARIO | MESH")]
    pub scenarios: Vec<PathBuf>,

    /// Length unit of bare meshes given on the command line (scenarios say theirs in
    /// `[object] units`).
    #[arg(long, value_name = "UNIT", default_value = "mm", value_parser = ["mm", "m", "inch"])]
    pub units: String,

    /// Print one JSON object per scenario (JSON Lines) instead of the summary.
    #[arg(long)]
    pub json: bool,

    /// Plan only; skip the physics check.
    #[arg(long)]
    pub no_sim: bool,

    /// Also find the payload margin: the largest mass multiplier (up to 64) that still holds.
    #[arg(long)]
    pub payload: bool,

    /// Write each planned grasp as an MJCF scene for MuJoCo into DIR/<scenario>/ (scene.xml,
    /// the object's STL, protocol.json for scripts/mujoco_replay.py).
    #[arg(long, value_name = "DIR")]
    pub export_mjcf: Option<PathBuf>,

    /// Write the thesis-style figures (SVG), the planned and simulated 3D scenes (.glb) and a
    /// self-contained report.html into DIR/<scenario>/.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,

    /// Write the hand as URDF into DIR/<scenario>/hand.urdf.
    #[arg(long, value_name = "DIR")]
    pub export_urdf: Option<PathBuf>,

    /// Collect up to N feasible grasps in search order (reported under `plan.grasps`).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub candidates: u32,

    /// With the physics check: check candidates in search order until one holds or N have been
    /// checked (default: the scenario's `[sim] max_checked`, 8).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100))]
    pub max_checked: Option<u32>,

    #[command(subcommand)]
    pub command: Option<Command>,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run many objects: every scenario and mesh in the given folders, or the files given; one
    /// JSON line per object, in input order, and a summary on stderr.
    ///
    /// Exit status: 0 every stated expectation met (bare meshes state none), 1 an expectation not
    /// met, 2 an input could not be run (its JSON line has an `error`; the others still run).
    Batch {
        /// Folders, scenario files (.toml) or meshes (.stl, .obj, .ply).
        #[arg(required = true, value_name = "DIR | SCENARIO")]
        inputs: Vec<PathBuf>,
        /// Scenario used for bare meshes (default: the thesis hand and defaults).
        #[arg(long, value_name = "SCENARIO")]
        template: Option<PathBuf>,
        /// Length unit of bare meshes (overrides the template's).
        #[arg(long, value_name = "UNIT", value_parser = ["mm", "m", "inch"])]
        units: Option<String>,
        /// Write the JSON lines to this file instead of stdout (written whole, or not at all).
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Worker threads (default: all cores).
        #[arg(long, value_name = "N")]
        jobs: Option<usize>,
        /// Run only the K-th of N contiguous blocks of the inputs (e.g. a Slurm array task).
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
        /// Plan only.
        #[arg(long)]
        no_sim: bool,
        /// Also find each grasp's payload margin.
        #[arg(long)]
        payload: bool,
    },
    /// Sweep planner parameters over a grid and rank the settings by simulated outcomes (hold
    /// rate, then mean payload margin, then mean translation); writes tune.csv, tune.json and
    /// score_<param>.svg into --out.
    Tune {
        /// Folders, scenario files (.toml) or meshes (.stl, .obj, .ply).
        #[arg(required = true, value_name = "DIR | SCENARIO")]
        inputs: Vec<PathBuf>,
        /// NAME=START:END:STEP, repeatable (sf_c, height_step_mm, angular_step_deg,
        /// vertical_deviation_deg, joint_deviation_deg, joint_deviation_theta1_deg,
        /// joint_deviation_theta2_deg, pitch_range_deg).
        #[arg(long = "param", required = true, value_name = "NAME=START:END:STEP")]
        params: Vec<String>,
        /// Output folder.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Plan up to N grasps per object and keep the best by simulation.
        #[arg(long, value_name = "N", default_value_t = 1)]
        candidates: usize,
        /// Scenario used for bare meshes (default: the thesis hand and defaults).
        #[arg(long, value_name = "SCENARIO")]
        template: Option<PathBuf>,
        /// Worker threads (default: all cores).
        #[arg(long, value_name = "N")]
        jobs: Option<usize>,
    },
    /// Write the thesis objects as binary STL (deterministic: the same bytes every time).
    GenAssets {
        /// Output folder.
        #[arg(long, default_value = "assets/objects")]
        out: PathBuf,
    },
}
