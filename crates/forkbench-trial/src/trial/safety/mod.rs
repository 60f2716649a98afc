//! Each step of a trial's people and safety function: movers walk their routes, the safety scanners watch the field set the speed selects, the truck is stopped or slowed, and contacts with people are judged.

use forkbench_core::{Pose2, Signal, Style};
use forkbench_safety::{Fields, MoverKind, Reading, Rect, STANDING_MPS, detect};
use forkbench_sensors::scan::WorldView as _;

use super::link::Stage;
use super::movers_view::WithMovers;
mod record;
use super::safety_run::{Monitor, SafetyRun, gap_to, truck_parts};
use super::state::Trial;
use crate::recorder::{Level, Recorder};
use record::{STOPPED, local, record_reading};

const PERSON: Style = Style::rgba([255, 120, 200, 255]).width(0.04);

/// The tick's safety gate: the speed the safety function (`safety`, reading the world's
/// `sim`) lets the truck drive at, for the controller's `speed_mps` this step.
pub(super) fn gate<R: Recorder + ?Sized>(
    safety: &mut Option<SafetyRun>,
    sim: &forkbench_sim::Sim,
    speed_mps: f64,
    rec: &mut R,
) -> f64 {
    let (t, dt) = (sim.time_s(), sim.dt_s());
    let Some(s) = safety.as_mut() else {
        return speed_mps;
    };
    s.requested_mps = speed_mps;
    let Some(m) = s.monitor.as_mut() else {
        return speed_mps;
    };
    let (was, held) = (m.function.stopped(), m.function.stats.stop_time_s);
    let standing = sim.speed_mps().abs() < STANDING_MPS;
    let v = m.function.gate(t, dt, speed_mps, standing);
    if was && !m.function.stopped() {
        let this_s = m.stop_began_s.take().map_or(0.0, |b| t - b);
        let why = format!(
            "safety: fields clear, driving on after {this_s:.1} s ({held:.1} s stopped in all)"
        );
        rec.event(t, Level::Info, &why);
    } else if !was && m.function.stopped() {
        m.stop_began_s = Some(t);
        rec.event(t, Level::Warn, "safety: protective stop (braking)");
    }
    v
}

impl Trial<'_> {
    /// After a physics step: the movers walk on, contacts and closest approaches are
    /// judged, and at each safety scan the fields are read.
    pub(super) fn safety_step<R: Recorder + ?Sized>(&mut self, rec: &mut R) {
        let Some(mut s) = self.safety.take() else {
            return;
        };
        self.move_and_judge(&mut s, rec);
        if let Some(mut m) = s.monitor.take() {
            if self.world.sim.time_s() + 1e-9 >= m.next_scan_s {
                m.next_scan_s += m.period_s;
                self.read_fields(&mut m, &s, rec);
            }
            s.monitor = Some(m);
        }
        self.safety = Some(s);
    }

    fn move_and_judge<R: Recorder + ?Sized>(&self, s: &mut SafetyRun, rec: &mut R) {
        let sim = &self.world.sim;
        let (t, dt, speed) = (sim.time_s(), sim.dt_s(), sim.speed_mps());
        let truck = &self.scn.truck;
        // One circle round the whole truck (a carried pallet included): most movers are
        // far outside it, and then no part's corners are needed.
        let (front, rear) = (
            truck.fork_length_m.max(self.scn.pallet.depth_m),
            truck.body_length_m,
        );
        let centre = sim
            .fork_root_pose()
            .to_world(&Pose2::new((front - rear) / 2.0, 0.0, 0.0));
        let reach = (front + rear).hypot(truck.body_width_m.max(self.scn.pallet.width_m)) / 2.0;
        let coarse = |body: &Rect| {
            let (dx, dy) = (body.0.x_m - centre.x_m, body.0.y_m - centre.y_m);
            ((dx * dx + dy * dy).sqrt() - reach - body.1.hypot(body.2) / 2.0).max(0.0)
        };
        let mut parts: Option<Vec<Rect>> = None;
        let mut gap = |body: &Rect, care_m: f64| {
            let far = coarse(body);
            if far >= care_m {
                return far;
            }
            let parts = parts.get_or_insert_with(|| truck_parts(sim, truck, &self.scn.pallet));
            gap_to(parts, body, care_m)
        };
        let moving = speed.abs() >= STANDING_MPS;
        for (i, m) in s.movers.iter_mut().enumerate() {
            let ((l, w), care) = (m.spec.body_m(), m.spec.behaviour.care_m());
            // People wait for a moving truck as their behaviour says (or not at all), and
            // walk round a standing one (passing through it here: only the moving truck
            // coming into touch is a contact).
            m.advance(t, dt, |next| {
                care.is_some_and(|g| moving && gap(&(*next, l, w), g) < g)
            });
            if m.gone() {
                s.touching[i] = false;
                continue;
            }
            // Exact where it may lower the closest approach or be a touch.
            let gap = gap(&m.body(), s.closest_m[i].max(1e-3));
            let touching = gap <= 0.0;
            // An overlap begun while the truck stood is someone walking round it, not an
            // approach of the moving truck.
            let passing = touching && s.touching[i];
            if moving && !passing {
                s.closest_m[i] = s.closest_m[i].min(gap);
            }
            if touching && moving && !s.touching[i] {
                s.contacts += 1;
                let who = match m.spec.kind {
                    MoverKind::Person => "person",
                    MoverKind::Vehicle => "vehicle",
                };
                let why = format!(
                    "the truck touched {who} {} at {:.2} m/s (t = {t:.2} s)",
                    i + 1,
                    speed.abs()
                );
                rec.event(t, Level::Error, &why);
                s.first_contact.get_or_insert(why);
            }
            s.touching[i] = touching;
        }
        if ((t / dt).round() as u64).is_multiple_of(super::SIGNAL_EVERY_STEPS) {
            for (i, m) in s.movers.iter().enumerate().filter(|(_, m)| !m.gone()) {
                let (p, l, w) = m.body();
                let outline = forkbench_core::geometry::rect_outline(&p, l, w);
                rec.signal(
                    t,
                    &format!("people/{}", i + 1),
                    &Signal::Path(&outline),
                    PERSON,
                );
            }
        }
    }

    /// How far the fork tips are from the target of this part of the cycle (the pallet
    /// face the pick aims at; where the place's path leaves the tips); none elsewhere.
    fn target_distance_m(&self) -> Option<f64> {
        let fork = Pose2::new(self.scn.truck.fork_length_m, 0.0, 0.0);
        let target = match self.stage {
            Stage::Pick => Some(self.sense.pallet_est),
            Stage::Phase(k) => self
                .scn
                .phases
                .get(usize::from(k).wrapping_sub(1))
                .filter(|p| p.name == "place")
                .and_then(|_| self.path.samples.last())
                .map(|end| end.pose().to_world(&fork)),
            Stage::Leg | Stage::Staging => None,
        };
        let tips = self.world.sim.fork_root_pose().to_world(&fork);
        target.map(|t| t.distance_to(&tips))
    }

    /// Whether the fields are muted now: in the pick's or the place's entry, once the
    /// fork tips came within the scenario's muting distance of the target, or (without
    /// one) once the target would have entered the protective field, until that part of
    /// the cycle ends (the caller watches reversing out regardless).
    fn muted(&self, m: &mut Monitor, near_m: Option<f64>) -> bool {
        if m.muted.is_some_and(|st| st != self.stage) {
            m.muted = None;
        }
        if m.warning_muted.is_some_and(|st| st != self.stage) {
            m.warning_muted = None;
        }
        if m.muted.is_some() {
            return true;
        }
        if let Some(d) = m.mute_near_target_m
            && near_m.is_some_and(|n| n <= d)
        {
            m.muted = Some(self.stage);
        }
        m.muted.is_some()
    }

    /// One safety scan of the field set the requested speed selects.
    fn read_fields<R: Recorder + ?Sized>(&self, m: &mut Monitor, s: &SafetyRun, rec: &mut R) {
        let t = self.world.sim.time_s();
        // Muting covers the entry (driving forwards); backing out is watched again.
        let forward = s.requested_mps >= 0.0;
        let near_m = self.target_distance_m();
        let muted = self.muted(m, near_m) && forward;
        let set = if muted {
            None
        } else {
            m.fields.active(s.requested_mps)
        };
        let clear = |m: &mut Monitor| {
            m.broken = false;
            m.function.read(Reading {
                t_s: t,
                protective: false,
                warning: false,
                mover_in_protective: false,
            });
        };
        let Some(set) = set.copied() else {
            return clear(m);
        };
        let root = self.world.sim.fork_root_pose();
        let fields = m
            .built
            .fields(&m.fields, &set, s.requested_mps, self.world.sim.steer_rad());
        let latches = (&mut m.muted, &mut m.warning_muted);
        let at_reach = (near_m, m.mute_near_target_m, m.fields.outline.front_m);
        if mute_at_reach(self.stage, latches, at_reach, fields) && forward {
            return clear(m);
        }
        let warning_muted = m.warning_muted.is_some() && forward;
        let view = WithMovers {
            sim: &self.world.sim,
            movers: &s.movers,
        };
        let mut surfaces = Vec::new();
        view.surfaces_near([root.x_m, root.y_m], m.reach_m, &mut surfaces);
        let segments: Vec<[[f64; 2]; 2]> = surfaces
            .iter()
            .map(|f| [local(&root, f.a), local(&root, f.b)])
            .collect();
        let seen = detect(fields, &segments, &m.eyes, (m.resolution_m, m.range_bias_m));
        let intruder = seen.protective.map(|p| {
            let q = root.to_world(&Pose2::new(p[0], p[1], 0.0));
            [q.x_m, q.y_m]
        });
        let reading = Reading {
            t_s: t,
            protective: intruder.is_some(),
            warning: seen.warning && !warning_muted,
            mover_in_protective: intruder.is_some() && mover_in_protective(s, &root, fields),
        };
        let new_break = intruder.is_some() && !m.broken && !m.function.stopped();
        m.broken = intruder.is_some();
        if let Some(p) = intruder.filter(|_| new_break) {
            let what = if reading.mover_in_protective {
                "a person or vehicle"
            } else {
                "no person (a false trip: rack, wall or post)"
            };
            let why = format!(
                "safety: protective field broken at ({:.2}, {:.2}) m by {what}; stopping ({:?}, {:.2} m/s asked)",
                p[0], p[1], self.stage, s.requested_mps
            );
            rec.event(t, Level::Warn, &why);
        }
        record_reading(rec, t, &root, fields, &reading, m.function.stopped());
        if let Some(p) = intruder {
            rec.signal(t, "safety/intrusion", &Signal::Points(&[p]), STOPPED);
        }
        m.function.read(reading);
    }

    /// What the safety function and the movers did, into the outcome; a contact with a
    /// person is the verdict.
    pub(super) fn judge_safety(&mut self) {
        let Some(s) = &self.safety else {
            return;
        };
        let report = s.outcome();
        let out = &mut self.verdict.out;
        if let Some(why) = &report.first_contact {
            let before = out.failure.as_ref().map(|f| {
                let detail = out.failure_detail.clone().unwrap_or_default();
                format!("{}: {detail}", f.name())
            });
            out.also_failed.splice(0..0, before);
            out.fail(
                crate::outcome::Failure::criterion(super::PERSON_CONTACT),
                why.clone(),
            );
        }
        // A failure while the fields held the truck: say so where a reviewer looks first.
        let held = report.stop_time_s;
        if !out.success
            && out.likely_cause.is_none()
            && report.first_contact.is_none()
            && held >= 1.0
        {
            let n = report.stops;
            let stops = format!("{n} protective stop{}", if n == 1 { "" } else { "s" });
            out.likely_cause = Some(format!(
                "the safety function held the truck stopped for {held:.1} s ({stops}, {} with nobody in the field)",
                report.false_trips
            ));
        }
        out.safety = Some(report);
    }
}

/// Without a muting distance (`near_m` the tips' distance to the target, `set_m` the
/// scenario's muting distance, `front_m` the tips ahead of the fork root): latches the
/// warning field muted once the target lies within its reach ahead of the tips, and every
/// field once it lies within the protective field's; true when every field is muted.
fn mute_at_reach(
    stage: Stage,
    (muted, warning_muted): (&mut Option<Stage>, &mut Option<Stage>),
    (near_m, set_m, front_m): (Option<f64>, Option<f64>, f64),
    fields: &Fields,
) -> bool {
    let (Some(near), None) = (near_m, set_m) else {
        return muted.is_some();
    };
    let reach = |polys: &[Vec<[f64; 2]>]| {
        polys
            .iter()
            .flatten()
            .map(|p| p[0] - front_m)
            .fold(0.0, f64::max)
    };
    if near <= reach(&fields.warning) {
        *warning_muted = Some(stage);
    }
    if near <= reach(&fields.protective) {
        *muted = Some(stage);
    }
    muted.is_some()
}

/// Whether a person or vehicle stands in the protective field of `fields` (the truck's
/// fork root at `root`): a corner or the centre of what a scanner sees of one.
fn mover_in_protective(s: &SafetyRun, root: &Pose2, fields: &Fields) -> bool {
    s.movers.iter().any(|mv| {
        mv.seen().iter().any(|(p, l, w)| {
            let corners = forkbench_core::geometry::rect_corners(p, *l, *w);
            corners
                .iter()
                .chain([[p.x_m, p.y_m]].iter())
                .any(|c| fields.hit(local(root, *c)).0)
        })
    })
}
