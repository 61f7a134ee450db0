//! Command-line flags, as typed (clap derive).

use clap::{Parser, Subcommand, ValueEnum};
use grasp_sim::mesh::LengthUnit;
use grasp_sim::scenario::GravityMode;
use std::path::PathBuf;

/// A length unit named on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Units {
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
    /// Inches.
    Inch,
}

impl From<Units> for LengthUnit {
    fn from(u: Units) -> LengthUnit {
        match u {
            Units::Mm => LengthUnit::Mm,
            Units::Cm => LengthUnit::Cm,
            Units::M => LengthUnit::M,
            Units::Inch => LengthUnit::Inch,
        }
    }
}

impl Units {
    /// The name as typed (`mm`, `cm`, `m`, `inch`).
    pub fn name(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::Cm => "cm",
            Units::M => "m",
            Units::Inch => "inch",
        }
    }
}

/// The gravity directions named on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Gravity {
    /// The aligned object's −Z.
    Down,
    /// ±X, ±Y, ±Z in turn.
    Six,
}

impl From<Gravity> for GravityMode {
    fn from(g: Gravity) -> GravityMode {
        match g {
            Gravity::Down => GravityMode::Down,
            Gravity::Six => GravityMode::Six,
        }
    }
}

/// The flags that decide what a run computes for each input (the main command, `batch` and its
/// workers share them).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct RunFlags {
    /// Plan only; skip the physics check.
    #[arg(long)]
    pub no_sim: bool,

    /// Also find the payload margin: the largest mass multiplier (up to 64) that still holds.
    #[arg(long)]
    pub payload: bool,

    /// Also compute the analytic grasp quality (Ferrari-Canny epsilon and volume of the grasp
    /// wrench space, L1 and L-infinity, docs/QUALITY.md) of every grasp reported: about 30-40 ms
    /// per grasp from the check's contacts, 0.1-0.2 s from the planned ones.
    #[arg(long)]
    pub quality: bool,
}

impl From<RunFlags> for grasp_sim::RunFlags {
    fn from(f: RunFlags) -> grasp_sim::RunFlags {
        grasp_sim::RunFlags {
            no_sim: f.no_sim,
            payload: f.payload,
            quality: f.quality,
        }
    }
}

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
    /// Scenario files (TOML) or bare meshes (STL, OBJ, PLY, or an object's URDF) to run, in
    /// order. A bare mesh runs with the bundled thesis hand and the defaults, and judges nothing.
    #[arg(required = true, value_name = "SCENARIO | MESH")]
    pub scenarios: Vec<PathBuf>,

    /// Length unit of bare meshes given on the command line (scenarios say theirs in
    /// `[object] units`).
    #[arg(long, value_name = "UNIT", value_enum, default_value_t = Units::Mm)]
    pub units: Units,

    /// Print one JSON object per scenario (JSON Lines) instead of the summary.
    #[arg(long)]
    pub json: bool,

    #[command(flatten)]
    pub flags: RunFlags,

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

    /// Gravity directions of the physics check, for every input: `down` (the aligned object's
    /// −Z) or `six` (±X, ±Y, ±Z in turn, each from the one closing); default: each scenario's
    /// `[sim] gravity`, `down` for a bare mesh.
    #[arg(long, value_name = "DIRECTIONS", value_enum)]
    pub gravity: Option<Gravity>,

    /// Perturbed checks of the chosen grasp, for every input (`sim.robust`: the hold probability
    /// with its 95 % interval; docs/SIM.md "Hold probability"); default: each scenario's
    /// `[sim] samples`, 1 (the main check only).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub samples: Option<u32>,

    /// Stop waiting for an input after this many seconds: its line is an error and the next
    /// input runs (a backstop; no input the planner's budget admits comes near it).
    #[arg(long, value_name = "SECONDS", value_parser = positive_seconds,
          default_value_t = grasp_sim::pipeline::inputs::DEFAULT_TIME_LIMIT_S)]
    pub time_limit: f64,

    /// Keep each object's convex decomposition (V-HACD, 0.1-0.4 s an object and axis) in DIR,
    /// made if missing, under the digest of its mesh: a later run that meets the same object
    /// reads it instead of making it again, the same collider bit for bit. For every command;
    /// also from the environment's GRASP_SIM_COLLIDER_CACHE.
    #[arg(long, value_name = "DIR", global = true)]
    pub collider_cache: Option<PathBuf>,

    #[command(subcommand)]
    pub command: Option<Command>,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run many objects: every scenario and mesh in the given folders, or the files given; one
    /// JSON line per object, in input order, and a summary on stderr.
    ///
    /// Each object runs in a worker process of its own, so a panic, a crash, a run past
    /// --object-timeout or memory exhaustion is an error line for that object and the others
    /// go on. Each line carries `batch.input`, `batch.input_hash` and `batch.wall_ms`.
    ///
    /// Exit status: 0 every stated expectation met (bare meshes state none), 1 an expectation not
    /// met, 2 an input could not be run (its JSON line has an `error`; the others still run).
    Batch(BatchArgs),
    /// Summarize a batch's results (a JSON Lines file from `batch`, or from `--json`): counts
    /// (planned, ungraspable, hold / slip / drop, held per gravity direction, expectations,
    /// errors) and the slowest objects; `--csv` writes one row per object.
    Summarize {
        /// The results file.
        #[arg(value_name = "RESULTS.jsonl")]
        file: PathBuf,
        /// Also write one row per object to this CSV file.
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
        /// How many of the slowest objects to list.
        #[arg(long, value_name = "N", default_value_t = 10)]
        slowest: usize,
    },
    /// Internal: run one object of a batch in a process of its own and print its line (the
    /// batch starts it for each object; see `batch --in-process`).
    #[command(hide = true)]
    BatchWorker {
        /// The scenario or mesh.
        path: PathBuf,
        /// The input hash the batch computed for it.
        #[arg(long)]
        input_hash: String,
        /// As `batch --template`.
        #[arg(long)]
        template: Option<PathBuf>,
        /// As `batch --units`.
        #[arg(long, value_enum)]
        units: Option<Units>,
        /// As `batch`'s.
        #[command(flatten)]
        flags: RunFlags,
    },
    /// Sweep planner parameters over a grid and rank the settings by simulated outcomes (hold
    /// rate, then mean payload margin, then mean translation); writes tune.csv, tune.json and
    /// score_<param>.svg into --out.
    Tune(TuneArgs),
    /// Label many diverse grasps per object with their hold probability (a grasp dataset):
    /// per object, plan up to --candidates feasible grasps, pick --grasps diverse ones
    /// (farthest-point over the palm pose and the finger contacts, the first candidate always
    /// among them), check each with --samples perturbed checks, and write one JSON line per
    /// grasp (docs/OUTPUT.md "Label lines"). Inputs, workers, --resume, --merge and shards as
    /// for `batch`; --resume continues grasp by grasp.
    ///
    /// Exit status: 0 every grasp labelled, 2 an object or a grasp could not be (its line has an
    /// `error`; the others are still labelled).
    Label(LabelArgs),
    /// Internal: label one object in a process of its own, printing its lines as they finish
    /// (`label` starts it for each object; see `label --in-process`).
    #[command(hide = true)]
    LabelWorker {
        /// The scenario or mesh.
        path: PathBuf,
        /// The input hash the run computed for it.
        #[arg(long)]
        input_hash: String,
        /// As `label --template`.
        #[arg(long)]
        template: Option<PathBuf>,
        /// As `label --units`.
        #[arg(long, value_enum)]
        units: Option<Units>,
        /// As `label --gravity`.
        #[arg(long, value_enum)]
        gravity: Option<Gravity>,
        /// As `label --grasps`.
        #[arg(long)]
        grasps: usize,
        /// As `label --samples`.
        #[arg(long)]
        samples: usize,
        /// As `label --candidates`.
        #[arg(long)]
        candidates: usize,
        /// As `label --export-mjcf`.
        #[arg(long)]
        export_mjcf: Option<PathBuf>,
        /// As `label --mujoco-fraction`.
        #[arg(long, default_value_t = 1.0)]
        mujoco_fraction: f64,
        /// Grasp indices already labelled, comma-separated.
        #[arg(long, value_delimiter = ',')]
        skip: Vec<usize>,
    },
    /// Check given grasps: every line of --grasps FILE (JSON Lines with `palm_pose` 4 x 4 in
    /// the object file's frame [mm] and `joint_angles_deg`, one [θ1, θ2] per finger; a `label`
    /// file is valid input) on the object, one record per line, as `label` writes them; of a
    /// file of several objects, the lines whose `object` is this one's.
    ///
    /// Exit status: 0 every line checked, 2 a line could not be (its record has an `error`;
    /// the other lines are still checked).
    Check {
        /// The grasps, one JSON object per line.
        #[arg(long, value_name = "FILE.jsonl")]
        grasps: PathBuf,
        /// The object: a scenario (its hand, friction and protocol too) or a bare mesh.
        #[arg(value_name = "SCENARIO | MESH")]
        input: PathBuf,
        /// Perturbed checks per grasp (the hold probability's samples).
        #[arg(long, value_name = "N", default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1000))]
        samples: u32,
        /// Gravity directions (default: the scenario's `[sim] gravity`, `down` for a mesh).
        #[arg(long, value_name = "DIRECTIONS", value_enum)]
        gravity: Option<Gravity>,
        /// Length unit of a bare mesh.
        #[arg(long, value_name = "UNIT", value_enum)]
        units: Option<Units>,
        /// Write the records to this file instead of stdout (written whole, or not at all).
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Hand files (issue 37): `hand show FILE` prints the model grasp-sim derives from a hand's
    /// URDF or MJCF (or from the one a scenario's `[hand]` names, with its mapping) and writes
    /// a figure of it over the file's link geometry.
    Hand {
        /// What to do.
        #[command(subcommand)]
        action: HandCommand,
    },
    /// Write the thesis objects as binary STL (deterministic: the same bytes every time).
    GenAssets {
        /// Output folder.
        #[arg(long, default_value = "assets/objects")]
        out: PathBuf,
        /// Write the hard meshes instead (issue 30: a helical gear, a cage, a studded brick,
        /// square bars, scan-sized meshes, rings too big for the hand; 20k–250k triangles,
        /// 40 MB in all), into `--out` (give one: they are not committed).
        #[arg(long)]
        hard: bool,
    },
}

/// `grasp-sim hand` subcommands.
#[derive(Debug, Subcommand)]
pub enum HandCommand {
    /// Print the derived hand model as a table and write its figure (SVG).
    Show {
        /// A hand's URDF (.urdf) or MJCF (.xml), or a scenario whose `[hand]` names one.
        file: PathBuf,
        /// Where to write the figure (default: `<FILE's stem>.hand.svg` here).
        #[arg(long, value_name = "FILE")]
        svg: Option<PathBuf>,
    },
}

/// `grasp-sim batch` flags.
#[derive(Debug, clap::Args)]
pub struct BatchArgs {
    /// Folders, scenario files (.toml) or meshes (.stl, .obj, .ply, .urdf).
    #[arg(required = true, value_name = "DIR | SCENARIO")]
    pub inputs: Vec<PathBuf>,
    /// Scenario used for bare meshes (default: the thesis hand and defaults).
    #[arg(long, value_name = "SCENARIO")]
    pub template: Option<PathBuf>,
    /// Length unit of bare meshes (overrides the template's).
    #[arg(long, value_name = "UNIT", value_enum)]
    pub units: Option<Units>,
    /// Write the JSON lines to this file instead of stdout (written whole, or not at all;
    /// with --resume, appended as objects finish).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Continue the run in --out FILE: keep the objects it already holds (same input path,
    /// same contents, flags and template; an edited input runs again), run the others,
    /// appending each line as it finishes (a killed run leaves a file this continues), and
    /// end with the file in input order, as one uninterrupted run writes it.
    #[arg(long, requires = "out")]
    pub resume: bool,
    /// With --resume: run again the objects whose line in FILE is an error.
    #[arg(long, requires = "resume")]
    pub retry_errors: bool,
    /// Stop an object still running after this many seconds; its line is an error.
    #[arg(long, value_name = "SECONDS", value_parser = positive_seconds)]
    pub object_timeout: Option<f64>,
    /// Limit each object's worker process to this much memory (address space, MiB); an
    /// object that runs out gets an error line.
    #[arg(long, value_name = "MIB", value_parser = clap::value_parser!(u64).range(16..))]
    pub object_memory: Option<u64>,
    /// Run the objects on threads of this process instead of a worker process each (a little
    /// faster for objects that take milliseconds): a panic is still an error line, but a
    /// crash or memory exhaustion ends the whole batch, and there is no --object-timeout.
    #[arg(long, conflicts_with_all = ["object_timeout", "object_memory"])]
    pub in_process: bool,
    /// Run nothing: put together the lines of these shard files (or folders of *.jsonl) in
    /// input order, checking that every input is there exactly once (give the inputs and the
    /// flags the shards ran with). Repeatable.
    #[arg(long, value_name = "FILE | DIR", conflicts_with_all = ["resume", "in_process"])]
    pub merge: Vec<PathBuf>,
    /// Objects run at once (default: all cores).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Run only the K-th of N contiguous blocks of the inputs (e.g. a Slurm array task).
    #[arg(long, value_name = "K/N", value_parser = grasp_sim::batch::parse_shard)]
    pub shard: Option<grasp_sim::batch::Shard>,
    /// What each object's run computes.
    #[command(flatten)]
    pub flags: RunFlags,
}

/// `grasp-sim label` flags.
#[derive(Debug, clap::Args)]
pub struct LabelArgs {
    /// Folders, scenario files (.toml) or meshes (.stl, .obj, .ply, .urdf).
    #[arg(required = true, value_name = "DIR | SCENARIO")]
    pub inputs: Vec<PathBuf>,
    /// Grasps to label per object (fewer where the planner finds fewer).
    #[arg(long, value_name = "K", default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub grasps: u32,
    /// Perturbed checks per grasp (docs/SIM.md "Hold probability").
    #[arg(long, value_name = "S", default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub samples: u32,
    /// Gravity directions for every input (default: each scenario's `[sim] gravity`, `down`
    /// for a bare mesh).
    #[arg(long, value_name = "DIRECTIONS", value_enum)]
    pub gravity: Option<Gravity>,
    /// Feasible candidates to plan per object at most, to pick from.
    #[arg(long, value_name = "N", default_value_t = grasp_sim::label::object::DEFAULT_CANDIDATES as u32,
          value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub candidates: u32,
    /// Scenario used for bare meshes (default: the thesis hand and defaults).
    #[arg(long, value_name = "SCENARIO")]
    pub template: Option<PathBuf>,
    /// Length unit of bare meshes (overrides the template's).
    #[arg(long, value_name = "UNIT", value_enum)]
    pub units: Option<Units>,
    /// Write the JSON lines to this file instead of stdout (written whole, or not at all;
    /// with --resume, appended as grasps finish).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Continue the run in --out FILE: keep the grasps it already holds (same input, contents,
    /// flags and template), label the others, and end with the file as one uninterrupted run
    /// writes it.
    #[arg(long, requires = "out")]
    pub resume: bool,
    /// With --resume: label again the objects and grasps whose line is an error.
    #[arg(long, requires = "resume")]
    pub retry_errors: bool,
    /// Stop an object still running after this many seconds; its finished grasps are kept
    /// and the object gets an error line.
    #[arg(long, value_name = "SECONDS", value_parser = positive_seconds)]
    pub object_timeout: Option<f64>,
    /// Limit each object's worker process to this much memory (address space, MiB).
    #[arg(long, value_name = "MIB", value_parser = clap::value_parser!(u64).range(16..))]
    pub object_memory: Option<u64>,
    /// Label the objects on threads of this process instead of a worker process each.
    #[arg(long, conflicts_with_all = ["object_timeout", "object_memory"])]
    pub in_process: bool,
    /// Run nothing: put together the lines of these shard files (or folders of *.jsonl) in
    /// input order, checking that every input's grasps are there exactly once. Repeatable.
    #[arg(long, value_name = "FILE | DIR", conflicts_with_all = ["resume", "in_process"])]
    pub merge: Vec<PathBuf>,
    /// Objects labelled at once (default: all cores; each object's checks also spread over
    /// the cores).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Label only the K-th of N contiguous blocks of the inputs (e.g. a Slurm array task).
    #[arg(long, value_name = "K/N", value_parser = grasp_sim::batch::parse_shard)]
    pub shard: Option<grasp_sim::batch::Shard>,
    /// Also write one numpy .npz per object (arrays of the lines' fields) into DIR.
    #[arg(long, value_name = "DIR")]
    pub npz: Option<PathBuf>,
    /// Also write each object's summary (candidates, picks and their spread, times) as one JSON
    /// line per object to FILE.
    #[arg(long, value_name = "FILE")]
    pub summary: Option<PathBuf>,
    /// Write the MJCF scene of a fraction of the labelled grasps into DIR/<object>/<grasp
    /// index>/, for `scripts/compare_engines.py --labels` (MuJoCo's answers beside rapier's).
    #[arg(long, value_name = "DIR")]
    pub export_mjcf: Option<PathBuf>,
    /// With --export-mjcf: the fraction of the grasps exported (the same grasps every run: a
    /// hash of the object and the grasp index decides).
    #[arg(long, value_name = "F", default_value_t = 1.0, requires = "export_mjcf",
          value_parser = fraction)]
    pub mujoco_fraction: f64,
}

fn fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(f) if (0.0..=1.0).contains(&f) => Ok(f),
        _ => Err(format!("`{s}` is not a fraction from 0 to 1")),
    }
}

impl LabelArgs {
    /// The library's request for these flags.
    pub fn request(self) -> grasp_sim::label::command::Request {
        grasp_sim::label::command::Request {
            inputs: self.inputs,
            worker: grasp_sim::label::command::WorkerArgs {
                template: self.template,
                units: self.units.map(Into::into),
                params: grasp_sim::label::LabelParams {
                    grasps: self.grasps as usize,
                    samples: self.samples as usize,
                    candidates: self.candidates as usize,
                },
                gravity: self.gravity.map(Into::into),
                export: self
                    .export_mjcf
                    .map(|dir| grasp_sim::label::object::MjcfExport {
                        dir,
                        fraction: self.mujoco_fraction,
                    }),
            },
            out: self.out,
            resume: self.resume,
            retry_errors: self.retry_errors,
            object_timeout: self.object_timeout,
            object_memory: self.object_memory,
            in_process: self.in_process,
            merge: self.merge,
            jobs: self.jobs,
            shard: self.shard,
            npz: self.npz,
            summary: self.summary,
        }
    }
}

/// The longest time bound accepted `[s]`: a year (a larger one overflowed the timer and
/// panicked, issue 32).
const MAX_SECONDS: f64 = 31_536_000.0;

fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(t) if t > 0.0 && t <= MAX_SECONDS => Ok(t),
        Ok(t) if t > MAX_SECONDS => Err(format!(
            "`{s}` seconds is more than the {MAX_SECONDS} (a year) a time bound may be"
        )),
        _ => Err(format!("`{s}` is not a positive number of seconds")),
    }
}

/// `grasp-sim tune` flags.
#[derive(Debug, clap::Args)]
pub struct TuneArgs {
    /// Folders, scenario files (.toml) or meshes (.stl, .obj, .ply, .urdf).
    #[arg(required_unless_present = "labels", value_name = "DIR | SCENARIO")]
    pub inputs: Vec<PathBuf>,
    /// Tune the order's significance factors (`[planner] sf_centred`, `sf_opposed`,
    /// `sf_spread`, `sf_margin`, `sf_even`) against the candidates of a `grasp-sim label` file instead of
    /// sweeping a grid: no simulation, k-fold cross-validation over objects (docs/USAGE.md
    /// "Tuning the order").
    #[arg(long, value_name = "FILE.jsonl", conflicts_with_all = ["inputs", "params"])]
    pub labels: Option<PathBuf>,
    /// With --labels: what to maximise: `first` (the first candidate's mean hold
    /// probability), `checks` (fewest candidates checked before a hold), `auc` (the score's
    /// AUC against a hold as planned).
    #[arg(long, value_name = "OBJECTIVE", default_value = "first", requires = "labels",
          value_parser = grasp_sim::tune::order::Objective::parse)]
    pub objective: grasp_sim::tune::order::Objective,
    /// With --labels: the order measured and tuned: `search` (the order a run's search checks
    /// the candidates in: the first by the grade, then by their closings, `[sim]
    /// order_by_closing`) or `grade` (the planner's grade alone).
    #[arg(long, value_name = "ORDER", default_value = "search", requires = "labels",
          value_parser = grasp_sim::tune::order::Order::parse)]
    pub order: grasp_sim::tune::order::Order,
    /// With --labels: folds of the cross-validation over objects.
    #[arg(long, value_name = "K", default_value_t = 5, requires = "labels",
          value_parser = clap::value_parser!(u32).range(2..=100))]
    pub folds: u32,
    // Help: NAME=START:END:STEP, repeatable, and the names of tune::TunedParam.
    #[arg(
        long = "param",
        required_unless_present = "labels",
        value_name = "NAME=START:END:STEP",
        value_parser = grasp_sim::tune::parse_sweep,
        help = format!("NAME=START:END:STEP, repeatable ({})", grasp_sim::tune::TunedParam::names())
    )]
    pub params: Vec<grasp_sim::tune::Sweep>,
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Plan up to N grasps per object and keep the best by simulation.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub candidates: usize,
    /// Scenario used for bare meshes (default: the thesis hand and defaults).
    #[arg(long, value_name = "SCENARIO")]
    pub template: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
}

impl TuneArgs {
    /// The library's request for these flags.
    pub fn request(self) -> grasp_sim::tune::command::Request {
        grasp_sim::tune::command::Request {
            inputs: self.inputs,
            sweeps: self.params,
            out: self.out,
            candidates: self.candidates,
            template: self.template,
            jobs: self.jobs,
        }
    }
}

impl BatchArgs {
    /// The library's request for these flags.
    pub fn request(self) -> grasp_sim::batch::command::Request {
        grasp_sim::batch::command::Request {
            inputs: self.inputs,
            worker: grasp_sim::batch::command::WorkerArgs {
                template: self.template,
                units: self.units.map(Into::into),
                flags: self.flags.into(),
            },
            out: self.out,
            resume: self.resume,
            retry_errors: self.retry_errors,
            object_timeout: self.object_timeout,
            object_memory: self.object_memory,
            in_process: self.in_process,
            merge: self.merge,
            jobs: self.jobs,
            shard: self.shard,
        }
    }
}
