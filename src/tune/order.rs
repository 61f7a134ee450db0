//! `grasp-sim tune --labels FILE`: the order's significance factors ([`crate::plan::order`])
//! tuned against labelled candidates (issue 58), with k-fold cross-validation over objects.
//!
//! A label file (`grasp-sim label`) holds, per object, many diverse candidates with their place
//! in the thesis's order, the order's terms and their hold probability. Reordering needs no
//! new simulation: a setting of the factors scores each labelled candidate and the objective
//! is read off the labels.
//!
//! - `first`: the mean, over objects, of the hold probability of the candidate the setting
//!   puts first: the best-scored labelled candidate of the first axis plan (where the planner
//!   with `max_checked = 1` would take its grasp). The thesis's first is always labelled.
//! - `checks`: the mean expected number of candidates checked before one holds, over objects
//!   with a candidate that holds: the labelled candidates in the setting's order (axis plans in
//!   the search's order, each by falling score), each holding with its probability, at most
//!   [`MAX_CHECKED`] checked.
//! - `auc`: the probability that a candidate that holds as planned (`as_planned_probability`
//!   at least 0.5) scores above one that does not, over the candidates of each object, pooled.
//!
//! Two orders can be measured ([`Order`]). `grade`: the planner's grade alone, the order of a
//! search without `[sim] order_by_closing`; its AUC is the score's. `search` (the default): the
//! order a run's search checks them in, read off each label's nominal check (its closing is
//! the one the search runs). The first by the grade is checked first where its closing kept
//! the plan, and the others follow in the order their closings give (as planned first, then
//! the shift in whole millimetres, then the grade); where its closing left the plan it is
//! ranked among them as one off plan. Its AUC is by place in that order. The factors then
//! decide the first candidate and the ties among the closings.
//!
//! The search is coordinate descent over the five factors with a shrinking step (8, 4, ..., 1/8),
//! from the thesis's order (every factor 0). It is chosen over a grid, which grows as the
//! step count to the fourth power, and over CMA-ES or a Bayesian search, which need random
//! draws and many more evaluations: the objective costs microseconds, is piecewise constant in
//! the factors (only the order counts), and a coordinate step that does not strictly improve
//! it is not taken, so the search is deterministic and stays at 0 where the labels say nothing.
//!
//! Cross-validation: the objects are dealt into `folds` by a hash of their name; each fold's
//! objects are scored with the factors tuned on the other folds. The held-out score, never seen
//! by the tuning that scores it, is what decides adoption; the factors written are those tuned
//! on every object.

use crate::plan::order::{OrderFactors, OrderTerms, NAMES, TERMS};
use anyhow::Context;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// The candidates checked at most per object (the default `[sim] max_checked`).
pub const MAX_CHECKED: usize = 8;

/// What `tune --labels` optimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Objective {
    /// The first candidate's mean hold probability.
    First,
    /// The expected candidates checked before a hold (fewer is better).
    Checks,
    /// The AUC of the score against a hold as planned.
    Auc,
}

impl Objective {
    /// The objective named `s`.
    pub fn parse(s: &str) -> Result<Objective, String> {
        match s {
            "first" => Ok(Objective::First),
            "checks" => Ok(Objective::Checks),
            "auc" => Ok(Objective::Auc),
            _ => Err(format!("`{s}` is not an objective (first, checks, auc)")),
        }
    }
}

/// One labelled candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Labelled {
    /// Its axis plan (0: the first searched).
    pub axis_plan: usize,
    /// Its place in that plan's thesis order.
    pub place: usize,
    /// The grasps that plan found.
    pub found: usize,
    /// The order's terms.
    pub terms: OrderTerms,
    /// Its hold probability.
    pub hold: f64,
    /// Its probability of a hold as planned.
    pub as_planned: f64,
    /// What its nominal check's closing did (`fidelity`); `None` in a file without it.
    pub closing: Option<LabelledClosing>,
}

/// What a labelled candidate's nominal closing did, gravity off: what `[sim]
/// order_by_closing` ranks by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelledClosing {
    /// The closing kept the plan (`fidelity.as_planned`).
    pub as_planned: bool,
    /// The object's shift over the closing `[mm]` (`fidelity.shift_mm`).
    pub shift_mm: f64,
}

/// The order measured and tuned (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Order {
    /// The planner's grade alone.
    Grade,
    /// The order a run's search checks the candidates in (`[sim] order_by_closing`).
    Search,
}

impl Order {
    /// The order named `s`.
    pub fn parse(s: &str) -> Result<Order, String> {
        match s {
            "grade" => Ok(Order::Grade),
            "search" => Ok(Order::Search),
            _ => Err(format!("`{s}` is not an order (grade, search)")),
        }
    }
}

/// Every object's labelled candidates, by object name.
pub type Labels = BTreeMap<String, Vec<Labelled>>;

/// Reads a label file: the grasp lines with a grade (error and ungraspable lines left out).
///
/// # Errors
/// The file cannot be read, or a grasp line lacks its grade's terms (a file from before them).
pub fn read_labels(path: &Path) -> anyhow::Result<Labels> {
    let bytes = crate::files::read_regular(path, crate::files::MAX_RESULTS_BYTES)
        .with_context(|| format!("{}", path.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    let mut out = Labels::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let v = crate::files::parse_json_line(line)
            .map_err(|e| anyhow::anyhow!("{}: line {}: {e}", path.display(), i + 1))?;
        if v.get("error").is_some() || v.get("hold_probability").is_none() {
            continue;
        }
        let g = &v["grade"];
        let n = |k: &str| g[k].as_u64().map(|x| x as usize);
        let t = |k: &str| g["terms"][k].as_f64();
        let parsed = (|| {
            Some(Labelled {
                axis_plan: n("axis_plan")?,
                place: n("place")?,
                found: n("found")?,
                terms: OrderTerms::from_array([
                    t("centred")?,
                    t("opposed")?,
                    t("spread")?,
                    t("margin")?,
                    t("even")?,
                ]),
                hold: v["hold_probability"].as_f64()?,
                as_planned: v["as_planned_probability"].as_f64()?,
                closing: (|| {
                    Some(LabelledClosing {
                        as_planned: v["fidelity"]["as_planned"].as_bool()?,
                        shift_mm: v["fidelity"]["shift_mm"].as_f64()?,
                    })
                })(),
            })
        })();
        let l = parsed.ok_or_else(|| {
            anyhow::anyhow!(
                "{}: line {}: no `grade` with `axis_plan`, `place`, `found` and `terms` (label it again with this version)",
                path.display(),
                i + 1
            )
        })?;
        let object = v["object"].as_str().unwrap_or("").to_string();
        out.entry(object).or_default().push(l);
    }
    Ok(out)
}

/// The candidates of one object in the order `f` gives them: axis plans in search order, each
/// by falling score (ties: the thesis's place).
fn ordered<'a>(cands: &'a [Labelled], f: &OrderFactors) -> Vec<&'a Labelled> {
    let mut v: Vec<(&Labelled, f64)> = cands
        .iter()
        .map(|c| (c, f.score(c.place, c.found, &c.terms)))
        .collect();
    v.sort_by(|(a, sa), (b, sb)| {
        a.axis_plan
            .cmp(&b.axis_plan)
            .then(sb.total_cmp(sa))
            .then(a.place.cmp(&b.place))
    });
    v.into_iter().map(|(c, _)| c).collect()
}

/// The candidates of one object in the order `order` gives them with the factors `f`: under
/// [`Order::Search`] as `select::select_by_closing` checks them (the first by the grade first
/// if its closing kept the plan; the others, and the first if it did not as one off plan, by
/// their closings: as planned first, then the shift in whole millimetres, then the grade's
/// order); by the grade alone where a label has no closing.
fn ordered_as<'a>(cands: &'a [Labelled], f: &OrderFactors, order: Order) -> Vec<&'a Labelled> {
    let by_grade = ordered(cands, f);
    let closings: Option<Vec<LabelledClosing>> = by_grade.iter().map(|c| c.closing).collect();
    let (Order::Search, Some(closings)) = (order, closings) else {
        return by_grade;
    };
    let first_kept = closings.first().is_some_and(|k| k.as_planned);
    // (comes first, as planned, whole millimetres); the first, checked first where its closing
    // kept the plan, else one off plan.
    let key = |i: usize| {
        let k = closings[i];
        (
            i == 0 && first_kept,
            k.as_planned && i > 0,
            k.shift_mm.floor(),
        )
    };
    let mut places: Vec<usize> = (0..by_grade.len()).collect();
    places.sort_by(|&i, &j| {
        let (a, b) = (key(i), key(j));
        b.0.cmp(&a.0)
            .then(b.1.cmp(&a.1))
            .then(a.2.total_cmp(&b.2))
            .then(i.cmp(&j))
    });
    places.into_iter().map(|i| by_grade[i]).collect()
}

/// The three measures of the order `f` gives the objects `names` of `labels`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Measures {
    /// Objects measured.
    pub objects: usize,
    /// The first candidate's mean hold probability.
    pub first: f64,
    /// The mean expected candidates checked before a hold, over objects with one that holds.
    pub checks: f64,
    /// The AUC of the score against a hold as planned (pooled within objects; `NaN` where no
    /// object has both).
    pub auc: f64,
}

/// The measures of `f` on `names` in `order`.
pub fn measure(labels: &Labels, names: &[&str], f: &OrderFactors, order: Order) -> Measures {
    measure_with(labels, names, &|_| *f, order)
}

/// The measures on `names`, each object ordered by its own factors `f(name)` in `order`.
pub fn measure_with(
    labels: &Labels,
    names: &[&str],
    factors: &dyn Fn(&str) -> OrderFactors,
    order: Order,
) -> Measures {
    let (mut first, mut checks, mut holding) = (0.0, 0.0, 0usize);
    let (mut pairs, mut wins) = (0.0f64, 0.0f64);
    for name in names {
        let Some(cands) = labels.get(*name) else {
            continue;
        };
        let f = &factors(name);
        let ranked = ordered_as(cands, f, order);
        first += ranked.first().map_or(0.0, |c| c.hold);
        if cands.iter().any(|c| c.hold > 0.0) {
            // E[checks] = Σ_k P(the first k − 1 failed), at most MAX_CHECKED checks.
            let (mut e, mut none_yet) = (0.0, 1.0);
            for c in ranked.iter().take(MAX_CHECKED) {
                e += none_yet;
                none_yet *= 1.0 - c.hold;
            }
            checks += e;
            holding += 1;
        }
        // Within the object: every (holds as planned, does not) pair, by score (the grade's;
        // in the search's order, the place in it, earlier higher).
        let scores: Vec<(f64, bool)> = match order {
            Order::Grade => cands
                .iter()
                .map(|c| (f.score(c.place, c.found, &c.terms), c.as_planned >= 0.5))
                .collect(),
            Order::Search => ranked
                .iter()
                .enumerate()
                .map(|(k, c)| (-(k as f64), c.as_planned >= 0.5))
                .collect(),
        };
        for (sa, pa) in &scores {
            for (sb, pb) in &scores {
                if *pa && !*pb {
                    pairs += 1.0;
                    wins += if sa > sb {
                        1.0
                    } else if sa == sb {
                        0.5
                    } else {
                        0.0
                    };
                }
            }
        }
    }
    let n = names.len().max(1) as f64;
    Measures {
        objects: names.len(),
        first: first / n,
        checks: checks / holding.max(1) as f64,
        auc: if pairs > 0.0 { wins / pairs } else { f64::NAN },
    }
}

/// The value `objective` maximises.
fn value(m: &Measures, objective: Objective) -> f64 {
    match objective {
        Objective::First => m.first,
        Objective::Checks => -m.checks,
        Objective::Auc => {
            if m.auc.is_nan() {
                0.5
            } else {
                m.auc
            }
        }
    }
}

/// The factors coordinate descent finds on `names` (see the module docs).
pub fn descend(
    labels: &Labels,
    names: &[&str],
    objective: Objective,
    order: Order,
) -> OrderFactors {
    let mut x = [0.0f64; TERMS];
    let mut best = value(
        &measure(labels, names, &OrderFactors::from_array(x), order),
        objective,
    );
    let mut step = 8.0;
    while step >= 0.125 {
        let mut improved = true;
        let mut rounds = 0;
        while improved && rounds < 50 {
            improved = false;
            rounds += 1;
            for k in 0..TERMS {
                for dir in [1.0, -1.0] {
                    let mut y = x;
                    y[k] = (y[k] + dir * step).clamp(
                        -crate::plan::order::MAX_FACTOR,
                        crate::plan::order::MAX_FACTOR,
                    );
                    let v = value(
                        &measure(labels, names, &OrderFactors::from_array(y), order),
                        objective,
                    );
                    // A strict gain, beyond float noise, or no move.
                    if v > best + 1e-12 {
                        best = v;
                        x = y;
                        improved = true;
                    }
                }
            }
        }
        step /= 2.0;
    }
    OrderFactors::from_array(x)
}

/// The fold of object `name` among `folds`: a hash of the name, so that the same object is
/// in the same fold whatever else the file holds.
pub fn fold_of(name: &str, folds: usize) -> usize {
    use sha2::{Digest, Sha256};
    let d = Sha256::digest(name.as_bytes());
    (u64::from_le_bytes([d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7]]) % folds as u64) as usize
}

/// One fold of the cross-validation.
#[derive(Debug, Clone, Serialize)]
pub struct FoldResult {
    /// The fold's number from 0.
    pub fold: usize,
    /// The objects held out.
    pub held_out: Vec<String>,
    /// The factors tuned on the other folds, by `[planner]` key.
    pub factors: BTreeMap<String, f64>,
    /// The tuned factors on the folds they were tuned on.
    pub train: Measures,
    /// The thesis's order on the same folds.
    pub train_thesis: Measures,
    /// The tuned factors on the fold held out.
    pub test: Measures,
    /// The thesis's order on the fold held out.
    pub test_thesis: Measures,
}

/// What `tune --labels` found.
#[derive(Debug, Clone, Serialize)]
pub struct OrderTuning {
    /// The objective.
    pub objective: Objective,
    /// The order measured.
    pub order: Order,
    /// The folds.
    pub folds: Vec<FoldResult>,
    /// Every object scored by the factors tuned without its fold: the cross-validated estimate.
    pub held_out: Measures,
    /// The thesis's order on every object.
    pub thesis: Measures,
    /// The factors tuned on every object (those written to planner.toml).
    pub factors: BTreeMap<String, f64>,
    /// Those factors on every object (in-sample: not an estimate).
    pub in_sample: Measures,
    /// True if and only if the held-out objective beats the thesis's order.
    pub generalizes: bool,
}

fn named(f: &OrderFactors) -> BTreeMap<String, f64> {
    NAMES
        .iter()
        .zip(f.as_array())
        .map(|(n, v)| (n.to_string(), v))
        .collect()
}

/// Tunes the factors on `labels` against `objective` with `folds`-fold cross-validation.
pub fn tune(labels: &Labels, objective: Objective, folds: usize, order: Order) -> OrderTuning {
    let folds = folds.max(2);
    let names: Vec<&str> = labels.keys().map(String::as_str).collect();
    let thesis = OrderFactors::default();
    let mut results = Vec::new();
    // Per object, the factors tuned without its fold.
    let mut held_factors: BTreeMap<&str, OrderFactors> = BTreeMap::new();
    for k in 0..folds {
        let (test, train): (Vec<&str>, Vec<&str>) =
            names.iter().partition(|n| fold_of(n, folds) == k);
        let f = descend(labels, &train, objective, order);
        for n in &test {
            held_factors.insert(n, f);
        }
        results.push(FoldResult {
            fold: k,
            held_out: test.iter().map(|s| s.to_string()).collect(),
            factors: named(&f),
            train: measure(labels, &train, &f, order),
            train_thesis: measure(labels, &train, &thesis, order),
            test: measure(labels, &test, &f, order),
            test_thesis: measure(labels, &test, &thesis, order),
        });
    }
    // The cross-validated estimate: each object under its own fold's factors.
    let held_out = measure_with(labels, &names, &|n| held_factors[n], order);
    let thesis_m = measure(labels, &names, &thesis, order);
    let all = descend(labels, &names, objective, order);
    OrderTuning {
        objective,
        order,
        folds: results,
        held_out,
        thesis: thesis_m,
        factors: named(&all),
        in_sample: measure(labels, &names, &all, order),
        generalizes: value(&held_out, objective) > value(&thesis_m, objective) + 1e-12,
    }
}

/// The tuned factors as a `[planner]` table a scenario or template can hold.
pub fn planner_toml(t: &OrderTuning) -> String {
    let mut s = format!(
        "# The order's factors tuned by `grasp-sim tune --labels` (objective {:?}, the {:?} \
         order); held out, the first candidate's mean hold probability {:.3} against the \
         thesis's {:.3}.\n[planner]\n",
        t.objective, t.order, t.held_out.first, t.thesis.first
    );
    if !t.generalizes {
        s.insert_str(
            0,
            "# Held out, these factors do not beat the thesis's (every factor 0) on the \
             objective: keep the thesis's.\n",
        );
    }
    for (k, v) in &t.factors {
        s.push_str(&format!("{k} = {v:?}\n"));
    }
    s
}

/// `tune --labels FILE --objective O --folds K --out DIR`: tunes, prints the table of the
/// folds (tuned beside the thesis's order, on the folds tuned on and on the one held out),
/// and writes `DIR/tune.json` and `DIR/planner.toml`. Returns the exit status (0).
///
/// # Errors
/// A label file that cannot be read or holds no labelled object, an output that cannot be
/// written.
pub fn run(
    labels: &Path,
    (objective, order): (Objective, Order),
    folds: usize,
    out: &Path,
) -> anyhow::Result<u8> {
    crate::pipeline::check_output_dir(out).context("--out")?;
    let l = read_labels(labels)?;
    if l.len() < folds.max(2) {
        anyhow::bail!(
            "{}: {} labelled objects, fewer than the {} folds",
            labels.display(),
            l.len(),
            folds.max(2)
        );
    }
    let t = tune(&l, objective, folds, order);
    print_table(labels, &l, &t, (objective, order));
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    crate::batch::journal::write_atomically(
        &out.join("tune.json"),
        format!("{}\n", crate::report::to_rounded_json(&t)?).as_bytes(),
    )?;
    crate::batch::journal::write_atomically(
        &out.join("planner.toml"),
        planner_toml(&t).as_bytes(),
    )?;
    eprintln!(
        "tune: wrote {} and {}",
        out.join("tune.json").display(),
        out.join("planner.toml").display()
    );
    Ok(0)
}

/// Prints [`run`]'s table: per fold, the tuned and the thesis's order on the folds tuned on and
/// on the one held out, then the held-out estimate over every object.
fn print_table(labels: &Path, l: &Labels, t: &OrderTuning, (objective, order): (Objective, Order)) {
    let m = |m: &Measures| format!("{:>6.3} {:>6.2} {:>6.3}", m.first, m.checks, m.auc);
    println!(
        "order tuned on {} ({} objects, {} candidates), objective {objective:?}, {} folds, measured in the {} order",
        labels.display(),
        l.len(),
        l.values().map(Vec::len).sum::<usize>(),
        t.folds.len(),
        match order {
            Order::Grade => "grade's (the planner's grade alone)",
            Order::Search => "search's (the grade's first, then the closings')",
        }
    );
    println!("columns: first-candidate hold probability, expected checks to a hold, AUC");
    println!(
        "{:>4} {:>7} | {:^20} | {:^20} | {:^20} | {:^20} | factors",
        "fold",
        "objects",
        "trained: tuned",
        "trained: thesis",
        "held out: tuned",
        "held out: thesis"
    );
    for f in &t.folds {
        println!(
            "{:>4} {:>7} | {} | {} | {} | {} | {}",
            f.fold,
            f.held_out.len(),
            m(&f.train),
            m(&f.train_thesis),
            m(&f.test),
            m(&f.test_thesis),
            f.factors
                .iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    println!(
        "held out, every object under the factors tuned without it: {} (thesis {}); {}",
        m(&t.held_out),
        m(&t.thesis),
        if t.generalizes {
            "the tuned order generalizes"
        } else {
            "the tuned order does not beat the thesis's on objects it did not see: keep the thesis's"
        }
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(place: usize, spread: f64, hold: f64) -> Labelled {
        Labelled {
            axis_plan: 0,
            place,
            found: 100,
            terms: OrderTerms::from_array([0.0, 0.0, spread, 0.0, 0.0]),
            hold,
            as_planned: hold,
            closing: None,
        }
    }

    /// Objects made for it: the thesis's first never holds, and the candidate that holds has
    /// the larger spread. Tuning finds a positive `sf_spread`, which puts the holding candidate
    /// first on objects it never saw.
    #[test]
    fn a_tuned_factor_moves_the_candidate_that_holds_first() {
        let mut labels = Labels::new();
        for i in 0..10 {
            labels.insert(
                format!("object_{i}"),
                vec![
                    cand(0, 0.2, 0.0),
                    cand(10 + i, 0.3, 0.1),
                    cand(40 + i, 0.8, 1.0),
                ],
            );
        }
        let thesis = measure(
            &labels,
            &labels.keys().map(String::as_str).collect::<Vec<_>>(),
            &OrderFactors::default(),
            Order::Search,
        );
        assert_eq!(thesis.first, 0.0);
        let t = tune(&labels, Objective::First, 5, Order::Search);
        assert!(t.factors["sf_spread"] > 0.0, "{:?}", t.factors);
        assert_eq!(t.held_out.first, 1.0);
        assert!(t.generalizes);
        assert!(planner_toml(&t).starts_with("# The order's factors tuned"));
        assert_eq!(t.held_out.checks, 1.0);
        assert!((thesis.checks - 2.9).abs() < 1e-12, "{}", thesis.checks);
    }

    /// Labels that say nothing (every candidate alike) leave every factor at 0.
    #[test]
    fn labels_that_say_nothing_leave_the_thesis_order() {
        let mut labels = Labels::new();
        for i in 0..6 {
            labels.insert(format!("o{i}"), vec![cand(0, 0.2, 0.5), cand(5, 0.9, 0.5)]);
        }
        let t = tune(&labels, Objective::First, 3, Order::Search);
        assert!(t.factors.values().all(|&v| v == 0.0), "{:?}", t.factors);
        assert!(!t.generalizes);
        assert!(planner_toml(&t).starts_with("# Held out, these factors do not beat"));
    }

    fn closed(place: usize, hold: f64, as_planned: bool, shift_mm: f64) -> Labelled {
        Labelled {
            closing: Some(LabelledClosing {
                as_planned,
                shift_mm,
            }),
            ..cand(place, 0.5, hold)
        }
    }

    /// The search's order, as `select_by_closing` checks: the grade's first when its closing
    /// kept the plan, then the closings' order (as planned first, then the shift in whole
    /// millimetres, then the grade's order), the first among them as one off plan where its
    /// closing left it; the AUC by place.
    #[test]
    fn the_search_order_checks_the_first_then_by_the_closings() {
        let object = |first: Labelled| {
            let mut labels = Labels::new();
            labels.insert(
                "o".into(),
                vec![
                    first,
                    closed(1, 0.0, false, 12.0),
                    closed(2, 0.5, true, 1.9),
                    closed(3, 1.0, true, 1.2),
                    closed(4, 0.75, true, 0.4),
                ],
            );
            labels
        };
        let f = OrderFactors::default();
        let places = |labels: &Labels, order| -> Vec<usize> {
            ordered_as(&labels["o"], &f, order)
                .iter()
                .map(|c| c.place)
                .collect()
        };
        // The first closed as planned: it stays first, the others by their closings (0.4 mm
        // first; 1.9 and 1.2 both round down to 1 mm, the grade's order between them).
        let held = object(closed(0, 1.0, true, 3.0));
        assert_eq!(places(&held, Order::Grade), [0, 1, 2, 3, 4]);
        assert_eq!(places(&held, Order::Search), [0, 4, 2, 3, 1]);
        // The first left its plan by 30 mm: after every pick, by its shift.
        let left = object(closed(0, 0.25, false, 30.0));
        assert_eq!(places(&left, Order::Search), [4, 2, 3, 1, 0]);
        let m = measure(&left, &["o"], &f, Order::Search);
        assert_eq!(m.first, 0.75);
        // Holding as planned (p >= 0.5): places 4, 2, 3, all before 1 and 0.
        assert_eq!(m.auc, 1.0);
        // E[checks] = 1 + 0.25 + 0.25 · 0.5 (then place 3 holds surely).
        assert!((m.checks - 1.375).abs() < 1e-12, "{}", m.checks);
        // By the grade: every holding candidate scores below both that do not (place order).
        assert_eq!(measure(&left, &["o"], &f, Order::Grade).auc, 0.0);
        // A first whose closing kept the plan but did not hold is still checked first.
        let fell = object(closed(0, 0.0, true, 0.2));
        assert_eq!(places(&fell, Order::Search), [0, 4, 2, 3, 1]);
        assert_eq!(measure(&fell, &["o"], &f, Order::Search).first, 0.0);
    }
}
