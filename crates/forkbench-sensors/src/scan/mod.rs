//! Planar range scanners that look at the world through ray casts (a `WorldView`), never at the truth: a scan from a pose, with ideal rays or the model's errors.

mod caster;
mod config;

pub use config::{MAX_SWEEP_S, REACH_MARGIN_M, SCANNER_PRESETS, ScannerConfig};

use forkbench_core::Pose2;
use forkbench_core::signal::Scan;
use rand::{Rng, RngExt as _};

use caster::{Caster, spot_return};

/// What a ray hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seen {
    /// A fixed obstacle: rack, upright, wall.
    Fixed,
    /// A pallet's stringer (pallet index in the world).
    Pallet(usize),
}

/// The first surface along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    pub range_m: f64,
    /// Unit surface normal at the hit, in the map frame.
    pub normal: [f64; 2],
    pub seen: Seen,
}

/// A straight piece of a surface: from `a` to `b`, facing along `normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    pub a: [f64; 2],
    pub b: [f64; 2],
    pub normal: [f64; 2],
    pub seen: Seen,
}

impl Surface {
    /// How far along the ray from `o` in the unit direction `d` it meets this surface,
    /// within `max_m`.
    pub fn ray_range(&self, o: [f64; 2], d: [f64; 2], max_m: f64) -> Option<f64> {
        let e = [self.b[0] - self.a[0], self.b[1] - self.a[1]];
        let den = d[0] * e[1] - d[1] * e[0];
        if den.abs() < 1e-12 {
            return None;
        }
        let w = [self.a[0] - o[0], self.a[1] - o[1]];
        let t = (w[0] * e[1] - w[1] * e[0]) / den;
        let u = (w[0] * d[1] - w[1] * d[0]) / den;
        (t >= 0.0 && t <= max_m && (0.0..=1.0).contains(&u)).then_some(t)
    }

    /// The four sides of a `length_m` × `width_m` rectangle centred on `centre` (length
    /// along its heading), each facing outward.
    pub fn rect(centre: &Pose2, length_m: f64, width_m: f64, seen: Seen) -> [Surface; 4] {
        let k = forkbench_core::geometry::rect_corners(centre, length_m, width_m);
        let (s, c) = centre.heading_rad.sin_cos();
        // Corners run counter-clockwise from front left: top, left, bottom, right sides.
        let normals = [[-s, c], [-c, -s], [s, -c], [c, s]];
        std::array::from_fn(|i| Surface {
            a: k[i],
            b: k[(i + 1) % 4],
            normal: normals[i],
            seen,
        })
    }
}

/// A read-only view of the world that sensors cast rays into. The truck's own body and
/// forks are not in it: its sensors are mounted between the forks.
pub trait WorldView {
    /// The first hit from `origin` along the unit vector `dir` within `max_m`.
    fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<RayHit>;

    /// Every surface that may lie within `radius_m` of `centre`, appended to `out`: a
    /// scan takes them once and intersects each beam with the few in its direction.
    fn surfaces_near(&self, centre: [f64; 2], radius_m: f64, out: &mut Vec<Surface>);
}

/// How a scan is taken: ideal rays, or the sensor's errors with this trial's bias.
#[derive(Debug)]
pub enum Errors<'a, R: Rng + ?Sized> {
    /// No noise, no bias, no spot: one exact ray per beam.
    Ideal,
    Modelled {
        bias_m: f64,
        rng: &'a mut R,
    },
}

/// One scan from `sensor` (its pose in the map).
pub fn scan<R: Rng + ?Sized>(
    cfg: &ScannerConfig,
    world: &dyn WorldView,
    sensor: Pose2,
    errors: Errors<'_, R>,
) -> Scan {
    scan_swept(cfg, world, &|_| sensor, errors)
}

/// Segments a moving sweep is cast in: each beam leaves from its segment's pose, within
/// a sixteenth of the sweep's travel of its own.
const SWEEP_SEGMENTS: usize = 16;

/// A scan whose beams leave from where the sensor is as the sweep passes them:
/// `sensor_at(f)` is its true pose a fraction `f` through the sweep (0: the first beam,
/// 1: the last). The scan is stamped with the pose at its end, as a driver places it.
pub fn scan_swept<R: Rng + ?Sized>(
    cfg: &ScannerConfig,
    world: &dyn WorldView,
    sensor_at: &dyn Fn(f64) -> Pose2,
    mut errors: Errors<'_, R>,
) -> Scan {
    let n = cfg.beams();
    let angle_min_rad = -cfg.fov_rad / 2.0;
    let end = sensor_at(1.0);
    let segments = if cfg.sweep_s > 0.0 && sensor_at(0.0) != end {
        SWEEP_SEGMENTS.min(n.max(1))
    } else {
        1
    };
    let poses: Vec<Pose2> = if segments == 1 {
        vec![end]
    } else {
        (0..segments)
            .map(|j| sensor_at((j as f64 + 0.5) / segments as f64))
            .collect()
    };
    let casters: Vec<Caster> = poses
        .iter()
        .map(|p| Caster::new(world, p, cfg.range_max_m + 1.0))
        .collect();
    let ranges_m = (0..n)
        .map(|i| {
            let j = i * segments / n.max(1);
            let (pose, caster) = (&poses[j], &casters[j]);
            let a = pose.heading_rad + angle_min_rad + i as f64 * cfg.step_rad;
            let r = match &mut errors {
                Errors::Ideal => caster.cast(a).map(|h| h.range_m),
                Errors::Modelled { bias_m, rng } => spot_return(cfg, caster, a).map(|(r, th)| {
                    let z: f64 = rng.sample(rand_distr::StandardNormal);
                    r + *bias_m + cfg.range_sigma_at(r, th) * z
                }),
            };
            r.filter(|r| (cfg.range_min_m..=cfg.range_max_m).contains(r))
                .unwrap_or(f64::NAN)
        })
        .collect();
    Scan {
        sensor: end,
        angle_min_rad,
        angle_step_rad: cfg.step_rad,
        range_min_m: cfg.range_min_m,
        range_max_m: cfg.range_max_m,
        ranges_m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wall along x = 5 (normal −x) and nothing else.
    struct Wall;

    impl WorldView for Wall {
        fn cast_ray(&self, o: [f64; 2], d: [f64; 2], max_m: f64) -> Option<RayHit> {
            if d[0] <= 0.0 {
                return None;
            }
            let t = (5.0 - o[0]) / d[0];
            (t <= max_m).then_some(RayHit {
                range_m: t,
                normal: [-1.0, 0.0],
                seen: Seen::Fixed,
            })
        }

        fn surfaces_near(&self, _: [f64; 2], _: f64, out: &mut Vec<Surface>) {
            out.push(Surface {
                a: [5.0, -100.0],
                b: [5.0, 100.0],
                normal: [-1.0, 0.0],
                seen: Seen::Fixed,
            });
        }
    }

    #[test]
    fn ideal_rays_meet_the_wall_where_geometry_says() {
        let cfg = ScannerConfig::tim561();
        assert_eq!(cfg.beams(), 819);
        let s =
            scan::<rand::rngs::ThreadRng>(&cfg, &Wall, Pose2::new(1.0, 0.0, 0.0), Errors::Ideal);
        for (i, r) in s.ranges_m.iter().enumerate() {
            let a = s.angle_min_rad + i as f64 * s.angle_step_rad;
            let want = 4.0 / a.cos();
            if a.cos() > 0.0 && want <= cfg.range_max_m {
                assert!((r - want).abs() < 1e-9, "beam {i}: {r} vs {want}");
            } else {
                assert!(r.is_nan(), "beam {i} at {a} rad: {r}");
            }
        }
    }

    #[test]
    fn grazing_beams_and_bad_settings_are_refused() {
        let cfg = ScannerConfig::tim561();
        // 85° off the wall's normal: past the 80° cut-off, no return.
        let near = Caster::new(&Wall, &Pose2::new(4.9, 0.0, 0.0), 11.0);
        assert_eq!(near.range(&cfg, 85f64.to_radians()), None);
        assert!(near.range(&cfg, 0.0).is_some());
        let wide = ScannerConfig {
            fov_rad: 7.0,
            ..ScannerConfig::tim561()
        };
        assert_eq!(
            wide.validate().expect_err("fov").field.as_deref(),
            Some("fov_rad")
        );
        let neg = ScannerConfig {
            range_sigma_m: -1.0,
            ..ScannerConfig::tim561()
        };
        assert_eq!(
            neg.validate().expect_err("σ").field.as_deref(),
            Some("range_sigma_m")
        );
    }

    #[test]
    fn kinect2_row_has_its_columns_and_range_growing_noise() {
        use rand::SeedableRng;
        let cfg = ScannerConfig::kinect2();
        assert_eq!(cfg.beams(), 512);
        cfg.validate().expect("valid");
        // Fankhauser et al.'s axial model head-on: 1.3 mm at 1 m, 4.3 mm at 4 m.
        assert!((cfg.range_sigma_at(1.0, 0.0) - 0.0013).abs() < 1e-12);
        assert!((cfg.range_sigma_at(4.0, 0.0) - 0.0043).abs() < 1e-12);
        // Two metres from the wall: residuals over the model's σ have unit spread.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let (mut n, mut ss) = (0usize, 0.0);
        for _ in 0..20 {
            let bias_m = 0.0;
            let s = scan(
                &cfg,
                &Wall,
                Pose2::new(3.0, 0.0, 0.0),
                Errors::Modelled {
                    bias_m,
                    rng: &mut rng,
                },
            );
            for (i, r) in s.ranges_m.iter().enumerate() {
                let a = s.angle_min_rad + i as f64 * s.angle_step_rad;
                let want = 2.0 / a.cos();
                ss += ((r - want) / cfg.range_sigma_at(want, a.abs())).powi(2);
                n += 1;
            }
        }
        let sd = (ss / n as f64).sqrt();
        assert!((sd - 1.0).abs() < 0.05, "normalised sd {sd} over {n} beams");
        let neg = ScannerConfig {
            range_sigma_per_m: -0.01,
            ..ScannerConfig::kinect2()
        };
        assert_eq!(
            neg.validate().expect_err("σ < 0").field.as_deref(),
            Some("range_sigma_per_m")
        );
    }
}
