//! The hold probability (issue 34, docs/SIM.md "Hold probability"): the chosen grasp checked
//! again under `[sim] samples` perturbations of what a real grasp is uncertain about, the
//! object's pose relative to the hand before closing, friction, mass and motor torque, each
//! drawn from `[sim] seed` so that the same inputs give the same samples.
//!
//! Sample `k`'s perturbation depends only on the seed, `k` and the ranges (not on the number of
//! samples, nor on the threads): `[sim] replay_sample = k` runs the main check under it, and
//! the MJCF export writes it for MuJoCo. The samples run in parallel, each its own check on the
//! one object collider (its convex decomposition is made once per run: [`ObjectShape`] is
//! shared by reference). Under `six` a sample closes the hand once and holds each direction from
//! a copy of its closed scene (the `fast` protocol's [`super::protocol::Closed`]); no closing is
//! shared between samples, since every sample moves the object relative to the hand.
//!
//! The hold probability is the fraction of samples whose every gravity direction held, with its
//! 95 % Wilson score interval: with few samples an all-held count is far from certainty (8 of 8
//! gives a lower bound of 0.68), which is what `[expect] min_hold_probability` judges. The
//! probability of a hold as planned (issue 55) counts, of the same samples, those that held and
//! whose closing kept the planned grasp; `[expect] min_as_planned_probability` and `[sim] choose
//! = "robust"` judge its interval.

use super::outcome::{SimOutcome, Verdict};
use super::params::{RobustParams, SimParams};
use super::scene::{Case, SimHand};
use nalgebra::{UnitQuaternion, Vector3};
use rayon::prelude::*;
use std::time::Instant;

/// One sample's perturbation: how the object sits relative to the hand, and how friction, the
/// object's mass and the motors' torque differ from the scenario's. Reported as
/// `sim.robust.first_failure.perturbation` (and `sim.replay`).
#[derive(Debug, Clone, PartialEq)]
pub struct Perturbation {
    /// The sample's index (`[sim] replay_sample` replays it).
    pub sample: usize,
    /// The object's translation relative to the hand before closing, aligned frame `[mm]`.
    pub offset_mm: [f64; 3],
    /// The object's rotation relative to the hand before closing, about its centre of mass,
    /// as a rotation vector (axis times angle), aligned frame `[deg]`.
    pub rotation_deg: [f64; 3],
    /// The friction coefficient's multiplier (every contact).
    pub friction_scale: f64,
    /// The object mass's multiplier.
    pub mass_scale: f64,
    /// The finger motors' torque limit's multiplier.
    pub torque_scale: f64,
}

/// SplitMix64's finaliser: a well-mixed 64-bit value of `x` (Steele, Lea and Flood 2014).
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Draw `i` of sample `k` under `seed`: uniform in `[0, 1)`, from the top 53 bits.
fn unit(seed: u64, k: usize, i: u64) -> f64 {
    let x = mix(mix(mix(seed) ^ k as u64) ^ i);
    (x >> 11) as f64 / (1u64 << 53) as f64
}

impl Perturbation {
    /// Sample `k` under `p`'s seed and ranges: each coordinate of the offset uniform in
    /// `±pose_offset_mm`; the rotation about an axis uniform on the sphere by an angle uniform
    /// in `[0, pose_rotation_deg]`; each multiplier uniform in `1 ± range_pct / 100`.
    pub fn draw(p: &RobustParams, k: usize) -> Perturbation {
        let u = |i: u64| unit(p.seed, k, i);
        let sym = |i: u64| 2.0 * u(i) - 1.0;
        let offset_mm = [0, 1, 2].map(|i| p.pose_offset_mm * sym(i));
        // An axis uniform on the sphere: z uniform in [-1, 1], the azimuth uniform.
        let z = sym(3);
        let phi = std::f64::consts::TAU * u(4);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let angle = p.pose_rotation_deg * u(5);
        let rotation_deg = [r * phi.cos() * angle, r * phi.sin() * angle, z * angle];
        let scale = |pct: f64, i: u64| 1.0 + pct / 100.0 * sym(i);
        Perturbation {
            sample: k,
            offset_mm,
            rotation_deg,
            friction_scale: scale(p.friction_range_pct, 6),
            mass_scale: scale(p.mass_range_pct, 7),
            torque_scale: scale(p.torque_range_pct, 8),
        }
    }

    /// The object's rotation relative to the hand.
    fn rotation(&self) -> UnitQuaternion<f64> {
        let v = Vector3::from(self.rotation_deg).map(f64::to_radians);
        UnitQuaternion::from_scaled_axis(v)
    }
}

/// A perturbed case's own parts: the hand's pose relative to the object and the parameters
/// with the motors' torque scaled.
pub struct Perturbed {
    pose: SimHand,
    params: SimParams,
    mass_kg: f64,
    friction: f64,
}

impl Perturbed {
    /// `case` under `p`. The object moved by (R, t) about its centre of mass `c` relative to
    /// the hand is the hand moved by the inverse relative to the object (the frame the scene is
    /// built in): a palm point `x` goes to `c + Rᵀ(x − c − t)`, its axes to `Rᵀ a`.
    pub fn of(case: &Case, p: &Perturbation) -> Perturbed {
        let com_mm = object_com_mm(case);
        let r_inv = p.rotation().inverse();
        let t = Vector3::from(p.offset_mm);
        let origin = case.pose.origin_mm;
        let moved = com_mm + r_inv * (origin.coords - com_mm - t);
        let mut params = case.params.clone();
        params.fingers.torque_limit_nm *= p.torque_scale;
        // A sample is checked in full: its verdict is reported (`verdicts`, `first_failure`).
        params.hold.closing_decides = false;
        Perturbed {
            pose: SimHand {
                origin_mm: moved.into(),
                axes: case.pose.axes.map(|a| r_inv * a),
                theta_deg: case.pose.theta_deg.clone(),
                planned_contacts_mm: Vec::new(),
            },
            params,
            mass_kg: case.mass_kg * p.mass_scale,
            friction: case.friction * p.friction_scale,
        }
    }

    /// The perturbed case on `base`'s hand and object.
    pub fn case<'a>(&'a self, base: &Case<'a>) -> Case<'a> {
        Case {
            hand: base.hand,
            pose: &self.pose,
            object: base.object,
            mass_kg: self.mass_kg,
            friction: self.friction,
            params: &self.params,
        }
    }
}

/// The object's centre of mass as the check has it, aligned frame `[mm]`.
fn object_com_mm(case: &Case) -> Vector3<f64> {
    let c = super::collider::object_com_m(case.object);
    Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z)) / super::convert::M_PER_MM
}

/// Counts of the verdicts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Samples that held.
    pub hold: usize,
    /// Samples that slipped.
    pub slip: usize,
    /// Samples that dropped the object.
    pub drop: usize,
}

impl Counts {
    fn add(&mut self, v: Verdict) {
        match v {
            Verdict::Hold => self.hold += 1,
            Verdict::Slip => self.slip += 1,
            Verdict::Drop => self.drop += 1,
        }
    }

    fn total(&self) -> usize {
        self.hold + self.slip + self.drop
    }
}

/// The 95 % two-sided normal quantile.
const Z95: f64 = 1.959_963_984_540_054;

/// The 95 % Wilson score interval `[lo, hi]` of `k` successes in `n` trials (`[0, 1]` for none):
/// `(p̂ + z²/2n ± z √(p̂(1−p̂)/n + z²/4n²)) / (1 + z²/n)` (Wilson 1927).
pub fn wilson(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let n = n as f64;
    let p = k as f64 / n;
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / n;
    let centre = p + z2 / (2.0 * n);
    let half = Z95 * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    [
        ((centre - half) / denom).clamp(0.0, 1.0),
        ((centre + half) / denom).clamp(0.0, 1.0),
    ]
}

/// The hold probability over one gravity direction.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectionRobust {
    /// Gravity direction (unit, aligned frame).
    pub gravity: [f64; 3],
    /// The samples' verdicts under it.
    pub counts: Counts,
    /// The fraction that held.
    pub hold_probability: f64,
    /// Its 95 % Wilson interval.
    pub interval: [f64; 2],
    /// Samples that held under it with a closing that kept the planned grasp.
    pub held_as_planned: usize,
}

/// The first sample that did not hold: enough to replay it (`[sim] replay_sample`).
#[derive(Debug, Clone, PartialEq)]
pub struct FirstFailure {
    /// Its index.
    pub sample: usize,
    /// Its verdict (the worst over the directions).
    pub verdict: Verdict,
    /// The first direction that did not hold.
    pub gravity: [f64; 3],
    /// What was perturbed.
    pub perturbation: Perturbation,
}

/// The perturbation ranges a run drew from (`[sim]` keys of the same names).
#[derive(Debug, Clone, PartialEq)]
pub struct Ranges {
    /// `[mm]`, each coordinate.
    pub pose_offset_mm: f64,
    /// `[deg]`.
    pub pose_rotation_deg: f64,
    /// `[%]`.
    pub friction_range_pct: f64,
    /// `[%]`.
    pub mass_range_pct: f64,
    /// `[%]`.
    pub torque_range_pct: f64,
}

/// The hold probability under perturbation (`sim.robust`).
#[derive(Debug, Clone, PartialEq)]
pub struct Robust {
    /// Perturbed checks run.
    pub samples: usize,
    /// `[sim] seed`.
    pub seed: u64,
    /// The ranges drawn from.
    pub ranges: Ranges,
    /// Each sample's verdict, the worst over its directions.
    pub counts: Counts,
    /// The fraction of samples that held in every direction.
    pub hold_probability: f64,
    /// Its 95 % Wilson interval `[lo, hi]`.
    pub interval: [f64; 2],
    /// Samples that held in every direction with a closing that kept the planned grasp.
    pub held_as_planned: usize,
    /// `held_as_planned / samples`: the probability of a hold as planned.
    pub as_planned_probability: f64,
    /// Its 95 % Wilson interval `[lo, hi]`.
    pub as_planned_interval: [f64; 2],
    /// Per gravity direction.
    pub directions: Vec<DirectionRobust>,
    /// Each sample's verdict, in sample order.
    pub verdicts: Vec<Verdict>,
    /// Each sample's fidelity (`true`: its closing kept the planned grasp), in sample order.
    pub as_planned: Vec<bool>,
    /// The first sample that did not hold (`None`: all held).
    pub first_failure: Option<FirstFailure>,
    /// Physics steps over all samples.
    pub steps: usize,
    /// Wall time of the samples `[ms]`.
    pub wall_ms: f64,
    /// True if and only if the lower bound of `as_planned_interval` reaches `[sim]
    /// choose_min_lower_bound` (what `choose = "robust"` takes as a success).
    pub passes: bool,
}

impl Robust {
    /// The candidate search's rank of a sampled candidate, larger better: the lower bound of
    /// the probability of a hold as planned, then of the hold probability, then the two
    /// probabilities.
    pub fn rank(&self) -> [f64; 4] {
        [
            self.as_planned_interval[0],
            self.interval[0],
            self.as_planned_probability,
            self.hold_probability,
        ]
    }
}

/// Runs `[sim] samples` perturbed checks of `case` in parallel and counts their verdicts.
pub fn sample(case: &Case) -> Robust {
    let t0 = Instant::now();
    let runs: Vec<(Perturbation, SimOutcome)> = (0..case.params.robust.samples)
        .into_par_iter()
        .map(|k| check_sample(case, k))
        .collect();
    robust_of(case, &runs, t0.elapsed().as_secs_f64() * 1000.0)
}

/// Sample `k`'s perturbed check of `case`: one of the checks [`sample`] runs, for a caller that
/// spreads the samples of several grasps over the cores itself
/// ([`super::entry::labelled_sample`]).
pub fn check_sample(case: &Case, k: usize) -> (Perturbation, SimOutcome) {
    let p = Perturbation::draw(&case.params.robust, k);
    let perturbed = Perturbed::of(case, &p);
    let out = super::check(&perturbed.case(case));
    (p, out)
}

/// The hold probability of `case` from its samples' checks `runs` (sample `k` at index `k`,
/// as [`check_sample`] gives them), which took `wall_ms`.
pub fn robust_of(case: &Case, runs: &[(Perturbation, SimOutcome)], wall_ms: f64) -> Robust {
    let rp = &case.params.robust;
    let mut counts = Counts::default();
    let mut held_as_planned = 0;
    let mut directions: Vec<DirectionRobust> = Vec::new();
    let mut first_failure = None;
    for (p, out) in runs {
        counts.add(out.verdict);
        held_as_planned += usize::from(out.held_as_planned());
        for (i, d) in out.directions.iter().enumerate() {
            if directions.len() <= i {
                directions.push(DirectionRobust {
                    gravity: d.gravity,
                    counts: Counts::default(),
                    hold_probability: 0.0,
                    interval: [0.0, 1.0],
                    held_as_planned: 0,
                });
            }
            directions[i].counts.add(d.verdict);
            directions[i].held_as_planned +=
                usize::from(d.verdict == Verdict::Hold && d.as_planned);
        }
        if out.verdict != Verdict::Hold && first_failure.is_none() {
            let failed = out.directions.iter().find(|d| d.verdict != Verdict::Hold);
            first_failure = Some(FirstFailure {
                sample: p.sample,
                verdict: out.verdict,
                gravity: failed.map_or([0.0; 3], |d| d.gravity),
                perturbation: p.clone(),
            });
        }
    }
    for d in &mut directions {
        let n = d.counts.total();
        d.hold_probability = d.counts.hold as f64 / n.max(1) as f64;
        d.interval = wilson(d.counts.hold, n);
    }
    let interval = wilson(counts.hold, rp.samples);
    let as_planned_interval = wilson(held_as_planned, rp.samples);
    Robust {
        samples: rp.samples,
        seed: rp.seed,
        ranges: Ranges {
            pose_offset_mm: rp.pose_offset_mm,
            pose_rotation_deg: rp.pose_rotation_deg,
            friction_range_pct: rp.friction_range_pct,
            mass_range_pct: rp.mass_range_pct,
            torque_range_pct: rp.torque_range_pct,
        },
        counts,
        hold_probability: counts.hold as f64 / rp.samples.max(1) as f64,
        interval,
        held_as_planned,
        as_planned_probability: held_as_planned as f64 / rp.samples.max(1) as f64,
        as_planned_interval,
        directions,
        verdicts: runs.iter().map(|r| r.1.verdict).collect(),
        as_planned: runs.iter().map(|r| r.1.fidelity.as_planned).collect(),
        first_failure,
        steps: runs.iter().map(|r| r.1.steps).sum(),
        wall_ms,
        passes: as_planned_interval[0] >= rp.choose_min_lower_bound,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wilson_interval_matches_its_formula_at_known_counts() {
        // 8 of 8: n / (n + z²) = 8 / 11.8415 = 0.6756 (the all-success lower bound).
        let [lo, hi] = wilson(8, 8);
        assert!((lo - 8.0 / (8.0 + Z95 * Z95)).abs() < 1e-12, "{lo}");
        assert!((lo - 0.6756).abs() < 1e-4 && hi == 1.0);
        // 14 of 16: the example, 64-97 %.
        let [lo, hi] = wilson(14, 16);
        assert!(
            (lo - 0.6398).abs() < 1e-3 && (hi - 0.9650).abs() < 1e-3,
            "{lo} {hi}"
        );
        // 0 of 16 mirrors 16 of 16.
        let [lo0, hi0] = wilson(0, 16);
        let [lo16, hi16] = wilson(16, 16);
        assert!(lo0 == 0.0 && (hi0 - (1.0 - lo16)).abs() < 1e-12 && hi16 == 1.0);
        assert_eq!(wilson(0, 0), [0.0, 1.0]);
    }

    #[test]
    fn a_sample_is_checked_in_full_whatever_closing_decides_says() {
        // A sample's verdict is reported (`verdicts`, `first_failure`): a failed closing is
        // held under gravity there even when the candidate search decides it at once.
        let hand = crate::hand::thesis_for_tests();
        let mesh = crate::objects::cylinder(40.0, 124.0);
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let object = super::super::ObjectShape::from_mesh(&mesh, volume);
        let mut params = SimParams::default();
        params.hold.closing_decides = true;
        let pose = SimHand {
            origin_mm: nalgebra::Point3::new(-20.0, 0.0, 62.0),
            axes: [-Vector3::x(), -Vector3::y(), Vector3::z()],
            theta_deg: vec![[72.11, 91.81]; 3],
            planned_contacts_mm: Vec::new(),
        };
        let case = Case {
            hand: &hand,
            pose: &pose,
            object: &object,
            mass_kg: 0.08,
            friction: 0.3,
            params: &params,
        };
        let p = Perturbation::draw(&params.robust, 0);
        let perturbed = Perturbed::of(&case, &p);
        let sample = perturbed.case(&case);
        assert!(!sample.params.hold.closing_decides);
        let mut expected = params.clone();
        expected.hold.closing_decides = false;
        expected.fingers.torque_limit_nm *= p.torque_scale;
        assert_eq!(*sample.params, expected);
    }

    #[test]
    fn a_sample_depends_on_seed_and_index_only_and_stays_in_its_ranges() {
        let p = RobustParams::default();
        let a = Perturbation::draw(&p, 3);
        assert_eq!(a, Perturbation::draw(&p, 3));
        assert_ne!(a, Perturbation::draw(&p, 4));
        let other = RobustParams {
            seed: 1,
            ..p.clone()
        };
        assert_ne!(a, Perturbation::draw(&other, 3));
        let mut angles = Vec::new();
        for k in 0..500 {
            let s = Perturbation::draw(&p, k);
            assert!(s.offset_mm.iter().all(|v| v.abs() <= 2.0));
            let angle = Vector3::from(s.rotation_deg).norm();
            assert!(angle <= 3.0 + 1e-12);
            angles.push(angle);
            for (m, r) in [
                (s.friction_scale, 0.15),
                (s.mass_scale, 0.15),
                (s.torque_scale, 0.10),
            ] {
                assert!((m - 1.0).abs() <= r + 1e-12, "{m}");
            }
        }
        // Uniform angles in [0, 3]: a mean near 1.5 (500 draws: σ of the mean 0.04).
        let mean = angles.iter().sum::<f64>() / 500.0;
        assert!((mean - 1.5).abs() < 0.15, "{mean}");
    }
}
