//! A corridor bend (two legs of width W at angle θ) and an exact test of a moving rectangle against its walls.

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_geom::{Footprint, Obstacles};

/// Least clearance kept by every check (a search adds the sagitta of its own arcs, see
/// `Space::margin_m`), so motions checked at their end poses are free.
pub const MARGIN_M: f64 = 1e-4;

/// The bend: leg 1 runs along +y (centre line x = 0) up to the corner, leg 2 leaves it
/// turned right by `angle_rad`; the centre lines cross at the origin. The outer corner I
/// is on the left, the inner corner J on the right. In a T junction (90° only) leg 2 is
/// one arm of a crossbar that continues to the left: no outer wall along leg 1, and a
/// second inner corner K on the left.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bend {
    pub width_m: f64,
    pub angle_rad: f64,
    /// Leg 2 direction and its left normal.
    pub d2: [f64; 2],
    pub l2: [f64; 2],
    /// Inner corner.
    pub j: [f64; 2],
    /// Outer corner (L) or the left arm's inner corner K (T).
    pub i: [f64; 2],
    pub tee: bool,
}

/// The junction a vehicle turns through.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Junction {
    /// Two legs meeting at an angle (an L at 90°).
    L,
    /// Turning from the stem of a T into its right arm (90°).
    T,
}

impl Junction {
    pub fn bend(self, width_m: f64, angle_rad: f64) -> Bend {
        match self {
            Junction::L => Bend::new(width_m, angle_rad),
            Junction::T => Bend::tee(width_m),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Junction::L => "L",
            Junction::T => "T",
        }
    }
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

impl Bend {
    pub fn new(width_m: f64, angle_rad: f64) -> Self {
        let (s, c) = angle_rad.sin_cos();
        let t = (angle_rad / 2.0).tan();
        let hw = width_m / 2.0;
        Self {
            width_m,
            angle_rad,
            d2: [s, c],
            l2: [-c, s],
            j: [hw, -hw * t],
            i: [-hw, hw * t],
            tee: false,
        }
    }

    /// A T junction of corridors of width `width_m`, turning right from the stem.
    pub fn tee(width_m: f64) -> Self {
        let hw = width_m / 2.0;
        Self {
            i: [-hw, -hw],
            tee: true,
            ..Self::new(width_m, std::f64::consts::FRAC_PI_2)
        }
    }

    /// The inner blocks: apex and the two directions they extend in (down leg 1, and
    /// along the crossbar away from the stem).
    fn blocks(&self) -> impl Iterator<Item = ([f64; 2], [f64; 2], [f64; 2])> {
        let j = (self.j, [0.0, -1.0], self.d2);
        let k = (self.i, [0.0, -1.0], [-self.d2[0], -self.d2[1]]);
        std::iter::once(j).chain(self.tee.then_some(k))
    }

    /// Heading of leg 1 and of leg 2 (rad, from +x).
    pub fn headings(&self) -> (f64, f64) {
        let h1 = std::f64::consts::FRAC_PI_2;
        (h1, h1 - self.angle_rad)
    }

    /// Distance from a point of the corridor to its nearest wall (negative outside).
    pub fn clearance(&self, p: [f64; 2]) -> f64 {
        let hw = self.width_m / 2.0;
        let mut outer = hw - dot(self.l2, p);
        if !self.tee {
            outer = outer.min(p[0] + hw);
        }
        if p[0] > hw && dot(self.l2, p) < -hw {
            return -(p[0] - hw).min(-hw - dot(self.l2, p));
        }
        if self.tee && p[0] < -hw && dot(self.l2, p) < -hw {
            return -(-hw - p[0]).min(-hw - dot(self.l2, p));
        }
        // Distance to each inner block: the rays from its apex along its two walls.
        let ray = |apex: [f64; 2], dir: [f64; 2]| {
            let v = [p[0] - apex[0], p[1] - apex[1]];
            let t = dot(v, dir).max(0.0);
            (v[0] - t * dir[0]).hypot(v[1] - t * dir[1])
        };
        self.blocks()
            .map(|(apex, e1, e2)| ray(apex, e1).min(ray(apex, e2)))
            .fold(outer, f64::min)
    }

    /// True when the body sweeping linearly from corners `a` to corners `b` (a translation
    /// exactly; a small rotation up to the margin) stays inside the corridor. Separating
    /// axes against the inner wall block (a convex wedge at J) and corner tests against
    /// the two outer walls (convex side). Testing a subset of axes can only err towards
    /// "collides", never the other way.
    pub fn sweep_free(&self, a: &[[f64; 2]; 4], b: &[[f64; 2]; 4], margin_m: f64) -> bool {
        let edge = |q: &[[f64; 2]; 4], i: usize| {
            let d = [q[(i + 1) % 4][0] - q[i][0], q[(i + 1) % 4][1] - q[i][1]];
            let n = d[0].hypot(d[1]).max(1e-12);
            [-d[1] / n, d[0] / n]
        };
        self.sweep_free_axes(
            a,
            b,
            [edge(a, 0), edge(a, 1), edge(b, 0), edge(b, 1)],
            margin_m,
        )
    }

    /// [`Bend::sweep_free`] with the bodies' edge normals given (unit vectors of `a`'s two
    /// edge directions' normals, then `b`'s), as a search that caches them per heading does.
    pub fn sweep_free_axes(
        &self,
        a: &[[f64; 2]; 4],
        b: &[[f64; 2]; 4],
        edge_normals: [[f64; 2]; 4],
        margin_m: f64,
    ) -> bool {
        let hw = self.width_m / 2.0;
        let m = margin_m;
        let pts = a.iter().chain(b.iter());
        // Outer walls: x ≥ -W/2 (L only) and l2·p ≤ W/2 for every corner (the sweep lies
        // in their hull).
        for p in pts.clone() {
            if (!self.tee && p[0] < -hw + m) || dot(self.l2, *p) > hw - m {
                return false;
            }
        }
        // Each inner block (a convex wedge) must be separated along one axis: its own wall
        // normals, the body's edge normals at both ends, or the normal of the motion.
        let mut axes: [[f64; 2]; 7] = [
            [1.0, 0.0],
            self.l2,
            [0.0; 2],
            [0.0; 2],
            [0.0; 2],
            [0.0; 2],
            [0.0; 2],
        ];
        axes[2..6].copy_from_slice(&edge_normals);
        let v = [b[0][0] - a[0][0], b[0][1] - a[0][1]];
        let nv = v[0].hypot(v[1]);
        let count = if nv > 1e-12 {
            axes[6] = [-v[1] / nv, v[0] / nv];
            7
        } else {
            6
        };
        let axes = &axes[..count];
        self.blocks().all(|(apex, e1, e2)| {
            axes.iter().any(|u| {
                // The wedge projects onto [u·apex, ∞) when both its directions have
                // u·e ≥ 0, onto (-∞, u·apex] when both have u·e ≤ 0 (1e-12: exact zeros
                // computed with rounding), and onto everything otherwise.
                let (ue1, ue2) = (dot(*u, e1), dot(*u, e2));
                let au = dot(*u, apex);
                let (lo, hi) = pts
                    .clone()
                    .map(|p| dot(*u, *p))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                        (l.min(x), h.max(x))
                    });
                (ue1 >= -1e-12 && ue2 >= -1e-12 && hi <= au - m)
                    || (ue1 <= 1e-12 && ue2 <= 1e-12 && lo >= au + m)
            })
        })
    }

    /// The same walls as parry2d obstacles, for independent validation. The inner block
    /// (the wedge at J) is, up to 90°, the union of two rectangles: one beyond leg 1's
    /// inner wall below J, one beyond leg 2's inner wall past J; parry2d tests rectangle
    /// pairs exactly by separating axes, whereas its general convex test (GJK) reported
    /// contact across gaps of 0.3 mm with 6 m shapes (2 mm with 60 m). Sharper bends use a
    /// triangle. Each outer side is a thick rectangle beyond its wall line.
    pub fn obstacles(&self, reach_m: f64) -> Obstacles {
        // Covers the searched legs plus half a body.
        let far = 1.5 * reach_m;
        let mut o = Obstacles::new();
        let (h1, h2) = self.headings();
        let hw = self.width_m / 2.0;
        let j = self.j;
        if self.angle_rad <= std::f64::consts::FRAC_PI_2 + 1e-12 {
            // Below J, right of x = W/2.
            o.add_rect(
                &Pose2::new(j[0] + far / 2.0, j[1] - far / 2.0, 0.0),
                far,
                far,
            );
            // Past J along leg 2, right of its inner wall (−l2 side).
            let c = [
                j[0] + self.d2[0] * far / 2.0 - self.l2[0] * far / 2.0,
                j[1] + self.d2[1] * far / 2.0 - self.l2[1] * far / 2.0,
            ];
            o.add_rect(&Pose2::new(c[0], c[1], h2), far, far);
        } else {
            o.add_convex(&[
                j,
                [j[0], j[1] - far],
                [j[0] + self.d2[0] * far, j[1] + self.d2[1] * far],
            ]);
        }
        if self.tee {
            // The left arm's inner block, a quadrant below-left of K.
            let k = self.i;
            o.add_rect(
                &Pose2::new(k[0] - far / 2.0, k[1] - far / 2.0, 0.0),
                far,
                far,
            );
        }
        let outer: &[(f64, [f64; 2])] = if self.tee {
            &[(h2, self.l2)]
        } else {
            &[(h1, [-1.0, 0.0]), (h2, self.l2)]
        };
        for &(heading, normal) in outer {
            let centre = [normal[0] * (hw + far / 2.0), normal[1] * (hw + far / 2.0)];
            o.add_rect(&Pose2::new(centre[0], centre[1], heading), 4.0 * far, far);
        }
        o
    }
}

/// A rectangular vehicle and the point it turns about.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vehicle {
    pub length_m: f64,
    pub width_m: f64,
    /// Kinematic point (the one that moves along the heading) ahead of the body centre:
    /// 0 for an AMV, the front axle for the forklift.
    pub kinematic_ahead_m: f64,
    /// Smallest turning radius of the kinematic point (forklift mode).
    pub min_radius_m: f64,
}

impl Vehicle {
    /// The forklift body (forks excluded) turning about its front axle, which lies
    /// L/2 − (fork root ahead of the axle) ahead of the body centre, at r_min = wheelbase /
    /// tan(α_max).
    pub fn forklift(spec: &ForkliftSpec) -> Self {
        Self {
            length_m: spec.body_length_m,
            width_m: spec.body_width_m,
            kinematic_ahead_m: spec.body_length_m / 2.0 - spec.fork_root_ahead_of_front_axle_m,
            min_radius_m: spec.wheelbase_m
                / spec.layout.planning_lock_rad(spec.max_steer_rad).tan(),
        }
    }

    /// Inscribed-circle diameter Li = Wc and circumscribed diameter L0.
    pub fn inscribed_m(&self) -> f64 {
        self.width_m
    }

    pub fn circumscribed_m(&self) -> f64 {
        self.length_m.hypot(self.width_m)
    }

    /// Corners of the body centred at `c` with heading `h`.
    pub fn corners(&self, c: [f64; 2], h: f64) -> [[f64; 2]; 4] {
        Footprint::centred(self.length_m, self.width_m).corners(&Pose2::new(c[0], c[1], h))
    }

    pub fn footprint(&self) -> Footprint {
        Footprint::centred(self.length_m, self.width_m)
    }
}

/// Closed form, oblique translation: the body keeps leg 1's heading, so across leg 2 it
/// is a rectangle turned by θ, whose width there is Lc·|sin θ| + Wc·|cos θ| (and Wc in
/// leg 1). Largest at θ = arctan(Lc/Wc), where it equals the diagonal L0.
pub fn oblique_min_width_m(v: &Vehicle, angle_rad: f64) -> f64 {
    (v.length_m * angle_rad.sin().abs() + v.width_m * angle_rad.cos().abs()).max(v.width_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_sweep_test_agrees_with_parry2d_on_poses() {
        let v = Vehicle {
            length_m: 0.56,
            width_m: 0.40,
            kinematic_ahead_m: 0.0,
            min_radius_m: 0.0,
        };
        let mut disagreements = 0;
        let mut n = 0;
        for (wi, deg, tee) in [
            (0.55, 30.0, false),
            (0.62, 55.0, false),
            (0.7, 90.0, false),
            (0.5, 120.0, false),
            (0.6, 90.0, true),
        ] {
            let bend = if tee {
                Bend::tee(wi)
            } else {
                Bend::new(wi, f64::to_radians(deg))
            };
            let obs = bend.obstacles(2.0);
            let mut seed = 12345u64;
            let mut rnd = || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64
            };
            for _ in 0..4000 {
                let c = [rnd() * 1.6 - 0.8, rnd() * 1.6 - 0.8];
                let h = rnd() * std::f64::consts::TAU;
                // Body centres in the corridor, as every search state is.
                if bend.clearance(c) <= 0.0 {
                    continue;
                }
                let corners = v.corners(c, h);
                let analytic = bend.sweep_free(&corners, &corners, MARGIN_M);
                let parry = !obs.collides(&v.footprint(), &Pose2::new(c[0], c[1], h));
                // Within the margin (and f32) of contact the two may differ legitimately.
                let near = {
                    let obs_in = bend.obstacles(2.0).collides(
                        &forkbench_geom::Footprint::centred(0.56 + 4e-4, 0.40 + 4e-4),
                        &Pose2::new(c[0], c[1], h),
                    );
                    let obs_out = bend.obstacles(2.0).collides(
                        &forkbench_geom::Footprint::centred(0.56 - 4e-4, 0.40 - 4e-4),
                        &Pose2::new(c[0], c[1], h),
                    );
                    obs_in != obs_out
                };
                n += 1;
                if analytic != parry && !near {
                    disagreements += 1;
                }
            }
        }
        assert_eq!(disagreements, 0, "of {n} random poses");
    }

    #[test]
    fn oblique_worst_angle_is_arctan_lc_over_wc() {
        let v = Vehicle {
            length_m: 0.56,
            width_m: 0.40,
            kinematic_ahead_m: 0.0,
            min_radius_m: 0.0,
        };
        let worst = (0..=9000)
            .map(|i| f64::to_radians(i as f64 / 100.0))
            .max_by(|a, b| oblique_min_width_m(&v, *a).total_cmp(&oblique_min_width_m(&v, *b)))
            .expect("angles");
        assert!((worst - (0.56f64 / 0.40).atan()).abs() < f64::to_radians(0.01));
        assert!((oblique_min_width_m(&v, worst) - v.circumscribed_m()).abs() < 1e-6);
    }
}
