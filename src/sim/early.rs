//! The rest rule of the `fast` protocol (docs/SIM.md, "Deciding early"): from the object's poses
//! relative to the palm sampled during a hold, whether it is at rest within the hold thresholds
//! (`hold`), or beyond them for good (`slip`), with what the numbers reported may still move by.
//! Pure arithmetic on the samples: millimetres, degrees, seconds.

use super::outcome::Verdict;
use super::params::SimParams;
use nalgebra::{UnitQuaternion, Vector3};

/// The early-decision rule of the `fast` protocol (docs/SIM.md, "Deciding early").
#[derive(Debug, Clone, Copy)]
pub struct EarlyDecision {
    /// The window over which its motion is measured, and the least time held before a `rest`
    /// decision `[s]`.
    pub window_s: f64,
    /// The fastest motion seen in the window is projected to the end of the hold at this many
    /// times its speed.
    pub safety: f64,
    /// The projected further motion must also stay within what the numbers reported at the
    /// decision may differ from the full protocol's: this `[mm]` ...
    pub report_mm: f64,
    /// ... or `[deg]` ...
    pub report_deg: f64,
    /// ... or this fraction of the value reported, whichever is larger.
    pub report_fraction: f64,
    /// A rest decision keeps the object within this fraction of the hold thresholds, motion to
    /// come included: an object near a threshold runs to the end of the hold.
    pub margin: f64,
    /// Every finger joint's further motion, bounded as the object's, must stay within this
    /// `[deg]` (`[sim] rest_joint_deg`).
    pub joint_deg: f64,
}

impl EarlyDecision {
    /// The rule with the scenario's `rest_window_s` and `rest_safety`.
    pub fn from_params(params: &SimParams) -> EarlyDecision {
        EarlyDecision {
            window_s: params.early.rest_window_s,
            safety: params.early.rest_safety,
            report_mm: 0.5,
            report_deg: 0.5,
            report_fraction: 0.1,
            margin: params.early.rest_margin,
            joint_deg: params.early.rest_joint_deg,
        }
    }
}

/// The object's pose relative to the palm is sampled this often during a hold `[s]`.
pub const SAMPLE_S: f64 = 1.0 / 48.0;

/// What the samples of a hold are measured against: the pose after closing, and how the
/// rotation is judged.
#[derive(Debug, Clone, Copy)]
pub struct RestFrame {
    /// Object translation relative to the palm after closing `[mm]`.
    pub pc: Vector3<f64>,
    /// Object rotation relative to the palm after closing.
    pub qc: UnitQuaternion<f64>,
    /// Only the tilt of the principal axis is judged (a body of revolution).
    pub is_revolution: bool,
    /// Time between samples `[s]`.
    pub sample_dt: f64,
}

impl RestFrame {
    /// The judged rotation between two orientations `[deg]`.
    pub fn judged(&self, a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
        let (full, tilt) = rotations(a, b);
        if self.is_revolution {
            tilt
        } else {
            full
        }
    }
}

/// What the rest rule measures over its window: where the object is now and how much further
/// it may go by the end of the hold.
#[derive(Debug, Clone, Copy)]
struct Settling {
    /// Translation and judged rotation relative to the pose after closing, now `[mm]`, `[deg]`.
    now_mm: f64,
    now_deg: f64,
    /// `safety` × (drift × time left + spread) `[mm]`, `[deg]`.
    more_mm: f64,
    more_deg: f64,
}

impl EarlyDecision {
    /// True when the hand's joints have settled: over the last window of `joints` (each
    /// sample's joint angles `[deg]`, one every `sample_dt`), every joint's drift continued
    /// for `remaining_s` plus its spread, at `safety` times their size, stays within
    /// `joint_deg`. A finger whose motor has reached its torque limit creeps while the object
    /// it presses still looks at rest, and the object then slips (stick-slip): the object's
    /// rest alone does not show it.
    pub fn joints_settled(&self, joints: &[Vec<f64>], sample_dt: f64, remaining_s: f64) -> bool {
        let Some((recent, window_s)) = self.last_window(joints, sample_dt) else {
            return false;
        };
        let (first, last) = (&recent[0], &recent[recent.len() - 1]);
        (0..last.len()).all(|k| {
            let (lo, hi) = recent
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), j| {
                    (lo.min(j[k]), hi.max(j[k]))
                });
            let drift = (last[k] - first[k]).abs() / window_s;
            self.safety * (drift * remaining_s + (hi - lo)) <= self.joint_deg
        })
    }

    /// The samples of the last `window_s` (sampled every `sample_dt`), the one before the window
    /// included, and the window's length `[s]`; `None` while fewer samples than that were taken.
    fn last_window<'a, T>(&self, samples: &'a [T], sample_dt: f64) -> Option<(&'a [T], f64)> {
        let window = ((self.window_s / sample_dt).round() as usize).max(1);
        if samples.len() <= window {
            return None;
        }
        Some((
            &samples[samples.len() - window - 1..],
            window as f64 * sample_dt,
        ))
    }

    /// The last `window_s` of `samples` measured: `None` while the hold is shorter than the
    /// window.
    fn settling(
        &self,
        samples: &[(Vector3<f64>, UnitQuaternion<f64>)],
        frame: &RestFrame,
        remaining_s: f64,
    ) -> Option<Settling> {
        let (recent, window_s) = self.last_window(samples, frame.sample_dt)?;
        let (first, last) = (recent[0], recent[recent.len() - 1]);
        let mut spread_mm = 0.0f64;
        let mut spread_deg = 0.0f64;
        for (i, a) in recent.iter().enumerate() {
            for b in &recent[i + 1..] {
                spread_mm = spread_mm.max((a.0 - b.0).norm());
                spread_deg = spread_deg.max(frame.judged(&a.1, &b.1));
            }
        }
        let drift_mm = (last.0 - first.0).norm() / window_s;
        let drift_deg = frame.judged(&first.1, &last.1) / window_s;
        Some(Settling {
            now_mm: (last.0 - frame.pc).norm(),
            now_deg: frame.judged(&frame.qc, &last.1),
            more_mm: self.safety * (drift_mm * remaining_s + spread_mm),
            more_deg: self.safety * (drift_deg * remaining_s + spread_deg),
        })
    }

    /// True when the further motion bound is within what the numbers reported now may differ
    /// from the full protocol's.
    fn reportable(&self, s: &Settling) -> bool {
        s.more_mm <= self.report_mm.max(self.report_fraction * s.now_mm)
            && s.more_deg <= self.report_deg.max(self.report_fraction * s.now_deg)
    }

    /// The rest rules (docs/SIM.md, "Deciding early"): what the motion of the last `window_s`
    /// of `samples` (the poses relative to the palm so far, one every `frame.sample_dt`), its
    /// mean drift and its spread at `safety` times their size continued for `remaining_s`,
    /// decides now, provided it keeps the numbers reported now within what they may differ from
    /// the full protocol's:
    /// - `Hold` when the object stays within `margin` of the hold thresholds;
    /// - `Slip` when it cannot come back within `1 / margin` of a threshold (the distance to the
    ///   pose after closing moves by no more than the object does, and so does the judged
    ///   rotation);
    /// - `None` otherwise.
    ///
    /// Motion alone decides: whether the closing kept the plan is the fidelity's question.
    ///
    /// A `Slip` holds only for an object on the hand, which the caller checks.
    pub fn decide(
        &self,
        samples: &[(Vector3<f64>, UnitQuaternion<f64>)],
        frame: &RestFrame,
        remaining_s: f64,
        params: &SimParams,
    ) -> Option<Verdict> {
        let s = self.settling(samples, frame, remaining_s)?;
        if !self.reportable(&s) {
            return None;
        }
        if s.now_mm + s.more_mm <= self.margin * params.hold.hold_translation_mm
            && s.now_deg + s.more_deg <= self.margin * params.hold.hold_rotation_deg
        {
            return Some(Verdict::Hold);
        }
        let beyond = s.now_mm - s.more_mm >= params.hold.hold_translation_mm / self.margin
            || s.now_deg - s.more_deg >= params.hold.hold_rotation_deg / self.margin;
        beyond.then_some(Verdict::Slip)
    }
}

/// The object's judged rotation and its parts: (full rotation, tilt of the principal axis),
/// both `[deg]`, relative to `qc`.
pub(super) fn rotations(qc: &UnitQuaternion<f64>, q: &UnitQuaternion<f64>) -> (f64, f64) {
    let full = qc.angle_to(q).to_degrees();
    let tilt = (qc * Vector3::z()).angle(&(q * Vector3::z())).to_degrees();
    (full, tilt)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule with a 0.2 s window (the default until issue 35 made it 0.1 s), projected at
    /// twice its speed, within 0.8 of the thresholds (5 mm, 5°).
    fn rule() -> (EarlyDecision, SimParams) {
        let mut params = SimParams::default();
        params.early.rest_window_s = 0.2;
        (EarlyDecision::from_params(&params), params)
    }

    /// Measured against the identity, a sample every 1/48 s (a 10-sample window).
    fn frame(is_revolution: bool) -> RestFrame {
        RestFrame {
            pc: Vector3::zeros(),
            qc: UnitQuaternion::identity(),
            is_revolution,
            sample_dt: SAMPLE_S,
        }
    }

    /// `n` samples of an object at rest at `p` `[mm]`.
    fn at_rest(n: usize, p: Vector3<f64>) -> Vec<(Vector3<f64>, UnitQuaternion<f64>)> {
        vec![(p, UnitQuaternion::identity()); n]
    }

    #[test]
    fn nothing_is_decided_before_a_whole_window_has_been_sampled() {
        let (r, params) = rule();
        let f = frame(false);
        // round(0.2 s / (1/48 s)) = 10 samples, plus the one the window starts from.
        let still = Vector3::new(1.0, 0.0, 0.0);
        assert_eq!(r.decide(&at_rest(10, still), &f, 1.0, &params), None);
        assert_eq!(
            r.decide(&at_rest(11, still), &f, 1.0, &params),
            Some(Verdict::Hold)
        );
    }

    #[test]
    fn at_rest_the_distance_from_the_closed_pose_decides() {
        let (r, params) = rule();
        let f = frame(false);
        let decide = |x: f64| r.decide(&at_rest(20, Vector3::new(x, 0.0, 0.0)), &f, 1.5, &params);
        // Within 0.8 × 5 mm: hold; beyond 5 mm / 0.8 = 6.25 mm: slip; between: undecided.
        assert_eq!(decide(3.9), Some(Verdict::Hold));
        assert_eq!(decide(4.1), None);
        assert_eq!(decide(6.2), None);
        assert_eq!(decide(6.3), Some(Verdict::Slip));
    }

    #[test]
    fn motion_is_projected_to_the_end_of_the_hold() {
        let (r, _) = rule();
        let f = frame(false);
        // 1 mm/s along x, from 2 mm: over the 10-sample window (0.2083 s) the object moves
        // 0.2083 mm, so with 1 s left the bound is 2 × (1 mm/s × 1 s + 0.2083 mm) = 2.417 mm.
        let samples: Vec<_> = (0..=20)
            .map(|i| {
                let x = 2.0 + i as f64 * SAMPLE_S;
                (Vector3::new(x, 0.0, 0.0), UnitQuaternion::identity())
            })
            .collect();
        let s = r.settling(&samples, &f, 1.0).unwrap();
        let window_s = 10.0 * SAMPLE_S;
        let now = 2.0 + 20.0 * SAMPLE_S;
        assert!((s.now_mm - now).abs() < 1e-12, "{} mm", s.now_mm);
        let expected = 2.0 * (1.0 + window_s);
        assert!(
            (s.more_mm - expected).abs() < 1e-9,
            "further motion {} mm, expected {expected}",
            s.more_mm
        );
        assert_eq!((s.now_deg, s.more_deg), (0.0, 0.0));
        // 2.4 mm more cannot be reported as the full protocol's within 0.5 mm or 10 % (0.24 mm).
        assert!(!r.reportable(&s));
        // With 0.05 s left, 2 × (0.05 + 0.2083) = 0.517 mm is still over 0.5 mm; with none
        // left, the spread alone, 2 × 0.2083 = 0.417 mm, is within it.
        assert!(!r.reportable(&r.settling(&samples, &f, 0.05).unwrap()));
        assert!(r.reportable(&r.settling(&samples, &f, 0.0).unwrap()));
    }

    #[test]
    fn a_creeping_finger_joint_keeps_the_direction_open() {
        let (r, _) = rule();
        // Six joints still; then joint 4 creeping at 1°/s, as a motor that gave way does
        // while the object it presses has not yet moved.
        let still: Vec<Vec<f64>> = vec![vec![1.0, -2.0, 0.5, 3.0, 1.4, 2.6]; 20];
        assert!(r.joints_settled(&still, SAMPLE_S, 1.5));
        let creep: Vec<Vec<f64>> = (0..20)
            .map(|i| vec![1.0, -2.0, 0.5, 3.0 + i as f64 * SAMPLE_S, 1.4, 2.6])
            .collect();
        // Over the 10-sample window (0.2083 s) it moves 0.2083°: with 1.5 s left the bound is
        // 2 × (1°/s × 1.5 s + 0.2083°) = 3.42°, beyond 1°; with none left, 0.417°, within.
        assert!(!r.joints_settled(&creep, SAMPLE_S, 1.5));
        assert!(r.joints_settled(&creep, SAMPLE_S, 0.0));
        let wide = EarlyDecision {
            joint_deg: 3.5,
            ..r
        };
        assert!(wide.joints_settled(&creep, SAMPLE_S, 1.5));
        // Fewer samples than a window: not settled.
        assert!(!r.joints_settled(&still[..10], SAMPLE_S, 1.5));
    }

    #[test]
    fn a_body_of_revolution_is_judged_by_the_tilt_of_its_axis() {
        let spin = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 10f64.to_radians());
        let tip = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 10f64.to_radians());
        let id = UnitQuaternion::identity();
        let (full, tilt) = rotations(&id, &spin);
        assert!(
            (full - 10.0).abs() < 1e-9 && tilt.abs() < 1e-6,
            "{full} {tilt}"
        );
        let (full, tilt) = rotations(&id, &tip);
        assert!((full - 10.0).abs() < 1e-9 && (tilt - 10.0).abs() < 1e-9);
        assert!(frame(true).judged(&id, &spin).abs() < 1e-6);
        assert!((frame(false).judged(&id, &spin) - 10.0).abs() < 1e-9);
        // Spun 10° at rest: a hold for a cylinder, beyond 5° / 0.8 and a slip for a box.
        let (r, params) = rule();
        let spun = vec![(Vector3::zeros(), spin); 20];
        assert_eq!(
            r.decide(&spun, &frame(true), 1.0, &params),
            Some(Verdict::Hold)
        );
        assert_eq!(
            r.decide(&spun, &frame(false), 1.0, &params),
            Some(Verdict::Slip)
        );
    }
}
