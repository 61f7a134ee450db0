//! One object's line in a batch's JSON Lines output, and what identifies it for `--resume` and
//! `--merge`: the input's path as the batch saw it and a hash of everything that decides its
//! result.
//!
//! A line is the run report (DESIGN.md §6) or `{"scenario", "error"}` for an object that could
//! not be run, plus `"batch": {"input", "input_hash", "wall_ms"}`. The hash covers the scenario
//! file's text, the scenario as parsed (so the hand file and, for a bare mesh, the template and
//! units are in it), the mesh file's bytes, the run options (as JSON) and the grasp-sim
//! version: an input edited since its line was written does not match it and is run again.

use super::Item;
use crate::report::{to_rounded_json, ErrorView, RecordView, RunReport};
use crate::scenario::Scenario;
use crate::RunOptions;
use serde::Serialize;
use sha2::{Digest, Sha256};

/// What identifies an object's line: its input and the hash of what decides its result.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Key {
    /// The input path as the batch saw it (a folder's entries as `folder/name`).
    pub input: String,
    /// `sha256:` and the hex digest (see the module docs for what it covers).
    pub input_hash: String,
}

/// What a batch adds to each line, under `"batch"`.
#[derive(Debug, Clone, Serialize)]
pub struct BatchInfo {
    /// The input path as the batch saw it.
    pub input: String,
    /// See [`Key::input_hash`].
    pub input_hash: String,
    /// Wall time of this object's run `[ms]`: a timing, different run to run (as
    /// `plan.timings_ms` and `sim.wall_ms`).
    pub wall_ms: f64,
}

/// Why a line is not a batch record.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RecordError {
    /// Not JSON, or too long to read: the parser's message, or the length.
    #[error("{0}")]
    NotJson(String),
    /// JSON without `batch.<field>`.
    #[error("no `batch.{0}` (not a line written by `batch`)")]
    NoBatchField(&'static str),
}

/// One object's line, kept as the text written (so a line read back from a file is written
/// again byte for byte) and as read back ([`RecordView`], to count outcomes).
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// What the line belongs to.
    pub key: Key,
    /// The JSON object, one line, no newline.
    pub line: String,
    /// The same, read back: what the readers use.
    pub view: RecordView,
}

#[derive(Serialize)]
struct ReportLine<'a> {
    #[serde(flatten)]
    report: &'a RunReport,
    batch: &'a BatchInfo,
}

#[derive(Serialize)]
struct ErrorLine<'a> {
    scenario: &'a str,
    error: &'a str,
    batch: &'a BatchInfo,
}

impl Record {
    /// The line of a run that finished (numbers rounded as `--json` rounds them).
    pub fn from_report(report: &RunReport, batch: BatchInfo) -> Record {
        match to_rounded_json(&ReportLine {
            report,
            batch: &batch,
        }) {
            Ok(line) => Record::from_line(line, &batch),
            Err(e) => Record::from_error(
                &report.scenario,
                &format!("cannot write the report as JSON: {e}"),
                batch,
            ),
        }
    }

    /// The line of an object that could not be run: `scenario` names it (its path), `error`
    /// says why in one line.
    pub fn from_error(scenario: &str, error: &str, batch: BatchInfo) -> Record {
        let error = error.replace('\n', " ");
        let line = to_rounded_json(&ErrorLine {
            scenario,
            error: &error,
            batch: &batch,
        })
        .unwrap_or_else(|_| {
            // Serializing strings and a number cannot fail; keep a valid line regardless.
            serde_json::json!({"scenario": scenario, "error": error}).to_string()
        });
        Record::from_line(line, &batch)
    }

    fn from_line(line: String, batch: &BatchInfo) -> Record {
        let value = serde_json::from_str(&line).unwrap_or(serde_json::Value::Null);
        Record {
            key: Key {
                input: batch.input.clone(),
                input_hash: batch.input_hash.clone(),
            },
            line,
            view: RecordView::of(&value),
        }
    }

    /// Reads a line written by a batch: a JSON object with `batch.input` and
    /// `batch.input_hash`.
    ///
    /// # Errors
    /// [`RecordError`]: what is wrong with the line.
    pub fn parse(line: &str) -> Result<Record, RecordError> {
        let value = crate::files::parse_json_line(line).map_err(RecordError::NotJson)?;
        let view = RecordView::of(&value);
        let key = Key {
            input: (view.batch.input.clone()).ok_or(RecordError::NoBatchField("input"))?,
            input_hash: (view.batch.input_hash.clone())
                .ok_or(RecordError::NoBatchField("input_hash"))?,
        };
        Ok(Record {
            key,
            line: line.to_string(),
            view,
        })
    }

    /// The error, when the object could not be run.
    pub fn error(&self) -> Option<&str> {
        self.view.error.as_ref().and_then(ErrorView::as_str)
    }
}

/// The run options that decide a result, as hashed: every field of [`RunOptions`] but
/// `folder` (where the outputs go does not change what is computed), the paths as their bytes
/// (so that any path, UTF-8 or not, serializes). A field added to `RunOptions` that changes
/// results belongs here.
#[derive(Serialize)]
struct HashedOptions<'a> {
    no_sim: bool,
    payload: bool,
    quality: bool,
    candidates: usize,
    max_checked: Option<usize>,
    export_mjcf: Option<&'a [u8]>,
    export_urdf: Option<&'a [u8]>,
    report: Option<&'a [u8]>,
}

/// `options` as hashed: [`HashedOptions`] as JSON.
fn options_json<'a>(options: &'a RunOptions) -> Vec<u8> {
    let RunOptions {
        no_sim,
        payload,
        quality,
        candidates,
        max_checked,
        ref export_mjcf,
        ref export_urdf,
        ref report,
        folder: _,
        // Batch never checks a given grasp (the library's and Python's `check` do).
        given: _,
    } = *options;
    let bytes =
        |p: &'a Option<std::path::PathBuf>| p.as_ref().map(|p| p.as_os_str().as_encoded_bytes());
    let hashed = HashedOptions {
        no_sim,
        payload,
        quality,
        candidates,
        max_checked,
        export_mjcf: bytes(export_mjcf),
        export_urdf: bytes(export_urdf),
        report: bytes(report),
    };
    // Booleans, numbers and lists of bytes: serializing them cannot fail.
    serde_json::to_vec(&hashed).unwrap_or_default()
}

/// Feeds the file at `path` to `h` as it is read (regular files of at most `limit` bytes only,
/// as loading reads them: a FIFO or `/dev/zero` never blocks the hash), then its length; or, when
/// it cannot be read, why.
fn stream_file(h: &mut Sha256, label: &str, path: &std::path::Path, limit: u64) {
    h.update(label.as_bytes());
    match crate::files::stream_regular(path, limit, &mut |b| h.update(b)) {
        Ok(n) => h.update(n.to_le_bytes()),
        Err(e) => {
            h.update(b" unreadable: ");
            h.update(e.to_string().as_bytes());
        }
    }
}

/// The hash of everything that decides an item's result (see the module docs), as
/// `sha256:<hex>`.
pub fn input_hash(item: &Item, template: &Scenario, options: &RunOptions) -> String {
    let mut h = Sha256::new();
    let mut part = |label: &str, bytes: &[u8]| {
        h.update(label.as_bytes());
        h.update((bytes.len() as u64).to_le_bytes());
        h.update(bytes);
    };
    part("grasp-sim", env!("CARGO_PKG_VERSION").as_bytes());
    part("options", &options_json(options));
    let scenario = super::scenario_for(item, template);
    // The scenario file, as bytes; and the parsed scenario: its hand (file contents parsed),
    // and for a mesh the template, serialised (a path that is not UTF-8 cannot be: then its
    // Debug text).
    let parsed = match &scenario {
        Ok(s) => serde_json::to_vec(s).unwrap_or_else(|_| format!("{s:?}").into_bytes()),
        Err(e) => format!("{e:#}").into_bytes(),
    };
    part(
        if scenario.is_ok() {
            "scenario"
        } else {
            "scenario error"
        },
        &parsed,
    );
    if let Item::Scenario(p) = item {
        stream_file(&mut h, "scenario file", p, crate::files::MAX_TEXT_BYTES);
    }
    if let Ok(s) = &scenario {
        stream_file(&mut h, "mesh", &s.object.mesh, crate::files::MAX_MESH_BYTES);
        // A URDF's object is its meshes too.
        if crate::mesh::MeshFormat::from_path(&s.object.mesh) == Some(crate::mesh::MeshFormat::Urdf)
        {
            for f in crate::mesh::urdf::referenced_files(&s.object.mesh) {
                stream_file(&mut h, "urdf mesh", &f, crate::files::MAX_MESH_BYTES);
            }
        }
    }
    let digest = h.finalize();
    let mut hex = String::with_capacity(7 + 64);
    hex.push_str("sha256:");
    for b in digest {
        hex.push_str(&format!("{b:02x}"));
    }
    hex
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(input: &str) -> BatchInfo {
        BatchInfo {
            input: input.to_string(),
            input_hash: "sha256:00".to_string(),
            wall_ms: 1.25,
        }
    }

    #[test]
    fn error_lines_read_back() {
        let r = Record::from_error("a/b.stl", "bad\nmesh", info("a/b.stl"));
        assert_eq!(
            r.line,
            r#"{"scenario":"a/b.stl","error":"bad mesh","batch":{"input":"a/b.stl","input_hash":"sha256:00","wall_ms":1.25}}"#
        );
        let back = Record::parse(&r.line).unwrap();
        assert_eq!(back, r);
        assert_eq!(back.error(), Some("bad mesh"));
    }

    #[test]
    fn lines_without_batch_fields_are_refused() {
        for (line, why) in [
            ("{\"scenario\":\"x\"}", "no `batch.input`"),
            ("{\"batch\":{\"input\":\"x\"}}", "no `batch.input_hash`"),
            ("{\"batch\":", "not JSON"),
            ("[1,2]", "no `batch.input`"),
        ] {
            let e = Record::parse(line).unwrap_err().to_string();
            assert!(e.contains(why), "{line}: {e}");
        }
    }

    #[test]
    fn the_hash_follows_the_mesh_bytes_and_the_options() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = dir.path().join("m.stl");
        std::fs::write(&mesh, b"solid a\nendsolid a\n").unwrap();
        let item = Item::Mesh(mesh.clone());
        let template = super::super::default_template();
        let opts = RunOptions::default();
        let h1 = input_hash(&item, &template, &opts);
        assert!(h1.starts_with("sha256:") && h1.len() == 71, "{h1}");
        assert_eq!(h1, input_hash(&item, &template, &opts));
        std::fs::write(&mesh, b"solid b\nendsolid b\n").unwrap();
        let h2 = input_hash(&item, &template, &opts);
        assert_ne!(h1, h2);
        let no_sim = RunOptions {
            no_sim: true,
            ..RunOptions::default()
        };
        assert_ne!(h2, input_hash(&item, &template, &no_sim));
        // Where the outputs go does not decide the result.
        let elsewhere = RunOptions {
            folder: Some("elsewhere".to_string()),
            ..RunOptions::default()
        };
        assert_eq!(h2, input_hash(&item, &template, &elsewhere));
        let mut inch = template.clone();
        inch.object.units = crate::mesh::LengthUnit::Inch;
        assert_ne!(h2, input_hash(&item, &inch, &opts));
        // A setting deep in a group of the serialised scenario counts, and so does the hand.
        let mut step = template.clone();
        step.sim.solver.timestep_s *= 0.5;
        assert_ne!(h2, input_hash(&item, &step, &opts));
        let mut hand = template.clone();
        hand.hand.palm.offset_mm += 1.0;
        assert_ne!(h2, input_hash(&item, &hand, &opts));
    }
}
