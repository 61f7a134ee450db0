//! Issue 19 item 5: `grasp-sim summarize results.jsonl`.

use std::process::Output;

fn run(args: &[&str]) -> Output {
    crate::grasp_sim().args(args).output().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn summarize_counts_a_batch_and_writes_its_csv() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("r.jsonl");
    let bad = dir.path().join("bad.stl");
    std::fs::write(&bad, b"not a mesh").unwrap();
    let b = run(&[
        "batch",
        "--jobs",
        "2",
        "--out",
        results.to_str().unwrap(),
        "scenarios/cylinder_d10.toml",
        "scenarios/cylinder_d40.toml",
        "scenarios/sim_cup_weak_motors.toml",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(b.status.code(), Some(2), "{}", text(&b.stderr));
    let csv = dir.path().join("r.csv");
    let s = run(&[
        "summarize",
        results.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
        "--slowest",
        "2",
    ]);
    let out = text(&s.stdout);
    assert_eq!(s.status.code(), Some(0), "{}", text(&s.stderr));
    for want in [
        "r.jsonl: 4 objects",
        "planned       2 (50.0 %), ungraspable 1 (25.0 %), errors 1 (25.0 %)",
        "physics       2 checked: 1 hold, 0 slip, 1 drop; 1 not run",
        "-Z (down)  1 of 2 held (0 slip, 1 drop)",
        "expectations  3 met, 0 not met, 0 not judged",
        "bad.stl: ",
    ] {
        assert!(out.contains(want), "no `{want}` in\n{out}");
    }
    let slowest: Vec<&str> = out
        .lines()
        .skip_while(|l| !l.contains("slowest:"))
        .skip(1)
        .take_while(|l| l.starts_with("    ") && l.contains(" s  "))
        .collect();
    assert_eq!(slowest.len(), 2, "{out}");
    let csv = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 5, "{csv}");
    assert!(rows[0].starts_with("input,scenario,status,verdict,"));
    assert!(
        rows[1].starts_with("scenarios/cylinder_d10.toml,cylinder_d10,ungraspable,not_run,"),
        "{}",
        rows[1]
    );
    assert!(
        rows[2].starts_with("scenarios/cylinder_d40.toml,cylinder_d40,feasible,hold,"),
        "{}",
        rows[2]
    );
    assert!(rows[2].contains(",-Z hold,hold,true,"), "{}", rows[2]);
    assert!(rows[4].contains(",error,"), "{}", rows[4]);
}

#[test]
fn summarize_bad_input_is_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str, bytes: &[u8]| {
        let f = dir.path().join(name);
        std::fs::write(&f, bytes).unwrap();
        f.to_str().unwrap().to_string()
    };
    let cases = [
        (
            dir.path().join("nope.jsonl").to_str().unwrap().to_string(),
            "nope.jsonl: ",
        ),
        (
            p("garbage.jsonl", b"\x00\xff\xfe garbage\n"),
            "garbage.jsonl: line 1",
        ),
        (
            p("other.jsonl", b"{\"a\": 1}\n"),
            "other.jsonl: line 1 is not a batch record: no `scenario`",
        ),
        (
            p("nested.jsonl", b"{\"scenario\": \"x\", \"plan\": 3}\n"),
            "nested.jsonl: line 1",
        ),
        (dir.path().to_str().unwrap().to_string(), ""),
    ];
    for (file, want) in cases {
        let out = run(&["summarize", &file]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{file}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("grasp-sim: error: ") && err.contains(want),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(out.stdout.is_empty());
    }
    // An empty file is an empty dataset, not an error.
    let empty = p("empty.jsonl", b"");
    let out = run(&["summarize", &empty]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("empty.jsonl: 0 objects"));
    // A CSV that cannot be written fails before reading.
    let out = run(&["summarize", &empty, "--csv", "no/such/dir/x.csv"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("--csv"), "{}", text(&out.stderr));
}

#[test]
fn an_empty_results_file_sums_to_zero_not_minus_zero() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.jsonl");
    std::fs::write(&empty, "").unwrap();
    let out = crate::succeed(crate::grasp_sim().arg("summarize").arg(&empty));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains(": 0 objects"), "{text}");
    assert!(
        text.contains("time          0.0 s summed over objects (0.000 s per object)"),
        "{text}"
    );
}
