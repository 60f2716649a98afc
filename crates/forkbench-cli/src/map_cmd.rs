//! `forkbench map`: a world file rasterised to an occupancy grid, written as a ROS map_server map.

use std::path::PathBuf;

use anyhow::Context as _;
use forkbench_nav::{OccupancyGrid, write_map};

/// Arguments of `forkbench map`.
#[derive(Debug, clap::Args)]
pub struct MapArgs {
    /// World file (TOML) to rasterise.
    world: PathBuf,
    /// Directory for NAME.yaml and NAME.pgm (NAME: the world's name).
    #[arg(long)]
    out: PathBuf,
    /// Cell size.
    #[arg(long, default_value_t = 0.05)]
    resolution_m: f64,
    /// Free floor around the world's racks and walls.
    #[arg(long, default_value_t = 1.0)]
    margin_m: f64,
    /// Grow the obstacles by this radius before writing (e.g. 0.815, Luo's half
    /// wheelbase: the map a point planner searches, as `plan --collision inflate` does).
    #[arg(long)]
    inflate_m: Option<f64>,
}

pub fn run(a: &MapArgs) -> anyhow::Result<()> {
    let world = forkbench_trial::World::load(&a.world)?;
    let slots: Vec<[f64; 2]> = world.pallet_slot.iter().map(|s| [s.x_m, s.y_m]).collect();
    let grid =
        OccupancyGrid::from_obstacles(&world.obstacles(), &slots, a.resolution_m, a.margin_m)
            .with_context(|| format!("{}: rasterising", a.world.display()))?;
    let grid = match a.inflate_m {
        Some(r) if !(r.is_finite() && (0.0..=forkbench_nav::MAX_INFLATION_M).contains(&r)) => {
            anyhow::bail!(
                "--inflate-m {r}: must lie within 0..{} m (the work grows with its square)",
                forkbench_nav::MAX_INFLATION_M
            )
        }
        Some(r) => grid.inflated(r),
        None => grid,
    };
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let name = forkbench_trial::text::safe_file_stem(&world.name);
    let yaml = write_map(&grid, &a.out, &name)?;
    let (free, occupied, unknown) = grid.counts();
    crate::emit(&format!(
        "{}: {} × {} cells at {} m, origin ({:.2}, {:.2}) m; {free} free, {occupied} occupied, {unknown} unknown\n",
        yaml.display(),
        grid.width,
        grid.height,
        grid.resolution_m,
        grid.origin_m[0],
        grid.origin_m[1],
    ))
}
