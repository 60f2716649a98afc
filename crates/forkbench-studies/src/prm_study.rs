//! Luo's PRM studies on the embedded warehouse (the leg they plan), and a planning map loaded from a ROS map or a world.

use std::path::Path;

use forkbench_core::ForkliftSpec;
use forkbench_nav::reproduce::StudyRow;
use forkbench_nav::{GridError, MapError, NavError, NavMap};

use forkbench_trial::ScenarioError;

/// The station the studied leg starts at, the rack slot it ends before, and how far in
/// front of the slot's face (south, in the aisle) it ends: the paper's longest leg,
/// station to shelf.
const STUDY_STATION: &str = "charging";
const STUDY_SLOT: &str = "row2b-bay3-south";
const STUDY_AISLE_OFFSET_M: f64 = 1.5;
/// The embedded world the studies plan on.
const STUDY_WORLD: &str = "warehouse.toml";
/// The study's grid: 5 cm cells.
const STUDY_RESOLUTION_M: f64 = 0.05;

/// A planning map or study that could not be made.
#[derive(Debug, thiserror::Error)]
pub enum NavStudyError {
    #[error(transparent)]
    World(#[from] ScenarioError),
    #[error(transparent)]
    Map(#[from] MapError),
    /// The grid error is the message's end, not a source: a chain printer would say it twice.
    #[error("{file}: rasterising: {reason}")]
    Grid { file: String, reason: GridError },
    #[error(transparent)]
    Nav(#[from] NavError),
}

/// The studies' rows, the leg's ends and the inflation they planned with.
#[derive(Debug)]
pub struct PrmStudy {
    pub ends: ([f64; 2], [f64; 2]),
    pub inflate_m: f64,
    pub rows: Vec<StudyRow>,
}

/// `reproduce prm`: both studies and an RRT row over `runs` seeds, on the embedded
/// warehouse rasterised once and inflated by 0.5 × wheelbase.
pub fn run(runs: u64) -> Result<PrmStudy, NavStudyError> {
    let world = forkbench_trial::defaults::embedded_world(STUDY_WORLD)?;
    let inflate_m = forkbench_nav::luo_inflation_m(&ForkliftSpec::default());
    let grid = NavMap::from_world(&world.obstacles(), STUDY_RESOLUTION_M)
        .map_err(|reason| NavStudyError::Grid {
            file: format!("worlds/{STUDY_WORLD}"),
            reason,
        })?
        .grid
        .inflated(inflate_m);
    let ends = study_leg(&world)?;
    let rows = forkbench_nav::reproduce::studies(&grid, ends, runs)?;
    Ok(PrmStudy {
        ends,
        inflate_m,
        rows,
    })
}

/// The studied leg's ends: the station, and the aisle in front of the slot.
fn study_leg(world: &forkbench_trial::World) -> Result<([f64; 2], [f64; 2]), ScenarioError> {
    let place = |list: &[forkbench_trial::scenario::PalletSlot], name: &str| {
        list.iter()
            .find(|p| p.name == name)
            .map(|p| [p.x_m, p.y_m])
            .ok_or_else(|| {
                let file = format!("worlds/{STUDY_WORLD}");
                forkbench_trial::scenario::invalid(&file, "place", &format!("no place {name:?}"))
            })
    };
    let start = place(&world.station, STUDY_STATION)?;
    let slot = place(&world.pallet_slot, STUDY_SLOT)?;
    Ok((start, [slot[0], slot[1] - STUDY_AISLE_OFFSET_M]))
}

/// A planning map: a ROS map_server YAML, or a world TOML rasterised at `resolution_m`.
pub fn load_map(map: &Path, resolution_m: f64) -> Result<NavMap, NavStudyError> {
    if map.extension().is_some_and(|e| e == "yaml" || e == "yml") {
        return Ok(NavMap::from_grid(forkbench_trial::World::read_grid(map)?));
    }
    let world = forkbench_trial::World::load(map)?;
    NavMap::from_world(&world.obstacles(), resolution_m).map_err(|reason| NavStudyError::Grid {
        file: map.display().to_string(),
        reason,
    })
}
