//! report.html: one self-contained page (figures inline, no scripts, fonts or network).

use crate::report::RunReport;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The page for one scenario's run: the summary (Grasp Parameter Set, physics verdict and its
/// numbers) and every figure, inline.
pub fn page(report: &RunReport, figures: &[(String, String)]) -> String {
    let mut s = String::new();
    s.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
    s.push_str(&format!(
        "<title>grasp-sim: {}</title>",
        esc(&report.scenario)
    ));
    s.push_str(
        "<style>body{font-family:sans-serif;margin:24px;max-width:1400px}\
         pre{background:#f4f4f4;padding:12px;white-space:pre-wrap}\
         .figs{display:flex;flex-wrap:wrap;gap:16px}.fig{border:1px solid #ccc;padding:4px}\
         .verdict{font-size:20px;font-weight:bold}</style></head><body>",
    );
    s.push_str(&format!("<h1>grasp-sim: {}</h1>", esc(&report.scenario)));
    let sim = &report.sim;
    let verdict = match (sim.translation_mm, sim.rotation_deg) {
        (Some(t), Some(r)) => format!(
            "Physics check: {} (moved {t:.2} mm and {r:.2} deg relative to the palm under gravity{})",
            sim.verdict,
            sim.payload_margin
                .map(|m| format!("; payload margin {m:.2}x"))
                .unwrap_or_default()
        ),
        _ => format!("Physics check: {}", sim.verdict),
    };
    s.push_str(&format!("<p class=\"verdict\">{}</p>", esc(&verdict)));
    s.push_str(&format!(
        "<p>Plan: {}; expected outcome {}: {}</p>",
        esc(&report.plan.status),
        esc(&report.expect.outcome),
        match report.expect.met {
            Some(true) => "met",
            Some(false) => "NOT met",
            None => "not judged",
        }
    ));
    s.push_str("<h2>Grasp Parameter Set</h2><pre>");
    s.push_str(&esc(&report.summary()));
    s.push_str("</pre><h2>Figures</h2><div class=\"figs\">");
    for (name, svg) in figures {
        s.push_str(&format!("<div class=\"fig\" id=\"{}\">", esc(name)));
        s.push_str(svg);
        s.push_str("</div>");
    }
    s.push_str("</div><p>3D scenes: grasp_planned.glb (the planned grasp) and grasp_simulated.glb \
                (where the physics check left the bodies), in this folder; they open in any glTF viewer.</p>");
    s.push_str("</body></html>\n");
    s
}
