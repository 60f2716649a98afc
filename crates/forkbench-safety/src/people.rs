//! People and other trucks moving on routes through the warehouse: where each is at every step, its legs as a scanner sees them, and the body a contact is judged on.

use forkbench_core::{Pose2, SettingsError};
use serde::{Deserialize, Serialize};

/// A walking person's contact body: across the shoulders, and front to back.
pub const PERSON_BODY_M: (f64, f64) = (0.5, 0.3);
/// Each leg's cross-section in the scan plane (a square this wide), and the distance
/// between the legs' centres.
pub const LEG_M: f64 = 0.1;
const LEG_SPACING_M: f64 = 0.2;
/// Half a step: how far a leg swings ahead of or behind the body's centre.
const HALF_STEP_M: f64 = 0.35;
/// Walking speeds a person may be given.
pub const WALKING_MPS: (f64, f64) = (1.0, 1.6);
/// A person who sees a moving truck coming stands still (the assumption the scanner
/// makers' formula rests on): they wait while their next position would come closer to
/// its outline than this.
pub const YIELD_GAP_M: f64 = 0.5;
/// A person who stops and waits for a truck to pass keeps this far from a moving one: a
/// choice, about two strides, the distance at which people in aisles step aside.
pub const WAIT_GAP_M: f64 = 2.0;

/// How a mover reacts to a moving truck (`behaviour`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Behaviour {
    /// Stands still while its next position would come within [`YIELD_GAP_M`] of a moving
    /// truck, then walks on.
    #[default]
    Yield,
    /// Walks its route whatever the trucks do: someone who does not look, whom only the
    /// truck's fields keep from contact (the case ISO 3691-4's people detection is for).
    KeepWalking,
    /// Stops once a moving truck comes within [`WAIT_GAP_M`] of where it would step, and
    /// waits until none is: someone who lets the truck pass.
    StopAndWait,
}

impl Behaviour {
    fn is_yield(&self) -> bool {
        *self == Behaviour::Yield
    }

    /// How close to a moving truck it lets its next position come; none: it never waits.
    pub fn care_m(&self) -> Option<f64> {
        match self {
            Behaviour::Yield => Some(YIELD_GAP_M),
            Behaviour::KeepWalking => None,
            Behaviour::StopAndWait => Some(WAIT_GAP_M),
        }
    }
}
/// Most waypoints a route may have, and the longest wait a setting may ask for.
pub const MAX_ROUTE_POINTS: usize = 64;
const MAX_TIME_S: f64 = 3600.0;
/// How far from the origin a route point may lie: a world's extent.
pub const MAX_ROUTE_COORD_M: f64 = 1e4;

/// What moves: a person (two legs in the scan plane) or another truck (a rectangle).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MoverKind {
    Person,
    Vehicle,
}

/// One mover of a scenario (`[[mover]]`): its route in the map and its timing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MoverSpec {
    pub kind: MoverKind,
    /// A vehicle's length and width (a person's body is fixed).
    pub length_m: Option<f64>,
    pub width_m: Option<f64>,
    /// Waypoints `[x_m, y_m]` in the map, in order; it stands at the first until it sets
    /// off, and leaves the world at the last.
    #[serde(deserialize_with = "forkbench_core::exact::arrays")]
    pub route: Vec<[f64; 2]>,
    pub speed_mps: f64,
    /// When it sets off: drawn per trial from the seed, uniformly within `[from, to]`.
    #[serde(default, deserialize_with = "forkbench_core::exact::array")]
    pub start_s: [f64; 2],
    /// It stands at waypoint `pause_at` (an index into `route`) for `pause_s`.
    pub pause_at: Option<usize>,
    #[serde(default)]
    pub pause_s: f64,
    /// How it reacts to a moving truck; left out of serialised specs at its default.
    #[serde(default, skip_serializing_if = "Behaviour::is_yield")]
    pub behaviour: Behaviour,
}

impl MoverSpec {
    /// Every value in range; the error names the field.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let n = self.route.len();
        if !(2..=MAX_ROUTE_POINTS).contains(&n) {
            return Err(SettingsError::field(
                "route",
                format!("must list 2 to {MAX_ROUTE_POINTS} points (got {n})"),
            ));
        }
        if let Some(v) = self
            .route
            .iter()
            .flatten()
            .find(|v| !(v.is_finite() && v.abs() <= MAX_ROUTE_COORD_M))
        {
            return Err(SettingsError::field(
                "route",
                format!(
                    "points lie within ±{MAX_ROUTE_COORD_M} m of the origin, as a world does (got {v})"
                ),
            ));
        }
        let (lo, hi) = match self.kind {
            MoverKind::Person => WALKING_MPS,
            MoverKind::Vehicle => (0.1, 3.0),
        };
        forkbench_core::settings::in_ranges(&[
            ("speed_mps", self.speed_mps, lo, hi),
            ("start_s", self.start_s[0], 0.0, MAX_TIME_S),
            ("start_s", self.start_s[1], self.start_s[0], MAX_TIME_S),
            ("pause_s", self.pause_s, 0.0, MAX_TIME_S),
        ])?;
        match (self.kind, self.length_m, self.width_m) {
            (MoverKind::Vehicle, Some(l), Some(w)) => forkbench_core::settings::in_ranges(&[
                ("length_m", l, 0.5, 10.0),
                ("width_m", w, 0.3, 4.0),
            ])?,
            (MoverKind::Vehicle, l, _) => {
                let field = if l.is_none() { "length_m" } else { "width_m" };
                return Err(SettingsError::field(field, "a vehicle needs its size"));
            }
            (MoverKind::Person, None, None) => {}
            (MoverKind::Person, l, _) => {
                let field = if l.is_some() { "length_m" } else { "width_m" };
                return Err(SettingsError::field(
                    field,
                    "a person's body is fixed (0.5 m × 0.3 m, legs 0.1 m)",
                ));
            }
        }
        match self.pause_at {
            Some(k) if k >= n => Err(SettingsError::field(
                "pause_at",
                format!("the route has points 0 to {} (got {k})", n - 1),
            )),
            _ => Ok(()),
        }
    }

    /// Its contact body's length (along its way) and width.
    pub fn body_m(&self) -> (f64, f64) {
        match self.kind {
            MoverKind::Person => (PERSON_BODY_M.1, PERSON_BODY_M.0),
            MoverKind::Vehicle => (self.length_m.unwrap_or(1.0), self.width_m.unwrap_or(1.0)),
        }
    }
}

/// A mover during one trial: how far along its route it has come.
#[derive(Debug, Clone)]
pub struct Mover {
    pub spec: MoverSpec,
    /// When it sets off in this trial.
    pub start_s: f64,
    walked_m: f64,
    paused_s: f64,
    /// Cumulative route length at each waypoint.
    at_point_m: Vec<f64>,
}

impl Mover {
    /// `start_s`: its start drawn for this trial.
    pub fn new(spec: MoverSpec, start_s: f64) -> Self {
        let mut at_point_m = vec![0.0];
        for w in spec.route.windows(2) {
            let last = at_point_m[at_point_m.len() - 1];
            at_point_m.push(last + (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]));
        }
        Mover {
            spec,
            start_s,
            walked_m: 0.0,
            paused_s: 0.0,
            at_point_m,
        }
    }

    /// Whether it has left the world at its route's end.
    pub fn gone(&self) -> bool {
        self.walked_m >= self.at_point_m[self.at_point_m.len() - 1]
    }

    /// Whether it is walking or driving now (not waiting to start, pausing or gone).
    pub fn moving(&self, t_s: f64) -> bool {
        t_s >= self.start_s && !self.gone() && !self.pausing()
    }

    fn pausing(&self) -> bool {
        self.spec.pause_at.is_some_and(|k| {
            self.walked_m >= self.at_point_m[k] && self.paused_s < self.spec.pause_s
        })
    }

    /// One step of `dt_s` at time `t_s`; `blocked(next)`: whether its body at `next`
    /// would come too close to a truck (it then waits).
    pub fn advance(&mut self, t_s: f64, dt_s: f64, mut blocked: impl FnMut(&Pose2) -> bool) {
        if t_s < self.start_s || self.gone() {
            return;
        }
        if self.pausing() {
            self.paused_s += dt_s;
            return;
        }
        let mut next_m = self.walked_m + self.spec.speed_mps * dt_s;
        if let Some(k) = self.spec.pause_at {
            // Stop at the pause point rather than step past it.
            if self.walked_m < self.at_point_m[k] {
                next_m = next_m.min(self.at_point_m[k]);
            }
        }
        if !blocked(&self.pose_at(next_m)) {
            self.walked_m = next_m;
        }
    }

    /// Where it is and which way it faces.
    pub fn pose(&self) -> Pose2 {
        self.pose_at(self.walked_m)
    }

    fn pose_at(&self, s_m: f64) -> Pose2 {
        let r = &self.spec.route;
        let k = self
            .at_point_m
            .windows(2)
            .position(|w| s_m < w[1])
            .unwrap_or(r.len() - 2);
        let (a, b) = (r[k], r[k + 1]);
        let len = self.at_point_m[k + 1] - self.at_point_m[k];
        let u = if len > 0.0 {
            ((s_m - self.at_point_m[k]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Pose2::new(
            a[0] + u * (b[0] - a[0]),
            a[1] + u * (b[1] - a[1]),
            (b[1] - a[1]).atan2(b[0] - a[0]),
        )
    }

    /// Its contact body: centre pose, length along its heading, width.
    pub fn body(&self) -> (Pose2, f64, f64) {
        let (l, w) = self.spec.body_m();
        (self.pose(), l, w)
    }

    /// What a scanner sees of it: a person's two legs, swinging as it walks, or a
    /// vehicle's outline (centre, length, width of each rectangle). Nothing once gone.
    pub fn seen(&self) -> Vec<(Pose2, f64, f64)> {
        if self.gone() {
            return Vec::new();
        }
        let p = self.pose();
        match self.spec.kind {
            MoverKind::Vehicle => {
                let (l, w) = self.spec.body_m();
                vec![(p, l, w)]
            }
            MoverKind::Person => {
                // A gait cycle is two steps: the legs swing in opposition.
                let phase = std::f64::consts::PI * self.walked_m / (2.0 * HALF_STEP_M);
                let swing = HALF_STEP_M * phase.sin();
                [(1.0, swing), (-1.0, -swing)]
                    .map(|(side, ahead)| {
                        let leg = p.to_world(&Pose2::new(ahead, side * LEG_SPACING_M / 2.0, 0.0));
                        (leg, LEG_M, LEG_M)
                    })
                    .to_vec()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn person(route: Vec<[f64; 2]>) -> MoverSpec {
        MoverSpec {
            kind: MoverKind::Person,
            length_m: None,
            width_m: None,
            route,
            speed_mps: 1.2,
            start_s: [1.0, 1.0],
            pause_at: Some(1),
            pause_s: 2.0,
            behaviour: Behaviour::Yield,
        }
    }

    #[test]
    fn a_person_waits_walks_pauses_and_leaves() {
        let mut m = Mover::new(person(vec![[0.0, 0.0], [2.4, 0.0], [2.4, 2.4]]), 1.0);
        let dt = 0.01;
        let at = |m: &mut Mover, t: &mut f64, until: f64| {
            while *t < until - 1e-9 {
                m.advance(*t, dt, |_| false);
                *t += dt;
            }
            m.pose()
        };
        let mut t = 0.0;
        assert_eq!(at(&mut m, &mut t, 1.0).x_m, 0.0, "stands until its start");
        assert!((at(&mut m, &mut t, 2.0).x_m - 1.2).abs() < 0.02);
        let corner = at(&mut m, &mut t, 4.0);
        assert!((corner.x_m - 2.4).abs() < 1e-9, "pauses at the corner");
        assert!(corner.y_m.abs() < 0.02 && !m.moving(t));
        at(&mut m, &mut t, 7.1);
        assert!(m.gone(), "{:?}", m.pose());
        assert!(m.seen().is_empty());
    }

    #[test]
    fn a_blocked_person_waits() {
        let mut m = Mover::new(person(vec![[0.0, 0.0], [5.0, 0.0]]), 0.0);
        m.advance(0.0, 0.1, |next| next.x_m > 0.05);
        assert_eq!(m.pose().x_m, 0.0);
        m.advance(0.0, 0.1, |_| false);
        assert!(m.pose().x_m > 0.1);
    }

    #[test]
    fn bad_movers_are_refused_by_field() {
        let mut p = person(vec![[0.0, 0.0]]);
        assert_eq!(
            p.validate().expect_err("one point").field.as_deref(),
            Some("route")
        );
        p.route.push([1.0, 0.0]);
        p.speed_mps = 3.0;
        assert_eq!(
            p.validate().expect_err("a runner").field.as_deref(),
            Some("speed_mps")
        );
        p.speed_mps = 1.2;
        p.start_s = [-1.0, 0.0];
        assert_eq!(
            p.validate().expect_err("negative").field.as_deref(),
            Some("start_s")
        );
        p.start_s = [0.0, 0.0];
        p.pause_at = Some(5);
        assert_eq!(
            p.validate().expect_err("no point 5").field.as_deref(),
            Some("pause_at")
        );
    }
}
