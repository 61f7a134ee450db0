//! `grasp_sim._native`: the compiled half of the Python package (issue 36), a thin PyO3 layer
//! over the grasp-sim library.
//!
//! Everything here converts and delegates: hands through `Hand::parse` / `Hand::load`, meshes
//! through the library's loader, scenarios through `Scenario::parse` (the TOML the command line
//! reads, so validation and messages are the CLI's), runs through `pipeline::run`, batches
//! through `batch::run_all`. The typed API, its docstrings and the conversions of the JSON
//! report into objects live in the pure-Python package beside this crate (`grasp_sim/`).
//!
//! Every call that does Rust work releases the GIL ([`Python::detach`]) and catches panics, so
//! a fault in the library is a `GraspSimError`, never a crash of the interpreter.

use grasp_sim::batch::{self, journal, Isolation, Item, ItemResult, Key, Record};
use grasp_sim::hand::{Hand, HandError};
use grasp_sim::mesh::{self, LengthUnit, LoadedMesh, MeshError, MeshFormat};
use grasp_sim::pipeline::{self, RunFlags, RunOptions};
use grasp_sim::report::to_rounded_json;
use grasp_sim::scenario::{GravityMode, Scenario, ScenarioError};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::{Path, PathBuf};
use std::sync::{mpsc, Mutex};
use std::time::Duration;

create_exception!(
    grasp_sim,
    GraspSimError,
    PyException,
    "Any error of grasp-sim: its message is the one line the command line prints."
);
create_exception!(
    grasp_sim,
    BadInputError,
    GraspSimError,
    "A bad object: a mesh file or arrays that cannot be read or fail validation, or a bad argument."
);
create_exception!(
    grasp_sim,
    BadScenarioError,
    GraspSimError,
    "A bad scenario: unknown key, wrong type or value out of range (in a file or in keyword arguments)."
);
create_exception!(
    grasp_sim,
    BadHandError,
    GraspSimError,
    "A bad hand file, or an override out of range."
);

/// The error's one line, as the command line prints it after `grasp-sim: error: `.
fn one_line(e: &dyn std::fmt::Display) -> String {
    format!("{e:#}").replace('\n', " ")
}

fn scenario_err(e: ScenarioError) -> PyErr {
    match e {
        ScenarioError::Hand(h) => BadHandError::new_err(one_line(&h)),
        other => BadScenarioError::new_err(one_line(&other)),
    }
}

fn pipeline_err(e: pipeline::Error) -> PyErr {
    let line = one_line(&e);
    pipeline_err_with(&e, line)
}

/// The exception class of `e`, with the message `line`.
fn pipeline_err_with(e: &pipeline::Error, line: String) -> PyErr {
    match e {
        pipeline::Error::Scenario(ScenarioError::Hand(_)) => BadHandError::new_err(line),
        pipeline::Error::Scenario(_) => BadScenarioError::new_err(line),
        pipeline::Error::Mesh(_) | pipeline::Error::Given(_) => BadInputError::new_err(line),
        _ => GraspSimError::new_err(line),
    }
}

/// The text of a panic's payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".to_string())
}

/// Runs `f` without the GIL, a panic caught and turned into a `GraspSimError`.
fn detached<T, F>(py: Python<'_>, what: &str, f: F) -> PyResult<T>
where
    F: FnOnce() -> PyResult<T> + Send,
    T: Send,
{
    // A `PyErr` made without the GIL is lazy (its type and message only), so it may cross.
    match py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f))) {
        Ok(result) => result,
        Err(payload) => Err(GraspSimError::new_err(format!(
            "{what}: panicked: {}",
            panic_message(payload.as_ref())
        ))),
    }
}

fn unit(name: &str) -> PyResult<LengthUnit> {
    LengthUnit::from_name(name).ok_or_else(|| {
        BadInputError::new_err(format!(
            "units: unknown unit \"{name}\"; one of {}",
            LengthUnit::ALL
                .map(|u| format!("\"{}\"", u.name()))
                .join(", ")
        ))
    })
}

/// Loads a hand: a bundled name (`thesis`, `bh8`) unless a file of that name exists, else a
/// hand file, as `[hand] file` resolves it. Returns `(name, file, params_json)`: `file` is what
/// a scenario's `[hand] file` names it by (the bundled name, or the absolute path).
#[pyfunction]
#[pyo3(signature = (spec, overrides=Vec::new()))]
fn load_hand(
    py: Python<'_>,
    spec: PathBuf,
    overrides: Vec<(String, f64)>,
) -> PyResult<(String, String, String)> {
    detached(py, "Hand.load", move || {
        let bundled = spec
            .to_str()
            .and_then(grasp_sim::hand::bundled)
            .filter(|_| !spec.is_file());
        let bad = |e: HandError| BadHandError::new_err(one_line(&e));
        let (file, hand) = match bundled {
            Some((name, text)) => {
                let label = PathBuf::from(format!("<bundled hand {name}>"));
                (
                    name.to_string(),
                    Hand::parse(text, &label, &overrides).map_err(bad)?,
                )
            }
            None => {
                let abs = std::path::absolute(&spec).unwrap_or(spec.clone());
                let hand = Hand::load(&spec, &overrides).map_err(bad)?;
                (abs.display().to_string(), hand)
            }
        };
        let json = serde_json::to_string(&hand)
            .map_err(|e| GraspSimError::new_err(format!("hand as JSON: {e}")))?;
        Ok((hand.name.clone(), file, json))
    })
}

/// What a loaded mesh found, as JSON for the Python side.
fn mesh_info(loaded: &LoadedMesh) -> String {
    let t = loaded.topology;
    let props = mesh::mass_properties(&loaded.mesh);
    serde_json::json!({
        "triangles_read": loaded.triangles_read,
        "degenerate_dropped": loaded.degenerate_dropped,
        "holes_filled": loaded.holes_filled,
        "was_inverted": loaded.was_inverted,
        "boundary_edges": t.boundary_edges,
        "non_manifold_edges": t.non_manifold_edges,
        "misoriented_edges": t.misoriented_edges,
        "volume_mm3": props.volume_mm3,
        "format": loaded.format.as_str(),
        "unit": loaded.unit.name(),
        "warnings": loaded.warnings(),
    })
    .to_string()
}

/// The welded mesh `[mm]` as `(vertices (N, 3) float64, faces (M, 3) int64)` arrays.
fn mesh_arrays(m: &mesh::Mesh) -> (Array2<f64>, Array2<i64>) {
    let v: Vec<f64> = m.vertices.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    let f: Vec<i64> = m.triangles.iter().flat_map(|t| t.map(i64::from)).collect();
    (
        Array2::from_shape_vec((m.vertices.len(), 3), v).expect("3 coordinates per vertex"),
        Array2::from_shape_vec((m.triangles.len(), 3), f).expect("3 indices per triangle"),
    )
}

type MeshOut<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>, String);

/// Reads and validates a mesh file (STL, OBJ, PLY or URDF) as the command line does; returns
/// `(vertices [mm], faces, info_json)`.
#[pyfunction]
fn load_mesh_file<'py>(py: Python<'py>, path: PathBuf, units: &str) -> PyResult<MeshOut<'py>> {
    let unit = unit(units)?;
    let (v, f, info) = detached(py, "Object.from_file", move || {
        let loaded =
            mesh::load_mesh(&path, unit).map_err(|e| BadInputError::new_err(one_line(&e)))?;
        let (v, f) = mesh_arrays(&loaded.mesh);
        Ok((v, f, mesh_info(&loaded)))
    })?;
    Ok((v.into_pyarray(py), f.into_pyarray(py), info))
}

/// Binary STL bytes of the triangles `faces` makes of `vertices` (in their own unit); a face
/// index out of range is the loader's `FaceIndex` error (the face numbered from 1, as in files).
fn stl_bytes(
    vertices: &[[f64; 3]],
    faces: &[[i64; 3]],
    label: &Path,
) -> Result<Vec<u8>, MeshError> {
    let mut bytes = Vec::with_capacity(84 + 50 * faces.len());
    bytes.extend_from_slice(&[0u8; 80]);
    let count = u32::try_from(faces.len()).map_err(|_| MeshError::NotStl {
        path: label.to_path_buf(),
        detail: format!("{} faces, more than a mesh may have", faces.len()),
    })?;
    bytes.extend_from_slice(&count.to_le_bytes());
    for (k, face) in faces.iter().enumerate() {
        bytes.extend_from_slice(&[0u8; 12]);
        for &i in face {
            let v = usize::try_from(i)
                .ok()
                .and_then(|i| vertices.get(i))
                .ok_or_else(|| MeshError::FaceIndex {
                    path: label.to_path_buf(),
                    face: k + 1,
                    index: i,
                    vertices: vertices.len(),
                })?;
            // Every mesh format is read as f32 (the loader's triangle soup): the same here, so
            // arrays give exactly what a file holding them gives.
            for c in v {
                bytes.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0u8; 2]);
    }
    Ok(bytes)
}

/// Validates a mesh given as arrays (`vertices (N, 3)` in `units`, `faces (M, 3)` zero-based)
/// through the loader, as a binary STL of those triangles; returns
/// `(stl_bytes, (vertices [mm], faces, info_json))`. The STL is what the pipeline reads.
#[pyfunction]
fn mesh_from_arrays<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    units: &str,
    label: PathBuf,
) -> PyResult<(Bound<'py, PyBytes>, MeshOut<'py>)> {
    let unit = unit(units)?;
    let (vs, fs) = (vertices.as_array(), faces.as_array());
    if vs.ncols() != 3 || fs.ncols() != 3 {
        return Err(BadInputError::new_err(format!(
            "{}: vertices must be (N, 3) and faces (M, 3), got {:?} and {:?}",
            label.display(),
            vs.shape(),
            fs.shape()
        )));
    }
    let vs: Vec<[f64; 3]> = vs.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    let fs: Vec<[i64; 3]> = fs.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    let (stl, v, f, info) = detached(py, "Object.from_arrays", move || {
        let stl = stl_bytes(&vs, &fs, &label).map_err(|e| BadInputError::new_err(one_line(&e)))?;
        let loaded = mesh::parse_mesh(&stl, &label, MeshFormat::Stl, unit)
            .map_err(|e| BadInputError::new_err(one_line(&e)))?;
        let (v, f) = mesh_arrays(&loaded.mesh);
        Ok((stl, v, f, mesh_info(&loaded)))
    })?;
    Ok((
        PyBytes::new(py, &stl),
        (v.into_pyarray(py), f.into_pyarray(py), info),
    ))
}

/// A grasp to check as given: palm position `[mm]` and quaternion (`w, x, y, z`) in the
/// object's file frame, `[θ1, θ2]` per finger `[deg]`, and the axis name gravity refers to.
type Given = ([f64; 3], [f64; 4], Vec<[f64; 2]>, Option<String>);

/// A scenario given as JSON (a table per section, as its TOML would have it): converted to
/// TOML and parsed by `Scenario::parse` with `label` as its path.
fn scenario_of_json(scenario_json: &str, label: &std::path::Path) -> PyResult<Scenario> {
    let table: toml::Table = serde_json::from_str(scenario_json).map_err(|e| {
        BadScenarioError::new_err(format!("{}: not a scenario table: {e}", label.display()))
    })?;
    let text = toml::to_string(&table).map_err(|e| {
        BadScenarioError::new_err(format!(
            "{}: cannot be written as TOML: {e}",
            label.display()
        ))
    })?;
    Scenario::parse(&text, label).map_err(scenario_err)
}

/// Run flags as the command line's.
fn options(
    no_sim: bool,
    payload: bool,
    quality: bool,
    candidates: usize,
    max_checked: Option<usize>,
) -> RunOptions {
    let mut o = RunOptions::from(RunFlags {
        no_sim,
        payload,
        quality,
    });
    o.candidates = candidates.max(1);
    o.max_checked = max_checked;
    o
}

/// Runs a scenario given as JSON (a table per section, as its TOML would have it): converted
/// to TOML and parsed by `Scenario::parse` with `label` as its path, then run. Returns the run's
/// JSON line (`--json`).
///
/// `given` (position `[mm]`, quaternion `wxyz`, `[θ1, θ2]` per finger, axis name): check this
/// grasp instead of the planner's (`RunOptions::given`).
#[pyfunction]
#[pyo3(signature = (scenario_json, label, no_sim=false, payload=false, quality=false, candidates=1, max_checked=None, given=None))]
#[allow(clippy::too_many_arguments)]
fn run_table(
    py: Python<'_>,
    scenario_json: String,
    label: PathBuf,
    no_sim: bool,
    payload: bool,
    quality: bool,
    candidates: usize,
    max_checked: Option<usize>,
    given: Option<Given>,
) -> PyResult<String> {
    let what = label.display().to_string();
    detached(py, &what, move || {
        let scenario = scenario_of_json(&scenario_json, &label)?;
        let mut o = options(no_sim, payload, quality, candidates, max_checked);
        o.given = given.map(|(position_mm, quaternion_wxyz, theta_deg, axis_name)| {
            grasp_sim::GivenGrasp {
                position_mm,
                quaternion_wxyz,
                theta_deg,
                axis_name,
            }
        });
        let report = pipeline::run(&scenario, &o).map_err(pipeline_err)?;
        to_rounded_json(&report).map_err(|e| GraspSimError::new_err(e.to_string()))
    })
}

/// Checks given grasp lines (`label` / `check --grasps` input: one JSON object each) on the
/// scenario given as JSON (as [`run_table`]'s), `samples` perturbed checks each; returns one
/// record per line, in line order (an error record for a line that cannot be checked), as
/// `grasp-sim check --grasps` writes them.
#[pyfunction]
#[pyo3(signature = (scenario_json, label, lines, samples))]
fn check_lines_table(
    py: Python<'_>,
    scenario_json: String,
    label: PathBuf,
    lines: Vec<String>,
    samples: usize,
) -> PyResult<Vec<String>> {
    let what = label.display().to_string();
    detached(py, &what, move || {
        let scenario = scenario_of_json(&scenario_json, &label)?;
        let n = lines.len();
        let given: Vec<Result<String, String>> = lines.into_iter().map(Ok).collect();
        let info = |_: usize, wall_ms: f64| grasp_sim::label::LabelInfo {
            input: label.display().to_string(),
            input_hash: String::new(),
            grasps: n,
            wall_ms,
        };
        let out = std::sync::Mutex::new(Vec::new());
        let emit = |l: grasp_sim::label::Line| {
            out.lock().unwrap_or_else(|p| p.into_inner()).push(l);
        };
        grasp_sim::label::check_lines(&scenario, &given, samples.max(1), &info, &emit)
            .map_err(pipeline_err)?;
        let mut records = out.into_inner().unwrap_or_else(|p| p.into_inner());
        records.sort_by_key(|l| l.order);
        Ok(records.into_iter().map(|l| l.text).collect())
    })
}

/// Runs a scenario file (or a bare mesh with the built-in template, in `units`) exactly as
/// `grasp-sim --json PATH` does; returns its JSON line. Errors carry the CLI's line.
#[pyfunction]
#[pyo3(signature = (path, units="mm", gravity=None, no_sim=false, payload=false, quality=false, candidates=1))]
#[allow(clippy::too_many_arguments)]
fn run_file(
    py: Python<'_>,
    path: PathBuf,
    units: &str,
    gravity: Option<&str>,
    no_sim: bool,
    payload: bool,
    quality: bool,
    candidates: usize,
) -> PyResult<String> {
    let unit = unit(units)?;
    let gravity = match gravity {
        None => None,
        Some("down") => Some(GravityMode::Down),
        Some("six") => Some(GravityMode::Six),
        Some(g) => {
            return Err(BadInputError::new_err(format!(
                "gravity: \"{g}\" is neither \"down\" nor \"six\""
            )))
        }
    };
    detached(py, &path.display().to_string(), move || {
        let item = match MeshFormat::from_path(&path) {
            Some(_) => Item::Mesh(path.clone()),
            None => Item::Scenario(path.clone()),
        };
        let mut template = batch::default_template();
        template.object.units = unit;
        let o = options(no_sim, payload, quality, candidates, None);
        let ran = batch::scenario_for(&item, &template).and_then(|mut s| {
            if let Some(g) = gravity {
                s.sim.gravity = g;
            }
            pipeline::run(&s, &o)
        });
        match ran {
            Ok(report) => {
                to_rounded_json(&report).map_err(|e| GraspSimError::new_err(e.to_string()))
            }
            Err(e) => {
                let line = pipeline::inputs::error_line(&item, &path, &e);
                Err(pipeline_err_with(&e, line))
            }
        }
    })
}

/// What the batch thread sends: a finished object's line, or the end (with an error that
/// stopped the writing of the results file).
enum Message {
    Line { message: String, line: String },
    End(Option<String>),
}

/// `INPUT: feasible hold`, `INPUT: error`: the command line's progress message.
fn outcome_message(input: &str, record: &Record) -> String {
    let word = match record.error() {
        Some(_) => "error".to_string(),
        None => format!(
            "{} {}",
            record.view.plan.status.as_deref().unwrap_or("?"),
            record.view.sim.verdict.as_deref().unwrap_or("?")
        ),
    };
    format!("{input}: {word}")
}

/// A batch running on a thread of its own (in-process, `jobs` objects at once); iterating it
/// gives `(done, total, message, line)` for each object as it finishes, the GIL released while
/// it waits.
#[pyclass(module = "grasp_sim._native")]
struct Batch {
    rx: Mutex<Option<mpsc::Receiver<Message>>>,
    done: Mutex<usize>,
    total: usize,
}

#[pymethods]
impl Batch {
    #[new]
    #[pyo3(signature = (inputs, jobs=None, out=None, resume=false, no_sim=false, payload=false, quality=false, units=None, template=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        inputs: Vec<PathBuf>,
        jobs: Option<usize>,
        out: Option<PathBuf>,
        resume: bool,
        no_sim: bool,
        payload: bool,
        quality: bool,
        units: Option<&str>,
        template: Option<PathBuf>,
    ) -> PyResult<Batch> {
        let units = units.map(unit).transpose()?;
        if resume && out.is_none() {
            return Err(BadInputError::new_err(
                "resume: needs `out`, the results file to resume".to_string(),
            ));
        }
        let (rx, total) = detached(py, "batch", move || {
            start_batch(
                inputs,
                jobs,
                out,
                resume,
                (no_sim, payload, quality),
                units,
                template,
            )
        })?;
        Ok(Batch {
            rx: Mutex::new(Some(rx)),
            done: Mutex::new(0),
            total,
        })
    }

    /// How many objects the batch has, those kept from `out` included.
    #[getter]
    fn total(&self) -> usize {
        self.total
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<(usize, usize, String, String)>> {
        loop {
            // Short waits without the GIL, so Ctrl-C (a pending signal) is seen between them.
            // (The receiver is not `Sync`: it is reached through its mutex inside the wait.)
            let got = py.detach(|| {
                let guard = self.rx.lock().unwrap_or_else(|p| p.into_inner());
                guard
                    .as_ref()
                    .map(|rx| rx.recv_timeout(Duration::from_millis(100)))
            });
            match got {
                None => return Ok(None),
                Some(Ok(Message::Line { message, line })) => {
                    let mut done = self.done.lock().unwrap_or_else(|p| p.into_inner());
                    *done += 1;
                    return Ok(Some((*done, self.total, message, line)));
                }
                Some(Ok(Message::End(error))) => {
                    self.close();
                    return match error {
                        Some(e) => Err(GraspSimError::new_err(e)),
                        None => Ok(None),
                    };
                }
                Some(Err(mpsc::RecvTimeoutError::Timeout)) => py.check_signals()?,
                Some(Err(mpsc::RecvTimeoutError::Disconnected)) => {
                    self.close();
                    return Err(GraspSimError::new_err(
                        "batch: the batch thread ended without finishing".to_string(),
                    ));
                }
            }
        }
    }
}

impl Batch {
    /// No more results: later calls to `__next__` end the iteration.
    fn close(&self) {
        *self.rx.lock().unwrap_or_else(|p| p.into_inner()) = None;
    }
}

/// Expands the inputs, opens the results file (resumed), and starts the thread that runs what
/// is left; returns the receiving end and the number of objects.
fn start_batch(
    inputs: Vec<PathBuf>,
    jobs: Option<usize>,
    out: Option<PathBuf>,
    resume: bool,
    (no_sim, payload, quality): (bool, bool, bool),
    units: Option<LengthUnit>,
    template: Option<PathBuf>,
) -> PyResult<(mpsc::Receiver<Message>, usize)> {
    let options = RunOptions::from(RunFlags {
        no_sim,
        payload,
        quality,
    });
    let worker = batch::command::WorkerArgs {
        template,
        units,
        flags: RunFlags {
            no_sim,
            payload,
            quality,
        },
    };
    let template = worker.template().map_err(scenario_err)?;
    if let Some(path) = &out {
        pipeline::check_output_file(path)
            .map_err(|e| BadInputError::new_err(format!("out: {e:#}")))?;
    }
    let items = batch::expand(&inputs).map_err(|e| match e {
        ScenarioError::Io { .. } => BadInputError::new_err(one_line(&e)),
        other => scenario_err(other),
    })?;
    let keys = batch::keys(&items, &template, &options);
    let (journal, mut kept) = match (&out, resume) {
        (Some(path), true) => {
            let (j, read) =
                journal::Journal::open(path).map_err(|e| BadInputError::new_err(one_line(&e)))?;
            let kept: std::collections::HashMap<Key, Record> = read
                .records
                .into_iter()
                .map(|(_, r)| (r.key.clone(), r))
                .collect();
            (Some(j), kept)
        }
        _ => (None, Default::default()),
    };
    // Keep only the lines of current inputs, as the command line does.
    let current: std::collections::HashSet<&Key> = keys.iter().collect();
    kept.retain(|k, _| current.contains(k));
    let total = items.len();
    let jobs = jobs.unwrap_or_else(batch::command::default_jobs).max(1);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for key in &keys {
            if let Some(rec) = kept.get(key) {
                let _ = tx.send(Message::Line {
                    message: format!("{}: kept from the results file", key.input),
                    line: rec.line.clone(),
                });
            }
        }
        let todo: Vec<usize> = (0..items.len())
            .filter(|&i| !kept.contains_key(&keys[i]))
            .collect();
        let run_items: Vec<Item> = todo.iter().map(|&i| items[i].clone()).collect();
        let run_keys: Vec<Key> = todo.iter().map(|&i| keys[i].clone()).collect();
        let append_error = Mutex::new(None::<String>);
        let each = |item: &Item, r: &ItemResult| {
            if let Ok(rec) = r {
                if let Some(j) = &journal {
                    if let Err(e) = j.append(rec) {
                        append_error
                            .lock()
                            .unwrap_or_else(|p| p.into_inner())
                            .get_or_insert(one_line(&e));
                    }
                }
                let _ = tx.send(Message::Line {
                    message: outcome_message(&item.path().display().to_string(), rec),
                    line: rec.line.clone(),
                });
            }
        };
        let results = batch::run_all(
            &run_items,
            &run_keys,
            &template,
            &options,
            jobs,
            &Isolation::InProcess,
            &each,
        );
        for (key, r) in run_keys.into_iter().zip(results) {
            if let Ok(rec) = r {
                kept.insert(key, rec);
            }
        }
        let mut text = String::new();
        for key in &keys {
            if let Some(rec) = kept.get(key) {
                text.push_str(&rec.line);
                text.push('\n');
            }
        }
        let written = match (&out, journal) {
            (Some(_), Some(j)) => j.finish(text.as_bytes()).map_err(|e| one_line(&e)),
            (Some(path), None) => {
                journal::write_atomically(path, text.as_bytes()).map_err(|e| one_line(&e))
            }
            (None, _) => Ok(()),
        };
        let error = append_error
            .into_inner()
            .unwrap_or_else(|p| p.into_inner())
            .or(written.err());
        let _ = tx.send(Message::End(error));
    });
    Ok((rx, total))
}

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("GraspSimError", py.get_type::<GraspSimError>())?;
    m.add("BadInputError", py.get_type::<BadInputError>())?;
    m.add("BadScenarioError", py.get_type::<BadScenarioError>())?;
    m.add("BadHandError", py.get_type::<BadHandError>())?;
    m.add("VERSION", env!("CARGO_PKG_VERSION"))?;
    // The library's test hooks (`GRASP_SIM_TEST_FAULT`) exist in debug builds only.
    m.add("DEBUG_BUILD", cfg!(debug_assertions))?;
    m.add_function(wrap_pyfunction!(load_hand, m)?)?;
    m.add_function(wrap_pyfunction!(load_mesh_file, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_from_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(run_table, m)?)?;
    m.add_function(wrap_pyfunction!(run_file, m)?)?;
    m.add_function(wrap_pyfunction!(check_lines_table, m)?)?;
    m.add_class::<Batch>()?;
    Ok(())
}
