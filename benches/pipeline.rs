//! Benchmarks of each stage (BENCHMARKS.md records the figures and the command).
//!
//!     cargo bench --bench pipeline
//!
//! - `slice/*`: one horizontal and one vertical slice of UV spheres of about 10k and 100k
//!   triangles.
//! - `plan/*`: the whole kinematic planner (align, stages 1–3, search) on each thesis object.
//! - `plan_scaling/*`: the planner on the cup as AngularStep and HeightStep change.
//! - `sim/*`: the physics check of the planned D40 grasp: `down`, `six` and `payload` (fast
//!   protocol), `full_down` and `full_six` (the full-length reference), `before_down`,
//!   `before_six` and `before_payload` (the check before issue 15).
//! - `quality/*`: the analytic grasp quality (issue 18) of the planned grasp of D40, the cup
//!   and the chapter 4 object, from the contacts at the end of the `down` check's closing
//!   (`sim_*`) and from the planned contacts (`planned_*`), beside that same `down` check
//!   (`check_down_*`), so the ratio comes from one run.
//! - `support_scan/*`: the support point of a convex polyhedron of 256 and 1,024 points (a
//!   LIBERO bottle's hull part has 300–1,100) towards 4,096 directions, by parry's scan
//!   (`parry_*`) and by the object's hulls in the scene (`lanes_*`, `sim::fast_hull`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use grasp_sim::hand::Hand;
use grasp_sim::mesh::{align, mass_properties};
use grasp_sim::objects;
use grasp_sim::plan::plan;
use grasp_sim::quality;
use grasp_sim::report::StageTimings;
use grasp_sim::scenario::{GravityMode, PlannerParams, Protocol, SimParams};
use grasp_sim::sim::{check, check_with_payload, Case, ObjectShape, SimHand};
use grasp_sim::slice::{slice, Plane, SliceOptions};
use std::hint::black_box;
use std::path::Path;

fn thesis_hand() -> Hand {
    Hand::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/hands/thesis.toml"),
        &[],
    )
    .unwrap()
}

fn bench_slice(c: &mut Criterion) {
    let mut g = c.benchmark_group("slice");
    for n in [100usize, 316] {
        let sphere = objects::uv_sphere(50.0, n);
        let tris = sphere.triangles.len();
        g.bench_with_input(BenchmarkId::new("horizontal", tris), &sphere, |b, m| {
            b.iter(|| {
                slice(
                    black_box(m),
                    &Plane::horizontal(10.0),
                    SliceOptions::default(),
                )
            })
        });
        g.bench_with_input(BenchmarkId::new("vertical", tris), &sphere, |b, m| {
            b.iter(|| slice(black_box(m), &Plane::vertical(0.3), SliceOptions::default()))
        });
    }
    g.finish();
}

fn bench_plan(c: &mut Criterion) {
    let hand = thesis_hand();
    let params = PlannerParams::default();
    let mut g = c.benchmark_group("plan");
    for (name, mesh) in objects::thesis_objects() {
        g.bench_function(name, |b| {
            b.iter(|| {
                let a = align(black_box(&mesh));
                let mut t = StageTimings::default();
                plan(&a.mesh, &hand, &params, 0.3, 1, &mut t)
            })
        });
    }
    g.finish();

    // The whole selection as a run does it without the physics check: the thesis's axis first,
    // then the other axes and senses, then the extended rules (issue 13: what three axes cost).
    let mut g = c.benchmark_group("select");
    let d10 = objects::cylinder(10.0, 124.0);
    let sphere = objects::uv_sphere(30.0, 72);
    let cases = [
        ("cup", objects::frustum(56.0, 80.0, 110.0)),
        (
            "chapter4",
            objects::thesis_objects().pop().expect("chapter 4").1,
        ),
        ("d10_ungraspable_every_axis", d10),
        ("sphere_extended_rules", sphere),
    ];
    for (name, mesh) in cases {
        g.bench_function(name, |b| {
            b.iter(|| {
                let props = grasp_sim::mesh::mass_properties(black_box(&mesh));
                let never = |_: &grasp_sim::mesh::AlignedObject,
                             _: &grasp_sim::plan::search::Grasp|
                 -> grasp_sim::sim::SimOutcome {
                    unreachable!("no physics check")
                };
                let mut t = StageTimings::default();
                grasp_sim::select::select(
                    &mesh,
                    &props,
                    &grasp_sim::select::SelectParams {
                        hand: &hand,
                        planner: &params,
                        friction: 0.3,
                        collect: 1,
                        max_checked: None,
                        check: &never,
                        recheck: None,
                        probe: None,
                        domains: None,
                        frame: grasp_sim::mesh::FrameRule::File,
                        order_by_closing: None,
                        order_samples: None,
                        plan_reach: 0,
                        order_reach: 0,
                    },
                    &mut t,
                )
            })
        });
    }
    g.finish();

    let cup = align(&objects::frustum(56.0, 80.0, 110.0)).mesh;
    let mut g = c.benchmark_group("plan_scaling");
    for step in [5.0, 10.0, 20.0] {
        let p = PlannerParams {
            angular_step_deg: step,
            ..PlannerParams::default()
        };
        g.bench_with_input(BenchmarkId::new("angular_step_deg", step), &p, |b, p| {
            b.iter(|| plan(&cup, &hand, p, 0.3, 1, &mut StageTimings::default()))
        });
    }
    for step in [1.25, 2.5, 5.0] {
        let p = PlannerParams {
            height_step_mm: step,
            ..PlannerParams::default()
        };
        g.bench_with_input(BenchmarkId::new("height_step_mm", step), &p, |b, p| {
            b.iter(|| plan(&cup, &hand, p, 0.3, 1, &mut StageTimings::default()))
        });
    }
    g.finish();
}

fn bench_kinematics(c: &mut Criterion) {
    let hand = thesis_hand();
    c.bench_function("kinematics/graspable_range", |b| {
        b.iter(|| grasp_sim::plan::kinematics::graspable_range(black_box(&hand)))
    });
}

fn bench_sim(c: &mut Criterion) {
    let hand = thesis_hand();
    let mesh = objects::cylinder(40.0, 124.0);
    let a = align(&mesh);
    let (_, found) = plan(
        &a.mesh,
        &hand,
        &PlannerParams::default(),
        0.3,
        1,
        &mut StageTimings::default(),
    );
    let g0 = &found.grasps[0];
    let pose = SimHand::from_grasp(g0, &hand);
    let shape = ObjectShape::from_mesh(&a.mesh, mass_properties(&a.mesh).volume_mm3);
    let mass = 500.0 * mass_properties(&a.mesh).volume_mm3 * 1e-9;
    let mut g = c.benchmark_group("sim");
    g.sample_size(10);
    // `down`, `six` and `payload` (the check and its payload search) under the default `fast`
    // protocol; `full_down` and `full_six` are the full-length reference with the same closing;
    // `before_*` the check before issue 15 (full-length, fixed 0.5 s closing).
    for (name, gravity, protocol, payload, stalled) in [
        ("down", GravityMode::Down, Protocol::Fast, false, true),
        ("six", GravityMode::Six, Protocol::Fast, false, true),
        ("payload", GravityMode::Down, Protocol::Fast, true, true),
        ("full_down", GravityMode::Down, Protocol::Full, false, true),
        ("full_six", GravityMode::Six, Protocol::Full, false, true),
        (
            "before_down",
            GravityMode::Down,
            Protocol::Full,
            false,
            false,
        ),
        ("before_six", GravityMode::Six, Protocol::Full, false, false),
        (
            "before_payload",
            GravityMode::Down,
            Protocol::Full,
            true,
            false,
        ),
    ] {
        let mut params = SimParams {
            gravity,
            protocol,
            ..SimParams::default()
        };
        params.closing.close_until_stalled = stalled;
        g.bench_function(name, |b| {
            let case = Case {
                hand: &hand,
                pose: &pose,
                object: &shape,
                mass_kg: mass,
                friction: 0.3,
                params: &params,
            };
            b.iter(|| check_with_payload(&case, payload))
        });
    }
    g.finish();
}

fn bench_quality(c: &mut Criterion) {
    let hand = thesis_hand();
    let mut g = c.benchmark_group("quality");
    g.sample_size(10);
    let objects = objects::thesis_objects();
    for name in ["cylinder_d40", "cup", "chapter4"] {
        let mesh = &objects.iter().find(|(n, _)| *n == name).expect(name).1;
        let a = align(mesh);
        let (_, found) = plan(
            &a.mesh,
            &hand,
            &PlannerParams::default(),
            0.3,
            1,
            &mut StageTimings::default(),
        );
        let grasp = &found.grasps[0];
        let pose = SimHand::from_grasp(grasp, &hand);
        let volume = mass_properties(&a.mesh).volume_mm3;
        let shape = ObjectShape::from_mesh(&a.mesh, volume);
        let params = SimParams::default();
        let case = Case {
            hand: &hand,
            pose: &pose,
            object: &shape,
            mass_kg: 500.0 * volume * 1e-9,
            friction: 0.3,
            params: &params,
        };
        let outcome = check(&case);
        g.bench_function(format!("check_down_{name}"), |b| b.iter(|| check(&case)));
        g.bench_function(
            format!("sim_{name}_{}_contacts", outcome.grip_contacts.len()),
            |b| b.iter(|| quality::of_grasp(grasp, &a, Some(&outcome), &hand, 0.3)),
        );
        g.bench_function(format!("planned_{name}"), |b| {
            b.iter(|| quality::of_grasp(grasp, &a, None, &hand, 0.3))
        });
    }
    g.finish();
}

fn bench_support_scan(c: &mut Criterion) {
    use grasp_sim::sim::fast_hull::FastHull;
    use rapier3d::parry::math::Vector;
    use rapier3d::parry::shape::{ConvexPolyhedron, SupportMap};
    let mut g = c.benchmark_group("support_scan");
    let mut s = 1_u32;
    let mut r = move || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1 << 24) as f32 - 0.5
    };
    let dirs: Vec<Vector> = (0..4096).map(|_| Vector::new(r(), r(), r())).collect();
    for n in [256_usize, 1024] {
        // Points on a sphere: every one is a vertex of the hull.
        let points: Vec<Vector> = (0..n)
            .map(|_| Vector::new(r(), r(), r()).normalize())
            .collect();
        let poly = ConvexPolyhedron::from_convex_hull(&points).unwrap();
        let fast = FastHull::new(poly.clone());
        g.bench_function(format!("parry_{n}"), |b| {
            b.iter(|| {
                dirs.iter()
                    .map(|d| poly.local_support_point(*d).x)
                    .sum::<f32>()
            })
        });
        g.bench_function(format!("lanes_{n}"), |b| {
            b.iter(|| {
                dirs.iter()
                    .map(|d| fast.local_support_point(*d).x)
                    .sum::<f32>()
            })
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    bench_support_scan,
    bench_slice,
    bench_kinematics,
    bench_plan,
    bench_sim,
    bench_quality
);
criterion_main!(benches);
