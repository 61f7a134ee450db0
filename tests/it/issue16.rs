//! Issue 16, the rest: progress on a terminal, every candidate in the summary, tune's invalid
//! settings, "did you mean", welding within a tolerance, rounded JSON figures, the report page.

use crate::{grasp_sim, succeed};

/// Runs `args` under `script`, so that stderr is a terminal; `None` where `script` is missing.
fn on_a_terminal(args: &str) -> Option<String> {
    let bin = env!("CARGO_BIN_EXE_grasp-sim");
    let out = std::process::Command::new("script")
        .args(["-qec", &format!("{bin} {args} >/dev/null"), "/dev/null"])
        .current_dir(crate::root())
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn long_runs_show_progress_on_a_terminal_only() {
    let Some(tty) = on_a_terminal("scenarios/cylinder_d40.toml") else {
        eprintln!("no `script` here: the terminal half is not checked");
        return;
    };
    assert!(
        tty.contains("cylinder_d40: planning, physics check"),
        "{tty}"
    );
    let piped = succeed(grasp_sim().args(["scenarios/cylinder_d40.toml"]));
    let err = String::from_utf8_lossy(&piped.stderr);
    assert!(!err.contains("physics check"), "{err}");

    let out = tempfile::tempdir().unwrap();
    let args = format!(
        "tune scenarios/cylinder_d40.toml --param sf_c=0:1:1 --out {}",
        out.path().display()
    );
    let tty = on_a_terminal(&args).expect("tune runs");
    assert!(tty.contains("/2") && tty.contains("tune: "), "{tty}");
    let piped = succeed(grasp_sim().args(args.split(' ')));
    let err = String::from_utf8_lossy(&piped.stderr);
    assert!(!err.contains("done at one setting"), "{err}");
}

#[test]
fn the_summary_lists_every_candidate_collected_or_checked() {
    let out = succeed(grasp_sim().args(["scenarios/cup.toml", "--no-sim", "--candidates", "3"]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("3 candidates tried"), "{text}");
    assert!(text.contains("Candidates  3 collected"), "{text}");
    for (k, approach) in [(1, 0), (2, 10), (3, 20)] {
        assert!(
            text.contains(&format!(
                "{k}. axis least (thesis), approach {approach} deg"
            )),
            "{text}"
        );
    }
    assert!(
        text.contains("* 1. "),
        "the reported grasp is marked: {text}"
    );
    // Checked by the physics check: each candidate's verdict, and how many were checked.
    let out = grasp_sim()
        .args(["scenarios/sim_d40_slippery_heavy.toml"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("8 candidates tried, 8 checked"), "{text}");
    assert_eq!(text.matches("; check: drop (").count(), 8, "{text}");
    // A single grasp is not listed twice.
    let out = succeed(grasp_sim().args(["scenarios/cup.toml", "--no-sim"]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("Candidates  "), "{text}");
}

#[test]
fn tune_says_why_a_setting_is_invalid_and_does_not_rank_it() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().display().to_string();
    // 3 mm does not divide the 25 mm finger gap; 2.5 mm does.
    let run = grasp_sim()
        .args([
            "tune",
            "scenarios/cylinder_d10.toml",
            "--param",
            "height_step_mm=2.5:3:0.5",
            "--out",
            &dir,
        ])
        .output()
        .unwrap();
    crate::assert_success(&run);
    let table = String::from_utf8_lossy(&run.stdout);
    let row = table
        .lines()
        .find(|l| l.trim_start().starts_with('3'))
        .unwrap();
    assert!(
        row.contains("invalid, not ranked") && row.contains("must divide the finger gap of 25 mm"),
        "{table}"
    );
    assert!(!row.contains("best"), "{table}");
    let csv = std::fs::read_to_string(out.path().join("tune.csv")).unwrap();
    let line = csv.lines().find(|l| l.starts_with("3,")).unwrap();
    assert!(line.starts_with("3,,,,,,1,\""), "{csv}");
    let header = csv.lines().next().unwrap();
    assert_eq!(header.split(',').count(), 8, "{csv}");
    assert!(!table.contains("-0.00"), "{table}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("tune.json")).unwrap())
            .unwrap();
    assert!(json["settings"][1]["invalid"]
        .as_str()
        .unwrap()
        .contains("height_step_mm"));
    assert!(json["settings"][0].get("invalid").is_none());
    // Every setting invalid: nothing to rank is bad input.
    let run = grasp_sim()
        .args([
            "tune",
            "scenarios/cylinder_d10.toml",
            "--param",
            "height_step_mm=3:3:1",
            "--out",
            &dir,
        ])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("every setting is invalid"), "{err}");
}

#[test]
fn an_invalid_setting_is_ranked_below_none_of_the_valid_ones() {
    use grasp_sim::tune::{parse_sweep, tune};
    // The D10 cylinder is ungraspable at every setting: all valid settings score 0, as the
    // invalid one would; the best must still be a valid one, even when the invalid one is first.
    let items =
        grasp_sim::batch::expand(&[crate::root().join("scenarios/cylinder_d10.toml")]).unwrap();
    let r = tune(
        &items,
        &grasp_sim::batch::default_template(),
        &[parse_sweep("height_step_mm=2:2.5:0.5").unwrap()],
        1,
        1,
    )
    .unwrap();
    assert!(r.settings[0].invalid.is_some(), "{:?}", r.settings[0]);
    assert_eq!(r.best, 1);
}

#[test]
fn a_mistyped_key_gets_a_did_you_mean() {
    let dir = tempfile::tempdir().unwrap();
    let cup = crate::root().join("assets/objects/cup.stl");
    let write = |name: &str, text: String| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let err = |p: &std::path::Path| {
        let out = grasp_sim().arg(p).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let mesh = cup.display();
    // A scenario key, a section name, a hand-file key and an override key.
    let p = write(
        "a.toml",
        format!("[object]\nmesh = \"{mesh}\"\ndensty_kg_m3 = 3\n"),
    );
    assert!(
        err(&p).contains("did you mean `density_kg_m3`?"),
        "{}",
        err(&p)
    );
    let p = write("b.toml", format!("[object]\nmesh = \"{mesh}\"\n[planer]\n"));
    assert!(
        err(&p).contains("unknown section `[planer]`")
            && err(&p).contains("did you mean `[planner]`?"),
        "{}",
        err(&p)
    );
    // A value of the wrong type is named in the file's words, not Rust's.
    let p = write(
        "t.toml",
        format!("[object]\nmesh = \"{mesh}\"\n[sim]\nduration_s = \"2\"\n"),
    );
    assert!(err(&p).contains("expected a number"), "{}", err(&p));
    let p = write(
        "g.toml",
        format!("[object]\nmesh = \"{mesh}\"\n[sim]\ngravity = 6\n"),
    );
    assert!(err(&p).contains("expected a name in quotes"), "{}", err(&p));
    let hand = std::fs::read_to_string(crate::root().join("assets/hands/thesis.toml")).unwrap();
    write(
        "h.toml",
        hand.replacen("\nmargin_mm = ", "\nmargn_mm = ", 1),
    );
    let p = write(
        "c.toml",
        format!("[object]\nmesh = \"{mesh}\"\n[hand]\nfile = \"h.toml\"\n"),
    );
    let e = err(&p);
    assert!(
        e.contains("h.toml: line ") && e.contains("did you mean `margin_mm`?"),
        "{e}"
    );
    let p = write(
        "d.toml",
        format!(
            "[object]\nmesh = \"{mesh}\"\n[hand]\noverrides = {{ \"phalanx_2.lenght_mm\" = 18.0 }}\n"
        ),
    );
    assert!(
        err(&p).contains("did you mean `phalanx_2.length_mm`?"),
        "{}",
        err(&p)
    );
    // Nothing near: no guess.
    let p = write(
        "e.toml",
        format!("[object]\nmesh = \"{mesh}\"\ncolour = 3\n"),
    );
    assert!(!err(&p).contains("did you mean"), "{}", err(&p));
}

#[test]
fn a_malformed_ascii_stl_names_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 x\nendloop\nendfacet\nendsolid\n",
            "line 6 (`vertex 0 1 x`): expected `vertex x y z`",
        ),
        (
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n",
            "line 6 (end of file): expected `vertex`",
        ),
        (
            "\nsolid t\n  facet normal 0 0 1\n  outer lop\n",
            "line 4 (`outer lop`): expected `outer loop`",
        ),
        (
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n",
            "line 4 (`vertex nan 0 0`): expected `vertex x y z`, with finite numbers",
        ),
    ];
    for (k, (text, needle)) in cases.iter().enumerate() {
        let p = dir.path().join(format!("m{k}.stl"));
        std::fs::write(&p, text).unwrap();
        let out = grasp_sim().arg(&p).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

#[test]
fn payload_without_the_physics_check_says_it_is_ignored() {
    let out = succeed(grasp_sim().args(["scenarios/cup.toml", "--no-sim", "--payload"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--payload is ignored with --no-sim"), "{err}");
    let out = succeed(grasp_sim().args(["scenarios/cup.toml", "--no-sim"]));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("--payload"));
}

/// A closed box as ASCII STL in metres, one corner written as 1e-18 in some of its triangles
/// and as 0 in the others.
fn box_with_a_noisy_seam() -> String {
    let (a, b, c) = (0.04f64, 0.05f64, 0.11f64);
    let v = |i: usize, noisy: bool| -> [f64; 3] {
        let p = [
            if i & 1 == 1 { a } else { 0.0 },
            if i & 2 == 2 { b } else { 0.0 },
            if i & 4 == 4 { c } else { 0.0 },
        ];
        if i == 0 && noisy {
            [1e-18, 1e-18, 0.0]
        } else {
            p
        }
    };
    // Outward-wound quads of the box (corners by bit: x = 1, y = 2, z = 4).
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut s = String::from("solid box\n");
    for (k, q) in quads.iter().enumerate() {
        for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            s.push_str("facet normal 0 0 0\nouter loop\n");
            for i in tri {
                let p = v(i, k == 2);
                s.push_str(&format!("vertex {:e} {:e} {:e}\n", p[0], p[1], p[2]));
            }
            s.push_str("endloop\nendfacet\n");
        }
    }
    s.push_str("endsolid box\n");
    s
}

#[test]
fn a_seam_off_by_rounding_is_welded() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("box.stl");
    std::fs::write(&p, box_with_a_noisy_seam()).unwrap();
    let out = succeed(
        grasp_sim()
            .args(["--json", "--no-sim", "--units", "m"])
            .arg(&p),
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["object"]["boundary_edges"], 0, "{}", v["object"]);
    assert_eq!(v["object"]["triangles"], 12);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("boundary"), "{err}");
    // Distinct vertices a file can tell apart stay apart: the thesis objects keep their counts.
    let loaded = grasp_sim::mesh::load_mesh(
        &crate::root().join("assets/objects/cup.stl"),
        grasp_sim::mesh::LengthUnit::Mm,
    )
    .unwrap();
    assert_eq!(loaded.topology.boundary_edges, 0);
    assert_eq!(loaded.mesh.triangles.len(), 576);
}

#[test]
fn json_figures_carry_no_float_noise() {
    let out = succeed(grasp_sim().args(["--json", "--no-sim", "scenarios/chapter4.toml"]));
    let text = String::from_utf8_lossy(&out.stdout);
    // Every number outside strings has at most 12 significant digits and none is a tiny
    // leftover of a cancellation (3.6e-16 mm) or a negative zero.
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    fn walk(v: &serde_json::Value, bad: &mut Vec<String>) {
        match v {
            serde_json::Value::Number(n) => {
                if let Some(x) = n.as_f64().filter(|_| n.is_f64()) {
                    let rounded = grasp_sim::report::round_significant(x, 12);
                    if rounded != x || (x != 0.0 && x.abs() < 1e-10) || n.to_string() == "-0.0" {
                        bad.push(n.to_string());
                    }
                }
            }
            serde_json::Value::Array(a) => a.iter().for_each(|x| walk(x, bad)),
            serde_json::Value::Object(o) => o.values().for_each(|x| walk(x, bad)),
            _ => {}
        }
    }
    let mut bad = Vec::new();
    walk(&v, &mut bad);
    assert!(bad.is_empty(), "{bad:?}");
    // Field order is the contract's (scenario first), not alphabetical.
    assert!(text.starts_with("{\"scenario\":"), "{}", &text[..40]);
}

#[test]
fn the_report_page_explains_in_tables_words_links_and_figures() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path();
    let run = succeed(
        grasp_sim()
            .args([
                "scenarios/cup.toml",
                "scenarios/cylinder_d10.toml",
                "--report",
            ])
            .arg(dir),
    );
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains(&format!(
            "report written to {}",
            dir.join("cup").join("report.html").display()
        )),
        "{err}"
    );
    let cup = std::fs::read_to_string(dir.join("cup/report.html")).unwrap();
    // The Grasp Parameter Set is a table, the scenes are linked.
    assert!(cup.contains("<table class=\"gps\">"), "{cup}");
    assert!(cup.contains("<td>finger_1</td><td>98.2</td><td>116.8</td>"));
    assert!(cup.contains("<a href=\"grasp_planned.glb\">"));
    assert!(cup.contains("<a href=\"grasp_simulated.glb\">"));
    assert!(dir.join("cup/grasp_simulated.glb").exists());
    // Legends sit above the frame, and data is clipped to the frame.
    let svg = std::fs::read_to_string(dir.join("cup/finger_1.svg")).unwrap();
    assert!(svg.contains("<clipPath id=\"frame-") && svg.contains("clip-path=\"url(#frame-"));
    let legend_y: Vec<f64> = svg
        .lines()
        .filter(|l| l.contains("class=\"legend\""))
        .map(|l| {
            let y = l.split(" y=\"").nth(2).unwrap();
            y[..y.find('"').unwrap()].parse().unwrap()
        })
        .collect();
    assert!(
        !legend_y.is_empty() && legend_y.iter().all(|y| *y < 62.0),
        "{legend_y:?}"
    );
    // The widest legend entry ends inside the figure.
    let planes = std::fs::read_to_string(dir.join("cup/finger_planes.svg")).unwrap();
    let width: f64 = {
        let w = planes.split("width=\"").nth(1).unwrap();
        w[..w.find('"').unwrap()].parse().unwrap()
    };
    let line = planes
        .lines()
        .find(|l| l.contains("top, centre and bottom plane"))
        .unwrap();
    let x: f64 = {
        let x = line.split("<text class=\"legend\" x=\"").nth(1).unwrap();
        x[..x.find('"').unwrap()].parse().unwrap()
    };
    assert!(x + 6.2 * 43.0 < width, "legend at {x} in {width}");
    // An ungraspable object: the not-run check in words, and a figure of what decided it.
    let d10 = std::fs::read_to_string(dir.join("cylinder_d10/report.html")).unwrap();
    assert!(d10.contains("Physics check: not run (no feasible grasp to check)"));
    assert!(!d10.contains("not_run"), "raw token on the page");
    assert!(d10.contains("id=\"rejections\""));
    let why = std::fs::read_to_string(dir.join("cylinder_d10/rejections.svg")).unwrap();
    assert!(why.contains("too thin"), "{why}");
    // A re-run into the same folder without the physics check removes the stale scene.
    succeed(
        grasp_sim()
            .args(["scenarios/cup.toml", "--no-sim", "--report"])
            .arg(dir),
    );
    assert!(!dir.join("cup/grasp_simulated.glb").exists());
    let cup = std::fs::read_to_string(dir.join("cup/report.html")).unwrap();
    assert!(!cup.contains("grasp_simulated.glb"));
    assert!(cup.contains("Physics check: not run (--no-sim)"));
}

#[test]
fn an_ungraspable_object_shows_the_constraints_that_rejected_it() {
    // The cup without palm pitch under the thesis's rules alone (the extended rules pinch it
    // across its rim: tests/it/tune.rs).
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("cup_no_pitch.toml");
    std::fs::write(
        &scenario,
        format!(
            "[object]\nmesh = \"{}\"\n[planner]\npitch_range_deg = 0.0\nangular_step_deg = 30.0\nextended_rules = false\n",
            crate::root().join("assets/objects/cup.stl").display()
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    succeed(
        grasp_sim()
            .arg(&scenario)
            .args(["--no-sim", "--report"])
            .arg(&out),
    );
    let why = std::fs::read_to_string(out.join("cup_no_pitch/rejections.svg")).unwrap();
    assert!(why.contains("palm pitch out of range ("), "{why}");
    assert!(why.contains("class=\"rejection\""), "{why}");
}

/// The newcomer's path of 2026-12-01: one bad input does not sink a `tune`, an output file
/// that is a folder and a folder with nothing to run are refused before any work, two inputs
/// of one name write two output folders, and `--units` on a scenario says it does not apply.
#[test]
fn tune_batch_and_outputs_keep_the_good_inputs_and_refuse_bad_paths_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = crate::root().join("assets/objects/cylinder_d40.stl");
    let bad = d.join("nan.stl");
    std::fs::write(&bad, "solid t\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n").unwrap();
    // tune: the bad mesh is named and left out, the good one tuned on, the results written,
    // exit 2.
    let out_dir = d.join("tune");
    let out = grasp_sim()
        .args(["tune", "--param", "sf_c=0:1:1", "--out"])
        .arg(&out_dir)
        .arg(&good)
        .arg(&bad)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("nan.stl: malformed ASCII STL: line 4"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("over 1 object"));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("tune.json")).unwrap()).unwrap();
    assert_eq!(json["skipped"][0][0], bad.display().to_string());
    assert_eq!(json["counters"]["objects_loaded"], 1);
    // tune on the bad mesh alone: its error, nothing written.
    let alone = d.join("tune_alone");
    let out = grasp_sim()
        .args(["tune", "--param", "sf_c=0:1:1", "--out"])
        .arg(&alone)
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(!alone.join("tune.json").exists());
    // A folder with nothing to run, for tune and batch: an error naming it, no work done.
    let empty = d.join("only_dae");
    std::fs::create_dir(&empty).unwrap();
    std::fs::write(empty.join("mug.dae"), "<COLLADA/>").unwrap();
    for args in [
        vec!["batch".to_string()],
        vec![
            "tune".into(),
            "--param".into(),
            "sf_c=0:1:1".into(),
            "--out".into(),
            d.join("t2").display().to_string(),
        ],
    ] {
        let out = grasp_sim().args(&args).arg(&empty).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("no scenario (.toml) or mesh (.stl, .obj, .ply, .urdf) in this folder"),
            "{err}"
        );
    }
    // batch --out naming a folder: refused before the object runs.
    let out = grasp_sim()
        .arg("batch")
        .arg(&good)
        .arg("--out")
        .arg(d)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("is a folder; give a file to write the results to"),
        "{err}"
    );
    assert!(!err.contains("[1/1]") && !err.contains("hold"), "{err}");
    // Two inputs of one name: two report folders, the second told.
    for sub in ["a", "b"] {
        std::fs::create_dir(d.join(sub)).unwrap();
        std::fs::copy(&good, d.join(sub).join("obj.stl")).unwrap();
    }
    let reports = d.join("reports");
    let out = grasp_sim()
        .args(["--no-sim", "--report"])
        .arg(&reports)
        .arg(d.join("a/obj.stl"))
        .arg(d.join("b/obj.stl"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(reports.join("obj/report.html").is_file());
    assert!(reports.join("obj-2/report.html").is_file());
    assert!(
        err.contains("an earlier input has the name `obj`; its output folders are `obj-2`"),
        "{err}"
    );
    // --units on a scenario: it does not apply, and the run says so.
    let out = succeed(grasp_sim().args(["--no-sim", "--units", "m", "scenarios/cup.toml"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--units m applies to bare meshes"), "{err}");
}

#[test]
fn the_summary_names_the_grasp_axis_and_the_rules_beyond_the_thesis() {
    // A 50 x 70 x 150 mm box: the thesis's rules find nothing (the palm meets the object in
    // its plane), the extended rules back the palm off. The Plan line says so.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("box.stl");
    std::fs::write(
        &p,
        grasp_sim::objects::prism(50.0, 70.0, 150.0).to_binary_stl(),
    )
    .unwrap();
    let out = succeed(grasp_sim().arg("--no-sim").arg(&p));
    let text = String::from_utf8_lossy(&out.stdout);
    let plan = text
        .lines()
        .find(|l| l.trim_start().starts_with("Plan "))
        .unwrap();
    let json = succeed(grasp_sim().args(["--no-sim", "--json"]).arg(&p));
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let g = &v["plan"]["grasp"];
    assert_eq!(g["rules"], "extended", "{g}");
    assert_eq!(g["relaxations"][0], "palm_backed_off", "{g}");
    assert!(
        plan.contains("feasible under rules beyond the thesis (extended: palm_backed_off)"),
        "{plan}"
    );
    // About its least axis, as the Object line: no Grasp axis line.
    assert_eq!(g["axis_name"], "least");
    assert!(!text.contains("Grasp axis"), "{text}");
    // The thesis's cup plans under the thesis's rules: the Plan line says nothing more.
    let cup = succeed(grasp_sim().args(["--no-sim", "scenarios/cup.toml"]));
    let cup = String::from_utf8_lossy(&cup.stdout);
    assert!(cup.contains("  Plan        feasible; "), "{cup}");
    // An open tube (no caps) is grasped about its own axis. The mass properties of its open
    // surface make that axis the largest; the object's own frame (docs/FRAMES.md, issue 30)
    // takes its moments from a fan of tetrahedra from the surface's centroid, which encloses
    // the tube's solid, so its own axis is the least: the Object line's height is along it,
    // and there is no Grasp axis line.
    let tube = dir.path().join("tube.stl");
    std::fs::write(&tube, open_tube(30.0, 120.0, 64)).unwrap();
    let out = succeed(grasp_sim().args(["--no-sim", "--json"]).arg(&tube));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        v["plan"]["grasp"]["axis_name"], "least",
        "{}",
        v["plan"]["grasp"]
    );
    let out = succeed(grasp_sim().arg("--no-sim").arg(&tube));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("height 120.0 mm") && !text.contains("Grasp axis"),
        "{text}"
    );
}

/// An open tube of radius `r` and height `h` on `n` facets (no caps), as ASCII STL.
fn open_tube(r: f64, h: f64, n: usize) -> String {
    use std::f64::consts::TAU;
    let p = |k: usize, z: f64| {
        let a = TAU * k as f64 / n as f64;
        format!("vertex {} {} {z}\n", r * a.cos(), r * a.sin())
    };
    let mut s = String::from("solid tube\n");
    for k in 0..n {
        for tri in [
            [p(k, 0.0), p(k + 1, 0.0), p(k + 1, h)],
            [p(k, 0.0), p(k + 1, h), p(k, h)],
        ] {
            s.push_str("facet normal 0 0 0\nouter loop\n");
            s.extend(tri);
            s.push_str("endloop\nendfacet\n");
        }
    }
    s.push_str("endsolid tube\n");
    s
}
