//! The hold probability under perturbation (issue 34): a grasp that holds in every sample, one
//! at the edge of its friction cone that holds in some, one that never holds; the same samples
//! whatever the threads; a failure replayed; `[expect] min_hold_probability` judged on the
//! Wilson interval's lower bound.

use grasp_sim::report::RunReport;
use grasp_sim::report::Verdict;
use grasp_sim::scenario::Scenario;
use grasp_sim::{run, RunOptions};

/// The closing before the default changed (a straight approach with a 10° squeeze, no
/// reseat): chapter 4's first candidates and the slippery D40 are marginal under it, which the
/// tests of the samples need. Under the default closing chapter 4's first candidate holds in
/// 8 of 8 samples.
const SQUEEZE_CLOSING: &str =
    "approach = \"squeeze\"\nreseat = false\nsqueeze_deg = 10\nsqueeze2_deg = 10";

/// A bundled scenario with absolute asset paths, `sim` added to its `[sim]` table and
/// `expect` to its `[expect]` table, written to a temporary folder and loaded.
fn variant(name: &str, sim: &str, expect: &str) -> (tempfile::TempDir, Scenario) {
    variant_of(&format!("scenarios/{name}.toml"), sim, expect)
}

/// [`variant`] of the scenario at `path` (relative to the repository), its mesh path made
/// absolute.
fn variant_of(path: &str, sim: &str, expect: &str) -> (tempfile::TempDir, Scenario) {
    let root = crate::root();
    let file = root.join(path);
    let name = file.file_stem().unwrap().to_string_lossy().into_owned();
    let text = std::fs::read_to_string(&file).unwrap();
    let assets = format!("{}/assets", root.display());
    let mut text = text.replace("../assets", &assets);
    if !text.contains("mesh = \"/") {
        let here = file.parent().unwrap().display().to_string();
        text = text.replace("mesh = \"", &format!("mesh = \"{here}/"));
    }
    if text.contains("\n[sim]\n") {
        text = text.replace("\n[sim]\n", &format!("\n[sim]\n{sim}\n"));
    } else {
        text.push_str(&format!("\n[sim]\n{sim}\n"));
    }
    text = text.replace("\n[expect]\n", &format!("\n[expect]\n{expect}\n"));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let scenario = Scenario::load(&path).unwrap();
    (dir, scenario)
}

fn run_on(threads: usize, s: &Scenario) -> RunReport {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| run(s, &RunOptions::default()).unwrap())
}

/// The report's JSON without its wall-clock times.
fn timeless(r: &RunReport) -> serde_json::Value {
    crate::timeless(serde_json::to_value(r).unwrap())
}

/// The all-held lower bound of n samples: n / (n + z²), z the 95 % normal quantile.
fn all_held_lower(n: f64) -> f64 {
    let z = 1.959_963_984_540_054_f64;
    n / (n + z * z)
}

#[test]
fn d40_holds_in_every_sample_and_eight_of_eight_is_not_certainty() {
    // The thesis's D40 grasp: every perturbed check holds (p = 1), but 8 of 8 bounds the
    // probability below only by 0.676, so 0.999 is not met and 0.67 is.
    let (_d, strict) = variant(
        "cylinder_d40",
        "samples = 8",
        "min_hold_probability = 0.999",
    );
    let r = run_on(2, &strict);
    let robust = r.sim.robust.as_ref().expect("sim.robust with 8 samples");
    assert_eq!(
        (robust.counts.hold, robust.counts.slip, robust.counts.drop),
        (8, 0, 0)
    );
    assert_eq!(robust.hold_probability, 1.0);
    assert!((robust.interval[0] - all_held_lower(8.0)).abs() < 1e-12);
    assert_eq!(robust.interval[1], 1.0);
    assert!(robust.first_failure.is_none());
    assert_eq!(r.sim.verdict.verdict(), Some(Verdict::Hold));
    assert_eq!(r.expect.met, Some(false), "{}", r.expect.details);
    assert!(
        r.expect.details.contains("held in 8 of 8") && r.expect.details.contains("0.676"),
        "{}",
        r.expect.details
    );
    assert!(r
        .summary()
        .contains("held in 8 of 8 perturbed checks (100 %, 95 % interval 68–100 %)"));
    // The same samples judged against a bound just below 0.676: met.
    let mut lenient = strict.expect.clone().unwrap();
    lenient.min_hold_probability = Some(0.67);
    let judged = grasp_sim::report::ExpectReport::judge(&lenient, &r.plan, &r.sim);
    assert_eq!(judged.met, Some(true), "{}", judged.details);
}

#[test]
fn a_grasp_at_the_edge_of_its_friction_cone_holds_in_some_samples_the_same_on_any_threads() {
    // The D40 cylinder at 2 kg with mu = 0.085: the main check holds, but a few per cent less
    // friction or more mass and it falls (0.2 < p < 0.8).
    let (_d, s) = variant(
        "sim_d40_slippery_heavy",
        &format!("samples = 8\n{SQUEEZE_CLOSING}"),
        "",
    );
    let mut s = s;
    s.object.friction = 0.085;
    s.expect = None;
    let one = run_on(1, &s);
    let two = run_on(2, &s);
    assert_eq!(timeless(&one), timeless(&two), "1 and 2 threads differ");
    let r = one.sim.robust.as_ref().unwrap();
    assert!(
        r.hold_probability > 0.2 && r.hold_probability < 0.8,
        "{:?}",
        r.verdicts
    );
    assert_eq!(r.counts.hold + r.counts.slip + r.counts.drop, 8);
    assert_eq!(
        r.counts.hold,
        r.verdicts.iter().filter(|v| **v == Verdict::Hold).count()
    );
    // The interval brackets the estimate, and is wide with 8 samples.
    assert!(r.interval[0] < r.hold_probability && r.hold_probability < r.interval[1]);
    assert!(r.interval[1] - r.interval[0] > 0.4);
    // The first failure is the first sample that did not hold; replaying it alone gives its
    // verdict as the main check's.
    let first = r.first_failure.as_ref().unwrap();
    let k = r.verdicts.iter().position(|v| *v != Verdict::Hold).unwrap();
    assert_eq!(first.sample, k);
    assert_eq!(first.verdict, r.verdicts[k]);
    let mut replay = s.clone();
    replay.sim.robust.samples = 1;
    replay.sim.robust.replay_sample = Some(k);
    let replayed = run_on(2, &replay);
    assert!(replayed.sim.robust.is_none());
    assert_eq!(replayed.sim.replay.as_ref(), Some(&first.perturbation));
    assert_eq!(replayed.sim.verdict.verdict(), Some(first.verdict));
}

#[test]
fn open_fingers_never_hold() {
    let (_d, s) = variant("sim_open_fingers", "samples = 4", "");
    let r = run_on(2, &s);
    let robust = r.sim.robust.as_ref().unwrap();
    assert_eq!(robust.counts.drop, 4);
    assert_eq!(robust.hold_probability, 0.0);
    assert_eq!(robust.interval[0], 0.0);
    assert!((robust.interval[1] - (1.0 - all_held_lower(4.0))).abs() < 1e-12);
    assert_eq!(robust.first_failure.as_ref().unwrap().sample, 0);
}

#[test]
fn one_sample_reports_no_robust_part_and_bad_ranges_are_refused() {
    let (_d, s) = variant("sim_open_fingers", "samples = 1", "");
    let r = run_on(2, &s);
    let json = serde_json::to_value(&r).unwrap();
    assert!(json["sim"].get("robust").is_none() && json["sim"].get("replay").is_none());
    for (sim, key) in [
        ("samples = 0", "sim.samples"),
        ("friction_range_pct = -1.0", "sim.friction_range_pct"),
        ("choose = \"robust\"", "sim.choose"),
        ("choose_min_lower_bound = 1.5", "sim.choose_min_lower_bound"),
    ] {
        let root = crate::root();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(
            &path,
            format!(
                "[object]\nmesh = \"{}\"\n[sim]\n{sim}\n",
                root.join("assets/objects/cylinder_d40.stl").display()
            ),
        )
        .unwrap();
        let err = Scenario::load(&path).unwrap_err().to_string();
        assert!(err.contains(key), "{sim}: {err}");
    }
}

#[test]
fn the_samples_flag_overrides_the_scenario_and_the_summary_says_it() {
    let out = crate::succeed(crate::grasp_sim().args([
        "--json",
        "--samples",
        "2",
        "scenarios/sim_open_fingers.toml",
    ]));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["sim"]["robust"]["samples"], 2);
    assert_eq!(v["sim"]["robust"]["counts"]["drop"], 2);
    assert_eq!(v["sim"]["verdict"], "drop");
    let out = crate::succeed(crate::grasp_sim().args([
        "--samples",
        "2",
        "scenarios/sim_open_fingers.toml",
    ]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("Robust      held in 0 of 2 perturbed checks (0 %, 95 % interval 0–66 %); first failure: sample 0 (drop under -Z; replay with [sim] replay_sample = 0)"),
        "{text}"
    );
    let out = crate::grasp_sim()
        .args(["--samples", "0", "scenarios/sim_open_fingers.toml"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

/// The index in `plan.grasps` of the chosen grasp (`plan.grasp`).
fn chosen_index(r: &RunReport) -> usize {
    let chosen = r.plan.grasp.as_ref().expect("a chosen grasp");
    r.plan
        .grasps
        .iter()
        .position(|g| g.is_same_grasp(chosen))
        .expect("the chosen grasp among the candidates")
}

#[test]
fn robust_choice_passes_over_a_marginal_hold_for_a_later_robust_grasp() {
    // Chapter 4's object, gravity down, 8 samples. The search checks candidates until one
    // succeeds: under `choose = "first"` the second candidate (the first holds, but not as
    // planned) holds as planned in its main check and is taken, though only 6 of its 8 samples
    // hold as planned (lower bound 0.41). Under `choose = "robust"` success is a lower bound of
    // the probability of a hold as planned of at least 0.6, which only 8 of 8 (0.676) reaches:
    // the search goes on past it and takes the 7th candidate, the first whose samples all held
    // as planned.
    // The search order (`order_by_closing = 0`): the closing order would start elsewhere.
    let (_d, first) = variant(
        "chapter4",
        &format!("samples = 8\norder_by_closing = 0\n{SQUEEZE_CLOSING}"),
        "",
    );
    let (_e, robust) = variant(
        "chapter4",
        &format!(
            "samples = 8\nchoose = \"robust\"\nchoose_min_lower_bound = 0.6\norder_by_closing = 0\n{SQUEEZE_CLOSING}"
        ),
        "",
    );
    let f = run_on(2, &first);
    let rf = f.sim.robust.as_ref().unwrap();
    assert_eq!(f.sim.verdict.verdict(), Some(Verdict::Hold));
    assert_eq!(chosen_index(&f), 1);
    assert_eq!(f.plan.candidates_checked, 2);
    assert_eq!(
        rf.held_as_planned, 6,
        "{:?} {:?}",
        rf.verdicts, rf.as_planned
    );
    assert!(
        rf.as_planned_interval[0] < 0.6,
        "{:?}",
        rf.as_planned_interval
    );
    let r = run_on(2, &robust);
    let rr = r.sim.robust.as_ref().unwrap();
    let k = chosen_index(&r);
    // The search stopped at the first candidate that passed: every one before it was checked
    // and failed the bound (else the search would have stopped there).
    assert_eq!(r.plan.candidates_checked, k + 1);
    assert_eq!(k, 6);
    assert!(!r.plan.grasps[k].is_same_grasp(&f.plan.grasps[1]));
    assert_eq!(rr.held_as_planned, 8, "{:?}", rr.as_planned);
    assert!(
        (rr.as_planned_interval[0] - all_held_lower(8.0)).abs() < 1e-12
            && rr.as_planned_interval[0] >= 0.6
    );
    assert_eq!(r.sim.verdict.verdict(), Some(Verdict::Hold));
    // The first choice's grasp is among those passed over, with its main check a hold.
    let passed_over = &r.plan.grasps[1];
    assert!(passed_over.is_same_grasp(&f.plan.grasps[1]));
    assert_eq!(
        passed_over.check.as_ref().and_then(|c| c.ran()),
        Some(Verdict::Hold)
    );
    // Every candidate checked carries its own samples (`plan.grasps[].check.robust`): the one
    // passed over held as planned in 6 of 8, as under `choose = "first"`, the one chosen 8 of
    // 8, as `sim.robust` says; under `choose = "first"` no candidate carries any.
    let held = |g: &grasp_sim::report::GraspReport| {
        g.check.as_ref().and_then(|c| c.robust.as_ref()).map(|r| {
            (
                (r.as_planned_probability * r.samples as f64).round() as usize,
                r.samples,
            )
        })
    };
    assert_eq!(held(passed_over), Some((6, 8)));
    assert_eq!(held(&r.plan.grasps[k]), Some((8, 8)));
    assert!(r.plan.grasps[..=k].iter().all(|g| held(g).is_some()));
    assert!(f.plan.grasps.iter().all(|g| held(g).is_none()));
}

#[test]
fn tune_ranks_settings_by_the_mean_hold_probability_first() {
    // Chapter 4 with 8 samples over three values of Sf_c: each setting's grasp holds in its
    // main check and in every sample (hold rate and hold probability 1 everywhere), but Sf_c =
    // 0.3 finds one that holds as planned in 6 of 8 samples while 0.5 and 0.7 find ones that
    // do in 7 of 8. By the payload margin and the translation alone 0.3 would come before 0.7
    // (the same margin, less translation); ranked by the probability of a hold as planned
    // first it comes last. In the search order (`order_by_closing = 0`), as the ranking is
    // what this tests. The hold at 8 substeps, where the translations differ as said (at 12
    // they differ by 0.005 µm the other way).
    use grasp_sim::batch::{default_template, expand};
    use grasp_sim::tune::{parse_sweep, rank, tune};
    let (dir, _s) = variant(
        "chapter4",
        &format!(
            "samples = 8\norder_by_closing = 0\nhold_solver_iterations = 8\n{SQUEEZE_CLOSING}"
        ),
        "",
    );
    let items = expand(&[dir.path().join("chapter4.toml")]).unwrap();
    let r = tune(
        &items,
        &default_template(),
        &[parse_sweep("sf_c=0.3:0.7:0.2").unwrap()],
        1,
        2,
    )
    .unwrap();
    let p: Vec<f64> = r
        .settings
        .iter()
        .map(|s| s.mean_as_planned_probability.unwrap())
        .collect();
    assert_eq!(p, [6.0 / 8.0, 7.0 / 8.0, 7.0 / 8.0]);
    for s in &r.settings {
        assert_eq!(s.hold_rate, 1.0, "{:?}", s.values);
        assert_eq!(s.mean_hold_probability, Some(1.0), "{:?}", s.values);
        assert_eq!(
            s.objects[0].as_planned_probability,
            s.mean_as_planned_probability
        );
    }
    let mut order: Vec<usize> = (0..3).collect();
    order.sort_by(|&a, &b| rank(&r.settings[a], &r.settings[b]));
    assert_eq!(order, [1, 2, 0], "{:?}", r.settings);
    assert_eq!(r.best, 1);
    // Without the probability the last two would swap: the criteria that follow it order
    // Sf_c = 0.3 before 0.7.
    let unsampled = |i: usize| grasp_sim::tune::SettingResult {
        mean_hold_probability: None,
        mean_as_planned_probability: None,
        ..r.settings[i].clone()
    };
    assert_eq!(
        rank(&unsampled(0), &unsampled(2)),
        std::cmp::Ordering::Less,
        "{:?}",
        r.settings
    );
}

#[test]
fn tune_checks_the_chosen_grasp_as_a_run_reports_it() {
    // With `replay_sample` and one sample, a run reports the replayed check (the cup moves 11
    // µm under sample 1's perturbation against 1.5 µm unperturbed): so does tune.
    use grasp_sim::batch::{default_template, expand};
    use grasp_sim::tune::{parse_sweep, tune};
    let (dir, s) = variant("cup", "replay_sample = 1", "");
    let ran = run_on(2, &s);
    assert_eq!(ran.sim.replay.as_ref().map(|p| p.sample), Some(1));
    let items = expand(&[dir.path().join("cup.toml")]).unwrap();
    let sweep = [parse_sweep("sf_c=0.5:0.5:0.1").unwrap()];
    let r = tune(&items, &default_template(), &sweep, 1, 2).unwrap();
    let cup = &r.settings[0].objects[0];
    assert_eq!(cup.translation_mm, ran.sim.translation_mm, "{cup:?}");
    assert_eq!(cup.verdict.map(Verdict::from), ran.sim.verdict.verdict());
}

#[test]
fn the_six_directions_of_a_sample_continue_from_its_one_closing() {
    // Under `six` a perturbed sample closes the hand once and holds each direction from a copy
    // of the closed scene: its steps are one closing's plus each direction's hold, not six
    // closings (as `protocol = "full"` takes them, which closes afresh per direction).
    let (_d, s) = variant("cylinder_d40", "gravity = \"six\"\nreplay_sample = 3", "");
    let r = run_on(2, &s);
    let dt = s.sim.solver.timestep_s;
    let steps = |t: f64| (t / dt).round() as usize;
    let closing = steps(r.sim.closing.as_ref().unwrap().duration_s);
    assert!(closing > 0, "{closing}");
    let dirs = &r.sim.directions;
    assert_eq!(dirs.len(), 6);
    let holds: usize = dirs.iter().map(|d| steps(d.decided_at_s)).sum();
    assert_eq!(r.sim.steps, Some(closing + holds));
    // Every direction starts from the same closed pose, bit for bit.
    for d in dirs {
        assert_eq!(d.closed_at_s, dirs[0].closed_at_s);
        assert_eq!(
            d.closing_translation_mm.to_bits(),
            dirs[0].closing_translation_mm.to_bits()
        );
    }
    let mut full = s.clone();
    full.sim.protocol = grasp_sim::sim::params::Protocol::Full;
    let f = run_on(2, &full);
    let fdirs = &f.sim.directions;
    let holds: usize = fdirs.iter().map(|d| steps(d.decided_at_s)).sum();
    assert_eq!(f.sim.steps, Some(6 * closing + holds));
}

#[test]
fn a_replayed_sample_is_of_the_grasp_chosen_without_it() {
    // The tapered box's chosen grasp (the fifth candidate) drops the object in some of its 8
    // samples. Replaying the first failure must check that grasp under it: the candidate search
    // judges the candidates as given, not under the replayed perturbation (under which the
    // chosen grasp fails, and the search would go on to another candidate that holds under it).
    const BOX: &str = "assets/objects/train/tapered_box.toml";
    let (_d, mut s) = variant_of(BOX, "samples = 8", "");
    // The thesis's order, where the first candidate does not hold, searched in that order.
    s.planner = s.planner.clone().in_thesis_order();
    s.sim.selection.order_by_closing = 0;
    let r = run_on(2, &s);
    let first = r
        .sim
        .robust
        .as_ref()
        .unwrap()
        .first_failure
        .clone()
        .unwrap();
    assert!(r.plan.candidates_checked > 1);
    let (_e, mut replay) = variant_of(BOX, &format!("replay_sample = {}", first.sample), "");
    replay.planner = replay.planner.clone().in_thesis_order();
    replay.sim.selection.order_by_closing = 0;
    let replayed = run_on(2, &replay);
    assert_eq!(replayed.plan.candidates_checked, r.plan.candidates_checked);
    assert!(replayed
        .plan
        .grasp
        .as_ref()
        .unwrap()
        .is_same_grasp(r.plan.grasp.as_ref().unwrap()));
    assert_eq!(replayed.sim.replay.as_ref(), Some(&first.perturbation));
    assert_eq!(replayed.sim.verdict.verdict(), Some(first.verdict));
    assert!(replayed.sim.robust.is_none());
}

#[test]
fn the_two_probabilities_are_judged_apart() {
    // The vase of the tuning set holds in all 8 of its samples, but one sample's closing leaves
    // the plan: the hold probability's lower bound is 0.676 (8 of 8), the hold as planned's
    // 0.529 (7 of 8, Wilson). `min_hold_probability = 0.6` is met, `min_as_planned_probability
    // = 0.6` is not, and each says what it counted (issue 55).
    const VASE: &str = "assets/objects/train/vase.toml";
    let (_d, s) = variant_of(VASE, "samples = 8", "min_hold_probability = 0.6");
    let r = run_on(2, &s);
    let rb = r.sim.robust.as_ref().unwrap();
    assert_eq!((rb.counts.hold, rb.held_as_planned), (8, 7), "{rb:?}");
    assert_eq!(rb.as_planned.iter().filter(|a| !**a).count(), 1);
    assert!((rb.as_planned_interval[0] - grasp_sim::sim::robust::wilson(7, 8)[0]).abs() < 1e-15);
    assert_eq!(r.expect.met, Some(true), "{}", r.expect.details);
    assert!(
        r.expect
            .details
            .contains("held in 8 of 8 perturbed checks, 95 % lower bound 0.676"),
        "{}",
        r.expect.details
    );
    let (_e, s) = variant_of(VASE, "samples = 8", "min_as_planned_probability = 0.6");
    let r = run_on(2, &s);
    assert_eq!(r.expect.met, Some(false), "{}", r.expect.details);
    assert!(
        r.expect
            .details
            .contains("held as planned in 7 of 8 perturbed checks, 95 % lower bound 0.529"),
        "{}",
        r.expect.details
    );
    // `as_planned = true` asks a hold: with another outcome it is refused, naming the key.
    let root = crate::root();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        format!(
            "[object]\nmesh = \"{}\"\n[expect]\noutcome = \"slip\"\nas_planned = true\n",
            root.join("assets/objects/cylinder_d40.stl").display()
        ),
    )
    .unwrap();
    let err = Scenario::load(&path).unwrap_err().to_string();
    assert!(err.contains("expect.as_planned"), "{err}");
}
