//! Planar range scanners that look at the world through ray casts (a `WorldView`), never at the truth: the SICK TiM561 model and its settings.
//!
//! TiM561-2050101 figures (SICK, TiM55x/TiM56x operating instructions 8015886, technical
//! data): aperture 270°, angular resolution 0.33°, scanning frequency 15 Hz, working
//! range 0.05–10 m, measurement error typically 20 mm statistical (1σ) and ±60 mm
//! systematic. The light spot (SICK's TiM3xx/TiM8xx instructions, same HDDM+ family at
//! 0.33°): 8.6 mrad divergence + 5.8 mrad HDDM+ supplement, 7 mm at the cover. The
//! grazing-incidence cut-off is a modelling choice (no datasheet figure).

use forkbench_core::signal::Scan;
use forkbench_core::{Pose2, SettingsError};
use rand::{Rng, RngExt as _};
use serde::{Deserialize, Serialize};

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

/// A planar scanner's settings (SI); defaults are the TiM561.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScannerConfig {
    /// Mount in the fork-root frame (x forward along the forks, y left).
    pub mount: Pose2,
    pub fov_rad: f64,
    pub step_rad: f64,
    pub rate_hz: f64,
    pub range_min_m: f64,
    pub range_max_m: f64,
    /// Random range error, 1σ, every beam.
    pub range_sigma_m: f64,
    /// Systematic range error: drawn once per trial, uniform within ±this.
    pub range_bias_max_m: f64,
    /// Full angle the spot widens by (divergence and HDDM+ supplement), and its width at
    /// the cover: a beam whose spot straddles a depth edge returns a mixed range.
    pub spot_divergence_rad: f64,
    pub spot_at_cover_m: f64,
    /// Beyond this angle between beam and surface normal nothing comes back.
    pub max_incidence_rad: f64,
}

impl Default for ScannerConfig {
    fn default() -> Self {
        Self::tim561()
    }
}

/// Sub-rays per beam across its spot.
const SPOT_RAYS: usize = 3;
/// Sub-ray ranges further apart than this are a depth edge inside the spot.
const EDGE_M: f64 = 0.05;

/// The scanner models known by name.
pub const SCANNER_PRESETS: [&str; 1] = ["tim561"];

impl ScannerConfig {
    /// A scanner model by name ([`SCANNER_PRESETS`]), with its settings.
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "tim561" => Some(Self::tim561()),
            _ => None,
        }
    }

    /// SICK TiM561 (see the module's sources), mounted at the fork root facing forward.
    pub fn tim561() -> Self {
        Self {
            mount: Pose2::new(0.0, 0.0, 0.0),
            fov_rad: 270f64.to_radians(),
            step_rad: 0.33f64.to_radians(),
            rate_hz: 15.0,
            range_min_m: 0.05,
            range_max_m: 10.0,
            range_sigma_m: 0.020,
            range_bias_max_m: 0.060,
            spot_divergence_rad: 0.0086 + 0.0058,
            spot_at_cover_m: 0.007,
            max_incidence_rad: 80f64.to_radians(),
        }
    }

    /// Every value in its range, naming the field.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let bad = |f: &str, why: &str| Err(SettingsError::field(f, why));
        if !(self.fov_rad > 0.0 && self.fov_rad <= std::f64::consts::TAU) {
            return bad("fov_rad", "must lie in (0, 2π]");
        }
        if !(self.step_rad > 0.0 && self.step_rad <= self.fov_rad) {
            return bad("step_rad", "must be positive and at most fov_rad");
        }
        if self.fov_rad / self.step_rad > 100_000.0 {
            return bad("step_rad", "gives more than 100,000 beams");
        }
        for (f, v) in [("rate_hz", self.rate_hz), ("range_max_m", self.range_max_m)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(f, "must be a positive finite number");
            }
        }
        for (f, v) in [
            ("range_min_m", self.range_min_m),
            ("range_sigma_m", self.range_sigma_m),
            ("range_bias_max_m", self.range_bias_max_m),
            ("spot_divergence_rad", self.spot_divergence_rad),
            ("spot_at_cover_m", self.spot_at_cover_m),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(f, "must be a finite number ≥ 0");
            }
        }
        if self.range_min_m >= self.range_max_m {
            return bad("range_min_m", "must be below range_max_m");
        }
        if !(self.max_incidence_rad > 0.0 && self.max_incidence_rad <= std::f64::consts::FRAC_PI_2)
        {
            return bad("max_incidence_rad", "must lie in (0, π/2]");
        }
        if !self.mount.is_finite() {
            return bad("mount", "must be finite");
        }
        Ok(())
    }

    /// Beam count: the aperture in whole steps, both ends included.
    pub fn beams(&self) -> usize {
        (self.fov_rad / self.step_rad + 1e-9).floor() as usize + 1
    }

    /// The sensor's pose in the map for a fork-root pose.
    pub fn sensor_pose(&self, fork_root: &Pose2) -> Pose2 {
        fork_root.to_world(&self.mount)
    }

    /// The systematic error of one trial: uniform within ±`range_bias_max_m`.
    pub fn draw_bias<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        self.range_bias_max_m * (2.0 * rng.random::<f64>() - 1.0)
    }
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
    mut errors: Errors<'_, R>,
) -> Scan {
    let n = cfg.beams();
    let angle_min_rad = -cfg.fov_rad / 2.0;
    let caster = Caster::new(world, &sensor, cfg.range_max_m + 1.0);
    let ranges_m = (0..n)
        .map(|i| {
            let a = sensor.heading_rad + angle_min_rad + i as f64 * cfg.step_rad;
            let r = match &errors {
                Errors::Ideal => caster.cast(a).map(|h| h.range_m),
                Errors::Modelled { .. } => spot_return(cfg, &caster, a),
            };
            let r = match (&mut errors, r) {
                (Errors::Modelled { bias_m, rng }, Some(r)) => {
                    let z: f64 = rng.sample(rand_distr::StandardNormal);
                    Some(r + *bias_m + cfg.range_sigma_m * z)
                }
                (_, r) => r,
            };
            r.filter(|r| (cfg.range_min_m..=cfg.range_max_m).contains(r))
                .unwrap_or(f64::NAN)
        })
        .collect();
    Scan {
        sensor,
        angle_min_rad,
        angle_step_rad: cfg.step_rad,
        range_min_m: cfg.range_min_m,
        range_max_m: cfg.range_max_m,
        ranges_m,
    }
}

fn dir(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c, s]
}

/// Angular bins of the caster: each holds the surfaces a ray in it may meet.
const BIN_RAD: f64 = 1.0 * std::f64::consts::PI / 180.0;

/// Rays from one origin against the surfaces around it, binned by direction, so a beam
/// is intersected with the few surfaces it can meet (the scan's cost does not grow with
/// the whole warehouse).
struct Caster {
    origin: [f64; 2],
    max_m: f64,
    surfaces: Vec<Surface>,
    /// Bin `j` holds `members[starts[j]..starts[j + 1]]` (one allocation for all bins).
    starts: Vec<u32>,
    members: Vec<u32>,
}

impl Caster {
    fn new(world: &dyn WorldView, origin: &Pose2, max_m: f64) -> Self {
        let o = [origin.x_m, origin.y_m];
        let mut surfaces = Vec::new();
        world.surfaces_near(o, max_m, &mut surfaces);
        // Only the sides that face the origin can be hit first.
        surfaces.retain(|f| (f.a[0] - o[0]) * f.normal[0] + (f.a[1] - o[1]) * f.normal[1] < 0.0);
        let n_bins = (std::f64::consts::TAU / BIN_RAD).ceil() as usize;
        let spans: Vec<(usize, usize)> = surfaces
            .iter()
            .map(|f| Self::bins_spanned(o, f, n_bins))
            .collect();
        let mut starts = vec![0u32; n_bins + 1];
        for &(first, count) in &spans {
            for j in 0..count {
                starts[(first + j) % n_bins + 1] += 1;
            }
        }
        for j in 0..n_bins {
            starts[j + 1] += starts[j];
        }
        let mut fill = starts.clone();
        let mut members = vec![0u32; starts[n_bins] as usize];
        for (k, &(first, count)) in spans.iter().enumerate() {
            for j in 0..count {
                let bin = (first + j) % n_bins;
                members[fill[bin] as usize] = k as u32;
                fill[bin] += 1;
            }
        }
        Self {
            origin: o,
            max_m,
            surfaces,
            starts,
            members,
        }
    }

    /// The first bin a surface's angular span (seen from `o`) touches, and how many.
    fn bins_spanned(o: [f64; 2], f: &Surface, n_bins: usize) -> (usize, usize) {
        let ta = (f.a[1] - o[1]).atan2(f.a[0] - o[0]);
        let tb = (f.b[1] - o[1]).atan2(f.b[0] - o[0]);
        // The shorter arc between the ends: a segment not through the origin spans < π.
        let mut span = tb - ta;
        if span > std::f64::consts::PI {
            span -= std::f64::consts::TAU;
        } else if span < -std::f64::consts::PI {
            span += std::f64::consts::TAU;
        }
        let (start, len) = if span >= 0.0 { (ta, span) } else { (tb, -span) };
        let count = (len / BIN_RAD).ceil() as usize + 1;
        (Self::bin_of(start, n_bins), count.min(n_bins))
    }

    fn bin_of(angle: f64, n_bins: usize) -> usize {
        let t = angle.rem_euclid(std::f64::consts::TAU);
        ((t / BIN_RAD) as usize).min(n_bins - 1)
    }

    /// The nearest surface along direction `a` within range.
    fn cast(&self, a: f64) -> Option<RayHit> {
        self.cast_along(a, dir(a))
    }

    /// [`Caster::cast`] with the direction's unit vector `d` already at hand.
    fn cast_along(&self, a: f64, d: [f64; 2]) -> Option<RayHit> {
        let o = self.origin;
        let mut best: Option<RayHit> = None;
        let bin = Self::bin_of(a, self.starts.len() - 1);
        let members = &self.members[self.starts[bin] as usize..self.starts[bin + 1] as usize];
        for &k in members {
            let f = &self.surfaces[k as usize];
            let e = [f.b[0] - f.a[0], f.b[1] - f.a[1]];
            let den = d[0] * e[1] - d[1] * e[0];
            if den.abs() < 1e-12 {
                continue;
            }
            let w = [f.a[0] - o[0], f.a[1] - o[1]];
            let t = (w[0] * e[1] - w[1] * e[0]) / den;
            let u = (w[0] * d[1] - w[1] * d[0]) / den;
            if t >= 0.0
                && t <= self.max_m
                && (0.0..=1.0).contains(&u)
                && best.is_none_or(|h| t < h.range_m)
            {
                best = Some(RayHit {
                    range_m: t,
                    normal: f.normal,
                    seen: f.seen,
                });
            }
        }
        best
    }

    /// Range along `a`, `None` past the range or at grazing incidence.
    fn range(&self, cfg: &ScannerConfig, a: f64) -> Option<f64> {
        let d = dir(a);
        let hit = self.cast_along(a, d)?;
        let cos_incidence = -(d[0] * hit.normal[0] + d[1] * hit.normal[1]);
        (cos_incidence >= cfg.max_incidence_rad.cos()).then_some(hit.range_m)
    }
}

/// The beam's return from its spot: sub-rays across the spot's width at the range the
/// centre ray finds. Where they agree, the centre's range; across a depth edge the
/// echoes merge into one range between the surfaces (a mixed return), weighted by the
/// share of the spot on each; no centre return and no edge: nothing.
fn spot_return(cfg: &ScannerConfig, caster: &Caster, a: f64) -> Option<f64> {
    let centre = caster.range(cfg, a);
    let r0 = centre.unwrap_or(cfg.range_max_m);
    let half_angle = 0.5 * (cfg.spot_divergence_rad + cfg.spot_at_cover_m / r0.max(0.1));
    let mut subs = [0.0; SPOT_RAYS];
    let mut n = 0;
    for k in 0..SPOT_RAYS {
        let t = k as f64 / (SPOT_RAYS - 1) as f64;
        let offset = (2.0 * t - 1.0) * half_angle;
        // The middle sub-ray is the centre ray itself.
        let r = if offset == 0.0 {
            centre
        } else {
            caster.range(cfg, a + offset)
        };
        if let Some(r) = r {
            subs[n] = r;
            n += 1;
        }
    }
    let subs = &subs[..n];
    let (lo, hi) = subs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), r| {
            (l.min(*r), h.max(*r))
        });
    if n < 2 || hi - lo <= EDGE_M {
        return centre;
    }
    Some(subs.iter().sum::<f64>() / n as f64)
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
}
