//! Seeing the grasp (`--report DIR`): the thesis's figures as SVG, the planned and simulated
//! scenes as binary glTF, and one self-contained HTML page.

pub mod figures;
pub mod glb;
pub mod html;
pub mod svg;
pub mod views;

use crate::hand::Hand;
use crate::mesh::Mesh;
use crate::plan::search::Grasp;
use crate::plan::GradedDomain;
use crate::report::RunReport;
use std::path::Path;

/// Where the physics check left the bodies (aligned frame, metres; the palm, phalanx 1 and 2 of
/// each finger, then the object).
#[derive(Clone, Copy)]
pub struct SimulatedPoses<'a> {
    /// At the end of the first gravity direction's hold.
    pub end: &'a [crate::sim::BodyPose],
    /// At the end of the closing, gravity still off.
    pub closed: &'a [crate::sim::BodyPose],
}

/// Writes every figure (`*.svg`) and `report.html` into `dir`; returns the figure names.
///
/// # Errors
/// The file that could not be written.
pub fn write_report(
    dir: &Path,
    report: &RunReport,
    graded: &GradedDomain,
    grasp: Option<&Grasp>,
    mesh: &Mesh,
    hand: &Hand,
    simulated: Option<SimulatedPoses>,
) -> Result<Vec<String>, crate::export::ExportError> {
    let closed = simulated.map(|s| s.closed);
    let simulated = simulated.map(|s| s.end);
    let err = |path: &Path, e: std::io::Error| crate::export::ExportError {
        path: path.to_path_buf(),
        source: e,
    };
    std::fs::create_dir_all(dir).map_err(|e| err(dir, e))?;
    let mut figs: Vec<(String, String)> = vec![
        (
            "effective_elevation".to_string(),
            figures::effective_elevation(graded),
        ),
        (
            "grades_curvature".to_string(),
            figures::grades(graded, "curvature"),
        ),
        (
            "grades_diameter".to_string(),
            figures::grades(graded, "diameter"),
        ),
        (
            "grades_combined".to_string(),
            figures::grades(graded, "combined"),
        ),
        ("grades_palm".to_string(), figures::grades(graded, "palm")),
    ];
    if grasp.is_none() {
        figs.push(("rejections".to_string(), figures::rejections(report)));
    }
    if let Some(g) = grasp {
        figs.push(("palm".to_string(), figures::palm(g, hand)));
        figs.push(("finger_planes".to_string(), figures::finger_planes(g, hand)));
        for (k, f) in hand.finger_list.iter().enumerate() {
            figs.push((
                format!("finger_{}", f.name.trim_start_matches("finger_")),
                figures::finger(g, hand, mesh, k),
            ));
        }
    }
    for (name, svg) in &figs {
        let path = dir.join(format!("{name}.svg"));
        std::fs::write(&path, svg).map_err(|e| err(&path, e))?;
    }
    // The three views of the grasp (issue 33): planned and closed hand over the object.
    let mut view_figs: Vec<(String, String)> = Vec::new();
    let mut view_legend = String::new();
    // The planned hand's link poses, for the views and the planned glTF scene alike.
    let planned = grasp.map(|g| {
        let theta: Vec<[f64; 2]> = g
            .fingers
            .iter()
            .map(|f| [f.centre.theta1_deg, f.centre.theta2_deg])
            .collect();
        glb::planned_poses(hand, &g.palm.origin, &g.palm.axes, &theta)
    });
    if let Some(planned) = &planned {
        let scene = views::Scene {
            mesh,
            hand,
            planned,
            closed: closed.filter(|c| c.len() == planned.len() + 1),
            shift: report
                .sim
                .closing
                .as_ref()
                .map(|c| (c.shift_mm, c.turn_deg)),
        };
        view_legend = views::page_legend(&scene);
        view_figs = views::render(&scene);
    }
    for (name, svg) in &view_figs {
        let path = dir.join(format!("{name}.svg"));
        std::fs::write(&path, svg).map_err(|e| err(&path, e))?;
    }
    let mut scenes: Vec<&str> = Vec::new();
    if let Some(planned) = &planned {
        let mut bodies = glb::hand_bodies(hand, planned);
        bodies.push(glb::object_body(
            mesh,
            nalgebra::Vector3::zeros(),
            nalgebra::UnitQuaternion::identity(),
        ));
        let path = dir.join("grasp_planned.glb");
        std::fs::write(&path, glb::glb(&bodies)).map_err(|e| err(&path, e))?;
        scenes.push("grasp_planned.glb");
        if let Some(poses) = simulated.filter(|p| p.len() == planned.len() + 1) {
            let mut bodies = glb::hand_bodies(hand, &poses[..planned.len()]);
            let (t, r) = poses[planned.len()];
            bodies.push(glb::object_body(mesh, t, r));
            let path = dir.join("grasp_simulated.glb");
            std::fs::write(&path, glb::glb(&bodies)).map_err(|e| err(&path, e))?;
            scenes.push("grasp_simulated.glb");
        }
    }
    // A re-run into an old folder must not leave a scene (or a figure) this run did not make.
    let written: Vec<String> = figs
        .iter()
        .chain(&view_figs)
        .map(|(n, _)| format!("{n}.svg"))
        .collect();
    for stale in [
        "grasp_planned.glb",
        "grasp_simulated.glb",
        "palm.svg",
        "finger_planes.svg",
        "finger_1.svg",
        "finger_2.svg",
        "finger_3.svg",
        "rejections.svg",
        "view_top.svg",
        "view_side.svg",
        "view_oblique.svg",
    ] {
        let path = dir.join(stale);
        let made = written.iter().any(|w| w == stale) || scenes.contains(&stale);
        if !made && path.exists() {
            std::fs::remove_file(&path).map_err(|e| err(&path, e))?;
        }
    }
    let path = dir.join("report.html");
    let page = html::page(report, &figs, &scenes, (&view_figs, &view_legend));
    std::fs::write(&path, page).map_err(|e| err(&path, e))?;
    Ok(figs.into_iter().chain(view_figs).map(|(n, _)| n).collect())
}
