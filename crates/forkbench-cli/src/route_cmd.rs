//! `forkbench plan prm|rrt|rrt-connect --map …`: one global plan on an occupancy grid (Luo's PRM + A*, RRT baselines).

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use forkbench_core::ForkliftSpec;
use forkbench_core::Pose2;
use forkbench_nav::{
    CollisionModel, GlobalPlan, GlobalPlannerKind, GlobalQuery, OccupancyGrid, plan_global,
};
use serde_json::json;

/// What a global plan needs beyond start and goal.
#[derive(Debug, Clone)]
pub struct RouteArgs {
    pub planner: GlobalPlannerKind,
    pub map: PathBuf,
    pub start: Pose2,
    pub goal: Pose2,
    pub nodes: usize,
    /// PRM: grow until the query is connected (`nodes` the most samples drawn).
    pub first_solution: bool,
    /// Plans this many times in one process, seeds `seed`, `seed + 1`, … (one report each).
    pub runs: usize,
    /// `None`: unlimited.
    pub connect_m: Option<f64>,
    pub seed: u64,
    pub resolution_m: f64,
    /// Obstacle inflation; the paper's 0.5 × wheelbase by default.
    pub inflate_m: Option<f64>,
    pub collision: CollisionModel,
    pub smooth: bool,
    /// With `smooth`: plan a Hybrid-A* manoeuvre when the route cannot be smoothed.
    pub fallback: bool,
    /// Hybrid-A*'s settings (the planner's own, or the fallback's).
    pub hybrid: forkbench_nav::hybrid::HybridParams,
    pub lead_m: f64,
    pub approach_m: Option<f64>,
    pub margin_m: f64,
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

impl RouteArgs {
    fn query(&self) -> GlobalQuery {
        let mut algorithm = self
            .planner
            .algorithm(self.nodes, self.connect_m, self.seed);
        if let forkbench_nav::Algorithm::HybridAstar(_) = algorithm {
            algorithm = forkbench_nav::Algorithm::HybridAstar(self.hybrid);
        }
        if let (true, forkbench_nav::Algorithm::Prm(p)) = (self.first_solution, algorithm) {
            algorithm = forkbench_nav::Algorithm::PrmFirstSolution(p);
        }
        GlobalQuery {
            start: self.start,
            goal: self.goal,
            algorithm,
            collision: self.collision,
            inflate_m: self
                .inflate_m
                .unwrap_or(forkbench_nav::luo_inflation_m(&self.truck)),
            smooth: self.smooth,
            lead_m: [self.lead_m, self.approach_m.unwrap_or(self.lead_m)],
            approach: Vec::new(),
            margin_m: self.margin_m,
            truck: self.truck.clone(),
            manoeuvre_fallback: self.fallback.then_some(self.hybrid),
        }
    }
}

/// Plans `a.runs` times; whether every run found a path (a search that ran and found
/// none is a verdict, exit 3, for every planner alike; bad input is an error).
pub fn run(a: &RouteArgs) -> anyhow::Result<bool> {
    let map = forkbench_studies::prm_study::load_map(&a.map, a.resolution_m)?;
    let mut a = a.clone();
    let mut all_found = true;
    for run in 0..a.runs.max(1) {
        let q = a.query();
        let plan = match plan_global(&map, &q) {
            Err(
                e @ (forkbench_nav::NavError::Unreachable(_)
                | forkbench_nav::NavError::Budget { .. }),
            ) => {
                all_found = false;
                crate::emit(&if a.json {
                    format!(
                        "{}\n",
                        json!({"planner": a.planner.name(), "seed": a.seed, "polyline_m": null, "error": e.to_string()})
                    )
                } else {
                    format!("no path found: {e}\n")
                })?;
                a.seed = a.seed.wrapping_add(1);
                continue;
            }
            r => r.with_context(|| format!("plan {} on {}", a.planner.name(), a.map.display()))?,
        };
        all_found &= plan.route.points.is_some();
        if let (Some(file), 0) = (&a.plot, run) {
            forkbench_report::map::draw_route(file, a.planner, &a.map, &map, &q, &plan)?;
        }
        let simplified = if q.smooth || a.planner.kinodynamic() {
            None
        } else {
            forkbench_nav::simplify::simplify_plan(&map, &q, &plan, a.seed)
        };
        crate::emit(&report(&a, &map.grid, &q, &plan, simplified.as_ref()))?;
        a.seed = a.seed.wrapping_add(1);
    }
    Ok(all_found)
}

/// The smoothing result as JSON: the samples, or why there are none.
fn smoothing_json(plan: &GlobalPlan) -> serde_json::Value {
    match &plan.smoothed {
        None => serde_json::Value::Null,
        Some(Err(e)) => json!({"ok": false, "error": e.to_string()}),
        Some(Ok(s)) => json!({
            "ok": s.clear(),
            "polyline_m": s.polyline,
            "length_m": s.path.length_m(),
            "max_curvature_per_m": s.max_curvature_per_m,
            "min_clearance_m": s.min_clearance_m,
            "strike": s.hit,
            "samples": s.path.samples.iter().map(|p| [p.s_m, p.x_m, p.y_m, p.heading_rad, p.curvature_per_m]).collect::<Vec<_>>(),
        }),
    }
}

/// The smoothing result in one line of text.
fn smoothing_text(plan: &GlobalPlan) -> String {
    match &plan.smoothed {
        None => String::new(),
        Some(Err(e)) => format!("smoothing failed: {e}\n"),
        Some(Ok(s)) => match s.hit {
            Some(h) => format!(
                "smoothing failed: the swept footprint strikes obstacle {} at s = {:.2} m ({:.2}, {:.2})\n",
                h.obstacle, h.s_m, h.x_m, h.y_m
            ),
            None => format!(
                "smoothed: {:.2} m, |κ| ≤ {:.3} 1/m, footprint clearance ≥ {:.3} m\n",
                s.path.length_m(),
                s.max_curvature_per_m,
                s.min_clearance_m
            ),
        },
    }
}

fn report(
    a: &RouteArgs,
    grid: &OccupancyGrid,
    q: &GlobalQuery,
    plan: &GlobalPlan,
    simplified: Option<&forkbench_nav::simplify::Simplified>,
) -> String {
    let r = &plan.route;
    let t = &r.timing;
    let total = t.total_s() + plan.smoothing_s;
    if a.json {
        let out = json!({
            "planner": a.planner.name(),
            "map": a.map.display().to_string(),
            "grid": {"width": grid.width, "height": grid.height, "resolution_m": grid.resolution_m, "origin_m": grid.origin_m},
            "collision": q.collision,
            "inflate_m": (q.collision == CollisionModel::Inflate).then_some(q.inflate_m),
            "nodes_requested": a.nodes,
            "connect_m": a.connect_m,
            "seed": a.seed,
            "success": if a.smooth || a.planner.kinodynamic() { plan.succeeded() } else { r.found() },
            "manoeuvre": plan.manoeuvre.as_ref().map(manoeuvre_json),
            "fallback": plan.fallback,
            "polyline_m": r.points,
            "length_m": r.found().then_some(r.length_m),
            "first_solution": a.first_solution,
            "simplified": simplified.map(|s| json!({"polyline_m": s.points, "length_m": s.length_m, "time_s": s.time_s})),
            "roadmap_nodes": r.nodes,
            "roadmap_edges": plan.roadmap.as_ref().map(forkbench_nav::Roadmap::edge_count),
            "smoothing": smoothing_json(plan),
            "min_clearance_m": plan.drivable().map(|s| s.min_clearance_m),
            "timing_s": {"sampling": t.sampling_s, "connection": t.connection_s, "search": t.search_s, "smoothing": plan.smoothing_s, "total": total},
        });
        return format!("{out}\n");
    }
    let model = match q.collision {
        CollisionModel::Inflate => format!("obstacles inflated by {:.3} m", q.inflate_m),
        CollisionModel::Footprint => format!(
            "the truck's footprint swept along each edge, {:.2} m margin",
            q.margin_m
        ),
    };
    let seed = if a.planner.kinodynamic() {
        String::new()
    } else {
        format!(", seed {}", a.seed)
    };
    let head = format!(
        "{} on {} ({} × {} cells at {} m, {model}){seed}\n",
        a.planner.name(),
        a.map.display(),
        grid.width,
        grid.height,
        grid.resolution_m,
    );
    let timing = format!(
        "time {:.2} ms (sampling {:.2}, connection {:.2}, search {:.2}, smoothing {:.2}); {} nodes\n",
        1e3 * total,
        1e3 * t.sampling_s,
        1e3 * t.connection_s,
        1e3 * t.search_s,
        1e3 * plan.smoothing_s,
        r.nodes
    );
    let body = match &r.points {
        Some(p) => format!("path found: {} waypoints, {:.2} m\n", p.len(), r.length_m),
        None => "no path found\n".to_owned(),
    };
    let short = simplified.map_or(String::new(), |s| {
        format!(
            "simplified (shortcuts): {} waypoints, {:.2} m, in {:.3} ms\n",
            s.points.len(),
            s.length_m,
            1e3 * s.time_s
        )
    });
    head + &body + &short + &smoothing_text(plan) + &manoeuvre_text(plan) + &timing
}

/// A manoeuvre as JSON: its segments (direction, length, samples) and cusps.
fn manoeuvre_json(m: &forkbench_nav::hybrid::Manoeuvre) -> serde_json::Value {
    let segments: Vec<_> = m
        .segments
        .iter()
        .map(|p| {
            json!({
                "reverse": p.reverse,
                "length_m": p.length_m(),
                "samples": p.samples.iter().map(|s| [s.s_m, s.x_m, s.y_m, s.heading_rad, s.curvature_per_m]).collect::<Vec<_>>(),
            })
        })
        .collect();
    let cusps: Vec<_> = m
        .cusps()
        .iter()
        .map(|c| [c.x_m, c.y_m, c.heading_rad])
        .collect();
    json!({
        "length_m": m.length_m,
        "reverse_m": m.reverse_m(),
        "cusps": cusps,
        "segments": segments,
        "expansions": m.expansions,
        "time_s": m.time_s,
    })
}

/// The manoeuvre, and why it replaced a smoothed route, in text.
fn manoeuvre_text(plan: &GlobalPlan) -> String {
    let mut out = String::new();
    if let Some(why) = &plan.fallback {
        out += &format!("fallback: {why}\n");
    }
    if let Some(m) = &plan.manoeuvre {
        out += &format!(
            "manoeuvre (Hybrid-A*): {} segments, {} cusps, {:.2} m ({:.2} m backwards); {} nodes expanded in {:.2} ms\n",
            m.segments.len(),
            m.cusps().len(),
            m.length_m,
            m.reverse_m(),
            m.expansions,
            1e3 * m.time_s
        );
    }
    out
}

/// `reproduce prm`: Luo's studies on the embedded warehouse over `runs` seeds.
pub fn reproduce(runs: u64, json: bool, plot: Option<&Path>) -> anyhow::Result<()> {
    let forkbench_studies::prm_study::PrmStudy {
        ends,
        inflate_m,
        rows,
    } = forkbench_studies::prm_study::run(runs)?;
    if let Some(file) = plot {
        forkbench_report::prm::draw(file, &rows)?;
    }
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
        "Luo PRM + A* on worlds/warehouse.toml (40 × 26 m, 5 cm cells, obstacles inflated by {inflate_m:.3} m = 0.5 × wheelbase), \
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
