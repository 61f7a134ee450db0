//! Seeing the grasp (`--report DIR`): the thesis's figures as SVG, the planned and simulated
//! scenes as binary glTF, and one self-contained HTML page.

pub mod figures;
pub mod glb;
pub mod html;
pub mod svg;
pub mod views;

use crate::export::ExportError;
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
) -> Result<Vec<String>, ExportError> {
    let closed = simulated.map(|s| s.closed);
    let simulated = simulated.map(|s| s.end);
    std::fs::create_dir_all(dir).map_err(|e| export_error(dir, e))?;
    let figs = stage_figures(report, graded, grasp, mesh, hand);
    write_svgs(dir, &figs)?;
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
    write_svgs(dir, &view_figs)?;
    let scenes = match &planned {
        Some(planned) => write_scenes(dir, mesh, hand, planned, simulated)?,
        None => Vec::new(),
    };
    let written: Vec<String> = figs
        .iter()
        .chain(&view_figs)
        .map(|(n, _)| format!("{n}.svg"))
        .collect();
    remove_stale(dir, &written, &scenes)?;
    let path = dir.join("report.html");
    let page = html::page(report, &figs, &scenes, (&view_figs, &view_legend));
    crate::files::write_replacing(&path, page.as_bytes()).map_err(|e| export_error(&path, e))?;
    Ok(figs.into_iter().chain(view_figs).map(|(n, _)| n).collect())
}

/// The error of writing `path`.
fn export_error(path: &Path, e: std::io::Error) -> ExportError {
    ExportError {
        path: path.to_path_buf(),
        error: e,
    }
}

/// The stage figures, named: the Effective Elevation and the four grades; then the palm, the
/// finger planes and each finger for a grasp, or the rejections without one.
fn stage_figures(
    report: &RunReport,
    graded: &GradedDomain,
    grasp: Option<&Grasp>,
    mesh: &Mesh,
    hand: &Hand,
) -> Vec<(String, String)> {
    let mut figs: Vec<(String, String)> = vec![(
        "effective_elevation".to_string(),
        figures::effective_elevation(graded),
    )];
    for which in ["curvature", "diameter", "combined", "palm"] {
        figs.push((format!("grades_{which}"), figures::grades(graded, which)));
    }
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
    figs
}

/// Writes each figure as `dir/<name>.svg`.
fn write_svgs(dir: &Path, figs: &[(String, String)]) -> Result<(), ExportError> {
    for (name, svg) in figs {
        let path = dir.join(format!("{name}.svg"));
        crate::files::write_replacing(&path, svg.as_bytes()).map_err(|e| export_error(&path, e))?;
    }
    Ok(())
}

/// Writes the planned glTF scene and, when the physics check left every body's pose, the
/// simulated one; returns their file names.
fn write_scenes(
    dir: &Path,
    mesh: &Mesh,
    hand: &Hand,
    planned: &[crate::sim::BodyPose],
    simulated: Option<&[crate::sim::BodyPose]>,
) -> Result<Vec<&'static str>, ExportError> {
    let mut scenes = Vec::new();
    let mut bodies = glb::hand_bodies(hand, planned);
    bodies.push(glb::object_body(
        mesh,
        nalgebra::Vector3::zeros(),
        nalgebra::UnitQuaternion::identity(),
    ));
    let path = dir.join("grasp_planned.glb");
    crate::files::write_replacing(&path, &glb::glb(&bodies)).map_err(|e| export_error(&path, e))?;
    scenes.push("grasp_planned.glb");
    if let Some(poses) = simulated.filter(|p| p.len() == planned.len() + 1) {
        let mut bodies = glb::hand_bodies(hand, &poses[..planned.len()]);
        let (t, r) = poses[planned.len()];
        bodies.push(glb::object_body(mesh, t, r));
        let path = dir.join("grasp_simulated.glb");
        crate::files::write_replacing(&path, &glb::glb(&bodies))
            .map_err(|e| export_error(&path, e))?;
        scenes.push("grasp_simulated.glb");
    }
    Ok(scenes)
}

/// Removes the figures and scenes an earlier run left in `dir` that this run did not make
/// (`written` figures, `scenes`): a re-run into an old folder must not show them.
fn remove_stale(dir: &Path, written: &[String], scenes: &[&str]) -> Result<(), ExportError> {
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
            std::fs::remove_file(&path).map_err(|e| export_error(&path, e))?;
        }
    }
    Ok(())
}
