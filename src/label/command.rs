//! `grasp-sim label` over many objects, as `batch` runs them (the inputs expanded and sharded,
//! each object in a worker process of its own or on threads, `--out FILE --resume`, `--merge`),
//! but one JSON line per labelled grasp; and `grasp-sim check --grasps`.
//!
//! Each line carries `label` = {`input`, `input_hash`, `grasps`, `wall_ms`}: the input as the
//! command saw it, the hash of what decides its lines (the input and its mesh, the template,
//! the label flags, the version), and how many grasps its object's run labels. With `--resume`
//! lines are appended as each grasp's checks finish; a run that is killed loses no finished
//! grasp: the next run plans the object again (the same picks), labels only the grasps not in
//! the file, and writes the file in input order, each object's lines by grasp index.

use super::object::{error_line, LabelParams, Line, ObjectSummary};
use super::LabelInfo;
use crate::batch::{self, journal, Item, Key, Shard, Worker};
use crate::mesh::LengthUnit;
use crate::pipeline::{check_output_dir, check_output_file, Progress};
use crate::scenario::{GravityMode, Scenario};
use anyhow::Context;
use rayon::prelude::*;
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The settings that decide an object's lines, shared by the command and its workers.
#[derive(Debug, Clone)]
pub struct WorkerArgs {
    /// The scenario used for bare meshes (`None`: the built-in template).
    pub template: Option<PathBuf>,
    /// The length unit of bare meshes (`None`: the template's).
    pub units: Option<LengthUnit>,
    /// Grasps, samples and candidates per object.
    pub params: LabelParams,
    /// The gravity directions for every input (`None`: each scenario's own).
    pub gravity: Option<GravityMode>,
    /// The MJCF scenes of a fraction of the grasps (`--export-mjcf`, `--mujoco-fraction`).
    pub export: Option<super::object::MjcfExport>,
}

impl WorkerArgs {
    /// The template for bare meshes, with `units` applied.
    ///
    /// # Errors
    /// A bad template scenario.
    pub fn template(&self) -> Result<Scenario, crate::scenario::ScenarioError> {
        let mut template = match &self.template {
            Some(p) => Scenario::load_template(p)?,
            None => batch::default_template(),
        };
        if let Some(u) = self.units {
            template.object.units = u;
        }
        Ok(template)
    }

    /// The scenario of `item`, with the gravity asked for.
    fn scenario(
        &self,
        item: &Item,
        template: &Scenario,
    ) -> Result<Scenario, crate::pipeline::Error> {
        let mut s = batch::scenario_for(item, template)?;
        if let Some(g) = self.gravity {
            s.sim.gravity = g;
        }
        Ok(s)
    }

    /// The hidden `label-worker` command's arguments that give these settings.
    fn to_args(&self) -> Vec<OsString> {
        let mut args: Vec<OsString> = vec!["label-worker".into()];
        if let Some(t) = &self.template {
            args.push("--template".into());
            args.push(t.into());
        }
        if let Some(u) = self.units {
            args.push("--units".into());
            args.push(u.name().into());
        }
        if let Some(g) = self.gravity {
            args.push("--gravity".into());
            args.push(g.as_str().into());
        }
        if let Some(e) = &self.export {
            args.push("--export-mjcf".into());
            args.push(e.dir.clone().into());
            args.push("--mujoco-fraction".into());
            args.push(e.fraction.to_string().into());
        }
        for (flag, n) in [
            ("--grasps", self.params.grasps),
            ("--samples", self.params.samples),
            ("--candidates", self.params.candidates),
        ] {
            args.push(flag.into());
            args.push(n.to_string().into());
        }
        args
    }

    /// The hash of everything that decides `item`'s lines: `batch`'s input hash of it (its
    /// files, its scenario, the template, the version) and these settings.
    fn input_hash(&self, item: &Item, template: &Scenario) -> String {
        let base = batch::input_hash(item, template, &crate::RunOptions::default());
        let mut h = Sha256::new();
        h.update(base.as_bytes());
        h.update(b"label");
        for n in [
            self.params.grasps,
            self.params.samples,
            self.params.candidates,
        ] {
            h.update((n as u64).to_le_bytes());
        }
        h.update(self.gravity.map_or("scenario", |g| g.as_str()).as_bytes());
        let mut hex = String::from("sha256:");
        for b in h.finalize() {
            hex.push_str(&format!("{b:02x}"));
        }
        hex
    }
}

/// What `label` is asked to do (its flags, typed).
#[derive(Debug, Clone)]
pub struct Request {
    /// Folders, scenario files or meshes.
    pub inputs: Vec<PathBuf>,
    /// What decides each object's lines.
    pub worker: WorkerArgs,
    /// The results file (`None`: stdout).
    pub out: Option<PathBuf>,
    /// Continue the run in `out`.
    pub resume: bool,
    /// With `resume`: run again the objects with an error line.
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
    pub shard: Option<Shard>,
    /// Also write one `.npz` per object into this folder.
    pub npz: Option<PathBuf>,
    /// Also write each object's summary (one JSON line per object) to this file.
    pub summary: Option<PathBuf>,
}

/// One line read back: the key it belongs to, its grasp index, whether it is an error, the
/// object's grasp count, and its text.
#[derive(Debug, Clone)]
struct ReadLine {
    key: Key,
    grasp_index: Option<usize>,
    is_error: bool,
    grasps: usize,
    text: String,
}

/// Reads a line written by `label`.
fn read_line(text: &str) -> Result<ReadLine, String> {
    let v = crate::files::parse_json_line(text)?;
    let info: LabelInfo = serde_json::from_value(v["label"].clone()).map_err(|_| {
        "no `label` with `input`, `input_hash`, `grasps` (not a line written by `label`)"
            .to_string()
    })?;
    Ok(ReadLine {
        key: Key {
            input: info.input,
            input_hash: info.input_hash,
        },
        grasp_index: v["grasp_index"].as_u64().map(|i| i as usize),
        is_error: v.get("error").is_some(),
        grasps: info.grasps,
        text: text.to_string(),
    })
}

/// The lines of a label file: each complete line read (a partial last line left out).
///
/// # Errors
/// The file cannot be read, or a complete line is not a label line.
fn read_lines(path: &Path) -> anyhow::Result<(Vec<ReadLine>, usize)> {
    let bytes = crate::files::read_regular(path, crate::files::MAX_RESULTS_BYTES)
        .with_context(|| format!("{}", path.display()))?;
    let complete = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let mut out = Vec::new();
    for (i, line) in bytes[..complete].split(|&b| b == b'\n').enumerate() {
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let text = std::str::from_utf8(line)
            .map_err(|_| anyhow::anyhow!("{}: line {} is not UTF-8", path.display(), i + 1))?;
        if out.len() == MAX_GIVEN_LINES {
            anyhow::bail!(
                "{}: line {} is past the {MAX_GIVEN_LINES} lines a label file may hold here",
                path.display(),
                i + 1
            );
        }
        let r = read_line(text.trim_end_matches('\r')).map_err(|why| {
            anyhow::anyhow!(
                "{}: line {} is not a label line: {why}",
                path.display(),
                i + 1
            )
        })?;
        out.push(r);
    }
    Ok((out, bytes.len() - complete))
}

/// What the file already holds of an object.
#[derive(Debug, Default, Clone)]
struct Held {
    /// Its lines by grasp index (`None`: an object-level line).
    lines: BTreeMap<Option<usize>, ReadLine>,
}

impl Held {
    /// True if and only if the object needs no more work: an object-level line that is not an
    /// error (ungraspable), or every grasp its run labels.
    fn is_complete(&self) -> bool {
        if let Some(l) = self.lines.get(&None) {
            return !l.is_error;
        }
        let grasps = self.lines.values().map(|l| l.grasps).max().unwrap_or(0);
        grasps > 0 && self.lines.keys().filter(|k| k.is_some()).count() >= grasps
    }

    /// The grasp indices already labelled (error lines too, unless they are to be retried).
    fn done(&self) -> BTreeSet<usize> {
        self.lines.keys().flatten().copied().collect()
    }
}

/// Runs `label` as `request` says; returns the exit status (2 if an object or a grasp could
/// not be labelled, else 0).
///
/// # Errors
/// Bad flags, a template or results file that cannot be read, an output that cannot be written.
pub fn run(request: &Request, progress: &dyn Progress) -> anyhow::Result<u8> {
    let template = request.worker.template()?;
    check_outputs(request)?;
    let _folders = lock_output_folders(request)?;
    let mut items = batch::expand(&request.inputs)?;
    if let Some(shard) = request.shard {
        items = shard.of(&items);
    }
    let keys = keys_of(request, &items, &template);
    let _lock = match &request.out {
        Some(path) => Some(journal::RunLock::take(path)?),
        None => None,
    };
    if !request.merge.is_empty() {
        return merge(request, &keys);
    }
    // What the file holds, by key; and the journal to append to.
    let (mut held, journal) = resumed(request)?;
    let todo: Vec<usize> = (0..items.len())
        .filter(|&i| !held.get(&keys[i]).is_some_and(Held::is_complete))
        .collect();
    report_resume(request, items.len(), todo.len());
    let jobs = request
        .jobs
        .unwrap_or_else(batch::command::default_jobs)
        .max(1);
    let worker = (!request.in_process)
        .then(|| worker(request, (jobs / todo.len().max(1)).max(1)))
        .transpose()?;
    let keeper = Keeper::new(journal.as_ref());
    let summaries: Mutex<Vec<(usize, ObjectSummary)>> = Mutex::new(Vec::new());
    let done = std::sync::atomic::AtomicUsize::new(0);
    progress.begin(todo.len());
    let t0 = std::time::Instant::now();
    let work = || {
        todo.par_iter().for_each(|&i| {
            let item = &items[i];
            let key = &keys[i];
            let skip = held.get(key).map(Held::done).unwrap_or_default();
            let keep = |line: Line| keeper.keep(line);
            let summary = match &worker {
                None => run_in_process(item, key, &template, &request.worker, &skip, &keep),
                Some(w) => run_isolated(item, key, w, &skip, &keep),
            };
            let message = match &summary {
                Some(s) => s.line(),
                None => format!("{}: error", item.path().display()),
            };
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress.step(k, todo.len(), &message);
            if let Some(s) = summary {
                summaries
                    .lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .push((i, s));
            }
        })
    };
    match rayon::ThreadPoolBuilder::new().num_threads(jobs).build() {
        Ok(pool) => pool.install(work),
        Err(_) => work(),
    }
    progress.end();
    hold_lines(&mut held, keeper.into_lines()?);
    let mut summaries = summaries.into_inner().unwrap_or_else(|p| p.into_inner());
    summaries.sort_by_key(|(i, _)| *i);
    let (errors, grasps) = write_all(request, &keys, &held, journal, &summaries)?;
    if let Some(dir) = &request.npz {
        write_npz(dir, &keys, &held, &template, &request.worker, &items)?;
    }
    let seconds = t0.elapsed().as_secs_f64();
    report_totals(grasps, items.len(), &summaries, errors, seconds, jobs);
    Ok(if errors > 0 { 2 } else { 0 })
}

/// Adds `lines` to what `held` holds of their objects, each in place of a line of the same
/// object and grasp index.
fn hold_lines(held: &mut HashMap<Key, Held>, lines: Vec<ReadLine>) {
    for l in lines {
        held.entry(l.key.clone())
            .or_default()
            .lines
            .insert(l.grasp_index, l);
    }
}

/// Locks the output folders of this run (`--npz`, `--export-mjcf`): a second run into one is
/// refused (issue 56). The locks hold while the returned guards live.
///
/// # Errors
/// A folder that cannot be written or is locked by another run.
fn lock_output_folders(request: &Request) -> anyhow::Result<Vec<crate::files::FolderLock>> {
    let export = request.worker.export.as_ref().map(|e| e.dir.clone());
    [&request.npz, &export]
        .into_iter()
        .flatten()
        .map(|d| crate::pipeline::lock_output_dir(d))
        .collect()
}

/// Each item's key: its input as given and the hash of what decides its lines.
fn keys_of(request: &Request, items: &[Item], template: &Scenario) -> Vec<Key> {
    items
        .par_iter()
        .map(|item| Key {
            input: item.path().display().to_string(),
            input_hash: request.worker.input_hash(item, template),
        })
        .collect()
}

/// With `--out FILE --resume`, says how many of the `objects` the file already completes and
/// how many (`todo`) are labelled now.
fn report_resume(request: &Request, objects: usize, todo: usize) {
    if let Some(path) = request.out.as_ref().filter(|_| request.resume) {
        eprintln!(
            "resume: {} of {} complete in {}; labelling {}",
            objects - todo,
            batch::plural(objects, "object"),
            path.display(),
            todo
        );
    }
}

/// The run's last line: the grasps labelled over the `objects`, this run's share, the errors,
/// and the perturbed checks' rate over `seconds` on `jobs` jobs.
fn report_totals(
    grasps: usize,
    objects: usize,
    summaries: &[(usize, ObjectSummary)],
    errors: usize,
    seconds: f64,
    jobs: usize,
) {
    let samples: usize = summaries.iter().map(|(_, s)| s.samples_checked).sum();
    eprintln!(
        "label: {} labelled in {} ({} this run) with {} errors; {} perturbed checks in {seconds:.1} s ({:.2} a second) on {jobs} jobs",
        batch::plural(grasps, "grasp"),
        batch::plural(objects, "object"),
        summaries.iter().map(|(_, s)| s.labelled).sum::<usize>(),
        errors,
        samples,
        samples as f64 / seconds.max(1e-9),
    );
}

/// Writes `text` to `out` atomically, or to standard output without one.
///
/// # Errors
/// A write that failed.
fn write_text(out: Option<&Path>, text: &str) -> anyhow::Result<()> {
    match out {
        Some(path) => journal::write_atomically(path, text.as_bytes())?,
        None => std::io::stdout().lock().write_all(text.as_bytes())?,
    }
    Ok(())
}

/// Checks that every output `request` names can be written, before any work.
///
/// # Errors
/// The first that cannot, named by its flag.
fn check_outputs(request: &Request) -> anyhow::Result<()> {
    for (flag, file) in [("--out", &request.out), ("--summary", &request.summary)] {
        if let Some(path) = file {
            check_output_file(path).context(flag)?;
        }
    }
    let export = request.worker.export.as_ref().map(|e| e.dir.clone());
    for (flag, dir) in [("--npz", &request.npz), ("--export-mjcf", &export)] {
        if let Some(d) = dir {
            check_output_dir(d).context(flag)?;
        }
    }
    Ok(())
}

/// Where the objects' lines go as they finish: appended to the journal (with `--resume`) and
/// kept for the file written at the end; the first append that failed.
struct Keeper<'a> {
    journal: Option<&'a journal::Journal>,
    lines: Mutex<Vec<ReadLine>>,
    error: Mutex<Option<anyhow::Error>>,
}

impl<'a> Keeper<'a> {
    /// A keeper appending to `journal`, when given, with no line kept yet.
    fn new(journal: Option<&'a journal::Journal>) -> Keeper<'a> {
        Keeper {
            journal,
            lines: Mutex::new(Vec::new()),
            error: Mutex::new(None),
        }
    }

    /// Keeps `line` (a line that is not a label line is dropped).
    fn keep(&self, line: Line) {
        let Ok(r) = read_line(&line.text) else {
            return;
        };
        if let Some(Err(e)) = self.journal.map(|j| j.append_line(&line.text)) {
            self.error
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .get_or_insert(e.into());
        }
        self.lines.lock().unwrap_or_else(|p| p.into_inner()).push(r);
    }

    /// The lines kept, in the order they came.
    ///
    /// # Errors
    /// The first append to the journal that failed.
    fn into_lines(self) -> anyhow::Result<Vec<ReadLine>> {
        if let Some(e) = self.error.into_inner().unwrap_or_else(|p| p.into_inner()) {
            return Err(e);
        }
        Ok(self.lines.into_inner().unwrap_or_else(|p| p.into_inner()))
    }
}

/// What `--out FILE --resume` already holds, by key (error lines left out with
/// `--retry-errors`), and the journal to append to; nothing without `--resume`.
///
/// # Errors
/// The file cannot be opened, locked or read.
fn resumed(request: &Request) -> anyhow::Result<(HashMap<Key, Held>, Option<journal::Journal>)> {
    let mut held: HashMap<Key, Held> = HashMap::new();
    let (Some(path), true) = (&request.out, request.resume) else {
        return Ok((held, None));
    };
    let (j, partial) = journal::Journal::open_lines(path)?;
    if partial > 0 {
        eprintln!(
            "grasp-sim: warning: {}: cut off a partial last line ({partial} bytes) an interrupted run left",
            path.display()
        );
    }
    let (lines, _) = read_lines(path)?;
    for l in lines {
        if request.retry_errors && l.is_error {
            continue;
        }
        held.entry(l.key.clone())
            .or_default()
            .lines
            .insert(l.grasp_index, l);
    }
    Ok((held, Some(j)))
}

/// Writes every line (to `--out`, through the journal when resuming, or to stdout) and the
/// `--summary` file; returns the error lines and the grasp lines written.
///
/// # Errors
/// An output that cannot be written.
fn write_all(
    request: &Request,
    keys: &[Key],
    held: &HashMap<Key, Held>,
    journal: Option<journal::Journal>,
    summaries: &[(usize, ObjectSummary)],
) -> anyhow::Result<(usize, usize)> {
    let (text, errors, grasps) = ordered(keys, held);
    match (&request.out, journal) {
        (Some(_), Some(j)) => j.finish(text.as_bytes())?,
        (Some(path), None) => journal::write_atomically(path, text.as_bytes())?,
        _ => std::io::stdout().lock().write_all(text.as_bytes())?,
    }
    if let Some(path) = &request.summary {
        let mut text = String::new();
        for (_, s) in summaries {
            text.push_str(&crate::report::to_rounded_json(s)?);
            text.push('\n');
        }
        journal::write_atomically(path, text.as_bytes())?;
    }
    Ok((errors, grasps))
}

/// Every line for `keys`, in input order, each object's object-level line first and then its
/// grasps by index; with the number of error lines and of grasp lines.
fn ordered(keys: &[Key], held: &HashMap<Key, Held>) -> (String, usize, usize) {
    let mut text = String::new();
    let (mut errors, mut grasps) = (0, 0);
    for key in keys {
        let Some(h) = held.get(key) else { continue };
        for l in h.lines.values() {
            text.push_str(&l.text);
            text.push('\n');
            errors += usize::from(l.is_error);
            grasps += usize::from(l.grasp_index.is_some() && !l.is_error);
        }
    }
    (text, errors, grasps)
}

/// The `label` part of an object's lines.
fn info_of(key: &Key) -> impl Fn(usize, usize, f64) -> LabelInfo + Sync + '_ {
    move |_, grasps, wall_ms| LabelInfo {
        input: key.input.clone(),
        input_hash: key.input_hash.clone(),
        grasps,
        wall_ms,
    }
}

/// Labels one object on this thread, passing each line to `keep`; a panic or a bad input
/// becomes the object's error line.
fn run_in_process(
    item: &Item,
    key: &Key,
    template: &Scenario,
    args: &WorkerArgs,
    skip: &BTreeSet<usize>,
    keep: &(dyn Fn(Line) + Sync),
) -> Option<ObjectSummary> {
    let info = info_of(key);
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let scenario = args.scenario(item, template)?;
        super::label_object(
            &scenario,
            &args.params,
            args.export.as_ref(),
            skip,
            &info,
            keep,
        )
    }));
    let input = item.path().display().to_string();
    let why = match result {
        Ok(Ok(summary)) => return Some(summary),
        Ok(Err(e)) => format!("{e:#}"),
        Err(payload) => format!(
            "{input}: panicked: {}",
            crate::pipeline::inputs::panic_message(payload.as_ref())
        ),
    };
    keep(error_line(&input, None, &why, info(0, 0, 0.0)));
    None
}

/// The worker for each object: this binary's hidden `label-worker`.
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

/// Labels one object in a worker process, passing each line it prints to `keep` as it comes;
/// a worker that fails (a crash, a timeout, memory) gets the object's error line, its
/// finished grasps kept.
fn run_isolated(
    item: &Item,
    key: &Key,
    worker: &Worker,
    skip: &BTreeSet<usize>,
    keep: &(dyn Fn(Line) + Sync),
) -> Option<ObjectSummary> {
    let mut w = worker.clone();
    if !skip.is_empty() {
        w.args.push("--skip".into());
        w.args.push(
            skip.iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(",")
                .into(),
        );
    }
    let summary: Mutex<Option<ObjectSummary>> = Mutex::new(None);
    let on_line = |text: &str| {
        if let Some(s) = text.strip_prefix("summary ") {
            if let Ok(v) = crate::files::parse_json_line(s) {
                *summary.lock().unwrap_or_else(|p| p.into_inner()) = summary_of(&v);
            }
            return;
        }
        match read_line(text) {
            Ok(r) if r.key == *key => keep(Line {
                grasp_index: r.grasp_index,
                order: r.grasp_index.unwrap_or(0),
                is_error: r.is_error,
                text: r.text,
            }),
            _ => {}
        }
    };
    let input = item.path().display().to_string();
    match batch::isolate::run_streaming(item, key, &w, &on_line) {
        Ok(None) => summary.into_inner().unwrap_or_else(|p| p.into_inner()),
        Ok(Some(why)) => {
            keep(error_line(
                &input,
                None,
                &format!("{input}: {why}"),
                info_of(key)(0, 0, 0.0),
            ));
            None
        }
        Err(batch::Interrupted(why)) => {
            eprintln!("grasp-sim: error: {why}");
            None
        }
    }
}

/// An [`ObjectSummary`] read back from a worker.
fn summary_of(v: &serde_json::Value) -> Option<ObjectSummary> {
    let n = |k: &str| v[k].as_u64().map(|x| x as usize).unwrap_or(0);
    let f = |k: &str| v[k].as_f64().unwrap_or(0.0);
    let pair = |k: &str| {
        (
            v[k][0].as_f64().unwrap_or(0.0),
            v[k][1].as_f64().unwrap_or(0.0),
        )
    };
    Some(ObjectSummary {
        object: v["object"].as_str()?.to_string(),
        candidates: n("candidates"),
        picked: n("picked"),
        labelled: n("labelled"),
        samples_checked: n("samples_checked"),
        holding: n("holding"),
        picked_spread: pair("picked_spread"),
        first_spread: pair("first_spread"),
        plan_ms: f("plan_ms"),
        collider_ms: f("collider_ms"),
        check_ms: f("check_ms"),
        wall_ms: f("wall_ms"),
    })
}

/// `label-worker`: one object with the command's settings, each line on stdout as it is done
/// (then `summary {json}`).
///
/// # Errors
/// A bad template, an input that is neither a scenario nor a mesh, or stdout gone.
pub fn run_worker(
    path: &Path,
    input_hash: &str,
    args: &WorkerArgs,
    skip: &BTreeSet<usize>,
) -> anyhow::Result<u8> {
    let template = args.template()?;
    let item = batch::classify(path.to_path_buf()).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: neither a scenario (.toml) nor a mesh (.stl, .obj, .ply, .urdf)",
            path.display()
        )
    })?;
    let key = Key {
        input: path.display().to_string(),
        input_hash: input_hash.to_string(),
    };
    let out = Mutex::new(std::io::stdout());
    let print = |text: &str| {
        let mut o = out.lock().unwrap_or_else(|p| p.into_inner());
        let _ = writeln!(o, "{text}");
        let _ = o.flush();
    };
    let summary = run_in_process(&item, &key, &template, args, skip, &|l: Line| {
        print(&l.text)
    });
    if let Some(s) = summary {
        print(&format!("summary {}", crate::report::to_rounded_json(&s)?));
    }
    Ok(0)
}

/// `label --merge`: the shard files' lines for these inputs, in input order, checked: every
/// input's object there exactly once and complete.
fn merge(request: &Request, keys: &[Key]) -> anyhow::Result<u8> {
    let files = crate::batch::command::shard_files(&request.merge)?;
    let mut held: HashMap<Key, Held> = HashMap::new();
    let mut duplicated = Vec::new();
    for f in &files {
        let (lines, partial) = read_lines(f)?;
        if partial > 0 {
            eprintln!(
                "grasp-sim: warning: {}: ignoring a partial last line (its shard was interrupted)",
                f.display()
            );
        }
        for l in lines {
            let h = held.entry(l.key.clone()).or_default();
            if h.lines.contains_key(&l.grasp_index) {
                duplicated.push(format!("{} grasp {:?}", l.key.input, l.grasp_index));
            }
            h.lines.insert(l.grasp_index, l);
        }
    }
    let known: BTreeSet<&Key> = keys.iter().collect();
    let missing: Vec<&str> = keys
        .iter()
        .filter(|k| !held.get(*k).is_some_and(Held::is_complete))
        .map(|k| k.input.as_str())
        .collect();
    let unknown: Vec<&str> = held
        .keys()
        .filter(|k| !known.contains(k))
        .map(|k| k.input.as_str())
        .collect();
    let mut problems = Vec::new();
    for (what, list, hint) in [
        ("missing or incomplete", missing, "did every shard finish?"),
        (
            "stale or unknown",
            unknown,
            "made from other contents, flags or template, or not among the inputs",
        ),
        (
            "duplicated",
            duplicated.iter().map(String::as_str).collect(),
            "do the shards overlap?",
        ),
    ] {
        if let Some(first) = list.first() {
            problems.push(format!("{} {what} (first: {first}; {hint})", list.len()));
        }
    }
    if !problems.is_empty() {
        anyhow::bail!(
            "merge check failed: {} inputs: {}",
            keys.len(),
            problems.join("; ")
        );
    }
    let (text, errors, grasps) = ordered(keys, &held);
    write_text(request.out.as_deref(), &text)?;
    eprintln!(
        "merge: {} of {} from {}, every input exactly once, {errors} errors",
        batch::plural(grasps, "grasp"),
        batch::plural(keys.len(), "object"),
        batch::plural(files.len(), "file")
    );
    Ok(if errors > 0 { 2 } else { 0 })
}

/// `--npz DIR`: each object's `.npz` (named after its scenario, made a file name), from its
/// grasp lines.
fn write_npz(
    dir: &Path,
    keys: &[Key],
    held: &HashMap<Key, Held>,
    template: &Scenario,
    args: &WorkerArgs,
    items: &[Item],
) -> anyhow::Result<()> {
    for (key, item) in keys.iter().zip(items) {
        let Some(h) = held.get(key) else { continue };
        let lines: Vec<serde_json::Value> = h
            .lines
            .values()
            .filter(|l| l.grasp_index.is_some() && !l.is_error)
            .filter_map(|l| crate::files::parse_json_line(&l.text).ok())
            .collect();
        let Some(first) = lines.first() else { continue };
        let name = first["object"].as_str().unwrap_or("object").to_string();
        let fingers = args
            .scenario(item, template)
            .map_or(3, |s| s.hand.finger_list.len());
        let bytes = super::npz::npz(&lines, fingers)?;
        let file = dir.join(format!("{}.npz", crate::files::folder_name(&name)));
        journal::write_atomically(&file, &bytes)?;
    }
    Ok(())
}

/// The most lines `check --grasps` reads from one file, and `label --resume` from the file it
/// continues: a label file of 60,000 objects at K = 16 (a line checked takes at least 0.1 s of
/// physics; a line read back some 1.8 KB of memory).
pub const MAX_GIVEN_LINES: usize = 1_000_000;

/// What `check --grasps` is asked to do.
#[derive(Debug, Clone)]
pub struct CheckRequest {
    /// The grasp lines (JSON Lines: a label file is valid input).
    pub grasps: PathBuf,
    /// The scenario or mesh the grasps are of.
    pub input: PathBuf,
    /// The length unit of a bare mesh.
    pub units: Option<LengthUnit>,
    /// Perturbed checks per grasp.
    pub samples: usize,
    /// The gravity directions (`None`: the scenario's).
    pub gravity: Option<GravityMode>,
    /// The results file (`None`: stdout).
    pub out: Option<PathBuf>,
}

/// `check --grasps`: every line's grasp checked on the object, one record per line in line
/// order (an error record for a line that cannot be checked); returns 2 if any line could not
/// be checked, else 0.
///
/// # Errors
/// A grasp file or input that cannot be read, an output that cannot be written.
pub fn check(request: &CheckRequest, progress: &dyn Progress) -> anyhow::Result<u8> {
    if let Some(path) = &request.out {
        check_output_file(path).context("--out")?;
    }
    let args = request.worker_args();
    let template = args.template()?;
    let item = batch::classify(request.input.clone()).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: neither a scenario (.toml) nor a mesh (.stl, .obj, .ply, .urdf)",
            request.input.display()
        )
    })?;
    let scenario = args.scenario(&item, &template)?;
    let bytes = crate::files::read_regular(&request.grasps, crate::files::MAX_RESULTS_BYTES)
        .with_context(|| format!("{}", request.grasps.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    // Each line given becomes a record of some hundred bytes: a file of short lines within the
    // size cap (`{}` 358 million times) would take hundreds of gigabytes.
    let count = text.lines().filter(|l| !l.trim().is_empty()).count();
    if count > MAX_GIVEN_LINES {
        anyhow::bail!(
            "{}: {count} lines, more than the {MAX_GIVEN_LINES} one check takes (split the file)",
            request.grasps.display()
        );
    }
    let given: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .collect();
    let (numbers, lines) = lines_of_object(&given, &scenario.name, &request.grasps);
    let key = Key {
        input: request.input.display().to_string(),
        input_hash: args.input_hash(&item, &template),
    };
    let info = |_: usize, wall_ms: f64| LabelInfo {
        input: key.input.clone(),
        input_hash: key.input_hash.clone(),
        grasps: lines.len(),
        wall_ms,
    };
    let out: Mutex<Vec<Line>> = Mutex::new(Vec::new());
    let done = std::sync::atomic::AtomicUsize::new(0);
    progress.begin(lines.len());
    let emit = |l: Line| {
        let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        progress.step(
            k,
            lines.len(),
            &format!(
                "grasp {}{}",
                l.grasp_index.map_or(String::new(), |i| i.to_string()),
                if l.is_error { ": error" } else { "" }
            ),
        );
        out.lock().unwrap_or_else(|p| p.into_inner()).push(l);
    };
    let summary =
        super::check_numbered_lines(&scenario, &lines, &numbers, request.samples, &info, &emit)?;
    progress.end();
    // In line order.
    let mut records = out.into_inner().unwrap_or_else(|p| p.into_inner());
    records.sort_by_key(|l| l.order);
    let (text, errors) = joined_lines(&records);
    write_text(request.out.as_deref(), &text)?;
    eprintln!(
        "check: {}: {} of {} checked ({errors} could not be), {} with hold probability >= 0.5; {} perturbed checks in {:.1} s",
        summary.object,
        summary.labelled,
        batch::plural(records.len(), "line"),
        summary.holding,
        summary.samples_checked,
        summary.wall_ms / 1000.0
    );
    Ok(if errors > 0 { 2 } else { 0 })
}

/// The lines of a grasp file to check on the object `name`, with their numbers in the file: when
/// some line's `object` is `name` (a label file of many objects), those lines and the lines that
/// name no object; otherwise every line, with a warning if they name other objects. Says on
/// stderr how many lines of other objects it leaves out.
fn lines_of_object(
    given: &[(usize, &str)],
    name: &str,
    file: &Path,
) -> (Vec<usize>, Vec<Result<String, String>>) {
    let objects: Vec<Option<String>> = given
        .iter()
        .map(|(_, l)| {
            crate::files::parse_json_line(l)
                .ok()
                .and_then(|v| v.get("object")?.as_str().map(str::to_string))
        })
        .collect();
    let ours = objects.iter().any(|o| o.as_deref() == Some(name));
    let keep = |o: &Option<String>| !ours || o.as_deref().is_none_or(|o| o == name);
    let skipped = objects.iter().filter(|o| !keep(o)).count();
    if skipped > 0 {
        eprintln!(
            "check: {}: {} of other objects left out (only those of `{name}` are checked)",
            file.display(),
            batch::plural(skipped, "line")
        );
    } else if let Some(other) = objects.iter().flatten().find(|o| *o != name) {
        // The file's text, escaped and cut short: the warning stays one line.
        let other: String = other
            .chars()
            .take(60)
            .flat_map(char::escape_debug)
            .collect();
        eprintln!(
            "check: warning: {}: no line is of `{name}` (a line names `{other}`): every line is checked on `{name}`",
            file.display()
        );
    }
    given
        .iter()
        .zip(&objects)
        .filter(|(_, o)| keep(o))
        .map(|((n, l), _)| (*n, Ok(l.to_string())))
        .unzip()
}

impl CheckRequest {
    /// The worker settings of a check: the built-in template, no grasps to plan, the request's
    /// units, samples and gravity, no MJCF export.
    fn worker_args(&self) -> WorkerArgs {
        WorkerArgs {
            template: None,
            units: self.units,
            params: LabelParams {
                grasps: 0,
                samples: self.samples,
                candidates: 0,
            },
            gravity: self.gravity,
            export: None,
        }
    }
}

/// The lines' texts, one a line, and how many of them are error lines.
fn joined_lines(records: &[Line]) -> (String, usize) {
    let mut text = String::new();
    let mut errors = 0;
    for r in records {
        text.push_str(&r.text);
        text.push('\n');
        errors += usize::from(r.is_error);
    }
    (text, errors)
}
