//! `--report DIR`: thesis-style SVG figures, planned and simulated glTF scenes, report.html, and
//! an ungraspable object's rejections.

fn report(scenario: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    crate::succeed(
        crate::grasp_sim()
            .arg(format!("scenarios/{scenario}.toml"))
            .arg("--report")
            .arg(dir.path()),
    );
    dir
}

#[test]
fn the_report_has_figures_scenes_and_a_page() {
    let dir = report("cup");
    let d = dir.path().join("cup");
    // Every figure is well-formed SVG and draws its series.
    for (name, classes) in [
        (
            "effective_elevation",
            &["object", "effective-elevation", "indexed-elevation"][..],
        ),
        ("grades_curvature", &["grade"][..]),
        ("grades_diameter", &["grade"][..]),
        ("grades_combined", &["grade"][..]),
        ("grades_palm", &["grade", "ungraspable"][..]),
        (
            "palm",
            &[
                "object",
                "palm-outline",
                "palm-contact-line",
                "palm-contact",
            ][..],
        ),
        ("finger_planes", &["object", "finger-plane"][..]),
        (
            "finger_1",
            &[
                "object",
                "palm-contact-line",
                "phalanx-1-domain",
                "phalanx-2-domain",
                "als",
                "joint",
            ][..],
        ),
        ("finger_2", &["object", "als"][..]),
        ("finger_3", &["object", "als"][..]),
    ] {
        let text = std::fs::read_to_string(d.join(format!("{name}.svg"))).unwrap();
        let doc = roxmltree::Document::parse(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
        for c in classes {
            assert!(
                doc.descendants().any(|n| n.attribute("class") == Some(*c)),
                "{name}: no `{c}` series"
            );
        }
        assert!(text.contains("mm"), "{name}: axes in mm");
    }
    // 39 indexed elevations, one bar each.
    let grades = std::fs::read_to_string(d.join("grades_combined.svg")).unwrap();
    assert_eq!(
        grades.matches("class=\"grade\"").count() + grades.matches("class=\"ungraspable\"").count(),
        39
    );
    // Both scenes parse with the gltf crate's reader and hold one node per body.
    for scene in ["grasp_planned.glb", "grasp_simulated.glb"] {
        let bytes = std::fs::read(d.join(scene)).unwrap();
        let g = gltf::Gltf::from_slice(&bytes).unwrap_or_else(|e| panic!("{scene}: {e}"));
        let names: Vec<String> = g
            .nodes()
            .filter_map(|n| n.name().map(str::to_string))
            .collect();
        for n in [
            "grasp",
            "palm",
            "object",
            "finger_1_phalanx_1",
            "finger_2_phalanx_2",
            "finger_3_phalanx_1",
        ] {
            assert!(
                names.iter().any(|x| x == n),
                "{scene}: node {n} missing in {names:?}"
            );
        }
        assert_eq!(g.meshes().count(), 8);
    }
    // The planned and simulated scenes differ (the physics moved the fingers onto the object).
    assert_ne!(
        std::fs::read(d.join("grasp_planned.glb")).unwrap(),
        std::fs::read(d.join("grasp_simulated.glb")).unwrap()
    );
    // One self-contained page: the verdict, the Grasp Parameter Set, every figure inline, and
    // nothing fetched from elsewhere.
    let html = std::fs::read_to_string(d.join("report.html")).unwrap();
    assert!(html.contains("Physics check: hold"));
    assert!(html.contains("Grasp Parameter Set") && html.contains("Palm_Pitch_Angle"));
    assert_eq!(html.matches("<svg").count(), 13);
    for remote in ["http://", "https://", "<script", "src=\""] {
        let hits = html.matches(remote).count();
        let allowed = if remote == "http://" { 13 } else { 0 }; // the SVG namespace only
        assert_eq!(hits, allowed, "{remote} appears {hits} times");
    }
}

#[test]
fn an_ungraspable_object_still_gets_its_stage_figures() {
    let dir = report("cylinder_d10");
    let d = dir.path().join("cylinder_d10");
    assert!(d.join("effective_elevation.svg").is_file());
    assert!(d.join("grades_diameter.svg").is_file());
    assert!(!d.join("palm.svg").exists());
    assert!(!d.join("grasp_planned.glb").exists());
    let html = std::fs::read_to_string(d.join("report.html")).unwrap();
    assert!(html.contains("ungraspable"));
}

#[test]
fn the_report_shows_the_grasp_in_three_views() {
    // Issue 33: the planned hand (dashed) and the hand where the closing left it (filled) over
    // the object, from above, the side and obliquely, with the closing's shift in the legend.
    let dir = report("cylinder_d40");
    let d = dir.path().join("cylinder_d40");
    let html = std::fs::read_to_string(d.join("report.html")).unwrap();
    let json = crate::succeed(crate::grasp_sim().args(["--json", "scenarios/cylinder_d40.toml"]));
    let r: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let shift = r["sim"]["closing"]["shift_mm"].as_f64().unwrap();
    let legend = format!("closing shift {shift:.1} mm");
    for view in ["view_top", "view_side", "view_oblique"] {
        let text = std::fs::read_to_string(d.join(format!("{view}.svg"))).unwrap();
        let doc = roxmltree::Document::parse(&text).unwrap_or_else(|e| panic!("{view}: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
        // The object's triangles and the closed hand's faces, filled ...
        let polygons = doc
            .descendants()
            .filter(|n| n.has_tag_name("polygon"))
            .count();
        assert!(polygons > 100, "{view}: {polygons} polygons");
        // ... and the planned hand: 12 dashed edges per box, 7 bodies (phalanx 2 with no tip).
        let dashed = doc
            .descendants()
            .filter(|n| n.has_tag_name("line") && n.attribute("stroke") == Some("#1f4fbf"))
            .count();
        assert_eq!(dashed, 12 * 7, "{view}");
        assert!(text.contains(&legend), "{view}: no `{legend}`");
        // Inline in the page, as written.
        assert!(html.contains(&text), "{view} not inline in report.html");
    }
    assert!(html.contains("The grasp in three views"));
    assert!(html.contains("closed theta1 [deg]"));
    // The same run writes the same views, byte for byte.
    let again = report("cylinder_d40");
    for view in ["view_top", "view_side", "view_oblique"] {
        let a = std::fs::read(d.join(format!("{view}.svg"))).unwrap();
        let b = std::fs::read(
            again
                .path()
                .join("cylinder_d40")
                .join(format!("{view}.svg")),
        )
        .unwrap();
        assert_eq!(a, b, "{view}");
    }
}

#[test]
fn the_report_page_explains_in_tables_words_links_and_figures() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path();
    let run = crate::succeed(
        crate::grasp_sim()
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
    crate::succeed(
        crate::grasp_sim()
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
    crate::succeed(
        crate::grasp_sim()
            .arg(&scenario)
            .args(["--no-sim", "--report"])
            .arg(&out),
    );
    let why = std::fs::read_to_string(out.join("cup_no_pitch/rejections.svg")).unwrap();
    assert!(why.contains("palm pitch out of range ("), "{why}");
    assert!(why.contains("class=\"rejection\""), "{why}");
}
