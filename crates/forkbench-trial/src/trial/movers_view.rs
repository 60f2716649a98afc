//! The world as the trial's scanners see it with people and other vehicles in it: the simulator's racks, walls and pallet, and each mover's legs or outline.

use forkbench_safety::Mover;
use forkbench_sensors::scan::{RayHit, Seen, Surface, WorldView};
use forkbench_sim::Sim;

/// The simulator's world with the movers in it (they occlude; the physics never pushes
/// them).
pub(crate) struct WithMovers<'w> {
    pub(crate) sim: &'w Sim,
    pub(crate) movers: &'w [Mover],
}

impl WithMovers<'_> {
    fn mover_surfaces(&self, centre: [f64; 2], radius_m: f64, out: &mut Vec<Surface>) {
        for m in self.movers {
            for (p, l, w) in m.seen() {
                if (p.x_m - centre[0]).hypot(p.y_m - centre[1]) <= radius_m + l.hypot(w) {
                    out.extend(Surface::rect(&p, l, w, Seen::Fixed));
                }
            }
        }
    }
}

impl WorldView for WithMovers<'_> {
    fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<RayHit> {
        let mut best = self.sim.cast_ray(origin, dir, max_m);
        let mut surfaces = Vec::new();
        self.mover_surfaces(origin, max_m, &mut surfaces);
        for f in &surfaces {
            if let Some(t) = f.ray_range(origin, dir, max_m)
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

    fn surfaces_near(&self, centre: [f64; 2], radius_m: f64, out: &mut Vec<Surface>) {
        self.sim.surfaces_near(centre, radius_m, out);
        self.mover_surfaces(centre, radius_m, out);
    }
}

impl super::state::Trial<'_> {
    /// The movers' legs and outlines as map segments, for sensors that only ask whether
    /// a sight line is clear (the NAV350's reflectors); none without movers.
    pub(super) fn movers_in_sight(&self) -> Vec<[[f64; 2]; 2]> {
        let Some(s) = &self.safety else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for m in &s.movers {
            for (p, l, w) in m.seen() {
                for f in Surface::rect(&p, l, w, Seen::Fixed) {
                    out.push([f.a, f.b]);
                }
            }
        }
        out
    }
}
