//! MJCF and URDF export: well-formed XML with the expected bodies, joints and actuators.

fn export(scenario: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    crate::succeed(
        crate::grasp_sim()
            .args(["--json", "--no-sim", "--export-mjcf"])
            .arg(dir.path())
            .arg("--export-urdf")
            .arg(dir.path())
            .arg(format!("scenarios/{scenario}.toml")),
    );
    dir
}

fn names<'a>(doc: &'a roxmltree::Document, tag: &str) -> Vec<&'a str> {
    doc.descendants()
        .filter(|n| n.has_tag_name(tag))
        .filter_map(|n| n.attribute("name"))
        .collect()
}

#[test]
fn mjcf_has_the_hand_the_object_and_the_actuators() {
    let dir = export("cylinder_d40");
    let scene = dir.path().join("cylinder_d40");
    let text = std::fs::read_to_string(scene.join("scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&text).expect("well-formed MJCF");
    let bodies = names(&doc, "body");
    let mut expected = vec!["palm".to_string(), "object".to_string()];
    for f in ["finger_1", "finger_2", "finger_3"] {
        expected.push(format!("{f}_phalanx_1"));
        expected.push(format!("{f}_phalanx_2"));
    }
    for e in &expected {
        assert!(bodies.contains(&e.as_str()), "body {e} missing: {bodies:?}");
    }
    let joints: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("joint"))
        .collect();
    assert_eq!(joints.len(), 6);
    for j in &joints {
        assert_eq!(j.attribute("type"), Some("hinge"));
        let r: Vec<f64> = j
            .attribute("range")
            .unwrap()
            .split(' ')
            .map(|v| v.parse().unwrap())
            .collect();
        // Bends of 45°..135° (θ of 135°..45°).
        assert!(
            (r[0] - 45f64.to_radians()).abs() < 1e-6 && (r[1] - 135f64.to_radians()).abs() < 1e-6
        );
    }
    assert_eq!(
        doc.descendants()
            .filter(|n| n.has_tag_name("freejoint"))
            .count(),
        1
    );
    // The hand's contacts as rapier's: only the jointed pairs are kept apart, so the fingers
    // may meet each other and phalanx 2 the palm.
    let mut excluded: Vec<(&str, &str)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("exclude"))
        .map(|n| (n.attribute("body1").unwrap(), n.attribute("body2").unwrap()))
        .collect();
    excluded.sort();
    assert_eq!(
        excluded,
        [
            ("finger_1_phalanx_1", "finger_1_phalanx_2"),
            ("finger_2_phalanx_1", "finger_2_phalanx_2"),
            ("finger_3_phalanx_1", "finger_3_phalanx_2"),
            ("palm", "finger_1_phalanx_1"),
            ("palm", "finger_2_phalanx_1"),
            ("palm", "finger_3_phalanx_1"),
        ]
    );
    let actuators: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("position"))
        .collect();
    assert_eq!(actuators.len(), 6);
    for a in &actuators {
        // The balanced squeeze: the thumb (finger_2) alone on its side at the torque limit,
        // finger_1 and finger_3 sharing the other side at half of it each.
        let thumb = a
            .attribute("name")
            .is_some_and(|n| n.starts_with("finger_2"));
        assert_eq!(
            a.attribute("forcerange"),
            Some(if thumb {
                "-1.000000 1.000000"
            } else {
                "-0.500000 0.500000"
            }),
            "the torque limit"
        );
        assert_eq!(a.attribute("kp"), Some("20"));
    }
    let keys = names(&doc, "key");
    assert_eq!(keys, ["open", "planned"]);
    // The planned keyframe holds the planned joint angles as bends: θ1 = 72.1° is 107.9°.
    let planned = doc
        .descendants()
        .find(|n| n.attribute("name") == Some("planned"))
        .unwrap();
    let q: Vec<f64> = planned
        .attribute("qpos")
        .unwrap()
        .split(' ')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(q.len(), 6 + 7);
    assert!(
        (q[0].to_degrees() - (180.0 - 72.1)).abs() < 0.2,
        "bend {}",
        q[0].to_degrees()
    );
    // The object's mass and the mesh file beside the scene.
    let inertial = doc
        .descendants()
        .find(|n| n.has_tag_name("inertial"))
        .unwrap();
    let mass: f64 = inertial.attribute("mass").unwrap().parse().unwrap();
    assert!((mass - 0.0779).abs() < 1e-3, "mass {mass}");
    assert!(scene.join("object.stl").is_file());
    let protocol: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scene.join("protocol.json")).unwrap())
            .unwrap();
    assert_eq!(protocol["is_revolution"], true);
    assert_eq!(protocol["hold_translation_mm"], 5.0);
}

#[test]
fn a_non_convex_object_is_exported_as_its_convex_parts() {
    let dir = export("chapter4");
    let scene = dir.path().join("chapter4");
    let text = std::fs::read_to_string(scene.join("scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let parts = doc
        .descendants()
        .filter(|n| n.has_tag_name("mesh") && n.attribute("file").is_some())
        .count();
    assert!(parts > 1, "{parts} parts");
    for k in 0..parts {
        assert!(scene.join(format!("object_part_{k}.stl")).is_file());
    }
}

/// A box geom's moment of inertia `[kg·m²]` about the z axis through its body's origin (the
/// hinge): its own about its centre plus the parallel-axis term.
fn box_inertia_about_hinge(geom: roxmltree::Node) -> f64 {
    let nums = |a: &str| -> Vec<f64> {
        geom.attribute(a)
            .unwrap()
            .split(' ')
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (h, c) = (nums("size"), nums("pos"));
    let density: f64 = geom.attribute("density").unwrap().parse().unwrap();
    let mass = density * 8.0 * h[0] * h[1] * h[2];
    mass * ((4.0 * h[0] * h[0] + 4.0 * h[1] * h[1]) / 12.0 + c[0] * c[0] + c[1] * c[1])
}

/// The exported step resolves the fastest finger servo: MuJoCo's `implicitfast` integrates a
/// position servo's stiffness explicitly, and at a step where ω·dt was 1.2 (phalanx 2 on its
/// 20 N·m/rad servo, 0.2 ms) the capped servo swung phalanx 2 at twice the motor law's speed
/// and struck objects out of the hand; at ω·dt 0.29 it was still 1.5 times too fast, at 0.15
/// it follows the law (docs/studies/2026-12-06-mujoco-timestep.md). Phalanx 2 on its servo,
/// and joint 1 under the replay's lock (ten times the stiffness) with the whole finger on it,
/// each within ω·dt 0.15.
#[test]
fn the_mujoco_step_resolves_the_finger_servos() {
    let dir = export("cylinder_d40");
    let text = std::fs::read_to_string(dir.path().join("cylinder_d40/scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let dt: f64 = doc
        .descendants()
        .find(|n| n.has_tag_name("option"))
        .and_then(|n| n.attribute("timestep"))
        .unwrap()
        .parse()
        .unwrap();
    let geom = |name: &str| {
        doc.descendants()
            .find(|n| n.has_tag_name("geom") && n.attribute("name") == Some(name))
            .unwrap_or_else(|| panic!("geom {name}"))
    };
    let kp = |name: &str| -> f64 {
        doc.descendants()
            .find(|n| n.has_tag_name("position") && n.attribute("name") == Some(name))
            .and_then(|n| n.attribute("kp"))
            .unwrap()
            .parse()
            .unwrap()
    };
    for f in ["finger_1", "finger_2", "finger_3"] {
        let i2 = box_inertia_about_hinge(geom(&format!("{f}_phalanx_2")));
        // 3.9 g, 20 mm long: 5.9e-7 kg·m² about joint 2.
        assert!((i2 - 5.9e-7).abs() < 0.1e-7, "{f}: phalanx 2 {i2:e} kg·m²");
        let w2 = (kp(&format!("{f}_joint_2")) / i2).sqrt();
        assert!(
            w2 * dt <= 0.3,
            "{f} joint 2: ω {w2:.0} rad/s, ω·dt {:.2}",
            w2 * dt
        );
        // Joint 1 carries phalanx 1 and, straight out beyond it, phalanx 2 (the least inertia
        // over the bends is at least phalanx 1's alone).
        let i1 = box_inertia_about_hinge(geom(&format!("{f}_phalanx_1")));
        let w1 = (10.0 * kp(&format!("{f}_joint_1")) / i1).sqrt();
        assert!(
            w1 * dt <= 0.3,
            "{f} joint 1 locked: ω {w1:.0} rad/s, ω·dt {:.2}",
            w1 * dt
        );
    }
}

#[test]
fn urdf_has_links_joints_limits_and_effort() {
    let dir = export("cup");
    let text = std::fs::read_to_string(dir.path().join("cup/hand.urdf")).unwrap();
    let doc = roxmltree::Document::parse(&text).expect("well-formed URDF");
    assert_eq!(names(&doc, "link").len(), 7);
    let joints: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("joint"))
        .collect();
    assert_eq!(joints.len(), 6);
    for j in joints {
        assert_eq!(j.attribute("type"), Some("revolute"));
        let limit = j.children().find(|n| n.has_tag_name("limit")).unwrap();
        assert_eq!(limit.attribute("effort"), Some("1"));
        let lo: f64 = limit.attribute("lower").unwrap().parse().unwrap();
        assert!((lo - 45f64.to_radians()).abs() < 1e-6);
    }
}
