//! The main command: the inputs on the command line run one after the other, each on its own,
//! with its summary (or JSON line) on stdout and its warnings and errors on stderr.
//!
//! A bad input is reported and the others still run and print; the exit status is the worst
//! (2 bad input, 1 an expectation not met, 0).

use super::input::{self, Item};
use super::{run, RunOptions};
use crate::mesh::LengthUnit;
use crate::scenario::{GravityMode, Scenario};
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

/// What the command line asks of every input.
#[derive(Debug, Clone)]
pub struct CommandLine {
    /// What each run computes and writes.
    pub options: RunOptions,
    /// The length unit of bare meshes.
    pub units: LengthUnit,
    /// Gravity directions for every input (`None`: each scenario's own).
    pub gravity: Option<GravityMode>,
    /// Perturbed checks for every input (`None`: each scenario's `[sim] samples`).
    pub samples: Option<usize>,
    /// JSON Lines instead of the summary.
    pub json: bool,
    /// The longest one input may run (`None`: no bound).
    pub time_limit: Option<std::time::Duration>,
}

/// The default time bound per input: far above what any input the planner's budget admits
/// takes (tens of seconds for a 250k-triangle scan with the physics check), a backstop against
/// an input that would run for ever.
pub const DEFAULT_TIME_LIMIT_S: f64 = 600.0;

/// Why an input has no report.
#[derive(Debug)]
enum Failure {
    /// Bad input.
    Error(super::Error),
    /// A panic inside the run (a bug): the input's line says so and the others still run.
    Panicked(String),
    /// No result within the time bound.
    TimedOut(std::time::Duration),
}

/// Starts a progress display for one scenario's run and returns what ends it (or nothing).
pub type Spinner<'a> = &'a dyn Fn(&Scenario, &RunOptions) -> Option<Box<dyn FnOnce()>>;

/// Runs every input in `paths` in turn, printing each report to `out`; returns the exit status.
///
/// # Errors
/// Only a failure to write to `out`: a bad input is reported on stderr and counted in the status.
pub fn run_inputs(
    paths: &[std::path::PathBuf],
    cl: &CommandLine,
    out: &mut dyn Write,
    spinner: Spinner,
) -> anyhow::Result<u8> {
    if cl.options.no_sim && cl.options.payload {
        eprintln!(
            "grasp-sim: warning: --payload is ignored with --no-sim (the payload search is part of the physics check)"
        );
    }
    let mut template = input::default_template();
    template.object.units = cl.units;
    let mut status = 0u8;
    let mut names = Names::default();
    for path in paths {
        let item = match crate::mesh::MeshFormat::from_path(path) {
            Some(_) => Item::Mesh(path.clone()),
            None => Item::Scenario(path.clone()),
        };
        if cl.units != LengthUnit::Mm && matches!(item, Item::Scenario(_)) {
            eprintln!(
                "grasp-sim: warning: {}: --units {} applies to bare meshes; a scenario gives its unit in `[object] units` (millimetres if it says none)",
                path.display(),
                cl.units.name()
            );
        }
        let ran = input::scenario_for(&item, &template).map(|mut s| {
            if let Some(g) = cl.gravity {
                s.sim.gravity = g;
            }
            if let Some(n) = cl.samples {
                s.sim.robust.samples = n;
            }
            let options = names.options_for(&s, path, &cl.options);
            let finish = spinner(&s, &options);
            let r = run_bounded(s, options, cl.time_limit);
            if let Some(finish) = finish {
                finish();
            }
            r
        });
        let ran = ran.map_err(Failure::Error).and_then(|r| r);
        match ran {
            Ok((report, folder)) => {
                print_report(&report, folder.as_deref(), cl, out)?;
                if report.expect.met == Some(false) {
                    status = status.max(1);
                }
            }
            Err(Failure::Error(e)) => {
                eprintln!("grasp-sim: error: {}", error_line(&item, path, &e));
                status = 2;
            }
            Err(Failure::Panicked(why)) => {
                eprintln!("grasp-sim: error: {}: panicked: {why}", path.display());
                status = 2;
            }
            Err(Failure::TimedOut(limit)) => {
                eprintln!(
                    "grasp-sim: error: {}: no result within {} s, the time bound per input (--time-limit)",
                    path.display(),
                    limit.as_secs_f64()
                );
                status = 2;
            }
        }
    }
    Ok(status)
}

/// Runs one scenario on a thread of its own, waiting at most `limit`: a panic becomes the
/// input's error, and a run past the bound is left behind (it ends with the process) while the
/// next input runs. The thread has a large stack, for deeply nested input files.
fn run_bounded(
    scenario: Scenario,
    options: RunOptions,
    limit: Option<std::time::Duration>,
) -> Result<(crate::report::RunReport, Option<String>), Failure> {
    let (send, receive) = std::sync::mpsc::channel();
    let worker = std::thread::Builder::new()
        .name(format!("input {}", scenario.name.replace('\0', "\\0")))
        .stack_size(256 << 20)
        .spawn(move || {
            let r = run(&scenario, &options).map(|r| (r, options.folder));
            let _ = send.send(r);
        });
    let worker = match worker {
        Ok(w) => w,
        Err(e) => return Err(Failure::Panicked(format!("cannot start a thread: {e}"))),
    };
    let received = match limit {
        Some(limit) => receive.recv_timeout(limit).map_err(|e| match e {
            std::sync::mpsc::RecvTimeoutError::Timeout => Some(limit),
            std::sync::mpsc::RecvTimeoutError::Disconnected => None,
        }),
        None => receive.recv().map_err(|_| None),
    };
    match received {
        Ok(r) => {
            let _ = worker.join();
            r.map_err(Failure::Error)
        }
        Err(Some(limit)) => Err(Failure::TimedOut(limit)),
        // The sender went away without a result: the run panicked.
        Err(None) => Err(Failure::Panicked(match worker.join() {
            Err(payload) => panic_message(payload.as_ref()),
            Ok(()) => "(no result)".to_string(),
        })),
    }
}

/// A panic's message, where it has one.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".to_string())
}

/// The names seen so far: two inputs of one name (every file of a YCB-style set is
/// `textured.obj`) would write one output folder, so the later ones get `NAME-2`, `NAME-3`, ...
/// and are told.
#[derive(Default)]
struct Names(HashMap<String, usize>);

impl Names {
    fn options_for(&mut self, s: &Scenario, path: &Path, options: &RunOptions) -> RunOptions {
        let mut options = options.clone();
        let count = self.0.entry(s.name.clone()).or_insert(0);
        *count += 1;
        if *count > 1 && options.writes_folders() {
            let folder = format!("{}-{count}", s.name);
            eprintln!(
                "grasp-sim: warning: {}: an earlier input has the name `{}`; its output folders are `{folder}`",
                path.display(),
                s.name
            );
            options.folder = Some(folder);
        }
        options
    }
}

/// The one line for an input that could not run. A scenario's mesh or hand file that cannot be
/// read names that file; the line names the scenario that asked for it too. (The Python
/// package words its errors with it as well.)
pub fn error_line(item: &Item, path: &Path, e: &super::Error) -> String {
    let msg = format!("{e:#}").replace('\n', " ");
    let scenario = path.display().to_string();
    // A file that is neither a `.toml` scenario nor a mesh by its extension (a `.dae`, a
    // `.txt`) was read as a scenario: say what is read.
    let hint = match item {
        Item::Scenario(_)
            if !path.is_dir()
                && !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) =>
        {
            " (read as a scenario: grasp-sim reads scenarios from .toml files and meshes from .stl, .obj, .ply and .urdf)"
        }
        _ => "",
    };
    match item {
        Item::Scenario(_) if !msg.starts_with(&scenario) => format!("{scenario}: {msg}{hint}"),
        _ => format!("{msg}{hint}"),
    }
}

/// The report's warnings and written files on stderr, and the report itself on `out`.
fn print_report(
    report: &crate::report::RunReport,
    folder: Option<&str>,
    cl: &CommandLine,
    out: &mut dyn Write,
) -> anyhow::Result<()> {
    for w in &report.warnings {
        eprintln!("grasp-sim: warning: {w}");
    }
    let folder = folder.unwrap_or(&report.scenario);
    if let Some(dir) = &cl.options.report {
        eprintln!(
            "grasp-sim: report written to {}",
            dir.join(folder).join("report.html").display()
        );
    }
    if cl.options.export_mjcf.is_some() {
        match &report.mjcf_scene {
            Some(scene) => eprintln!("grasp-sim: MJCF scene written to {}", scene.display()),
            None => eprintln!(
                "grasp-sim: warning: {}: no MJCF scene written: {}",
                report.scenario,
                report
                    .plan
                    .reason
                    .as_deref()
                    .unwrap_or("no grasp to export")
            ),
        }
    }
    if cl.json {
        writeln!(out, "{}", crate::report::to_rounded_json(report)?)?;
    } else {
        write!(out, "{}", report.summary())?;
    }
    out.flush()?;
    Ok(())
}
