//! The tyres' impulses on the truck: the traction where the layout puts it, and the side grip of the fixed axle and the steered wheel.

use super::*;

/// Where the steered wheel touches the floor, a wheelbase behind the fixed axle's centre
/// `axle`.
fn steered_wheel_point(axle: &Pose2, wheelbase_m: f64) -> [f64; 2] {
    let (s, c) = axle.heading_rad.sin_cos();
    [axle.x_m - c * wheelbase_m, axle.y_m - s * wheelbase_m]
}

impl Sim {
    /// Drive/brake force from the drive's speed loop where the layout puts the traction, at
    /// most what the driven tyres' grip on the floor can pass (μ times their axle's load).
    pub(crate) fn apply_drive(&mut self, speed_cmd: f64, dt: f64) {
        if self.spec.layout.steered_drive_wheel() {
            return self.apply_wheel_drive(speed_cmd, dt);
        }
        let a = self.front_axle_pose();
        let v = self.speed_mps();
        let accel = self.drive.accel(
            speed_cmd,
            v,
            self.cfg.speed_gain_per_s,
            self.cfg.max_accel_mps2,
        );
        let grip_n = self.cfg.tyre_friction * self.axle_loads_n()[0];
        let j = (self.truck_mass_kg * accel).clamp(-grip_n, grip_n) * dt;
        let (s, c) = a.heading_rad.sin_cos();
        let b = &mut self.world.bodies[self.truck];
        let p = b.translation();
        b.apply_impulse_at_point(v2(j * c, j * s), p, true);
    }

    /// A steered drive wheel's motor holds the wheel's own rolling speed: the command
    /// for the fixed axle over the cosine of the steering angle (the fixed axle moves at the
    /// wheel's speed times that cosine), capped at the truck's top speed (or the command's,
    /// if faster), so a wheel turned to 90° spins the truck on the spot at that speed
    /// rather than without bound.
    /// It pushes along its heading at its contact point, at most what its grip passes.
    fn apply_wheel_drive(&mut self, speed_cmd: f64, dt: f64) {
        let a = self.front_axle_pose();
        let wheel = steered_wheel_point(&a, self.spec.wheelbase_m);
        let along = a.heading_rad - self.steer_rad;
        let (hs, hc) = along.sin_cos();
        let b = &self.world.bodies[self.truck];
        let v = b.velocity_at_point(v2(wheel[0], wheel[1]));
        let rolling = v.x as f64 * hc + v.y as f64 * hs;
        let top = self.spec.max_speed_mps.max(speed_cmd.abs());
        let wheel_cmd = (speed_cmd / self.steer_rad.cos().max(1e-3)).clamp(-top, top);
        let accel = self.drive.accel(
            wheel_cmd,
            rolling,
            self.cfg.speed_gain_per_s,
            self.cfg.max_accel_mps2,
        );
        let grip_n = self.cfg.tyre_friction * self.axle_loads_n()[1];
        let j = (self.truck_mass_kg * accel).clamp(-grip_n, grip_n) * dt;
        let b = &mut self.world.bodies[self.truck];
        b.apply_impulse_at_point(v2(j * hc, j * hs), v2(wheel[0], wheel[1]), true);
    }

    /// Lateral tyre impulses at the front axle and the steered rear wheel that cancel
    /// side slip (solved together: they couple through the yaw), each capped at μ N dt.
    pub(crate) fn apply_tyres(&mut self, dt: f64) {
        let a = self.front_axle_pose();
        let (s, c) = a.heading_rad.sin_cos();
        let l = self.spec.wheelbase_m;
        let b = &self.world.bodies[self.truck];
        let com = b.center_of_mass();
        let com = [com.x as f64, com.y as f64];
        let lin = b.linvel();
        let lin = [lin.x as f64, lin.y as f64];
        let w = b.angvel() as f64;
        let pf = [a.x_m, a.y_m];
        let pr = steered_wheel_point(&a, l);
        let nf = [-s, c];
        // Rear wheel points at −α for a left (positive) turn: the ICR lies on the front axle line.
        let hr = a.heading_rad - self.steer_rad;
        let nr = [-hr.sin(), hr.cos()];
        let pts = [(pf, nf), (pr, nr)];
        let r = pts.map(|(p, _)| [p[0] - com[0], p[1] - com[1]]);
        let u = [0, 1].map(|k| {
            let ((_, n), ri) = (pts[k], r[k]);
            let vp = [lin[0] - w * ri[1], lin[1] + w * ri[0]];
            vp[0] * n[0] + vp[1] * n[1]
        });
        let (m, i) = (self.truck_mass_kg, self.truck_inertia);
        let k = |a: usize, bb: usize| {
            let (na, nb) = (pts[a].1, pts[bb].1);
            (na[0] * nb[0] + na[1] * nb[1]) / m + cross(r[a], na) * cross(r[bb], nb) / i
        };
        let kk = [[k(0, 0), k(0, 1)], [k(1, 0), k(1, 1)]];
        let det = kk[0][0] * kk[1][1] - kk[0][1] * kk[1][0];
        if det.abs() < 1e-18 {
            return;
        }
        let lam = [
            -(kk[1][1] * u[0] - kk[0][1] * u[1]) / det,
            -(kk[0][0] * u[1] - kk[1][0] * u[0]) / det,
        ];
        let loads = self.axle_loads_n();
        let b = &mut self.world.bodies[self.truck];
        for (idx, ((p, n), lam)) in pts.iter().zip(lam).enumerate() {
            let cap = self.cfg.tyre_friction * loads[idx] * dt;
            let lam = lam.clamp(-cap, cap);
            b.apply_impulse_at_point(v2(lam * n[0], lam * n[1]), v2(p[0], p[1]), true);
        }
    }
}
