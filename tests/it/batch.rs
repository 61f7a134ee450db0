//! `grasp-sim batch`: stable order across thread counts, shards that concatenate to the whole,
//! and an output file written whole.

fn batch(args: &[&str]) -> (Option<i32>, String, String) {
    let out = crate::grasp_sim().arg("batch").args(args).output().unwrap();
    (
        out.status.code(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// JSON lines with the wall-clock fields removed (the only ones allowed to differ).
fn stable(text: &str) -> Vec<serde_json::Value> {
    text.lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            v["plan"]["timings_ms"] = serde_json::Value::Null;
            v["sim"]["wall_ms"] = serde_json::Value::Null;
            v["batch"]["wall_ms"] = serde_json::Value::Null;
            v
        })
        .collect()
}

#[test]
fn jobs_and_shards_do_not_change_the_output() {
    let (code, one, err) = batch(&["--no-sim", "--jobs", "1", "assets/objects"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("batch: 7 objects") && err.contains("6 planned, 1 ungraspable"),
        "{err}"
    );
    let (_, two, _) = batch(&["--no-sim", "--jobs", "2", "assets/objects"]);
    let one = stable(&one);
    assert_eq!(one.len(), 7);
    assert_eq!(one, stable(&two));
    // Input order: the folder's files sorted by path.
    let names: Vec<&str> = one
        .iter()
        .map(|v| v["scenario"].as_str().unwrap())
        .collect();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(names, sorted);
    let mut joined = Vec::new();
    for k in 1..=3 {
        let (code, text, err) =
            batch(&["--no-sim", "--shard", &format!("{k}/3"), "assets/objects"]);
        assert_eq!(code, Some(0), "{err}");
        joined.extend(stable(&text));
    }
    assert_eq!(joined, one);
}

#[test]
fn out_file_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.stl"), b"not a mesh").unwrap();
    std::fs::copy(
        crate::root().join("assets/objects/cylinder_d40.stl"),
        dir.path().join("good.stl"),
    )
    .unwrap();
    let out = dir.path().join("results.jsonl");
    let (code, stdout, err) = batch(&[
        "--no-sim",
        "--out",
        out.to_str().unwrap(),
        dir.path().to_str().unwrap(),
    ]);
    // A bad mesh is reported on its own line and in the summary; the batch still finishes.
    assert_eq!(code, Some(2), "{err}");
    assert!(stdout.is_empty());
    assert!(
        err.contains("bad.stl") && err.contains("1 error;") || err.ends_with("1 error\n"),
        "{err}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    assert!(lines[0]["error"].as_str().unwrap().contains("not an STL"));
    assert_eq!(lines[1]["plan"]["status"], "feasible");
    let (code, _, err) = batch(&["--shard", "3/2", "assets/objects"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("K <= N"), "{err}");
}

/// Issue 16 item 2: batch exits 1 when an expectation fails (as the scenario alone does), counts
/// expectations met / not met, and does not judge bare meshes.
#[test]
fn batch_exit_codes_and_expectation_counts() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = crate::root().join("assets/objects/cylinder_d40.stl");
    std::fs::copy(&mesh, dir.path().join("d40.stl")).unwrap();
    let wrong = dir.path().join("wrong.toml");
    std::fs::write(
        &wrong,
        "[object]\nmesh = \"d40.stl\"\n[expect]\noutcome = \"ungraspable\"\n",
    )
    .unwrap();
    let bare = dir.path().join("d40.stl");
    let (code, stdout, err) = batch(&["--no-sim", wrong.to_str().unwrap(), bare.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("expectations: 0 met, 1 not met, 1 not judged"),
        "{err}"
    );
    let lines: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines[0]["expect"]["met"], false);
    assert!(
        lines[1]["expect"]["met"].is_null(),
        "bare mesh judged: {}",
        lines[1]["expect"]
    );
    assert!(
        err.contains("batch: 2 objects") && err.contains("0 errors"),
        "{err}"
    );
    let (code, _, err) = batch(&["--no-sim", "--jobs", "1", bare.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("batch: 1 object in") && err.contains(", 1 job)"),
        "{err}"
    );
    let help = crate::grasp_sim()
        .args(["batch", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("Exit status: 0") && help.contains("1 an expectation not"),
        "{help}"
    );
}

/// Issue 16 item 3: an --out that cannot be written fails before anything runs.
#[test]
fn batch_checks_its_output_file_first() {
    let (code, stdout, err) =
        batch(&["--no-sim", "--out", "no/such/dir/x.jsonl", "assets/objects"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(stdout.is_empty());
    assert_eq!(err.lines().count(), 1, "work started: {err}");
    assert!(
        err.contains("--out") && err.contains("no/such/dir"),
        "{err}"
    );
}

/// Issue 16 item 7: a hand file lying in a folder of scenarios is not run as a scenario.
#[test]
fn batch_skips_hand_files_in_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        crate::root().join("assets/objects/cylinder_d40.stl"),
        dir.path().join("d40.stl"),
    )
    .unwrap();
    std::fs::copy(
        crate::root().join("assets/hands/thesis.toml"),
        dir.path().join("hand.toml"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("s.toml"),
        "[object]\nmesh = \"d40.stl\"\n[hand]\nfile = \"hand.toml\"\n",
    )
    .unwrap();
    let (code, stdout, err) = batch(&["--no-sim", dir.path().to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    assert!(err.contains("0 errors"), "{err}");
}
