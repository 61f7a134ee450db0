//! grasp-sim: kinematic enveloping grasp planning for a three-fingered hand, after S. Salimi's
//! thesis "Kinematic Enveloping Grasp Planning Method for Robotic Dexterous Hands and
//! Three-Dimensional Objects" (McMaster University), checked in a rapier3d physics scene.
//!
//! Data flow (each stage a plain function, so tests, benches and the tuner can call one alone):
//!
//! ```text
//! scenario.toml → scenario::Scenario → prepared::PreparedObject (mesh::load_mesh, mass, collider)
//!   → select::select: for each rule set (thesis, extended, pinch) and axis: mesh::align →
//!     plan (stages 1–3 on slice::slice, then the search) → each candidate's sim check
//!   → quality (optional) → report::RunReport (JSON, summary; expectations judged)
//! ```
//!
//! Units: the mesh, slicer and planner work in millimetres and degrees in the aligned object frame
//! (principal axis +Z, bottom at Z = 0), as the thesis does; the physics check works in SI units,
//! converted once at its boundary ([`sim::convert`]).
//!
//! Math types: the planner uses nalgebra (f64). rapier3d 0.36 and parry3d 0.31 use glam types
//! (`Vec3`, `Pose3`, f32 by default); the conversion between the two lives in [`sim::convert`],
//! the only module that knows both.

#![warn(missing_docs)]

pub mod batch;
pub mod export;
pub mod hand;
pub mod mesh;
mod messages;
pub mod objects;
pub mod plan;
pub mod prepared;
pub mod quality;
pub mod report;
pub mod scenario;
pub mod select;
pub mod sim;
pub mod slice;
pub mod summarize;
pub mod tune;
pub mod visual;

use prepared::PreparedObject;
use report::{
    ExpectReport, GradesReport, GraspSource, IndexScale, ObjectReport, PlanReport, PlanStatus,
    PoseReport, RunReport, SimReport, SimVerdict, StageTimings,
};
use scenario::Scenario;
use std::collections::BTreeMap;

/// Any error that stops a scenario from running: bad input, never a grasp outcome.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A bad scenario or hand file.
    #[error(transparent)]
    Scenario(#[from] scenario::ScenarioError),
    /// A bad mesh file.
    #[error(transparent)]
    Mesh(#[from] mesh::MeshError),
    /// An export could not be written.
    #[error(transparent)]
    Export(#[from] export::ExportError),
}

/// How to run a scenario.
#[derive(Clone)]
pub struct RunOptions {
    /// Skip the physics check.
    pub no_sim: bool,
    /// Find the payload margin by bisection (several more physics runs).
    pub payload: bool,
    /// Compute the analytic grasp quality of every grasp reported (`quality`, docs/QUALITY.md):
    /// a 6-D convex hull per grasp, so off by default.
    pub quality: bool,
    /// How many feasible grasps to collect, in search order (the thesis stops at 1).
    pub candidates: usize,
    /// With the physics check: check candidates in search order until one holds or this many
    /// have been checked (`None`: the scenario's `[sim] max_checked`).
    pub max_checked: Option<usize>,
    /// Write the planned grasp as an MJCF scene into this folder (a subfolder per scenario).
    pub export_mjcf: Option<std::path::PathBuf>,
    /// Write the hand as URDF into this folder (a subfolder per scenario).
    pub export_urdf: Option<std::path::PathBuf>,
    /// Write figures, 3D scenes and report.html into this folder (a subfolder per scenario).
    pub report: Option<std::path::PathBuf>,
    /// The name of the subfolder of `report`, `export_mjcf` and `export_urdf` (`None`: the
    /// scenario's name).
    pub folder: Option<String>,
}

/// Candidates the physics check runs on at most before a run settles for the best it saw.
pub const DEFAULT_MAX_CHECKED: usize = 8;

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            no_sim: false,
            payload: false,
            quality: false,
            candidates: 1,
            max_checked: None,
            export_mjcf: None,
            export_urdf: None,
            report: None,
            folder: None,
        }
    }
}

/// Everything but `folder`, as a derived `Debug` would write it: a batch's input hash is this
/// text (`batch::input_hash`), and where the outputs go does not change what is computed, so
/// results files written before `folder` existed still resume.
impl std::fmt::Debug for RunOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunOptions")
            .field("no_sim", &self.no_sim)
            .field("payload", &self.payload)
            .field("quality", &self.quality)
            .field("candidates", &self.candidates)
            .field("max_checked", &self.max_checked)
            .field("export_mjcf", &self.export_mjcf)
            .field("export_urdf", &self.export_urdf)
            .field("report", &self.report)
            .finish()
    }
}

impl RunOptions {
    /// The subfolder of the output folders for `scenario`.
    pub fn folder_for<'a>(&'a self, scenario: &'a Scenario) -> &'a str {
        self.folder.as_deref().unwrap_or(&scenario.name)
    }
}

/// Runs a scenario: prepares its object, plans (choosing among candidates with the physics
/// check when it runs), checks the chosen grasp, judges `[expect]` and writes what `options`
/// ask for.
///
/// # Errors
/// [`Error`] for a bad mesh file or an export that cannot be written.
pub fn run(scenario: &Scenario, options: &RunOptions) -> Result<RunReport, Error> {
    let mut timings = StageTimings::default();
    let object = PreparedObject::load(&scenario.object, &mut timings)?;
    let selection = select_grasps(scenario, options, &object, &mut timings);
    let qualities = qualities(scenario, options, &selection);
    let plan = plan_report(scenario, &selection, &qualities, timings);
    let chosen = selection.chosen();
    let checked_on = chosen.map_or(&object.aligned, |c| &selection.axes[c.axis_plan].aligned);
    let mut mjcf_scene = None;
    let (sim, sim_poses, ran) = run_sim(
        scenario,
        options,
        &object,
        (checked_on, &selection.axes[0].graded),
        chosen.map(|c| (&c.grasp, c.check.clone())),
        &mut mjcf_scene,
    )?;
    // A check that ran here (not in the candidate search: `override_angles`) closed its own
    // grip: the quality is that grip's, not the planned contacts'.
    let quality = match (&ran, options.quality) {
        (Some(out), true) => Some(quality::of_check(
            checked_on,
            out,
            &scenario.hand,
            scenario.object.friction,
        )),
        _ => selection.chosen.and_then(|i| qualities[i].clone()),
    };
    let expect = match &scenario.expect {
        Some(e) => ExpectReport::judge(e, &plan, &sim),
        None => ExpectReport::none(),
    };
    let shown = selection.reported_axis();
    let report = RunReport {
        scenario: scenario.name.clone(),
        object: object_report(scenario, &object),
        warnings: warnings(
            scenario,
            &object,
            &shown.graded,
            plan.open_slices,
            plan.status == PlanStatus::Ungraspable,
        ),
        plan,
        sim,
        expect,
        quality,
        mjcf_scene,
    };
    if let Some(dir) = &options.report {
        visual::write_report(
            &dir.join(options.folder_for(scenario)),
            &report,
            &shown.graded,
            chosen.map(|c| &c.grasp),
            &shown.aligned.mesh,
            &scenario.hand,
            sim_poses
                .as_ref()
                .map(|(end, closed)| visual::SimulatedPoses { end, closed }),
        )?;
    }
    Ok(report)
}

/// Plans across axes and rule sets; with the physics check on the planner's grasps, checks
/// candidates until one holds (at most `max_checked`).
fn select_grasps(
    scenario: &Scenario,
    options: &RunOptions,
    object: &PreparedObject,
    timings: &mut StageTimings,
) -> select::Selection {
    let check = |a: &mesh::AlignedObject, g: &plan::search::Grasp| -> sim::SimOutcome {
        let shape = object.shape(a);
        let pose = sim::SimHand::from_grasp(g);
        sim::check(&object.case(scenario, &pose, &shape))
    };
    // The physics check chooses among candidates only when it runs on the planner's grasps.
    let checks_candidates = !options.no_sim && scenario.sim.input.override_angles.is_none();
    let max_checked = options
        .max_checked
        .unwrap_or(scenario.sim.selection.max_checked);
    select::select(
        object.mesh(),
        &object.props,
        &select::SelectParams {
            hand: &scenario.hand,
            planner: &scenario.planner,
            friction: scenario.object.friction,
            collect: options.candidates,
            max_checked: checks_candidates.then_some(max_checked.max(1)),
            check: &check,
            domains: None,
            frame: scenario.object.frame,
        },
        timings,
    )
}

/// The analytic quality of every candidate when `--quality` asks for it.
fn qualities(
    scenario: &Scenario,
    options: &RunOptions,
    selection: &select::Selection,
) -> Vec<Option<quality::Quality>> {
    selection
        .candidates
        .iter()
        .map(|c| {
            options.quality.then(|| {
                let aligned = &selection.axes[c.axis_plan].aligned;
                let (h, mu) = (&scenario.hand, scenario.object.friction);
                quality::of_grasp(&c.grasp, aligned, c.check.as_ref(), h, mu)
            })
        })
        .collect()
}

/// The `object` part of the report.
fn object_report(scenario: &Scenario, object: &PreparedObject) -> ObjectReport {
    let aligned = &object.aligned;
    let axis = aligned.principal_axis_original();
    let c = aligned.original.centroid;
    let q = aligned.to_aligned.rotation;
    let tr = aligned.to_aligned.translation.vector;
    ObjectReport {
        mesh: scenario.object.mesh.display().to_string(),
        triangles: object.mesh().triangles.len(),
        volume_mm3: object.volume_mm3(),
        principal_axis: [axis.x, axis.y, axis.z],
        height_mm: aligned.height_mm,
        centroid_mm: [c.x, c.y, c.z],
        mass_kg: object.mass_kg,
        degenerate_dropped: object.loaded.degenerate_dropped,
        boundary_edges: object.loaded.topology.boundary_edges,
        to_aligned: PoseReport {
            position_mm: [tr.x, tr.y, tr.z],
            quaternion_wxyz: [q.w, q.i, q.j, q.k],
        },
    }
}

/// The input's warnings: the loader's, open vertical slices of the axis reported and, for an
/// ungraspable object small for the hand, the unit that would make it hand-sized.
fn warnings(
    scenario: &Scenario,
    object: &PreparedObject,
    graded: &plan::GradedDomain,
    open_slices: usize,
    ungraspable: bool,
) -> Vec<String> {
    object
        .loaded
        .warnings()
        .into_iter()
        .chain(
            ungraspable
                .then(|| object.loaded.small_object_hint(graded.range.min_mm))
                .flatten(),
        )
        .chain((open_slices > 0).then(|| {
            format!(
                "{open_slices} of {} vertical slices stay open after joining their ends: \
                 the planner uses their pieces as they are",
                graded.domain.slices.len()
            )
        }))
        .map(|w| format!("{}: {w}", scenario.object.mesh.display()))
        .collect()
}

/// The `plan` part of the report.
fn plan_report(
    scenario: &Scenario,
    selection: &select::Selection,
    qualities: &[Option<quality::Quality>],
    timings: StageTimings,
) -> PlanReport {
    let graded = &selection.reported_axis().graded;
    let all_grasps: Vec<report::GraspReport> = selection
        .candidates
        .iter()
        .zip(qualities)
        .map(|(c, q)| report::GraspReport {
            quality: q.as_ref().map(report::GraspQuality::of),
            ..grasp_report(
                &c.grasp,
                &selection.axes[c.axis_plan].aligned,
                c.check.as_ref(),
            )
        })
        .collect();
    let chosen_report = selection.chosen.map(|i| all_grasps[i].clone());
    let (status, reason) = if chosen_report.is_some() {
        (PlanStatus::Feasible, None)
    } else {
        (
            PlanStatus::Ungraspable,
            Some(ungraspable_reason(selection, &scenario.hand)),
        )
    };
    let g = &graded.grades;
    PlanReport {
        status,
        reason,
        effective_elevation_mm: graded.domain.effective,
        indexed_elevations: graded.domain.elevations.len(),
        index_elevation_mm: IndexScale {
            first: graded.domain.effective[0],
            step: graded.domain.height_step_mm,
        },
        sorted_indices: graded.sorted_indices.clone(),
        graspable_diameter_mm: graded.range.used(),
        graspable_diameter_basis: "kinematic".to_string(),
        thesis_largest_diameter_mm: graded.range.max_thesis_mm,
        largest_span_mm: graded.largest_span_mm,
        effective_diameter_mm: graded
            .diameters_mm
            .iter()
            .map(|d| d.is_finite().then_some(*d))
            .collect(),
        grades: GradesReport {
            curvature: g.curvature.clone(),
            diameter: g.diameter.clone(),
            combined: g.combined.clone(),
            palm: g.palm.clone(),
        },
        candidates_tried: selection.axes.iter().map(|a| a.candidates_tried).sum(),
        search_stopped: selection.budget_stops().map(|s| {
            format!(
                "candidate budget of {} per rule set reached on {s}",
                scenario.planner.candidate_budget
            )
        }),
        rejections: rejections(selection, &scenario.hand),
        grasp: chosen_report,
        grasps: if all_grasps.len() > 1 {
            all_grasps
        } else {
            Vec::new()
        },
        candidates_checked: selection.checked(),
        open_slices: graded
            .domain
            .slices
            .iter()
            .filter(|s| s.open_count() > 0)
            .count(),
        axes: selection.axes.iter().map(axis_report).collect(),
        timings_ms: timings,
    }
}

/// How often each constraint rejected a candidate, over every axis and rule set.
fn rejections(selection: &select::Selection, hand: &hand::Hand) -> BTreeMap<String, usize> {
    let mut all: BTreeMap<String, usize> = BTreeMap::new();
    for a in &selection.axes {
        for (r, n) in &a.rejections {
            *all.entry(r.describe(hand)).or_insert(0) += n;
        }
    }
    all
}

/// Writes the URDF and MJCF exports asked for, and runs the physics check on the chosen grasp
/// or on `override_angles` (pose from the thesis axis's `graded` domain). The outcome is
/// returned too when the check ran here rather than in the candidate search.
#[allow(clippy::type_complexity)]
fn run_sim(
    scenario: &Scenario,
    options: &RunOptions,
    object: &PreparedObject,
    (aligned, graded): (&mesh::AlignedObject, &plan::GradedDomain),
    grasp: Option<(&plan::search::Grasp, Option<sim::SimOutcome>)>,
    mjcf_scene: &mut Option<std::path::PathBuf>,
) -> Result<
    (
        SimReport,
        Option<(Vec<sim::BodyPose>, Vec<sim::BodyPose>)>,
        Option<sim::SimOutcome>,
    ),
    Error,
> {
    if let Some(dir) = &options.export_urdf {
        export::write_urdf(
            &dir.join(options.folder_for(scenario)),
            &scenario.hand,
            &scenario.sim,
        )?;
    }
    if options.no_sim && options.export_mjcf.is_none() {
        return Ok((SimReport::not_run("--no-sim"), None, None));
    }
    let p = &scenario.sim;
    let (pose, source, done) = match (&p.input.override_angles, grasp) {
        (Some(angles), _) => {
            match select::override_pose(
                &aligned.mesh,
                &scenario.hand,
                graded,
                p.input.override_index,
                angles,
            ) {
                Ok(pose) => (pose, GraspSource::OverrideAngles, None),
                Err(e) => return Ok((SimReport::not_run(&e.to_string()), None, None)),
            }
        }
        (None, Some((g, done))) => (sim::SimHand::from_grasp(g), GraspSource::Planner, done),
        (None, None) => return Ok((SimReport::not_run("no feasible grasp to check"), None, None)),
    };
    let shape = object.shape(aligned);
    let case = object.case(scenario, &pose, &shape);
    if let Some(dir) = &options.export_mjcf {
        let input = export::ExportInput {
            name: &scenario.name,
            object: aligned,
            case,
        };
        let folder = dir.join(options.folder_for(scenario));
        export::write_mjcf(&folder, &input)?;
        *mjcf_scene = Some(folder.join("scene.xml"));
    }
    if options.no_sim {
        return Ok((SimReport::not_run("--no-sim"), None, None));
    }
    // The candidate search already checked the chosen grasp: the same case, the same outcome.
    let (out, payload, ran) = match done {
        Some(out) => {
            let payload = (options.payload && out.verdict == sim::Verdict::Hold)
                .then(|| sim::payload_bracket(&case));
            (out, payload, false)
        }
        None => {
            let (out, payload) = sim::check_with_payload(&case, options.payload);
            (out, payload, true)
        }
    };
    let poses = (out.final_poses.clone(), out.closed_poses.clone());
    let ran = ran.then(|| out.clone());
    let report = checked_report(out, payload, &case, &shape, source, options);
    Ok((report, Some(poses), ran))
}

/// The `sim` report of a check that ran on `case` (with the payload bracket when asked for).
fn checked_report(
    out: sim::SimOutcome,
    payload: Option<(f64, Option<f64>)>,
    case: &sim::Case,
    shape: &sim::ObjectShape,
    source: GraspSource,
    options: &RunOptions,
) -> SimReport {
    SimReport {
        verdict: SimVerdict::Ran(out.verdict),
        translation_mm: Some(out.translation_mm),
        rotation_deg: Some(out.rotation_deg),
        simulated_s: Some(out.simulated_s),
        steps: Some(out.steps),
        wall_ms: Some(out.wall_ms),
        start: Some(sim::scene::start(case)),
        collider: Some(sim::ColliderReport::of(shape)),
        mass_kg: Some(case.mass_kg),
        grasp_source: Some(source),
        payload_margin: options
            .payload
            .then(|| payload.map_or(0.0, |(held, _)| held)),
        payload_fails_at: payload.and_then(|(_, failed)| failed),
        closing: Some(out.closing),
        directions: out.directions,
        limits: Some(report::HoldLimits {
            translation_mm: case.params.hold.hold_translation_mm,
            rotation_deg: case.params.hold.hold_rotation_deg,
            penetration_mm: case.params.hold.max_penetration_mm,
            closing_shift_mm: case.params.hold.max_closing_shift_mm,
        }),
    }
}

fn pose_report(
    origin: &nalgebra::Point3<f64>,
    rotation: &nalgebra::UnitQuaternion<f64>,
) -> PoseReport {
    PoseReport {
        position_mm: [origin.x, origin.y, origin.z],
        quaternion_wxyz: [rotation.w, rotation.i, rotation.j, rotation.k],
    }
}

/// Why no grasp was found: the thesis axis's reason under the thesis's rules, and what the
/// other axes and rules met.
fn ungraspable_reason(selection: &select::Selection, hand: &hand::Hand) -> String {
    let describe = |a: &select::AxisPlan| -> String {
        if let Some(r) = &a.graded.reason {
            return r.clone();
        }
        let mut counts: Vec<(String, usize)> = a
            .rejections
            .iter()
            .map(|(r, n)| (r.describe(hand), *n))
            .collect();
        counts.sort_by(|x, y| y.1.cmp(&x.1).then(x.0.cmp(&y.0)));
        let top: Vec<String> = counts
            .iter()
            .take(3)
            .map(|(d, n)| format!("{d} ({n})"))
            .collect();
        format!(
            "no kinematically feasible grasp in {} candidates; most rejected by: {}",
            a.candidates_tried,
            top.join(", ")
        )
    };
    let first = describe(&selection.axes[0]);
    let reason = match selection.axes.len() {
        1 => first,
        n => format!(
            "{first} (and no grasp in the {} other axis and rule combinations tried: `plan.axes` in --json)",
            n - 1
        ),
    };
    match selection.budget_stops() {
        None => reason,
        Some(_) => {
            let tried: usize = selection.axes.iter().map(|a| a.candidates_tried).sum();
            let stopped = selection.axes.iter().filter(|a| a.budget_stopped).count();
            format!(
                "{reason}; the search stopped at its candidate budget on {stopped} of them \
                 ({tried} candidates tried in all: `plan.search_stopped`)"
            )
        }
    }
}

fn axis_report(a: &select::AxisPlan) -> report::AxisReport {
    let v = a.aligned.principal_axis_original();
    report::AxisReport {
        axis: [v.x, v.y, v.z],
        axis_name: a.aligned.axis.name(),
        rules: a.rules,
        pinch: a.rules == plan::RuleSet::Pinch,
        indexed_elevations: a.graded.domain.elevations.len(),
        sorted_indices: a.graded.sorted_indices.len(),
        candidates_tried: a.candidates_tried,
        candidates_available: a.candidates_available,
        budget_stopped: a.budget_stopped,
        grasps_found: a.grasps_found,
        reason: (a.grasps_found == 0).then(|| {
            a.graded
                .reason
                .clone()
                .unwrap_or_else(|| "every candidate rejected".to_string())
        }),
    }
}

fn grasp_report(
    g: &plan::search::Grasp,
    aligned: &mesh::AlignedObject,
    check: Option<&sim::SimOutcome>,
) -> report::GraspReport {
    let r_aligned = hand::palm_rotation(&g.palm.axes);
    let r_original = aligned.to_aligned.rotation.inverse() * r_aligned;
    let als = |a: &plan::finger::AlsAngles| [a.theta1_deg, a.theta2_deg];
    report::GraspReport {
        approach_angle_deg: g.approach_angle_deg,
        palm_pitch_deg: g.palm.pitch_rad.to_degrees(),
        elevation_index: g.elevation_index,
        elevation_mm: g.elevation_mm,
        palm_pose: pose_report(&aligned.to_original(&g.palm.origin), &r_original),
        palm_pose_aligned: pose_report(&g.palm.origin, &r_aligned),
        fingers: g
            .fingers
            .iter()
            .map(|f| report::FingerReport {
                name: f.name.clone(),
                theta1_deg: f.centre.theta1_deg,
                theta2_deg: f.centre.theta2_deg,
                als: report::AlsReport {
                    top: als(&f.top),
                    centre: als(&f.centre),
                    bottom: als(&f.bottom),
                },
                tip_contact: f.centre.is_tip_contact,
            })
            .collect(),
        axis: {
            let v = aligned.principal_axis_original();
            [v.x, v.y, v.z]
        },
        axis_name: aligned.axis.name(),
        rules: g.rules,
        relaxations: g.relaxations.clone(),
        check: check.map(|o| report::CandidateCheck {
            verdict: o.verdict,
            translation_mm: o.translation_mm,
            rotation_deg: o.rotation_deg,
        }),
        quality: None,
    }
}
