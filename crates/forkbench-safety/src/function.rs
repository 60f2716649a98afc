//! The truck's safety function: a protective-field intrusion stops it, a warning-field intrusion slows it, each after the scanner's and the controller's response, and it resumes once the fields stay clear for a dwell time.

use std::collections::VecDeque;

use serde::Serialize;

/// One evaluation of the fields by the safety scanners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// When the scan was taken.
    pub t_s: f64,
    pub protective: bool,
    pub warning: bool,
    /// Whether a person (or another vehicle) stood in the protective field: a stop
    /// without one is a false trip (a rack, a reflector post, a wall).
    pub mover_in_protective: bool,
}

/// What the safety function did over a trial.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct SafetyStats {
    /// Protective stops, and of them those with no person or vehicle in the field.
    pub stops: u32,
    pub false_trips: u32,
    /// Time the truck was held stopped.
    pub stop_time_s: f64,
    /// Warning-field slowdowns, and the time the speed was held down.
    pub slowdowns: u32,
    pub slowdown_time_s: f64,
}

/// The function's state between steps.
#[derive(Debug, Clone)]
pub struct SafetyFunction {
    /// From a scan to the truck acting on it: the scanner's and the controller's
    /// response times.
    delay_s: f64,
    dwell_s: f64,
    warning_speed_mps: f64,
    pending: VecDeque<Reading>,
    stopped: bool,
    clear_since_s: Option<f64>,
    slowed: bool,
    /// When the controller last asked a standing truck to move: it may start once a
    /// reading taken since then has come through clear (the start interlock).
    start_asked_s: Option<f64>,
    last_applied_s: f64,
    pub stats: SafetyStats,
}

impl SafetyFunction {
    pub fn new(delay_s: f64, dwell_s: f64, warning_speed_mps: f64) -> Self {
        SafetyFunction {
            delay_s,
            dwell_s,
            warning_speed_mps,
            pending: VecDeque::new(),
            stopped: false,
            clear_since_s: None,
            slowed: false,
            start_asked_s: None,
            last_applied_s: f64::NEG_INFINITY,
            stats: SafetyStats::default(),
        }
    }

    /// A scan's evaluation; the truck acts on it after the response times.
    pub fn read(&mut self, r: Reading) {
        self.pending.push_back(r);
    }

    /// Whether the truck is held stopped now.
    pub fn stopped(&self) -> bool {
        self.stopped
    }

    /// Whether the speed is held down by a warning now.
    pub fn slowed(&self) -> bool {
        self.slowed && !self.stopped
    }

    /// The commanded speed the truck may drive at `t_s`, over the next `dt_s`;
    /// `standing`: whether the truck stands now (a standing truck starts only once a
    /// reading of the fields its motion selects has come through clear).
    pub fn gate(&mut self, t_s: f64, dt_s: f64, speed_cmd_mps: f64, standing: bool) -> f64 {
        while let Some(r) = self.pending.front().copied() {
            if r.t_s + self.delay_s > t_s + 1e-9 {
                break;
            }
            self.pending.pop_front();
            self.apply(r);
        }
        if self.stopped && self.clear_since_s.is_some_and(|c| t_s - c >= self.dwell_s) {
            self.stopped = false;
            self.clear_since_s = None;
        }
        if self.stopped {
            self.stats.stop_time_s += dt_s;
            return 0.0;
        }
        let asks = speed_cmd_mps.abs() >= crate::STANDING_MPS;
        if !(standing && asks) {
            self.start_asked_s = None;
        } else {
            let asked = *self.start_asked_s.get_or_insert(t_s);
            if self.last_applied_s < asked {
                return 0.0;
            }
        }
        if self.slowed && speed_cmd_mps.abs() > self.warning_speed_mps {
            self.stats.slowdown_time_s += dt_s;
            return speed_cmd_mps.clamp(-self.warning_speed_mps, self.warning_speed_mps);
        }
        speed_cmd_mps
    }

    fn apply(&mut self, r: Reading) {
        self.last_applied_s = r.t_s;
        if r.protective {
            if !self.stopped {
                self.stopped = true;
                self.stats.stops += 1;
                if !r.mover_in_protective {
                    self.stats.false_trips += 1;
                }
            }
            self.clear_since_s = None;
        } else if self.stopped && self.clear_since_s.is_none() {
            self.clear_since_s = Some(r.t_s + self.delay_s);
        }
        if r.warning && !self.slowed && !self.stopped {
            self.stats.slowdowns += 1;
        }
        self.slowed = r.warning;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reading(t_s: f64, protective: bool, warning: bool) -> Reading {
        Reading {
            t_s,
            protective,
            warning,
            mover_in_protective: false,
        }
    }

    #[test]
    fn an_intrusion_stops_after_the_response_and_clears_after_the_dwell() {
        let mut f = SafetyFunction::new(0.2, 1.0, 0.3);
        f.read(reading(0.0, true, true));
        assert_eq!(
            f.gate(0.1, 0.1, 0.8, false),
            0.8,
            "not yet: the response time"
        );
        assert_eq!(f.gate(0.2, 0.1, 0.8, false), 0.0, "stopped");
        f.read(reading(0.3, false, false));
        assert_eq!(f.gate(0.5, 0.1, 0.8, true), 0.0, "clear from 0.5 s");
        assert_eq!(f.gate(1.4, 0.1, 0.8, true), 0.0, "still within the dwell");
        assert_eq!(
            f.gate(1.5, 0.1, 0.8, true),
            0.0,
            "clear, standing: a fresh reading first"
        );
        f.read(reading(1.52, false, false));
        assert_eq!(f.gate(1.8, 0.1, 0.8, true), 0.8, "resumed");
        assert_eq!((f.stats.stops, f.stats.false_trips), (1, 1));
        f.read(reading(2.0, false, true));
        assert_eq!(f.gate(2.2, 0.1, -0.8, false), -0.3, "slowed by the warning");
        assert_eq!(f.stats.slowdowns, 1);
    }

    #[test]
    fn a_standing_truck_starts_only_after_a_clear_reading_of_its_new_request() {
        let mut f = SafetyFunction::new(0.2, 1.0, 0.3);
        f.read(reading(0.0, false, false));
        assert_eq!(f.gate(0.3, 0.1, 0.0, true), 0.0, "standing, nothing asked");
        assert_eq!(
            f.gate(0.4, 0.1, 0.5, true),
            0.0,
            "asked at 0.4 s: not yet read"
        );
        f.read(reading(0.45, false, false));
        assert_eq!(
            f.gate(0.6, 0.1, 0.5, true),
            0.0,
            "the reading is not through yet"
        );
        assert_eq!(f.gate(0.7, 0.1, 0.5, true), 0.5, "clear: it starts");
        assert_eq!(f.gate(0.8, 0.1, 0.5, false), 0.5);
    }
}
