//! `grasp-sim batch` as a whole: the inputs expanded and sharded, the results file resumed or
//! merged, the objects run (each in a worker process of its own, or on threads), and the
//! lines written in input order. The command line only parses flags into a [`Request`] and
//! shows progress.

use super::{journal, Counts, Interrupted, Isolation, Item, ItemResult, Key, Record, Worker};
use crate::mesh::LengthUnit;
use crate::pipeline::{check_output_file, Progress};
use crate::scenario::Scenario;
use crate::{RunFlags, RunOptions};
use anyhow::Context;
use std::collections::{HashMap, HashSet};
use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};

/// What a batch is asked to do (the `batch` flags, typed).
#[derive(Debug, Clone, Default)]
pub struct Request {
    /// Folders, scenario files or meshes.
    pub inputs: Vec<PathBuf>,
    /// The settings a worker needs to run an object as the batch would.
    pub worker: WorkerArgs,
    /// The results file (`None`: stdout).
    pub out: Option<PathBuf>,
    /// Continue the run in `out`.
    pub resume: bool,
    /// With `resume`: run the objects whose line is an error again.
    pub retry_errors: bool,
    /// Stop an object still running after this many seconds.
    pub object_timeout: Option<f64>,
    /// Each worker's memory limit (MiB).
    pub object_memory: Option<u64>,
    /// Threads of this process instead of worker processes.
    pub in_process: bool,
    /// Put these shard files (or folders of them) together instead of running.
    pub merge: Vec<PathBuf>,
    /// Objects run at once (`None`: every core).
    pub jobs: Option<usize>,
    /// Only this shard of the inputs.
    pub shard: Option<super::Shard>,
}

/// The settings that decide an object's result, shared by the batch and its workers: the one
/// place that writes them as a worker's arguments.
#[derive(Debug, Clone, Default)]
pub struct WorkerArgs {
    /// The scenario used for bare meshes (`None`: the built-in template).
    pub template: Option<PathBuf>,
    /// The length unit of bare meshes (`None`: the template's).
    pub units: Option<LengthUnit>,
    /// What each run computes.
    pub flags: RunFlags,
}

impl WorkerArgs {
    /// The template for bare meshes: `template` or the built-in one, with `units` applied.
    ///
    /// # Errors
    /// A bad template scenario.
    pub fn template(&self) -> Result<Scenario, crate::scenario::ScenarioError> {
        let mut template = match &self.template {
            Some(p) => Scenario::load_template(p)?,
            None => super::default_template(),
        };
        if let Some(u) = self.units {
            template.object.units = u;
        }
        Ok(template)
    }

    /// The arguments of the hidden `batch-worker` command that give these settings.
    pub fn to_args(&self) -> Vec<OsString> {
        let mut args: Vec<OsString> = vec!["batch-worker".into()];
        if let Some(t) = &self.template {
            args.push("--template".into());
            args.push(t.into());
        }
        if let Some(u) = self.units {
            args.push("--units".into());
            args.push(u.name().into());
        }
        for (on, flag) in [
            (self.flags.no_sim, "--no-sim"),
            (self.flags.payload, "--payload"),
            (self.flags.quality, "--quality"),
        ] {
            if on {
                args.push(flag.into());
            }
        }
        args
    }
}

/// Runs a batch as `request` says, showing each finished object to `progress` (the message
/// `INPUT: feasible hold`, `INPUT: error`, ...); returns the exit status (2 an input could not
/// be run, else 1 an expectation not met, else 0).
///
/// # Errors
/// Bad flags, a template or results file that cannot be read, an output that cannot be written.
pub fn run(request: &Request, progress: &dyn Progress) -> anyhow::Result<u8> {
    if request.worker.flags.no_sim && request.worker.flags.payload {
        eprintln!(
            "grasp-sim: warning: --payload is ignored with --no-sim (the payload search is part of the physics check)"
        );
    }
    let options = RunOptions::from(request.worker.flags);
    let template = request.worker.template()?;
    if let Some(path) = &request.out {
        check_output_file(path).context("--out")?;
    }
    let mut items = super::expand(&request.inputs)?;
    if let Some(shard) = request.shard {
        items = shard.of(&items);
    }
    let keys = super::keys(&items, &template, &options);
    // One run per results file, plain or resumed (a merge writes it too).
    let _lock = match &request.out {
        Some(path) => Some(journal::RunLock::take(path)?),
        None => None,
    };
    if !request.merge.is_empty() {
        return merge(request, &keys);
    }
    let (journal, kept) = resumed(request)?;
    let mut batch = Batch {
        in_file: kept.keys().cloned().collect(),
        kept,
        interrupted: 0,
    };
    let todo: Vec<usize> = (0..items.len())
        .filter(|&i| !batch.kept.contains_key(&keys[i]))
        .collect();
    if let Some(path) = request.out.as_ref().filter(|_| request.resume) {
        eprintln!(
            "resume: {} of {} already in {}; running {}",
            items.len() - todo.len(),
            super::plural(items.len(), "object"),
            path.display(),
            todo.len()
        );
    }
    let run_items: Vec<Item> = todo.iter().map(|&i| items[i].clone()).collect();
    let run_keys: Vec<Key> = todo.iter().map(|&i| keys[i].clone()).collect();
    let jobs = request.jobs.unwrap_or_else(default_jobs).max(1);
    let isolation = match request.in_process {
        true => Isolation::InProcess,
        false => Isolation::Process(worker(request, (jobs / run_items.len().max(1)).max(1))?),
    };
    let t0 = std::time::Instant::now();
    let results = run_journalled(
        &run_items,
        &run_keys,
        (&template, &options, jobs, &isolation),
        journal.as_ref(),
        progress,
    )?;
    batch.take(&run_keys, results);
    let counts = batch.write(request, &keys, journal)?;
    eprintln!(
        "{}{}",
        super::summary(&counts, run_items.len(), t0.elapsed().as_secs_f64(), jobs),
        if batch.interrupted > 0 {
            format!(
                "; {} interrupted (no line; --resume runs them again)",
                batch.interrupted
            )
        } else {
            String::new()
        }
    );
    Ok(exit_status(&counts, batch.interrupted))
}

/// Every core this process may use.
pub fn default_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// With `--resume`: the results file opened for appending, and the lines it already holds for
/// these inputs, as they are now (without the errors, with `--retry-errors`).
fn resumed(request: &Request) -> anyhow::Result<(Option<journal::Journal>, HashMap<Key, Record>)> {
    let (Some(path), true) = (&request.out, request.resume) else {
        return Ok(Default::default());
    };
    let (j, read) = journal::Journal::open(path)?;
    if read.partial_bytes > 0 {
        eprintln!(
            "grasp-sim: warning: {}: cut off a partial last line ({} bytes) an interrupted run left",
            path.display(),
            read.partial_bytes
        );
    }
    let mut kept: HashMap<Key, Record> = read
        .records
        .into_iter()
        .map(|(_, r)| (r.key.clone(), r))
        .collect();
    if request.retry_errors {
        kept.retain(|_, r| r.error().is_none());
    }
    Ok((Some(j), kept))
}

/// Runs the objects, appending each line to the journal as it finishes and showing it.
fn run_journalled(
    items: &[Item],
    keys: &[Key],
    (template, options, jobs, isolation): (&Scenario, &RunOptions, usize, &Isolation),
    journal: Option<&journal::Journal>,
    progress: &dyn Progress,
) -> anyhow::Result<Vec<ItemResult>> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    let append_error = std::sync::Mutex::new(None);
    let total = items.len();
    let each = |item: &Item, r: &ItemResult| {
        if let (Some(j), Ok(rec)) = (journal, r) {
            if let Err(e) = j.append(rec) {
                append_error
                    .lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .get_or_insert(e);
            }
        }
        let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        let message = format!("{}: {}", item.path().display(), outcome_word(r));
        progress.step(k, total, &message);
    };
    progress.begin(total);
    let results = super::run_all(items, keys, template, options, jobs, isolation, &each);
    progress.end();
    match append_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        Some(e) => Err(e.into()),
        None => Ok(results),
    }
}

/// What became of an object, in a word or two: `feasible hold`, `error`, `interrupted`.
fn outcome_word(r: &ItemResult) -> String {
    match r {
        Ok(rec) => match rec.error() {
            Some(_) => "error".to_string(),
            None => format!(
                "{} {}{}",
                rec.view.plan.status.as_deref().unwrap_or("?"),
                rec.view.sim.verdict.as_deref().unwrap_or("?"),
                // With `[sim] samples` (issue 34): the hold probability and its lower bound.
                match (
                    rec.view.sim.robust.hold_probability,
                    rec.view.sim.robust.lower_bound()
                ) {
                    (Some(p), Some(lo)) => format!(" (hold probability {p:.2}, >= {lo:.2})"),
                    _ => String::new(),
                }
            ),
        },
        Err(_) => "interrupted".to_string(),
    }
}

/// The lines of a batch: those kept from the results file and those run now.
struct Batch {
    kept: HashMap<Key, Record>,
    /// The keys the results file held when the run began.
    in_file: Vec<Key>,
    interrupted: usize,
}

impl Batch {
    /// The results of this run: each error said, each line kept, each interruption counted.
    fn take(&mut self, keys: &[Key], results: Vec<ItemResult>) {
        for (key, r) in keys.iter().zip(results) {
            match r {
                Ok(rec) => {
                    if let Some(e) = rec.error() {
                        eprintln!("grasp-sim: error: {e}");
                    }
                    self.kept.insert(key.clone(), rec);
                }
                Err(Interrupted(why)) => {
                    self.interrupted += 1;
                    eprintln!("grasp-sim: error: {why}");
                }
            }
        }
    }

    /// Writes every line in input order (a line for an input no longer given, or since edited,
    /// goes) and counts them.
    fn write(
        &self,
        request: &Request,
        keys: &[Key],
        journal: Option<journal::Journal>,
    ) -> anyhow::Result<Counts> {
        let mut text = String::new();
        let mut lines = Vec::with_capacity(keys.len());
        for key in keys {
            if let Some(rec) = self.kept.get(key) {
                text.push_str(&rec.line);
                text.push('\n');
                lines.push(rec);
            }
        }
        let current: HashSet<&Key> = keys.iter().collect();
        let dropped = self.in_file.iter().filter(|k| !current.contains(k)).count();
        match (&request.out, journal) {
            (Some(path), Some(j)) => {
                if dropped > 0 {
                    eprintln!(
                        "grasp-sim: warning: {}: dropped {} for no current input (an input edited or removed, or other flags or template)",
                        path.display(),
                        super::plural(dropped, "line")
                    );
                }
                j.finish(text.as_bytes())?;
            }
            (Some(path), None) => journal::write_atomically(path, text.as_bytes())?,
            _ => std::io::stdout().lock().write_all(text.as_bytes())?,
        }
        Ok(Counts::of_records(lines))
    }
}

/// 2 if an input could not be run, else 1 if an expectation was not met, else 0.
fn exit_status(counts: &Counts, interrupted: usize) -> u8 {
    if counts.errors > 0 || interrupted > 0 {
        2
    } else if counts.not_met > 0 {
        1
    } else {
        0
    }
}

/// The worker for each object: this binary's hidden `batch-worker`, with the settings that
/// decide an object's result; each worker may use `threads` threads.
fn worker(request: &Request, threads: usize) -> anyhow::Result<Worker> {
    let program = std::env::current_exe()
        .context("cannot find this program to start a worker per object (try --in-process)")?;
    Ok(Worker {
        program,
        args: request.worker.to_args(),
        timeout: request
            .object_timeout
            .map(std::time::Duration::from_secs_f64),
        memory_limit_mib: request.object_memory,
        threads,
    })
}

/// `batch --merge`: the shard files' lines for these inputs, in input order, checked.
fn merge(request: &Request, keys: &[Key]) -> anyhow::Result<u8> {
    let files = shard_files(&request.merge)?;
    let mut records = Vec::new();
    for f in &files {
        let read = journal::read_records(f)?;
        if read.partial_bytes > 0 {
            eprintln!(
                "grasp-sim: warning: {}: ignoring a partial last line (its shard was interrupted)",
                f.display()
            );
        }
        records.extend(
            read.records
                .into_iter()
                .map(|(line, r)| (format!("{}:{line}", f.display()), r)),
        );
        if records.len() > journal::MAX_RECORDS {
            anyhow::bail!(
                "{}: more than the {} records a batch file may hold, with the shard files before it",
                f.display(),
                journal::MAX_RECORDS
            );
        }
    }
    let merged = super::merge(keys, records)?;
    let mut text = String::new();
    for r in &merged {
        text.push_str(&r.line);
        text.push('\n');
    }
    match &request.out {
        Some(path) => journal::write_atomically(path, text.as_bytes())?,
        None => std::io::stdout().lock().write_all(text.as_bytes())?,
    }
    let counts = Counts::of_records(&merged);
    eprintln!(
        "merge: {} from {}, every input exactly once: {} planned, {} ungraspable; physics: {} hold, {} slip, {} drop; expectations: {} met, {} not met, {} not judged; {}",
        super::plural(merged.len(), "object"),
        super::plural(files.len(), "file"),
        counts.feasible,
        counts.ungraspable,
        counts.hold,
        counts.slip,
        counts.drop,
        counts.met,
        counts.not_met,
        counts.unjudged,
        super::plural(counts.errors, "error")
    );
    Ok(exit_status(&counts, 0))
}

/// The files `--merge` names: each file given, and the `*.jsonl` of each folder, sorted (for
/// `batch` and `label`).
///
/// # Errors
/// A folder that cannot be read.
pub(crate) fn shard_files(given: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for m in given {
        if m.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(m)
                .with_context(|| format!("{}: cannot read folder", m.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "jsonl"))
                .collect();
            found.sort();
            files.extend(found);
        } else {
            files.push(m.clone());
        }
    }
    Ok(files)
}

/// `batch-worker`: one object with the batch's settings, its line on stdout.
///
/// # Errors
/// A bad template, an input that is neither a scenario nor a mesh, or stdout gone.
pub fn run_worker(path: &Path, input_hash: &str, args: &WorkerArgs) -> anyhow::Result<u8> {
    let template = args.template()?;
    let item = super::classify(path.to_path_buf()).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: neither a scenario (.toml) nor a mesh (.stl, .obj, .ply, .urdf)",
            path.display()
        )
    })?;
    let key = Key {
        input: path.display().to_string(),
        input_hash: input_hash.to_string(),
    };
    let record = super::run_one(&item, &key, &template, &RunOptions::from(args.flags));
    let mut out = std::io::stdout().lock();
    writeln!(out, "{}", record.line)?;
    out.flush()?;
    Ok(0)
}
