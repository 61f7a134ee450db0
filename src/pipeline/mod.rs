//! Running one input, end to end: the one place that turns a scenario into its report, used by
//! the command line ([`inputs`]), `batch` and the Python-free library API alike.
//!
//! [`compute`] prepares the object, plans (choosing among candidates with the physics check when
//! it runs), checks the chosen grasp and judges `[expect]`; it writes nothing. [`write_outputs`]
//! writes what the options ask for (`--export-urdf`, `--export-mjcf`, `--report`) from what was
//! computed. [`run`] is the two in turn.

mod build;
pub mod input;
pub mod inputs;

use crate::prepared::PreparedObject;
use crate::report::{ExpectReport, GraspSource, PlanStatus, RunReport, SimReport, StageTimings};
use crate::scenario::Scenario;
use crate::{export, mesh, plan, quality, scenario, select, sim, visual};

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
    /// A grasp given to check ([`RunOptions::given`]) that cannot be posed.
    #[error("given grasp: {0}")]
    Given(String),
    /// An output folder's name (a scenario's `name`) that would not stay inside the folder
    /// given (`../x`, an absolute path, NUL): nothing is written.
    #[error("{dir}: the run's name {name:?} {problem}: not a folder name inside it, nothing written", dir = .dir.display())]
    OutputName {
        /// The output folder given.
        dir: std::path::PathBuf,
        /// The name.
        name: String,
        /// What is wrong with it ([`crate::files::folder_name_problem`]).
        problem: String,
    },
}

/// A grasp given from outside the planner, to check as it is: a learned model's, another
/// candidate's, a hand-made one. The palm pose is in the object's file frame, as the JSON's
/// `plan.grasp.palm_pose`; the angles are `[θ1, θ2]` per finger in the hand's order.
#[derive(Debug, Clone, PartialEq)]
pub struct GivenGrasp {
    /// Palm centre on its contact surface, object file frame `[mm]`.
    pub position_mm: [f64; 3],
    /// Palm orientation, object file frame (`w, x, y, z`; normalised here).
    pub quaternion_wxyz: [f64; 4],
    /// `[θ1, θ2]` per finger `[deg]`.
    pub theta_deg: Vec<[f64; 2]>,
    /// The principal axis whose aligned frame `gravity = "down"` and the six directions refer
    /// to, by its JSON `axis_name` (`least`, `middle-`, …); `None`: the thesis axis.
    pub axis_name: Option<String>,
}

impl GivenGrasp {
    /// The pose in `aligned`'s frame, or why it cannot be posed for a hand of `fingers`.
    fn pose_in(
        &self,
        aligned: &mesh::AlignedObject,
        fingers: usize,
    ) -> Result<sim::SimHand, String> {
        let finite = self
            .position_mm
            .iter()
            .chain(&self.quaternion_wxyz)
            .all(|v| v.is_finite())
            && self.theta_deg.iter().flatten().all(|v| v.is_finite());
        if !finite {
            return Err("a coordinate or angle is not a finite number".to_string());
        }
        if self.theta_deg.len() != fingers {
            return Err(format!(
                "{} fingers' joint angles for a hand of {fingers} fingers",
                self.theta_deg.len()
            ));
        }
        if let Some(a) = self.theta_deg.iter().flatten().find(|a| a.abs() > 360.0) {
            return Err(format!("joint angle {a}° is outside [-360°, 360°]"));
        }
        let [w, x, y, z] = self.quaternion_wxyz;
        let q = nalgebra::Quaternion::new(w, x, y, z);
        if q.norm() < 1e-9 {
            return Err("the palm quaternion is zero".to_string());
        }
        let r = aligned.to_aligned.rotation * nalgebra::UnitQuaternion::from_quaternion(q);
        let m = r.to_rotation_matrix();
        let p = nalgebra::Point3::from(self.position_mm);
        Ok(sim::SimHand {
            origin_mm: aligned.to_aligned * p,
            axes: [0, 1, 2].map(|i| m.matrix().column(i).into_owned()),
            theta_deg: self.theta_deg.clone(),
            planned_contacts_mm: Vec::new(),
        })
    }
}

/// The flags that decide what is computed for each input, as the command line, `batch` and its
/// workers give them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RunFlags {
    /// Skip the physics check.
    pub no_sim: bool,
    /// Find the payload margin by bisection.
    pub payload: bool,
    /// Compute the analytic grasp quality of every grasp reported.
    pub quality: bool,
}

/// How to run a scenario.
#[derive(Debug, Clone)]
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
    /// Check this grasp instead of the planner's (the planner still runs and is reported, but
    /// its candidates are not checked). Library and Python only.
    pub given: Option<GivenGrasp>,
}

/// Candidates the physics check runs on at most before a run settles for the best it saw.
pub const DEFAULT_MAX_CHECKED: usize = 8;

impl Default for RunOptions {
    fn default() -> Self {
        RunFlags::default().into()
    }
}

impl From<RunFlags> for RunOptions {
    fn from(f: RunFlags) -> RunOptions {
        RunOptions {
            no_sim: f.no_sim,
            payload: f.payload,
            quality: f.quality,
            candidates: 1,
            max_checked: None,
            export_mjcf: None,
            export_urdf: None,
            report: None,
            folder: None,
            given: None,
        }
    }
}

impl RunOptions {
    /// The subfolder of the output folders for `scenario`.
    pub fn folder_for<'a>(&'a self, scenario: &'a Scenario) -> &'a str {
        self.folder.as_deref().unwrap_or(&scenario.name)
    }

    /// Whether any output folder is asked for.
    pub fn writes_folders(&self) -> bool {
        self.report.is_some() || self.export_mjcf.is_some() || self.export_urdf.is_some()
    }
}

/// What [`compute`] found for a scenario: the report, and what the outputs are written from.
pub struct Computed {
    /// The report (its `mjcf_scene` is set by [`write_outputs`]).
    pub report: RunReport,
    object: PreparedObject,
    selection: select::Selection,
    /// The pose the physics check ran (or would run) on, and where the grasp came from.
    posed: Option<sim::SimHand>,
    /// The bodies' poses at the end of the first hold and at the end of the closing.
    sim_poses: Option<(Vec<sim::BodyPose>, Vec<sim::BodyPose>)>,
    /// The aligned object the check is on.
    checked_axis: CheckedOn,
}

impl Computed {
    /// The aligned object the checked grasp (or `override_angles`) is on.
    fn checked_on(&self) -> &mesh::AlignedObject {
        match &self.checked_axis {
            CheckedOn::Own => &self.object.aligned,
            CheckedOn::Plan(i) => &self.selection.axes[*i].aligned,
            CheckedOn::Given(a) => a.as_ref(),
        }
    }
}

/// Where the check is: on an axis plan's aligned object, or on an axis a given grasp names that
/// the planner did not search (aligned for it, as the planner would align it).
enum CheckedOn {
    /// The object's own aligned frame (the thesis axis).
    Own,
    /// The aligned object of `selection.axes[i]`.
    Plan(usize),
    /// A given grasp's axis the search never reached.
    Given(Box<mesh::AlignedObject>),
}

/// Where the check is: the given grasp's axis, else the chosen grasp's; the object's own
/// aligned frame when neither names one.
///
/// # Errors
/// [`Error::Given`] for an axis name that names no principal axis.
fn checked_axis(
    options: &RunOptions,
    selection: &select::Selection,
    object: &PreparedObject,
    scenario: &Scenario,
) -> Result<CheckedOn, Error> {
    let Some(given) = &options.given else {
        return Ok(selection
            .chosen()
            .map_or(CheckedOn::Own, |c| CheckedOn::Plan(c.axis_plan)));
    };
    let Some(name) = &given.axis_name else {
        return Ok(CheckedOn::Own);
    };
    if let Some(i) = selection
        .axes
        .iter()
        .position(|a| a.aligned.axis.name() == *name)
    {
        return Ok(CheckedOn::Plan(i));
    }
    // A candidate of a run that searched further (more candidates, or an axis this run's
    // search stopped before) is checked where it was planned: its axis aligned as the planner
    // aligns it.
    match mesh::GraspAxis::from_name(name) {
        Some(axis) => Ok(CheckedOn::Given(Box::new(mesh::align_with_rule(
            object.mesh(),
            &object.props,
            axis,
            scenario.object.frame,
        )))),
        None => Err(Error::Given(format!(
            "axis \"{name}\" is not a principal axis (least, middle, largest, each with `-` \
             when flipped) nor an arc of a ring (arc0, arc90)"
        ))),
    }
}

/// Runs a scenario: [`compute`], then [`write_outputs`].
///
/// # Errors
/// [`Error`] for a bad mesh file or an output that cannot be written.
pub fn run(scenario: &Scenario, options: &RunOptions) -> Result<RunReport, Error> {
    let mut computed = compute(scenario, options)?;
    write_outputs(&mut computed, scenario, options)?;
    Ok(computed.report)
}

/// Loads `scenario`'s object and checks the planner's work bound before any planning;
/// `timings` receives `load` and `align`.
///
/// # Errors
/// [`Error`] for a bad mesh file, or an object too large for the planner (with a hint when
/// its unit looks wrong).
pub fn prepare(scenario: &Scenario, timings: &mut StageTimings) -> Result<PreparedObject, Error> {
    let object = PreparedObject::load(&scenario.object, timings)?;
    let p = &scenario.planner;
    mesh::check_planner_work(
        object.mesh(),
        object.props.centroid,
        &scenario.object.mesh,
        p.height_step_mm,
        p.angular_step_deg,
    )
    .map_err(|mut e| {
        // An object too large for the planner is most often one read in the wrong unit: say so.
        if let mesh::MeshError::TooLarge { hint, .. } = &mut e {
            if let Some(w) = object.loaded.units_warning() {
                *hint = format!("; {w}");
            }
        }
        e
    })?;
    Ok(object)
}

/// Prepares the object, plans, checks the chosen grasp and judges `[expect]`. Writes nothing.
///
/// # Errors
/// [`Error`] for a bad mesh file.
pub fn compute(scenario: &Scenario, options: &RunOptions) -> Result<Computed, Error> {
    let mut timings = StageTimings::default();
    let object = prepare(scenario, &mut timings)?;
    let selection = select_grasps(scenario, options, &object, &mut timings);
    let qualities = qualities(scenario, options, &selection);
    let plan = build::plan_report(scenario, &selection, &qualities, timings);
    let checked_axis = checked_axis(options, &selection, &object, scenario)?;
    let checked_on = match &checked_axis {
        CheckedOn::Own => &object.aligned,
        CheckedOn::Plan(i) => &selection.axes[*i].aligned,
        CheckedOn::Given(a) => a.as_ref(),
    };
    let posed = posed(scenario, options, &selection, checked_on)?;
    let (sim, sim_poses, ran) = run_sim(scenario, options, &object, checked_on, &posed);
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
    let mut report = RunReport {
        scenario: scenario.name.clone(),
        object: build::object_report(scenario, &object),
        warnings: build::warnings(
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
        mjcf_scene: None,
    };
    // Issue 37: a hand file's coupled joints, checked against the plan.
    if let Some(g) = &report.plan.grasp {
        let theta: Vec<[f64; 2]> = g
            .fingers
            .iter()
            .map(|f| [f.theta1_deg, f.theta2_deg])
            .collect();
        report.warnings.extend(scenario.hand.coupling_lines(&theta));
    }
    Ok(Computed {
        report,
        posed: posed.ok().map(|p| p.0),
        object,
        selection,
        sim_poses,
        checked_axis,
    })
}

/// The pose to check on `checked_on`: the given grasp's, else [`sim_pose`]'s.
///
/// # Errors
/// [`Error::Given`] for a given grasp that cannot be posed.
fn posed(
    scenario: &Scenario,
    options: &RunOptions,
    selection: &select::Selection,
    checked_on: &mesh::AlignedObject,
) -> Result<Posed, Error> {
    Ok(match &options.given {
        Some(given) => Ok((
            given
                .pose_in(checked_on, scenario.hand.finger_list.len())
                .map_err(Error::Given)?,
            GraspSource::Given,
            None,
        )),
        None => {
            let graded = &selection.axes[0].graded;
            check_override_index(scenario, graded)?;
            sim_pose(
                scenario,
                checked_on,
                graded,
                selection.chosen().map(|c| (&c.grasp, c.check.clone())),
            )
        }
    })
}

/// `[sim] override_index` against the indexed elevations the planner found: 1 to their count
/// (it was clamped into that range before issue 56, while 0 and −1 were refused).
///
/// # Errors
/// [`scenario::ScenarioError::Invalid`] naming the key and the valid range.
fn check_override_index(scenario: &Scenario, graded: &plan::GradedDomain) -> Result<(), Error> {
    let input = &scenario.sim.input;
    let (Some(_), Some(index)) = (&input.override_angles, input.override_index) else {
        return Ok(());
    };
    let n = graded.domain.elevations.len();
    if (1..=n).contains(&index) {
        return Ok(());
    }
    Err(Error::Scenario(scenario::ScenarioError::Invalid {
        path: scenario.path.clone(),
        key: "sim.override_index".to_string(),
        problem: if n == 0 {
            format!("is {index}, but the object has no indexed elevation to place the palm on")
        } else {
            format!("must be in 1..={n} (the object's indexed elevations), got {index}")
        },
    }))
}

/// Writes the URDF and MJCF exports and the `--report` folder that `options` ask for, from
/// what [`compute`] found; sets the report's `mjcf_scene`.
///
/// # Errors
/// [`Error::Export`] for an output that cannot be written.
pub fn write_outputs(
    computed: &mut Computed,
    scenario: &Scenario,
    options: &RunOptions,
) -> Result<(), Error> {
    // Every output folder is the folder given joined with one folder name: checked here, for
    // any scenario (a library caller's too), before anything is written.
    let folder = options.folder_for(scenario);
    if let Some(problem) = crate::files::folder_name_problem(folder) {
        let given = [&options.export_urdf, &options.export_mjcf, &options.report];
        if let Some(dir) = given.into_iter().flatten().next() {
            return Err(Error::OutputName {
                dir: dir.clone(),
                name: folder.to_string(),
                problem,
            });
        }
    }
    if let Some(dir) = &options.export_urdf {
        export::write_urdf(
            &dir.join(options.folder_for(scenario)),
            &scenario.hand,
            &scenario.sim,
        )?;
    }
    if let (Some(dir), Some(pose)) = (&options.export_mjcf, &computed.posed) {
        let aligned = computed.checked_on();
        let shape = computed.object.shape(aligned, pose, &scenario.hand);
        let input = export::ExportInput {
            name: &scenario.name,
            object: aligned,
            case: computed.object.case(scenario, pose, &shape),
        };
        let folder = dir.join(options.folder_for(scenario));
        export::write_mjcf(&folder, &input)?;
        write_sample_scenes(&folder, &input)?;
        computed.report.mjcf_scene = Some(folder.join("scene.xml"));
    }
    if let Some(dir) = &options.report {
        let shown = computed.selection.reported_axis();
        visual::write_report(
            &dir.join(options.folder_for(scenario)),
            &computed.report,
            &shown.graded,
            computed.selection.chosen().map(|c| &c.grasp),
            &shown.aligned.mesh,
            &scenario.hand,
            computed
                .sim_poses
                .as_ref()
                .map(|(end, closed)| visual::SimulatedPoses { end, closed }),
        )?;
    }
    Ok(())
}

/// With `[sim] samples` above 1 (issue 34): each perturbed sample's MJCF scene, into
/// `folder/samples/<k>/`, for MuJoCo to replay the same samples
/// (`scripts/compare_engines.py --robust`).
fn write_sample_scenes(folder: &std::path::Path, input: &export::ExportInput) -> Result<(), Error> {
    let rp = &input.case.params.robust;
    if rp.samples < 2 {
        return Ok(());
    }
    for k in 0..rp.samples {
        let p = sim::Perturbation::draw(rp, k);
        let perturbed = sim::robust::Perturbed::of(&input.case, &p);
        let sample = export::ExportInput {
            name: input.name,
            object: input.object,
            case: perturbed.case(&input.case),
        };
        export::write_mjcf(&folder.join("samples").join(k.to_string()), &sample)?;
    }
    Ok(())
}

/// The physics check `check` (a [`sim::entry`] point) of one planned grasp on `aligned`, as a
/// run does it: the one place that turns a grasp into a check.
pub fn check_grasp(
    scenario: &Scenario,
    object: &PreparedObject,
    aligned: &mesh::AlignedObject,
    grasp: &plan::search::Grasp,
    check: fn(&sim::Case) -> sim::SimOutcome,
) -> sim::SimOutcome {
    let pose = sim::SimHand::from_grasp(grasp, &scenario.hand);
    let shape = object.shape(aligned, &pose, &scenario.hand);
    check(&object.case(scenario, &pose, &shape))
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
        check_grasp(scenario, object, a, g, sim::entry::search)
    };
    // The full check, for the candidates a failed closing decided when none succeeds
    // (`select::SelectParams::recheck`).
    let recheck = |a: &mesh::AlignedObject, g: &plan::search::Grasp| -> sim::SimOutcome {
        check_grasp(scenario, object, a, g, sim::entry::search_in_full)
    };
    // `[sim] order_by_closing`: the search's first check, where its closing left the plan
    // the closing alone (`select::SelectParams::probe`).
    let probe = |a: &mesh::AlignedObject, g: &plan::search::Grasp| -> sim::SimOutcome {
        check_grasp(scenario, object, a, g, sim::entry::search_probe)
    };
    // `[sim] order_by_closing`: the closing alone, gravity off.
    let close = |a: &mesh::AlignedObject, g: &plan::search::Grasp| -> select::Preclosed {
        preclosed(scenario, object, a, g)
    };
    // `[sim] order_samples`: the perturbed closings, gravity off.
    let sampled = |a: &mesh::AlignedObject, g: &plan::search::Grasp| -> usize {
        sampled_closings_on_plan(scenario, object, a, g)
    };
    // The physics check chooses among candidates only when it runs on the planner's grasps.
    let checks_candidates =
        !options.no_sim && scenario.sim.input.override_angles.is_none() && options.given.is_none();
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
            recheck: Some(&recheck),
            probe: Some(&probe),
            domains: None,
            frame: scenario.object.frame,
            order_by_closing: Some((scenario.sim.selection.order_by_closing, &close)),
            order_samples: Some((scenario.sim.selection.order_samples, &sampled)),
            plan_reach: 0,
            order_reach: scenario.sim.selection.order_reach,
        },
        timings,
    )
}

/// What grasp `g`'s closing on `a` does with gravity off (`[sim] order_by_closing`), as a run
/// and a `tune` sweep rank it.
pub(crate) fn preclosed(
    scenario: &Scenario,
    object: &PreparedObject,
    a: &mesh::AlignedObject,
    g: &plan::search::Grasp,
) -> select::Preclosed {
    let pose = sim::SimHand::from_grasp(g, &scenario.hand);
    let shape = object.shape(a, &pose, &scenario.hand);
    let f = sim::entry::closing_fidelity(&object.case(scenario, &pose, &shape));
    select::Preclosed {
        as_planned: f.as_planned,
        shift_mm: f.shift_mm,
        sampled_on_plan: None,
    }
}

/// How many of grasp `g`'s `[sim] order_samples` perturbed closings on `a` kept the plan, as a
/// run and a `tune` sweep rank it.
pub(crate) fn sampled_closings_on_plan(
    scenario: &Scenario,
    object: &PreparedObject,
    a: &mesh::AlignedObject,
    g: &plan::search::Grasp,
) -> usize {
    let pose = sim::SimHand::from_grasp(g, &scenario.hand);
    let shape = object.shape(a, &pose, &scenario.hand);
    let case = object.case(scenario, &pose, &shape);
    sim::entry::sampled_closings_on_plan(&case, scenario.sim.selection.order_samples)
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

/// The pose to check: `override_angles` (placed on the thesis axis's `graded` domain) or the
/// chosen grasp, where the grasp came from, and the candidate search's outcome for it; or why
/// there is nothing to check.
type Posed = Result<(sim::SimHand, GraspSource, Option<sim::SimOutcome>), String>;

fn sim_pose(
    scenario: &Scenario,
    aligned: &mesh::AlignedObject,
    graded: &plan::GradedDomain,
    grasp: Option<(&plan::search::Grasp, Option<sim::SimOutcome>)>,
) -> Posed {
    let p = &scenario.sim;
    match (&p.input.override_angles, grasp) {
        (Some(angles), _) => select::override_pose(
            &aligned.mesh,
            &scenario.hand,
            graded,
            p.input.override_index,
            angles,
        )
        .map(|pose| (pose, GraspSource::OverrideAngles, None))
        .map_err(|e| e.to_string()),
        (None, Some((g, done))) => Ok((
            sim::SimHand::from_grasp(g, &scenario.hand),
            GraspSource::Planner,
            done,
        )),
        (None, None) => Err("no feasible grasp to check".to_string()),
    }
}

/// The physics check's report, the bodies' poses for the report's scenes, and the outcome when
/// the check ran here rather than in the candidate search.
type Simulated = (
    SimReport,
    Option<(Vec<sim::BodyPose>, Vec<sim::BodyPose>)>,
    Option<sim::SimOutcome>,
);

/// Runs the physics check on the posed grasp (or says why it did not run).
fn run_sim(
    scenario: &Scenario,
    options: &RunOptions,
    object: &PreparedObject,
    aligned: &mesh::AlignedObject,
    posed: &Posed,
) -> Simulated {
    // With --no-sim the check's reason is `--no-sim`, unless an MJCF export asked for the pose
    // and there is none: then the reason is why not.
    let (pose, source, done) = match posed {
        Err(_) if options.no_sim && options.export_mjcf.is_none() => {
            return (SimReport::not_run("--no-sim"), None, None)
        }
        Err(why) => return (SimReport::not_run(why), None, None),
        Ok(_) if options.no_sim => return (SimReport::not_run("--no-sim"), None, None),
        Ok((pose, source, done)) => (pose, *source, done),
    };
    let shape = object.shape(aligned, pose, &scenario.hand);
    let case = object.case(scenario, pose, &shape);
    // The candidate search already checked the chosen grasp: the same case, the same outcome.
    let sim::entry::Reported {
        outcome: out,
        payload,
    } = sim::entry::reported(&case, done.clone(), options.payload);
    let poses = (out.final_poses.clone(), out.closed_poses.clone());
    let ran = done.is_none().then(|| out.clone());
    let report = build::checked_report(out, payload, &case, &shape, source, options);
    (report, Some(poses), ran)
}

/// Progress of a long command (`batch`, `tune`), shown by the caller: a bar on a terminal, lines
/// in a log, or nothing.
pub trait Progress: Sync {
    /// `total` steps begin.
    fn begin(&self, total: usize);
    /// Step `done` of `total` has finished; `message` says which and how.
    fn step(&self, done: usize, total: usize, message: &str);
    /// The steps are over.
    fn end(&self);
}

/// Creates `dir` if needed and checks a file can be written in it: output folders are checked
/// before any work, so an unwritable one costs nothing.
///
/// # Errors
/// A file in the way, or a folder that cannot be created or written in.
pub fn check_output_dir(dir: &std::path::Path) -> anyhow::Result<()> {
    use anyhow::Context;
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!("{}: is a file, not a folder", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create folder", dir.display()))?;
    crate::files::check_writable_dir(dir).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot write in this folder: {}",
            dir.display(),
            crate::messages::io_message(&e)
        )
    })
}

/// [`check_output_dir`], then the folder locked for this run ([`crate::files::FolderLock`]):
/// a second run into the same folder is refused with the lock's message while this one runs.
///
/// # Errors
/// [`check_output_dir`]'s, or another run holding the folder, or the lock file not made.
pub fn lock_output_dir(dir: &std::path::Path) -> anyhow::Result<crate::files::FolderLock> {
    check_output_dir(dir)?;
    crate::files::FolderLock::take(dir).map_err(|e| {
        if e.kind() == std::io::ErrorKind::WouldBlock {
            anyhow::anyhow!("{}: {e}", dir.display())
        } else {
            anyhow::anyhow!(
                "{}: cannot lock the folder: {}",
                dir.display(),
                crate::messages::io_message(&e)
            )
        }
    })
}

/// Checks that `file` can be written later: its folder exists and takes a file.
///
/// # Errors
/// No such folder, a folder where the file should be, or a folder that cannot be written in.
pub fn check_output_file(file: &std::path::Path) -> anyhow::Result<()> {
    let dir = file
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    if !dir.is_dir() {
        anyhow::bail!(
            "{}: cannot write: no folder {}",
            file.display(),
            dir.display()
        );
    }
    if file.is_dir() {
        anyhow::bail!(
            "{}: is a folder; give a file to write the results to (for example {})",
            file.display(),
            file.join("results.jsonl").display()
        );
    }
    if let Err(e) = crate::files::check_replaceable(file) {
        anyhow::bail!("{}: {e}", file.display());
    }
    crate::files::check_writable_dir(dir).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot write in {}: {}",
            file.display(),
            dir.display(),
            crate::messages::io_message(&e)
        )
    })
}
