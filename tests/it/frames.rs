//! Frame invariance (issue 30): every real-object mesh written in five random rigid frames
//! (a fixed seed) must plan with the same status, the same grasp in the object's own (aligned)
//! frame within 0.5 mm and 0.5°, and the same verdict.
//!
//! `cargo test` runs the comparison, plan only, on eight committed real meshes chosen for the
//! rule each exercises (`eight_real_objects_plan_alike_in_five_random_frames`) and on synthetic
//! shapes. The full set, with the physics check, is long, so it is `#[ignore]`d; run it with
//!
//!     cargo test --release frames -- --ignored --nocapture
//!
//! (`GRASP_SIM_FRAMES_NO_SIM=1` plans only; `GRASP_SIM_FRAMES_ONLY=a,b` takes only the scenarios
//! named; `GRASP_SIM_FRAMES_DUMP=DIR` keeps each mesh as written and its run's report in DIR, as
//! `NAME_SHIFT.stl` and `.json` with SHIFT the frame's shift along X in whole mm, 0 for the
//! file's own frame, to replay one with the binary; the 21 real meshes that are not committed
//! join it after `python3 scripts/real_objects.py`). docs/FRAMES.md gives the rule and what it
//! measures.

use grasp_sim::report::{PlanStatus, RunReport};
use grasp_sim::scenario::Scenario;
use grasp_sim::{run, RunOptions};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// A deterministic pseudo-random number in [0, 1) (SplitMix64 on a counter).
fn unit(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// Five rigid frames from seed 30: a uniformly random rotation (a random unit quaternion) and
/// a shift of up to 500 mm along each axis.
fn frames() -> Vec<Isometry3<f64>> {
    let mut s = 30u64;
    (0..5)
        .map(|_| {
            let (u1, u2, u3) = (unit(&mut s), unit(&mut s), unit(&mut s));
            let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
            let t = std::f64::consts::TAU;
            let q = nalgebra::Quaternion::new(
                b * (t * u3).cos(),
                a * (t * u2).sin(),
                a * (t * u2).cos(),
                b * (t * u3).sin(),
            );
            let shift = Vector3::new(unit(&mut s), unit(&mut s), unit(&mut s)) * 1000.0
                - Vector3::repeat(500.0);
            Isometry3::from_parts(
                Translation3::from(shift),
                UnitQuaternion::from_quaternion(q),
            )
        })
        .collect()
}

/// Plans (and with `sim`, checks) the scenario's mesh written in `frame` as binary STL in mm.
fn plan_in(base: &Scenario, frame: &Isometry3<f64>, dir: &std::path::Path, sim: bool) -> RunReport {
    let loaded = grasp_sim::mesh::load_mesh(&base.object.mesh, base.object.units).unwrap();
    let mut mesh = loaded.mesh;
    mesh.map_vertices(|p| frame * p);
    let path = dir.join(format!("{}.stl", base.name));
    std::fs::write(&path, mesh.to_binary_stl()).unwrap();
    let dump = std::env::var_os("GRASP_SIM_FRAMES_DUMP").map(std::path::PathBuf::from);
    let tag = format!("{}_{:.0}", base.name, frame.translation.vector.x);
    if let Some(d) = &dump {
        std::fs::write(d.join(format!("{tag}.stl")), mesh.to_binary_stl()).unwrap();
    }
    let mut s = base.clone();
    s.object.mesh = path;
    s.object.units = grasp_sim::mesh::LengthUnit::Mm;
    let r = run(
        &s,
        &RunOptions {
            no_sim: !sim,
            ..RunOptions::default()
        },
    )
    .unwrap();
    if let Some(d) = &dump {
        std::fs::write(
            d.join(format!("{tag}.json")),
            serde_json::to_string_pretty(&r).unwrap(),
        )
        .unwrap();
    }
    r
}

/// What differs between two runs of one object, in words (empty when nothing does).
fn differences(a: &RunReport, b: &RunReport) -> Vec<String> {
    let mut out = Vec::new();
    if a.plan.status != b.plan.status {
        out.push(format!("status {:?} / {:?}", a.plan.status, b.plan.status));
        return out;
    }
    if let (Some(g), Some(h)) = (&a.plan.grasp, &b.plan.grasp) {
        let p = Point3::from(g.palm_pose_aligned.position_mm);
        let q = Point3::from(h.palm_pose_aligned.position_mm);
        let rot = |w: [f64; 4]| {
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w[0], w[1], w[2], w[3]))
        };
        let angle = rot(g.palm_pose_aligned.quaternion_wxyz)
            .angle_to(&rot(h.palm_pose_aligned.quaternion_wxyz))
            .to_degrees();
        if (p - q).norm() > 0.5 || angle > 0.5 {
            out.push(format!(
                "palm {:.2} mm, {angle:.2} deg apart ({} #{} {:.1} deg / {} #{} {:.1} deg)",
                (p - q).norm(),
                g.axis_name,
                g.elevation_index,
                g.approach_angle_deg,
                h.axis_name,
                h.elevation_index,
                h.approach_angle_deg
            ));
        }
        for (f, e) in g.fingers.iter().zip(&h.fingers) {
            let d = (f.theta1_deg - e.theta1_deg)
                .abs()
                .max((f.theta2_deg - e.theta2_deg).abs());
            if d > 0.5 {
                out.push(format!("{}: joint angles {d:.2} deg apart", f.name));
            }
        }
    }
    if a.sim.verdict != b.sim.verdict {
        out.push(format!("verdict {:?} / {:?}", a.sim.verdict, b.sim.verdict));
    }
    out
}

/// Every real-object scenario whose mesh is present.
fn real_scenarios() -> Vec<Scenario> {
    let dir = crate::root().join("assets/real/scenarios");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| Scenario::load(p).unwrap())
        .filter(|s| s.object.mesh.exists())
        .collect()
}

fn check_frames(names: Option<&[&str]>, sim: bool) -> (usize, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let frames = frames();
    let mut failures = Vec::new();
    let mut objects = 0;
    for s in real_scenarios() {
        if names.is_some_and(|n| !n.contains(&s.name.as_str())) {
            continue;
        }
        objects += 1;
        let reference = plan_in(&s, &Isometry3::identity(), dir.path(), sim);
        for (k, f) in frames.iter().enumerate() {
            let other = plan_in(&s, f, dir.path(), sim);
            let d = differences(&reference, &other);
            if !d.is_empty() {
                failures.push(format!("{} frame {k}: {}", s.name, d.join("; ")));
            }
        }
        if reference.plan.status == PlanStatus::Feasible {
            eprintln!("{}: checked in 5 frames", s.name);
        }
    }
    (objects, failures)
}

#[test]
#[ignore = "long: every real-object mesh in five frames; see the module docs"]
fn every_real_object_plans_alike_in_five_random_frames() {
    let sim = std::env::var_os("GRASP_SIM_FRAMES_NO_SIM").is_none();
    let only = std::env::var("GRASP_SIM_FRAMES_ONLY").ok();
    let names: Option<Vec<&str>> = only.as_deref().map(|o| o.split(',').collect());
    let (objects, failures) = check_frames(names.as_deref(), sim);
    eprintln!(
        "{} of {objects} objects differ in some frame:\n{}",
        failures
            .iter()
            .map(|f| f.split(' ').next().unwrap_or(""))
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        failures.join("\n")
    );
    assert!(failures.is_empty(), "{} differences", failures.len());
}

#[test]
fn eight_real_objects_plan_alike_in_five_random_frames() {
    // Plan only, on committed meshes, each for a part of the frame rule (docs/FRAMES.md): a
    // low-poly bottle whose two equal moments leave the in-plane axis to the farthest rim
    // vertex, equally far at 24 vertices (the first in the file's order); a thermos of three
    // open shells, whose moments come from the covariant fan of tetrahedra (the file's own
    // integration about its bounding box turned it over in one frame); a dial whose X sense
    // came from round-off; a hammer whose tapering handle grades its elevations 1e-7 apart
    // (sorted at 1e-4); a can. Each failed before issue 30's frame work but the can. And three
    // whose slices decided by round-off: an open ball whose panels' cuts kept a collinear point
    // in one frame (COLLINEAR_MM), a golf club whose touching shells the union merged in one
    // frame and not in another (TOUCH_MM), a milk carton whose fin left a zero-area sliver.
    let names = [
        "mw_basketball",
        "mw_dial",
        "mw_golf_club",
        "mw_hammer",
        "mw_thermos",
        "rs_bottle",
        "rs_can",
        "rs_milk",
    ];
    let (objects, failures) = check_frames(Some(&names), false);
    assert_eq!(objects, names.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Plans `mesh` (in mm, no physics) written in `frame`, with the default (geometric) frame rule.
fn plan_mesh_in(
    mesh: &grasp_sim::mesh::Mesh,
    frame: &Isometry3<f64>,
    dir: &std::path::Path,
) -> RunReport {
    let mut m = mesh.clone();
    m.map_vertices(|p| frame * p);
    let path = dir.join("m.stl");
    std::fs::write(&path, m.to_binary_stl()).unwrap();
    let s = Scenario::parse("[object]\nmesh = \"m.stl\"\n", &dir.join("s.toml")).unwrap();
    run(
        &s,
        &RunOptions {
            no_sim: true,
            ..RunOptions::default()
        },
    )
    .unwrap()
}

#[test]
fn square_bars_bodies_of_revolution_and_a_ridged_object_plan_alike_in_five_frames() {
    // The shapes the frame rule is for: square sections (equal moments: the in-plane axes from
    // the farthest vertex), a body of revolution wider at one end (the sense from the third
    // moment), and the thesis's chapter 4 object with its vertical ridge (no symmetry at all).
    // Each is planned as written and in five random rigid frames.
    use grasp_sim::objects::{self, hard};
    let dir = tempfile::tempdir().unwrap();
    let shapes = [
        ("square_bar_20", hard::square_bar(20.0, 150.0, 1)),
        ("square_bar_35", hard::square_bar(35.0, 150.0, 3)),
        ("frustum_56_80", objects::frustum(56.0, 80.0, 110.0)),
        (
            "chapter4",
            objects::chapter4(&objects::Chapter4Dims::default()),
        ),
    ];
    let mut failures = Vec::new();
    for (name, mesh) in &shapes {
        let reference = plan_mesh_in(mesh, &Isometry3::identity(), dir.path());
        assert_eq!(reference.plan.status, PlanStatus::Feasible, "{name}");
        for (k, f) in frames().iter().enumerate() {
            let d = differences(&reference, &plan_mesh_in(mesh, f, dir.path()));
            if !d.is_empty() {
                failures.push(format!("{name} frame {k}: {}", d.join("; ")));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
