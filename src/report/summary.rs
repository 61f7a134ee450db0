//! The human summary of a run: the thesis's "Grasp Parameter Set" style where a plan exists,
//! the physics check, the closing, the quality and the result in one sentence.

use super::check::{ClosingOutcome, Fidelity, FidelityReason, FingerClosing, Verdict};
use super::robust::{Perturbation, Robust};
use super::{GraspReport, PlanReport, RunReport, SimReport, SimVerdict};
use crate::messages::plural;
use std::fmt::Write;

impl GraspReport {
    /// Returns true if and only if `other` is the same grasp: the same axis, rules, approach,
    /// elevation, pitch and joint angles.
    pub fn is_same_grasp(&self, other: &GraspReport) -> bool {
        self.axis_name == other.axis_name
            && self.rules == other.rules
            && self.approach_angle_deg == other.approach_angle_deg
            && self.elevation_index == other.elevation_index
            && self.palm_pitch_deg == other.palm_pitch_deg
            && self
                .fingers
                .iter()
                .zip(&other.fingers)
                .all(|(a, b)| a.theta1_deg == b.theta1_deg && a.theta2_deg == b.theta2_deg)
    }

    /// The rules in words: `thesis`, or `extended: ` and the relaxations used.
    pub fn one_line_rules(&self) -> String {
        let rules = match serde_json::to_value(self.rules) {
            Ok(serde_json::Value::String(r)) => r,
            _ => String::new(),
        };
        let relaxed: Vec<String> = self
            .relaxations
            .iter()
            .filter_map(|r| match serde_json::to_value(r) {
                Ok(serde_json::Value::String(r)) => Some(r),
                _ => None,
            })
            .collect();
        if relaxed.is_empty() {
            rules
        } else {
            format!("{rules}: {}", relaxed.join(", "))
        }
    }

    /// The grasp in one line: axis and rules (with relaxations), approach, elevation, pitch,
    /// joint angles, and the physics check's verdict when it ran on this grasp.
    pub fn one_line(&self) -> String {
        let rules = self.one_line_rules();
        let thetas: Vec<String> = self
            .fingers
            .iter()
            .map(|f| format!("{:.1}/{:.1}", f.theta1_deg, f.theta2_deg))
            .collect();
        let check = match &self.check {
            Some(c) => format!(
                "; check: {}{} ({:.2} mm, {:.2} deg)",
                c.verdict,
                if c.fidelity.as_planned {
                    ""
                } else {
                    ", not as planned"
                },
                c.translation_mm,
                c.rotation_deg
            ),
            None => "; not checked".to_string(),
        };
        let quality = match &self.quality {
            Some(q) => format!("; epsilon {:.3} ({} contacts)", q.epsilon, q.source),
            None => String::new(),
        };
        let closing = match &self.closing_order {
            Some(c) => format!(
                "; closed {}, {:.1} mm",
                if c.as_planned {
                    "as planned"
                } else {
                    "off plan"
                },
                c.shift_mm
            ),
            None => String::new(),
        };
        format!(
            "axis {} ({rules}), approach {:.0} deg, index {} (Z {:.1} mm), pitch {} deg, theta1/theta2 {}{closing}{check}{quality}",
            self.axis_name,
            self.approach_angle_deg,
            self.elevation_index,
            self.elevation_mm,
            fmt_signed(self.palm_pitch_deg, 1),
            thetas.join(", ")
        )
    }
}

impl RunReport {
    /// The human summary, in the thesis's "Grasp Parameter Set" style where a plan exists.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        self.write_object(&mut s);
        self.write_search_range(&mut s);
        self.write_plan(&mut s);
        if let Some(g) = &self.plan.grasp {
            write_grasp_parameter_set(&mut s, g);
        }
        self.write_sim(&mut s);
        if let Some(q) = &self.quality {
            let _ = writeln!(s, "  Quality     {}", quality_line(q));
        }
        let _ = writeln!(s, "  Result      {}", self.result_sentence());
        self.write_expect(&mut s);
        s
    }

    /// The scenario's name, the object, its principal axis, and the grasp's axis when it is
    /// not the least one.
    fn write_object(&self, s: &mut String) {
        let o = &self.object;
        let _ = writeln!(s, "{}", self.scenario);
        let _ = writeln!(
            s,
            "  Object      {}: {} triangles, volume {:.1} cm^3, mass {:.3} kg, height {:.1} mm",
            o.mesh,
            o.triangles,
            o.volume_mm3 / 1000.0,
            o.mass_kg,
            o.height_mm
        );
        let a = o.principal_axis;
        let _ = writeln!(
            s,
            "  Principal axis (original frame) ({:.4}, {:.4}, {:.4})",
            a[0], a[1], a[2]
        );
        // The height above is along the least axis; a grasp about another one is planned, and
        // its elevations below measured, along that one.
        if let Some(g) = self.plan.grasp.as_ref().filter(|g| g.axis_name != "least") {
            let _ = writeln!(
                s,
                "  Grasp axis  the {} principal axis ({:.4}, {:.4}, {:.4}), original frame: the elevations below are along it",
                g.axis_name, g.axis[0], g.axis[1], g.axis[2]
            );
        }
    }

    /// The elevation range searched, the graspable diameters, and the sorted palm indices.
    fn write_search_range(&self, s: &mut String) {
        let p = &self.plan;
        // Under the extended rules the range is the whole object widened so that an outer
        // finger may overhang its ends: not the thesis's Effective Elevation, so not called so.
        let range_name = match p.grasp.as_ref().map(|g| g.rules) {
            Some(crate::plan::RuleSet::Thesis) | None => "Effective elevation",
            Some(_) => "Search elevation (extended rules: outer fingers may overhang the ends)",
        };
        let [lo, hi] = p.effective_elevation_mm;
        // An object shorter than the two finger offsets has no Effective Elevation: its range
        // would print inverted.
        let range = if hi >= lo {
            format!("{lo:.1}..{hi:.1} mm")
        } else {
            "none (the object is shorter than the finger width)".to_string()
        };
        let _ = writeln!(
            s,
            "  {range_name} {range}, {} indexed elevations; graspable diameter {:.1}..{:.1} mm ({}; thesis 9x rule {:.1})",
            p.indexed_elevations,
            p.graspable_diameter_mm[0],
            p.graspable_diameter_mm[1],
            p.graspable_diameter_basis,
            p.thesis_largest_diameter_mm
        );
        let _ = writeln!(
            s,
            "  Sorted palm indices ({}): {}",
            p.sorted_indices.len(),
            sorted_indices_head(p)
        );
    }

    /// The plan's status (and why, or under which rules), the candidates tried and checked,
    /// and every grasp collected when there are several.
    fn write_plan(&self, s: &mut String) {
        let p = &self.plan;
        let plan_line = match (&p.reason, &p.grasp) {
            (Some(r), _) => format!("{} ({r})", p.status),
            (None, Some(g)) if g.rules != crate::plan::RuleSet::Thesis => format!(
                "{} under rules beyond the thesis ({}), as the thesis's own found no grasp, or none that held",
                p.status,
                g.one_line_rules()
            ),
            (None, _) => p.status.to_string(),
        };
        let checked = if p.candidates_checked > 0 {
            format!(", {} checked", p.candidates_checked)
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "  Plan        {plan_line}; {} tried{checked}",
            plural(p.candidates_tried, "candidate")
        );
        if p.grasps.len() > 1 {
            // Under `[sim] order_by_closing` the closed picks come first, in the order checked.
            let order = if p.grasps.iter().any(|g| g.closing_order.is_some()) {
                "the closed ones first, in the order their closings gave"
            } else {
                "in search order"
            };
            let _ = writeln!(
                s,
                "  Candidates  {} collected, {order} (* the one reported below):",
                p.grasps.len()
            );
            for (k, g) in p.grasps.iter().enumerate() {
                let chosen = p.grasp.as_ref().is_some_and(|c| c.is_same_grasp(g));
                let _ = writeln!(
                    s,
                    "   {}{:>2}. {}",
                    if chosen { "*" } else { " " },
                    k + 1,
                    g.one_line()
                );
            }
        }
    }

    /// The physics check's line and, when it closed the hand, the closing's lines.
    fn write_sim(&self, s: &mut String) {
        let _ = writeln!(s, "  Sim         {}", self.sim_line());
        if let Some(p) = &self.sim.replay {
            let _ = writeln!(s, "  Replay      {}", replay_line(p));
        }
        if let Some(r) = &self.sim.robust {
            let _ = writeln!(s, "  Robust      {}", robust_line(r));
        }
        if let Some(c) = &self.sim.closing {
            let _ = writeln!(s, "  Closing     {}", closing_line(c));
            let set = |f: &FingerClosing, which: fn(&FingerClosing) -> [f64; 2]| {
                let [a, b] = which(f);
                format!("{a:.1}/{b:.1}")
            };
            let planned: Vec<String> = c
                .fingers
                .iter()
                .map(|f| format!("{} {}", f.name, set(f, |f| f.planned_deg)))
                .collect();
            let closed: Vec<String> = c
                .fingers
                .iter()
                .map(|f| format!("{} {}", f.name, set(f, |f| f.final_deg)))
                .collect();
            let _ = writeln!(s, "    theta1/theta2 planned {} deg", planned.join(", "));
            let _ = writeln!(s, "    theta1/theta2 closed  {} deg", closed.join(", "));
        }
        if let Some(f) = &self.sim.fidelity {
            let _ = writeln!(s, "  Fidelity    {}", fidelity_line(f, &self.sim));
        }
    }

    /// The physics check in one line: the verdict, how far the object moved, the steps and
    /// time, and the payload margin when searched; or why it did not run.
    fn sim_line(&self) -> String {
        let sim = &self.sim;
        match (&sim.verdict, sim.translation_mm) {
            (SimVerdict::NotRun { reason }, _) => format!("not run ({reason})"),
            (SimVerdict::Ran(verdict), Some(t)) => format!(
                "{verdict}: moved {:.2} mm and {:.2} deg relative to the palm {}; {} steps, {:.0} ms{}",
                t,
                sim.rotation_deg.unwrap_or(0.0),
                if *verdict == Verdict::Drop {
                    "by the end of the hold"
                } else {
                    "while held"
                },
                sim.steps.unwrap_or(0),
                sim.wall_ms.unwrap_or(0.0),
                match sim.payload_margin {
                    Some(m) if *verdict == Verdict::Hold => format!("; payload margin {m:.2}x"),
                    Some(_) => "; payload margin none (it does not hold its own weight)".to_string(),
                    None => String::new(),
                }
            ),
            (SimVerdict::Ran(verdict), None) => verdict.to_string(),
        }
    }

    /// Whether the expectations were met, or that none was given.
    fn write_expect(&self, s: &mut String) {
        if self.expect.is_given() {
            let met = match self.expect.met {
                Some(true) => "met",
                Some(false) => "NOT MET",
                None => "not judged",
            };
            let _ = writeln!(
                s,
                "  Expect      {}: {met} ({})",
                self.expect.outcome_name(),
                self.expect.details
            );
        } else {
            let _ = writeln!(s, "  Expect      none given: nothing judged");
        }
    }

    /// One plain sentence: which grasp, whether it held, and why not when it did not.
    pub fn result_sentence(&self) -> String {
        let p = &self.plan;
        let Some(g) = &p.grasp else {
            return format!(
                "no grasp found: {}",
                p.reason
                    .as_deref()
                    .unwrap_or("the planner found no feasible grasp")
            );
        };
        let grasp = format!(
            "grasp at approach {:.0} deg, Finger_1 index {} (Z {:.1} mm), palm pitch {} deg",
            g.approach_angle_deg,
            g.elevation_index,
            g.elevation_mm,
            fmt_signed(g.palm_pitch_deg, 1)
        );
        let sim = &self.sim;
        let moved = format!(
            "{:.2} mm and {:.2} deg relative to the palm",
            sim.translation_mm.unwrap_or(0.0),
            sim.rotation_deg.unwrap_or(0.0)
        );
        match &sim.verdict {
            SimVerdict::Ran(Verdict::Hold) => match sim.fidelity.as_ref().filter(|f| !f.as_planned)
            {
                None => format!("{grasp}: HELD under gravity (moved {moved})"),
                Some(f) => format!(
                    "{grasp}: HELD under gravity (moved {moved}), but NOT as planned ({}): \
                     command the closed joint angles",
                    reasons_words(f)
                ),
            },
            SimVerdict::Ran(Verdict::Slip) => format!(
                "{grasp}: NOT held: the object slipped {moved}, beyond the hold limits{}, but \
                 stayed in the hand",
                sim.limits.map_or(String::new(), |l| format!(
                    " ({} mm, {} deg)",
                    l.translation_mm, l.rotation_deg
                ))
            ),
            SimVerdict::Ran(Verdict::Drop) => {
                format!("{grasp}: NOT held: the object fell out of the hand (moved {moved})")
            }
            SimVerdict::NotRun { reason } => {
                format!("{grasp}; not checked in physics ({reason})")
            }
        }
    }
}

/// The reasons a closing left the plan, in words: "pushed 6.2 mm", "2 of 6 phalanges on plan",
/// "a finger 2.40 mm inside".
fn reasons_words(f: &Fidelity) -> String {
    let words: Vec<String> = f
        .reasons
        .iter()
        .map(|r| match r {
            FidelityReason::Pushed => format!("pushed {:.1} mm", f.shift_mm),
            FidelityReason::OffPlan => format!(
                "{} of {} phalanges on plan",
                f.phalanges_on_plan, f.phalanges
            ),
            FidelityReason::Penetrated => {
                format!("a finger {:.2} mm inside", f.penetration_mm)
            }
        })
        .collect();
    words.join(", ")
}

/// The summary's fidelity line (issue 55): whether the grasp the closing made is the one
/// planned, how far the closing took it from the plan, and each bound it crossed, e.g. "NOT as
/// planned: the closing took the object 6.2 mm and 1.3 deg from the plan (at most 5 mm);
/// 2 of 6 phalanges end on plan (at least 3); worst joint 12.0 deg short".
pub fn fidelity_line(f: &Fidelity, sim: &SimReport) -> String {
    let has = |r| f.reasons.contains(&r);
    let limits = sim.limits;
    let min_on_plan = sim.closing.as_ref().map(|c| c.min_on_plan);
    let mut s = format!(
        "{}: the closing took the object {:.1} mm and {:.1} deg from the plan",
        if f.as_planned {
            "as planned"
        } else {
            "NOT as planned"
        },
        f.shift_mm,
        f.turn_deg
    );
    if let (true, Some(l)) = (has(FidelityReason::Pushed), limits) {
        s += &format!(" (at most {} mm: max_closing_shift_mm)", l.closing_shift_mm);
    }
    s += &format!(
        "; {} of {} phalanges end on plan",
        f.phalanges_on_plan, f.phalanges
    );
    if let (true, Some(n)) = (has(FidelityReason::OffPlan), min_on_plan) {
        s += &format!(" (at least {n}: min_on_plan_fraction)");
    }
    let e = f.worst_joint_error_deg;
    s += &format!(
        "; worst joint {:.1} deg {}",
        e.abs(),
        if e < 0.0 { "short" } else { "past" }
    );
    if has(FidelityReason::Penetrated) {
        s += &format!(
            "; a finger ended {:.2} mm inside the object{}",
            f.penetration_mm,
            limits.map_or(String::new(), |l| format!(
                " (at most {} mm: max_penetration_mm)",
                l.penetration_mm
            ))
        );
    }
    if !f.as_planned && sim.verdict.verdict() == Some(Verdict::Hold) {
        s += "; the grasp that held is the closed one: command its joint angles";
    }
    s
}

/// The summary's closing line (issue 33): how far the closing pushed and turned the object,
/// which body touched first, and the joint furthest from its plan, e.g. "the closing pushed
/// the object 23.0 mm; finger_2 stopped 27.0 deg short of its plan".
pub fn closing_line(c: &ClosingOutcome) -> String {
    let mut s = format!(
        "the closing pushed the object {:.1} mm and turned it {:.1} deg{}",
        c.shift_mm,
        c.turn_deg,
        if c.pushed {
            format!(
                " (more than max_closing_shift_mm, {} mm: not as planned)",
                c.max_shift_mm
            )
        } else {
            String::new()
        }
    );
    if let Some((name, joint, e)) = c.worst_joint() {
        let how = if e < 0.0 { "short of" } else { "past" };
        s += &format!(
            "; {name} joint {joint} stopped {:.1} deg {how} its plan",
            e.abs()
        );
    }
    let phalanges = 2 * c.fingers.len();
    s += &format!(
        "; {} of {phalanges} phalanges end on the object within {} deg of their plan{}",
        c.phalanges_on_plan,
        crate::sim::protocol::WITHIN_PLAN_DEG,
        if c.off_plan {
            format!(" (fewer than {}: not as planned)", c.min_on_plan)
        } else {
            String::new()
        }
    );
    match &c.first_touch {
        Some(t) if t.phalanx == 0 => s += &format!("; the palm touched first, at {:.3} s", t.at_s),
        Some(t) => {
            s += &format!(
                "; {} phalanx {} touched first, at {:.3} s",
                t.body, t.phalanx, t.at_s
            )
        }
        None => s += "; nothing touched the object",
    }
    s
}

/// The hold probability in words, per direction, and the first failing sample with how to
/// replay it.
pub fn robust_line(r: &Robust) -> String {
    let dirs: Vec<String> = r
        .directions
        .iter()
        .map(|d| {
            format!(
                "{} {}/{}",
                direction_name(d.gravity),
                d.counts.hold,
                r.samples
            )
        })
        .collect();
    let mut line = r.in_words();
    if r.directions.len() > 1 {
        line.push_str(&format!("; per direction {}", dirs.join(", ")));
    }
    if let Some(f) = &r.first_failure {
        line.push_str(&format!(
            "; first failure: sample {} ({} under {}; replay with [sim] replay_sample = {})",
            f.sample,
            f.verdict,
            direction_name(f.gravity),
            f.sample
        ));
    }
    line
}

/// A perturbation in words.
fn replay_line(p: &Perturbation) -> String {
    let [x, y, z] = p.offset_mm;
    let [a, b, c] = p.rotation_deg;
    format!(
        "sample {}: object offset ({x:.2}, {y:.2}, {z:.2}) mm and turned ({a:.2}, {b:.2}, {c:.2}) deg relative to the hand; friction x{:.3}, mass x{:.3}, motor torque x{:.3}",
        p.sample, p.friction_scale, p.mass_scale, p.torque_scale
    )
}

/// `+X`, `-Z`, ... for an axis direction; the vector otherwise.
/// A gravity direction in words: `+X`, `-Z`, or its components.
pub fn direction_name(g: [f64; 3]) -> String {
    for (i, axis) in ["X", "Y", "Z"].iter().enumerate() {
        if g[i].abs() == 1.0 {
            return format!("{}{axis}", if g[i] > 0.0 { "+" } else { "-" });
        }
    }
    format!("({:.2}, {:.2}, {:.2})", g[0], g[1], g[2])
}

/// The summary's quality line: epsilon and volume, what they were computed from, and why
/// epsilon is 0 when it is.
fn quality_line(q: &crate::quality::Quality) -> String {
    let closure = if q.force_closure {
        "force closure".to_string()
    } else {
        format!(
            "not force closure: {}",
            q.note.as_deref().unwrap_or("the origin is not inside")
        )
    };
    let from = match q.source {
        "sim" => "at the end of closing",
        _ => "planned",
    };
    format!(
        "epsilon {:.3} ({closure}), volume {:.3e} (L1 grasp wrench space, {} cone edges, mu {}); {} {from}",
        q.epsilon,
        q.volume,
        q.cone_edges,
        q.friction,
        plural(q.contacts.len(), "contact")
    )
}

/// The first eight sorted palm indices with their elevations, and how many more there are;
/// `none` when there are none.
fn sorted_indices_head(p: &PlanReport) -> String {
    let head: Vec<String> = p
        .sorted_indices
        .iter()
        .take(8)
        .map(|&i| {
            format!(
                "{i} (Z {:.1})",
                p.index_elevation_mm.first + (i - 1) as f64 * p.index_elevation_mm.step
            )
        })
        .collect();
    let more = p.sorted_indices.len().saturating_sub(8);
    format!(
        "{}{}",
        if head.is_empty() {
            "none".to_string()
        } else {
            head.join(", ")
        },
        if more > 0 {
            format!(", ... {more} more")
        } else {
            String::new()
        }
    )
}

/// The chosen grasp as the thesis's Grasp Parameter Set: per finger its joint angles, the
/// approach, the palm pitch, Finger_1's elevation, and the palm pose.
fn write_grasp_parameter_set(s: &mut String, g: &GraspReport) {
    let _ = writeln!(s, "  Grasp Parameter Set:");
    let _ = writeln!(s, "    GraspCondition -> Passed");
    for f in &g.fingers {
        let _ = writeln!(
            s,
            "    {} -> theta1 = {:.1} deg  theta2 = {:.1} deg{}",
            capitalise(&f.name),
            f.theta1_deg,
            f.theta2_deg,
            if f.tip_contact { "  (tip contact)" } else { "" }
        );
    }
    let _ = writeln!(
        s,
        "    ApproachAngle = {:.0} deg  Palm_Pitch_Angle = {} deg",
        g.approach_angle_deg,
        fmt_signed(g.palm_pitch_deg, 1)
    );
    let _ = writeln!(
        s,
        "    Finger_1 Approach Elevation index = {}  Z = {:.1} mm",
        g.elevation_index, g.elevation_mm
    );
    let pp = &g.palm_pose;
    let _ = writeln!(
        s,
        "    Palm pose (original frame): position ({:.2}, {:.2}, {:.2}) mm, quaternion wxyz ({:.4}, {:.4}, {:.4}, {:.4})",
        pp.position_mm[0], pp.position_mm[1], pp.position_mm[2],
        pp.quaternion_wxyz[0], pp.quaternion_wxyz[1], pp.quaternion_wxyz[2], pp.quaternion_wxyz[3]
    );
}

/// `v` with `digits` decimals, without the sign of a value that rounds to zero ("-0.0").
pub fn fmt_signed(v: f64, digits: usize) -> String {
    let s = format!("{v:.digits$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// `name` with its first letter in upper case.
fn capitalise(name: &str) -> String {
    let mut c = name.chars();
    match c.next() {
        Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::fmt_signed;

    #[test]
    fn a_value_that_rounds_to_zero_has_no_sign() {
        assert_eq!(fmt_signed(-0.0, 2), "0.00");
        assert_eq!(fmt_signed(-0.004, 2), "0.00");
        assert_eq!(fmt_signed(-0.006, 2), "-0.01");
        assert_eq!(fmt_signed(7.25, 1), "7.2");
        assert_eq!(fmt_signed(-6.2, 1), "-6.2");
    }
}
