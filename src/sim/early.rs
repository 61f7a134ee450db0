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
    /// The last `window_s` of `samples` measured: `None` while the hold is shorter than the
    /// window.
    fn settling(
        &self,
        samples: &[(Vector3<f64>, UnitQuaternion<f64>)],
        frame: &RestFrame,
        remaining_s: f64,
    ) -> Option<Settling> {
        let window = ((self.window_s / frame.sample_dt).round() as usize).max(1);
        if samples.len() <= window {
            return None;
        }
        let recent = &samples[samples.len() - window - 1..];
        let window_s = window as f64 * frame.sample_dt;
        let (first, last) = (recent[0], recent[window]);
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
    /// - `Hold` when the object stays within `margin` of the hold thresholds (a hold by motion;
    ///   the verdict is `slip` all the same if the closing left a finger too deep);
    /// - `Slip` when it cannot come back within `1 / margin` of a threshold (the distance to the
    ///   pose after closing moves by no more than the object does, and so does the judged
    ///   rotation), or, for a grasp the closing left too deep in the object (`penetrated`),
    ///   wherever it is: such a grasp is `slip` whatever it does while on the hand;
    /// - `None` otherwise.
    ///
    /// A `Slip` holds only for an object on the hand, which the caller checks.
    pub fn decide(
        &self,
        samples: &[(Vector3<f64>, UnitQuaternion<f64>)],
        frame: &RestFrame,
        remaining_s: f64,
        params: &SimParams,
        penetrated: bool,
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
        (beyond || penetrated).then_some(Verdict::Slip)
    }
}

/// The object's judged rotation and its parts: (full rotation, tilt of the principal axis),
/// both `[deg]`, relative to `qc`.
pub(super) fn rotations(qc: &UnitQuaternion<f64>, q: &UnitQuaternion<f64>) -> (f64, f64) {
    let full = qc.angle_to(q).to_degrees();
    let tilt = (qc * Vector3::z()).angle(&(q * Vector3::z())).to_degrees();
    (full, tilt)
}
