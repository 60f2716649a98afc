//! How localisation went over a stretch of a trial (the whole of it, or one leg): fixes, misses, gaps and the pose error.

use crate::outcome::{LegOutcome, TrialOutcome};

/// How localisation went over a stretch of a trial (the whole of it, or one leg).
#[derive(Debug, Clone, Copy)]
pub(super) struct LocStats {
    pub(super) start_s: f64,
    pub(super) fixes: u32,
    pub(super) missed: u32,
    pub(super) last_fix_s: f64,
    pub(super) largest_gap_s: f64,
    pub(super) error_sum_m: f64,
    pub(super) steps: u32,
    pub(super) error_max_m: f64,
}

impl LocStats {
    pub(super) fn new(start_s: f64) -> Self {
        Self {
            start_s,
            fixes: 0,
            missed: 0,
            last_fix_s: start_s,
            largest_gap_s: 0.0,
            error_sum_m: 0.0,
            steps: 0,
            error_max_m: 0.0,
        }
    }

    pub(super) fn reading(&mut self, t_s: f64, got_pose: bool) {
        if got_pose {
            self.fixes += 1;
            self.largest_gap_s = self.largest_gap_s.max(t_s - self.last_fix_s);
            self.last_fix_s = t_s;
        } else {
            self.missed += 1;
        }
    }

    pub(super) fn error(&mut self, error_m: f64) {
        self.error_sum_m += error_m;
        self.steps += 1;
        self.error_max_m = self.error_max_m.max(error_m);
    }

    /// The longest gap between fixes up to `t_s`, the open one included.
    fn largest_gap_until(&self, t_s: f64) -> f64 {
        self.largest_gap_s.max(t_s - self.last_fix_s)
    }

    fn mean_error_m(&self) -> f64 {
        if self.steps == 0 {
            f64::NAN
        } else {
            self.error_sum_m / f64::from(self.steps)
        }
    }

    /// Writes the stretch's figures into a trial outcome, ending at `t_s`.
    pub(super) fn finish_trial(&self, t_s: f64, period_s: f64, out: &mut TrialOutcome) {
        out.fixes = self.fixes;
        out.fixes_missed = self.missed;
        out.time_without_fix_s = f64::from(self.missed) * period_s;
        out.largest_fix_gap_s = self.largest_gap_until(t_s);
        out.localization_error_mean_m = self.mean_error_m();
        out.localization_error_max_m = self.error_max_m;
    }

    /// Writes the stretch's figures into a leg's outcome, ending at `t_s`.
    pub(super) fn finish_leg(&self, t_s: f64, leg: &mut LegOutcome) {
        leg.fixes_missed = self.missed;
        leg.largest_fix_gap_s = self.largest_gap_until(t_s.max(self.start_s));
        leg.localization_error_max_m = self.error_max_m;
    }
}
