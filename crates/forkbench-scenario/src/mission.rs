//! The `[mission]` table: a warehouse mission from a station through other stations to the scenario's staging pose, where the pick begins.

use forkbench_core::Pose2;
use forkbench_nav::CollisionModel;
use forkbench_track::TrackerConfig;
use serde::{Deserialize, Serialize};

use super::world::World;
use super::{PoseDeg, invalid};
use crate::ScenarioError;

/// Longest back-out, lead-in or approach a mission may ask for (m).
pub const MAX_MANOEUVRE_M: f64 = 50.0;
/// The global planner of a mission (Luo's PRM + A* by default).
pub use forkbench_nav::GlobalPlannerKind;

/// `[mission.global]`: how legs are planned.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GlobalFile {
    pub planner: GlobalPlannerKind,
    pub nodes: usize,
    /// PRM connection distance; absent: unlimited.
    pub connect_m: Option<f64>,
    pub collision: CollisionModel,
    /// Inflate model: radius; absent: 0.5 × wheelbase (Luo).
    pub inflate_m: Option<f64>,
    /// Clearance the footprint keeps (also checked along smoothed paths).
    pub margin_m: f64,
    /// Straight lead-in after a leg's start (fixes the start heading).
    pub lead_m: f64,
    /// Straight lead-out before a leg's goal: the last corner ends this far before it.
    pub approach_m: f64,
    pub resolution_m: f64,
    /// Seeds tried per leg before the leg fails (seed, seed + 1, …).
    pub attempts: u32,
    /// Refuse a smoothed path whose swept footprint strikes an obstacle. Off, a path is
    /// driven as planned (as the paper's inflation model does, which never checks it).
    pub check_swept: bool,
    /// `planner = "hybrid-astar"`: its lattice, costs and budget (`[mission.global.hybrid]`).
    pub hybrid: forkbench_nav::hybrid::HybridParams,
}

impl Default for GlobalFile {
    fn default() -> Self {
        Self {
            planner: GlobalPlannerKind::Prm,
            nodes: 500,
            connect_m: Some(10.0),
            collision: CollisionModel::Footprint,
            inflate_m: None,
            margin_m: CollisionModel::Footprint.default_margin_m(),
            lead_m: 2.5,
            approach_m: 1.8,
            resolution_m: 0.05,
            attempts: 10,
            check_swept: true,
            hybrid: forkbench_nav::hybrid::HybridParams::default(),
        }
    }
}

/// `[mission]` as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissionFile {
    /// Station (by name) or pose where the truck starts.
    pub start: Place,
    /// Stations visited in order before the staging pose.
    #[serde(default)]
    pub via: Vec<Place>,
    /// How far the truck backs out of a station before the next leg.
    #[serde(default = "default_backout")]
    pub backout_m: f64,
    /// Largest distance from a leg's goal where the truck may stop.
    #[serde(default = "default_arrive_m")]
    pub arrive_tolerance_m: f64,
    #[serde(default = "default_arrive_deg")]
    pub arrive_tolerance_deg: f64,
    /// Time limit of one leg.
    #[serde(default = "default_leg_timeout")]
    pub leg_timeout_s: f64,
    #[serde(default)]
    pub global: GlobalFile,
    /// Pure pursuit for the legs (the paper: 0.6 m/s, 0.6 m look-ahead).
    #[serde(default = "mission_tracker")]
    pub tracker: TrackerConfig,
}

/// A station name or a pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Place {
    Station(String),
    Pose(PoseDeg),
}

fn default_backout() -> f64 {
    3.0
}
fn default_arrive_m() -> f64 {
    0.3
}
fn default_arrive_deg() -> f64 {
    10.0
}
fn default_leg_timeout() -> f64 {
    180.0
}

/// Luo's tracking settings: 0.6 m/s with a 0.6 m look-ahead.
pub fn mission_tracker() -> TrackerConfig {
    TrackerConfig {
        lookahead_m: 0.6,
        lookahead_gain_s: None,
        min_lookahead_m: 0.4,
        cruise_speed_mps: 0.6,
        approach_speed_mps: 0.3,
        approach_distance_m: 1.0,
        decel_mps2: 0.4,
    }
}

/// A named place of a mission, resolved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Waypoint {
    pub name: String,
    pub pose: Pose2,
}

/// A validated mission: places resolved against the world.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MissionSpec {
    pub start: Waypoint,
    pub via: Vec<Waypoint>,
    pub backout_m: f64,
    pub arrive_tolerance_m: f64,
    pub arrive_tolerance_rad: f64,
    pub leg_timeout_s: f64,
    pub global: GlobalFile,
    pub tracker: TrackerConfig,
}

impl MissionFile {
    /// Resolves station names and checks every value, naming the field.
    pub fn resolve(&self, world: &World, file: &str) -> Result<MissionSpec, ScenarioError> {
        let place = |p: &Place, field: &str| -> Result<Waypoint, ScenarioError> {
            match p {
                Place::Pose(d) => {
                    d.check(file, field)?;
                    Ok(Waypoint {
                        name: format!("({:.1}, {:.1})", d.x_m, d.y_m),
                        pose: d.to_pose(),
                    })
                }
                Place::Station(name) => world
                    .station_pose(name)
                    .map(|pose| Waypoint {
                        name: name.clone(),
                        pose,
                    })
                    .ok_or_else(|| {
                        let known: Vec<_> = world.station.iter().map(|s| s.name.as_str()).collect();
                        invalid(
                            file,
                            field,
                            &format!("no station {name:?} in the world (it has {known:?})"),
                        )
                    }),
            }
        };
        self.check(file)?;
        // A trial rasterises the world at this resolution: one that never could is a
        // setting error here, not a failure of every trial.
        forkbench_nav::OccupancyGrid::layout_for(
            &world.obstacles(),
            &[],
            self.global.resolution_m,
            0.0,
        )
        .map_err(|e| {
            invalid(
                file,
                "mission.global.resolution_m",
                &format!("the world cannot be rasterised at it: {e}"),
            )
        })?;
        let via = self
            .via
            .iter()
            .enumerate()
            .map(|(i, p)| place(p, &format!("mission.via[{i}]")))
            .collect::<Result<_, _>>()?;
        Ok(MissionSpec {
            start: place(&self.start, "mission.start")?,
            via,
            backout_m: self.backout_m,
            arrive_tolerance_m: self.arrive_tolerance_m,
            arrive_tolerance_rad: self.arrive_tolerance_deg.to_radians(),
            leg_timeout_s: self.leg_timeout_s,
            global: self.global.clone(),
            tracker: self.tracker.clone(),
        })
    }

    /// Lengths and tolerances in range. Upper bounds keep a typo from becoming work: a
    /// back-out or approach longer than a warehouse aisle is a leg of its own, and its
    /// path's samples and footprint checks grow with its length.
    fn check_bounded(&self, file: &str) -> Result<(), ScenarioError> {
        let g = &self.global;
        let bounded = [
            ("mission.backout_m", self.backout_m, MAX_MANOEUVRE_M),
            ("mission.arrive_tolerance_m", self.arrive_tolerance_m, 10.0),
            (
                "mission.arrive_tolerance_deg",
                self.arrive_tolerance_deg,
                180.0,
            ),
            ("mission.global.lead_m", g.lead_m, MAX_MANOEUVRE_M),
            ("mission.global.approach_m", g.approach_m, MAX_MANOEUVRE_M),
            ("mission.global.resolution_m", g.resolution_m, 5.0),
        ];
        for (field, v, max) in bounded {
            if !(v.is_finite() && v > 0.0 && v <= max) {
                return Err(invalid(
                    file,
                    field,
                    &format!(
                        "{} must be a number in (0, {max}]",
                        crate::text::compact_numbers(&v.to_string())
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check(&self, file: &str) -> Result<(), ScenarioError> {
        let g = &self.global;
        self.check_bounded(file)?;
        if g.planner.kinodynamic() && g.collision != CollisionModel::Footprint {
            return Err(invalid(
                file,
                "mission.global.collision",
                "hybrid-astar checks the truck's footprint: collision must be \"footprint\"",
            ));
        }
        if let Err(e) = g.hybrid.check() {
            return Err(invalid(file, "mission.global.hybrid", &e.to_string()));
        }
        if !(self.leg_timeout_s.is_finite()
            && self.leg_timeout_s > 0.0
            && self.leg_timeout_s <= super::MAX_TIMEOUT_S)
        {
            return Err(invalid(
                file,
                "mission.leg_timeout_s",
                &format!("must be within 0..{} s", super::MAX_TIMEOUT_S),
            ));
        }
        if !(g.margin_m.is_finite() && (0.0..=2.0).contains(&g.margin_m)) {
            return Err(invalid(
                file,
                "mission.global.margin_m",
                "must be within 0..2 m",
            ));
        }
        if g.nodes == 0 || g.nodes > 100_000 {
            return Err(invalid(
                file,
                "mission.global.nodes",
                "must be within 1..100000",
            ));
        }
        if g.attempts == 0 || g.attempts > 100 {
            return Err(invalid(
                file,
                "mission.global.attempts",
                "must be within 1..100",
            ));
        }
        for (field, v) in [
            ("mission.global.connect_m", g.connect_m),
            ("mission.global.inflate_m", g.inflate_m),
        ] {
            if v.is_some_and(|v| !(v.is_finite() && v > 0.0)) {
                return Err(invalid(file, field, "must be a positive finite number"));
            }
        }
        if g.connect_m.is_some_and(|v| v > 1000.0) {
            return Err(invalid(
                file,
                "mission.global.connect_m",
                "must be at most 1000 m",
            ));
        }
        if g.inflate_m
            .is_some_and(|v| v > forkbench_nav::MAX_INFLATION_M)
        {
            return Err(invalid(
                file,
                "mission.global.inflate_m",
                &format!("must be at most {} m", forkbench_nav::MAX_INFLATION_M),
            ));
        }
        if let Err(e) = self.tracker.validate() {
            return Err(super::invalid_setting(file, "mission.tracker", &e));
        }
        Ok(())
    }
}
