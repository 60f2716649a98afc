//! World files (racks, walls, pallet slots), and the checks of poses as files write them (metres, degrees).

use std::path::Path as FsPath;

use forkbench_core::Pose2;
use forkbench_geom::Obstacles;
use forkbench_sim::Obstacle;
use serde::{Deserialize, Serialize};

use super::{invalid, parse, read};
use crate::ScenarioError;
use crate::pose_deg::{MAX_WORLD_EXTENT_M, PoseDeg};

impl PoseDeg {
    /// Each value finite and within the world's extent; errors name `file` and `field`.
    pub(super) fn check(&self, file: &str, field: &str) -> Result<(), ScenarioError> {
        for (name, v) in [
            ("x_m", self.x_m),
            ("y_m", self.y_m),
            ("heading_deg", self.heading_deg),
        ] {
            if !v.is_finite() {
                return Err(invalid(
                    file,
                    &format!("{field}.{name}"),
                    "must be a finite number",
                ));
            }
        }
        for (name, v) in [("x_m", self.x_m), ("y_m", self.y_m)] {
            if v.abs() > MAX_WORLD_EXTENT_M {
                return Err(invalid(
                    file,
                    &format!("{field}.{name}"),
                    "lies beyond ±10 km: the world's extent is bounded so one trial's work is",
                ));
            }
        }
        if self.heading_deg.abs() > 1e4 {
            return Err(invalid(
                file,
                &format!("{field}.heading_deg"),
                "must lie within ±10000°",
            ));
        }
        Ok(())
    }
}

/// How far inside an obstacle a reflector may lie and still count as on its face.
const ON_FACE_TOLERANCE_M: f64 = 1e-9;

/// Most reflector × obstacle pairs a world may have (the NAV350's work per fix).
pub const MAX_REFLECTOR_WORK: usize = 2_000_000;

/// A fixed rectangle in a world file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectFile {
    #[serde(default)]
    pub name: String,
    pub x_m: f64,
    pub y_m: f64,
    #[serde(default)]
    pub heading_deg: f64,
    pub length_m: f64,
    pub width_m: f64,
}

/// A named place a pallet can stand (face centre, heading into the pallet).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PalletSlot {
    pub name: String,
    pub x_m: f64,
    pub y_m: f64,
    pub heading_deg: f64,
}

impl PalletSlot {
    pub fn pose(&self) -> Pose2 {
        Pose2::new(self.x_m, self.y_m, self.heading_deg.to_radians())
    }
}

/// A warehouse layout.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub rack: Vec<RectFile>,
    #[serde(default)]
    pub wall: Vec<RectFile>,
    #[serde(default)]
    pub pallet_slot: Vec<PalletSlot>,
    /// Named places a truck drives to (charging station, sorting station): the pose the
    /// fork root should reach.
    #[serde(default)]
    pub station: Vec<PalletSlot>,
    /// NAV350 reflectors (points in the scanner's plane).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reflector: Vec<forkbench_sensors::reflectors::Reflector>,
    /// Fixed clutter (`[[clutter]]`): scans see it, the truck strikes it, plans avoid it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clutter: Vec<super::clutter::ClutterFile>,
}

impl World {
    /// A world file (TOML), or a ROS map_server map (`.yaml`/`.yml` with its image).
    pub fn load(path: &FsPath) -> Result<Self, ScenarioError> {
        let file = path.display().to_string();
        if path.extension().is_some_and(|e| e == "yaml" || e == "yml") {
            return Self::from_map(path);
        }
        Self::parse(&read(path)?, &file)
    }

    /// A map_server map's grid, its cells within the world's extent (±10 km): the bound
    /// every planner's memory and work is sized by, for scenarios and `plan --map` alike.
    pub fn read_grid(path: &FsPath) -> Result<forkbench_nav::OccupancyGrid, ScenarioError> {
        let file = path.display().to_string();
        let grid = forkbench_nav::read_map(path).map_err(|e| ScenarioError::Parse {
            file: file.clone(),
            message: e.to_string(),
        })?;
        let (lo, hi) = grid.extent();
        if lo.iter().chain(&hi).any(|v| v.abs() > MAX_WORLD_EXTENT_M) {
            return Err(invalid(
                &file,
                "resolution",
                &format!(
                    "the map's cells span ({:.6e}, {:.6e}) to ({:.6e}, {:.6e}) m, beyond ±10 km \
                     (a world's extent): check origin and resolution",
                    lo[0], lo[1], hi[0], hi[1]
                ),
            ));
        }
        Ok(grid)
    }

    /// A map from SLAM or Nav2 as a world: its occupied and unknown cells, merged into
    /// rectangles, are the racks (the physics and the planners see the same cells). A map
    /// has no named places: scenarios give poses.
    pub fn from_map(path: &FsPath) -> Result<Self, ScenarioError> {
        let file = path.display().to_string();
        let grid = Self::read_grid(path)?;
        let rack = forkbench_nav::blocked_rects(&grid)
            .into_iter()
            .enumerate()
            .map(|(i, [lo, hi])| RectFile {
                name: format!("cells {i}"),
                x_m: (lo[0] + hi[0]) / 2.0,
                y_m: (lo[1] + hi[1]) / 2.0,
                heading_deg: 0.0,
                length_m: hi[0] - lo[0],
                width_m: hi[1] - lo[1],
            })
            .collect();
        let name = path
            .file_stem()
            .map_or("map".to_owned(), |s| s.to_string_lossy().into_owned());
        let w = World {
            name,
            description: format!("occupancy map {file}"),
            rack,
            ..World::default()
        };
        // A map's origin and resolution can put its cells anywhere: the same bounds.
        w.check(&file)?;
        Ok(w)
    }

    pub fn parse(text: &str, file: &str) -> Result<Self, ScenarioError> {
        let w: World = parse(text, file)?;
        w.check(file)?;
        Ok(w)
    }

    /// Every coordinate finite and within ±10 km, lengths positive, and no two pallet
    /// slots or stations sharing a name (scenarios and missions pick them by name).
    fn check(&self, file: &str) -> Result<(), ScenarioError> {
        let w = self;
        for (kind, list) in [("rack", &w.rack), ("wall", &w.wall)] {
            for (i, r) in list.iter().enumerate() {
                let f = format!("{kind}[{i}]");
                PoseDeg {
                    x_m: r.x_m,
                    y_m: r.y_m,
                    heading_deg: r.heading_deg,
                }
                .check(file, &f)?;
                for (name, v) in [("length_m", r.length_m), ("width_m", r.width_m)] {
                    if !(v.is_finite() && v > 0.0 && v <= MAX_WORLD_EXTENT_M) {
                        return Err(invalid(
                            file,
                            &format!("{f}.{name}"),
                            "must be a positive length of at most 10 km",
                        ));
                    }
                }
            }
        }
        if w.clutter.len() > super::clutter::MAX_CLUTTER {
            return Err(invalid(
                file,
                "clutter",
                &format!(
                    "{} items; at most {}",
                    w.clutter.len(),
                    super::clutter::MAX_CLUTTER
                ),
            ));
        }
        for (i, c) in w.clutter.iter().enumerate() {
            c.check(file, &format!("clutter[{i}]"))?;
        }
        for (kind, list) in [("pallet_slot", &w.pallet_slot), ("station", &w.station)] {
            let mut seen = std::collections::HashMap::new();
            for (i, s) in list.iter().enumerate() {
                PoseDeg {
                    x_m: s.x_m,
                    y_m: s.y_m,
                    heading_deg: s.heading_deg,
                }
                .check(file, &format!("{kind}[{i}]"))?;
                if let Some(j) = seen.insert(s.name.as_str(), i) {
                    return Err(invalid(
                        file,
                        &format!("{kind}[{i}].name"),
                        &format!(
                            "{:?} is also {kind}[{j}]'s name; names pick them, so each once",
                            s.name
                        ),
                    ));
                }
            }
        }
        self.check_reflectors(file)
    }

    /// Reflectors: finite and within the world's extent, each name once, none inside a
    /// rack or wall (mount them on a face, a few centimetres proud of it).
    fn check_reflectors(&self, file: &str) -> Result<(), ScenarioError> {
        let obstacles = self.obstacles();
        // Each NAV350 fix tests reflectors against the racks and walls: a bound on that
        // work, not on either count alone.
        let work = self.reflector.len().saturating_mul(obstacles.len().max(1));
        if work > MAX_REFLECTOR_WORK {
            return Err(invalid(
                file,
                "reflector",
                &format!(
                    "{} reflectors × {} racks and walls = {work} sight-line tests per fix, more \
                     than {MAX_REFLECTOR_WORK}: fewer reflectors, or split the site into worlds",
                    self.reflector.len(),
                    obstacles.len()
                ),
            ));
        }
        let mut seen = std::collections::HashMap::new();
        for (i, r) in self.reflector.iter().enumerate() {
            let f = format!("reflector[{i}]");
            PoseDeg {
                x_m: r.x_m,
                y_m: r.y_m,
                heading_deg: 0.0,
            }
            .check(file, &f)?;
            if let Some(j) = seen.insert(r.name.as_str(), i) {
                return Err(invalid(
                    file,
                    &format!("{f}.name"),
                    &format!("{:?} is also reflector[{j}]'s name", r.name),
                ));
            }
            // `--missing-reflectors` lists names separated by commas.
            if r.name.is_empty() || r.name.contains(',') {
                return Err(invalid(
                    file,
                    &format!("{f}.name"),
                    &format!(
                        "{:?}: a name is not empty and has no comma (the command line lists \
                         names separated by commas)",
                        r.name
                    ),
                ));
            }
            // On a face is allowed: that is where a reflector hangs (a turned face's
            // coordinates round, so "on" has a nanometre's tolerance).
            if let Some(o) = obstacles
                .iter()
                .find(|o| o.depth_inside([r.x_m, r.y_m]) > ON_FACE_TOLERANCE_M)
            {
                return Err(invalid(
                    file,
                    &f,
                    &format!(
                        "({}, {}) m lies inside the obstacle at ({}, {}) m; a reflector hangs on \
                         a face, outside it",
                        r.x_m, r.y_m, o.centre.x_m, o.centre.y_m
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The same world without the reflectors named (each must exist).
    pub fn without_reflectors(&self, names: &[String]) -> Result<World, ScenarioError> {
        if let Some(n) = names
            .iter()
            .find(|n| !self.reflector.iter().any(|r| &r.name == *n))
        {
            return Err(super::invalid(
                &self.name,
                "reflector",
                &format!("{n:?} is not a reflector of this world"),
            ));
        }
        let mut w = self.clone();
        w.reflector.retain(|r| !names.contains(&r.name));
        Ok(w)
    }

    /// Every rack's and wall's sides, as the surfaces a scanner's light can meet.
    pub fn fixed_surfaces(&self) -> Vec<forkbench_sensors::scan::Surface> {
        use forkbench_sensors::scan::{Seen, Surface};
        self.obstacles()
            .iter()
            .flat_map(|o| Surface::rect(&o.centre, o.length_m, o.width_m, Seen::Fixed))
            .collect()
    }

    /// Racks and walls for the footprint checker, with a label per obstacle for messages.
    pub fn footprint_obstacles(&self) -> (Obstacles, Vec<String>) {
        let mut obstacles = Obstacles::new();
        let mut labels = Vec::new();
        for (kind, list) in [("rack", &self.rack), ("wall", &self.wall)] {
            for r in list {
                obstacles.add_rect(
                    &Pose2::new(r.x_m, r.y_m, r.heading_deg.to_radians()),
                    r.length_m,
                    r.width_m,
                );
                labels.push(if r.name.is_empty() {
                    kind.to_owned()
                } else {
                    format!("{kind} {:?}", r.name)
                });
            }
        }
        for c in &self.clutter {
            for (centre, l, w) in c.rects() {
                obstacles.add_rect(&centre, l, w);
                labels.push(format!("{} {:?}", c.kind, c.name));
            }
        }
        (obstacles, labels)
    }

    /// The pose of the pallet slot `name`.
    pub fn slot_pose(&self, name: &str) -> Option<Pose2> {
        self.pallet_slot
            .iter()
            .find(|s| s.name == name)
            .map(PalletSlot::pose)
    }

    /// The pose of the station `name`.
    pub fn station_pose(&self, name: &str) -> Option<Pose2> {
        self.station
            .iter()
            .find(|s| s.name == name)
            .map(PalletSlot::pose)
    }

    /// Racks, walls and clutter as simulator obstacles.
    pub fn obstacles(&self) -> Vec<Obstacle> {
        let clutter = self.clutter.iter().flat_map(|c| c.rects());
        self.rack
            .iter()
            .chain(&self.wall)
            .map(|r| {
                (
                    Pose2::new(r.x_m, r.y_m, r.heading_deg.to_radians()),
                    r.length_m,
                    r.width_m,
                )
            })
            .chain(clutter)
            .map(|(centre, length_m, width_m)| Obstacle {
                centre,
                length_m,
                width_m,
            })
            .collect()
    }
}
