//! The experimental physics check (issue 5): what is already reliable about it.

use grasp_sim::scenario::Scenario;
use grasp_sim::{run, RunOptions};
use std::process::Command;

fn scenario_with(mesh: &str, sim: &str) -> (tempfile::TempDir, Scenario) {
    let dir = tempfile::tempdir().unwrap();
    let root = crate::root();
    let s = dir.path().join("s.toml");
    std::fs::write(
        &s,
        format!(
            "[object]\nmesh = \"{}\"\n[hand]\nfile = \"{}\"\n[sim]\n{sim}\n[expect]\noutcome = \"hold\"\n",
            root.join("assets/objects").join(mesh).display(),
            root.join("assets/hands/thesis.toml").display()
        ),
    )
    .unwrap();
    let scenario = Scenario::load(&s).unwrap();
    (dir, scenario)
}

fn with_sim() -> RunOptions {
    RunOptions {
        sim: true,
        ..RunOptions::default()
    }
}

#[test]
fn the_scene_matches_the_plan_and_no_squeeze_means_no_grip() {
    // With no overshoot the motors aim exactly at the planned angles: the fingers must stop
    // there (the rapier hand is the planner's hand, joint for joint), and with no squeeze there
    // is no grip, so the object is not held under gravity (DESIGN.md 5: a target at contact
    // squeezes with almost no force).
    let (_d, s) = scenario_with("cylinder_d40.stl", "squeeze_deg = 0.0");
    let r = run(&s, &with_sim()).unwrap();
    let dir = &r.sim.directions[0];
    for (k, e) in dir.joint_errors_deg.iter().enumerate() {
        for (j, err) in e.iter().enumerate() {
            assert!(
                err.abs() < 0.5,
                "finger {k} joint {}: {err} deg off the plan",
                j + 1
            );
        }
    }
    assert_ne!(r.sim.verdict, "hold", "{:?}", r.sim);
    assert!(r.sim.translation_mm.unwrap() > 5.0, "{:?}", r.sim);
    // With the default 10° overshoot the fingers do grip: the object does not fall.
    let (_d, s) = scenario_with("cylinder_d40.stl", "");
    let r = run(&s, &with_sim()).unwrap();
    assert_ne!(r.sim.verdict, "drop", "{:?}", r.sim);
    assert!(r.sim.translation_mm.unwrap() < 20.0, "{:?}", r.sim);
}

#[test]
fn open_fingers_drop_the_object() {
    let root = crate::root();
    let out = Command::new(env!("CARGO_BIN_EXE_grasp-sim"))
        .current_dir(&root)
        .args(["--json", "--sim", "scenarios/sim_open_fingers.toml"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["sim"]["verdict"], "drop");
    assert_eq!(v["sim"]["grasp_source"], "override_angles");
    assert_eq!(v["expect"]["met"], true);
    assert!(v["sim"]["translation_mm"].as_f64().unwrap() > 100.0);
}

#[test]
fn without_sim_the_check_is_reported_as_not_run() {
    let (_d, s) = scenario_with("cylinder_d40.stl", "");
    let r = run(&s, &RunOptions::default()).unwrap();
    assert_eq!(r.sim.verdict, "not_run");
    assert!(r.sim.reason.as_deref().unwrap().contains("--sim"));
    assert!(r.sim.translation_mm.is_none());
}

#[test]
fn the_same_scenario_gives_the_same_sim_numbers() {
    let (_d, s) = scenario_with("cup.stl", "gravity = \"down\"");
    let a = run(&s, &with_sim()).unwrap();
    let b = run(&s, &with_sim()).unwrap();
    assert_eq!(a.sim.translation_mm, b.sim.translation_mm);
    assert_eq!(a.sim.rotation_deg, b.sim.rotation_deg);
    assert_eq!(a.sim.steps, b.sim.steps);
    let strip = |r: &grasp_sim::report::RunReport| {
        let mut v = serde_json::to_value(r).unwrap();
        v["sim"]["wall_ms"] = serde_json::Value::Null;
        v["plan"]["timings_ms"] = serde_json::Value::Null;
        v
    };
    assert_eq!(strip(&a), strip(&b));
}

#[test]
fn rapier_tolerances_are_pinned_at_hand_scale() {
    // At rapier's default length unit (1 m) the allowed penetration would be 5 mm and the
    // prediction distance 20 mm: most of a 40 mm object. grasp-sim sets a 1 cm unit.
    use grasp_sim::sim::scene::{build, ObjectShape, SimHand};
    let (_d, s) = scenario_with("cylinder_d40.stl", "");
    let mesh = grasp_sim::objects::cylinder(40.0, 124.0);
    let shape = ObjectShape::from_mesh(&mesh, grasp_sim::mesh::mass_properties(&mesh).volume_mm3);
    assert_eq!(shape.kind, "convex_hull");
    let pose = SimHand {
        origin_mm: nalgebra::Point3::new(20.0, 0.0, 87.0),
        axes: [
            nalgebra::Vector3::x(),
            nalgebra::Vector3::y(),
            nalgebra::Vector3::z(),
        ],
        theta_deg: vec![[72.1, 91.8]; 3],
    };
    let scene = build(&s.hand, &pose, &shape, 0.078, 0.3, &s.sim);
    let ip = &scene.world.integration_parameters;
    assert!(
        (ip.allowed_linear_error() - 5e-5).abs() < 1e-9,
        "{}",
        ip.allowed_linear_error()
    );
    assert!(
        (ip.prediction_distance() - 2e-4).abs() < 1e-9,
        "{}",
        ip.prediction_distance()
    );
    // The chapter 4 object is not convex: it gets a convex decomposition, not a hull.
    let c4 = grasp_sim::objects::chapter4(&grasp_sim::objects::Chapter4Dims::default());
    let c4_shape = ObjectShape::from_mesh(&c4, grasp_sim::mesh::mass_properties(&c4).volume_mm3);
    assert_eq!(c4_shape.kind, "convex_decomposition");
    assert!(c4_shape.parts > 1);
}
