//! Rays from one origin against the surfaces around it, and a beam's return from its light spot.

use forkbench_core::Pose2;

use super::{RayHit, ScannerConfig, Surface, WorldView};

/// Sub-rays per beam across its spot.
const SPOT_RAYS: usize = 3;
/// Sub-ray ranges further apart than this are a depth edge inside the spot.
const EDGE_M: f64 = 0.05;

fn dir(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c, s]
}

/// Angular bins of the caster: each holds the surfaces a ray in it may meet.
const BIN_RAD: f64 = 1.0 * std::f64::consts::PI / 180.0;

/// Rays from one origin against the surfaces around it, binned by direction, so a beam
/// is intersected with the few surfaces it can meet (the scan's cost does not grow with
/// the whole warehouse).
pub(super) struct Caster {
    origin: [f64; 2],
    max_m: f64,
    surfaces: Vec<Surface>,
    /// Bin `j` holds `members[starts[j]..starts[j + 1]]` (one allocation for all bins).
    starts: Vec<u32>,
    members: Vec<u32>,
}

impl Caster {
    pub(super) fn new(world: &dyn WorldView, origin: &Pose2, max_m: f64) -> Self {
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
    pub(super) fn cast(&self, a: f64) -> Option<RayHit> {
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
            if let Some(t) = f.ray_range(o, d, self.max_m)
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

    /// Range along `a` and the incidence angle there; `None` past the range or at
    /// grazing incidence.
    pub(super) fn range(&self, cfg: &ScannerConfig, a: f64) -> Option<(f64, f64)> {
        let d = dir(a);
        let hit = self.cast_along(a, d)?;
        let cos_incidence = -(d[0] * hit.normal[0] + d[1] * hit.normal[1]);
        (cos_incidence >= cfg.max_incidence_rad.cos())
            .then(|| (hit.range_m, cos_incidence.clamp(-1.0, 1.0).acos()))
    }
}

/// The beam's return from its spot: sub-rays across the spot's width at the range the
/// centre ray finds. Where they agree, the centre's range; across a depth edge the
/// echoes merge into one range between the surfaces (a mixed return), weighted by the
/// share of the spot on each; no centre return and no edge: nothing.
/// Returns the range and the incidence at the centre (head-on for a mixed return).
pub(super) fn spot_return(cfg: &ScannerConfig, caster: &Caster, a: f64) -> Option<(f64, f64)> {
    let centre = caster.range(cfg, a);
    let r0 = centre.map_or(cfg.range_max_m, |c| c.0);
    let half_angle = 0.5 * (cfg.spot_divergence_rad + cfg.spot_at_cover_m / r0.max(0.1));
    let mut subs = [0.0; SPOT_RAYS];
    let mut n = 0;
    for k in 0..SPOT_RAYS {
        let t = k as f64 / (SPOT_RAYS - 1) as f64;
        let offset = (2.0 * t - 1.0) * half_angle;
        // The middle sub-ray is the centre ray itself.
        let r = if offset == 0.0 {
            centre.map(|c| c.0)
        } else {
            caster.range(cfg, a + offset).map(|c| c.0)
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
    if cfg.echo_separation_m > 0.0 && hi - lo > cfg.echo_separation_m {
        // Two echoes told apart: the one from the larger share of the spot (the nearer on
        // a tie, which arrives first).
        let near = subs.iter().filter(|r| **r - lo <= EDGE_M).count();
        let far: Vec<f64> = subs.iter().copied().filter(|r| *r - lo > EDGE_M).collect();
        return if 2 * near >= n || far.is_empty() {
            Some((lo, 0.0))
        } else {
            Some((far.iter().sum::<f64>() / far.len() as f64, 0.0))
        };
    }
    Some((subs.iter().sum::<f64>() / n as f64, 0.0))
}
