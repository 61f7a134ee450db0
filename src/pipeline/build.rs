//! The report's parts, built from what a run computed: the object, the plan (grasps, axes,
//! rejections, why nothing was found) and the physics check.

use super::RunOptions;
use crate::prepared::PreparedObject;
use crate::report::{
    self, GradesReport, GraspSource, IndexScale, ObjectReport, PlanReport, PlanStatus, PoseReport,
    SimReport, SimVerdict, StageTimings,
};
use crate::scenario::Scenario;
use crate::{hand, mesh, plan, quality, select, sim};
use std::collections::BTreeMap;

/// The `object` part of the report.
pub(super) fn object_report(scenario: &Scenario, object: &PreparedObject) -> ObjectReport {
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
pub(super) fn warnings(
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
pub(super) fn plan_report(
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
        .map(|(c, q)| candidate_report(c, &selection.axes[c.axis_plan].aligned, q.as_ref()))
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
        graspable_diameter_basis: crate::report::DiameterBasis::Kinematic,
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

/// The `sim` report of a check that ran on `case` (with the payload bracket when asked for).
pub(super) fn checked_report(
    out: sim::SimOutcome,
    payload: Option<(f64, Option<f64>)>,
    case: &sim::Case,
    shape: &sim::ObjectShape,
    source: GraspSource,
    options: &RunOptions,
) -> SimReport {
    SimReport {
        verdict: SimVerdict::Ran(out.verdict.into()),
        translation_mm: Some(out.translation_mm),
        rotation_deg: Some(out.rotation_deg),
        simulated_s: Some(out.simulated_s),
        steps: Some(out.steps),
        wall_ms: Some(out.wall_ms),
        start: Some((&sim::scene::start(case)).into()),
        collider: Some((&sim::ColliderReport::of(shape)).into()),
        mass_kg: Some(case.mass_kg),
        grasp_source: Some(source),
        payload_margin: options
            .payload
            .then(|| payload.map_or(0.0, |(held, _)| held)),
        payload_fails_at: payload.and_then(|(_, failed)| failed),
        closing: Some((&out.closing).into()),
        fidelity: Some((&out.fidelity).into()),
        directions: out.directions.iter().map(Into::into).collect(),
        robust: out.robust.as_ref().map(Into::into),
        replay: out.replay.as_ref().map(Into::into),
        limits: Some(report::HoldLimits {
            translation_mm: case.params.hold.hold_translation_mm,
            rotation_deg: case.params.hold.hold_rotation_deg,
            penetration_mm: case.params.hold.max_penetration_mm,
            closing_shift_mm: case.params.hold.max_closing_shift_mm,
            on_plan_fraction: case.params.hold.min_on_plan_fraction,
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
        leaning: a.rules == plan::RuleSet::Leaning,
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

/// A candidate's report: its grasp, its check, its brief quality and, under `[sim]
/// order_by_closing`, the closing that ordered it.
fn candidate_report(
    c: &select::Candidate,
    aligned: &mesh::AlignedObject,
    q: Option<&quality::Quality>,
) -> report::GraspReport {
    report::GraspReport {
        quality: q.map(report::GraspQuality::of),
        closing_order: c.preclosed.map(|f| report::ClosingOrder {
            as_planned: f.as_planned,
            shift_mm: f.shift_mm,
            sampled_on_plan: f.sampled_on_plan,
        }),
        ..grasp_report(&c.grasp, aligned, c.check.as_ref())
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
        palm_standoff_mm: (g.palm.standoff_mm > 0.0).then_some(g.palm.standoff_mm),
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
            verdict: if o.decided_by_closing() {
                SimVerdict::NotRun {
                    reason: "the closing left the plan and [sim] closing_decides is on: not \
                             held under gravity"
                        .to_string(),
                }
            } else {
                SimVerdict::Ran(o.verdict.into())
            },
            fidelity: (&o.fidelity).into(),
            closed_joint_angles_deg: o.closing.fingers.iter().map(|f| f.final_deg).collect(),
            translation_mm: o.translation_mm,
            rotation_deg: o.rotation_deg,
            robust: o.robust.as_ref().map(|r| report::CandidateRobust {
                held: r.counts.hold,
                samples: r.samples,
                hold_probability: r.hold_probability,
                interval: r.interval,
                as_planned_probability: r.as_planned_probability,
                as_planned_interval: r.as_planned_interval,
            }),
        }),
        quality: None,
        closing_order: None,
    }
}
