//! `--report DIR`: thesis-style SVG figures, planned and simulated glTF scenes, report.html.

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
