//! One randomised scene in the scanner's frame: the pallet's parts (or none), a wall behind it, an occluder, and clutter of the kinds a warehouse puts in a scanner's view.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use forkbench_core::{PalletSpec, Pose2};
use rand::{Rng, RngExt as _};

use super::spec::DatasetSpec;
use crate::scan::{RayHit, Seen, Surface, WorldView};

/// A scene's surfaces, cast into by brute force (a few hundred at most).
#[derive(Debug, Clone, Default)]
pub struct Scene {
    pub surfaces: Vec<Surface>,
    /// The kinds placed, in order (the occluder as `occluder`, the wall behind as
    /// `wall_behind`).
    pub clutter: Vec<&'static str>,
}

impl WorldView for Scene {
    fn cast_ray(&self, o: [f64; 2], d: [f64; 2], max_m: f64) -> Option<RayHit> {
        self.surfaces
            .iter()
            .filter(|s| s.normal[0] * d[0] + s.normal[1] * d[1] < 0.0)
            .filter_map(|s| {
                s.ray_range(o, d, max_m).map(|range_m| RayHit {
                    range_m,
                    normal: s.normal,
                    seen: s.seen,
                })
            })
            .min_by(|a, b| a.range_m.total_cmp(&b.range_m))
    }

    fn surfaces_near(&self, _centre: [f64; 2], _radius_m: f64, out: &mut Vec<Surface>) {
        out.extend_from_slice(&self.surfaces);
    }
}

/// A circle the clutter keeps out of (the pallet's body, the scanner).
#[derive(Debug, Clone, Copy)]
struct KeepOut {
    centre: [f64; 2],
    radius_m: f64,
}

/// The scanner's view of the pallet: bearings (relative to `centre_rad`) and the range
/// within which clutter would stand between them, so only the occluder hides a pallet
/// and a label's "present" is a pallet in view.
#[derive(Debug, Clone, Copy)]
struct Shadow {
    centre_rad: f64,
    lo_rad: f64,
    hi_rad: f64,
    range_m: f64,
}

impl Shadow {
    fn of(pallet: &PalletSpec, face: &Pose2) -> Self {
        let centre_rad = face.y_m.atan2(face.x_m);
        let (mut lo_rad, mut hi_rad, mut range_m) = (0.0f64, 0.0f64, 0.0f64);
        let (d, w) = (pallet.depth_m, pallet.width_m / 2.0);
        for (x, y) in [(0.0, -w), (0.0, w), (d, -w), (d, w)] {
            let p = face.to_world(&Pose2::new(x, y, 0.0));
            let rel = forkbench_core::units::wrap_angle(p.y_m.atan2(p.x_m) - centre_rad);
            lo_rad = lo_rad.min(rel);
            hi_rad = hi_rad.max(rel);
            range_m = range_m.max(p.x_m.hypot(p.y_m));
        }
        Self {
            centre_rad,
            lo_rad,
            hi_rad,
            range_m,
        }
    }

    /// Whether something of radius `extent_m` at `p` stands in the view.
    fn blocks(&self, p: [f64; 2], extent_m: f64) -> bool {
        let r = p[0].hypot(p[1]);
        if r - extent_m > self.range_m {
            return false;
        }
        let margin = (extent_m / r.max(1e-6)).min(1.0).asin();
        let rel = forkbench_core::units::wrap_angle(p[1].atan2(p[0]) - self.centre_rad);
        rel + margin > self.lo_rad && rel - margin < self.hi_rad
    }
}

fn uniform<R: Rng + ?Sized>(rng: &mut R, [lo, hi]: [f64; 2]) -> f64 {
    if hi > lo {
        rng.random_range(lo..hi)
    } else {
        lo
    }
}

impl Scene {
    fn rect(&mut self, centre: &Pose2, length_m: f64, width_m: f64) {
        self.surfaces
            .extend(Surface::rect(centre, length_m, width_m, Seen::Fixed));
    }

    /// A pallet's parts with its face at `face` (heading into it).
    fn pallet(&mut self, pallet: &PalletSpec, face: &Pose2, seen: Seen) {
        for (c, l, w) in pallet.part_boxes(face) {
            self.surfaces.extend(Surface::rect(&c, l, w, seen));
        }
    }

    /// A regular polygon of `n` sides around `c` (a leg, a round post).
    fn round(&mut self, c: [f64; 2], radius_m: f64, n: usize) {
        let at = |k: usize| {
            let a = TAU * k as f64 / n as f64;
            [c[0] + radius_m * a.cos(), c[1] + radius_m * a.sin()]
        };
        for k in 0..n {
            let mid = TAU * (k as f64 + 0.5) / n as f64;
            self.surfaces.push(Surface {
                a: at(k),
                b: at(k + 1),
                normal: [mid.cos(), mid.sin()],
                seen: Seen::Fixed,
            });
        }
    }
}

/// The pallet's face for a scene with one: range, bearing and turn drawn from the spec.
pub fn draw_face<R: Rng + ?Sized>(spec: &DatasetSpec, rng: &mut R) -> Pose2 {
    let r = uniform(rng, spec.range_m);
    let b = uniform(rng, spec.bearing_deg).to_radians();
    let h = uniform(rng, spec.heading_deg).to_radians();
    Pose2::new(r * b.cos(), r * b.sin(), b + h)
}

/// A scene with the pallet at `face` (or none), its wall behind and occluder as drawn,
/// and `spec`'s clutter placed around it in view: within `view.0` m of the scanner and
/// `view.1` rad of its axis.
pub fn build<R: Rng + ?Sized>(
    spec: &DatasetSpec,
    pallet: &PalletSpec,
    face: Option<&Pose2>,
    view: (f64, f64),
    rng: &mut R,
) -> Scene {
    let mut s = Scene::default();
    let mut keep = vec![KeepOut {
        centre: [0.0, 0.0],
        radius_m: 0.6,
    }];
    let shadow = face.map(|f| Shadow::of(pallet, f));
    if let Some(face) = face {
        s.pallet(pallet, face, Seen::Pallet(0));
        let body = face.to_world(&Pose2::new(pallet.depth_m / 2.0, 0.0, 0.0));
        keep.push(KeepOut {
            centre: [body.x_m, body.y_m],
            radius_m: pallet.depth_m.hypot(pallet.width_m) / 2.0 + 0.3,
        });
        if rng.random_bool(spec.clutter.wall_behind_fraction) {
            let gap = uniform(rng, [0.1, 1.0]);
            let c = face.to_world(&Pose2::new(pallet.depth_m + gap + 0.1, 0.0, FRAC_PI_2));
            s.rect(&c, uniform(rng, [3.0, 8.0]), 0.2);
            s.clutter.push("wall_behind");
        }
        if rng.random_bool(spec.clutter.hidden_fraction) {
            occlude(&mut s, pallet, face, rng);
        }
    }
    let n = rng.random_range(spec.clutter.per_scene[0]..=spec.clutter.per_scene[1]);
    for _ in 0..n {
        let k = rng.random_range(0..spec.clutter.kinds.len());
        let kind = super::spec::CLUTTER_KINDS
            .iter()
            .find(|c| **c == spec.clutter.kinds[k])
            .copied()
            .unwrap_or("box");
        if place(&mut s, kind, pallet, (&keep, shadow.as_ref()), view, rng) {
            s.clutter.push(kind);
        }
    }
    s
}

/// A box between the scanner and a point on the face, 40–80 % of the way there.
fn occlude<R: Rng + ?Sized>(s: &mut Scene, pallet: &PalletSpec, face: &Pose2, rng: &mut R) {
    let half = pallet.width_m / 2.0;
    let target = face.to_world(&Pose2::new(0.0, uniform(rng, [-half, half]), 0.0));
    let f = uniform(rng, [0.4, 0.8]);
    let side = uniform(rng, [0.15, 0.4]);
    let c = Pose2::new(
        target.x_m * f,
        target.y_m * f,
        uniform(rng, [0.0, FRAC_PI_2]),
    );
    s.rect(&c, side, side);
    s.clutter.push("occluder");
}

/// Places one item of `kind` clear of `keep` (20 tries); false when it found no room.
fn place<R: Rng + ?Sized>(
    s: &mut Scene,
    kind: &'static str,
    pallet: &PalletSpec,
    (keep, shadow): (&[KeepOut], Option<&Shadow>),
    (reach_m, half_fov): (f64, f64),
    rng: &mut R,
) -> bool {
    // Each kind's extent: the radius it must keep from a keep-out circle.
    let extent = match kind {
        "upright" => 1.6,
        "wrapped_load" => 0.8,
        "pallet_side" => pallet.depth_m.hypot(pallet.width_m) / 2.0,
        "wall" => 0.0,
        "forks" => 0.7,
        "person" => 0.3,
        _ => 0.45,
    };
    for _ in 0..20 {
        let r = uniform(rng, [0.8, reach_m]);
        let b = uniform(rng, [-half_fov, half_fov]);
        let c = [r * b.cos(), r * b.sin()];
        let heading = uniform(rng, [-PI, PI]);
        if kind == "wall" {
            let len = uniform(rng, [2.0, 8.0]);
            let along = |t: f64| [c[0] + t * heading.cos(), c[1] + t * heading.sin()];
            let in_view = shadow.is_some_and(|sh| {
                (0..=(len * 10.0) as usize)
                    .any(|k| sh.blocks(along(k as f64 * 0.1 - len / 2.0), 0.15))
            });
            if !in_view && keep.iter().all(|k| seg_clear(&c, heading, len, k)) {
                s.rect(&Pose2::new(c[0], c[1], heading), len, 0.2);
                return true;
            }
            continue;
        }
        let clear = keep
            .iter()
            .all(|k| (c[0] - k.centre[0]).hypot(c[1] - k.centre[1]) > k.radius_m + extent)
            && !shadow.is_some_and(|sh| sh.blocks(c, extent));
        if clear {
            item(s, kind, pallet, c, heading, b, rng);
            return true;
        }
    }
    false
}

/// Whether a wall of `len` centred at `c` along `heading` (0.2 m thick) stays clear of `k`.
fn seg_clear(c: &[f64; 2], heading: f64, len: f64, k: &KeepOut) -> bool {
    let (dx, dy) = (heading.cos(), heading.sin());
    let (px, py) = (k.centre[0] - c[0], k.centre[1] - c[1]);
    let t = (px * dx + py * dy).clamp(-len / 2.0, len / 2.0);
    (px - t * dx).hypot(py - t * dy) > k.radius_m + 0.1
}

/// Draws one item's surfaces at `c` (`bearing`: its direction from the scanner).
fn item<R: Rng + ?Sized>(
    s: &mut Scene,
    kind: &str,
    pallet: &PalletSpec,
    c: [f64; 2],
    heading: f64,
    bearing: f64,
    rng: &mut R,
) {
    let at = |x: f64, y: f64| Pose2::new(c[0], c[1], heading).to_world(&Pose2::new(x, y, 0.0));
    match kind {
        "upright" => {
            // A rack frame's front and back posts and its neighbour's: the spacing of
            // bays is what makes uprights look like a pallet's parts.
            let bay = uniform(rng, [0.9, 2.8]);
            let depth = uniform(rng, [0.8, 1.1]);
            let post = uniform(rng, [0.08, 0.12]);
            for (x, y) in [(0.0, 0.0), (0.0, bay), (depth, 0.0), (depth, bay)] {
                let p = at(x - depth / 2.0, y - bay / 2.0);
                s.rect(&Pose2::new(p.x_m, p.y_m, heading), post, post);
            }
        }
        "box" => {
            let (l, w) = (uniform(rng, [0.3, 0.8]), uniform(rng, [0.3, 0.8]));
            s.rect(&Pose2::new(c[0], c[1], heading), l, w);
        }
        "wrapped_load" => {
            let (l, w) = (uniform(rng, [0.8, 1.2]), uniform(rng, [0.8, 1.2]));
            s.rect(&Pose2::new(c[0], c[1], heading), l, w);
        }
        "person" => {
            let apart = uniform(rng, [0.15, 0.35]);
            for y in [-apart / 2.0, apart / 2.0] {
                let p = at(0.0, y);
                s.round([p.x_m, p.y_m], uniform(rng, [0.05, 0.07]), 8);
            }
        }
        "pallet_side" => {
            // Turned 75–105° from facing the scanner: its long side shows, its face
            // hardly at all.
            let turn = uniform(rng, [75.0f64, 105.0]).to_radians() * rand_sign(rng);
            let body = Pose2::new(c[0], c[1], bearing + turn);
            let face = body.to_world(&Pose2::new(-pallet.depth_m / 2.0, 0.0, 0.0));
            s.pallet(pallet, &face, Seen::Fixed);
        }
        _ => {
            // Another truck's forks: two tines, their tips toward anywhere.
            let spread = uniform(rng, [0.5, 0.7]);
            for y in [-spread / 2.0, spread / 2.0] {
                let p = at(0.0, y);
                s.rect(&Pose2::new(p.x_m, p.y_m, heading), 1.15, 0.12);
            }
        }
    }
}

fn rand_sign<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    if rng.random_bool(0.5) { 1.0 } else { -1.0 }
}
