//! `grasp-sim label` and `grasp-sim check --grasps` (issue 57): the label records equal single
//! checks of the same grasps, a bad given line gets an error record while the others are
//! checked, and `--resume` after a kill loses no finished grasp.

use crate::{grasp_sim, root};
use serde_json::Value;
use std::path::Path;

/// The lines of a JSON Lines file.
pub(crate) fn lines(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// A line without what differs between runs: its `label` part (input, hash, wall time).
pub(crate) fn without_label(v: &Value) -> Value {
    let mut v = v.clone();
    v.as_object_mut().unwrap().remove("label");
    v
}

/// `label` of `inputs` with `args`, into `out`; the exit status and stderr.
fn label(inputs: &[&Path], args: &[&str], out: &Path) -> (Option<i32>, String) {
    let o = grasp_sim()
        .arg("label")
        .args(inputs)
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// `check --grasps given` on `input` with `samples`, into `out` (stdout if `None`).
fn check(given: &Path, input: &Path, samples: &str, out: Option<&Path>) -> std::process::Output {
    let mut c = grasp_sim();
    c.args(["check", "--samples", samples, "--grasps"])
        .arg(given)
        .arg(input);
    if let Some(out) = out {
        c.arg("--out").arg(out);
    }
    c.output().unwrap()
}

#[test]
fn label_records_equal_single_checks_of_the_same_grasps() {
    let dir = tempfile::tempdir().unwrap();
    let cup = root().join("assets/objects/cup.stl");
    let out = dir.path().join("cup.jsonl");
    let (code, err) = label(
        &[&cup],
        &["--grasps", "5", "--samples", "3", "--in-process"],
        &out,
    );
    assert_eq!(code, Some(0), "{err}");
    let labelled = lines(&out);
    assert_eq!(labelled.len(), 5, "{err}");
    // The first candidate in search order is always labelled; the picks are distinct and in
    // search order in the file.
    let indices: Vec<u64> = labelled
        .iter()
        .map(|l| l["grasp_index"].as_u64().unwrap())
        .collect();
    assert_eq!(indices[0], 0);
    assert!(indices.windows(2).all(|w| w[0] < w[1]), "{indices:?}");
    for l in &labelled {
        let p = l["hold_probability"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&p), "{l}");
        assert_eq!(l["samples"].as_u64(), Some(3), "{l}");
        assert_eq!(l["joint_angles_deg"].as_array().unwrap().len(), 3);
        assert_eq!(l["palm_pose"][3], serde_json::json!([0.0, 0.0, 0.0, 1.0]));
        assert!(l["grade"]["palm"].as_f64().is_some(), "{l}");
    }
    // Each line checked alone, as a given grasp, reports exactly what `label` wrote for it.
    for (k, l) in labelled.iter().enumerate() {
        let one = dir.path().join(format!("g{k}.jsonl"));
        std::fs::write(&one, format!("{l}\n")).unwrap();
        let checked = dir.path().join(format!("c{k}.jsonl"));
        let o = check(&one, &cup, "3", Some(&checked));
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let c = lines(&checked);
        assert_eq!(c.len(), 1);
        assert_eq!(without_label(&c[0]), without_label(l), "grasp {k}");
    }
}

#[test]
fn label_picks_diverse_grasps_not_the_first_near_copies() {
    let dir = tempfile::tempdir().unwrap();
    let cup = root().join("assets/objects/cup.stl");
    let out = dir.path().join("cup.jsonl");
    let summary = dir.path().join("summary.jsonl");
    let o = grasp_sim()
        .arg("label")
        .arg(&cup)
        .args([
            "--grasps",
            "8",
            "--samples",
            "1",
            "--in-process",
            "--summary",
        ])
        .arg(&summary)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let s = &lines(&summary)[0];
    // The cup's first candidates differ only in the approach angle at one elevation: their
    // palms lie a few millimetres apart; the picks spread over the object.
    let picked = s["picked_spread"][0].as_f64().unwrap();
    let first = s["first_spread"][0].as_f64().unwrap();
    assert!(s["candidates"].as_u64().unwrap() > 100, "{s}");
    assert!(picked > 3.0 * first, "picked {picked} mm, first {first} mm");
    let indices: Vec<u64> = lines(&out)
        .iter()
        .map(|l| l["grasp_index"].as_u64().unwrap())
        .collect();
    assert!(*indices.last().unwrap() > 50, "{indices:?}");
}

#[test]
fn a_bad_given_line_gets_an_error_record_and_the_others_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d40 = root().join("assets/objects/cylinder_d40.stl");
    let out = dir.path().join("d40.jsonl");
    let (code, err) = label(
        &[&d40],
        &["--grasps", "2", "--samples", "2", "--in-process"],
        &out,
    );
    assert_eq!(code, Some(0), "{err}");
    let good = lines(&out);
    let mut scaled = good[0].clone();
    for i in 0..3 {
        for j in 0..3 {
            scaled["palm_pose"][i][j] =
                Value::from(scaled["palm_pose"][i][j].as_f64().unwrap() * 2.0);
        }
    }
    let mut two_fingers = good[0].clone();
    two_fingers["joint_angles_deg"]
        .as_array_mut()
        .unwrap()
        .pop();
    let nan =
        good[0]
            .to_string()
            .replacen(&format!("{}", good[0]["joint_angles_deg"][0][0]), "NaN", 1);
    let given = dir.path().join("given.jsonl");
    std::fs::write(
        &given,
        format!("{}\n{scaled}\n{two_fingers}\n{nan}\n{}\n", good[0], good[1]),
    )
    .unwrap();
    let checked = dir.path().join("checked.jsonl");
    let o = check(&given, &d40, "2", Some(&checked));
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let c = lines(&checked);
    assert_eq!(c.len(), 5);
    assert_eq!(without_label(&c[0]), without_label(&good[0]));
    assert_eq!(without_label(&c[4]), without_label(&good[1]));
    for (k, needle) in [
        (1, "not orthonormal"),
        (2, "has 2 fingers' angles, the hand has 3"),
        (3, "NaN or Infinity"),
    ] {
        let e = c[k]["error"].as_str().unwrap_or_else(|| panic!("{}", c[k]));
        assert!(
            e.contains(&format!("line {}", k + 1)) && e.contains(needle),
            "{e}"
        );
        assert!(c[k].get("verdict").is_none());
    }
}

#[test]
fn a_label_file_of_two_objects_is_checked_on_each_object_by_its_own_lines() {
    let dir = tempfile::tempdir().unwrap();
    let cup = root().join("assets/objects/cup.stl");
    let d40 = root().join("assets/objects/cylinder_d40.stl");
    let both = dir.path().join("both.jsonl");
    let (code, err) = label(
        &[&cup, &d40],
        &["--grasps", "2", "--samples", "1", "--in-process"],
        &both,
    );
    assert_eq!(code, Some(0), "{err}");
    let labelled = lines(&both);
    assert_eq!(labelled.len(), 4, "{err}");
    let of =
        |name: &str| -> Vec<&Value> { labelled.iter().filter(|l| l["object"] == name).collect() };
    assert_eq!(of("cup").len(), 2);
    // The file with a blank line and a bad line of the D40 after the four: the check on the
    // D40 checks its two lines and the bad one (named by its line in the file), not the cup's.
    let mut bad = of("cylinder_d40")[0].clone();
    bad["joint_angles_deg"] = Value::from(7);
    let given = dir.path().join("given.jsonl");
    let text = std::fs::read_to_string(&both).unwrap();
    std::fs::write(&given, format!("{text}\n{bad}\n")).unwrap();
    let checked = dir.path().join("checked.jsonl");
    let o = check(&given, &d40, "1", Some(&checked));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("2 lines of other objects left out"), "{err}");
    let c = lines(&checked);
    assert_eq!(c.len(), 3, "{err}");
    for (got, want) in c.iter().zip(of("cylinder_d40")) {
        assert_eq!(without_label(got), without_label(want));
    }
    let e = c[2]["error"].as_str().unwrap_or_else(|| panic!("{}", c[2]));
    assert!(e.starts_with("line 6:"), "{e}");
    // Lines that name only another object are all checked, with a one-line warning (a name
    // with a line break is shown escaped).
    let cup_only = dir.path().join("cup_only.jsonl");
    let cup_lines: String = of("cup")
        .iter()
        .map(|l| {
            let mut l = (*l).clone();
            l["object"] = Value::from("cup\nsecond");
            format!("{l}\n")
        })
        .collect();
    std::fs::write(&cup_only, cup_lines).unwrap();
    let o = check(&cup_only, &d40, "1", None);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let warning = err
        .lines()
        .find(|l| l.contains("warning"))
        .unwrap_or_default();
    assert!(
        warning.contains("no line is of `cylinder_d40` (a line names `cup\\nsecond`)"),
        "{err}"
    );
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 2);
}

#[test]
fn an_ungraspable_object_gets_one_line_saying_why() {
    let dir = tempfile::tempdir().unwrap();
    let d10 = root().join("scenarios/cylinder_d10.toml");
    let out = dir.path().join("d10.jsonl");
    let (code, err) = label(&[&d10], &["--grasps", "4", "--samples", "1"], &out);
    assert_eq!(code, Some(0), "{err}");
    let l = lines(&out);
    assert_eq!(l.len(), 1);
    assert!(l[0]["ungraspable"].as_str().is_some(), "{}", l[0]);
    assert_eq!(l[0]["object"], "cylinder_d10");
}

#[test]
fn resume_after_a_kill_loses_no_finished_grasp() {
    let dir = tempfile::tempdir().unwrap();
    let cup = root().join("assets/objects/cup.stl");
    let d40 = root().join("assets/objects/cylinder_d40.stl");
    let args = [
        "--grasps",
        "6",
        "--samples",
        "2",
        "--jobs",
        "1",
        "--in-process",
    ];
    // The whole run, uninterrupted.
    let whole = dir.path().join("whole.jsonl");
    let (code, err) = label(&[&cup, &d40], &args, &whole);
    assert_eq!(code, Some(0), "{err}");
    let whole = lines(&whole);
    assert_eq!(whole.len(), 12);
    // The same run, killed once a few grasps are in the file, then resumed.
    let out = dir.path().join("run.jsonl");
    let mut child = grasp_sim()
        .arg("label")
        .arg(&cup)
        .arg(&d40)
        .args(args)
        .args(["--resume", "--out"])
        .arg(&out)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    let count = |p: &Path| {
        std::fs::read_to_string(p)
            .map(|t| t.matches('\n').count())
            .unwrap_or(0)
    };
    while count(&out) < 3 && t0.elapsed().as_secs() < 120 {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    let before: Vec<Value> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    assert!(
        !before.is_empty() && before.len() < 12,
        "{} lines",
        before.len()
    );
    let (code, err) = label(&[&cup, &d40], &[&args[..], &["--resume"]].concat(), &out);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("resume:"), "{err}");
    let after = lines(&out);
    // The finished grasps are kept as written (their wall time too: not labelled again), and
    // the file ends as the uninterrupted run's.
    for b in &before {
        assert!(after.contains(b), "lost {b}");
    }
    let strip = |v: &[Value]| v.iter().map(without_label).collect::<Vec<_>>();
    assert_eq!(strip(&after), strip(&whole));
}

/// `label` of `inputs` with `flags` in one plain run, into `dir`/plain.jsonl; its path.
fn plain_label(dir: &Path, inputs: &[&str], flags: &[&str]) -> std::path::PathBuf {
    let plain = dir.join("plain.jsonl");
    let o = grasp_sim()
        .arg("label")
        .args(flags)
        .args(inputs)
        .arg("--out")
        .arg(&plain)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    plain
}

/// `scripts/slurm_array.sh` with `GRASP_SIM_COMMAND=label`: two array tasks and their merge
/// give the plain run's lines.
#[test]
fn slurm_array_tasks_label_as_one_run_does() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = ["assets/objects/cup.stl", "assets/objects/cylinder_d40.stl"];
    let flags = ["--grasps", "2", "--samples", "1"];
    let plain = plain_label(dir.path(), &inputs, &flags);
    let out = dir.path().join("run");
    let slurm = |mode: &str, id: Option<u32>| {
        let mut c = std::process::Command::new("bash");
        c.current_dir(root())
            .arg("scripts/slurm_array.sh")
            .arg(mode)
            .arg(&out)
            .args(flags)
            .args(inputs)
            .env("GRASP_SIM", env!("CARGO_BIN_EXE_grasp-sim"))
            .env("GRASP_SIM_COMMAND", "label")
            .env("SLURM_CPUS_PER_TASK", "1");
        if let Some(id) = id {
            c.env("SLURM_ARRAY_JOB_ID", "7")
                .env("SLURM_ARRAY_TASK_ID", id.to_string())
                .env("SLURM_ARRAY_TASK_MIN", "0")
                .env("SLURM_ARRAY_TASK_MAX", "1")
                .env("SLURM_ARRAY_TASK_COUNT", "2");
        }
        c.output().unwrap()
    };
    for id in [1, 0] {
        let r = slurm("task", Some(id));
        assert_eq!(
            r.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
    let m = slurm("merge", None);
    assert_eq!(
        m.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&m.stderr)
    );
    let strip = |v: Vec<Value>| v.iter().map(without_label).collect::<Vec<_>>();
    assert_eq!(
        strip(lines(&out.join("results.jsonl"))),
        strip(lines(&plain))
    );
}

/// `scripts/ray_batch.py --command label`: three Ray tasks over two objects and their merge
/// give the plain run's lines (skipped without Ray, required in CI).
#[test]
fn ray_tasks_label_as_one_run_does() {
    if !crate::engines::have_ray() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let inputs = ["assets/objects/cup.stl", "assets/objects/cylinder_d40.stl"];
    let flags = ["--grasps", "2", "--samples", "1"];
    let plain = plain_label(dir.path(), &inputs, &flags);
    let results = dir.path().join("results.jsonl");
    let out = std::process::Command::new("python3")
        .current_dir(root())
        .args(["scripts/ray_batch.py", "--num-cpus", "2", "--shards", "3"])
        .args(["--command", "label", "--binary"])
        .arg(env!("CARGO_BIN_EXE_grasp-sim"))
        .arg("--out")
        .arg(&results)
        .args(inputs)
        .arg("--")
        .args(flags)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("2 CPUs, 3 shards"), "{err}");
    let strip = |v: Vec<Value>| v.iter().map(without_label).collect::<Vec<_>>();
    let labelled = strip(lines(&results));
    assert_eq!(labelled.len(), 4, "two grasps of each object");
    assert_eq!(labelled, strip(lines(&plain)));
}

#[test]
fn a_finger_that_still_creeps_keeps_a_direction_open_until_the_slip() {
    // Meta-World's mug, the fourth of four labelled grasps (grasp 27): under +Z the object
    // stays still for the rest rule's first window while a finger whose motor gave way
    // creeps on, and then it slips (5.3 mm, 5.5°). The full-length reference says `slip`;
    // the fast protocol waits for the fingers to settle (`rest_joint_deg`) and says `slip`
    // too; without that test it would decide `hold` at once. The hold at 8 substeps, where
    // the motor gives way: at 12 (the default) the finger does not creep and the grasp holds.
    let dir = tempfile::tempdir().unwrap();
    let scenario = crate::real_scenario_text("mw_mug");
    let verdicts = |name: &str, sim: &str| -> (String, Vec<String>) {
        let path = dir.path().join(format!("{name}.toml"));
        let sim = format!("hold_solver_iterations = 8\n{sim}");
        std::fs::write(&path, format!("{scenario}\n[sim]\n{sim}\n")).unwrap();
        let out = dir.path().join(format!("{name}.jsonl"));
        let args = ["--grasps", "4", "--samples", "1", "--gravity", "six"];
        let (code, err) = label(&[&path], &[&args[..], &["--in-process"]].concat(), &out);
        assert_eq!(code, Some(0), "{err}");
        let l = lines(&out)
            .into_iter()
            .find(|l| l["grasp_index"].as_u64() == Some(27))
            .unwrap_or_else(|| panic!("{name}: grasp 27 not labelled: {err}"));
        let directions = l["directions"].as_array().unwrap();
        (
            l["verdict"].as_str().unwrap().to_string(),
            directions
                .iter()
                .map(|d| d["verdict"].as_str().unwrap().to_string())
                .collect(),
        )
    };
    let full = verdicts("full", "protocol = \"full\"");
    let fast = verdicts("fast", "");
    let without = verdicts("without", "rest_joint_deg = 360.0");
    assert_eq!(full.0, "slip", "{full:?}");
    assert_eq!(full.1[4], "slip", "+Z: {full:?}");
    assert_eq!(fast, full);
    assert_eq!(without.0, "hold", "{without:?}");
}

/// The kettle's first rule set that finds grasps finds three. A search that checks 8 goes on to
/// the later rule sets, so `label` plans those too and fills its K from them; with
/// `max_checked = 1` it labels the three alone. The three are labelled alike either way.
#[test]
fn label_covers_the_rule_sets_its_search_would_reach() {
    let dir = tempfile::tempdir().unwrap();
    let base = crate::real_scenario_text("kitchen_kettle");
    let run = |max_checked: usize| -> Vec<Value> {
        let path = dir.path().join(format!("kettle_{max_checked}.toml"));
        let text = format!("{base}\n[sim]\nmax_checked = {max_checked}\n");
        std::fs::write(&path, text).unwrap();
        let out = dir.path().join(format!("kettle_{max_checked}.jsonl"));
        let (code, err) = label(
            &[&path],
            &["--grasps", "6", "--samples", "1", "--in-process"],
            &out,
        );
        assert_eq!(code, Some(0), "{err}");
        lines(&out)
    };
    let alone = run(1);
    let covered = run(8);
    let index = |v: &Value| v["grasp_index"].as_u64().unwrap();
    assert_eq!(alone.iter().map(index).collect::<Vec<_>>(), [0, 1, 2]);
    assert_eq!(covered.len(), 6);
    assert!(covered[3..].iter().all(|v| index(v) >= 3));
    for (a, c) in alone.iter().zip(&covered) {
        assert_eq!(without_label(a), without_label(c));
    }
}
