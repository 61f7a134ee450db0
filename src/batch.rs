//! Running many objects: input expansion, templates, sharding, parallel runs in a stable order.
//!
//! An input is a scenario file, a mesh file (STL, OBJ or PLY), or a folder (its `*.toml`
//! scenarios and meshes, not recursing, sorted by path). A mesh is run with a template scenario: by default the
//! thesis hand (built into the binary), millimetres, 500 kg/m³, μ = 0.3, the thesis's planner and
//! physics defaults. Results come back in input order whatever the number of threads; a shard
//! `K/N` is the K-th of N contiguous blocks, so the shards' outputs concatenate to the whole.

use crate::hand::Hand;
use crate::report::RunReport;
use crate::scenario::{MassSpec, ObjectSpec, PlannerParams, Scenario, ScenarioError, SimParams};
use crate::{run, Error, RunOptions};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// The thesis hand file, built in for templates.
pub const THESIS_HAND_TOML: &str = crate::hand::BUNDLED[0].1;

/// One thing to run.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Item {
    /// A scenario file.
    Scenario(PathBuf),
    /// A mesh, run with the template.
    Mesh(PathBuf),
}

impl Item {
    /// The file.
    pub fn path(&self) -> &Path {
        match self {
            Item::Scenario(p) | Item::Mesh(p) => p,
        }
    }
}

/// Expands inputs into items, in a deterministic order. A folder gives its scenarios (`*.toml`)
/// when it has any (they name their own meshes), its meshes (`*.stl`, `*.obj`, `*.ply`) otherwise.
///
/// # Errors
/// [`ScenarioError::Io`] for an input that does not exist or is neither a folder, a `.toml` nor
/// a mesh file.
pub fn expand(inputs: &[PathBuf]) -> Result<Vec<Item>, ScenarioError> {
    let mut items = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).map_err(|e| ScenarioError::Io {
                path: input.clone(),
                message: e.to_string(),
            })?;
            let mut found: Vec<Item> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file())
                .filter_map(classify)
                .filter(|i| !is_hand_file(i.path()))
                .collect();
            if found.iter().any(|i| matches!(i, Item::Scenario(_))) {
                found.retain(|i| matches!(i, Item::Scenario(_)));
            }
            found.sort_by(|a, b| a.path().cmp(b.path()));
            items.extend(found);
        } else if input.is_file() {
            items.push(classify(input.clone()).ok_or_else(|| ScenarioError::Io {
                path: input.clone(),
                message: "neither a scenario (.toml) nor a mesh (.stl, .obj, .ply)".to_string(),
            })?);
        } else {
            return Err(ScenarioError::Io {
                path: input.clone(),
                message: "no such file or folder".to_string(),
            });
        }
    }
    Ok(items)
}

/// Returns true if and only if `path` is a TOML file that reads as a hand file (it has a
/// `[palm]` table and `[[finger]]` entries): a folder holding its hand beside its scenarios is
/// not a folder of one more scenario.
fn is_hand_file(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "toml")
        && std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.parse::<toml::Table>().ok())
            .is_some_and(|t| t.contains_key("palm") && t.contains_key("finger"))
}

fn classify(p: PathBuf) -> Option<Item> {
    match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "toml" => Some(Item::Scenario(p)),
        "stl" | "obj" | "ply" => Some(Item::Mesh(p)),
        _ => None,
    }
}

/// The default template: the thesis hand and the thesis's defaults.
pub fn default_template() -> Scenario {
    let hand = Hand::parse(THESIS_HAND_TOML, Path::new("<built-in thesis hand>"), &[])
        .expect("the built-in thesis hand is valid");
    Scenario {
        path: PathBuf::from("<built-in template>"),
        name: String::new(),
        object: ObjectSpec {
            mesh: PathBuf::new(),
            units: Default::default(),
            mass: MassSpec::Density(crate::scenario::DEFAULT_DENSITY_KG_M3),
            friction: 0.3,
        },
        hand,
        hand_file: PathBuf::from("<built-in thesis hand>"),
        planner: PlannerParams::default(),
        sim: SimParams::default(),
        // A bare mesh comes with no expectation: nothing to judge (issue 16, item 2).
        expect: None,
    }
}

/// The scenario for an item: the file itself, or the template with the mesh swapped in.
///
/// # Errors
/// A bad scenario file.
pub fn scenario_for(item: &Item, template: &Scenario) -> Result<Scenario, Error> {
    match item {
        Item::Scenario(p) => Ok(Scenario::load(p)?),
        Item::Mesh(p) => {
            let mut s = template.clone();
            s.object.mesh = p.clone();
            s.name = p
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            Ok(s)
        }
    }
}

/// Parses `K/N` (1 ≤ K ≤ N).
///
/// # Errors
/// A message saying what is wrong.
pub fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| format!("shard `{s}` is not K/N"))?;
    let k: usize = k
        .trim()
        .parse()
        .map_err(|_| format!("shard `{s}`: K is not a number"))?;
    let n: usize = n
        .trim()
        .parse()
        .map_err(|_| format!("shard `{s}`: N is not a number"))?;
    if n == 0 || k == 0 || k > n {
        return Err(format!("shard `{s}`: need 1 <= K <= N"));
    }
    Ok((k, n))
}

/// The K-th (1-based) of N contiguous blocks of `items`.
pub fn shard<T: Clone>(items: &[T], k: usize, n: usize) -> Vec<T> {
    let len = items.len();
    items[(k - 1) * len / n..k * len / n].to_vec()
}

/// The result of one item: its report, or the one-line error that stopped it.
pub type ItemResult = Result<RunReport, String>;

/// Runs `items` on `jobs` threads (at least 1), calling `progress` as each finishes; results in
/// item order.
pub fn run_all(
    items: &[Item],
    template: &Scenario,
    options: &RunOptions,
    jobs: usize,
    progress: &(dyn Fn(&Item, &ItemResult) + Sync),
) -> Vec<ItemResult> {
    let work = || {
        items
            .par_iter()
            .map(|item| {
                let r = scenario_for(item, template)
                    .and_then(|s| run(&s, options))
                    .map_err(|e| format!("{e:#}").replace('\n', " "));
                progress(item, &r);
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

/// The summary line of a batch.
pub fn summary(results: &[ItemResult], seconds: f64, jobs: usize) -> String {
    let mut feasible = 0;
    let mut ungraspable = 0;
    let mut errors = 0;
    let (mut hold, mut slip, mut drop) = (0, 0, 0);
    let (mut met, mut not_met, mut unjudged) = (0, 0, 0);
    for r in results {
        match r {
            Ok(rep) => {
                if rep.plan.status == "feasible" {
                    feasible += 1;
                } else {
                    ungraspable += 1;
                }
                match rep.sim.verdict.as_str() {
                    "hold" => hold += 1,
                    "slip" => slip += 1,
                    "drop" => drop += 1,
                    _ => {}
                }
                match rep.expect.met {
                    Some(true) => met += 1,
                    Some(false) => not_met += 1,
                    None => unjudged += 1,
                }
            }
            Err(_) => errors += 1,
        }
    }
    let n = results.len().max(1);
    // Threads beyond the number of objects sit idle: per-object time counts the busy ones.
    let busy = jobs.clamp(1, n);
    format!(
        "batch: {} in {:.2} s ({:.3} s per object, {}): {feasible} planned, {ungraspable} \
         ungraspable; physics: {hold} hold, {slip} slip, {drop} drop; expectations: {met} met, \
         {not_met} not met, {unjudged} not judged; {}",
        plural(results.len(), "object"),
        seconds,
        seconds * busy as f64 / n as f64,
        plural(jobs.max(1), "job"),
        plural(errors, "error")
    )
}

/// `n thing` or `n things`.
pub fn plural(n: usize, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}
