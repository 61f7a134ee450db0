//! Choosing the grasp: the thesis planner on every principal axis, the rules beyond the thesis
//! when it finds nothing, and (with the physics check) candidates checked in search order until
//! one holds.
//!
//! Order (issues 13 and 14): rule sets outer, axes inner, each axis's candidates in the thesis's
//! search order. The thesis's rules on the thesis's axis come first, so a thesis object gets the
//! thesis's grasp; the other axes follow ([`GraspAxis::SEARCH_ORDER`] says why in that order);
//! the extended rules ([`RuleSet::Extended`]) only when the thesis's rules found no grasp on any
//! axis, or, with the physics check, when none of their grasps held and checks remain; the
//! fingertip pinch ([`RuleSet::Pinch`]) on the same terms after the extended rules, and the palm
//! leaning on one contact ([`RuleSet::Leaning`]) last.
//!
//! Without the physics check the first feasible grasp is the answer, as in the thesis
//! (`--candidates N` collects N). With it, candidates are checked one by one until one holds as
//! planned or `max_checked` have been checked; the first that holds as planned is the answer,
//! else the first that held (the closing took it off its plan: its closed joint angles are the
//! grasp to command), else the first that slipped, else the first checked (issue 55), and
//! every candidate checked is reported with its verdict and fidelity. Under `[sim]
//! closing_decides` a candidate whose closing left the plan is not held under gravity at once,
//! and is checked again in full where the choice or the report needs it
//! ([`SelectParams::recheck`]).

use crate::hand::Hand;
use crate::mesh::{align_with_rule, AlignedObject, FrameRule, GraspAxis, MassProperties, Mesh};
use crate::plan::order::OrderFactors;
use crate::plan::search::{candidate_count, search_with, Grasp, Rejection};
use crate::plan::{self, GradedDomain, RuleSet};
use crate::report::StageTimings;
use crate::scenario::PlannerParams;
use crate::sim::{SimOutcome, Verdict};
use std::collections::BTreeMap;

/// The planner's view of the object about one axis under one rule set.
#[derive(Debug, Clone)]
pub struct AxisPlan {
    /// The axis and the object aligned with it.
    pub aligned: AlignedObject,
    /// The rule set used.
    pub rules: RuleSet,
    /// Stages 1–3 about this axis.
    pub graded: GradedDomain,
    /// Candidates (elevation × approach angle) tried.
    pub candidates_tried: usize,
    /// How often each constraint rejected a candidate.
    pub rejections: BTreeMap<Rejection, usize>,
    /// Feasible grasps found about this axis.
    pub grasps_found: usize,
    /// True if and only if the search walked the whole sorted domain.
    pub exhausted: bool,
    /// The candidates the sorted domain holds (elevations × approach angles).
    pub candidates_available: usize,
    /// True if and only if the search stopped at its share of the candidate budget
    /// ([`PlannerParams::candidate_budget`]) with candidates left untried.
    pub budget_stopped: bool,
}

/// A feasible grasp and, when the physics check ran on it, its outcome.
#[derive(Debug, Clone)]
pub struct Candidate {
    /// Which [`AxisPlan`] it came from (index into [`Selection::axes`]).
    pub axis_plan: usize,
    /// The grasp, in that plan's aligned frame.
    pub grasp: Grasp,
    /// The physics check's outcome, when it ran on this candidate.
    pub check: Option<SimOutcome>,
    /// Its place in its axis plan's thesis order (0: the thesis's first), whatever order the
    /// `[planner] sf_*` factors searched it in: what `grasp-sim tune --labels` reorders.
    pub thesis_place: usize,
    /// Under `[sim] order_by_closing`, what its closing did with gravity off, for a candidate
    /// it closed.
    pub preclosed: Option<Preclosed>,
}

/// What a candidate's closing did, gravity off (`[sim] order_by_closing`): the closing's own
/// fidelity figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Preclosed {
    /// The closing kept the plan ([`crate::sim::Fidelity`]'s `as_planned`).
    pub as_planned: bool,
    /// How far it pushed the object `[mm]`.
    pub shift_mm: f64,
    /// Under `[sim] order_samples`, how many of its perturbed closings kept the plan.
    pub sampled_on_plan: Option<usize>,
}

/// A closing with gravity off of a grasp about an axis (`[sim] order_by_closing`).
pub type CloseFn<'a> = &'a (dyn Fn(&AlignedObject, &Grasp) -> Preclosed + Sync);

/// `[sim] order_samples`: how many of a grasp's perturbed closings, gravity off, kept the plan.
pub type SampledFn<'a> = &'a (dyn Fn(&AlignedObject, &Grasp) -> usize + Sync);

/// Everything the selection did.
#[derive(Debug, Clone)]
pub struct Selection {
    /// Every (axis, rule set) planned, in order.
    pub axes: Vec<AxisPlan>,
    /// Every feasible grasp collected, in search order.
    pub candidates: Vec<Candidate>,
    /// The chosen candidate (index into `candidates`), if any.
    pub chosen: Option<usize>,
}

impl Selection {
    /// The chosen candidate.
    pub fn chosen(&self) -> Option<&Candidate> {
        self.chosen.map(|i| &self.candidates[i])
    }

    /// The axis plan the report describes: the chosen grasp's, else the thesis's axis under the
    /// thesis's rules (the first planned of the whole object's: a ring's arcs come before it).
    pub fn reported_axis(&self) -> &AxisPlan {
        match self.chosen() {
            Some(c) => &self.axes[c.axis_plan],
            None => self
                .axes
                .iter()
                .find(|a| a.aligned.axis.arc.is_none())
                .unwrap_or(&self.axes[0]),
        }
    }

    /// How many candidates the physics check ran on.
    pub fn checked(&self) -> usize {
        self.candidates.iter().filter(|c| c.check.is_some()).count()
    }

    /// Where the candidate budget stopped the search, in words (`None` when it stopped
    /// nowhere): each axis and rule set stopped, with the candidates it tried of those it had.
    pub fn budget_stops(&self) -> Option<String> {
        let stops: Vec<String> = self
            .axes
            .iter()
            .filter(|a| a.budget_stopped)
            .map(|a| {
                let rules = match a.rules {
                    RuleSet::Thesis => "thesis",
                    RuleSet::Extended => "extended",
                    RuleSet::Pinch => "pinch",
                    RuleSet::Leaning => "leaning",
                };
                format!(
                    "{} {rules} ({} of {})",
                    a.aligned.axis.name(),
                    a.candidates_tried,
                    a.candidates_available
                )
            })
            .collect();
        (!stops.is_empty()).then(|| stops.join(", "))
    }
}

/// What the selection needs besides the object.
#[derive(Clone, Copy)]
pub struct SelectParams<'a> {
    /// The hand.
    pub hand: &'a Hand,
    /// Planner parameters.
    pub planner: &'a PlannerParams,
    /// Coulomb friction (the planner's friction cone).
    pub friction: f64,
    /// Feasible grasps to collect at least (`--candidates`).
    pub collect: usize,
    /// With the physics check: at most this many candidates are checked. `None`: no check.
    pub max_checked: Option<usize>,
    /// Runs the physics check on a grasp about an axis ([`crate::sim::entry::search`]).
    #[allow(clippy::type_complexity)]
    pub check: &'a dyn Fn(&AlignedObject, &Grasp) -> SimOutcome,
    /// The full check (holds run after a failed closing, [`crate::sim::entry::search_in_full`]),
    /// for `[sim] closing_decides`: when no candidate succeeds, the candidates a failed closing
    /// decided are checked again with it, in order, until the one the full checks would choose
    /// is known. `None`: never (no check that `check` returns is decided by the closing).
    #[allow(clippy::type_complexity)]
    pub recheck: Option<&'a dyn Fn(&AlignedObject, &Grasp) -> SimOutcome>,
    /// Under `[sim] order_by_closing`, the search's first check
    /// ([`crate::sim::entry::search_probe`]): where the closing left the plan, the closing
    /// alone, gravity never on (the closings' order decides what follows, and the first's
    /// hold is run only if that order comes back to it); elsewhere `check`'s outcome, to the
    /// bit. `None`: `check`.
    #[allow(clippy::type_complexity)]
    pub probe: Option<&'a dyn Fn(&AlignedObject, &Grasp) -> SimOutcome>,
    /// Stage-1 domains kept across calls (a parameter sweep): they depend only on the axis, the
    /// rule set, the AngularStep and the HeightStep. `None`: built afresh.
    pub domains: Option<&'a DomainCache>,
    /// How the object's own frame is chosen (`[object] frame`).
    pub frame: FrameRule,
    /// `[sim] order_by_closing` and the closing it runs: with the physics check, that many
    /// candidates picked for diversity are closed first and checked in the order their closings
    /// give ([`select`]). `None` or 0: the search order.
    pub order_by_closing: Option<(usize, CloseFn<'a>)>,
    /// `[sim] order_samples` and the perturbed closings it runs: under `order_by_closing`, the
    /// first candidate is checked first only if all that many kept the plan, and the closed
    /// candidates are ranked by how many of their closings, the nominal one with them, kept
    /// it. `None` or 0: the nominal closing alone.
    pub order_samples: Option<(usize, SampledFn<'a>)>,
    /// Without the check (`max_checked` `None`), the rule sets beyond the thesis's are planned
    /// while fewer than this many candidates have been found: the candidates a search that
    /// checks this many could reach (it goes on to the next rule set when none of them held).
    /// 0 or 1: only when the thesis's rules found none.
    pub plan_reach: usize,
    /// `[sim] order_reach`: under `order_by_closing = n`, while none of the first rule set's
    /// picks keeps its plan the order picks on, `n` more, then `2n` more, until this many have
    /// been closed; a further pick joins only if most of its closings keep the plan
    /// ([`ranked_by_closing`]). At most `n`: no further picks.
    pub order_reach: usize,
}

/// Stage-1 domains by (axis, rule set, AngularStep bits, HeightStep bits).
pub type DomainCache =
    std::cell::RefCell<std::collections::HashMap<(GraspAxis, RuleSet, u64, u64), plan::Domain>>;

/// Plans across axes and rule sets, checking candidates when asked (see the module docs).
///
/// `timings` receives the summed wall time of each planner stage `[ms]`.
pub fn select(
    mesh: &Mesh,
    props: &MassProperties,
    p: &SelectParams,
    timings: &mut StageTimings,
) -> Selection {
    let (Some(max), Some((n, close))) = (p.max_checked, p.order_by_closing) else {
        return select_in(mesh, props, p, None, timings);
    };
    if n == 0 {
        return select_in(mesh, props, p, None, timings);
    }
    // `[sim] order_by_closing`: the search as without it, stopped at its first check if that
    // check did not succeed: its closing left the plan, or, with checks to spare, the grasp it
    // kept did not hold (that check counts, [`select_by_closing`]).
    let left = std::cell::Cell::new(false);
    let first_call = std::cell::Cell::new(true);
    // Under `order_samples`, how many of the first's perturbed closings kept the plan, when its
    // own did.
    let first_sampled = std::cell::Cell::new(None);
    let check = |a: &AlignedObject, g: &Grasp| -> SimOutcome {
        let first = first_call.replace(false);
        let out = match p.probe {
            Some(probe) if first => probe(a, g),
            _ => (p.check)(a, g),
        };
        if first && !out.succeeded() && (max > 1 || !out.fidelity.as_planned) {
            left.set(true);
        }
        if let Some((m @ 1.., sampled)) = p.order_samples.filter(|_| first && !left.get()) {
            let on_plan = sampled(a, g);
            first_sampled.set(Some(on_plan));
            if on_plan < m {
                left.set(true);
            }
        }
        out
    };
    let q = SelectParams {
        check: &check,
        ..*p
    };
    let sel = select_in(mesh, props, &q, Some(&left), timings);
    if !left.get() {
        return sel;
    }
    let first = sel.candidates.into_iter().find_map(|c| c.check);
    first
        .and_then(|first| {
            let closings = (max, n, close, first_sampled.get());
            select_by_closing(mesh, props, p, closings, first, timings)
        })
        .unwrap_or_else(|| select_in(mesh, props, p, None, timings))
}

/// An axis's frame for [`select_in`]: the object in it, and for an arc of a ring the arc in it.
type Frames = (AlignedObject, Option<AlignedObject>);

/// [`select`] without `order_by_closing`; the search ends as soon as `stop` is set (what it
/// found is returned as it stands, nothing chosen).
fn select_in(
    mesh: &Mesh,
    props: &MassProperties,
    p: &SelectParams,
    stop: Option<&std::cell::Cell<bool>>,
    timings: &mut StageTimings,
) -> Selection {
    let mut sel = Selection {
        axes: Vec::new(),
        candidates: Vec::new(),
        chosen: None,
    };
    let collect = p.collect.max(1);
    // A ring's arcs first ([`crate::mesh::ring`]), then the whole object's axes.
    let principal = crate::mesh::principal_axes(mesh, props, p.frame);
    let ring = crate::mesh::ring::is_ring(mesh, props, &principal);
    let axes: Vec<GraspAxis> = if ring {
        GraspAxis::RING_ARCS
            .iter()
            .chain(&GraspAxis::SEARCH_ORDER)
            .copied()
            .collect()
    } else {
        GraspAxis::SEARCH_ORDER.to_vec()
    };
    // Per axis: the object in its frame, and for an arc the arc in it, which the planner sees.
    let mut aligned_cache: Vec<Option<Option<Frames>>> = vec![None; axes.len()];
    for rules in [
        RuleSet::Thesis,
        RuleSet::Extended,
        RuleSet::Pinch,
        RuleSet::Leaning,
    ] {
        if rules.is_extended() && (!p.planner.extended_rules || !wants_extended(&sel, p)) {
            break;
        }
        // The candidates this rule set has tried over its axes (the budget is per rule set).
        let mut spent = 0usize;
        for (k, axis) in axes.iter().enumerate() {
            if is_done(&sel, p, collect) || stop.is_some_and(std::cell::Cell::get) {
                break;
            }
            let frames = aligned_cache[k].get_or_insert_with(|| match axis.arc {
                Some(_) => crate::mesh::ring::arc_frames(mesh, props, *axis, p.frame, &principal)
                    .map(|(whole, arc)| (whole, Some(arc))),
                None => Some((align_with_rule(mesh, props, *axis, p.frame), None)),
            });
            let Some((aligned, arc)) = frames.clone() else {
                continue;
            };
            let mut t = StageTimings::default();
            let graded = graded_for(&sel, p, rules, arc.as_ref().unwrap_or(&aligned), &mut t);
            // An equal share of what is left of the rule set's budget (rounded up, so an axis
            // with few candidates leaves more to those after it).
            let budget = match p.planner.candidate_budget {
                0 => usize::MAX,
                b => b.saturating_sub(spent).div_ceil(axes.len() - k),
            };
            let plan = search_axis(
                &mut sel,
                p,
                (aligned, arc, rules, graded),
                budget,
                (collect, stop),
                &mut t,
            );
            timings.add(&t);
            spent += plan.candidates_tried;
            sel.axes.push(plan);
        }
    }
    if stop.is_some_and(std::cell::Cell::get) {
        return sel;
    }
    choose_rechecked(&mut sel, p);
    sel
}

/// Chooses among `sel`'s checked candidates ([`choose`]), the candidates a failed closing
/// decided checked again with `p.recheck` first when none succeeded; under `choose =
/// "robust"` a candidate whose own closing failed can still be chosen by its samples, and its
/// check is then made a full one.
fn choose_rechecked(sel: &mut Selection, p: &SelectParams) {
    if let Some(recheck) = p.recheck {
        recheck_failed_closings(sel, recheck);
    }
    sel.chosen = choose(&sel.candidates);
    if let (Some(recheck), Some(i)) = (p.recheck, sel.chosen) {
        recheck_if_closing_decided(sel, i, recheck);
    }
}

/// `[sim] order_by_closing = n` (issue 58), once the search's first check, `first_check`, did
/// not succeed (its closing left the plan, or the grasp it kept did not hold): every
/// candidate is planned as `label` plans them (up to [`crate::pick::DEFAULT_CANDIDATES`], unchecked), and the rule sets after
/// the first too while fewer than `max` were found (what the search could reach); `n` of the
/// first rule set's are picked for diversity as `label` picks them (the first always among
/// them), and `n` of the later rule sets' ([`picks_by_rule_set`]); the picks are closed with
/// gravity off, and they are checked in the order their closings give (as planned first, then
/// the shift in whole millimetres, then the search order) until one succeeds, `max` have been
/// checked, or one held and none left can hold as planned (their closings left the plan); the
/// first's check is `first_check`. The selection lists the picks in that order, then the other
/// candidates collected (`collect`) in search order. `None` when none of them succeeded
/// before the checks ran out of candidates: the caller then searches as without the setting
/// (the rules beyond the thesis among it).
fn select_by_closing(
    mesh: &Mesh,
    props: &MassProperties,
    p: &SelectParams,
    (max, n, close, first_sampled): (usize, usize, CloseFn<'_>, Option<usize>),
    first_check: SimOutcome,
    timings: &mut StageTimings,
) -> Option<Selection> {
    let plan_all = SelectParams {
        collect: crate::pick::DEFAULT_CANDIDATES.max(p.collect),
        max_checked: None,
        recheck: None,
        probe: None,
        order_by_closing: None,
        order_samples: None,
        plan_reach: max,
        ..*p
    };
    let first = Preclosed {
        as_planned: first_check.fidelity.as_planned,
        shift_mm: first_check.fidelity.shift_mm,
        sampled_on_plan: first_sampled,
    };
    let mut sel = select_in(mesh, props, &plan_all, None, timings);
    let sampled = p.order_samples.filter(|(m, _)| *m > 0);
    let ranked = ranked_by_closing(&sel, p.hand, (n, p.order_reach, close, sampled), first);
    let places = put_first(&mut sel, &ranked, p.collect);
    let mut first_check = Some(first_check);
    let mut settled = false;
    for (k, &place) in places.iter().enumerate() {
        if sel.checked() >= max || has_hold(&sel) {
            break;
        }
        // With fewer candidates than checks the search goes on as without the setting when
        // none succeeds (below), the rules beyond the thesis among it: no early end then.
        if sel.candidates.len() >= max && held_and_none_left_can_succeed(&sel, k, &places) {
            settled = true;
            break;
        }
        // The first's check is reused unless its closing alone was run (the probe).
        let out = match first_check.take_if(|o| place == 0 && !o.decided_by_closing()) {
            Some(out) => out,
            None => {
                let c = &sel.candidates[k];
                (p.check)(&sel.axes[c.axis_plan].aligned, &c.grasp)
            }
        };
        sel.candidates[k].check = Some(out);
    }
    if !has_hold(&sel) && !settled && sel.checked() < max {
        return None;
    }
    choose_rechecked(&mut sel, p);
    Some(sel)
}

/// True when a checked candidate of `sel` held and none from the `k`-th on can succeed: each
/// was closed and its closing left the plan, which its check's closing does again (the same
/// closing), so none can hold as planned, or it is the search's first candidate (`places`: each
/// one's place in search order), whose check did not succeed; [`choose`] then takes the first
/// that held, whatever the rest would do. Not under `choose = "robust"` (a check with samples), whose success is
/// the samples', not the closing's.
fn held_and_none_left_can_succeed(sel: &Selection, k: usize, places: &[usize]) -> bool {
    let checked = || sel.candidates.iter().filter_map(|c| c.check.as_ref());
    checked().all(|o| o.robust.is_none())
        && checked().any(|o| o.verdict == Verdict::Hold)
        && sel.candidates[k..]
            .iter()
            .zip(&places[k..])
            .all(|(c, &place)| place == 0 || c.preclosed.is_some_and(|f| !f.as_planned))
}

/// Up to `2n` of `sel`'s candidates picked for diversity ([`picks_by_rule_set`]), each
/// with its closing by `close` (the first candidate's is `first`, closed already), in the
/// order they are checked in. The first, checked already, comes first where its closing kept
/// the plan (its hold judged it: that check counts from the start); where its closing left the
/// plan it was judged by the closing alone, as every pick is, and goes among them. Then as
/// planned first, then the shift in whole millimetres, then the search order.
///
/// Under `[sim] order_samples` (`sampled`: `m` perturbed closings), the first comes first only
/// if its perturbed closings kept the plan too, and "as planned" is the count of a pick's
/// closings, the nominal one and the perturbed, that kept it (the nominal one's breaking a
/// tie). The perturbed closings run pick by pick in the order above until one pick has all
/// `m + 1` on plan: it comes first, as it would were every pick closed perturbed; the picks
/// not reached keep their nominal count alone, so a search that checks on after it follows
/// what is known, at the cost of the closings that found it. The closings run in parallel;
/// the order does not depend on the threads.
///
/// While no pick's nominal closing keeps the plan, the first rule set's candidates are picked
/// on (`reach`, `[sim] order_reach`: `n` more, then twice as many, until `reach` have been
/// picked), and a further pick joins only if more than half of its closings (the nominal one
/// and, under `order_samples`, the perturbed) keep the plan.
fn ranked_by_closing(
    sel: &Selection,
    hand: &Hand,
    (n, reach, close, sampled): (usize, usize, CloseFn<'_>, Option<(usize, SampledFn<'_>)>),
    first: Preclosed,
) -> Vec<(usize, Preclosed)> {
    let features: Vec<_> = sel
        .candidates
        .iter()
        .map(|c| crate::pick::feature_of(&c.grasp, &sel.axes[c.axis_plan].aligned, hand))
        .collect();
    let mut picks = picks_by_rule_set(sel, &features, n);
    // The first is among the picks (`farthest_points` starts from it).
    let mut closed = close_picks(sel, &picks, first, close);
    if !closed.iter().any(|f| f.as_planned) {
        pick_on(
            sel,
            &features,
            (n, reach),
            (first, close, sampled),
            (&mut picks, &mut closed),
        );
    }
    let m = sampled.map_or(0, |(m, _)| m);
    let mut ranked: Vec<(usize, Preclosed)> = picks.into_iter().zip(closed).collect();
    // (checked first, closings on plan, nominal on plan): the first comes first where its
    // closings kept the plan; then the closings that kept it (the nominal one alone without
    // `order_samples`), the nominal one's breaking a tie.
    let sort = |ranked: &mut Vec<(usize, Preclosed)>| {
        let key = |i: usize, f: &Preclosed| {
            let on = usize::from(f.as_planned) + f.sampled_on_plan.unwrap_or(0);
            (i == 0 && on == m + 1, on, f.as_planned)
        };
        ranked.sort_by(|(i, a), (j, b)| {
            key(*j, b)
                .cmp(&key(*i, a))
                .then(a.shift_mm.floor().total_cmp(&b.shift_mm.floor()))
                .then(i.cmp(j))
        });
    };
    sort(&mut ranked);
    if let Some((m @ 1.., sampled)) = sampled {
        for (i, f) in &mut ranked {
            let c = &sel.candidates[*i];
            let on = *f
                .sampled_on_plan
                .get_or_insert_with(|| sampled(&sel.axes[c.axis_plan].aligned, &c.grasp));
            if f.as_planned && on == m {
                break;
            }
        }
        sort(&mut ranked);
    }
    ranked
}

/// The closings of `sel`'s candidates `picks` by `close`, in parallel (the first candidate's
/// is `first`, closed already).
fn close_picks(
    sel: &Selection,
    picks: &[usize],
    first: Preclosed,
    close: CloseFn<'_>,
) -> Vec<Preclosed> {
    use rayon::prelude::*;
    picks
        .par_iter()
        .map(|&i| {
            let c = &sel.candidates[i];
            if i == 0 {
                first
            } else {
                close(&sel.axes[c.axis_plan].aligned, &c.grasp)
            }
        })
        .collect()
}

/// None of the `n` picks kept its plan: picks on among the first rule set's candidates (the
/// farthest points of a larger set start with the smaller's), `n` more, then twice as many,
/// until `reach` have been picked or one taken in keeps its plan, and takes in, with their
/// closings, those that kept it in more than half of their closings (the nominal one and, under
/// `sampled`, the perturbed, run only where the nominal one kept it): a further pick off its
/// plan, or on it by chance, would only add draws to the picks that left it.
fn pick_on(
    sel: &Selection,
    features: &[crate::pick::Feature],
    (n, reach): (usize, usize),
    (first, close, sampled): (Preclosed, CloseFn<'_>, Option<(usize, SampledFn<'_>)>),
    (picks, closed): (&mut Vec<usize>, &mut Vec<Preclosed>),
) {
    use rayon::prelude::*;
    let m = sampled.map_or(0, |(m, _)| m);
    let (own, _) = by_first_rule_set(sel);
    let mut tried: std::collections::HashSet<usize> = picks.iter().copied().collect();
    let mut picked = n;
    while picked < reach && !closed.iter().any(|f| f.as_planned) {
        picked = (2 * picked).min(reach);
        let fresh: Vec<usize> = crate::pick::farthest_among(features, &own, picked)
            .into_iter()
            .filter(|i| tried.insert(*i))
            .collect();
        if fresh.is_empty() {
            break;
        }
        let mut fresh_closed = close_picks(sel, &fresh, first, close);
        if let Some((1.., sampled)) = sampled {
            let counts: Vec<Option<usize>> = fresh
                .par_iter()
                .zip(&fresh_closed)
                .map(|(&i, f)| {
                    let c = &sel.candidates[i];
                    f.as_planned
                        .then(|| sampled(&sel.axes[c.axis_plan].aligned, &c.grasp))
                })
                .collect();
            for (f, on) in fresh_closed.iter_mut().zip(counts) {
                f.sampled_on_plan = on;
            }
        }
        for (i, f) in fresh.into_iter().zip(fresh_closed) {
            let on = usize::from(f.as_planned) + f.sampled_on_plan.unwrap_or(0);
            if f.as_planned && 2 * on > m + 1 {
                picks.push(i);
                closed.push(f);
            }
        }
    }
}

/// `n` candidates of `sel` picked for diversity ([`crate::pick::farthest_among`] over
/// `features`) among those of the first candidate's rule set (the first always among them),
/// and `n` more among those of the rule sets planned after it: a search that checks more
/// candidates than the first rule set gave goes on to the next, so the picks cover what it
/// could reach without the first rule set's being crowded out (a pinch can give hundreds of
/// candidates where the rules before it gave four).
fn picks_by_rule_set(sel: &Selection, features: &[crate::pick::Feature], n: usize) -> Vec<usize> {
    let (own, later) = by_first_rule_set(sel);
    let mut picks = crate::pick::farthest_among(features, &own, n);
    picks.extend(crate::pick::farthest_among(features, &later, n));
    picks
}

/// The indices of `sel`'s candidates of the first candidate's rule set, and of the rule sets
/// planned after it (which follow them in search order).
pub fn by_first_rule_set(sel: &Selection) -> (Vec<usize>, Vec<usize>) {
    let first = sel.candidates.first().map(|c| c.grasp.rules);
    (0..sel.candidates.len()).partition(|&i| Some(sel.candidates[i].grasp.rules) == first)
}

/// Puts the `ranked` candidates of `sel` first, in that order and with their closings, then
/// the others in search order up to `collect` in all; returns each one's place in search order.
fn put_first(sel: &mut Selection, ranked: &[(usize, Preclosed)], collect: usize) -> Vec<usize> {
    let mut slots: Vec<Option<Candidate>> = std::mem::take(&mut sel.candidates)
        .into_iter()
        .map(Some)
        .collect();
    let mut places = Vec::new();
    for (i, figures) in ranked {
        if let Some(mut c) = slots[*i].take() {
            c.preclosed = Some(*figures);
            sel.candidates.push(c);
            places.push(*i);
        }
    }
    let rest = collect.saturating_sub(sel.candidates.len());
    let others = slots
        .into_iter()
        .enumerate()
        .filter_map(|(i, c)| Some((i, c?)));
    for (i, c) in others.take(rest) {
        sel.candidates.push(c);
        places.push(i);
    }
    places
}

/// Checks candidate `i` again with `recheck` if a failed closing decided its check.
#[allow(clippy::type_complexity)]
fn recheck_if_closing_decided(
    sel: &mut Selection,
    i: usize,
    recheck: &dyn Fn(&AlignedObject, &Grasp) -> SimOutcome,
) {
    let c = &sel.candidates[i];
    if c.check.as_ref().is_some_and(SimOutcome::decided_by_closing) {
        let full = recheck(&sel.axes[c.axis_plan].aligned, &c.grasp);
        sel.candidates[i].check = Some(full);
    }
}

/// Under `[sim] closing_decides`, a candidate whose closing left the plan got a provisional
/// `slip` or `drop` by where the object was when the closing ended; the full check holds it
/// under gravity. That changes nothing while some candidate succeeds ([`choose`] takes the
/// first that did), but when none does, [`choose`] takes the first that held (as planned,
/// else not), else the first that slipped: so, in order, each such candidate is checked again
/// in full until the first `hold` is known (or all are), and [`choose`] then reports what the
/// full checks would have (the same candidate, the same check).
#[allow(clippy::type_complexity)]
fn recheck_failed_closings(
    sel: &mut Selection,
    recheck: &dyn Fn(&AlignedObject, &Grasp) -> SimOutcome,
) {
    let sampled_hold = sel.candidates.iter().any(|c| {
        c.check
            .as_ref()
            .and_then(|o| o.robust.as_ref())
            .is_some_and(|r| r.counts.hold > 0)
    });
    if has_hold(sel) || sampled_hold {
        return;
    }
    for i in 0..sel.candidates.len() {
        recheck_if_closing_decided(sel, i, recheck);
        if sel.candidates[i]
            .check
            .as_ref()
            .is_some_and(|o| o.verdict == Verdict::Hold)
        {
            return;
        }
    }
}

/// The graded domain of `rules` on `aligned`. The pinch pass searches the extended rules'
/// graded domain again (it changes only how a finger is placed): it is reused rather than
/// sliced and graded a second time. With a domain cache, stage 1 comes from it.
fn graded_for(
    sel: &Selection,
    p: &SelectParams,
    rules: RuleSet,
    aligned: &AlignedObject,
    t: &mut StageTimings,
) -> plan::GradedDomain {
    let axis = aligned.axis;
    let extended = sel
        .axes
        .iter()
        .find(|a| a.rules == RuleSet::Extended && a.aligned.axis == axis)
        .filter(|_| rules.pinches())
        .map(|a| a.graded.clone());
    // Another rule set's domain of this axis: its vertical slices are this one's.
    let sliced = sel
        .axes
        .iter()
        .find(|a| a.aligned.axis == axis)
        .map(|a| &a.graded.domain);
    match (extended, p.domains) {
        (Some(graded), _) => graded,
        (None, None) => match sliced {
            Some(other) => plan::grade_domain_reusing(
                other,
                &aligned.mesh,
                p.hand,
                p.planner,
                p.friction,
                rules,
                t,
            ),
            None => plan::grade_domain_with(&aligned.mesh, p.hand, p.planner, p.friction, rules, t),
        },
        (None, Some(cache)) => {
            let key = (
                axis,
                rules.domain_rules(),
                p.planner.angular_step_deg.to_bits(),
                p.planner.height_step_mm.to_bits(),
            );
            let domain = cache
                .borrow_mut()
                .entry(key)
                .or_insert_with(|| {
                    plan::stage1_with(&aligned.mesh, p.hand, p.planner, rules.domain_rules())
                })
                .clone();
            plan::grade_built_with(domain, p.hand, p.planner, p.friction, rules, t)
        }
    }
}

/// Searches one axis under one rule set for at most `budget` candidates, adding each feasible
/// grasp to `sel` (checked while checks remain and none has held) until enough is known.
fn search_axis(
    sel: &mut Selection,
    p: &SelectParams,
    (aligned, arc, rules, graded): (
        AlignedObject,
        Option<AlignedObject>,
        RuleSet,
        plan::GradedDomain,
    ),
    budget: usize,
    (collect, stop): (usize, Option<&std::cell::Cell<bool>>),
    t: &mut StageTimings,
) -> AxisPlan {
    let slot = sel.axes.len();
    let t0 = std::time::Instant::now();
    let mut found = 0;
    let mut stopped = false;
    let available = candidate_count(&graded, p.planner);
    // Adds a feasible grasp, checked while checks remain and none has held; false once enough
    // is known.
    let take = |sel: &mut Selection, g: Grasp, thesis_place: usize| {
        let check = match p.max_checked {
            Some(max) if sel.checked() < max && !has_hold(sel) => Some((p.check)(&aligned, &g)),
            _ => None,
        };
        sel.candidates.push(Candidate {
            axis_plan: slot,
            grasp: g,
            check,
            thesis_place,
            preclosed: None,
        });
        !is_done(sel, p, collect) && !stop.is_some_and(std::cell::Cell::get)
    };
    // The planner sees the arc of a ring; the check, the whole object in the arc's frame.
    let planned_on = arc.as_ref().unwrap_or(&aligned);
    let factors = OrderFactors::of(p.planner);
    let mut push = NetPush::new(p, rules, planned_on);
    let (tried, mut rejections) = if factors.is_thesis() {
        search_with(
            &planned_on.mesh,
            p.hand,
            &graded,
            p.planner,
            rules,
            budget,
            |g| {
                if push.pushes_out(&g) {
                    return true;
                }
                found += 1;
                stopped = !take(sel, g, found - 1);
                !stopped
            },
        )
    } else {
        let taken = |g, i| take(sel, g, i);
        let searched;
        (found, stopped, searched) =
            reordered(p, (planned_on, &graded, rules), budget, &mut push, taken);
        searched
    };
    t.search += crate::plan::timings::ms(t0);
    if push.rejected > 0 {
        rejections.insert(plan::search::Rejection::NetPush, push.rejected);
    }
    AxisPlan {
        aligned,
        rules,
        graded,
        candidates_tried: tried,
        rejections,
        grasps_found: found,
        exhausted: !stopped && tried == available,
        candidates_available: available,
        budget_stopped: !stopped && tried < available,
    }
}

/// Issue 58's order: the axis's feasible grasps (those `push` keeps) in the thesis's order,
/// then given to `take` with their thesis place by falling score ([`crate::plan::order`]) until
/// it returns false; the candidate budget bounds the search as before. Returns the grasps
/// found, whether `take` stopped the search, and the candidates tried and the rejections.
fn reordered(
    p: &SelectParams,
    (planned_on, graded, rules): (&AlignedObject, &plan::GradedDomain, RuleSet),
    budget: usize,
    push: &mut NetPush,
    mut take: impl FnMut(Grasp, usize) -> bool,
) -> (usize, bool, (usize, BTreeMap<Rejection, usize>)) {
    let (mut all, searched) = all_feasible(p, planned_on, graded, rules, budget);
    all.retain(|g| !push.pushes_out(g));
    let found = all.len();
    let order = crate::plan::order::reorder(&all, planned_on, p.hand, &OrderFactors::of(p.planner));
    let mut slots: Vec<Option<Grasp>> = all.into_iter().map(Some).collect();
    let stopped = order
        .into_iter()
        .filter_map(|i| Some((slots[i].take()?, i)))
        .any(|(g, i)| !take(g, i));
    (found, stopped, searched)
}

/// `[planner] net_push_cone` over one axis's search: under the rules beyond the thesis, a grasp
/// whose net push along the axis leaves the friction cone is rejected ([`plan::squeeze`]).
struct NetPush<'a> {
    on: bool,
    surface: plan::squeeze::Surface<'a>,
    hand: &'a Hand,
    friction: f64,
    /// The grasps rejected so far.
    rejected: usize,
}

impl<'a> NetPush<'a> {
    fn new(p: &SelectParams<'a>, rules: RuleSet, planned_on: &'a AlignedObject) -> NetPush<'a> {
        NetPush {
            on: p.planner.net_push_cone && rules.is_extended(),
            surface: plan::squeeze::Surface::new(&planned_on.mesh),
            hand: p.hand,
            friction: p.friction,
            rejected: 0,
        }
    }

    /// Whether the rule rejects `g` (counted).
    fn pushes_out(&mut self, g: &Grasp) -> bool {
        let contacts = || plan::contacts::planned_contacts(g, self.hand);
        let out = self.on
            && plan::squeeze::net_push_lean(&self.surface, &contacts())
                .is_some_and(|lean| lean > self.friction);
        self.rejected += usize::from(out);
        out
    }
}

/// Every feasible grasp of `graded` in the thesis's search order, within `budget` candidates;
/// with the candidates tried and the rejections.
fn all_feasible(
    p: &SelectParams,
    aligned: &AlignedObject,
    graded: &plan::GradedDomain,
    rules: RuleSet,
    budget: usize,
) -> (Vec<Grasp>, (usize, BTreeMap<Rejection, usize>)) {
    let mut all = Vec::new();
    let searched = search_with(
        &aligned.mesh,
        p.hand,
        graded,
        p.planner,
        rules,
        budget,
        |g| {
            all.push(g);
            true
        },
    );
    (all, searched)
}

/// Returns true if and only if enough is known: without the check, `collect` grasps; with it,
/// a grasp that holds (or the check budget spent) and `collect` grasps.
fn is_done(sel: &Selection, p: &SelectParams, collect: usize) -> bool {
    let collected = sel.candidates.len() >= collect;
    match p.max_checked {
        None => collected,
        Some(max) => collected && (has_hold(sel) || sel.checked() >= max),
    }
}

/// The extended rules are tried when the thesis's rules found nothing on any axis, or, with the
/// physics check, when nothing they found held and checks remain; without it, while fewer than
/// [`SelectParams::plan_reach`] candidates have been found.
fn wants_extended(sel: &Selection, p: &SelectParams) -> bool {
    if sel.candidates.is_empty() {
        return true;
    }
    match p.max_checked {
        None => sel.candidates.len() < p.plan_reach,
        Some(max) => !has_hold(sel) && sel.checked() < max,
    }
}

/// Returns true if and only if a checked candidate succeeded ([`SimOutcome::succeeded`]: it
/// held as planned, or under `[sim] choose = "robust"` the lower bound of its probability of a
/// hold as planned passed).
fn has_hold(sel: &Selection) -> bool {
    sel.candidates
        .iter()
        .any(|c| c.check.as_ref().is_some_and(SimOutcome::succeeded))
}

/// The first candidate that succeeded (held as planned; under `choose = "robust"`, the lower
/// bound of its probability of a hold as planned passed); else, when candidates were sampled,
/// the one ranked highest by its samples ([`crate::sim::Robust::rank`]: the lower bound of a
/// hold as planned, then of a hold; the first on a tie) if any sample of it held; else the
/// first by the preference held as planned, held, slip, drop (issue 55), else the first found.
fn choose(candidates: &[Candidate]) -> Option<usize> {
    if let Some(i) = candidates
        .iter()
        .position(|c| c.check.as_ref().is_some_and(SimOutcome::succeeded))
    {
        return Some(i);
    }
    let sampled = candidates
        .iter()
        .enumerate()
        .filter_map(|(i, c)| Some((i, c.check.as_ref()?.robust.as_ref()?)))
        .filter(|(_, r)| r.counts.hold > 0);
    let best = sampled.max_by(|(i, a), (j, b)| {
        let (ra, rb) = (a.rank(), b.rank());
        ra.iter()
            .zip(&rb)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(j.cmp(i))
    });
    if let Some((i, _)) = best {
        return Some(i);
    }
    let checked = candidates
        .iter()
        .enumerate()
        .filter_map(|(i, c)| Some((i, c.check.as_ref()?.preference())));
    checked
        .min_by_key(|&(i, p)| (p, i))
        .map(|(i, _)| i)
        .or_else(|| (!candidates.is_empty()).then_some(0))
}

/// Why a scenario's `[sim] override_angles` cannot be checked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OverrideError {
    /// The graded domain has no indexed elevation to put the palm on.
    #[error("override_angles: the object has no indexed elevation")]
    NoElevation,
    /// The palm could not be placed at the chosen elevation.
    #[error("override_angles: palm placement failed: {0:?}")]
    PalmPlacement(plan::palm::PalmRejection),
}

/// The hand pose for a scenario whose joint angles are fixed by `[sim] override_angles`: the
/// palm at approach 0 and pitch 0 on indexed elevation `override_index` (default: the middle
/// one) of the graded domain. (Placed here, not in sim/, so that the physics check does not
/// call the planner: issue 31.)
///
/// # Errors
/// [`OverrideError`]: why the grasp cannot be checked.
pub fn override_pose(
    mesh: &Mesh,
    hand: &Hand,
    graded: &GradedDomain,
    override_index: Option<usize>,
    angles: &[[f64; 2]],
) -> Result<crate::sim::SimHand, OverrideError> {
    let n = graded.domain.elevations.len();
    if n == 0 {
        return Err(OverrideError::NoElevation);
    }
    let index = override_index.unwrap_or(n.div_ceil(2)).clamp(1, n);
    let z1 = graded.domain.elevations[index - 1];
    let palm =
        plan::palm::place_palm(mesh, hand, z1, 0.0, 0.0).map_err(OverrideError::PalmPlacement)?;
    Ok(crate::sim::SimHand {
        origin_mm: palm.origin,
        axes: palm.axes,
        theta_deg: angles.to_vec(),
        planned_contacts_mm: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The D40's candidates planned without a check, `plan_reach` as given.
    fn planned(reach: usize) -> (Selection, Vec<RuleSet>) {
        let mesh = crate::mesh::primitives::cylinder(40.0, 124.0);
        planned_with(&mesh, PlannerParams::default(), 0.5, reach)
    }

    /// `mesh`'s candidates planned without a check under `planner` and `friction`, `plan_reach`
    /// as given.
    fn planned_with(
        mesh: &Mesh,
        planner: PlannerParams,
        friction: f64,
        reach: usize,
    ) -> (Selection, Vec<RuleSet>) {
        let props = crate::mesh::mass_properties(mesh);
        let hand = crate::hand::thesis_for_tests();
        let no_check = |_: &AlignedObject, _: &Grasp| -> SimOutcome {
            unreachable!("planned without a check")
        };
        let sel = select(
            mesh,
            &props,
            &SelectParams {
                hand: &hand,
                planner: &planner,
                friction,
                collect: 100_000,
                max_checked: None,
                check: &no_check,
                recheck: None,
                probe: None,
                domains: None,
                frame: FrameRule::default(),
                order_by_closing: None,
                order_samples: None,
                plan_reach: reach,
                order_reach: 0,
            },
            &mut StageTimings::default(),
        );
        let rules = sel.candidates.iter().map(|c| c.grasp.rules).collect();
        (sel, rules)
    }

    #[test]
    fn a_plan_without_checks_goes_past_the_thesis_rules_only_below_its_reach() {
        let (thesis, rules) = planned(0);
        let n = thesis.candidates.len();
        assert!(n > 8, "the D40 has {n} candidates under the thesis's rules");
        assert!(rules.iter().all(|r| *r == RuleSet::Thesis));
        // A reach the thesis's candidates meet: the same plan.
        let (same, _) = planned(n);
        assert_eq!(same.candidates.len(), n);
        // One more than they give: the extended rules' candidates follow the thesis's, which
        // stay first and the same.
        let (more, rules) = planned(n + 1);
        assert!(
            more.candidates.len() > n,
            "{} candidates",
            more.candidates.len()
        );
        assert!(rules[..n].iter().all(|r| *r == RuleSet::Thesis));
        assert!(rules[n..].iter().all(|r| r.is_extended()));
        for (a, b) in thesis.candidates.iter().zip(&more.candidates) {
            assert_eq!(a.grasp.elevation_index, b.grasp.elevation_index);
            assert_eq!(a.grasp.approach_angle_deg, b.grasp.approach_angle_deg);
            assert_eq!(a.thesis_place, b.thesis_place);
        }
    }

    #[test]
    fn the_net_push_cone_rejects_the_extended_rules_grasps_that_push_a_cone_out() {
        // A cone whose side leans 30 degrees from its axis, past the friction cone (17 degrees
        // at mu = 0.3): the thesis's rules grade its side ungraspable, the extended rules plan
        // on it.
        let cone = crate::mesh::primitives::frustum(95.0, 25.0, 60.6);
        let lean = |sel: &Selection, c: &Candidate| {
            let aligned = &sel.axes[c.axis_plan].aligned;
            let contacts =
                plan::contacts::planned_contacts(&c.grasp, &crate::hand::thesis_for_tests());
            plan::squeeze::net_push_lean(&plan::squeeze::Surface::new(&aligned.mesh), &contacts)
                .unwrap()
        };
        let rejected = |sel: &Selection| -> usize {
            sel.axes
                .iter()
                .filter_map(|a| a.rejections.get(&Rejection::NetPush))
                .sum()
        };
        let (off, _) = planned_with(&cone, PlannerParams::default(), 0.3, 100_000);
        let pushing = off
            .candidates
            .iter()
            .filter(|c| c.grasp.rules.is_extended() && lean(&off, c) > 0.3)
            .count();
        assert!(pushing > 0, "no extended grasp pushes the cone out");
        assert_eq!(rejected(&off), 0);
        let on = PlannerParams {
            net_push_cone: true,
            ..PlannerParams::default()
        };
        let (on, _) = planned_with(&cone, on, 0.3, 100_000);
        assert!(rejected(&on) >= pushing, "{} < {pushing}", rejected(&on));
        for c in on.candidates.iter().filter(|c| c.grasp.rules.is_extended()) {
            let l = lean(&on, c);
            assert!(l <= 0.3, "kept a grasp whose net push leans {l}");
        }
    }
}
