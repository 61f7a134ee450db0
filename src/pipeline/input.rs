//! One input: what it is (a scenario or a bare mesh, by its extension), how folders expand into
//! inputs, and the scenario it runs as (the file itself, or the template with its mesh).

use crate::hand::Hand;
use crate::scenario::{ObjectSpec, PlannerParams, Scenario, ScenarioError, SimParams};
use crate::Error;
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
/// when it has any (they name their own meshes), else its URDFs (`*.urdf`, which name theirs),
/// else its meshes (`*.stl`, `*.obj`, `*.ply`).
///
/// # Errors
/// [`ScenarioError::Io`] for an input that is neither a folder, a `.toml` nor a mesh file by its
/// name (a missing `nope.stl` is an input, whose run says it is missing), or a folder with none
/// of these in it.
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
                // Not only regular files: a FIFO or a broken link named like an input is one,
                // and its line says why it cannot be read (rather than its being skipped).
                .filter(|p| !p.is_dir())
                .filter_map(classify)
                .filter(|i| !is_hand_file(i.path()))
                .collect();
            if found.iter().any(|i| matches!(i, Item::Scenario(_))) {
                found.retain(|i| matches!(i, Item::Scenario(_)));
            } else if found.iter().any(|i| is_urdf(i.path())) {
                found.retain(|i| is_urdf(i.path()));
            }
            if found.is_empty() {
                return Err(ScenarioError::Io {
                    path: input.clone(),
                    message: "no scenario (.toml) or mesh (.stl, .obj, .ply, .urdf) in this folder"
                        .to_string(),
                });
            }
            found.sort_by(|a, b| a.path().cmp(b.path()));
            items.extend(found);
        } else if input.is_file() {
            items.push(classify(input.clone()).ok_or_else(|| ScenarioError::Io {
                path: input.clone(),
                message:
                    "neither a scenario (.toml) nor a mesh (.stl, .obj, .ply, .urdf)".to_string(),
            })?);
        } else if let Some(item) = classify(input.clone()) {
            // Named like an input but missing or not a regular file (a FIFO, a device): an
            // input of its own, whose run says why it cannot be read; the others still run.
            items.push(item);
        } else {
            return Err(ScenarioError::Io {
                path: input.clone(),
                message: "no such file or folder".to_string(),
            });
        }
    }
    Ok(items)
}

/// Returns true if and only if `path` names a URDF (by its extension).
fn is_urdf(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
}

/// Returns true if and only if `path` is a TOML file that reads as a hand file (it has a
/// `[palm]` table and `[[finger]]` entries): a folder holding its hand beside its scenarios is
/// not a folder of one more scenario.
fn is_hand_file(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "toml")
        && crate::files::read_regular_string(path, crate::files::MAX_TEXT_BYTES)
            .ok()
            .and_then(|t| t.parse::<toml::Table>().ok())
            .is_some_and(|t| t.contains_key("palm") && t.contains_key("finger"))
}

/// The item a file is by its extension: `.toml` a scenario, `.stl`, `.obj`, `.ply`, `.urdf` a
/// mesh.
pub fn classify(p: PathBuf) -> Option<Item> {
    match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "toml" => Some(Item::Scenario(p)),
        "stl" | "obj" | "ply" | "urdf" => Some(Item::Mesh(p)),
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
        object: ObjectSpec::with_defaults(PathBuf::new()),
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
            s.name = crate::files::folder_name(
                &p.file_stem()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
            );
            Ok(s)
        }
    }
}
