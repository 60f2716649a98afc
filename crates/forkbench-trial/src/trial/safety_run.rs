//! What a trial keeps of its people and safety function (the movers, the scanners and their field sets, closest approaches and contacts), built from the scenario, and the safety outcome it reports.

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};
use forkbench_safety::{
    Eye, FieldCache, FieldSets, Mover, Outline, Rect, SafetyConfig, SafetyFunction,
    rect_gap_lower_bound_m, rect_gap_m,
};
use forkbench_sim::Sim;
use rand::RngExt as _;
use rand_chacha::ChaCha8Rng;

use super::link::Stage;
use super::streams::stream;
use crate::outcome::SafetyOutcome;
use crate::scenario::Scenario;

/// Safety scans per scanner response time (an S300's default double sampling).
const SCANS_PER_RESPONSE: f64 = 2.0;

/// The people and vehicles of a trial and, when the scenario monitors, its safety
/// function.
#[derive(Debug)]
pub(crate) struct SafetyRun {
    pub(super) movers: Vec<Mover>,
    pub(super) monitor: Option<Monitor>,
    /// Each mover's least gap to the moving truck so far.
    pub(super) closest_m: Vec<f64>,
    pub(super) touching: Vec<bool>,
    pub(super) contacts: u32,
    pub(super) first_contact: Option<String>,
    /// The speed the truck's controller asked for this step, before the safety function.
    pub(super) requested_mps: f64,
}

#[derive(Debug)]
pub(super) struct Monitor {
    pub(super) fields: FieldSets,
    pub(super) built: FieldCache,
    pub(super) function: SafetyFunction,
    /// The scanners at two diagonal corners, the fork root's left facing forward-left and
    /// the chassis' rear right facing back-right, so that together they see all round.
    pub(super) eyes: [Eye; 2],
    pub(super) resolution_m: f64,
    /// How much further than true the scanners read (their worst-case error, if asked).
    pub(super) range_bias_m: f64,
    pub(super) reach_m: f64,
    pub(super) period_s: f64,
    pub(super) next_scan_s: f64,
    /// The scenario's muting distance; none: each field is muted once the target would
    /// enter it.
    pub(super) mute_near_target_m: Option<f64>,
    /// The part of the cycle whose entry muted the fields.
    pub(super) muted: Option<Stage>,
    /// The part of the cycle whose entry muted the warning field alone.
    pub(super) warning_muted: Option<Stage>,
    /// The last scan found the protective field broken (an event marks each new break).
    pub(super) broken: bool,
    /// When the current protective stop began.
    pub(super) stop_began_s: Option<f64>,
}

impl SafetyRun {
    /// The scenario's movers (their starts drawn from the trial's seed, a stream per
    /// mover) and its safety function; `None` when it has neither.
    pub(super) fn new(
        scn: &Scenario,
        run: &super::Resolved,
    ) -> Result<Option<Self>, forkbench_scenario::ScenarioError> {
        let (truck, seed) = (&run.truck, run.seed);
        let cfg = scn.safety.as_ref().filter(|c| c.monitor);
        if scn.movers.is_empty() && cfg.is_none() {
            return Ok(None);
        }
        let mut seen: Vec<&forkbench_safety::MoverSpec> = Vec::new();
        let movers: Vec<Mover> = scn
            .movers
            .iter()
            .enumerate()
            .map(|(i, m)| {
                // Identical movers are told apart by how many came before.
                let twin = seen.iter().filter(|o| **o == m).count();
                seen.push(m);
                let mut rng = mover_stream(seed, m, twin);
                let [a, b] = m.start_s;
                let drawn = if b > a { rng.random_range(a..=b) } else { a };
                let (start, speed) = super::uncertain_apply::mover_pins(scn, &run.uncertain, i);
                let mut spec = m.clone();
                spec.speed_mps = speed.unwrap_or(spec.speed_mps);
                Mover::new(spec, start.unwrap_or(drawn))
            })
            .collect();
        let monitor = match cfg {
            Some(c) => Some(Monitor::new(scn, truck, c)?),
            None => None,
        };
        let n = movers.len();
        Ok(Some(SafetyRun {
            movers,
            monitor,
            closest_m: vec![f64::INFINITY; n],
            touching: vec![false; n],
            contacts: 0,
            first_contact: None,
            requested_mps: 0.0,
        }))
    }

    /// What the trial's outcome reports.
    pub(super) fn outcome(&self) -> SafetyOutcome {
        let stats = self.monitor.as_ref().map(|m| m.function.stats);
        SafetyOutcome {
            monitored: self.monitor.is_some(),
            stops: stats.map_or(0, |s| s.stops),
            false_trips: stats.map_or(0, |s| s.false_trips),
            stop_time_s: stats.map_or(0.0, |s| s.stop_time_s),
            slowdowns: stats.map_or(0, |s| s.slowdowns),
            slowdown_time_s: stats.map_or(0.0, |s| s.slowdown_time_s),
            person_contacts: self.contacts,
            first_contact: self.first_contact.clone(),
            closest_m: self
                .closest_m
                .iter()
                .map(|d| d.is_finite().then_some(*d))
                .collect(),
        }
    }
}

/// A mover's own random stream, keyed by what it is for and by the mover itself (its
/// kind, route and timing), not its place in the file: reordering `[[mover]]` tables
/// changes no draw.
fn mover_stream(seed: u64, m: &forkbench_safety::MoverSpec, twin: usize) -> ChaCha8Rng {
    let key = format!("mover start {twin} {m:?}");
    stream(seed, forkbench_core::hash::fnv1a(key.bytes()))
}

impl Monitor {
    /// Fields sized for `truck`, the run's (its actuators brake it).
    fn new(
        scn: &Scenario,
        truck: &forkbench_core::ForkliftSpec,
        c: &SafetyConfig,
    ) -> Result<Self, forkbench_scenario::ScenarioError> {
        let sizing = scn.safety_fields_for(truck)?;
        let outline = Outline {
            front_m: scn.truck.fork_length_m,
            rear_m: scn.truck.body_length_m,
            axle_behind_m: scn.truck.fork_root_ahead_of_front_axle_m,
            wheelbase_m: scn.truck.wheelbase_m,
            body_width_m: scn.truck.body_width_m,
        };
        let fields =
            FieldSets::from_sizing(&sizing, outline, c.field_length_scale, c.warning_margin_m);
        let reach_m = fields.reach_m();
        let fov_rad = c.scanner.fov_deg.to_radians();
        let period_s = c.scanner.response_time_s / SCANS_PER_RESPONSE;
        let (hw, q) = (scn.truck.body_width_m / 2.0, std::f64::consts::FRAC_PI_4);
        let front = Pose2::new(0.0, hw, q);
        let rear = Pose2::new(-scn.truck.body_length_m, -hw, -3.0 * q);
        Ok(Monitor {
            fields,
            built: FieldCache::default(),
            function: SafetyFunction::new(
                c.scanner.response_time_s + c.controller_response_s,
                c.resume_dwell_s,
                c.warning_speed_mps,
            ),
            eyes: [front, rear].map(|mount| Eye { mount, fov_rad }),
            resolution_m: c.scanner.resolution_m,
            range_bias_m: sizing.range_bias_m(),
            reach_m,
            period_s,
            next_scan_s: 0.0,
            mute_near_target_m: c.mute_near_target_m,
            muted: None,
            warning_muted: None,
            broken: false,
            stop_began_s: None,
        })
    }
}

/// The truck's parts a person can touch, in the map: the chassis, each fork and a
/// carried pallet.
pub(super) fn truck_parts(sim: &Sim, truck: &ForkliftSpec, pallet: &PalletSpec) -> Vec<Rect> {
    let root = sim.fork_root_pose();
    let at = |x: f64, y: f64| root.to_world(&Pose2::new(x, y, 0.0));
    let (l, w) = (truck.body_length_m, truck.body_width_m);
    let fork = |side: f64| {
        (
            at(truck.fork_length_m / 2.0, side * truck.fork_spacing_m / 2.0),
            truck.fork_length_m,
            truck.fork_width_m,
        )
    };
    let mut parts = vec![(at(-l / 2.0, 0.0), l, w), fork(1.0), fork(-1.0)];
    if sim.carrying() {
        let face = sim.pallet_pose();
        let centre = face.to_world(&Pose2::new(pallet.depth_m / 2.0, 0.0, 0.0));
        parts.push((centre, pallet.depth_m, pallet.width_m));
    }
    parts
}

/// The least gap from `body` to the truck's parts, exact below `care_m` (beyond it, any
/// value at least `care_m`: the callers only ask whether it is small).
pub(super) fn gap_to(parts: &[Rect], body: &Rect, care_m: f64) -> f64 {
    parts
        .iter()
        .map(|p| {
            let bound = rect_gap_lower_bound_m(p, body);
            if bound >= care_m {
                bound
            } else {
                rect_gap_m(p, body)
            }
        })
        .fold(f64::INFINITY, f64::min)
}
