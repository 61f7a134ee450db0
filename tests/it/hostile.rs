//! Hostile inputs (issue 32): each class gets exit 2 and one line naming the problem, or the
//! right answer, and never a panic, a hang or a memory blow-up. Each test builds its input.

use crate::grasp_sim;

/// The one line on stderr of a run that must exit 2, checked to contain every needle.
fn refused(out: &std::process::Output, needles: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
    err
}

/// Three sweeps of 1000 values each are each within the per-sweep cap, but their product (10⁹
/// settings) would be held in memory: refused before anything is loaded, the product stated.
#[test]
fn a_tune_grid_too_large_in_product_is_refused() {
    let out_dir = tempfile::tempdir().unwrap();
    let out = grasp_sim()
        .args([
            "tune",
            "--param",
            "sf_c=0:999:1",
            "--param",
            "height_step_mm=1:1000:1",
            "--param",
            "angular_step_deg=1:1000:1",
            "--out",
        ])
        .arg(out_dir.path())
        .arg("scenarios/cup.toml")
        .output()
        .unwrap();
    refused(
        &out,
        &["1000000000 settings", "1000 x 1000 x 1000", "at most 10000"],
    );
    assert_eq!(std::fs::read_dir(out_dir.path()).unwrap().count(), 0);
}

/// An input past the time bound per input is an error line, and the next input still runs:
/// with a bound of a millisecond every input here (the six-direction check with the payload
/// search, seconds each) is past it, each named on its own line.
#[test]
fn an_input_past_the_time_bound_is_an_error_line_and_the_next_still_runs() {
    let out = grasp_sim()
        .args(["--gravity", "six", "--payload", "--time-limit", "0.001"])
        .args(["scenarios/cup.toml", "scenarios/cylinder_d40.toml"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 2, "{err}");
    for (line, name) in lines.iter().zip(["cup.toml", "cylinder_d40.toml"]) {
        assert!(
            line.contains(name) && line.contains("no result within 0.001 s"),
            "{line}"
        );
    }
    assert!(out.stdout.is_empty());
    // The default bound is far above a normal run: the same inputs run and print.
    let out = grasp_sim()
        .args(["--no-sim", "scenarios/cup.toml"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
}
