//! Dead reckoning between NAV350 fixes from wheel odometry (measured speed and steering), as trucks do; a late fix is carried forward from the time it was measured.

use std::collections::VecDeque;

use forkbench_core::Pose2;

/// The oldest odometry a late fix may be carried over: past the largest localiser latency
/// a scenario may set, with room for its period.
const HISTORY_S: f64 = 11.0;

/// One odometry step as it was propagated: when it began on the predictor's clock, and
/// what moved the pose.
#[derive(Debug, Clone, Copy)]
struct OdometryStep {
    t_s: f64,
    speed_mps: f64,
    steer_rad: f64,
    wheelbase_m: f64,
    root_ahead_m: f64,
    dt_s: f64,
}

/// Holds the last localisation fix and propagates it with odometry until the next one.
#[derive(Debug, Clone, Default)]
pub struct PosePredictor {
    pose: Option<Pose2>,
    /// Time propagated so far: the sum of every step's `dt_s`.
    clock_s: f64,
    /// The odometry of the last `HISTORY_S`, to carry a late fix forward.
    history: VecDeque<OdometryStep>,
}

impl PosePredictor {
    pub fn new() -> Self {
        Self::default()
    }

    /// A new fix, measured now, replaces the prediction.
    pub fn fix(&mut self, measured: Pose2) {
        self.pose = Some(measured);
    }

    /// A fix measured `age_s` ago replaces the prediction, carried to now over the
    /// odometry since it was measured (a NAV350 with timestamped output, as trucks use
    /// it): a late fix never moves the believed pose back in time.
    pub fn fix_measured_ago(&mut self, measured: Pose2, age_s: f64) {
        let mut pose = measured;
        if age_s > 0.0 {
            let since = self.clock_s - age_s - 1e-9;
            for s in self.history.iter().filter(|s| s.t_s >= since) {
                pose = advance(&pose, s);
            }
        }
        self.pose = Some(pose);
    }

    /// Propagates the fork-root pose by one step of the rear-steer kinematics: the
    /// front axle moves along the heading at `speed`, yaw rate v·tan(α)/L, and the fork
    /// root sits `root_ahead_m` ahead of the front axle.
    pub fn propagate(
        &mut self,
        speed_mps: f64,
        steer_rad: f64,
        wheelbase_m: f64,
        root_ahead_m: f64,
        dt_s: f64,
    ) {
        let step = OdometryStep {
            t_s: self.clock_s,
            speed_mps,
            steer_rad,
            wheelbase_m,
            root_ahead_m,
            dt_s,
        };
        self.clock_s += dt_s;
        self.history.push_back(step);
        while self
            .history
            .front()
            .is_some_and(|s| s.t_s < self.clock_s - HISTORY_S)
        {
            self.history.pop_front();
        }
        if let Some(p) = &mut self.pose {
            *p = advance(p, &step);
        }
    }

    pub fn pose(&self) -> Option<Pose2> {
        self.pose
    }
}

/// The fork-root pose `p` carried `dt_s` at `speed_mps` and steering `steer_rad` by the
/// rear-steer kinematics (front axle `root_ahead_m` behind the root).
pub fn advance_pose(
    p: &Pose2,
    (speed_mps, steer_rad): (f64, f64),
    (wheelbase_m, root_ahead_m): (f64, f64),
    dt_s: f64,
) -> Pose2 {
    let s = OdometryStep {
        t_s: 0.0,
        speed_mps,
        steer_rad,
        wheelbase_m,
        root_ahead_m,
        dt_s,
    };
    advance(p, &s)
}

/// `p` carried over one odometry step.
fn advance(p: &Pose2, s: &OdometryStep) -> Pose2 {
    let (speed_mps, dt_s, root_ahead_m) = (s.speed_mps, s.dt_s, s.root_ahead_m);
    let (sn, c) = p.heading_rad.sin_cos();
    let axle = [p.x_m - c * root_ahead_m, p.y_m - sn * root_ahead_m];
    let yaw_rate = speed_mps * s.steer_rad.tan() / s.wheelbase_m;
    let mid = p.heading_rad + 0.5 * yaw_rate * dt_s;
    let axle = [
        axle[0] + speed_mps * dt_s * mid.cos(),
        axle[1] + speed_mps * dt_s * mid.sin(),
    ];
    let h = p.heading_rad + yaw_rate * dt_s;
    Pose2::new(
        axle[0] + h.cos() * root_ahead_m,
        axle[1] + h.sin() * root_ahead_m,
        h,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_steer_traces_the_kinematic_circle() {
        let (l, d) = (1.629, 0.45);
        let alpha = 0.5_f64;
        let mut p = PosePredictor::new();
        p.fix(Pose2::new(d, 0.0, 0.0));
        let r = l / alpha.tan();
        // Quarter turn of the front axle about the centre (0, r).
        let steps = 10_000;
        let arc = r * std::f64::consts::FRAC_PI_2;
        for _ in 0..steps {
            p.propagate(1.0, alpha, l, d, arc / steps as f64);
        }
        let q = p.pose().expect("fixed");
        assert!((q.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
        // Front axle at (r, r); fork root d further along +y.
        assert!(
            (q.x_m - r).abs() < 1e-6 && (q.y_m - (r + d)).abs() < 1e-6,
            "{q:?}"
        );
    }

    /// A fix measured 0.1 s ago at 0.8 m/s: carried to now, it lands on the truth;
    /// taken as current, it would put the truck 8 cm behind.
    #[test]
    fn a_late_fix_is_carried_forward_not_back_in_time() {
        let (l, d, dt, v) = (1.629, 0.45, 0.01, 0.8);
        let mut p = PosePredictor::new();
        let truth = |t: f64| Pose2::new(d + v * t, 0.0, 0.0);
        p.fix(truth(0.0));
        for k in 0..100 {
            p.propagate(v, 0.0, l, d, dt);
            let now = (k + 1) as f64 * dt;
            if k % 12 == 11 {
                let age = 0.1;
                p.fix_measured_ago(truth(now - age), age);
            }
            let err = p.pose().expect("fixed").distance_to(&truth(now));
            assert!(err < 1e-9, "at {now}: {err}");
        }
        let mut stale = PosePredictor::new();
        stale.fix(truth(0.0));
        stale.propagate(v, 0.0, l, d, dt);
        stale.fix(truth(0.01 - 0.1));
        assert!(stale.pose().expect("fixed").distance_to(&truth(0.01)) > 0.079);
    }
}
