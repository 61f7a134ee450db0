//! `grasp-sim tune` as a whole: the grid run over the inputs, tune.csv, tune.json and the score
//! plots written into the output folder, the ranking printed, and the work counted on stderr.

use super::{Sweep, TuneResult};
use crate::batch::{self, plural};
use crate::pipeline::{lock_output_dir, Progress};
use crate::scenario::Scenario;
use anyhow::Context;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// What a tuning run is asked to do (the `tune` flags, typed).
#[derive(Debug, Clone)]
pub struct Request {
    /// Folders, scenario files or meshes.
    pub inputs: Vec<PathBuf>,
    /// The parameters swept.
    pub sweeps: Vec<Sweep>,
    /// The output folder.
    pub out: PathBuf,
    /// Grasps planned per object (the best by simulation is kept).
    pub candidates: usize,
    /// The scenario used for bare meshes (`None`: the built-in template).
    pub template: Option<PathBuf>,
    /// Worker threads (`None`: every core).
    pub jobs: Option<usize>,
}

/// Runs the tuning `request` asks for, showing each object done at one setting to `progress`;
/// returns the exit status (2 when an input was left out, else 0).
///
/// # Errors
/// A bad template or input list, an output that cannot be written, or every setting invalid.
pub fn run(request: &Request, progress: &dyn Progress) -> anyhow::Result<u8> {
    check_sweeps(&request.sweeps)?;
    let template = match &request.template {
        Some(p) => Scenario::load_template(p)?,
        None => batch::default_template(),
    };
    let items = batch::expand(&request.inputs)?;
    // Held to the end of the sweep: a second tune into the same folder is refused.
    let _lock = lock_output_dir(&request.out).context("--out")?;
    let jobs = request
        .jobs
        .unwrap_or_else(batch::command::default_jobs)
        .max(1);
    let t0 = std::time::Instant::now();
    let total = items.len() * super::grid(&request.sweeps).len();
    let done = AtomicUsize::new(0);
    let each = |name: &str| {
        let k = done.fetch_add(1, Ordering::Relaxed) + 1;
        progress.step(k, total, &format!("{name} done at one setting"));
    };
    progress.begin(total);
    let result = super::tune_with_progress(
        &items,
        &template,
        &request.sweeps,
        request.candidates.max(1),
        jobs,
        &each,
    );
    progress.end();
    let result = result?;
    // Inputs that could not be loaded were left out; each is named, and the run exits 2.
    for (path, why) in &result.skipped {
        if why.contains(path.as_str()) {
            eprintln!("grasp-sim: error: {why}");
        } else {
            eprintln!("grasp-sim: error: {path}: {why}");
        }
    }
    let plots = write(&result, &request.out)?;
    print!("{}", super::to_table(&result));
    rank(&result, &request.sweeps)?;
    let c = &result.counters;
    eprintln!(
        "tune: {} x {} in {:.1} s ({}); loaded {}, built {}, ran {} and {} ({} reused); wrote {}",
        plural(result.settings.len(), "setting"),
        plural(items.len(), "object"),
        t0.elapsed().as_secs_f64(),
        plural(jobs, "job"),
        plural(c.objects_loaded, "object"),
        plural(c.domains_built, "domain"),
        plural(c.plans, "plan"),
        plural(c.sim_runs, "physics check"),
        c.sim_reused,
        plots
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(if result.skipped.is_empty() { 0 } else { 2 })
}

/// Checks the sweeps before any work: each parameter swept once, at most
/// [`super::MAX_SETTINGS`] settings in the grid.
///
/// # Errors
/// The parameter given twice, or the grid's size, naming `--param`.
fn check_sweeps(sweeps: &[Sweep]) -> anyhow::Result<()> {
    // One parameter swept twice would make a grid whose two columns set the same value, the
    // second overwriting the first at every setting.
    for (k, sweep) in sweeps.iter().enumerate() {
        if sweeps[..k].iter().any(|s| s.name == sweep.name) {
            anyhow::bail!(
                "--param: `{}` is given twice; sweep each parameter once (NAME=START:END:STEP)",
                sweep.name
            );
        }
    }
    let settings = super::grid_size(sweeps);
    if settings > super::MAX_SETTINGS {
        let sizes: Vec<String> = sweeps.iter().map(|s| s.values.len().to_string()).collect();
        anyhow::bail!(
            "--param: the grid has {settings} settings ({}); at most {} are run, so sweep fewer values",
            sizes.join(" x "),
            super::MAX_SETTINGS
        );
    }
    Ok(())
}

/// Writes tune.csv, tune.json and the score plots into `out`; returns the plots' paths.
fn write(result: &TuneResult, out: &Path) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot create folder", out.display()))?;
    batch::journal::write_atomically(&out.join("tune.csv"), super::to_csv(result).as_bytes())?;
    batch::journal::write_atomically(
        &out.join("tune.json"),
        crate::report::to_rounded_json_pretty(result)?.as_bytes(),
    )?;
    Ok(super::plot(result, out)?)
}

/// Prints the best setting, after saying how many were invalid.
///
/// # Errors
/// Every setting invalid: nothing to rank.
fn rank(result: &TuneResult, sweeps: &[Sweep]) -> anyhow::Result<()> {
    let invalid = result
        .settings
        .iter()
        .filter(|s| s.invalid.is_some())
        .count();
    if invalid == result.settings.len() {
        anyhow::bail!(
            "--param: every setting is invalid, nothing to rank ({})",
            result.settings[0].invalid.as_deref().unwrap_or("")
        );
    }
    if invalid > 0 {
        eprintln!(
            "tune: {} invalid (not run, not ranked; the table says why)",
            plural(invalid, "setting")
        );
    }
    let best = &result.settings[result.best];
    let setting: Vec<String> = sweeps
        .iter()
        .zip(&best.values)
        .map(|(s, v)| format!("{}={v}", s.name))
        .collect();
    println!(
        "best: {} (hold rate {:.3}, mean payload margin {:.2}, mean translation {} mm) over {}",
        setting.join(" "),
        best.hold_rate,
        best.mean_payload_margin,
        best.mean_translation_mm
            .map_or("-".to_string(), |t| format!("{t:.2}")),
        plural(result.counters.objects_loaded, "object")
    );
    Ok(())
}
