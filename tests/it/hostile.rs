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

/// `mkfifo`: a FIFO that nothing writes to, which would block a reader for ever.
fn fifo(path: &std::path::Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap();
    assert!(status.success());
}

/// A FIFO or a device behind an input's name is refused without being opened: in a single
/// run, in `summarize`, and in `batch` (whose parent hashes its inputs), each with the input's
/// own line, while the other inputs still run.
#[test]
fn special_files_as_inputs_are_refused_without_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let (f, z) = (dir.path().join("f.stl"), dir.path().join("z.stl"));
    fifo(&f);
    std::os::unix::fs::symlink("/dev/zero", &z).unwrap();
    for (input, what) in [
        (&f, "not a regular file (a FIFO)"),
        (&z, "not a regular file (a device)"),
    ] {
        let out = grasp_sim().arg("--no-sim").arg(input).output().unwrap();
        refused(&out, &[input.file_name().unwrap().to_str().unwrap(), what]);
    }
    let out = grasp_sim().arg("summarize").arg(&f).output().unwrap();
    refused(&out, &["f.stl", "not a regular file (a FIFO)"]);
    let good = crate::root().join("assets/objects/cylinder_d40.stl");
    let out = grasp_sim()
        .args(["batch", "--no-sim", "--jobs", "1"])
        .args([&f, &z, &good])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let lines: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(String::from)
        .collect();
    assert_eq!(lines.len(), 3, "{lines:?}");
    assert!(
        lines[0].contains("not a regular file (a FIFO)"),
        "{}",
        lines[0]
    );
    assert!(
        lines[1].contains("not a regular file (a device)"),
        "{}",
        lines[1]
    );
    assert!(lines[2].contains("\"status\":\"feasible\""), "{}", lines[2]);
}

/// `batch nope.stl good.stl` runs the good one: the missing input is an error line of its own,
/// as are a FIFO and a broken link inside a folder (they used to be skipped without a word).
#[test]
fn a_missing_input_costs_its_own_line_only() {
    let dir = tempfile::tempdir().unwrap();
    let good = crate::root().join("assets/objects/cylinder_d40.stl");
    let out = grasp_sim()
        .current_dir(dir.path())
        .args(["batch", "--no-sim", "--jobs", "1", "nope.stl"])
        .arg(&good)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert!(
        lines[0].contains("nope.stl: cannot read: no such file"),
        "{}",
        lines[0]
    );
    assert!(lines[1].contains("\"status\":\"feasible\""), "{}", lines[1]);

    let folder = dir.path().join("set");
    std::fs::create_dir(&folder).unwrap();
    std::fs::copy(&good, folder.join("a.stl")).unwrap();
    fifo(&folder.join("b.stl"));
    std::os::unix::fs::symlink("/nowhere", folder.join("c.stl")).unwrap();
    let out = grasp_sim()
        .args(["batch", "--no-sim", "--jobs", "1"])
        .arg(&folder)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stdout);
    let errors: Vec<&str> = text.lines().filter(|l| l.contains("\"error\"")).collect();
    assert_eq!(text.lines().count(), 3, "{text}");
    assert!(errors[0].contains("b.stl: cannot read: not a regular file (a FIFO)"));
    assert!(errors[1].contains("c.stl: cannot read: no such file"));
}

/// Outputs are renamed only onto a regular file or a new path: a device or a symbolic link as
/// `--out` or `--csv` is refused before anything runs, and left as it was.
#[test]
fn outputs_never_replace_a_device_or_a_link() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("link.jsonl");
    let target = dir.path().join("target.jsonl");
    std::fs::write(&target, "").unwrap();
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let good = crate::root().join("assets/objects/cylinder_d40.stl");
    let out = grasp_sim()
        .args(["batch", "--no-sim", "--out", "/dev/null"])
        .arg(&good)
        .output()
        .unwrap();
    refused(&out, &["/dev/null", "not a regular file (a device)"]);
    let out = grasp_sim()
        .args(["batch", "--no-sim", "--out"])
        .arg(&link)
        .arg(&good)
        .output()
        .unwrap();
    refused(&out, &["link.jsonl", "a symbolic link"]);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let results = dir.path().join("r.jsonl");
    let ok = grasp_sim()
        .args(["batch", "--no-sim", "--out"])
        .arg(&results)
        .arg(&good)
        .output()
        .unwrap();
    assert_eq!(ok.status.code(), Some(0));
    let out = grasp_sim()
        .arg("summarize")
        .arg(&results)
        .arg("--csv")
        .arg(&link)
        .output()
        .unwrap();
    refused(&out, &["link.jsonl", "a symbolic link"]);
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
}

/// Two batches on one `--out` cannot both run: the second is refused at once while the first
/// holds the file, and the first's lines are all there at the end.
#[test]
fn a_second_batch_on_the_same_out_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("r.jsonl");
    let lock = dir.path().join(".r.jsonl.lock");
    // Every bundled scenario with the payload search: tens of seconds.
    let mut first = grasp_sim()
        .args(["batch", "--in-process", "--payload", "--out"])
        .arg(&results)
        .arg("scenarios")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while !lock.exists() && t0.elapsed() < std::time::Duration::from_secs(60) {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(lock.exists(), "the first batch took its lock");
    let mut tested = 0;
    for resume in [false, true] {
        let mut second = grasp_sim();
        second.args(["batch", "--no-sim", "--out"]).arg(&results);
        if resume {
            second.arg("--resume");
        }
        let out = second.arg("scenarios/cup.toml").output().unwrap();
        if first.try_wait().unwrap().is_some() {
            // The first finished before the second started: nothing was tested (a machine
            // far faster than this suite assumes).
            break;
        }
        refused(
            &out,
            &["r.jsonl", "in use by another `grasp-sim batch` (locked)"],
        );
        tested += 1;
    }
    assert!(
        tested > 0,
        "the first batch ended before the second started"
    );
    let status = first.wait().unwrap().code();
    let scenarios = std::fs::read_dir(crate::root().join("scenarios"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "toml")
        })
        .count();
    assert!(matches!(status, Some(0 | 1)), "{status:?}");
    assert_eq!(
        std::fs::read_to_string(&results).unwrap().lines().count(),
        scenarios
    );
    assert!(!lock.exists(), "the lock file is removed at the end");
}

/// Settings that are each in range by type but imply unbounded work are refused with the limit
/// stated: a step so fine it would exhaust memory, a timestep or a hold that would never end.
#[test]
fn settings_whose_work_is_unbounded_are_refused_with_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = crate::root().join("assets/objects/cylinder_d40.stl");
    for (table, key, needle) in [
        (
            "[planner]\nangular_step_deg = 1e-6",
            "planner.angular_step_deg",
            "at least 1",
        ),
        (
            "[planner]\nheight_step_mm = 1e-6",
            "planner.height_step_mm",
            "at least 0.1 mm",
        ),
        (
            "[sim]\ntimestep_s = 1e-12",
            "sim.timestep_s",
            "at most 200000",
        ),
        (
            "[sim]\nprotocol = \"full\"\nduration_s = 1e9",
            "sim.timestep_s",
            "steps per gravity direction",
        ),
    ] {
        let s = dir.path().join("s.toml");
        std::fs::write(
            &s,
            format!("[object]\nmesh = \"{}\"\n{table}\n", mesh.display()),
        )
        .unwrap();
        let out = grasp_sim().arg(&s).output().unwrap();
        refused(&out, &["s.toml", key, needle]);
    }
}

/// A URDF with an unknown element nested 5000 deep (35 KB) overflowed the stack of the batch's
/// parent while it hashed its inputs, losing the whole batch: it is now refused by its depth,
/// in a single run and in a batch, and the other input still runs.
#[test]
fn a_deeply_nested_urdf_is_refused_by_its_depth() {
    let dir = tempfile::tempdir().unwrap();
    let deep = dir.path().join("deep.urdf");
    let n = 5000;
    let body = "<link name=\"a\"><collision><geometry><box size=\"0.02 0.02 0.02\"/></geometry></collision></link>";
    std::fs::write(
        &deep,
        format!(
            "<?xml version=\"1.0\"?>\n<!-- <not> <counted> -->\n<robot name=\"r\">{body}{}{}</robot>",
            "<foo>".repeat(n),
            "</foo>".repeat(n)
        ),
    )
    .unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&deep).output().unwrap();
    refused(
        &out,
        &["deep.urdf", "nested 257 deep", "at most 256 levels"],
    );
    let good = crate::root().join("assets/objects/cylinder_d40.stl");
    let out = grasp_sim()
        .args(["batch", "--no-sim", "--jobs", "1"])
        .arg(&deep)
        .arg(&good)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert!(lines[0].contains("at most 256 levels"), "{}", lines[0]);
    assert!(lines[1].contains("\"status\":\"feasible\""), "{}", lines[1]);
    // A shallow URDF of the same link reads (the scan counts comments and declarations as no
    // level, and self-closing elements as none).
    let shallow = dir.path().join("shallow.urdf");
    std::fs::write(
        &shallow,
        format!("<?xml version=\"1.0\"?>\n<!-- <a> -->\n<robot name=\"r\">{body}</robot>"),
    )
    .unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&shallow).output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `mass_kg = 1e20` was judged `hold` (the f32 physics overflowed) where 1e3 to 1e19 drop: a
/// mass or density past any hand is refused, the limit stated, and 1e3 kg still drops.
#[test]
fn an_absurd_mass_is_refused_and_a_heavy_one_drops() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = crate::root().join("assets/objects/cylinder_d40.stl");
    let write = |table: &str| {
        let s = dir.path().join("m.toml");
        std::fs::write(
            &s,
            format!("[object]\nmesh = \"{}\"\n{table}\n", mesh.display()),
        )
        .unwrap();
        s
    };
    let out = grasp_sim().arg(write("mass_kg = 1e20")).output().unwrap();
    refused(&out, &["m.toml", "object.mass_kg", "at most 10000 kg"]);
    let out = grasp_sim()
        .arg(write("density_kg_m3 = 1e9"))
        .output()
        .unwrap();
    refused(&out, &["m.toml", "object.density_kg_m3", "at most 100000"]);
    let out = grasp_sim()
        .arg("--json")
        .arg(write("mass_kg = 1000.0"))
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["sim"]["verdict"], "drop", "{v}");
}

/// Every face written twice doubled the volume and the mass: the repeats are dropped, the
/// volume is the single mesh's, and a warning says how many.
#[test]
fn duplicated_faces_are_counted_once_and_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let once = grasp_sim::objects::cylinder(40.0, 124.0);
    let mut twice = once.clone();
    twice.triangles.extend(once.triangles.clone());
    let (a, b) = (dir.path().join("once.stl"), dir.path().join("twice.stl"));
    std::fs::write(&a, once.to_binary_stl()).unwrap();
    std::fs::write(&b, twice.to_binary_stl()).unwrap();
    let run = |p: &std::path::Path| {
        let out = crate::grasp_sim()
            .args(["--json", "--no-sim"])
            .arg(p)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (v, String::from_utf8_lossy(&out.stderr).to_string())
    };
    let ((v1, _), (v2, err)) = (run(&a), run(&b));
    assert_eq!(v1["object"]["volume_mm3"], v2["object"]["volume_mm3"]);
    assert_eq!(v1["object"]["mass_kg"], v2["object"]["mass_kg"]);
    let n = once.triangles.len();
    assert!(
        err.contains(&format!("dropped {n} duplicated faces of {}", 2 * n)),
        "{err}"
    );
    let volume = v1["object"]["volume_mm3"].as_f64().unwrap();
    // The faceted cylinder's volume against π r² h.
    let analytic = std::f64::consts::PI * 20.0f64.powi(2) * 124.0;
    assert!(
        (volume - analytic).abs() < 1e-3 * analytic,
        "{volume} {analytic}"
    );
}

/// A `batch --template` need not carry a placeholder `[object] mesh` (each mesh replaces it):
/// one with only its density, or with no `[object]` at all, runs; a typo in it is still refused.
#[test]
fn a_template_needs_no_placeholder_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let good = crate::root().join("assets/objects/cylinder_d40.stl");
    for (body, mass) in [
        ("[object]\ndensity_kg_m3 = 1000.0\n", 0.155_773_557),
        ("[planner]\nsf_c = 0.5\n", 0.077_886_779),
    ] {
        let t = dir.path().join("t.toml");
        std::fs::write(&t, body).unwrap();
        let out = grasp_sim()
            .args(["batch", "--no-sim", "--template"])
            .arg(&t)
            .arg(&good)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let m = v["object"]["mass_kg"].as_f64().unwrap();
        assert!((m - mass).abs() < 1e-6, "{body}: {m}");
    }
    let t = dir.path().join("t.toml");
    std::fs::write(&t, "[object]\ndensity = 1000.0\n").unwrap();
    let out = grasp_sim()
        .args(["batch", "--no-sim", "--template"])
        .arg(&t)
        .arg(&good)
        .output()
        .unwrap();
    refused(&out, &["t.toml", "density"]);
}

/// `package://` found a mesh above the URDF's folder only when the URDF path was absolute: from
/// a relative path the same mesh is found too.
#[test]
fn package_paths_resolve_above_a_relative_urdf() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::create_dir_all(root.join("pkg/meshes")).unwrap();
    std::fs::create_dir_all(root.join("work/robots")).unwrap();
    std::fs::write(
        root.join("pkg/meshes/cyl.stl"),
        grasp_sim::objects::cylinder(40.0, 124.0).to_binary_stl(),
    )
    .unwrap();
    std::fs::write(
        root.join("work/robots/obj.urdf"),
        "<robot name=\"o\"><link name=\"a\"><collision><geometry><mesh filename=\"package://pkg/meshes/cyl.stl\" scale=\"0.001 0.001 0.001\"/></geometry></collision></link></robot>",
    )
    .unwrap();
    for (cwd, arg) in [
        (root.join("work"), "robots/obj.urdf".to_string()),
        (
            root.to_path_buf(),
            root.join("work/robots/obj.urdf").display().to_string(),
        ),
    ] {
        let out = grasp_sim()
            .current_dir(&cwd)
            .args(["--json", "--no-sim", &arg])
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{arg}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["object"]["triangles"], 576, "{arg}");
    }
}

/// A URDF joint that names a link the file does not have, or a link with two parents, was
/// accepted; each is refused with the joint's line.
#[test]
fn a_urdf_that_is_not_a_tree_of_its_links_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let link = |n: &str| {
        format!("<link name=\"{n}\"><collision><geometry><box size=\"0.02 0.02 0.02\"/></geometry></collision></link>")
    };
    let joint = |p: &str, c: &str| {
        format!("\n<joint name=\"{p}_{c}\" type=\"fixed\"><parent link=\"{p}\"/><child link=\"{c}\"/></joint>")
    };
    for (body, needle) in [
        (
            format!("{}{}", link("a"), joint("a", "ghost")),
            "line 2: <joint> names link `ghost`, which the file does not have",
        ),
        (
            format!(
                "{}{}{}{}{}",
                link("a"),
                link("b"),
                link("c"),
                joint("a", "c"),
                joint("b", "c")
            ),
            "line 3: link `c` has two parents (`a` and `b`)",
        ),
    ] {
        let u = dir.path().join("t.urdf");
        std::fs::write(&u, format!("<robot name=\"r\">{body}\n</robot>")).unwrap();
        let out = grasp_sim().arg("--no-sim").arg(&u).output().unwrap();
        refused(&out, &["t.urdf", needle]);
    }
}
