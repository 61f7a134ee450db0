//! Issue 16, the rest: progress on a terminal, every candidate in the summary, tune's invalid
//! settings, "did you mean", welding within a tolerance, rounded JSON figures, the report page.

use crate::{grasp_sim, succeed};

/// Runs `args` under `script`, so that stderr is a terminal; `None` where `script` is missing.
fn on_a_terminal(args: &str) -> Option<String> {
    let bin = env!("CARGO_BIN_EXE_grasp-sim");
    let out = std::process::Command::new("script")
        .args(["-qec", &format!("{bin} {args} >/dev/null"), "/dev/null"])
        .current_dir(crate::root())
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn long_runs_show_progress_on_a_terminal_only() {
    let Some(tty) = on_a_terminal("scenarios/cylinder_d40.toml") else {
        eprintln!("no `script` here: the terminal half is not checked");
        return;
    };
    assert!(
        tty.contains("cylinder_d40: planning, physics check"),
        "{tty}"
    );
    let piped = succeed(grasp_sim().args(["scenarios/cylinder_d40.toml"]));
    let err = String::from_utf8_lossy(&piped.stderr);
    assert!(!err.contains("physics check"), "{err}");

    let out = tempfile::tempdir().unwrap();
    let args = format!(
        "tune scenarios/cylinder_d40.toml --param sf_c=0:1:1 --out {}",
        out.path().display()
    );
    let tty = on_a_terminal(&args).expect("tune runs");
    assert!(tty.contains("/2") && tty.contains("tune: "), "{tty}");
    let piped = succeed(grasp_sim().args(args.split(' ')));
    let err = String::from_utf8_lossy(&piped.stderr);
    assert!(!err.contains("done at one setting"), "{err}");
}

#[test]
fn the_summary_lists_every_candidate_collected_or_checked() {
    let out = succeed(grasp_sim().args(["scenarios/cup.toml", "--no-sim", "--candidates", "3"]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("3 candidates tried"), "{text}");
    assert!(text.contains("Candidates  3 collected"), "{text}");
    for (k, approach) in [(1, 0), (2, 10), (3, 20)] {
        assert!(
            text.contains(&format!(
                "{k}. axis least (thesis), approach {approach} deg"
            )),
            "{text}"
        );
    }
    assert!(
        text.contains("* 1. "),
        "the reported grasp is marked: {text}"
    );
    // Checked by the physics check: each candidate's verdict, and how many were checked.
    let out = grasp_sim()
        .args(["scenarios/sim_d40_slippery_heavy.toml"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("8 candidates tried, 8 checked"), "{text}");
    assert_eq!(text.matches("; check: drop (").count(), 8, "{text}");
    // A single grasp is not listed twice.
    let out = succeed(grasp_sim().args(["scenarios/cup.toml", "--no-sim"]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("Candidates  "), "{text}");
}
