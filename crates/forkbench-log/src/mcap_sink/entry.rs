//! The entry errors for Foxglove's plots: lateral offset and heading to the pallet axis over the approach, measured against the pallet where it is (as the judge does), with the limits as two-point lines.

use forkbench_core::units::wrap_angle;
use forkbench_trial::StepRecord;

use super::McapRecorder;

/// The entry plots cover the fork tips' last this many metres before the pallet face, then
/// the insertion (as the rerun recording's).
const APPROACH_M: f64 = 1.5;

/// What the entry plots need across steps.
#[derive(Debug, Default)]
pub(super) struct EntryPlot {
    /// Lateral (m) and heading (°) limits.
    pub(super) limits: [f64; 2],
    /// The truck's fork length: the tips are this far ahead of the fork root.
    pub(super) fork_length_m: f64,
    /// Whether the approach has begun (the limit lines start there).
    started: bool,
}

impl McapRecorder {
    /// The entry errors at a step within the approach; the limit lines open at the first.
    pub(super) fn entry_step(&mut self, s: &StepRecord) {
        let local = s.pallet.to_local(&s.truth);
        if local.x_m + self.entry.fork_length_m < -APPROACH_M {
            return;
        }
        if !self.entry.started {
            self.entry.started = true;
            self.entry_limits(s.t_s);
        }
        self.send_scalar(s.t_s, "entry/lateral_to_pallet_axis_m", local.y_m);
        let heading_deg = wrap_angle(local.heading_rad).to_degrees();
        self.send_scalar(s.t_s, "entry/heading_to_pallet_axis_deg", heading_deg);
    }

    /// Both ends of the limit lines (at the approach's start, and at the trial's end).
    pub(super) fn entry_limits(&mut self, t_s: f64) {
        if !self.entry.started {
            return;
        }
        let [lateral, heading] = self.entry.limits;
        for (path, v) in [
            ("entry/lateral_limit_m", lateral),
            ("entry/lateral_limit_neg_m", -lateral),
            ("entry/heading_limit_deg", heading),
            ("entry/heading_limit_neg_deg", -heading),
        ] {
            self.send_scalar(t_s, path, v);
        }
    }
}
