//! The order's significance factors (issue 58): at 0 the thesis's order, bit for bit; a large
//! factor puts the candidate its term prefers first.

use crate::{grasp_sim, root};
use serde_json::Value;

/// The cup's scenario with `extra` added to its `[planner]` table, in `dir`.
fn cup_with(dir: &std::path::Path, extra: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(root().join("scenarios/cup.toml")).unwrap();
    let assets = root().join("assets");
    let text = text.replace("../assets", assets.to_str().unwrap());
    // The factors given replace the scenario's (the thesis's zeros).
    let text: String = text
        .lines()
        .filter(|l| {
            !extra
                .lines()
                .any(|e| l.starts_with(e.split('=').next().unwrap()))
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let text = if text.contains("[planner]") {
        text.replace("[planner]", &format!("[planner]\n{extra}"))
    } else {
        format!("{text}\n[planner]\n{extra}\n")
    };
    let p = dir.join(format!("cup_{}.toml", extra.len()));
    std::fs::write(&p, text).unwrap();
    p
}

fn grasps(scenario: &std::path::Path) -> Vec<Value> {
    let o = grasp_sim()
        .args(["--json", "--no-sim", "--candidates", "40"])
        .arg(scenario)
        .output()
        .unwrap();
    // 1: the cup's `[expect]` (the thesis's grasp) not met by a reordered plan.
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    v["plan"]["grasps"].as_array().unwrap().clone()
}

#[test]
fn factors_at_zero_give_the_thesis_order_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    // The cup's scenario sets every factor to 0: the thesis's order, its first grasp the
    // thesis's Grasp Parameter Set (thesis 5.3: elevation 23, approach 0°, pitch −7° within its 1°).
    let thesis = grasps(&root().join("scenarios/cup.toml"));
    assert_eq!(thesis.len(), 40);
    let first = &thesis[0];
    assert_eq!(first["elevation_index"], 23, "{first}");
    assert_eq!(first["approach_angle_deg"].as_f64(), Some(0.0), "{first}");
    let pitch = first["palm_pitch_deg"].as_f64().unwrap();
    assert!((pitch + 7.0).abs() < 1.0, "{first}");
    // The zeros written again: the same grasps, bit for bit.
    let zero = cup_with(dir.path(), "sf_centred = 0.0\nsf_even = 0.0");
    assert_eq!(grasps(&zero), thesis);
    // A factor reorders the axis's grasps: the 40 reported are others, or in another order.
    let centred = grasps(&cup_with(dir.path(), "sf_centred = 100.0"));
    assert_eq!(centred.len(), 40);
    assert_ne!(centred, thesis);
    // The defaults are the thesis's order.
    let defaults = dir.path().join("cup_defaults.toml");
    let text = std::fs::read_to_string(&zero).unwrap();
    let text: String = text
        .lines()
        .filter(|l| !l.starts_with("sf_"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&defaults, text).unwrap();
    assert_eq!(grasps(&defaults), thesis);
}

#[test]
fn a_large_factor_puts_the_grasp_its_term_prefers_first() {
    let dir = tempfile::tempdir().unwrap();
    let s = cup_with(dir.path(), "sf_spread = 100.0");
    let out = dir.path().join("l.jsonl");
    let o = grasp_sim()
        .arg("label")
        .arg(&s)
        .args(["--grasps", "12", "--samples", "1", "--in-process", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let lines: Vec<Value> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let first = lines.iter().find(|l| l["grasp_index"] == 0).unwrap();
    let spread = |l: &Value| l["grade"]["terms"]["spread"].as_f64().unwrap();
    // The place term is worth at most 1, the spread 100 × its difference.
    for l in lines.iter().filter(|l| l["grade"]["axis_plan"] == 0) {
        assert!(
            spread(first) >= spread(l) - 0.01,
            "{} < {}",
            spread(first),
            spread(l)
        );
    }
    assert_eq!(first["grade"]["place"], 0);
    // `even`: minus the spread of the planned joint-2 bends over the thesis hand's 90° range.
    for l in &lines {
        let bends: Vec<f64> = l["joint_angles_deg"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f[1].as_f64().unwrap())
            .collect();
        let spread2 = bends.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - bends.iter().cloned().fold(f64::INFINITY, f64::min);
        let even = l["grade"]["terms"]["even"].as_f64().unwrap();
        assert!(spread2 > 0.0 || even == 0.0);
        assert!((even + spread2 / 90.0).abs() < 1e-9, "{even} {spread2}");
    }
    assert!(lines
        .iter()
        .any(|l| l["grade"]["terms"]["even"].as_f64().unwrap() < -0.01));
}

/// The JSON report of LIBERO's akita bowl with `sim` as its `[sim]` table.
fn akita_bowl(dir: &std::path::Path, sim: &str) -> Value {
    let text = crate::real_scenario_text("libero_akita_black_bowl");
    let p = dir.join(format!("akita_{}.toml", sim.len()));
    std::fs::write(&p, format!("{text}\n[sim]\n{sim}\n")).unwrap();
    let o = grasp_sim()
        .args(["--json", "--candidates", "16"])
        .arg(&p)
        .output()
        .unwrap();
    crate::assert_success(&o);
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn the_closing_order_checks_first_a_grasp_whose_closing_stays_near_its_plan() {
    // The thesis's first candidate on the akita bowl: its closing throws the bowl 102 mm and
    // it drops. `order_by_closing = 16` (the default) closes 16 diverse candidates with gravity
    // off and checks first the one whose closing kept nearest its plan (none of the 16 as
    // planned: the least shift, 5.7 mm): it holds, with one check, as the thesis's first does
    // not.
    let dir = tempfile::tempdir().unwrap();
    let thesis = akita_bowl(dir.path(), "max_checked = 1\norder_by_closing = 0");
    assert_eq!(thesis["sim"]["verdict"], "drop", "{}", thesis["sim"]);
    let shift = thesis["sim"]["fidelity"]["shift_mm"].as_f64().unwrap();
    assert!(shift > 50.0, "{shift}");
    assert!(thesis["plan"]["grasp"].get("closing_order").is_none());

    // The order of 16 picks (`order_reach = 16`: none further), one check.
    let ordered = akita_bowl(dir.path(), "max_checked = 1\norder_reach = 16");
    assert_eq!(ordered["sim"]["verdict"], "hold", "{}", ordered["sim"]);
    assert_eq!(ordered["plan"]["candidates_checked"], 1);
    let grasps = ordered["plan"]["grasps"].as_array().unwrap();
    assert_eq!(grasps.len(), 16);
    // In the order their closings give: as planned first, then the shift in whole mm.
    let key = |g: &Value| {
        let c = &g["closing_order"];
        (
            !c["as_planned"].as_bool().unwrap(),
            c["shift_mm"].as_f64().unwrap().floor(),
        )
    };
    for w in grasps.windows(2) {
        assert!(
            key(&w[0]) <= key(&w[1]),
            "{} then {}",
            w[0]["closing_order"],
            w[1]["closing_order"]
        );
    }
    // The chosen grasp is the first of them, checked once, and not the thesis's first; the
    // thesis's first is among the 16 (`label`'s picks always hold it).
    assert_eq!(ordered["plan"]["grasp"], grasps[0]);
    assert!(grasps[0]["check"].is_object());
    assert!(grasps[1..].iter().all(|g| g.get("check").is_none()));
    let pose = |g: &Value| g["palm_pose"].clone();
    assert_ne!(pose(&grasps[0]), pose(&thesis["plan"]["grasp"]));
    assert!(grasps
        .iter()
        .any(|g| pose(g) == pose(&thesis["plan"]["grasp"])));
    let fidelity_shift = ordered["sim"]["fidelity"]["shift_mm"].as_f64().unwrap();
    let closed_shift = grasps[0]["closing_order"]["shift_mm"].as_f64().unwrap();
    // The check closes the same way as the closing that ordered it.
    assert_eq!(fidelity_shift, closed_shift);
    // With the default 8 checks the search ends there too: it held, and no pick closes as
    // planned, so none after it can hold as planned; the same grasp, the same check.
    let default = akita_bowl(dir.path(), "order_reach = 16");
    assert_eq!(default["plan"]["candidates_checked"], 1);
    assert_eq!(default["plan"]["grasp"], ordered["plan"]["grasp"]);
    assert_eq!(default["sim"]["fidelity"], ordered["sim"]["fidelity"]);

    // At the default `order_reach` (64) the order picks on, none of the 16 having kept its
    // plan: one further pick keeps it in 4 of its 5 closings and is checked first; it slips
    // (the bowl turns in the hand), and the default search's second check is the nearest of
    // the 16, which holds as before.
    let reached = akita_bowl(dir.path(), "");
    assert_eq!(reached["plan"]["grasps"].as_array().unwrap().len(), 17);
    assert_eq!(reached["plan"]["candidates_checked"], 2);
    assert_eq!(reached["plan"]["grasp"], default["plan"]["grasp"]);
    let further = &reached["plan"]["grasps"][0];
    assert_eq!(further["closing_order"]["as_planned"], true);
    assert_eq!(further["closing_order"]["sampled_on_plan"], 3);
    assert_eq!(further["check"]["verdict"], "slip");
}

/// The prism of the random shapes (`scripts/random_shapes.py --seed 9`, shape 44) with `sim`
/// added to a one-check `[sim]` table with 8 samples.
fn prism(dir: &std::path::Path, sim: &str) -> Value {
    random_shape(dir, "random_prism_seed9_044.stl", sim)
}

/// The fixture `name` (one of the random shapes) with `sim` added to a one-check `[sim]`
/// table with 8 samples.
fn random_shape(dir: &std::path::Path, name: &str, sim: &str) -> Value {
    one_check(dir, &root().join("tests/fixtures").join(name), sim)
}

/// The grasps `run` lists whose palm pose is none of `picks`': the order's further picks.
fn further_picks<'a>(run: &'a Value, picks: &[Value]) -> Vec<&'a Value> {
    run["plan"]["grasps"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|g| picks.iter().all(|p| p["palm_pose"] != g["palm_pose"]))
        .collect()
}

/// `mesh` run with one check of 8 samples and `sim` added to its `[sim]` table, in `dir`.
fn one_check(dir: &std::path::Path, mesh: &std::path::Path, sim: &str) -> Value {
    let name = mesh.file_name().unwrap().to_str().unwrap();
    let p = dir.join(format!("{name}_{}.toml", sim.len()));
    let text = format!(
        "[object]\nmesh = {:?}\n\n[sim]\nsamples = 8\nmax_checked = 1\n{sim}\n",
        mesh.to_str().unwrap()
    );
    std::fs::write(&p, text).unwrap();
    let o = grasp_sim().arg("--json").arg(&p).output().unwrap();
    crate::assert_success(&o);
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn perturbed_closings_check_first_a_grasp_that_keeps_its_plan_off_its_nominal_pose() {
    // The prism's first candidate closes as planned from its nominal pose, so the order by
    // the nominal closing alone (`order_samples = 0`) keeps it first, and it drops in every
    // perturbed sample. With `order_samples = 4` (the default) its four perturbed closings are
    // run too, two of them leave the plan, and the search checks first a grasp whose five
    // closings all kept it: it holds in every sample.
    let dir = tempfile::tempdir().unwrap();
    let nominal = prism(dir.path(), "order_samples = 0");
    let first = nominal["plan"]["grasp"].clone();
    assert_eq!(nominal["sim"]["fidelity"]["as_planned"], true);
    let p0 = nominal["sim"]["robust"]["hold_probability"]
        .as_f64()
        .unwrap();
    assert!(p0 <= 0.25, "{p0}");
    assert!(first.get("closing_order").is_none());

    let sampled = prism(dir.path(), "");
    assert_eq!(sampled["plan"]["candidates_checked"], 1);
    let p4 = sampled["sim"]["robust"]["hold_probability"]
        .as_f64()
        .unwrap();
    assert!(p4 >= 0.75, "{p4}");
    let chosen = &sampled["plan"]["grasp"];
    assert_ne!(chosen["palm_pose"], first["palm_pose"]);
    assert_eq!(chosen["closing_order"]["as_planned"], true);
    assert_eq!(chosen["closing_order"]["sampled_on_plan"], 4);
    // The first is among the closed picks, its perturbed closings counted: not all on plan.
    let grasps = sampled["plan"]["grasps"].as_array().unwrap();
    let thesis_first = grasps
        .iter()
        .find(|g| g["palm_pose"] == first["palm_pose"])
        .expect("the first candidate among the picks");
    let on = thesis_first["closing_order"]["sampled_on_plan"]
        .as_u64()
        .unwrap();
    assert!(on < 4, "{on}");
}

#[test]
fn the_order_picks_on_until_a_closing_keeps_its_plan() {
    // Two overlapping boxes of the random shapes (`scripts/random_shapes.py --seed 9`, shape
    // 39). None of the 16 picks the order closes keeps its plan (the least shift 5.2 mm,
    // against the 5 mm bound): with `order_reach = 16` the order stops there, and its first
    // holds in 3 of 8 samples. At the default it picks on, and takes a further pick (among
    // the first 64) most of whose five closings keep the plan: it holds in every sample.
    let dir = tempfile::tempdir().unwrap();
    let nearest = random_shape(
        dir.path(),
        "random_compound_seed9_039.stl",
        "order_reach = 16",
    );
    let picks = nearest["plan"]["grasps"].as_array().unwrap();
    assert_eq!(picks.len(), 16);
    assert!(picks
        .iter()
        .all(|g| g["closing_order"]["as_planned"] == false));
    let p16 = nearest["sim"]["robust"]["hold_probability"]
        .as_f64()
        .unwrap();
    assert!(p16 <= 0.5, "{p16}");

    let reached = random_shape(dir.path(), "random_compound_seed9_039.stl", "");
    assert_eq!(reached["plan"]["candidates_checked"], 1);
    let chosen = &reached["plan"]["grasp"];
    assert_eq!(chosen["closing_order"]["as_planned"], true);
    assert_eq!(reached["sim"]["fidelity"]["as_planned"], true);
    let p64 = reached["sim"]["robust"]["hold_probability"]
        .as_f64()
        .unwrap();
    assert!(p64 >= 0.875, "{p64}");
    // A further pick: none of the first 16.
    assert!(picks.iter().all(|g| g["palm_pose"] != chosen["palm_pose"]));
    // Every further pick listed kept its plan in more than half of its 5 closings.
    let further = further_picks(&reached, picks);
    assert!(!further.is_empty());
    for g in further {
        let c = &g["closing_order"];
        let on = 1 + c["sampled_on_plan"].as_u64().unwrap();
        assert!(c["as_planned"] == true && 2 * on > 5, "{c}");
    }
}

#[test]
fn the_order_picks_on_past_64_candidates_at_order_reach_128() {
    // A torus, its tube 35 mm thick round a 55 mm hole. None of the first 64 picks keeps its
    // plan (the 16 listed leave it by 5.6 mm or more, against the 5 mm bound), so at
    // `order_reach = 64` the order takes the nearest of the 16, which holds in 5 of 8 samples.
    // At `order_reach = 128` two of the picks from 65 to 128 keep their plan in 3 of their 5
    // closings, and the first of them holds in every sample.
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("torus.stl");
    let torus = grasp_sim::objects::torus(45.0, 17.5, 48, 24);
    std::fs::write(&mesh, torus.to_binary_stl()).unwrap();

    let at_64 = one_check(dir.path(), &mesh, "order_reach = 64");
    let picks = at_64["plan"]["grasps"].as_array().unwrap();
    assert_eq!(picks.len(), 16);
    assert!(picks
        .iter()
        .all(|g| g["closing_order"]["as_planned"] == false));
    let p64 = at_64["sim"]["robust"]["hold_probability"].as_f64().unwrap();
    assert!(p64 <= 0.625, "{p64}");

    let reached = one_check(dir.path(), &mesh, "order_reach = 128");
    let further = further_picks(&reached, picks);
    assert_eq!(
        further.len() + 16,
        reached["plan"]["grasps"].as_array().unwrap().len()
    );
    assert!(!further.is_empty());
    assert_eq!(
        reached["plan"]["grasp"]["palm_pose"],
        further[0]["palm_pose"]
    );
    assert_eq!(reached["sim"]["fidelity"]["as_planned"], true);
    let p128 = reached["sim"]["robust"]["hold_probability"]
        .as_f64()
        .unwrap();
    assert!(p128 >= 0.875, "{p128}");
}
