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
