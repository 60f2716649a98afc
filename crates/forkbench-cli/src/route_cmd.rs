//! `forkbench plan prm|rrt|rrt-connect --map …`: one global plan on an occupancy grid (Luo's PRM + A*, RRT baselines).

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use forkbench_core::ForkliftSpec;
use forkbench_nav::{
    OccupancyGrid, PrmParams, Route, RrtParams, plan_prm, plan_rrt, plan_rrt_connect, read_map,
};
use serde_json::json;

/// The global planners `plan` knows besides the pick planners.
pub const GLOBAL_PLANNERS: [&str; 3] = ["prm", "rrt", "rrt-connect"];

/// What a global plan needs beyond start and goal.
#[derive(Debug, Clone)]
pub struct RouteArgs {
    pub planner: String,
    pub map: PathBuf,
    pub start: [f64; 2],
    pub goal: [f64; 2],
    pub nodes: usize,
    /// `None`: unlimited.
    pub connect_m: Option<f64>,
    pub seed: u64,
    pub resolution_m: f64,
    /// Obstacle inflation; the paper's 0.5 × wheelbase by default.
    pub inflate_m: Option<f64>,
    pub truck: ForkliftSpec,
    pub json: bool,
    /// Draw the map, roadmap and path to FILE (.svg or .png).
    pub plot: Option<PathBuf>,
}

/// `--connect-m`: metres, or `inf` (infinity) for unlimited.
pub fn parse_connect(text: &str) -> Result<f64, String> {
    match text {
        "inf" | "unlimited" => Ok(f64::INFINITY),
        t => match t.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
            _ => Err(format!(
                "{t:?}: expected a positive distance in metres or `inf`"
            )),
        },
    }
}

/// The map: a ROS map_server YAML, or a world TOML rasterised at `resolution_m`.
pub fn load_grid(map: &Path, resolution_m: f64) -> anyhow::Result<OccupancyGrid> {
    if map.extension().is_some_and(|e| e == "yaml" || e == "yml") {
        return Ok(read_map(map)?);
    }
    let world = forkbench_trial::World::load(map)?;
    world_grid(&world, resolution_m).with_context(|| format!("{}: rasterising", map.display()))
}

/// A world's racks and walls rasterised, the grid ending at their outer edges.
fn world_grid(
    world: &forkbench_trial::World,
    resolution_m: f64,
) -> Result<OccupancyGrid, forkbench_nav::GridError> {
    OccupancyGrid::from_obstacles(&world.obstacles(), &[], resolution_m, 0.0)
}

pub fn run(a: &RouteArgs) -> anyhow::Result<()> {
    let inflate_m = a
        .inflate_m
        .unwrap_or(forkbench_nav::luo_inflation_m(&a.truck));
    let map = load_grid(&a.map, a.resolution_m)?;
    let grid = map.inflated(inflate_m);
    let mut roadmap = None;
    let route = match a.planner.as_str() {
        "prm" => {
            let p = PrmParams {
                nodes: a.nodes,
                connect_m: a.connect_m,
                seed: a.seed,
            };
            let (route, built) = plan_prm(&grid, a.start, a.goal, &p)?;
            roadmap = Some(built);
            route
        }
        kind => {
            let p = RrtParams {
                seed: a.seed,
                ..RrtParams::default()
            };
            if kind == "rrt" {
                plan_rrt(&grid, a.start, a.goal, &p)?
            } else {
                plan_rrt_connect(&grid, a.start, a.goal, &p)?
            }
        }
    };
    if let Some(file) = &a.plot {
        let title = match &route.points {
            Some(_) => format!(
                "{} on {}: {:.1} m",
                a.planner,
                a.map.display(),
                route.length_m
            ),
            None => format!("{} on {}: no path", a.planner, a.map.display()),
        };
        let fig = crate::map_plot::MapFigure {
            title,
            grid: &map,
            inflated: &grid,
            roadmap: roadmap.as_ref(),
            path: route.points.as_deref(),
            start: a.start,
            goal: a.goal,
        };
        crate::map_plot::draw_map(file, &fig)?;
    }
    crate::emit(&report(a, &grid, inflate_m, &route))
}

fn report(a: &RouteArgs, grid: &OccupancyGrid, inflate_m: f64, r: &Route) -> String {
    if a.json {
        let out = json!({
            "planner": a.planner,
            "map": a.map.display().to_string(),
            "grid": {"width": grid.width, "height": grid.height, "resolution_m": grid.resolution_m, "origin_m": grid.origin_m},
            "inflate_m": inflate_m,
            "nodes_requested": a.nodes,
            "connect_m": a.connect_m,
            "seed": a.seed,
            "success": r.found(),
            "polyline_m": r.points,
            "length_m": r.found().then_some(r.length_m),
            "roadmap_nodes": r.nodes,
            "timing_s": {"sampling": r.timing.sampling_s, "connection": r.timing.connection_s, "search": r.timing.search_s, "total": r.timing.total_s()},
        });
        return format!("{out}\n");
    }
    let head = format!(
        "{} on {} ({} × {} cells at {} m, obstacles inflated by {inflate_m:.3} m), seed {}\n",
        a.planner,
        a.map.display(),
        grid.width,
        grid.height,
        grid.resolution_m,
        a.seed
    );
    let t = &r.timing;
    let timing = format!(
        "time {:.2} ms (sampling {:.2}, connection {:.2}, search {:.2}); {} nodes\n",
        1e3 * t.total_s(),
        1e3 * t.sampling_s,
        1e3 * t.connection_s,
        1e3 * t.search_s,
        r.nodes
    );
    let body = match &r.points {
        Some(p) => format!("path found: {} waypoints, {:.2} m\n", p.len(), r.length_m),
        None => "no path found\n".to_owned(),
    };
    head + &body + &timing
}

/// The warehouse leg the reproduction plans: charging station to the aisle in front of a
/// far rack bay (the paper's longest leg, station to shelf).
fn study_leg(world: &forkbench_trial::World) -> anyhow::Result<([f64; 2], [f64; 2])> {
    let place = |list: &[forkbench_trial::scenario::PalletSlot], name: &str| {
        list.iter()
            .find(|p| p.name == name)
            .map(|p| [p.x_m, p.y_m])
            .ok_or_else(|| anyhow::anyhow!("worlds/warehouse.toml: no place {name:?}"))
    };
    let start = place(&world.station, "charging")?;
    let slot = place(&world.pallet_slot, "row2b-bay3-south")?;
    // 1.5 m in front of the slot's face, in the aisle.
    Ok((start, [slot[0], slot[1] - 1.5]))
}

/// `reproduce prm`: Luo's studies on the embedded warehouse over `runs` seeds.
pub fn reproduce(runs: u64, json: bool) -> anyhow::Result<()> {
    let world = forkbench_trial::defaults::embedded_world("warehouse.toml")?;
    let truck = ForkliftSpec::default();
    let inflate_m = forkbench_nav::luo_inflation_m(&truck);
    let grid = world_grid(&world, 0.05)?.inflated(inflate_m);
    let ends = study_leg(&world)?;
    let rows = forkbench_nav::reproduce::studies(&grid, ends, runs)?;
    if json {
        let rows: Vec<_> = rows
            .iter()
            .map(|r| json!({"planner": r.planner, "nodes": r.nodes, "connect_m": r.connect_m, "runs": r.runs, "found": r.found, "median_time_s": r.median_time_s, "median_length_m": r.median_length_m}))
            .collect();
        return crate::emit(&format!(
            "{}\n",
            json!({"start": ends.0, "goal": ends.1, "inflate_m": inflate_m, "rows": rows})
        ));
    }
    // Times are planning only: the grid is rasterised and inflated once, before.
    let mut out = format!(
        "Luo PRM + A* on worlds/warehouse.toml (40 × 25 m, 5 cm cells, obstacles inflated by {inflate_m:.3} m = 0.5 × wheelbase), \
         charging station ({:.1}, {:.1}) → aisle before row2b bay 3 ({:.2}, {:.2}), seeds 0..{runs}\n\n\
         | planner | nodes | connection | success | median time | median length | paper |\n|---|---|---|---|---|---|---|\n",
        ends.0[0], ends.0[1], ends.1[0], ends.1[1]
    );
    for r in &rows {
        let conn = r.connect_m.map_or("∞".to_owned(), |c| format!("{c} m"));
        let (nodes, conn) = if r.planner == "RRT" {
            ("—".to_owned(), "step 1 m".to_owned())
        } else {
            (r.nodes.unwrap_or(0).to_string(), conn)
        };
        let length = if r.median_length_m.is_nan() {
            "—".to_owned()
        } else {
            format!("{:.1} m", r.median_length_m)
        };
        out += &format!(
            "| {} | {nodes} | {conn} | {}/{} ({:.0} %) | {:.2} ms | {length} | {} |\n",
            r.planner,
            r.found,
            r.runs,
            100.0 * r.found as f64 / r.runs as f64,
            1e3 * r.median_time_s,
            paper(r)
        );
    }
    crate::emit(&out)
}

/// What the paper reports for a row (MATLAB 2020a, its own map), if anything.
fn paper(r: &forkbench_nav::reproduce::StudyRow) -> &'static str {
    match (r.planner, r.nodes, r.connect_m) {
        ("RRT", _, _) => "1.056 s",
        (_, Some(500), Some(10.0)) => "100 %, 0.517 s",
        (_, Some(15), Some(10.0)) => "35 %",
        (_, Some(50), Some(10.0)) => "93 % (or 80 %)",
        (_, Some(100), Some(10.0)) => "100 %",
        (_, Some(50), Some(5.0)) => "no path",
        _ => "",
    }
}
