//! The cheaper hold settings of issue 35 (docs/SIM.md, "Settings tried under the criterion"):
//! the hold's substeps change the hold and leave the closing alone, and the shorter rest
//! window decides a still grasp sooner with the same verdict and numbers.

use grasp_sim::report::{DecidedBy, Verdict};
use grasp_sim::scenario::{GravityMode, Scenario};
use grasp_sim::{run, RunOptions};

fn d40_six() -> Scenario {
    let mut s = Scenario::load(&crate::root().join("scenarios/cylinder_d40.toml")).unwrap();
    s.sim.gravity = GravityMode::Six;
    s.sim.selection.max_checked = 1;
    s
}

#[test]
fn the_holds_substeps_leave_the_closing_bit_for_bit() {
    // The same grasp held at 8 substeps a step (the default, the closing's) and at 6: the
    // closing is the same to the bit (it runs before the hold's setting applies), and the
    // holds differ, but both hold D40 within a tenth of a millimetre in every direction.
    let mut s = d40_six();
    let eight = run(&s, &RunOptions::default()).unwrap().sim;
    s.sim.solver.hold_solver_iterations = 6;
    let six = run(&s, &RunOptions::default()).unwrap().sim;
    assert_eq!(six.directions.len(), 6);
    for (a, b) in six.directions.iter().zip(&eight.directions) {
        assert_eq!(a.closed_at_s.to_bits(), b.closed_at_s.to_bits());
        assert_eq!(
            a.closing_translation_mm.to_bits(),
            b.closing_translation_mm.to_bits()
        );
        assert_eq!(
            a.closing_penetration_mm.to_bits(),
            b.closing_penetration_mm.to_bits()
        );
        assert_eq!(a.verdict, Verdict::Hold);
        assert_eq!(b.verdict, Verdict::Hold);
        assert!(a.translation_mm < 0.1 && b.translation_mm < 0.1);
    }
    let moved = six
        .directions
        .iter()
        .zip(&eight.directions)
        .any(|(a, b)| a.translation_mm.to_bits() != b.translation_mm.to_bits());
    assert!(moved, "the hold's substeps did not change the hold");
}

#[test]
fn a_shorter_rest_window_decides_a_still_grasp_sooner_with_the_same_numbers() {
    // D40 hardly moves in its hold: the 0.05 s window (the default since a629fd9) decides
    // every direction at rest within 0.11 s (five at 0.0625 s, three samples of 1/48 s; under
    // −Z the fingers settle first), the 0.1 s window (the default before) at 0.15–0.17 s, the
    // 0.2 s window at 0.229 s, and the verdicts and translations agree within 0.05 mm.
    let mut s = d40_six();
    let short = run(&s, &RunOptions::default()).unwrap().sim;
    s.sim.early.rest_window_s = 0.2;
    let long = run(&s, &RunOptions::default()).unwrap().sim;
    s.sim.early.rest_window_s = 0.1;
    let middle = run(&s, &RunOptions::default()).unwrap().sim;
    for ((a, b), m) in short
        .directions
        .iter()
        .zip(&long.directions)
        .zip(&middle.directions)
    {
        assert_eq!(a.decided_by, DecidedBy::Rest);
        assert_eq!(b.decided_by, DecidedBy::Rest);
        assert_eq!(m.decided_by, DecidedBy::Rest);
        assert!(a.decided_at_s < 0.11, "decided at {} s", a.decided_at_s);
        assert!(
            a.decided_at_s < m.decided_at_s && m.decided_at_s <= b.decided_at_s,
            "decided at {} s, {} s, {} s",
            a.decided_at_s,
            m.decided_at_s,
            b.decided_at_s
        );
        assert!(b.decided_at_s > 0.2, "decided at {} s", b.decided_at_s);
        assert_eq!(a.verdict, m.verdict);
        assert!((a.translation_mm - m.translation_mm).abs() < 0.05);
        assert_eq!(a.verdict, b.verdict);
        assert!((a.translation_mm - b.translation_mm).abs() < 0.05);
    }
    assert!(short.steps.unwrap() < middle.steps.unwrap());
    assert!(middle.steps.unwrap() < long.steps.unwrap());
}
