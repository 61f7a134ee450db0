//! The two hands side by side (docs/SIM.md, "The impulse-joint hand"): on the planned grasp of
//! a cylinder, the multibody hand and the impulse-joint hand close by the fixed protocol (joint
//! 1 for half the closing, then joint 2), and the example prints, every `--every` steps, the
//! joints' bends, the fastest joint and object speeds (what the stall rule reads), and the
//! deepest contact; then the cost of a step of each, alternating, timed over the closing and a
//! held second under gravity.
//!
//!     cargo run --release --example hand_joints -- [--d MM] [--every N] [--set KEY=VALUE ...]

use grasp_sim::scenario::SimParams;
use grasp_sim::sim::params::HandJoints;
use grasp_sim::sim::scene::{build, Scene};
use grasp_sim::sim::{Case, ObjectShape, SimHand};
use std::time::Instant;

fn main() {
    let mut d = 40.0;
    let mut every = 24;
    let mut sets = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--d" => d = args.next().expect("MM").parse().expect("a number"),
            "--every" => every = args.next().expect("N").parse().expect("a number"),
            "--set" => sets.push(parse_set(&args.next().expect("KEY=VALUE"))),
            _ => panic!("unknown argument {a}"),
        }
    }
    let table: toml::Table = sets.into_iter().collect();
    let base: SimParams = table.try_into().expect("[sim] keys");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let hand = grasp_sim::hand::Hand::load(&root.join("assets/hands/thesis.toml"), &[]).unwrap();
    let mesh = grasp_sim::objects::cylinder(d, 124.0);
    let aligned = grasp_sim::mesh::align(&mesh);
    let (_, found) = grasp_sim::plan::plan(
        &aligned.mesh,
        &hand,
        &grasp_sim::scenario::PlannerParams::default(),
        0.3,
        1,
        &mut grasp_sim::report::StageTimings::default(),
    );
    let pose = SimHand::from_grasp(&found.grasps[0], &hand);
    let volume = grasp_sim::mesh::mass_properties(&aligned.mesh).volume_mm3;
    let shape = ObjectShape::from_mesh(&aligned.mesh, volume);
    let kinds = [HandJoints::Multibody, HandJoints::Impulse];
    let params: Vec<SimParams> = kinds
        .iter()
        .map(|&k| {
            let mut p = base.clone();
            p.solver.hand_joints = k;
            p
        })
        .collect();
    let case = |p| Case {
        hand: &hand,
        pose: &pose,
        object: &shape,
        mass_kg: 500.0 * volume * 1e-9,
        friction: 0.3,
        params: p,
    };
    let dt = base.solver.timestep_s;
    let half = ((base.closing.close_duration_s / dt).round() as usize) / 2;
    for p in &params {
        println!(
            "## {:?}: planned bends {:?} deg",
            p.solver.hand_joints,
            planned(&pose)
        );
        println!("| step | bends [deg] | fastest joint [rad/s] | object [mm/s] | deepest [mm] |");
        println!("|---|---|---|---|---|");
        let mut scene = build(&case(p));
        for step in 1..=2 * half {
            if step == half + 1 {
                scene.release_joint2();
            }
            scene.world.step();
            if step % every == 0 {
                let (w, v) = motion(&scene);
                println!(
                    "| {step} | {} | {w:.4} | {v:.3} | {:.3} |",
                    bends(&scene),
                    deepest_mm(&scene)
                );
            }
        }
    }
    // The cost of a step: each hand closed and held for a second under gravity, three rounds,
    // alternating.
    let mut best = vec![f64::INFINITY; kinds.len()];
    for _ in 0..3 {
        for (k, p) in params.iter().enumerate() {
            let mut scene = build(&case(p));
            let t0 = Instant::now();
            for step in 1..=2 * half {
                if step == half + 1 {
                    scene.release_joint2();
                }
                scene.world.step();
            }
            scene.world.gravity = rapier3d::math::Vector::new(0.0, 0.0, -9.81);
            let hold = (1.0 / dt).round() as usize;
            for _ in 0..hold {
                scene.world.step();
            }
            let per = t0.elapsed().as_secs_f64() * 1000.0 / (2 * half + hold) as f64;
            best[k] = best[k].min(per);
        }
    }
    for (k, b) in kinds.iter().zip(&best) {
        println!("{k:?}: {b:.4} ms a step (best of three, closing and 1 s held)");
    }
    println!("ratio impulse / multibody: {:.3}", best[1] / best[0]);
}

/// `KEY=VALUE` (a TOML value) as a `[sim]` key and its value.
fn parse_set(kv: &str) -> (String, toml::Value) {
    let (k, v) = kv.split_once('=').expect("KEY=VALUE");
    let v: toml::Table = toml::from_str(&format!("v = {v}")).expect("a TOML value");
    (k.to_string(), v["v"].clone())
}

/// The planned `[θ1, θ2]` as bends `[deg]`.
fn planned(pose: &SimHand) -> Vec<[f64; 2]> {
    pose.theta_deg
        .iter()
        .map(|[a, b]| [180.0 - a, 180.0 - b])
        .collect()
}

/// Every joint's bend now `[deg]`.
fn bends(scene: &Scene) -> String {
    scene
        .fingers
        .iter()
        .map(|f| {
            let a = |j: &grasp_sim::sim::impulse_hand::FingerJoint| {
                j.angle(&scene.world).map_or(f32::NAN, f32::to_degrees)
            };
            format!("{:.2}/{:.2}", a(&f.joint1), a(&f.joint2))
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The fastest joint `[rad/s]` and the object's speed `[mm/s]`, as the stall rule reads them.
fn motion(scene: &Scene) -> (f64, f64) {
    let b = &scene.world.bodies;
    let mut w = 0.0f64;
    for f in &scene.fingers {
        let w1 = b[f.phalanx1].angvel();
        let w2 = b[f.phalanx2].angvel();
        w = w
            .max(f64::from(w1.length()))
            .max(f64::from((w2 - w1).length()));
    }
    (w, f64::from(b[scene.object].linvel().length()) * 1000.0)
}

/// The deepest contact between a hand collider and the object `[mm]`.
fn deepest_mm(scene: &Scene) -> f64 {
    let mut depth = 0.0f64;
    for pair in scene
        .world
        .narrow_phase
        .contact_pairs_with(scene.object_collider)
    {
        if let rapier3d::geometry::PairContacts::Rigid(r) = &pair.contacts {
            for m in &r.manifolds {
                for p in &m.points {
                    depth = depth.max(-f64::from(p.dist));
                }
            }
        }
    }
    depth * 1000.0
}
