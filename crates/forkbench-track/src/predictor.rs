//! Dead reckoning between NAV350 fixes from wheel odometry (measured speed and steering), as trucks do.

use forkbench_core::Pose2;

/// Holds the last localisation fix and propagates it with odometry until the next one.
#[derive(Debug, Clone, Default)]
pub struct PosePredictor {
    pose: Option<Pose2>,
}

impl PosePredictor {
    pub fn new() -> Self {
        Self::default()
    }

    /// A new fix replaces the prediction.
    pub fn fix(&mut self, measured: Pose2) {
        self.pose = Some(measured);
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
        if let Some(p) = &mut self.pose {
            let (s, c) = p.heading_rad.sin_cos();
            let axle = [p.x_m - c * root_ahead_m, p.y_m - s * root_ahead_m];
            let yaw_rate = speed_mps * steer_rad.tan() / wheelbase_m;
            let mid = p.heading_rad + 0.5 * yaw_rate * dt_s;
            let axle = [
                axle[0] + speed_mps * dt_s * mid.cos(),
                axle[1] + speed_mps * dt_s * mid.sin(),
            ];
            let h = p.heading_rad + yaw_rate * dt_s;
            *p = Pose2::new(
                axle[0] + h.cos() * root_ahead_m,
                axle[1] + h.sin() * root_ahead_m,
                h,
            );
        }
    }

    pub fn pose(&self) -> Option<Pose2> {
        self.pose
    }
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
}
