//! Frame invariance (issue 30): every real-object mesh written in five random rigid frames
//! (a fixed seed) must plan with the same status, the same grasp in the object's own (aligned)
//! frame within 0.5 mm and 0.5°, and with the physics check the same verdict wherever the
//! verdict is decided by the physics and not by round-off.
//!
//! With the physics check (the ignored test without `GRASP_SIM_FRAMES_NO_SIM`), a run checks
//! candidates in search order until one holds (`[sim] order_by_closing = 0`: the closing order
//! ranks candidates by their closings, which are as chaotic as the verdicts, so its picks and
//! their order may differ between frames; docs/FRAMES.md gives what it changes). It must load the same object in every frame
//! (volume, mass and kind of collider) and check the same candidates in the same order, each
//! the same grasp. Where a candidate's verdict differs between two frames, it is sampled under
//! perturbation in both (`choose = "robust"`, every candidate sampled
//! `GRASP_SIM_FRAMES_SAMPLES` times, 16 by default): if every sample held in both frames, both
//! verdicts must be `hold`; if none held in either, neither may be (a slip and a drop, which
//! the hold probability does not tell apart, may differ); anything between is a coin toss.
//! A verdict is a single sample of a chaotic check: a 1 ppm change of the contact stiffness,
//! every other input bit for bit the same, flips such candidates as another frame does
//! (docs/studies/2026-12-02-frames-verdicts.md). So where the samples call a difference
//! decisive, the run is repeated in both frames under the five 1 ppm nulls of docs/SIM.md:
//! if one of them flips the candidate's verdict in either frame, that verdict is a coin toss
//! too (the samples, millimetres and degrees apart, do not see the round-off neighbourhood of
//! the unperturbed check). The runs that differ only by coin tosses are listed, not failed;
//! the grasp chosen then differs too.
//!
//! With the default search (the closing order on), the ignored
//! `every_real_object_keeps_its_verdict_in_five_random_frames_with_the_defaults` requires the same
//! status and object in every frame and judges the reported grasp's verdict by the same rule:
//! where it holds in one frame and not in another, each frame's reported grasp is sampled; the
//! reported grasps that differ, or whose `as_planned` differs, are listed, not failed.
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

use grasp_sim::report::Verdict;
use grasp_sim::report::{GraspReport, PlanStatus, RunReport};
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

/// How a frame's run goes.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// The planner alone.
    Plan,
    /// The planner and the physics check, candidates in search order until one holds.
    Check,
    /// As `Check`, every candidate checked also sampled this many times under perturbation
    /// (`choose = "robust"` with a bound no candidate reaches, so that the search checks as
    /// many candidates as the scenario's `max_checked` allows, each with its hold probability).
    Sampled(usize),
    /// As `Check`, under the `k`-th of [`NULLS`].
    Null(usize),
    /// The scenario's own search (the closing order on, as by default), the reported grasp
    /// sampled this many times (0: not sampled) and under this null, if any.
    Defaults(usize, Option<usize>),
}

/// The five null perturbations of docs/SIM.md ("Which verdicts a setting can keep"): each moves
/// one constant by 1 ppm, which no measurement of a real hand could tell apart.
const NULLS: [&str; 5] = [
    "finger density +1 ppm",
    "joint 1 lock +1 ppm",
    "motor stiffness +1 ppm",
    "motor damping +1 ppm",
    "contact stiffness +1 ppm",
];

/// `s` under the `k`-th of [`NULLS`].
fn with_null(s: &mut Scenario, k: usize) {
    let f = &mut s.sim.fingers;
    match k {
        0 => f.finger_density_kg_m3 *= 1.000_001,
        1 => f.joint1_lock_torque_nm *= 1.000_001,
        2 => f.motor_stiffness_nm_per_rad *= 1.000_001,
        3 => f.motor_damping_nms_per_rad *= 1.000_001,
        _ => s.sim.solver.contact_stiffness_hz *= 1.000_001,
    }
}

/// Plans (and checks, as `mode` says) the scenario's mesh written in `frame` as binary STL in
/// mm.
fn plan_in(
    base: &Scenario,
    frame: &Isometry3<f64>,
    dir: &std::path::Path,
    mode: Mode,
) -> RunReport {
    let loaded = grasp_sim::mesh::load_mesh(&base.object.mesh, base.object.units).unwrap();
    let mut mesh = loaded.mesh;
    mesh.map_vertices(|p| frame * p);
    let path = dir.join(format!("{}.stl", base.name));
    std::fs::write(&path, mesh.to_binary_stl()).unwrap();
    let dump = std::env::var_os("GRASP_SIM_FRAMES_DUMP").map(std::path::PathBuf::from);
    let mut tag = format!("{}_{:.0}", base.name, frame.translation.vector.x);
    match mode {
        Mode::Sampled(n) => tag += &format!("_sampled{n}"),
        Mode::Null(k) => tag += &format!("_null{k}"),
        Mode::Defaults(n, k) => {
            tag += "_defaults";
            if n > 0 {
                tag += &format!("_sampled{n}");
            }
            if let Some(k) = k {
                tag += &format!("_null{k}");
            }
        }
        _ => {}
    }
    if let Some(d) = &dump {
        std::fs::create_dir_all(d).unwrap();
        std::fs::write(d.join(format!("{tag}.stl")), mesh.to_binary_stl()).unwrap();
    }
    let mut s = base.clone();
    s.object.mesh = path;
    s.object.units = grasp_sim::mesh::LengthUnit::Mm;
    if let Mode::Defaults(n, k) = mode {
        // The reported grasp, sampled after the search (`choose` stays `first`).
        if n > 0 {
            s.sim.robust.samples = n;
        }
        if let Some(k) = k {
            with_null(&mut s, k);
        }
    } else {
        // The search's order, candidate by candidate (the module docs).
        s.sim.selection.order_by_closing = 0;
    }
    if let Mode::Sampled(n) = mode {
        s.sim.robust.samples = n;
        s.sim.robust.choose = grasp_sim::sim::params::Choose::Robust;
        s.sim.robust.choose_min_lower_bound = 1.0;
    }
    if let Mode::Null(k) = mode {
        with_null(&mut s, k);
    }
    let r = run(
        &s,
        &RunOptions {
            no_sim: mode == Mode::Plan,
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
        out.extend(grasp_differences(g, h));
    }
    if a.sim.verdict != b.sim.verdict {
        out.push(format!("verdict {:?} / {:?}", a.sim.verdict, b.sim.verdict));
    }
    out
}

/// What differs between two grasps in the object's frame, in words (empty when the palms are
/// within 0.5 mm and 0.5° and every joint angle within 0.5°).
fn grasp_differences(g: &GraspReport, h: &GraspReport) -> Vec<String> {
    let mut out = Vec::new();
    {
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
    out
}

/// The candidates a run checked, in search order (`plan.grasps`, or its one grasp).
fn checked(r: &RunReport) -> Vec<&GraspReport> {
    if r.plan.grasps.is_empty() {
        r.plan.grasp.iter().collect()
    } else {
        r.plan.grasps.iter().collect()
    }
}

/// A candidate in words: axis, elevation index, approach angle.
fn named(g: &GraspReport) -> String {
    format!(
        "{} #{} {:.0} deg",
        g.axis_name, g.elevation_index, g.approach_angle_deg
    )
}

/// The physics check's inputs that must not depend on the frame: the enclosed volume, the
/// mass, and the kind of collider (the convex hull, or a decomposition).
fn input_differences(a: &RunReport, b: &RunReport) -> Vec<String> {
    let mut out = Vec::new();
    let rel = |x: f64, y: f64| (x - y).abs() / x.abs().max(y.abs()).max(f64::MIN_POSITIVE);
    if rel(a.object.volume_mm3, b.object.volume_mm3) > 1e-4 {
        out.push(format!(
            "volume {:.1} / {:.1} mm3",
            a.object.volume_mm3, b.object.volume_mm3
        ));
    }
    if let (Some(m), Some(n)) = (a.sim.mass_kg, b.sim.mass_kg) {
        if rel(m, n) > 1e-4 {
            out.push(format!("mass {m:.6} / {n:.6} kg"));
        }
    }
    let kind = |r: &RunReport| r.sim.collider.map(|c| c.kind);
    if kind(a) != kind(b) {
        out.push(format!("collider {:?} / {:?}", kind(a), kind(b)));
    }
    out
}

/// What differs between two checked runs of one object in two frames, candidate by candidate
/// in search order: the verdicts (what gravity did) and, apart, the fidelity (issue 55).
#[derive(Debug, Default)]
struct Flips {
    /// Candidates whose verdicts differ.
    verdicts: Vec<usize>,
    /// Candidates with the same verdict whose `as_planned` differs (the search then goes on in
    /// one frame and stops in the other: the candidate lists may differ in length from there).
    as_planned: Vec<usize>,
}

/// The candidates, by index in search order, whose verdicts, or whose fidelity alone, differ
/// between two checked runs that checked the same candidates; or what else differs, in words.
fn verdict_flips(a: &RunReport, b: &RunReport) -> Result<Flips, Vec<String>> {
    if a.plan.status != b.plan.status {
        return Err(vec![format!(
            "status {:?} / {:?}",
            a.plan.status, b.plan.status
        )]);
    }
    let mut out = input_differences(a, b);
    let (ca, cb) = (checked(a), checked(b));
    let mut flips = Flips::default();
    for (i, (g, h)) in ca.iter().zip(&cb).enumerate() {
        let d = grasp_differences(g, h);
        if !d.is_empty() {
            out.push(format!(
                "candidate {i} ({} / {}): {}",
                named(g),
                named(h),
                d.join("; ")
            ));
            break;
        }
        let verdict = |g: &GraspReport| g.check.as_ref().and_then(|c| c.ran());
        let planned = |g: &GraspReport| g.check.as_ref().map(|c| c.fidelity.as_planned);
        if verdict(g) != verdict(h) {
            flips.verdicts.push(i);
        } else if planned(g) != planned(h) {
            flips.as_planned.push(i);
        }
    }
    if out.is_empty()
        && flips.verdicts.is_empty()
        && flips.as_planned.is_empty()
        && ca.len() != cb.len()
    {
        out.push(format!(
            "{} / {} candidates checked, the same verdicts and fidelity",
            ca.len(),
            cb.len()
        ));
    }
    if out.is_empty() {
        Ok(flips)
    } else {
        Err(out)
    }
}

/// The nulls of `runs` (the runs of one frame under [`NULLS`], in order) under which the
/// `i`-th candidate, the same grasp as `g`, is judged `hold` where `nominal` is not or the
/// reverse, named with the verdict they gave (a null whose search stopped before it, or
/// checked another grasp there, says nothing).
fn null_flips(
    runs: &[RunReport],
    i: usize,
    g: &GraspReport,
    nominal: Option<Verdict>,
) -> Vec<String> {
    let holds = |v: Option<Verdict>| v == Some(Verdict::Hold);
    runs.iter()
        .enumerate()
        .filter_map(|(k, r)| {
            let c = checked(r).get(i).copied()?;
            if !grasp_differences(c, g).is_empty() {
                return None;
            }
            let v = c.check.as_ref().and_then(|c| c.ran());
            (holds(v) != holds(nominal)).then(|| format!("{}: {v:?}", NULLS[k]))
        })
        .collect()
}

/// The `i`-th candidate a sampled run checked: its samples held, of how many.
fn held(sampled: &RunReport, i: usize) -> Option<(usize, usize)> {
    let g = checked(sampled).get(i).copied()?;
    let r = g.check.as_ref()?.robust.as_ref()?;
    Some((r.held, r.samples))
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

/// What [`check_frames`] found.
#[derive(Debug, Default)]
struct FrameReport {
    /// Objects compared.
    objects: usize,
    /// Differences that fail.
    failures: Vec<String>,
    /// With the physics check: verdicts that differ on candidates whose hold probability is
    /// not decisive.
    tosses: Vec<String>,
    /// With the physics check: candidates whose verdict is the same in both frames but whose
    /// `as_planned` differs (reported, not failed: issue 55).
    as_planned: Vec<String>,
}

/// Compares every object (or those `names` names) in its own frame and five others.
fn check_frames(names: Option<&[&str]>, mode: Mode) -> FrameReport {
    let dir = tempfile::tempdir().unwrap();
    let frames = frames();
    let samples = std::env::var("GRASP_SIM_FRAMES_SAMPLES")
        .ok()
        .map_or(16, |n| n.parse().unwrap());
    let mut failures = Vec::new();
    let mut tosses = Vec::new();
    let mut as_planned = Vec::new();
    let mut objects = 0;
    for s in real_scenarios() {
        if names.is_some_and(|n| !n.contains(&s.name.as_str())) {
            continue;
        }
        objects += 1;
        let own = Isometry3::identity();
        let reference = plan_in(&s, &own, dir.path(), mode);
        let mut reference_sampled = None;
        let mut reference_nulls: Option<Vec<RunReport>> = None;
        for (k, f) in frames.iter().enumerate() {
            let other = plan_in(&s, f, dir.path(), mode);
            if mode == Mode::Plan {
                let d = differences(&reference, &other);
                if !d.is_empty() {
                    failures.push(format!("{} frame {k}: {}", s.name, d.join("; ")));
                }
                continue;
            }
            let flips = match verdict_flips(&reference, &other) {
                Ok(f) => f,
                Err(d) => {
                    failures.push(format!("{} frame {k}: {}", s.name, d.join("; ")));
                    continue;
                }
            };
            for &i in &flips.as_planned {
                let c = |r: &RunReport| {
                    checked(r)[i].check.as_ref().map(|c| {
                        (
                            c.fidelity.as_planned,
                            c.fidelity.shift_mm,
                            c.fidelity.phalanges_on_plan,
                        )
                    })
                };
                as_planned.push(format!(
                    "{} frame {k}: candidate {i} ({}) as planned, shift, on plan {:?} / {:?}",
                    s.name,
                    named(checked(&reference)[i]),
                    c(&reference),
                    c(&other)
                ));
            }
            let flips = flips.verdicts;
            if flips.is_empty() {
                continue;
            }
            // Verdicts differ: sample every candidate in both frames.
            let a = reference_sampled
                .get_or_insert_with(|| plan_in(&s, &own, dir.path(), Mode::Sampled(samples)));
            let b = plan_in(&s, f, dir.path(), Mode::Sampled(samples));
            let cands = checked(&reference);
            for i in flips {
                let g = cands[i];
                let verdict = |r: &RunReport| checked(r)[i].check.as_ref().and_then(|c| c.ran());
                let (va, vb) = (verdict(&reference), verdict(&other));
                let what = format!(
                    "{} frame {k}: candidate {i} ({}) {va:?} / {vb:?}",
                    s.name,
                    named(g)
                );
                let same_grasp = |r: &RunReport| {
                    checked(r)
                        .get(i)
                        .is_some_and(|x| grasp_differences(x, g).is_empty())
                };
                match (held(a, i), held(&b, i)) {
                    (Some((ha, n)), Some((hb, m))) if same_grasp(a) && same_grasp(&b) => {
                        // The hold probability tells hold from not hold: all samples held in
                        // both frames decides `hold`, none held decides "not hold" (a slip and
                        // a drop it does not tell apart).
                        let hold = Some(Verdict::Hold);
                        let decisive_wrong = (ha == n && hb == m && (va != hold || vb != hold))
                            || (ha == 0 && hb == 0 && (va == hold || vb == hold));
                        let line = format!("{what}, held {ha} of {n} / {hb} of {m} samples");
                        if !decisive_wrong {
                            tosses.push(line);
                            continue;
                        }
                        // The samples perturb the grasp by millimetres and degrees; the
                        // verdict itself may still turn on round-off. Where a 1 ppm null flips
                        // it in either frame, it is a coin toss there, as the samples' rule
                        // cannot see.
                        let a_nulls = reference_nulls.get_or_insert_with(|| {
                            (0..NULLS.len())
                                .map(|k| plan_in(&s, &own, dir.path(), Mode::Null(k)))
                                .collect()
                        });
                        let b_nulls: Vec<RunReport> = (0..NULLS.len())
                            .map(|k| plan_in(&s, f, dir.path(), Mode::Null(k)))
                            .collect();
                        let (fa, fb) = (
                            null_flips(a_nulls, i, g, va),
                            null_flips(&b_nulls, i, g, vb),
                        );
                        if fa.is_empty() && fb.is_empty() {
                            failures.push(format!(
                                "{line}: decisive, yet the verdicts differ, and no null flips \
                                 either"
                            ));
                        } else {
                            tosses.push(format!(
                                "{line}, decisive by the samples but flipped by 1 ppm nulls \
                                 ({}{}{})",
                                fa.join(", "),
                                if fa.is_empty() || fb.is_empty() {
                                    ""
                                } else {
                                    "; "
                                },
                                fb.join(", ")
                            ));
                        }
                    }
                    _ => failures.push(format!("{what}: not sampled")),
                }
            }
        }
        if reference.plan.status == PlanStatus::Feasible {
            eprintln!("{}: checked in 5 frames", s.name);
        }
    }
    FrameReport {
        objects,
        failures,
        tosses,
        as_planned,
    }
}

/// What [`check_frames_defaults`] found.
#[derive(Debug, Default)]
struct DefaultsReport {
    /// Objects compared.
    objects: usize,
    /// Differences that fail: the status, the object's inputs, or a verdict whose samples
    /// decide it and that no null flips.
    failures: Vec<String>,
    /// Verdicts that differ where the samples or a null call it a coin toss.
    tosses: Vec<String>,
    /// Reported grasps that differ, or whose `as_planned` differs (reported, not failed: the
    /// closing order ranks by closings, as chaotic as the verdicts).
    grasps: Vec<String>,
}

/// The reported grasp's verdict in words with its fidelity.
fn reported(r: &RunReport) -> String {
    let planned = r.sim.fidelity.as_ref().map(|f| f.as_planned);
    match &r.plan.grasp {
        Some(g) => format!(
            "{} {:?} as planned {planned:?}",
            named(g),
            r.sim.verdict.verdict()
        ),
        None => "no grasp".into(),
    }
}

/// The reported grasp's samples that held, of how many.
fn reported_held(r: &RunReport) -> Option<(usize, usize)> {
    r.sim.robust.as_ref().map(|b| (b.counts.hold, b.samples))
}

/// Compares every object (or those `names` names) in its own frame and five others with the
/// scenario's own search (the closing order on): the status and the object's inputs must be
/// the same; where the reported verdict differs between two frames (hold against not hold),
/// the reported grasp of each frame is sampled `GRASP_SIM_FRAMES_SAMPLES` times (16) and the
/// difference judged as [`check_frames`] judges a candidate's, nulls included.
fn check_frames_defaults(names: Option<&[&str]>) -> DefaultsReport {
    let dir = tempfile::tempdir().unwrap();
    let frames = frames();
    let samples = std::env::var("GRASP_SIM_FRAMES_SAMPLES")
        .ok()
        .map_or(16, |n| n.parse().unwrap());
    let mut out = DefaultsReport::default();
    let hold = Some(Verdict::Hold);
    for s in real_scenarios() {
        if names.is_some_and(|n| !n.contains(&s.name.as_str())) {
            continue;
        }
        out.objects += 1;
        let own = Isometry3::identity();
        let reference = plan_in(&s, &own, dir.path(), Mode::Defaults(0, None));
        let mut reference_sampled = None;
        let mut reference_nulls: Option<Vec<RunReport>> = None;
        for (k, f) in frames.iter().enumerate() {
            let other = plan_in(&s, f, dir.path(), Mode::Defaults(0, None));
            let what = format!(
                "{} frame {k}: {} / {}",
                s.name,
                reported(&reference),
                reported(&other)
            );
            if reference.plan.status != other.plan.status {
                out.failures.push(format!(
                    "{} frame {k}: status {:?} / {:?}",
                    s.name, reference.plan.status, other.plan.status
                ));
                continue;
            }
            let inputs = input_differences(&reference, &other);
            if !inputs.is_empty() {
                out.failures
                    .push(format!("{} frame {k}: {}", s.name, inputs.join("; ")));
                continue;
            }
            let (va, vb) = (reference.sim.verdict.verdict(), other.sim.verdict.verdict());
            let moved = match (&reference.plan.grasp, &other.plan.grasp) {
                (Some(g), Some(h)) => !grasp_differences(g, h).is_empty(),
                _ => false,
            };
            let planned = |r: &RunReport| r.sim.fidelity.as_ref().map(|f| f.as_planned);
            if moved || planned(&reference) != planned(&other) {
                out.grasps.push(what.clone());
            }
            if (va == hold) == (vb == hold) {
                continue;
            }
            // Hold in one frame, not in the other: sample each frame's reported grasp.
            let a = reference_sampled.get_or_insert_with(|| {
                plan_in(&s, &own, dir.path(), Mode::Defaults(samples, None))
            });
            let b = plan_in(&s, f, dir.path(), Mode::Defaults(samples, None));
            let same = |x: &RunReport, y: &RunReport| match (&x.plan.grasp, &y.plan.grasp) {
                (Some(g), Some(h)) => {
                    grasp_differences(g, h).is_empty()
                        && x.sim.verdict.verdict() == y.sim.verdict.verdict()
                }
                _ => false,
            };
            let (Some((ha, n)), Some((hb, m))) = (reported_held(a), reported_held(&b)) else {
                out.failures.push(format!("{what}: not sampled"));
                continue;
            };
            if !same(a, &reference) || !same(&b, &other) {
                out.failures
                    .push(format!("{what}: the sampled run reported another grasp"));
                continue;
            }
            let line = format!("{what}, held {ha} of {n} / {hb} of {m} samples");
            let decisive_wrong = (ha == n && hb == m) || (ha == 0 && hb == 0);
            if !decisive_wrong {
                out.tosses.push(line);
                continue;
            }
            // As in `check_frames`: a verdict that a 1 ppm null flips is a coin toss.
            let flips = |runs: &[RunReport], nominal: Option<Verdict>| -> Vec<String> {
                runs.iter()
                    .enumerate()
                    .filter(|(_, r)| (r.sim.verdict.verdict() == hold) != (nominal == hold))
                    .map(|(k, r)| format!("{}: {}", NULLS[k], reported(r)))
                    .collect()
            };
            let a_nulls = reference_nulls.get_or_insert_with(|| {
                (0..NULLS.len())
                    .map(|k| plan_in(&s, &own, dir.path(), Mode::Defaults(0, Some(k))))
                    .collect()
            });
            let b_nulls: Vec<RunReport> = (0..NULLS.len())
                .map(|k| plan_in(&s, f, dir.path(), Mode::Defaults(0, Some(k))))
                .collect();
            let (fa, fb) = (flips(a_nulls, va), flips(&b_nulls, vb));
            if fa.is_empty() && fb.is_empty() {
                out.failures.push(format!(
                    "{line}: decisive, yet the verdicts differ, and no null flips either"
                ));
            } else {
                out.tosses.push(format!(
                    "{line}, decisive by the samples but flipped by 1 ppm nulls ({})",
                    fa.into_iter().chain(fb).collect::<Vec<_>>().join(", ")
                ));
            }
        }
        eprintln!("{}: run in 6 frames", s.name);
    }
    out
}

#[test]
#[ignore = "long: every real-object mesh in six frames with the default search; see the module docs"]
fn every_real_object_keeps_its_verdict_in_five_random_frames_with_the_defaults() {
    let only = std::env::var("GRASP_SIM_FRAMES_ONLY").ok();
    let names: Option<Vec<&str>> = only.as_deref().map(|o| o.split(',').collect());
    let r = check_frames_defaults(names.as_deref());
    eprintln!(
        "{} reported grasps or fidelities differ (reported, not failed):\n{}",
        r.grasps.len(),
        r.grasps.join("\n")
    );
    eprintln!(
        "{} verdicts differ by coin tosses:\n{}",
        r.tosses.len(),
        r.tosses.join("\n")
    );
    eprintln!(
        "{} of {} objects' runs differ otherwise:\n{}",
        r.failures.len(),
        r.objects,
        r.failures.join("\n")
    );
    assert!(r.failures.is_empty(), "{}", r.failures.join("\n"));
}

#[test]
#[ignore = "long: every real-object mesh in five frames; see the module docs"]
fn every_real_object_plans_alike_in_five_random_frames() {
    let mode = if std::env::var_os("GRASP_SIM_FRAMES_NO_SIM").is_some() {
        Mode::Plan
    } else {
        Mode::Check
    };
    let only = std::env::var("GRASP_SIM_FRAMES_ONLY").ok();
    let names: Option<Vec<&str>> = only.as_deref().map(|o| o.split(',').collect());
    let FrameReport {
        objects,
        failures,
        tosses,
        as_planned,
    } = check_frames(names.as_deref(), mode);
    let count = |lines: &[String]| {
        lines
            .iter()
            .map(|f| f.split(' ').next().unwrap_or(""))
            .collect::<std::collections::BTreeSet<_>>()
            .len()
    };
    eprintln!(
        "{} of {objects} objects differ in some frame only by coin tosses (verdicts on \
         candidates whose hold probability is not decisive):\n{}",
        count(&tosses),
        tosses.join("\n")
    );
    eprintln!(
        "{} of {objects} objects keep every verdict but change a candidate's as_planned in some \
         frame (reported, not failed):\n{}",
        count(&as_planned),
        as_planned.join("\n")
    );
    eprintln!(
        "{} of {objects} objects differ in some frame otherwise:\n{}",
        count(&failures),
        failures.join("\n")
    );
    assert!(failures.is_empty(), "{} differences", failures.len());
}

#[test]
fn two_real_objects_keep_their_verdicts_in_five_random_frames_with_the_defaults() {
    // The default search on two committed meshes whose reported grasp moves between frames
    // (docs/FRAMES.md): the door handle, whose first candidate closes off its plan and whose
    // closing order picks another grasp in three frames, and the robosuite bottle, checked on
    // another axis in three. Each holds in every frame.
    let names = ["mw_door_handle", "rs_bottle"];
    let r = check_frames_defaults(Some(&names));
    assert_eq!(r.objects, names.len());
    assert!(r.failures.is_empty(), "{}", r.failures.join("\n"));
    assert!(r.tosses.is_empty(), "{}", r.tosses.join("\n"));
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
    let r = check_frames(Some(&names), Mode::Plan);
    assert_eq!(r.objects, names.len());
    assert!(r.failures.is_empty(), "{}", r.failures.join("\n"));
}

/// Plans `mesh` (in mm, no physics) written in `frame`, with the default (geometric) frame rule.
fn plan_mesh_in(
    mesh: &grasp_sim::mesh::Mesh,
    frame: &Isometry3<f64>,
    dir: &std::path::Path,
) -> RunReport {
    let options = RunOptions {
        no_sim: true,
        ..RunOptions::default()
    };
    run_mesh_in(mesh, frame, dir, &options)
}

/// Runs `mesh` (in mm) written in `frame` as a bare scenario with `options`.
fn run_mesh_in(
    mesh: &grasp_sim::mesh::Mesh,
    frame: &Isometry3<f64>,
    dir: &std::path::Path,
    options: &RunOptions,
) -> RunReport {
    let mut m = mesh.clone();
    m.map_vertices(|p| frame * p);
    let path = dir.join("m.stl");
    std::fs::write(&path, m.to_binary_stl()).unwrap();
    let s = Scenario::parse("[object]\nmesh = \"m.stl\"\n", &dir.join("s.toml")).unwrap();
    run(&s, options).unwrap()
}

/// A right prism on a regular `n`-gon of circumradius `r`, `h` tall, standing on Z = 0 `[mm]`.
fn regular_prism(n: usize, r: f64, h: f64) -> grasp_sim::mesh::Mesh {
    let corner = |k: usize, z: f64| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        Point3::new(r * a.cos(), r * a.sin(), z)
    };
    let (bottom, top) = (Point3::new(0.0, 0.0, 0.0), Point3::new(0.0, 0.0, h));
    let mut soup = Vec::new();
    for k in 0..n {
        let (a, b) = (corner(k, 0.0), corner(k + 1, 0.0));
        let (a2, b2) = (corner(k, h), corner(k + 1, h));
        soup.extend([[a, b, b2], [a, b2, a2], [bottom, b, a], [top, a2, b2]]);
    }
    grasp_sim::mesh::Mesh::from_triangles(&soup).0
}

#[test]
fn square_bars_bodies_of_revolution_and_a_ridged_object_plan_alike_in_five_frames() {
    // The shapes the frame rule is for: square sections (equal moments: the in-plane axes from
    // the largest flat faces or the farthest vertex), a body of revolution wider at one end
    // (the sense from the third moment), and the thesis's chapter 4 object with its vertical
    // ridge (no symmetry at all). Each is planned as written and in five random rigid frames.
    use grasp_sim::objects::{self, hard};
    let dir = tempfile::tempdir().unwrap();
    let shapes = [
        ("square_bar_20", hard::square_bar(20.0, 150.0, 1)),
        ("square_bar_35", hard::square_bar(35.0, 150.0, 3)),
        // Three equal moments: the first grasp axis square to a face.
        ("cube_60", hard::square_bar(60.0, 60.0, 3)),
        // Twelve triangles: the three equal moments must stay exactly equal.
        ("cube_40", hard::square_bar(40.0, 40.0, 1)),
        ("cube_90", hard::square_bar(90.0, 90.0, 1)),
        // 100 mm long: an elevation exactly one curvature reach below its end.
        ("square_bar_50_100", hard::square_bar(50.0, 100.0, 1)),
        // A square plate: a diamond's corner on the axis in the palm's plane, a span of a whole
        // number of steps.
        ("square_plate_70_40", hard::square_bar(70.0, 40.0, 2)),
        ("frustum_56_80", objects::frustum(56.0, 80.0, 110.0)),
        // 70 mm tall: the lowest finger's plane lies in the bottom face.
        ("hexagonal_prism_50_70", regular_prism(6, 27.0, 70.0)),
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

#[test]
fn a_cube_is_grasped_square_to_its_faces_in_any_frame() {
    // All three moments equal: the grasp axis runs along a face normal, as the faces pick it
    // (the farthest vertex put it along a diagonal, where every side leans 35-45 degrees from
    // the axis, past the friction cone, and the grasp needed `curvature_graded`: 4 of 6
    // phalanges on plan, the closing 3.3 mm off it). In the file's frame and a turned one the
    // grasp closes with every phalanx on plan and holds.
    use grasp_sim::objects::hard;
    use grasp_sim::plan::Relaxation;
    let dir = tempfile::tempdir().unwrap();
    let cube = hard::square_bar(60.0, 60.0, 3);
    for frame in [Isometry3::identity(), frames()[1]] {
        let r = run_mesh_in(&cube, &frame, dir.path(), &RunOptions::default());
        let g = r.plan.grasp.as_ref().expect("a grasp");
        let axis = frame.rotation.inverse() * Vector3::from(g.axis);
        let along = axis.x.abs().max(axis.y.abs()).max(axis.z.abs());
        assert!(
            along > 1.0 - 1e-9,
            "axis {axis:?} (cube frame) is not square to a face"
        );
        assert!(
            !g.relaxations.contains(&Relaxation::CurvatureGraded),
            "{:?}",
            g.relaxations
        );
        let f = r.sim.fidelity.as_ref().expect("a check");
        assert_eq!(r.sim.verdict.verdict(), Some(Verdict::Hold));
        assert!(f.as_planned, "{f:?}");
        assert_eq!((f.phalanges_on_plan, f.phalanges), (6, 6), "{f:?}");
        assert!(f.shift_mm < 1.0, "{f:?}");
    }
}
