//! Field sets in the truck's frame, switched by speed and direction of travel and bent by the steering: protective and warning fields built from the sizing.

use forkbench_core::Pose2;
use serde::Serialize;

use crate::FieldSizing;

/// Below this commanded speed the truck stands: no field is monitored.
pub const STANDING_MPS: f64 = 0.01;

/// Poses along the stopping arc a field's sweep is taken at.
const SWEEP_STEPS: usize = 8;

/// The truck's geometry in its fork-root frame, for placing and bending fields.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Outline {
    /// The fork tips ahead of the fork root.
    pub front_m: f64,
    /// The chassis' rear behind the fork root.
    pub rear_m: f64,
    /// The front (drive) axle behind the fork root, and the wheelbase to the steered
    /// rear axle.
    pub axle_behind_m: f64,
    pub wheelbase_m: f64,
    /// The truck's width with the scanner's tolerance on each side: its own sweep is
    /// watched this wide.
    pub body_width_m: f64,
}

/// One speed range's fields: how far they reach beyond the truck's leading end and how
/// wide they are.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FieldSet {
    pub speed_max_mps: f64,
    /// S_L (the worse of empty and rated load, scaled) and S_B.
    pub length_m: f64,
    pub width_m: f64,
    /// The warning field's extra reach ahead (and half of it to each side).
    pub warning_margin_m: f64,
}

/// The protective and warning fields in force, each the union of its polygons (in the
/// fork-root frame, counter-clockwise).
#[derive(Debug, Clone, PartialEq)]
pub struct Fields {
    /// A region not watched (the forks' own, backing out of a pallet).
    pub ignore: Option<Vec<[f64; 2]>>,
    pub protective: Vec<Vec<[f64; 2]>>,
    pub warning: Vec<Vec<[f64; 2]>>,
}

impl Fields {
    /// Whether `p` (fork-root frame) lies in the protective field, and in the warning
    /// field.
    pub fn hit(&self, p: [f64; 2]) -> (bool, bool) {
        if self.ignore.as_ref().is_some_and(|poly| contains(poly, p)) {
            return (false, false);
        }
        let any = |polys: &[Vec<[f64; 2]>]| polys.iter().any(|poly| contains(poly, p));
        (any(&self.protective), any(&self.warning))
    }
}

/// The field sets by speed range, the same for either direction of travel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldSets {
    pub outline: Outline,
    pub sets: Vec<FieldSet>,
}

impl FieldSets {
    /// Each range's protective field: S_L (the worse of empty and rated load, times
    /// `length_scale`) beyond the truck's leading end, S_B wide; its warning field
    /// reaches `warning_margin_m` further and half that wider on each side.
    pub fn from_sizing(
        sizing: &FieldSizing,
        outline: Outline,
        length_scale: f64,
        warning_margin_m: f64,
    ) -> Self {
        let sets = sizing
            .fields
            .chunks(2)
            .map(|pair| FieldSet {
                speed_max_mps: pair[0].speed_max_mps,
                length_m: pair.iter().map(|f| f.length_m).fold(0.0, f64::max) * length_scale,
                width_m: pair.iter().map(|f| f.width_m).fold(0.0, f64::max),
                warning_margin_m,
            })
            .collect();
        FieldSets { outline, sets }
    }

    /// The field set monitored at the commanded speed: the first range whose top is at
    /// or above it (the last beyond all); none while standing.
    pub fn active(&self, speed_cmd_mps: f64) -> Option<&FieldSet> {
        // NaN asks for nothing, as standing does.
        if speed_cmd_mps.is_nan() || speed_cmd_mps.abs() < STANDING_MPS {
            return None;
        }
        let v = speed_cmd_mps.abs();
        self.sets
            .iter()
            .find(|s| v <= s.speed_max_mps)
            .or(self.sets.last())
    }

    /// The fields of `set` for travel in the direction of `speed_cmd_mps` with the rear
    /// wheel at `steer_rad`: the truck's leading end (the forks' region going forwards,
    /// the chassis' rear in reverse) S_B wide, and the truck's own outline, each swept
    /// along the arc it would drive for the field's length, so a turn's swing (the rear
    /// and sides of a rear-steered truck) stays covered.
    pub fn fields(&self, set: &FieldSet, speed_cmd_mps: f64, steer_rad: f64) -> Fields {
        let o = &self.outline;
        let ahead = speed_cmd_mps >= 0.0;
        let lead = |h: f64| -> Vec<[f64; 2]> {
            if ahead {
                vec![[0.0, -h], [0.0, h], [o.front_m, -h], [o.front_m, h]]
            } else {
                vec![[-o.rear_m, -h], [-o.rear_m, h]]
            }
        };
        // The truck's own outline, forks included (a reverse turn swings them sideways).
        let hb = o.body_width_m / 2.0;
        let body = vec![
            [-o.rear_m, -hb],
            [-o.rear_m, hb],
            [o.front_m, -hb],
            [o.front_m, hb],
        ];
        // In reverse the forks draw back out of whatever stands between them now (a
        // set-down pallet): their own region is not watched.
        let ignore =
            (!ahead).then(|| vec![[0.0, -hb], [o.front_m, -hb], [o.front_m, hb], [0.0, hb]]);
        let (l, w, grow) = (set.length_m, set.width_m, set.warning_margin_m);
        let body_sweep = self.sweep(&body, l + grow, ahead, steer_rad);
        Fields {
            ignore,
            protective: vec![
                self.sweep(&lead(w / 2.0), l, ahead, steer_rad),
                self.sweep(&body, l, ahead, steer_rad),
            ],
            warning: vec![
                self.sweep(&lead((w + grow) / 2.0), l + grow, ahead, steer_rad),
                body_sweep,
            ],
        }
    }

    /// The hull of `corners` (fork-root frame) carried along the truck's arc for
    /// `length_m` of travel.
    fn sweep(&self, corners: &[[f64; 2]], length_m: f64, ahead: bool, steer: f64) -> Vec<[f64; 2]> {
        let o = &self.outline;
        let sign = if ahead { 1.0 } else { -1.0 };
        let kappa = steer.tan() / o.wbase();
        let axle0 = Pose2::new(-o.axle_behind_m, 0.0, 0.0);
        let mut points = Vec::with_capacity(corners.len() * (SWEEP_STEPS + 1));
        for k in 0..=SWEEP_STEPS {
            let s = sign * length_m * k as f64 / SWEEP_STEPS as f64;
            let axle = along_arc(&axle0, s, kappa);
            let root = axle.to_world(&Pose2::new(o.axle_behind_m, 0.0, 0.0));
            points.extend(corners.iter().map(|c| {
                let p = root.to_world(&Pose2::new(c[0], c[1], 0.0));
                [p.x_m, p.y_m]
            }));
        }
        hull(points)
    }

    /// The farthest any field reaches from the fork root, straight or turned (what a
    /// scan must cover).
    pub fn reach_m(&self) -> f64 {
        let o = &self.outline;
        self.sets
            .iter()
            .map(|s| {
                let (l, w) = (
                    s.length_m + s.warning_margin_m,
                    s.width_m + s.warning_margin_m,
                );
                (o.front_m.max(o.rear_m) + l).hypot(w / 2.0)
            })
            .fold(0.0, f64::max)
    }
}

impl Outline {
    fn wbase(&self) -> f64 {
        self.wheelbase_m.max(1e-6)
    }
}

/// The front axle's pose after `s_m` of signed travel at curvature `kappa`.
fn along_arc(p: &Pose2, s_m: f64, kappa: f64) -> Pose2 {
    if (kappa * s_m).abs() < 1e-9 {
        return p.to_world(&Pose2::new(s_m, 0.0, 0.0));
    }
    let dth = kappa * s_m;
    let (x, y) = (dth.sin() / kappa, (1.0 - dth.cos()) / kappa);
    p.to_world(&Pose2::new(x, y, dth))
}

/// The convex hull, counter-clockwise (Andrew's monotone chain).
fn hull(mut pts: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(pts.len() + 1);
    for pass in [false, true] {
        let start = out.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass {
            Box::new(pts.iter().rev())
        } else {
            Box::new(pts.iter())
        };
        for &p in iter {
            while out.len() >= start + 2 && cross(out[out.len() - 2], out[out.len() - 1], p) <= 0.0
            {
                out.pop();
            }
            out.push(p);
        }
        out.pop();
    }
    out
}

/// Whether `p` lies inside the polygon `poly` (even-odd rule).
pub fn contains(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sets() -> FieldSets {
        FieldSets {
            outline: Outline {
                front_m: 1.6,
                rear_m: 2.45,
                axle_behind_m: 0.45,
                wheelbase_m: 1.629,
                body_width_m: 1.4,
            },
            sets: vec![FieldSet {
                speed_max_mps: 0.8,
                length_m: 1.0,
                width_m: 2.0,
                warning_margin_m: 1.0,
            }],
        }
    }

    #[test]
    fn a_straight_field_is_the_rectangle_beyond_the_leading_end() {
        let s = sets();
        let f = s.fields(&s.sets[0], 0.5, 0.0);
        assert!(f.hit([2.5, 0.9]).0 && !f.hit([2.7, 0.0]).0);
        assert!(!f.hit([-0.5, 0.8]).0, "not beside the chassis");
        let r = s.fields(&s.sets[0], -0.5, 0.0);
        assert!(r.hit([-3.3, -0.9]).0 && !r.hit([-3.5, 0.0]).0);
        assert_eq!(r.hit([-4.3, 0.0]), (false, true));
        assert_eq!(
            r.hit([1.0, 0.0]),
            (false, false),
            "backing out of a pallet on the forks"
        );
        assert!(s.active(0.005).is_none(), "standing");
    }

    #[test]
    fn a_turn_bends_the_reverse_field_toward_the_rear_swing() {
        let s = sets();
        // Reversing with the rear wheel at +0.6 rad (a left turn going forwards) the truck
        // turns about a centre on its front axle line to the left, and its rear swings
        // left.
        let straight = s.fields(&s.sets[0], -0.5, 0.0);
        let turned = s.fields(&s.sets[0], -0.5, 0.6);
        let behind = [-2.7, 1.5];
        assert!(
            !straight.hit(behind).0 && turned.hit(behind).0,
            "{turned:?}"
        );
        // Beside the chassis, where its side swings.
        let beside = [-1.8, 0.85];
        assert!(
            !straight.hit(beside).0 && turned.hit(beside).0,
            "{turned:?}"
        );
    }
}
