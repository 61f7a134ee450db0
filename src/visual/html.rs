//! report.html: one self-contained page (figures inline, no scripts, fonts or network).

use crate::report::{GraspReport, RunReport, SimVerdict};

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The physics check in words: its verdict and numbers, or why it did not run.
fn verdict_sentence(report: &RunReport) -> String {
    let sim = &report.sim;
    let word = match &sim.verdict {
        SimVerdict::NotRun { .. } => "not run",
        SimVerdict::Ran(v) => v.as_str(),
    };
    let closing = sim
        .closing
        .as_ref()
        .map(|c| format!(". Closing: {}", crate::report::closing_line(c)))
        .unwrap_or_default();
    let sentence = match (sim.translation_mm, sim.rotation_deg) {
        (Some(t), Some(r)) => format!(
            "Physics check: {word} (moved {t:.2} mm and {r:.2} deg relative to the palm under gravity{})",
            sim.payload_margin
                .map(|m| format!("; payload margin {m:.2}x"))
                .unwrap_or_default()
        ),
        _ => match sim.verdict.reason() {
            Some(why) => format!("Physics check: {word} ({why})"),
            None => format!("Physics check: {word}"),
        },
    };
    sentence + &closing
}

/// The Grasp Parameter Set as a table (thesis 3.7), or the reason there is none.
fn parameter_set(report: &RunReport) -> String {
    let p = &report.plan;
    let Some(g) = &p.grasp else {
        return format!(
            "<p>No grasp: {}</p>",
            esc(p
                .reason
                .as_deref()
                .unwrap_or("the planner found no feasible grasp"))
        );
    };
    // The closed set beside the planned one (issue 33): the angles the closing reached.
    let closing = report.sim.closing.as_ref();
    let cols = if closing.is_some() { 5 } else { 3 };
    let mut s = format!(
        "<table class=\"gps\"><tr><th>Grasp condition</th><td colspan=\"{cols}\">Passed</td></tr>"
    );
    s.push_str("<tr><th>Finger</th><th>theta1 [deg]</th><th>theta2 [deg]</th><th>contact</th>");
    if closing.is_some() {
        s.push_str("<th>closed theta1 [deg]</th><th>closed theta2 [deg]</th>");
    }
    s.push_str("</tr>");
    s.push_str(&finger_rows(g, closing));
    for (k, v) in pose_rows(g) {
        s.push_str(&format!(
            "<tr><th>{}</th><td colspan=\"{cols}\">{}</td></tr>",
            esc(k),
            esc(&v)
        ));
    }
    s.push_str("</table>");
    s
}

/// One table row per finger: its name, planned joint angles and contact, and with the
/// `closing` the angles it closed to.
fn finger_rows(g: &GraspReport, closing: Option<&crate::report::ClosingOutcome>) -> String {
    let mut s = String::new();
    for (k, f) in g.fingers.iter().enumerate() {
        s.push_str(&format!(
            "<tr><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{}</td>",
            esc(&f.name),
            f.theta1_deg,
            f.theta2_deg,
            if f.tip_contact { "tip" } else { "phalanx" }
        ));
        if let Some(c) = closing {
            match c.fingers.get(k) {
                Some(fc) => s.push_str(&format!(
                    "<td>{:.1}</td><td>{:.1}</td>",
                    fc.final_deg[0], fc.final_deg[1]
                )),
                None => s.push_str("<td></td><td></td>"),
            }
        }
        s.push_str("</tr>");
    }
    s
}

/// The table's rows after the fingers: approach, pitch, elevation, axis and rules, palm pose.
fn pose_rows(g: &GraspReport) -> [(&'static str, String); 6] {
    let pp = &g.palm_pose;
    [
        ("Approach angle", format!("{:.0} deg", g.approach_angle_deg)),
        (
            "Palm pitch angle",
            format!("{} deg", crate::report::fmt_signed(g.palm_pitch_deg, 1)),
        ),
        (
            "Finger_1 approach elevation",
            format!("index {}, Z = {:.1} mm", g.elevation_index, g.elevation_mm),
        ),
        (
            "Axis, rules",
            format!("{} ({})", g.axis_name, g.one_line_rules()),
        ),
        (
            "Palm position (original frame)",
            format!(
                "({:.2}, {:.2}, {:.2}) mm",
                pp.position_mm[0], pp.position_mm[1], pp.position_mm[2]
            ),
        ),
        (
            "Palm rotation (quaternion wxyz)",
            format!(
                "({:.4}, {:.4}, {:.4}, {:.4})",
                pp.quaternion_wxyz[0],
                pp.quaternion_wxyz[1],
                pp.quaternion_wxyz[2],
                pp.quaternion_wxyz[3]
            ),
        ),
    ]
}

/// The page for one scenario's run: the verdict in words, the Grasp Parameter Set as a table,
/// links to the 3D scenes written (`scenes`), the full summary, and every figure, inline.
///
/// `views` are the three rendered views of the grasp (`view_*.svg`) and their one-line legend,
/// shown first, after the verdict.
pub fn page(
    report: &RunReport,
    figures: &[(String, String)],
    scenes: &[&str],
    views: (&[(String, String)], &str),
) -> String {
    let mut s = String::new();
    s.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
    s.push_str(&format!(
        "<title>grasp-sim: {}</title>",
        esc(&report.scenario)
    ));
    s.push_str(
        "<style>body{font-family:sans-serif;margin:24px;max-width:1400px}\
         pre{background:#f4f4f4;padding:12px;white-space:pre-wrap}\
         table.gps{border-collapse:collapse;margin-bottom:12px}\
         table.gps th,table.gps td{border:1px solid #ccc;padding:4px 10px;text-align:left}\
         table.gps th{background:#f4f4f4}\
         .figs{display:flex;flex-wrap:wrap;gap:16px}.fig{border:1px solid #ccc;padding:4px}\
         .verdict{font-size:20px;font-weight:bold}</style></head><body>",
    );
    s.push_str(&headline(report));
    let (view_figs, legend) = views;
    if !view_figs.is_empty() {
        s.push_str("<h2>The grasp in three views</h2><div class=\"figs\">");
        for (name, svg) in view_figs {
            s.push_str(&format!("<div class=\"fig\" id=\"{}\">", esc(name)));
            s.push_str(svg);
            s.push_str("</div>");
        }
        s.push_str(&format!("</div><p class=\"legend\">{}</p>", esc(legend)));
    }
    s.push_str("<h2>Grasp Parameter Set</h2>");
    s.push_str(&parameter_set(report));
    s.push_str(&scene_links(scenes));
    s.push_str("<details><summary>Full summary</summary><pre>");
    s.push_str(&esc(&report.summary()));
    s.push_str("</pre></details><h2>Figures</h2><div class=\"figs\">");
    for (name, svg) in figures {
        s.push_str(&format!("<div class=\"fig\" id=\"{}\">", esc(name)));
        s.push_str(svg);
        s.push_str("</div>");
    }
    s.push_str("</div></body></html>\n");
    s
}

/// The page's heading, the verdict in words, and the plan's status with the expectation.
fn headline(report: &RunReport) -> String {
    let mut s = String::new();
    s.push_str(&format!("<h1>grasp-sim: {}</h1>", esc(&report.scenario)));
    s.push_str(&format!(
        "<p class=\"verdict\">{}</p>",
        esc(&verdict_sentence(report))
    ));
    if let Some(f) = &report.sim.fidelity {
        s.push_str(&format!(
            "<p class=\"verdict\">Fidelity: {}</p>",
            esc(&crate::report::summary::fidelity_line(f, &report.sim))
        ));
    }
    if let Some(r) = &report.sim.robust {
        s.push_str(&format!(
            "<p class=\"verdict\">Hold probability {:.2}: {}</p>",
            r.hold_probability,
            esc(&crate::report::summary::robust_line(r))
        ));
    }
    s.push_str(&format!(
        "<p>Plan: {}; {}</p>",
        esc(report.plan.status.as_str()),
        if report.expect.is_given() {
            format!(
                "expected outcome {}: {}",
                esc(report.expect.outcome_name()),
                match report.expect.met {
                    Some(true) => "met",
                    Some(false) => "NOT met",
                    None => "not judged",
                }
            )
        } else {
            "no expectation given: nothing judged".to_string()
        }
    ));
    s
}

/// The links to the 3D scenes written, each saying what it shows; or that there are none.
fn scene_links(scenes: &[&str]) -> String {
    if scenes.is_empty() {
        "<p>3D scenes: none (no grasp to show).</p>".to_string()
    } else {
        let links: Vec<String> = scenes
            .iter()
            .map(|f| {
                let what = if *f == "grasp_simulated.glb" {
                    "where the physics check left the bodies"
                } else {
                    "the planned grasp"
                };
                format!("<a href=\"{f}\">{f}</a> ({what})")
            })
            .collect();
        format!(
            "<p>3D scenes: {}; they open in any glTF viewer.</p>",
            links.join(", ")
        )
    }
}
