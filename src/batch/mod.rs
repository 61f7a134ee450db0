//! Running many objects: input expansion, templates, sharding, parallel runs in a stable order.
//!
//! An input is a scenario file, a mesh file (STL, OBJ or PLY), or a folder (its `*.toml` scenarios
//! and meshes, not recursing, sorted by path). A mesh is run with a template scenario: by default
//! the thesis hand (built into the binary), millimetres, 500 kg/m³, μ = 0.3, the thesis's planner
//! and physics defaults. Results come back in input order whatever the number of threads; a shard
//! `K/N` is the K-th of N contiguous blocks, so the shards' outputs concatenate to the whole.
//!
//! Each object's result is a [`Record`]: one JSON line that also names its input and the hash
//! of what decides it ([`record`]). That is what makes a long run restartable and checkable:
//! [`journal`] appends records crash-safely and reads them back for `--resume`, [`merge`] puts
//! shard files together and checks that every input is there exactly once, and [`isolate`]
//! runs each object in its own process so a crash, a timeout or memory exhaustion costs one
//! error line.

pub mod command;
pub mod isolate;
pub mod journal;
pub mod record;

/// Re-exported for the binary (its home is the crate's `messages`).
pub use crate::messages::plural;
/// What one input is and how it becomes a scenario (their home is the pipeline's).
pub use crate::pipeline::input::{
    classify, default_template, expand, scenario_for, Item, THESIS_HAND_TOML,
};
pub use isolate::{Interrupted, Worker};
pub use record::{input_hash, Key, Record, RecordError};

use crate::report::RecordView;
use crate::report::Verdict;
use crate::scenario::Scenario;
use crate::{run, RunOptions};
use rayon::prelude::*;
use record::BatchInfo;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why a batch file could not be used: bad input, named by its file.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// The file cannot be read or written.
    ///
    /// Its message names the file; the I/O error is its source, so that a report of the error
    /// chain (anyhow's `{:#}`, as the binary prints errors) reads `<file>: <the I/O error>`.
    #[error("{}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// A complete line that is not a batch record.
    #[error("{}: line {line} is not a batch record: {why}", path.display())]
    NotARecord {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        why: String,
    },
    /// Another run is appending to the file.
    #[error("{}: in use by another `grasp-sim batch` (locked); one run per file", path.display())]
    Locked {
        /// The file.
        path: PathBuf,
    },
    /// Shard files that do not hold every input exactly once.
    #[error("merge check failed: {0}")]
    Merge(String),
}

impl BatchError {
    /// The error `source` of reading or writing `path`.
    pub(crate) fn io(path: &Path, source: std::io::Error) -> BatchError {
        BatchError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// A shard `K/N`: the K-th (1-based) of N contiguous blocks of the inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which block, 1 ≤ K ≤ N.
    pub k: usize,
    /// How many blocks.
    pub n: usize,
}

/// Why a `--shard` value is not `K/N`; each variant holds the value given.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    /// No `/`.
    #[error("shard `{0}` is not K/N")]
    NotKOverN(String),
    /// K or N is not a number.
    #[error("shard `{shard}`: {part} is not a number")]
    NotANumber {
        /// The value given.
        shard: String,
        /// `K` or `N`.
        part: char,
    },
    /// Not 1 ≤ K ≤ N.
    #[error("shard `{0}`: need 1 <= K <= N")]
    OutOfRange(String),
}

/// Parses `K/N` (1 ≤ K ≤ N).
///
/// # Errors
/// [`ShardError`] saying what is wrong.
pub fn parse_shard(s: &str) -> Result<Shard, ShardError> {
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| ShardError::NotKOverN(s.to_string()))?;
    let number = |v: &str, part: char| {
        v.trim()
            .parse::<usize>()
            .map_err(|_| ShardError::NotANumber {
                shard: s.to_string(),
                part,
            })
    };
    let (k, n) = (number(k, 'K')?, number(n, 'N')?);
    if n == 0 || k == 0 || k > n {
        return Err(ShardError::OutOfRange(s.to_string()));
    }
    Ok(Shard { k, n })
}

impl std::str::FromStr for Shard {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Self, ShardError> {
        parse_shard(s)
    }
}

impl Shard {
    /// This shard's block of `items`.
    pub fn of<T: Clone>(self, items: &[T]) -> Vec<T> {
        let (k, n, len) = (self.k, self.n, items.len());
        items[(k - 1) * len / n..k * len / n].to_vec()
    }
}

/// How each object runs.
#[derive(Debug, Clone)]
pub enum Isolation {
    /// On a thread of this process; a panic is caught and becomes the object's error line.
    InProcess,
    /// In a worker process of its own ([`isolate`]): a crash, a timeout or memory exhaustion
    /// too becomes the object's error line.
    Process(Worker),
}

/// The items of a batch with their keys, hashed in parallel.
pub fn keys(items: &[Item], template: &Scenario, options: &RunOptions) -> Vec<Key> {
    items
        .par_iter()
        .map(|item| Key {
            input: item.path().display().to_string(),
            input_hash: input_hash(item, template, options),
        })
        .collect()
}

/// Runs one item on this thread and returns its record; a panic is caught and becomes the
/// record's error (`panicked: <message>`).
pub fn run_one(item: &Item, key: &Key, template: &Scenario, options: &RunOptions) -> Record {
    let t0 = Instant::now();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        test_fault(item);
        scenario_for(item, template).and_then(|s| run(&s, options))
    }));
    let info = BatchInfo {
        input: key.input.clone(),
        input_hash: key.input_hash.clone(),
        wall_ms: t0.elapsed().as_secs_f64() * 1000.0,
    };
    let scenario = item.path().display().to_string();
    match result {
        Ok(Ok(report)) => Record::from_report(&report, info),
        Ok(Err(e)) => Record::from_error(&scenario, &format!("{e:#}"), info),
        Err(payload) => {
            let message = crate::pipeline::inputs::panic_message(payload.as_ref());
            Record::from_error(&scenario, &format!("{scenario}: panicked: {message}"), info)
        }
    }
}

/// Test hook, debug builds only: `GRASP_SIM_TEST_FAULT=panic:NAME` panics and
/// `GRASP_SIM_TEST_FAULT=abort:NAME` aborts the process while running an input whose path
/// contains `NAME`, so the tests can show that a fault inside a dependency costs one error
/// line. Release builds never read the variable.
fn test_fault(item: &Item) {
    #[cfg(debug_assertions)]
    if let Ok(fault) = std::env::var("GRASP_SIM_TEST_FAULT") {
        if let Some((kind, name)) = fault.split_once(':') {
            if item.path().to_string_lossy().contains(name) {
                match kind {
                    "panic" => panic!("test fault (GRASP_SIM_TEST_FAULT) in {name}"),
                    "abort" => std::process::abort(),
                    _ => {}
                }
            }
        }
    }
    #[cfg(not(debug_assertions))]
    let _ = item;
}

/// The result of one item: its record, or why it has none (its worker was interrupted).
pub type ItemResult = Result<Record, Interrupted>;

/// Runs `items` (with their `keys`) on `jobs` threads (at least 1), each in the way
/// `isolation` says; calls `done` as each finishes (from the worker threads, in completion
/// order); returns the results in item order.
pub fn run_all(
    items: &[Item],
    keys: &[Key],
    template: &Scenario,
    options: &RunOptions,
    jobs: usize,
    isolation: &Isolation,
    done: &(dyn Fn(&Item, &ItemResult) + Sync),
) -> Vec<ItemResult> {
    let work = || {
        items
            .par_iter()
            .zip(keys)
            .map(|(item, key)| {
                let r = match isolation {
                    Isolation::InProcess => Ok(run_one(item, key, template, options)),
                    Isolation::Process(w) => isolate::run_isolated(item, key, w),
                };
                done(item, &r);
                r
            })
            .collect()
    };
    match rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
    {
        Ok(pool) => pool.install(work),
        Err(_) => work(),
    }
}

/// Puts together the records of shard files for `keys` (the whole batch, in input order) and
/// checks them: every key exactly once, no record left over.
///
/// `records` are the records read, each with where it came from (`file:line`).
///
/// # Errors
/// [`BatchError::Merge`] saying how many inputs are missing, duplicated, stale (a record for
/// the input made from different contents, flags or template) or unknown, with the first of
/// each.
pub fn merge(keys: &[Key], records: Vec<(String, Record)>) -> Result<Vec<Record>, BatchError> {
    let mut found: BTreeMap<Key, Vec<(String, Record)>> = BTreeMap::new();
    for (place, r) in records {
        found.entry(r.key.clone()).or_default().push((place, r));
    }
    let inputs: BTreeMap<&str, &Key> = keys.iter().map(|k| (k.input.as_str(), k)).collect();
    let mut problems = Vec::new();
    let mut missing = Vec::new();
    let mut duplicated = Vec::new();
    let mut merged = Vec::with_capacity(keys.len());
    for k in keys {
        match found.get(k).map(Vec::as_slice) {
            Some([(_, r)]) => merged.push(r.clone()),
            Some(many @ [(_, r), ..]) => {
                duplicated.push(format!(
                    "{} ({} times: {})",
                    k.input,
                    many.len(),
                    many.iter()
                        .map(|(p, _)| p.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
                merged.push(r.clone());
            }
            _ => missing.push(k.input.clone()),
        }
    }
    let mut stale = Vec::new();
    let mut unknown = Vec::new();
    for (k, rs) in &found {
        match inputs.get(k.input.as_str()) {
            Some(expected) if *expected == k => {}
            Some(_) => stale.push(format!("{} ({})", k.input, rs[0].0)),
            None => unknown.push(format!("{} ({})", k.input, rs[0].0)),
        }
    }
    for (what, list, hint) in [
        ("missing", &missing, "did every shard finish?"),
        ("duplicated", &duplicated, "do the shards overlap?"),
        (
            "stale",
            &stale,
            "made from other contents, flags or template; run its shard again",
        ),
        ("unknown", &unknown, "not among the inputs"),
    ] {
        if let Some(first) = list.first() {
            problems.push(format!("{} {what} (first: {first}; {hint})", list.len()));
        }
    }
    if problems.is_empty() {
        Ok(merged)
    } else {
        Err(BatchError::Merge(format!(
            "{} inputs: {}",
            keys.len(),
            problems.join("; ")
        )))
    }
}

/// The counts a batch summary reports, from records (any JSON Lines of run reports).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Counts {
    /// Records.
    pub objects: usize,
    /// `plan.status` feasible.
    pub feasible: usize,
    /// `plan.status` ungraspable.
    pub ungraspable: usize,
    /// `sim.verdict` hold, slip, drop.
    pub hold: usize,
    /// See `hold`.
    pub slip: usize,
    /// See `hold`.
    pub drop: usize,
    /// `expect.met` true.
    pub met: usize,
    /// `expect.met` false.
    pub not_met: usize,
    /// `expect.met` null.
    pub unjudged: usize,
    /// Lines with an `error`.
    pub errors: usize,
}

impl Counts {
    /// Counts the outcomes of `lines`.
    pub fn of_views<'a>(lines: impl IntoIterator<Item = &'a RecordView>) -> Counts {
        let mut c = Counts::default();
        for v in lines {
            c.add(v);
        }
        c
    }

    /// Counts the outcome of one more line.
    pub fn add(&mut self, v: &RecordView) {
        let c = self;
        c.objects += 1;
        if v.error.is_some() {
            c.errors += 1;
            return;
        }
        if v.is_feasible() {
            c.feasible += 1;
        } else {
            c.ungraspable += 1;
        }
        match v.sim.ran() {
            Some(Verdict::Hold) => c.hold += 1,
            Some(Verdict::Slip) => c.slip += 1,
            Some(Verdict::Drop) => c.drop += 1,
            None => {}
        }
        match v.expect.met {
            Some(true) => c.met += 1,
            Some(false) => c.not_met += 1,
            None => c.unjudged += 1,
        }
    }

    /// Counts the outcomes of `records`.
    pub fn of_records<'a>(records: impl IntoIterator<Item = &'a Record>) -> Counts {
        Counts::of_views(records.into_iter().map(|r| &r.view))
    }
}

/// The summary line of a batch: `ran` objects run in `seconds` on `jobs` threads, of
/// `counts.objects` in all (the rest were already in the file being resumed).
pub fn summary(counts: &Counts, ran: usize, seconds: f64, jobs: usize) -> String {
    let Counts {
        feasible,
        ungraspable,
        hold,
        slip,
        drop,
        met,
        not_met,
        unjudged,
        errors,
        ..
    } = *counts;
    let n = ran.max(1);
    // Threads beyond the number of objects sit idle: per-object time counts the busy ones.
    let busy = jobs.clamp(1, n);
    let resumed = if ran == counts.objects {
        String::new()
    } else {
        format!(
            " ({} run, {} already done)",
            ran,
            counts.objects.saturating_sub(ran)
        )
    };
    format!(
        "batch: {}{resumed} in {:.2} s ({:.3} s per object, {}): {feasible} planned, \
         {ungraspable} ungraspable; physics: {hold} hold, {slip} slip, {drop} drop; \
         expectations: {met} met, {not_met} not met, {unjudged} not judged; {}",
        plural(counts.objects, "object"),
        seconds,
        seconds * busy as f64 / n as f64,
        plural(jobs.max(1), "job"),
        plural(errors, "error")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_split_into_contiguous_blocks() {
        let table = [
            ("2/3", Ok(Shard { k: 2, n: 3 })),
            (" 1 / 1 ", Ok(Shard { k: 1, n: 1 })),
            ("3/2", Err(ShardError::OutOfRange("3/2".to_string()))),
            ("0/2", Err(ShardError::OutOfRange("0/2".to_string()))),
            ("2", Err(ShardError::NotKOverN("2".to_string()))),
            (
                "x/2",
                Err(ShardError::NotANumber {
                    shard: "x/2".to_string(),
                    part: 'K',
                }),
            ),
        ];
        for (text, expected) in table {
            assert_eq!(text.parse::<Shard>(), expected, "{text}");
        }
        let items: Vec<u32> = (1..=7).collect();
        let blocks: Vec<Vec<u32>> = (1..=3).map(|k| Shard { k, n: 3 }.of(&items)).collect();
        assert_eq!(blocks, [vec![1, 2], vec![3, 4], vec![5, 6, 7]]);
    }
}
