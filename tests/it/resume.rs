//! Issue 19: `batch --resume` after a real kill, edited inputs run again, and `--merge` of
//! shard files with its check.

use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};

/// JSON lines with the timings removed (the only fields allowed to differ run to run).
pub fn stable(text: &str) -> Vec<serde_json::Value> {
    text.lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            if v.get("plan").is_some() {
                v["plan"]["timings_ms"] = serde_json::Value::Null;
                v["sim"]["wall_ms"] = serde_json::Value::Null;
            }
            v["batch"]["wall_ms"] = serde_json::Value::Null;
            v
        })
        .collect()
}

fn run(args: &[&str]) -> Output {
    crate::grasp_sim().args(args).output().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A folder of the thesis objects and the tuning set's meshes: 15 bare meshes.
pub fn fifteen_meshes(dir: &Path) -> PathBuf {
    let data = dir.join("objects");
    std::fs::create_dir_all(&data).unwrap();
    for sub in ["assets/objects", "assets/objects/train"] {
        for e in std::fs::read_dir(crate::root().join(sub)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "stl") {
                std::fs::copy(&p, data.join(p.file_name().unwrap())).unwrap();
            }
        }
    }
    data
}

fn complete_lines(path: &Path) -> Vec<String> {
    let t = std::fs::read_to_string(path).unwrap_or_default();
    match t.rfind('\n') {
        Some(i) => t[..i].lines().map(str::to_string).collect(),
        None => Vec::new(),
    }
}

#[test]
fn a_killed_batch_resumes_to_the_uninterrupted_file() {
    let dir = tempfile::tempdir().unwrap();
    let data = fifteen_meshes(dir.path());
    let out = dir.path().join("results.jsonl");
    let (d, o) = (data.to_str().unwrap(), out.to_str().unwrap());
    let mut child = crate::grasp_sim()
        .args([
            "batch", "--no-sim", "--jobs", "1", "--resume", "--out", o, d,
        ])
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while complete_lines(&out).len() < 3 {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the batch finished before it could be killed"
        );
        assert!(t0.elapsed().as_secs() < 120, "no progress in 120 s");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL: no chance to tidy up
    child.wait().unwrap();
    let before = complete_lines(&out);
    assert!(
        (3..15).contains(&before.len()),
        "{} lines at the kill",
        before.len()
    );
    #[cfg(target_os = "linux")]
    {
        // The workers die with the batch (parent-death signal).
        std::thread::sleep(std::time::Duration::from_millis(200));
        let left: Vec<String> = std::fs::read_dir("/proc")
            .unwrap()
            .filter_map(|e| std::fs::read(e.ok()?.path().join("cmdline")).ok())
            .map(|c| String::from_utf8_lossy(&c).replace('\0', " "))
            .filter(|c| c.contains("batch-worker") && c.contains(d))
            .collect();
        assert!(left.is_empty(), "workers outlived the batch: {left:?}");
    }
    // A torn write, as a crash in the middle of one would leave: no newline.
    {
        use std::io::Write;
        let mut f = std::fs::OpenOptions::new().append(true).open(&out).unwrap();
        f.write_all(b"{\"scenario\":\"torn\",\"obj").unwrap();
    }
    // A reader takes the whole lines only.
    let s = run(&["summarize", o]);
    assert_eq!(s.status.code(), Some(0), "{}", text(&s.stderr));
    assert!(
        text(&s.stdout).contains(&format!("{} objects", before.len())),
        "{}",
        text(&s.stdout)
    );
    assert!(
        text(&s.stderr).contains("partial last line"),
        "{}",
        text(&s.stderr)
    );

    let resumed = run(&[
        "batch", "--no-sim", "--jobs", "2", "--resume", "--out", o, d,
    ]);
    let err = text(&resumed.stderr);
    assert_eq!(resumed.status.code(), Some(0), "{err}");
    assert!(err.contains("cut off a partial last line"), "{err}");
    assert!(
        err.contains(&format!(
            "resume: {} of 15 objects already in {o}; running {}",
            before.len(),
            15 - before.len()
        )),
        "{err}"
    );
    let after = std::fs::read_to_string(&out).unwrap();
    // The lines written before the kill are kept as they were, not run again.
    for l in &before {
        assert!(after.lines().any(|a| a == l), "lost or rewritten: {l}");
    }
    let plain = run(&["batch", "--no-sim", d]);
    assert_eq!(plain.status.code(), Some(0), "{}", text(&plain.stderr));
    let plain = stable(&text(&plain.stdout));
    assert_eq!(plain.len(), 15);
    assert_eq!(stable(&after), plain, "resumed file differs from one run");
}

#[test]
fn resume_runs_edited_inputs_again_and_keeps_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("objects");
    std::fs::create_dir_all(&data).unwrap();
    let objects = crate::root().join("assets/objects");
    for name in ["cup.stl", "cylinder_d40.stl", "prism.stl"] {
        std::fs::copy(objects.join(name), data.join(name)).unwrap();
    }
    let out = dir.path().join("r.jsonl");
    let (d, o) = (data.to_str().unwrap(), out.to_str().unwrap());
    let args = ["batch", "--no-sim", "--resume", "--out", o, d];
    let first = run(&args);
    assert_eq!(first.status.code(), Some(0), "{}", text(&first.stderr));
    let one = std::fs::read_to_string(&out).unwrap();
    assert_eq!(one.lines().count(), 3);
    // Nothing changed: nothing runs, and the file is the same, byte for byte.
    let again = run(&args);
    assert!(
        text(&again.stderr).contains("3 of 3 objects already"),
        "{}",
        text(&again.stderr)
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), one);
    // The prism's mesh replaced by the chapter 4 object: that input alone runs again.
    std::fs::copy(objects.join("chapter4.stl"), data.join("prism.stl")).unwrap();
    let edited = run(&args);
    let err = text(&edited.stderr);
    assert!(
        err.contains("2 of 3 objects already") && err.contains("running 1"),
        "{err}"
    );
    assert!(err.contains("dropped 1 line for no current input"), "{err}");
    let two = std::fs::read_to_string(&out).unwrap();
    let (l1, l2): (Vec<&str>, Vec<&str>) = (one.lines().collect(), two.lines().collect());
    assert_eq!(l1[..2], l2[..2]);
    let prism: serde_json::Value = serde_json::from_str(l2[2]).unwrap();
    assert_eq!(prism["object"]["triangles"], 2336, "{}", prism["object"]);
    // Other flags are other results: without --no-sim every object runs again.
    let sim = run(&["batch", "--resume", "--out", o, "--jobs", "2", d]);
    assert!(
        text(&sim.stderr).contains("0 of 3 objects already"),
        "{}",
        text(&sim.stderr)
    );
    // An error line counts as done (the same input gives the same error) until
    // --retry-errors.
    std::fs::write(data.join("bad.stl"), b"not a mesh").unwrap();
    let bad = run(&args);
    assert_eq!(bad.status.code(), Some(2));
    let skip = run(&args);
    assert_eq!(skip.status.code(), Some(2), "the file still holds an error");
    assert!(text(&skip.stderr).contains("4 of 4 objects already"));
    let retry = run(&[
        "batch",
        "--no-sim",
        "--resume",
        "--retry-errors",
        "--out",
        o,
        d,
    ]);
    assert!(
        text(&retry.stderr).contains("3 of 4 objects already"),
        "{}",
        text(&retry.stderr)
    );
}

#[test]
fn resume_refuses_a_file_it_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let notes = dir.path().join("notes.jsonl");
    std::fs::write(&notes, "{\"scenario\":\"mine\"}\n").unwrap();
    let o = notes.to_str().unwrap();
    let r = run(&[
        "batch",
        "--no-sim",
        "--resume",
        "--out",
        o,
        "assets/objects/cup.stl",
    ]);
    let err = text(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("notes.jsonl: line 1 is not a batch record"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(&notes).unwrap(),
        "{\"scenario\":\"mine\"}\n"
    );
    let r = run(&["batch", "--resume", "assets/objects/cup.stl"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(text(&r.stderr).contains("--out"), "{}", text(&r.stderr));
}

#[test]
fn shard_files_merge_in_input_order_and_the_check_catches_gaps() {
    let dir = tempfile::tempdir().unwrap();
    let shards = dir.path().join("shards");
    std::fs::create_dir_all(&shards).unwrap();
    for k in 1..=3 {
        let f = shards.join(format!("s{k}.jsonl"));
        let r = run(&[
            "batch",
            "--no-sim",
            "--shard",
            &format!("{k}/3"),
            "--resume",
            "--out",
            f.to_str().unwrap(),
            "assets/objects",
        ]);
        assert_eq!(r.status.code(), Some(0), "{}", text(&r.stderr));
    }
    let merged = dir.path().join("all.jsonl");
    let m = merged.to_str().unwrap();
    let s = shards.to_str().unwrap();
    let r = run(&[
        "batch",
        "--no-sim",
        "--merge",
        s,
        "--out",
        m,
        "assets/objects",
    ]);
    let err = text(&r.stderr);
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert!(
        err.contains("merge: 7 objects from 3 files, every input exactly once"),
        "{err}"
    );
    let plain = run(&["batch", "--no-sim", "assets/objects"]);
    assert_eq!(
        stable(&std::fs::read_to_string(&merged).unwrap()),
        stable(&text(&plain.stdout))
    );
    // Each check, failing: nothing is written.
    let check = |args: &[&str], expect: &str| {
        let _ = std::fs::remove_file(&merged);
        let mut all = vec!["batch", "--merge", s, "--out", m];
        all.extend_from_slice(args);
        let r = run(&all);
        let err = text(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(
            err.contains("merge check failed") && err.contains(expect),
            "{err}"
        );
        assert!(!merged.exists());
    };
    // Other flags than the shards ran with: every record is stale.
    check(&["assets/objects"], "7 stale");
    std::fs::copy(shards.join("s1.jsonl"), shards.join("s1-again.jsonl")).unwrap();
    check(&["--no-sim", "assets/objects"], "2 duplicated");
    std::fs::remove_file(shards.join("s1-again.jsonl")).unwrap();
    std::fs::remove_file(shards.join("s2.jsonl")).unwrap();
    check(&["--no-sim", "assets/objects"], "2 missing");
    check(&["--no-sim", "assets/objects/cup.stl"], "unknown");
}
