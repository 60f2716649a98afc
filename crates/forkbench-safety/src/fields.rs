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
    /// The truck's width.
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
    /// The supplements for what the scanner misjudges (TZ + Z_R + Z_F): the field reaches
    /// this far beyond the region the truck's leading end stops in, whichever way a turn
    /// bends it.
    pub margin_m: f64,
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
    /// How far round the truck's own swept outline it is watched: the scanner's
    /// worst-case range error, so whatever stands in the truck's way is seen there even
    /// read long (a beam grazing the truck's side reads it behind the truck).
    pub body_margin_m: f64,
    /// Drawn field sets, each in force for its speed range and direction instead of the
    /// sized fields (polygons counter-clockwise).
    pub drawn: Vec<crate::FieldSetSpec>,
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
                margin_m: pair
                    .iter()
                    .map(|f| (f.width_m - f.vehicle_width_m) / 2.0)
                    .fold(0.0, f64::max),
                warning_margin_m,
            })
            .collect();
        FieldSets {
            outline,
            sets,
            body_margin_m: sizing.range_bias_m(),
            drawn: sizing
                .config
                .field_set
                .iter()
                .map(|f| {
                    let (protective, warning) = f.polygons();
                    crate::FieldSetSpec {
                        protective,
                        warning,
                        ..f.clone()
                    }
                })
                .collect(),
        }
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
    /// the chassis' rear in reverse) swept along the arc it would drive for the stopping
    /// part of the field's length and grown by the supplements, and the truck's own
    /// outline swept as far and grown by `body_margin_m`, so a turn's swing (the rear and
    /// sides of a rear-steered truck) stays covered.
    pub fn fields(&self, set: &FieldSet, speed_cmd_mps: f64, steer_rad: f64) -> Fields {
        let o = &self.outline;
        let ahead = speed_cmd_mps >= 0.0;
        let dir = if ahead {
            crate::Direction::Forward
        } else {
            crate::Direction::Reverse
        };
        let drawn = self
            .drawn
            .iter()
            .find(|d| d.speed_max_mps == set.speed_max_mps && d.direction == dir);
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
        let (l, w, grow) = (set.length_m, set.width_m, set.warning_margin_m);
        let r = set.margin_m.min(w / 2.0);
        // In reverse the forks draw back out of whatever stands round them now (a
        // set-down pallet, the rack's uprights): their own region, with the supplements
        // round it, is not watched.
        let ignore = (!ahead).then(|| {
            let (x, y) = (o.front_m + r, hb + r);
            vec![[0.0, -y], [x, -y], [x, y], [0.0, y]]
        });
        // The region the truck's leading end crosses while stopping, then the
        // supplements round it: straight, the formula's S_L × S_B rectangle; in a turn
        // the supplements still lie beyond the bent region in every direction.
        let lead_field = |half: f64, len: f64| {
            dilate(
                &self.sweep(&lead(half - r), (len - r).max(0.0), ahead, steer_rad),
                r,
            )
        };
        // The truck's own outline swept as far, grown by what the scanner may misread.
        let b = self.body_margin_m.min(r);
        let body_field =
            |len: f64| dilate(&self.sweep(&body, (len - b).max(0.0), ahead, steer_rad), b);
        if let Some(d) = drawn {
            // What the integrator drew, whole.
            return Fields {
                ignore: None,
                protective: vec![d.protective.clone()],
                warning: vec![d.warning.clone()],
            };
        }
        Fields {
            ignore,
            protective: vec![lead_field(w / 2.0, l), body_field(l)],
            warning: vec![lead_field((w + grow) / 2.0, l + grow), body_field(l + grow)],
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

    /// The farthest any field reaches from the fork root, straight or turned, drawn or
    /// sized (what a scan must cover).
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
            .chain(
                self.drawn
                    .iter()
                    .flat_map(|d| d.protective.iter().chain(&d.warning))
                    .map(|p| p[0].hypot(p[1])),
            )
            .fold(0.0, f64::max)
    }
}

impl Outline {
    fn wbase(&self) -> f64 {
        self.wheelbase_m.max(1e-6)
    }
}

/// Steering angles closer than this share their fields: the field a scan reads is built
/// for the nearest multiple, so a straight run or a held turn builds it once.
pub const FIELD_STEER_STEP_RAD: f64 = 0.005;

/// The fields built so far in a run, by field set, direction and (rounded) steering
/// angle: the same key builds the same fields, so a truck that steers back and forth
/// builds each once.
#[derive(Debug, Clone, Default)]
pub struct FieldCache {
    kept: std::collections::HashMap<FieldKey, Fields>,
}

type FieldKey = (u64, bool, i64);

/// The most field sets a cache keeps (it starts over past it): bounds its memory however
/// long a run steers.
const FIELD_CACHE_ENTRIES: usize = 4096;

impl FieldCache {
    /// [`FieldSets::fields`] at the steering angle rounded to [`FIELD_STEER_STEP_RAD`].
    pub fn fields(
        &mut self,
        sets: &FieldSets,
        set: &FieldSet,
        speed_cmd_mps: f64,
        steer_rad: f64,
    ) -> &Fields {
        let step = (steer_rad / FIELD_STEER_STEP_RAD).round();
        let key = (
            set.speed_max_mps.to_bits(),
            speed_cmd_mps >= 0.0,
            step as i64,
        );
        if self.kept.len() >= FIELD_CACHE_ENTRIES && !self.kept.contains_key(&key) {
            self.kept.clear();
        }
        self.kept
            .entry(key)
            .or_insert_with(|| sets.fields(set, speed_cmd_mps, step * FIELD_STEER_STEP_RAD))
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

/// The convex polygon grown by `r` each way along the truck's axes (its Minkowski sum
/// with a square of side 2r).
fn dilate(poly: &[[f64; 2]], r: f64) -> Vec<[f64; 2]> {
    if r <= 0.0 {
        return poly.to_vec();
    }
    let grown = poly
        .iter()
        .flat_map(|p| [[-r, -r], [-r, r], [r, -r], [r, r]].map(|d| [p[0] + d[0], p[1] + d[1]]))
        .collect();
    hull(grown)
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
            body_margin_m: 0.3,
            drawn: Vec::new(),
            sets: vec![FieldSet {
                speed_max_mps: 0.8,
                length_m: 1.0,
                width_m: 2.0,
                margin_m: 0.3,
                warning_margin_m: 1.0,
            }],
        }
    }

    #[test]
    fn a_straight_field_is_the_rectangle_beyond_the_leading_end() {
        let s = sets();
        let f = s.fields(&s.sets[0], 0.5, 0.0);
        assert!(f.hit([2.5, 0.9]).0 && !f.hit([2.7, 0.0]).0);
        assert!(
            f.hit([-0.5, 0.95]).0,
            "beside the chassis, within the supplements"
        );
        assert!(!f.hit([-0.5, 1.05]).0, "not beyond them");
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
        let beside = [-1.8, 1.2];
        assert!(
            !straight.hit(beside).0 && turned.hit(beside).0,
            "{turned:?}"
        );
    }

    #[test]
    fn in_a_turn_the_supplements_lie_round_the_bent_stopping_region() {
        let s = sets();
        let set = s.sets[0];
        let steer = 0.82;
        let f = s.fields(&set, -0.5, steer);
        // Where the rear's corners stop: the lead swept for the stopping part of S_L.
        let stop = s.sweep(
            &[[-2.45, -0.7], [-2.45, 0.7]],
            set.length_m - set.margin_m,
            false,
            steer,
        );
        // Every point of that region, moved by just under the supplements any way along
        // the truck's axes, is still in the protective field.
        let r = 0.99 * set.margin_m;
        for p in &stop {
            for d in [[-r, 0.0], [r, 0.0], [0.0, -r], [0.0, r], [-r, -r], [r, r]] {
                let q = [p[0] + d[0], p[1] + d[1]];
                assert!(f.hit(q).0, "{q:?} (from {p:?}) not in {:?}", f.protective);
            }
        }
        // Straight, the field is the formula's rectangle: S_L deep, S_B wide.
        let straight = s.fields(&set, -0.5, 0.0);
        assert!(straight.hit([-2.45 - 0.99, 0.99]).0);
        assert!(!straight.hit([-2.45 - 1.01, 0.0]).0 && !straight.hit([-3.0, 1.01]).0);
    }

    #[test]
    fn a_drawn_field_set_is_used_whole_and_its_reach_scanned() {
        let mut s = sets();
        let far = vec![[0.0, -1.0], [9.0, -1.0], [9.0, 1.0], [0.0, 1.0]];
        s.drawn.push(crate::FieldSetSpec {
            speed_max_mps: 0.8,
            direction: crate::Direction::Forward,
            protective: far.clone(),
            warning: far.clone(),
        });
        assert!(s.reach_m() >= 9.0, "{}", s.reach_m());
        let f = s.fields(&s.sets[0], 0.5, 0.4);
        assert_eq!((f.protective, f.ignore), (vec![far], None));
        // Reverse keeps the sized fields.
        assert!(s.fields(&s.sets[0], -0.5, 0.0).ignore.is_some());
    }
}
