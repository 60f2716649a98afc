//! Mission stage: before the pick, the truck drives the mission's legs (back out of a station, then a smoothed global path) in the same physics world.

use std::time::Instant;

use forkbench_core::units::wrap_angle;
use forkbench_core::{Path, Pose2, Signal, Style};
use forkbench_nav::smooth::{SmoothParams, smooth};
use forkbench_nav::{GlobalPlan, GlobalQuery, NavMap, plan_global, truck_parts};

use super::state::Trial;
use crate::outcome::LegOutcome;
use crate::recorder::{Level, Recorder};
use crate::scenario::mission::{GlobalPlannerKind, MissionSpec, Waypoint};
use crate::stage_error::{LegError, StageError};

/// How a mission's navigation layer is drawn: blocked cells, the roadmap, a leg's A*
/// polyline, its smoothed path and its backing out.
const OCCUPIED: Style = Style::rgba([150, 150, 150, 110]).width(0.02);
const ROADMAP: Style = Style::rgba([120, 160, 230, 30]).width(0.012);
const POLYLINE: Style = Style::rgb(255, 150, 40).width(0.024);
pub(super) const SMOOTHED: Style = Style::rgb(40, 110, 240).width(0.06);
pub(super) const REVERSE: Style = Style::rgb(170, 90, 230).width(0.06);

pub(super) fn path_points(p: &Path) -> Vec<[f64; 2]> {
    p.samples.iter().map(|q| [q.x_m, q.y_m]).collect()
}

/// A leg's global plan as signals, when the leg starts driving it: the roadmap (PRM's;
/// the sampling trees leave none) replaces the last leg's, then the A* polyline with its
/// corners and the smoothed path.
fn record_route<R: Recorder + ?Sized>(
    rec: &mut R,
    t_s: f64,
    leg: usize,
    plan: &GlobalPlan,
    (polyline, path): (&[[f64; 2]], &Path),
) {
    if let Some(map) = &plan.roadmap {
        let (nodes, edges) = (&map.nodes, &map.edges);
        let segments: Vec<[[f64; 2]; 2]> = edges
            .iter()
            .enumerate()
            .flat_map(|(i, nb)| {
                nb.iter()
                    .filter(move |(j, _)| *j > i)
                    .map(move |(j, _)| [nodes[i], nodes[*j]])
            })
            .collect();
        rec.signal(t_s, "nav/roadmap", &Signal::Segments(&segments), ROADMAP);
        rec.signal(
            t_s,
            "nav/roadmap/nodes",
            &Signal::Points(nodes),
            ROADMAP.width(0.08),
        );
    }
    let leg_path = format!("nav/route/{leg}");
    rec.signal(
        t_s,
        &format!("{leg_path}/polyline"),
        &Signal::Path(polyline),
        POLYLINE,
    );
    rec.signal(
        t_s,
        &format!("{leg_path}/corners"),
        &Signal::Points(polyline),
        POLYLINE.width(0.12),
    );
    rec.signal(t_s, &leg_path, &Signal::Path(&path_points(path)), SMOOTHED);
}

/// Running totals of one leg's drive.
#[derive(Debug, Default)]
pub(super) struct DriveStats {
    pub(super) cross_track_sum_m: f64,
    pub(super) cross_track_max_m: f64,
    pub(super) steps: u64,
    pub(super) collisions: u32,
}

impl Trial<'_> {
    /// Drives every leg to the staging pose; Err names the leg that failed and why.
    pub(super) async fn run_legs<R: Recorder + ?Sized>(
        &mut self,
        m: &MissionSpec,
        staging: &Waypoint,
        rec: &mut R,
    ) -> Result<(), StageError> {
        let map = NavMap::shared_from_world(&self.world.obstacles, m.global.resolution_m)?;
        rec.signal(
            self.world.sim.time_s(),
            "nav/occupied",
            &Signal::Grid(&map.grid.to_signal()),
            OCCUPIED,
        );
        let mut from = m.start.clone();
        let targets: Vec<&Waypoint> = m.via.iter().chain(std::iter::once(staging)).collect();
        for (i, to) in targets.into_iter().enumerate() {
            let leg = self.leg(&map, m, (i, &from, to), rec).await;
            let (ok, why) = self.record_leg(leg, rec);
            if !ok {
                return Err(StageError::Leg {
                    number: i + 1,
                    name: self.verdict.out.legs[i].name.clone(),
                    detail: why.unwrap_or_default(),
                });
            }
            from = to.clone();
        }
        Ok(())
    }

    /// A driven leg into the outcome, and its end into the log: whether it arrived, and
    /// why not.
    pub(super) fn record_leg<R: Recorder + ?Sized>(
        &mut self,
        leg: LegOutcome,
        rec: &mut R,
    ) -> (bool, Option<String>) {
        let (ok, why) = (leg.success, leg.failure_detail.clone());
        rec.event(
            self.world.sim.time_s(),
            if ok { Level::Info } else { Level::Error },
            &format!("leg {}: {}", leg.name, why.as_deref().unwrap_or("arrived")),
        );
        self.verdict.out.legs.push(leg);
        (ok, why)
    }

    /// One leg: back out of the place it starts at (all but the first), plan from where
    /// the truck stands, drive, and measure the arrival.
    pub(super) async fn leg<R: Recorder + ?Sized>(
        &mut self,
        map: &NavMap,
        m: &MissionSpec,
        (i, from, to): (usize, &Waypoint, &Waypoint),
        rec: &mut R,
    ) -> LegOutcome {
        let t0 = self.world.sim.time_s();
        self.loc.begin_leg(t0);
        let mut leg = blank_leg(format!("{} → {}", from.name, to.name));
        let mut stats = DriveStats::default();
        let result = self
            .leg_drives(map, m, (i, from, to), (&mut leg, &mut stats), rec)
            .await;
        finish_leg(&mut leg, result, &stats, self.world.sim.time_s() - t0);
        self.loc
            .leg_stats
            .finish_leg(self.world.sim.time_s(), &mut leg);
        if leg.success {
            check_arrival(&mut leg, m, to, &self.world.sim.fork_root_pose());
        }
        leg
    }

    /// A leg's plans and drives: Hybrid-A*'s manoeuvre, or a back-out (all but the first
    /// leg) and the smoothed route.
    async fn leg_drives<R: Recorder + ?Sized>(
        &mut self,
        map: &NavMap,
        m: &MissionSpec,
        (i, from, to): (usize, &Waypoint, &Waypoint),
        (leg, stats): (&mut LegOutcome, &mut DriveStats),
        rec: &mut R,
    ) -> Result<(), LegError> {
        if m.global.planner.kinodynamic() {
            // Hybrid-A* plans the way out of the station itself, reversing as needed.
            return self.manoeuvre_leg(map, m, (i, to), (leg, stats), rec).await;
        }
        if i > 0 {
            self.back_out(map, m, (i, from, to), (leg, stats), rec)
                .await?;
        }
        let here = self.sense(rec)?.1;
        let (plan, attempts, secs) = plan_leg(
            map,
            m,
            (&here, &to.pose),
            &self.scn.truck,
            super::streams::leg_seed(self.run.seed, i),
        );
        leg.planning_time_s = secs;
        leg.planning_attempts = attempts;
        leg.route_length_m = plan.as_ref().map_or(f64::NAN, |p| p.route.length_m);
        let p = plan?;
        let s = accepted(&p, m).ok_or_else(|| LegError::Smoothing(leg_plan_failure(&p)))?;
        leg.smoothing = "ok".into();
        leg.planned_length_m = s.path.length_m();
        leg.min_clearance_m = leg.min_clearance_m.min(s.min_clearance_m);
        record_route(rec, self.world.sim.time_s(), i, &p, (&s.polyline, &s.path));
        self.drive_path(&s.path, m, stats, rec).await
    }

    /// Backs out of the place a leg starts at, the way `plan_backout` finds, and drives it.
    async fn back_out<R: Recorder + ?Sized>(
        &mut self,
        map: &NavMap,
        m: &MissionSpec,
        (i, from, to): (usize, &Waypoint, &Waypoint),
        (leg, stats): (&mut LegOutcome, &mut DriveStats),
        rec: &mut R,
    ) -> Result<(), LegError> {
        let here = self.sense(rec)?.1;
        let (back, clearance) =
            plan_backout(map, m, &here, &to.pose, &self.scn.truck).ok_or_else(|| {
                LegError::NoBackout {
                    backout_m: m.backout_m,
                    from: from.name.clone(),
                }
            })?;
        leg.reverse_length_m = back.length_m();
        let points = path_points(&back);
        rec.signal(
            self.world.sim.time_s(),
            &format!("nav/route/{i}/reverse"),
            &Signal::Path(&points),
            REVERSE,
        );
        leg.min_clearance_m = clearance;
        self.drive_path(&back, m, stats, rec).await
    }
}

/// Where the truck stopped against the leg's goal; too far off fails the leg.
fn check_arrival(leg: &mut LegOutcome, m: &MissionSpec, to: &Waypoint, truth: &Pose2) {
    leg.final_position_error_m = truth.distance_to(&to.pose);
    leg.final_heading_error_rad = wrap_angle(truth.heading_rad - to.pose.heading_rad);
    if leg.final_position_error_m > m.arrive_tolerance_m
        || leg.final_heading_error_rad.abs() > m.arrive_tolerance_rad
    {
        leg.success = false;
        leg.failure_detail = Some(format!(
            "stopped {:.3} m and {:.1}° from {} (limits {} m, {:.1}°)",
            leg.final_position_error_m,
            leg.final_heading_error_rad.to_degrees(),
            to.name,
            m.arrive_tolerance_m,
            m.arrive_tolerance_rad.to_degrees()
        ));
    }
}

fn blank_leg(name: String) -> LegOutcome {
    LegOutcome {
        name,
        success: false,
        failure_detail: None,
        reverse_length_m: 0.0,
        route_length_m: f64::NAN,
        planned_length_m: f64::NAN,
        planning_time_s: 0.0,
        planning_attempts: 0,
        smoothing: String::new(),
        min_clearance_m: f64::INFINITY,
        collisions: 0,
        cross_track_mean_m: f64::NAN,
        cross_track_max_m: f64::NAN,
        time_s: 0.0,
        final_position_error_m: f64::NAN,
        final_heading_error_rad: f64::NAN,
        fixes_missed: 0,
        largest_fix_gap_s: 0.0,
        localization_error_max_m: 0.0,
    }
}

fn finish_leg(leg: &mut LegOutcome, result: Result<(), LegError>, s: &DriveStats, time_s: f64) {
    leg.collisions = s.collisions;
    if s.steps > 0 {
        leg.cross_track_mean_m = s.cross_track_sum_m / s.steps as f64;
        leg.cross_track_max_m = s.cross_track_max_m;
    }
    if !leg.min_clearance_m.is_finite() {
        leg.min_clearance_m = f64::NAN;
    }
    leg.time_s = time_s;
    match result {
        Ok(()) => leg.success = true,
        Err(why) => {
            let why = why.to_string();
            if leg.smoothing.is_empty() {
                leg.smoothing = why.clone();
            }
            leg.failure_detail = Some(why);
        }
    }
}

/// The smoothed path a leg drives: one that clears every obstacle, or with the swept
/// check off, any that smoothing produced.
fn accepted<'a>(p: &'a GlobalPlan, m: &MissionSpec) -> Option<&'a forkbench_nav::Smoothed> {
    match &p.smoothed {
        Some(Ok(s)) if s.clear() || !m.global.check_swept => Some(s),
        _ => None,
    }
}

/// Why a found route is not drivable.
fn leg_plan_failure(p: &GlobalPlan) -> String {
    match &p.smoothed {
        Some(Err(e)) => format!("smoothing failed: {e}"),
        Some(Ok(s)) => match s.hit {
            Some(h) => format!(
                "smoothing failed: the swept footprint strikes an obstacle at ({:.2}, {:.2}) m",
                h.x_m, h.y_m
            ),
            None => "smoothing failed".into(),
        },
        None => "no path found".into(),
    }
}

/// Ways into a leg's goal: straight through the lead-out, or a square turn onto the
/// goal heading from either side (from the start's side first), the turn's first point
/// `SQUARE_TURN_M` to the side of the lead-out.
fn approaches(m: &MissionSpec, from: &Pose2, to: &Pose2) -> Vec<Vec<[f64; 2]>> {
    const SQUARE_TURN_M: f64 = 3.0;
    let (s, c) = to.heading_rad.sin_cos();
    let a = m.global.approach_m;
    let lead_out = [to.x_m - a * c, to.y_m - a * s];
    let perp = [-s, c];
    let start_side = (from.x_m - lead_out[0]) * perp[0] + (from.y_m - lead_out[1]) * perp[1];
    let first = if start_side >= 0.0 { 1.0 } else { -1.0 };
    let mut out = vec![Vec::new()];
    for side in [first, -first] {
        let d = side * SQUARE_TURN_M;
        out.push(vec![[lead_out[0] + d * perp[0], lead_out[1] + d * perp[1]]]);
    }
    out
}

/// Plans a leg, trying each approach and then further seeds while no drivable path
/// comes out.
/// Most candidate roadmap edges one leg's planning may check over all its attempts and
/// approaches: a bound on its time that does not depend on the machine (results stay
/// deterministic), refused before any attempt.
pub const MAX_LEG_CANDIDATE_EDGES: f64 = 1.0e7;

fn leg_work(map: &NavMap, m: &MissionSpec, (from, to): (&Pose2, &Pose2)) -> Result<(), LegError> {
    let g = &m.global;
    if g.planner != GlobalPlannerKind::Prm {
        return Ok(());
    }
    let (lo, hi) = map.grid.extent();
    let per =
        forkbench_nav::candidate_edges(g.nodes, g.connect_m, (hi[0] - lo[0]) * (hi[1] - lo[1]));
    let n_approaches = approaches(m, from, to).len();
    if per * f64::from(g.attempts) * n_approaches as f64 > MAX_LEG_CANDIDATE_EDGES {
        return Err(LegError::TooMuchWork {
            attempts: g.attempts,
            approaches: n_approaches,
            per_attempt: per,
            nodes: g.nodes,
            limit: MAX_LEG_CANDIDATE_EDGES,
        });
    }
    Ok(())
}

fn plan_leg(
    map: &NavMap,
    m: &MissionSpec,
    (from, to): (&Pose2, &Pose2),
    truck: &forkbench_core::ForkliftSpec,
    seed: u64,
) -> (Result<GlobalPlan, LegError>, u32, f64) {
    let t0 = Instant::now();
    let _timed =
        forkbench_core::profile::enter_as(forkbench_core::profile::Stage::Plan, "mission route");
    let g = &m.global;
    if let Err(why) = leg_work(map, m, (from, to)) {
        return (Err(why), 0, 0.0);
    }
    let mut last = Err(LegError::NoAttempt);
    for a in 0..g.attempts {
        let seed = seed.wrapping_add(u64::from(a));
        let algorithm = g.planner.algorithm(g.nodes, g.connect_m, seed);
        for (k, approach) in approaches(m, from, to).into_iter().enumerate() {
            let q = GlobalQuery {
                start: *from,
                goal: *to,
                algorithm,
                collision: g.collision,
                inflate_m: g.inflate_m.unwrap_or(forkbench_nav::luo_inflation_m(truck)),
                smooth: true,
                lead_m: [g.lead_m, g.approach_m],
                approach,
                margin_m: g.margin_m,
                truck: truck.clone(),
                // A leg drives one forward path; manoeuvres with cusps are not driven yet.
                manoeuvre_fallback: None,
            };
            let plan = plan_global(map, &q).map_err(LegError::from);
            if plan.as_ref().is_ok_and(|p| accepted(p, m).is_some()) {
                return (plan, a + 1, t0.elapsed().as_secs_f64());
            }
            // A failure reports why the direct way did not work (the others are fallbacks).
            if k == 0 {
                last = plan;
            }
        }
    }
    (last, g.attempts, t0.elapsed().as_secs_f64())
}

/// A reverse path out of a station: back and turn a quarter either way, backing up to
/// `backout_m`; of the tracks whose swept footprint clears every obstacle, the one with
/// the most clearance, half a metre of it traded for the forks facing the next goal.
/// Straight back when no turn is clear. With the path, the truck's clearance along it.
fn plan_backout(
    map: &NavMap,
    m: &MissionSpec,
    at: &Pose2,
    next: &Pose2,
    truck: &forkbench_core::ForkliftSpec,
) -> Option<(Path, f64)> {
    let (s, c) = at.heading_rad.sin_cos();
    let toward = (next.y_m - at.y_m).atan2(next.x_m - at.x_m);
    let params = SmoothParams::for_curvature(truck.max_curvature_per_m());
    let parts = truck_parts(truck, m.global.margin_m);
    let true_parts = truck_parts(truck, 0.0);
    let quarter = std::f64::consts::FRAC_PI_2;
    let mut best: Option<(f64, Path, f64)> = None;
    for turn in [quarter, -quarter] {
        for k in 1..=4 {
            let d = m.backout_m * f64::from(k) / 4.0;
            let corner = [at.x_m - d * c, at.y_m - d * s];
            let h = at.heading_rad + turn;
            // Driven forward, the track runs from the backed-out pose to the station.
            let out = [corner[0] - d * h.cos(), corner[1] - d * h.sin()];
            let poly = [out, corner, [at.x_m, at.y_m]];
            let Ok(sm) = smooth(&poly, &map.obstacles, (&parts, &true_parts), &params) else {
                continue;
            };
            if !sm.clear() {
                continue;
            }
            let score = sm.min_clearance_m + 0.5 * (h - toward).cos();
            if best.as_ref().is_none_or(|(b, _, _)| score > *b) {
                best = Some((score, sm.path.driven_backwards(), sm.min_clearance_m));
            }
        }
    }
    if let Some((_, path, clearance)) = best {
        return Some((path, clearance));
    }
    let d = m.backout_m;
    let back = Pose2::new(at.x_m - d * c, at.y_m - d * s, at.heading_rad);
    let straight = Path::straight(&back, d, 0.02);
    if forkbench_nav::smooth::first_strike(&map.obstacles, &parts, &straight, 0.05).is_some() {
        return None;
    }
    let clearance = forkbench_nav::smooth::min_clearance(
        &map.obstacles,
        &true_parts,
        &straight,
        params.check_step_m * 2.0,
        params.clearance_cap_m,
    );
    Some((straight.driven_backwards(), clearance))
}
