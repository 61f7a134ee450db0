//! Integration tests, one binary so the suite links once.

mod batch;
mod cli;
mod closing;
mod engines;
mod export;
mod formats;
mod frames;
mod fuzz_drive;
mod geometry;
mod hand_files;
mod hostile;
mod isolation;
mod label;
mod order;
mod output_keys;
mod planner;
mod quality;
mod real_meshes;
mod repository;
mod resume;
mod rings;
mod robust;
mod settings;
mod sim;
mod summarize;
mod thesis_table;
mod tune;
mod urdf;
mod visual;

use std::path::PathBuf;

/// The built binary, run from the repository root (bundled scenarios resolve from there).
pub fn grasp_sim() -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_grasp-sim"));
    c.current_dir(root());
    c
}

/// The closing before the default changed on 2026-12-03, ff19c34 (docs/SIM.md "The closing,
/// adopted"): each finger straight at its planned bend plus a 10° squeeze, joint 1 locked where
/// it stopped, no reseat. Tests of mechanisms measured under it use it.
pub fn squeeze_closing() -> grasp_sim::scenario::SimParams {
    let mut params = grasp_sim::scenario::SimParams::default();
    params.closing.approach = grasp_sim::scenario::Approach::Squeeze;
    params.closing.reseat = false;
    params.fingers.squeeze_deg = 10.0;
    params.fingers.squeeze2_deg = 10.0;
    params
}

/// `v` without its wall-clock times (`wall_ms`, `timings_ms`) at any depth: what must be the
/// same, bit for bit, between two runs of the same input.
pub fn timeless(mut v: serde_json::Value) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.remove("wall_ms");
                m.remove("timings_ms");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The text of the real-object scenario `name`, its mesh and hand paths made absolute so that
/// it can be written anywhere.
pub fn real_scenario_text(name: &str) -> String {
    std::fs::read_to_string(root().join(format!("assets/real/scenarios/{name}.toml")))
        .unwrap()
        .replace(
            "\"../meshes/",
            &format!("\"{}/", root().join("assets/real/meshes").display()),
        )
        .replace(
            "\"../../hands/",
            &format!("\"{}/", root().join("assets/hands").display()),
        )
}

/// Runs `cmd` and returns its output, failing the test (with its stderr) unless it exits 0.
pub fn succeed(cmd: &mut std::process::Command) -> std::process::Output {
    let out = cmd.output().unwrap();
    assert_success(&out);
    out
}

/// Fails the test, showing the stderr, unless the process exited with status 0.
pub fn assert_success(out: &std::process::Output) {
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
