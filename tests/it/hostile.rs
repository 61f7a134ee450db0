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
            "[sim]\nprotocol = \"full\"\nduration_s = 3600",
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
    refused(&out, &["m.toml", "object.mass_kg", "10000] kg"]);
    let out = grasp_sim()
        .arg(write("density_kg_m3 = 1e9"))
        .output()
        .unwrap();
    refused(&out, &["m.toml", "object.density_kg_m3", "100000] kg/m³"]);
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

/// A closed shell with some faces written the wrong way round (a probe of issue 32, 2026-12-02): a
/// 40 mm cube with one of its 12 triangles turned read as 32 cm³ and half the mass, with only a
/// warning about misoriented edges. The turned faces are now wound as their neighbours are,
/// the volume is the cube's, and a warning says how many were turned; a cube with all but two
/// turned keeps the winding of most (inward) and is then turned outward whole, as before.
#[test]
fn faces_wound_against_their_neighbours_are_mended_not_subtracted() {
    let dir = tempfile::tempdir().unwrap();
    let good = cube([10.0, 20.0, 30.0], 40.0);
    let mut one = good.clone();
    one[9].swap(1, 2); // on the face x = 10: the volume integral takes the x-components
    let mut most = good.clone();
    for t in most.iter_mut().skip(2) {
        t.swap(1, 2);
    }
    let run = |name: &str, tris: &[[[f32; 3]; 3]]| {
        let p = dir.path().join(name);
        std::fs::write(&p, binary_stl(tris)).unwrap();
        let out = crate::grasp_sim()
            .args(["--json", "--no-sim"])
            .arg(&p)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let volume = v["object"]["volume_mm3"].as_f64().unwrap();
        (volume, String::from_utf8_lossy(&out.stderr).to_string())
    };
    let (v_good, err_good) = run("good.stl", &good);
    assert!((v_good - 64_000.0).abs() < 1e-6, "{v_good}");
    assert!(!err_good.contains("wound against"), "{err_good}");
    let (v_one, err_one) = run("one.stl", &one);
    assert!((v_one - 64_000.0).abs() < 1e-6, "{v_one}");
    assert!(
        err_one.contains("1 of 12 triangles were wound against their neighbours"),
        "{err_one}"
    );
    let (v_most, err_most) = run("most.stl", &most);
    assert!((v_most - 64_000.0).abs() < 1e-6, "{v_most}");
    assert!(
        err_most.contains("2 of 12 triangles were wound against their neighbours")
            && err_most.contains("wound inside-out"),
        "{err_most}"
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

/// A binary STL of `triangles`.
fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        b.extend([0u8; 12]);
        for p in t {
            for c in p {
                b.extend(c.to_le_bytes());
            }
        }
        b.extend([0u8; 2]);
    }
    b
}

/// The 12 outward triangles of the axis-aligned cube of side `s` with its low corner at `o`.
fn cube(o: [f32; 3], s: f32) -> Vec<[[f32; 3]; 3]> {
    let c = |i: usize| {
        [
            o[0] + s * (i & 1) as f32,
            o[1] + s * ((i >> 1) & 1) as f32,
            o[2] + s * ((i >> 2) & 1) as f32,
        ]
    };
    // Faces as corner quads, counter-clockwise seen from outside.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

/// The JSON line of a `--no-sim --json` run of `path`, which must exit 0 within the given time
/// bound (a hang would be reported past it, as an error line).
fn plan_json(path: &std::path::Path) -> serde_json::Value {
    let out = grasp_sim()
        .args(["--no-sim", "--json", "--time-limit", "300"])
        .arg(path)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Thirty overlapping 20 mm cubes, each 1 mm above the last, in one mesh (18 KB): one union of
/// all their cuts in i_overlay grew past 4 GB and aborted. Now the union is taken two shapes at
/// a time, and the volume is the union's: 20 × 20 × 49 mm³, not 30 cubes' 240,000.
#[test]
fn thirty_stacked_overlapping_cubes_unite_to_their_volume() {
    let dir = tempfile::tempdir().unwrap();
    let tris: Vec<_> = (0..30)
        .flat_map(|k| cube([0.0, 0.0, k as f32], 20.0))
        .collect();
    let path = dir.path().join("cubes30.stl");
    std::fs::write(&path, binary_stl(&tris)).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 84 + 50 * 360);
    let v = plan_json(&path);
    let vol = v["object"]["volume_mm3"].as_f64().unwrap();
    assert!((vol - 19_600.0).abs() < 1.0, "{vol}");
    assert_eq!(v["object"]["height_mm"].as_f64().unwrap(), 49.0);
}

/// A URDF chain of 300 overlapping 1 mm boxes, each 0.5 mm along x from its parent (more than
/// 100 s before, in the open-end join: every other box shares corners with the next but one, so
/// the welded mesh is not manifold and each cut is thousands of open pieces, which the join
/// tested all against all; now through a grid). It ends, a bar 1 mm thick, too thin for the
/// hand. The same chain stepped 0.2 mm up as well (no shared corners, a closed union) has the
/// union's volume, 300 − 299 × (0.5 × 1 × 0.8) = 180.4 mm³.
#[test]
fn a_chain_of_three_hundred_overlapping_boxes_ends_with_its_volume() {
    let dir = tempfile::tempdir().unwrap();
    for (step, volume) in [("0.0005 0 0", None), ("0.0005 0 0.0002", Some(180.4))] {
        let mut urdf = String::from("<robot name=\"chain\">");
        let b = "<geometry><box size=\"0.001 0.001 0.001\"/></geometry>";
        for k in 0..300 {
            urdf += &format!("<link name=\"l{k}\"><visual>{b}</visual></link>");
            if k > 0 {
                urdf += &format!(
                    "<joint name=\"j{k}\" type=\"fixed\"><parent link=\"l{}\"/><child link=\"l{k}\"/><origin xyz=\"{step}\"/></joint>",
                    k - 1
                );
            }
        }
        urdf += "</robot>\n";
        let path = dir.path().join("chain300.urdf");
        std::fs::write(&path, urdf).unwrap();
        let v = plan_json(&path);
        let reason = v["plan"]["reason"].as_str().unwrap_or_default();
        assert!(reason.starts_with("too thin"), "{step}: {reason}");
        let vol = v["object"]["volume_mm3"].as_f64().unwrap();
        if let Some(volume) = volume {
            assert!((vol - volume).abs() < 0.005 * volume, "{step}: {vol}");
        }
    }
}

/// An OBJ cylinder (64 segments, 20 mm radius, 60 mm tall) whose face indices are off by one:
/// one extra `v` line before it. Its faces are then a tangle of slivers; it ends, with or
/// without a grasp, and the well-indexed one has the 64-gon prism's volume.
#[test]
fn an_obj_with_indices_off_by_one_ends() {
    let dir = tempfile::tempdir().unwrap();
    let cylinder = |extra: bool| {
        let n = 64;
        let mut s = String::new();
        if extra {
            s += "v 0 0 0\n";
        }
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let (x, y) = (20.0 * a.cos(), 20.0 * a.sin());
            s += &format!("v {x} {y} 0\nv {x} {y} 60\n");
        }
        s += "v 0 0 0\nv 0 0 60\n";
        for i in 0..n {
            let j = (i + 1) % n;
            let (b0, t0, b1, t1) = (2 * i + 1, 2 * i + 2, 2 * j + 1, 2 * j + 2);
            s += &format!("f {b0} {b1} {t1}\nf {b0} {t1} {t0}\n");
            s += &format!("f {} {b1} {b0}\nf {} {t0} {t1}\n", 2 * n + 1, 2 * n + 2);
        }
        s
    };
    let good = dir.path().join("good.obj");
    std::fs::write(&good, cylinder(false)).unwrap();
    let vol = plan_json(&good)["object"]["volume_mm3"].as_f64().unwrap();
    let prism = 0.5 * 64.0 * 400.0 * (std::f64::consts::TAU / 64.0).sin() * 60.0;
    assert!((vol - prism).abs() < 1e-6 * prism, "{vol} vs {prism}");
    let bad = dir.path().join("off_by_one.obj");
    std::fs::write(&bad, cylinder(true)).unwrap();
    let out = grasp_sim()
        .args(["--no-sim", "--json", "--time-limit", "300"])
        .arg(&bad)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("no result within"),
        "{err}"
    );
    assert!(matches!(out.status.code(), Some(0) | Some(2)), "{err}");
}

/// A full disk while an output is written (the debug build's fault hook fails the write of the
/// named file half-way with ENOSPC): exit 2 with one line naming the file, and neither the file
/// nor its temporary remains, for `--export-mjcf`, `--export-urdf`, `--report` and `gen-assets`.
#[test]
#[cfg_attr(
    not(debug_assertions),
    ignore = "the fault hook GRASP_SIM_TEST_FAULT is compiled into debug builds only"
)]
fn a_full_disk_leaves_no_half_written_output() {
    let cases: [(&[&str], &str, &str); 4] = [
        (&["--no-sim", "--export-mjcf"], "scene.xml", "cup"),
        (&["--no-sim", "--export-urdf"], "hand.urdf", "cup"),
        (&["--no-sim", "--report"], "report.html", "cup"),
        (&["gen-assets", "--out"], "prism.stl", ""),
    ];
    for (args, file, sub) in cases {
        let dir = tempfile::tempdir().unwrap();
        let mut cmd = grasp_sim();
        cmd.args(args)
            .arg(dir.path())
            .env("GRASP_SIM_TEST_FAULT", format!("enospc:{file}"));
        if sub == "cup" {
            cmd.arg("scenarios/cup.toml");
        }
        let out = cmd.output().unwrap();
        refused(&out, &[file]);
        let folder = dir.path().join(sub);
        let names: Vec<String> = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(
            !names
                .iter()
                .any(|n| n.contains(file) || n.ends_with(".tmp")),
            "{file}: {names:?}"
        );
    }
}

/// An output whose rename must fail (a folder where `hand.urdf` goes): exit 2 naming it, the
/// folder left as it was, and no temporary file beside it.
#[test]
fn an_output_that_cannot_be_renamed_into_place_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let taken = dir.path().join("cup/hand.urdf");
    std::fs::create_dir_all(taken.join("inside")).unwrap();
    let out = grasp_sim()
        .args(["--no-sim", "--export-urdf"])
        .arg(dir.path())
        .arg("scenarios/cup.toml")
        .output()
        .unwrap();
    refused(&out, &["hand.urdf"]);
    assert!(taken.join("inside").is_dir());
    assert_eq!(
        std::fs::read_dir(dir.path().join("cup")).unwrap().count(),
        1
    );
}

/// Absurd values are refused in a short line: a friction of 1e300 is written `1e300`, not in
/// 301 digits; a candidate budget of u64::MAX is past the stated cap; an unknown PLY format is
/// named in words, not as the parser's Debug dump.
#[test]
fn absurd_values_get_short_plain_messages() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = crate::root().join("assets/objects/cylinder_d40.stl");
    let scenario = |name: &str, extra: &str, object: &str| {
        let p = dir.path().join(name);
        std::fs::write(
            &p,
            format!(
                "name = \"x\"\n{extra}\n[object]\nmesh = \"{}\"\n{object}\n",
                mesh.display()
            ),
        )
        .unwrap();
        p
    };
    let friction = scenario("friction.toml", "", "friction = 1e300");
    let out = grasp_sim().arg("--no-sim").arg(&friction).output().unwrap();
    let line = refused(&out, &["object.friction", "got 1e300"]);
    assert!(line.len() < 200, "{line}");
    let budget = scenario(
        "budget.toml",
        &format!("[planner]\ncandidate_budget = {}\n", u64::MAX),
        "",
    );
    let out = grasp_sim().arg("--no-sim").arg(&budget).output().unwrap();
    let text = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(text.contains("candidate_budget"), "{text}");
    let budget = scenario(
        "budget2.toml",
        "[planner]\ncandidate_budget = 1000001\n",
        "",
    );
    let out = grasp_sim().arg("--no-sim").arg(&budget).output().unwrap();
    refused(&out, &["planner.candidate_budget", "at most 1000000"]);
    let ply = dir.path().join("weird.ply");
    std::fs::write(
        &ply,
        "ply\nformat weird 1.0\nelement vertex 0\nend_header\n",
    )
    .unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&ply).output().unwrap();
    let line = refused(&out, &["weird.ply", "header line 2 `format weird 1.0`"]);
    assert!(
        !line.contains("ParseError") && !line.contains('{'),
        "{line}"
    );
}

/// A 1 km cube (a file in millimetres read as such, 600 bytes) asked the planner for 400,000
/// elevations at every approach angle and aborted past 4 GB. The planner's work is bounded by
/// the object's extent over its steps, with the limit stated; a 10 m cube at the defaults still
/// plans, and refused at `height_step_mm = 0.1`.
#[test]
fn an_object_too_large_for_the_planner_steps_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let km = dir.path().join("km.stl");
    std::fs::write(&km, binary_stl(&cube([0.0; 3], 1e6))).unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&km).output().unwrap();
    refused(
        &out,
        &["km.stl", "elevation-angle cells", "more than the 400000"],
    );
    let ten = dir.path().join("ten.stl");
    std::fs::write(&ten, binary_stl(&cube([0.0; 3], 1e4))).unwrap();
    let v = plan_json(&ten);
    assert!((v["object"]["volume_mm3"].as_f64().unwrap() - 1e12).abs() < 1e3);
    let fine = dir.path().join("fine.toml");
    std::fs::write(
        &fine,
        "name = \"fine\"\n[planner]\nheight_step_mm = 0.1\n[object]\nmesh = \"ten.stl\"\n",
    )
    .unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&fine).output().unwrap();
    refused(
        &out,
        &[
            "ten.stl",
            "height_step_mm = 0.1",
            "3117708 elevation-angle cells",
        ],
    );
}

/// The planner's work bound is taken in the object's aligned frame, not the file's: a 28 m cube
/// (1.73 × 28 m across square, 2.24 × 28 m in its file's box when written turned 45° about z)
/// plans alike written either way; the file's box refused it turned (450,000 cells against
/// the 400,000 limit) and planned it square.
#[test]
fn the_planner_work_bound_does_not_depend_on_the_file_frame() {
    let dir = tempfile::tempdir().unwrap();
    let s = 28_000.0_f32;
    let square = cube([0.0; 3], s);
    let (c, h) = (std::f32::consts::FRAC_1_SQRT_2, s / 2.0);
    let turned: Vec<[[f32; 3]; 3]> = square
        .iter()
        .map(|t| {
            t.map(|p| {
                [
                    c * (p[0] - h) - c * (p[1] - h),
                    c * (p[0] - h) + c * (p[1] - h),
                    p[2],
                ]
            })
        })
        .collect();
    let mut plans = Vec::new();
    for (name, tris) in [("square.stl", &square), ("turned.stl", &turned)] {
        let path = dir.path().join(name);
        std::fs::write(&path, binary_stl(tris)).unwrap();
        let v = plan_json(&path);
        plans.push((
            v["plan"]["status"].clone(),
            v["plan"]["indexed_elevations"].clone(),
        ));
    }
    assert_eq!(plans[0], plans[1]);
    assert_eq!(plans[0].0, "ungraspable", "{:?}", plans[0]);
}

/// From the probe (issue 32): a time bound of 1e300 s overflowed the timer and panicked (now
/// refused, the cap stated); a URDF naming a mesh that is a link to `/dev/zero` said "not
/// found" (now: what it is).
#[test]
fn probe_findings_are_plain_errors() {
    let out = grasp_sim()
        .args(["--no-sim", "--time-limit", "1e300", "scenarios/cup.toml"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked") && err.contains("a year"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.stl")).unwrap();
    let urdf = dir.path().join("r.urdf");
    std::fs::write(
        &urdf,
        "<robot name=\"r\"><link name=\"a\"><visual><geometry><mesh filename=\"zero.stl\"/></geometry></visual></link></robot>\n",
    )
    .unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&urdf).output().unwrap();
    refused(&out, &["zero.stl", "not a regular file (a device)"]);
}

/// The fuzz targets' findings (docs/FUZZING.md), kept as the fuzzers wrote them in
/// tests/fuzz_findings/: small meshes that took over the fuzzers' 10 s bound, up to 60 s in a
/// release build, nearly all of it in i_overlay's split solver, in the gap closing of stage 1's
/// slices: a 284-byte STL of four triangles (one degenerate, the rest an open sliver 20 mm
/// across with subnormal coordinates) and OBJs of 93–315 bytes, overlapping tetrahedra and
/// near-collinear faces among garbage lines, whose cuts are hundreds of rings about 1e-9 mm wide.
/// Rings thinner than 1 µm are no material (`mesh::polygon_limits::MIN_RING_WIDTH_MM`), so each
/// now ends at once with its one-line reason: no grasp, or, for the sliver, which encloses no
/// volume once its empty rings are left out, the refusal of a surface that is not a solid.
/// Two STLs of a later run (`mesh_stl_slow_*`, four triangles each) cross themselves in
/// their slices along near-collinear edges, where i_overlay's default snap radius cascades
/// (`mesh::polygon_limits`, `a_self_crossing_near_collinear_ring_unites_without_a_cascade`);
/// each plans to its reason: too short for the hand. The next run's three
/// (`mesh_stl_slow_{660abe42,b9d68fee,fb63b0b2}`, 4-5 s each, one of them libFuzzer's timeout
/// under load) are the same class in the union-based mass properties' 400 slices, where
/// i_overlay's `MEDIUM` step still cascaded (1552 pieces from an 8-point ring); with the ×256
/// step each plans in about 0.05 s. Since an open surface's volume is taken about its area
/// centroid (issue 30's frame rule, 93eb102), the 135-byte OBJ of faces flattened onto a
/// line (`mesh_obj_timeout_4d16f9e5`) encloses 0 mm³ and is refused, and the sliver STL
/// (`mesh_stl_timeout_333e974d`) encloses 0.0013 mm³ and plans to its reason, too short.
#[test]
fn the_fuzzers_slow_findings_end_with_their_reason() {
    let dir = crate::root().join("tests/fuzz_findings");
    let refused = ["mesh_obj_timeout_4d16f9e5.obj"];
    let mut names = Vec::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if refused.contains(&name.as_str()) {
            let out = grasp_sim()
                .args(["--no-sim", "--json"])
                .arg(&path)
                .output()
                .unwrap();
            // Its warnings (degenerate triangles, open edges, a small object) come first.
            let err = String::from_utf8_lossy(&out.stderr);
            let errors: Vec<&str> = err.lines().filter(|l| l.contains("error:")).collect();
            assert_eq!(out.status.code(), Some(2), "{name}: {err}");
            assert!(!err.contains("panicked"), "{err}");
            assert_eq!(errors.len(), 1, "{err}");
            assert!(
                errors[0].contains(&name) && errors[0].contains("encloses no volume"),
                "{err}"
            );
        } else {
            let v = plan_json(&path);
            assert_eq!(v["plan"]["status"], "ungraspable", "{name}: {v}");
        }
        names.push(name);
    }
    names.sort();
    assert_eq!(names.len(), 10, "{names:?}");
}

/// Issue 56: a scenario `name` was joined onto `--report DIR` as it was (`../../escape` wrote
/// two folders up, `..` replaced a report beside DIR, NUL exited 101): each is refused, naming
/// the key, and nothing is written; a mesh whose stem names no folder (`..stl`) still runs.
#[test]
fn a_name_that_would_leave_the_report_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = crate::root().join("assets/objects/cylinder_d40.stl");
    let report = dir.path().join("a/b/rep");
    for (name, needle) in [
        ("../../escape", "contains `/`"),
        ("..", "is `..`"),
        ("/abs/name", "contains `/`"),
        ("a\\u0000b", "contains a NUL byte"),
    ] {
        let s = dir.path().join("s.toml");
        std::fs::write(
            &s,
            format!(
                "name = \"{name}\"\n[object]\nmesh = \"{}\"\n",
                mesh.display()
            ),
        )
        .unwrap();
        let out = grasp_sim()
            .args(["--no-sim", "--report"])
            .arg(&report)
            .arg(&s)
            .output()
            .unwrap();
        refused(&out, &["s.toml", "`name`", needle]);
    }
    assert!(!dir.path().join("escape").exists());
    assert_eq!(std::fs::read_dir(&report).unwrap().count(), 0);
    let dots = dir.path().join("..stl");
    std::fs::copy(&mesh, &dots).unwrap();
    let out = grasp_sim()
        .args(["--no-sim", "--report"])
        .arg(&report)
        .arg(&dots)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(report.join("_.").join("report.html").is_file());
}

/// `hand show --svg` wrote with a plain truncating open: through a link, into a device, and
/// onto a FIFO it blocked. It now writes as every output does, so each is refused at once.
#[test]
fn hand_show_writes_its_figure_as_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let hand = crate::root().join("assets/hands/bh8.toml");
    let (f, l) = (dir.path().join("f.svg"), dir.path().join("l.svg"));
    fifo(&f);
    std::os::unix::fs::symlink("/dev/null", &l).unwrap();
    for (out, what) in [(&f, "a FIFO"), (&l, "a symbolic link")] {
        let t0 = std::time::Instant::now();
        let run = grasp_sim()
            .args(["hand", "show"])
            .arg(&hand)
            .arg("--svg")
            .arg(out)
            .output()
            .unwrap();
        refused(&run, &[out.file_name().unwrap().to_str().unwrap(), what]);
        assert!(t0.elapsed() < std::time::Duration::from_secs(30));
    }
    let good = dir.path().join("g.svg");
    let run = grasp_sim()
        .args(["hand", "show"])
        .arg(&hand)
        .arg("--svg")
        .arg(&good)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(0));
    assert!(std::fs::read_to_string(&good).unwrap().starts_with("<svg"));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
}

/// Values silently wrong (issue 56): a contact stiffness of 1e300 Hz was taken (an unmoved
/// object judged `drop`), a friction of 5e-324 was blamed on the vertical deviation, an
/// `override_index` past the domain was clamped: each is refused with its key and range.
#[test]
fn out_of_range_numbers_name_their_key_and_range() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = crate::root().join("assets/objects/cylinder_d40.stl");
    for (table, key, needle) in [
        ("[sim]\ncontact_stiffness_hz = 1e300", "sim.contact_stiffness_hz", "[1, 1000000] Hz, got 1e300"),
        ("friction = 5e-324", "object.friction", "[0.01, 2]"),
        (
            "[sim]\noverride_angles = [[90.0, 90.0], [90.0, 90.0], [90.0, 90.0]]\noverride_index = 500",
            "sim.override_index",
            "must be in 1..=",
        ),
        ("[planner]\npitch_range_deg = 1e9", "planner.pitch_range_deg", "[0, 90]"),
    ] {
        let (object, rest) = match table.strip_prefix('[') {
            Some(_) => ("", table),
            None => (table, ""),
        };
        let s = dir.path().join("s.toml");
        std::fs::write(
            &s,
            format!("[object]\nmesh = \"{}\"\n{object}\n{rest}\n", mesh.display()),
        )
        .unwrap();
        let out = grasp_sim().arg("--no-sim").arg(&s).output().unwrap();
        refused(&out, &["s.toml", key, needle]);
    }
    let out_dir = tempfile::tempdir().unwrap();
    let out = grasp_sim()
        .args([
            "tune",
            "--param",
            "sf_c=0.5:0.6:0.1",
            "--param",
            "sf_c=0.1:0.2:0.1",
            "--out",
        ])
        .arg(out_dir.path())
        .arg("scenarios/cup.toml")
        .output()
        .unwrap();
    refused(&out, &["--param", "`sf_c` is given twice"]);
}

/// An ASCII STL of two solids (an assembly) was read to its first `endsolid`: half the object.
/// Both cubes count now. A closed 10 km rod and a 0.001 × 1000 mm needle were "surfaces that
/// enclose no volume": the rod is refused for its size with the numbers, the needle plans to
/// its reason. An OBJ cap of 2000 vertices is refused with its line.
#[test]
fn assemblies_long_rods_needles_and_huge_polygons_get_their_real_answer() {
    let dir = tempfile::tempdir().unwrap();
    let ascii = |tris: &[[[f32; 3]; 3]], name: &str| {
        let mut s = format!("solid {name}\n");
        for t in tris {
            s += "facet normal 0 0 0\nouter loop\n";
            for v in t {
                s += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            s += "endloop\nendfacet\n";
        }
        s + &format!("endsolid {name}\n")
    };
    let two = dir.path().join("two.stl");
    std::fs::write(
        &two,
        ascii(&cube([0.0; 3], 40.0), "a") + &ascii(&cube([100.0, 0.0, 0.0], 40.0), "b"),
    )
    .unwrap();
    let v = plan_json(&two);
    assert_eq!(v["object"]["triangles"], 24, "{v}");
    let volume = v["object"]["volume_mm3"].as_f64().unwrap();
    assert!(
        (volume - 128_000.0).abs() < 1e-6,
        "volume {volume} mm³, expected 128000"
    );
    let rod = dir.path().join("rod.stl");
    std::fs::write(&rod, binary_stl(&boxed([0.0; 3], [20.0, 20.0, 1e7]))).unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&rod).output().unwrap();
    refused(
        &out,
        &["rod.stl", "elevation-angle cells", "more than the 400000"],
    );
    let needle = dir.path().join("needle.stl");
    std::fs::write(
        &needle,
        binary_stl(&boxed([0.0; 3], [0.001, 0.001, 1000.0])),
    )
    .unwrap();
    let v = plan_json(&needle);
    assert_eq!(v["plan"]["status"], "ungraspable", "{v}");
    let n = 2000;
    let mut obj = String::new();
    for z in [0.0, 60.0] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            obj += &format!("v {} {} {z}\n", 20.0 * a.cos(), 20.0 * a.sin());
        }
    }
    obj += "f";
    for i in (1..=n).rev() {
        obj += &format!(" {i}");
    }
    obj += "\n";
    let poly = dir.path().join("poly.obj");
    std::fs::write(&poly, obj).unwrap();
    let out = grasp_sim().arg("--no-sim").arg(&poly).output().unwrap();
    refused(
        &out,
        &[
            "poly.obj",
            "line 4001",
            "a face of 2000 vertices, more than the 1024",
        ],
    );
}

/// A hand behind thousands of fixed links took time with the cube of their number; past 2000
/// links it is refused at once, and reversed URDF limits are named as such.
#[test]
fn a_hand_of_thousands_of_links_is_refused_and_reversed_limits_named() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(crate::root().join("assets/hands/bh8.urdf")).unwrap();
    let mount = |n: usize| {
        let mut extra = String::new();
        for k in 0..n {
            extra += &format!("<link name=\"m{k}\"/>");
        }
        for k in 0..n - 1 {
            extra += &format!(
                "<joint name=\"mj{k}\" type=\"fixed\"><parent link=\"m{k}\"/><child link=\"m{}\"/></joint>",
                k + 1
            );
        }
        extra += &format!(
            "<joint name=\"mr\" type=\"fixed\"><parent link=\"m{}\"/><child link=\"palm\"/></joint>",
            n - 1
        );
        src.replace("</robot>", &format!("{extra}</robot>"))
    };
    for (n, ok) in [(1000, true), (2500, false)] {
        let urdf = dir.path().join(format!("m{n}.urdf"));
        std::fs::write(&urdf, mount(n)).unwrap();
        let toml = dir.path().join(format!("m{n}.toml"));
        std::fs::write(&toml, format!("[hand]\nurdf = \"m{n}.urdf\"\n")).unwrap();
        let t0 = std::time::Instant::now();
        let out = grasp_sim()
            .args(["hand", "show"])
            .arg(&toml)
            .arg("--svg")
            .arg(dir.path().join("h.svg"))
            .output()
            .unwrap();
        assert!(t0.elapsed() < std::time::Duration::from_secs(20), "{n}");
        if ok {
            assert_eq!(
                out.status.code(),
                Some(0),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
        } else {
            refused(
                &out,
                &[&format!("m{n}.urdf"), "more than the 2000 a hand may have"],
            );
        }
    }
    let reversed = src.replacen(
        "lower=\"0\" upper=\"3.1416\"",
        "lower=\"3.1416\" upper=\"0\"",
        1,
    );
    assert_ne!(reversed, src);
    std::fs::write(dir.path().join("r.urdf"), reversed).unwrap();
    let toml = dir.path().join("r.toml");
    std::fs::write(&toml, "[hand]\nurdf = \"r.urdf\"\n").unwrap();
    let out = grasp_sim()
        .args(["hand", "show"])
        .arg(&toml)
        .arg("--svg")
        .arg(dir.path().join("h.svg"))
        .output()
        .unwrap();
    refused(&out, &["r.urdf", "the limits are reversed"]);
}

/// An axis-aligned box from `lo` to `hi`, outward-wound.
fn boxed(lo: [f32; 3], hi: [f32; 3]) -> Vec<[[f32; 3]; 3]> {
    let size = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    cube([0.0; 3], 1.0)
        .into_iter()
        .map(|t| {
            t.map(|v| {
                [
                    lo[0] + v[0] * size[0],
                    lo[1] + v[1] * size[1],
                    lo[2] + v[2] * size[2],
                ]
            })
        })
        .collect()
}

/// A stack of thin plates close together (each 60 × 48 × 0.05 mm, 0.1 mm apart) cut along
/// the plates gives a slice of one thin piece per plate; the closing that bridges them shrank
/// a union with a notch between every two plates, in time that grew faster than the square of
/// the plates (issue 56: 300 plates took 21 s to plan, 1000 more than a minute). The notches
/// a finger does not feel are filled before the shrink: 300 plates plan in well under a second.
#[test]
fn a_stack_of_thin_plates_plans_in_time_proportional_to_the_plates() {
    let dir = tempfile::tempdir().unwrap();
    let plates: Vec<[[f32; 3]; 3]> = (0..300)
        .flat_map(|k| {
            let z = k as f32 * 0.1;
            boxed([0.0, 0.0, z], [60.0, 48.0, z + 0.05])
        })
        .collect();
    let stack = dir.path().join("plates.stl");
    std::fs::write(&stack, binary_stl(&plates)).unwrap();
    let t0 = std::time::Instant::now();
    let v = plan_json(&stack);
    let took = t0.elapsed().as_secs_f64();
    assert_eq!(v["object"]["triangles"], 3600, "{v}");
    let domain_ms = v["plan"]["timings_ms"]["stage1_domain"].as_f64().unwrap();
    assert!(
        took < 10.0,
        "300 plates planned in {took:.1} s, expected ~0.3 s"
    );
    assert!(
        domain_ms < 5000.0,
        "stage 1 took {domain_ms:.0} ms, expected ~300 ms"
    );
}

/// Two runs into one `--report` folder sometimes failed with "No such file or directory" (one
/// run's check of the folder removing the other's probe): the folder is now locked for the
/// run, and a second run is refused with the lock's message; the lock file goes with the run.
#[test]
fn a_second_run_into_a_locked_report_folder_gets_the_locks_message() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("rep");
    std::fs::create_dir(&report).unwrap();
    let held = grasp_sim::files::FolderLock::take(&report).unwrap();
    let out = grasp_sim()
        .args(["--no-sim", "--report"])
        .arg(&report)
        .arg("scenarios/cup.toml")
        .output()
        .unwrap();
    refused(
        &out,
        &[
            "--report",
            "rep",
            "in use by another grasp-sim run (locked)",
        ],
    );
    drop(held);
    assert_eq!(std::fs::read_dir(&report).unwrap().count(), 0);
    let out = grasp_sim()
        .args(["--no-sim", "--report"])
        .arg(&report)
        .args(["--export-mjcf"])
        .arg(&report)
        .arg("scenarios/cup.toml")
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!report.join(".grasp-sim.lock").exists());
}

/// "cannot write" said no more (a device, a name too long): each refusal of an output now
/// gives the operating system's reason or the limit.
#[test]
fn an_output_that_cannot_be_written_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let hand = crate::root().join("assets/hands/bh8.toml");
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let long = dir.path().join(format!("{}.svg", "n".repeat(300)));
    for (svg, needle) in [
        (file.join("h.svg"), "Not a directory"),
        (dir.path().join("missing/h.svg"), "no folder"),
        (long, "File name too long"),
        (
            std::path::PathBuf::from("/dev/null"),
            "not a regular file (a device)",
        ),
    ] {
        let out = grasp_sim()
            .args(["hand", "show"])
            .arg(&hand)
            .arg("--svg")
            .arg(&svg)
            .output()
            .unwrap();
        refused(&out, &["cannot write", needle]);
    }
    let out = grasp_sim()
        .args(["--no-sim", "--report"])
        .arg(file.join("rep"))
        .arg("scenarios/cup.toml")
        .output()
        .unwrap();
    refused(
        &out,
        &["--report", "cannot create folder", "Not a directory"],
    );
}

/// `check --grasps given input --out out`, one sample a grasp.
fn check_grasps(
    given: &std::path::Path,
    input: &std::path::Path,
    out: &std::path::Path,
) -> std::process::Output {
    grasp_sim()
        .args(["check", "--samples", "1", "--grasps"])
        .arg(given)
        .arg(input)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// `label` resuming the file that follows, one grasp and one sample per object.
const LABEL_RESUME: [&str; 7] = [
    "label",
    "--grasps",
    "1",
    "--samples",
    "1",
    "--resume",
    "--out",
];

/// A JSON line longer than 16 MiB (`files::MAX_JSON_LINE_BYTES`) is refused before it is
/// parsed: parsed, a line of numbers takes 16–32 times its length in memory, so a results or
/// grasps file of one 1 GiB line (the largest read) would exhaust a machine. In a grasps file it
/// costs its own record only; as a batch's or label's `--out` to resume, or as `tune --labels`,
/// it is refused with its line.
#[test]
fn a_json_line_longer_than_16_mib_is_refused_before_it_is_parsed() {
    let dir = tempfile::tempdir().unwrap();
    let d40 = crate::root().join("assets/objects/cylinder_d40.stl");
    let plan = grasp_sim()
        .args(["--no-sim", "--json"])
        .arg(&d40)
        .output()
        .unwrap();
    let r: serde_json::Value = serde_json::from_slice(&plan.stdout).unwrap();
    let g = &r["plan"]["grasp"];
    let angles: Vec<[f64; 2]> = g["fingers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            [
                f["theta1_deg"].as_f64().unwrap(),
                f["theta2_deg"].as_f64().unwrap(),
            ]
        })
        .collect();
    let good = serde_json::json!({
        "palm_pose": g["palm_pose"],
        "joint_angles_deg": angles,
        "axis_name": g["axis_name"],
    });
    let long = format!("{{\"palm_pose\": [{}1]}}", "1,".repeat(9 << 20));
    assert!(long.len() > 16 << 20);
    let given = dir.path().join("given.jsonl");
    std::fs::write(&given, format!("{long}\n{good}\n")).unwrap();
    let out = dir.path().join("o.jsonl");
    let run = check_grasps(&given, &d40, &out);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    let records: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(records.len(), 2, "{text}");
    let why = records[0]["error"].as_str().unwrap();
    assert!(
        why.starts_with("line 1: a line of ")
            && why.ends_with("longer than the 16 MiB a line may have"),
        "{why}"
    );
    assert_eq!(records[1]["verdict"], "hold", "{}", records[1]);

    // The same line where a file of results is read back.
    let results = dir.path().join("results.jsonl");
    std::fs::write(&results, format!("{long}\n")).unwrap();
    for args in [
        &["batch", "--no-sim", "--resume", "--out"][..],
        &LABEL_RESUME,
    ] {
        let run = grasp_sim()
            .args(args)
            .arg(&results)
            .arg(&d40)
            .output()
            .unwrap();
        refused(&run, &["results.jsonl", "line 1", "longer than the 16 MiB"]);
    }
    let run = grasp_sim()
        .args(["tune", "--labels"])
        .arg(&results)
        .args(["--objective", "first", "--out"])
        .arg(dir.path().join("tune"))
        .output()
        .unwrap();
    refused(
        &run,
        &["results.jsonl: line 1: a line of", "longer than the 16 MiB"],
    );
}

/// Each line given to `check --grasps` becomes a record of some hundred bytes, so a grasps file
/// of short lines within the 1 GiB cap would take hundreds of gigabytes: more than 1,000,000
/// lines (`label::command::MAX_GIVEN_LINES`) are refused before any is read, nothing written.
#[test]
fn a_grasps_file_of_more_lines_than_a_check_takes_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d40 = crate::root().join("assets/objects/cylinder_d40.stl");
    let given = dir.path().join("given.jsonl");
    std::fs::write(&given, "{}\n".repeat(1_000_001)).unwrap();
    let out = dir.path().join("o.jsonl");
    let run = check_grasps(&given, &d40, &out);
    refused(
        &run,
        &["given.jsonl: 1000001 lines, more than the 1000000 one check takes"],
    );
    assert!(!out.exists());
}

/// A batch file read back (`--resume`, `--merge`) holds at most 1,000,000 records
/// (`batch::journal::MAX_RECORDS`): each takes some 1.6 KB besides its line, so a file of short
/// records within the 1 GiB cap would take some 40 GB. Refused with the line past the cap.
#[test]
fn a_batch_file_of_more_records_than_a_batch_holds_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d40 = crate::root().join("assets/objects/cylinder_d40.stl");
    let text: String = (0..1_000_001)
        .map(|i| format!("{{\"batch\":{{\"input\":\"a{i}\",\"input_hash\":\"h\"}}}}\n"))
        .collect();
    let results = dir.path().join("results.jsonl");
    std::fs::write(&results, &text).unwrap();
    let run = grasp_sim()
        .args(["batch", "--no-sim", "--resume", "--out"])
        .arg(&results)
        .arg(&d40)
        .output()
        .unwrap();
    refused(
        &run,
        &["results.jsonl: line 1000001 is not a batch record: more than the 1000000 records"],
    );
    let shards = dir.path().join("shards");
    std::fs::create_dir(&shards).unwrap();
    let half = text.len() / 2;
    let cut = half + text[half..].find('\n').unwrap() + 1;
    std::fs::write(shards.join("a.jsonl"), &text[..cut]).unwrap();
    std::fs::write(shards.join("b.jsonl"), &text[cut..]).unwrap();
    let run = grasp_sim()
        .args(["batch", "--merge"])
        .arg(&shards)
        .arg("--out")
        .arg(dir.path().join("merged.jsonl"))
        .arg(&d40)
        .output()
        .unwrap();
    refused(
        &run,
        &["b.jsonl: more than the 1000000 records a batch file may hold"],
    );
    assert!(!dir.path().join("merged.jsonl").exists());
}

/// `label --resume` reads back at most 1,000,000 lines (`label::command::MAX_GIVEN_LINES`): 2
/// million short label lines took 3.6 GB, so a 1 GiB file of them some 23 GB. Refused with the
/// line past the cap.
#[test]
fn a_label_file_of_more_lines_than_a_resume_takes_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d40 = crate::root().join("assets/objects/cylinder_d40.stl");
    let text: String = (0..1_000_001)
        .map(|i| {
            format!(
                "{{\"grasp_index\":0,\"label\":{{\"input\":\"a{i}\",\"input_hash\":\"h\",\
                 \"grasps\":1,\"wall_ms\":0}}}}\n"
            )
        })
        .collect();
    let labels = dir.path().join("labels.jsonl");
    std::fs::write(&labels, &text).unwrap();
    let run = grasp_sim()
        .args(LABEL_RESUME)
        .arg(&labels)
        .arg(&d40)
        .output()
        .unwrap();
    refused(
        &run,
        &["labels.jsonl: line 1000001 is past the 1000000 lines a label file may hold"],
    );
    assert_eq!(std::fs::read_to_string(&labels).unwrap(), text);
}
