//! One global plan end to end: the map's two views (grid and shapes), the chosen planner and collision model, shortcuts and smoothing, each stage timed.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use forkbench_core::geometry::Obstacle;
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_geom::Obstacles;

use crate::hybrid::{HybridParams, HybridQuery, Manoeuvre, plan_hybrid};
use crate::smooth::{SmoothError, SmoothParams, Smoothed, lead_points, shortcut, smooth};
use crate::space::{CollisionModel, FootprintSpace, FreeSpace, grid_obstacles, truck_parts};
use crate::{
    GridError, NavError, OccupancyGrid, PrmParams, Roadmap, Route, RrtParams, plan_prm, plan_rrt,
    plan_rrt_connect,
};

/// A map in both forms: the occupancy grid the planners sample, and shapes for the
/// footprint checker (a world's racks and walls, or a map file's cell runs).
#[derive(Debug)]
pub struct NavMap {
    pub grid: OccupancyGrid,
    pub obstacles: Obstacles,
    /// Inflated copies of `grid` by radius (bit pattern), made on first use: every leg
    /// and every trial on this map asks for the same few.
    inflated: Mutex<Vec<(u64, Arc<OccupancyGrid>)>>,
}

/// Most worlds whose maps the process keeps.
const MAX_SHARED_MAPS: usize = 4;
/// Most inflated copies a map keeps.
const MAX_INFLATED: usize = 8;

impl NavMap {
    /// A world's rectangles, rasterised at `resolution_m`; the grid ends at their edges.
    pub fn from_world(obstacles: &[Obstacle], resolution_m: f64) -> Result<Self, GridError> {
        let grid = OccupancyGrid::from_obstacles(obstacles, &[], resolution_m, 0.0)?;
        let mut shapes = Obstacles::new();
        for o in obstacles {
            shapes.add_rect(&o.centre, o.length_m, o.width_m);
        }
        Ok(Self::new(grid, shapes))
    }

    /// [`NavMap::from_world`], shared: a batch's trials on one world get the map built
    /// by the first (the process keeps the last few worlds' maps).
    pub fn shared_from_world(
        obstacles: &[Obstacle],
        resolution_m: f64,
    ) -> Result<Arc<Self>, GridError> {
        type Entry = (u64, Vec<Obstacle>, Arc<NavMap>);
        static MAPS: Mutex<Vec<Entry>> = Mutex::new(Vec::new());
        let key = resolution_m.to_bits();
        let found = {
            let maps = MAPS.lock().unwrap_or_else(|e| e.into_inner());
            maps.iter()
                .find(|(r, o, _)| *r == key && o.as_slice() == obstacles)
                .map(|(_, _, m)| Arc::clone(m))
        };
        if let Some(m) = found {
            return Ok(m);
        }
        // Built outside the lock: two threads may both build it, never wait on each other.
        let map = Arc::new(Self::from_world(obstacles, resolution_m)?);
        let mut maps = MAPS.lock().unwrap_or_else(|e| e.into_inner());
        if maps.len() >= MAX_SHARED_MAPS {
            maps.remove(0);
        }
        maps.push((key, obstacles.to_vec(), Arc::clone(&map)));
        Ok(map)
    }

    /// A map read from a file: shapes from its occupied and unknown cells.
    pub fn from_grid(grid: OccupancyGrid) -> Self {
        let obstacles = grid_obstacles(&grid);
        Self::new(grid, obstacles)
    }

    /// The two views, which must describe the same space.
    pub fn new(grid: OccupancyGrid, obstacles: Obstacles) -> Self {
        Self {
            grid,
            obstacles,
            inflated: Mutex::new(Vec::new()),
        }
    }

    /// The grid with its obstacles grown by `radius_m`, made once per radius.
    pub fn inflated(&self, radius_m: f64) -> Arc<OccupancyGrid> {
        let key = radius_m.to_bits();
        // A poisoned lock only means another thread panicked mid-insert: the list is
        // still a valid cache.
        let mut cache = self.inflated.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, g)) = cache.iter().find(|(k, _)| *k == key) {
            return Arc::clone(g);
        }
        let g = Arc::new(self.grid.inflated(radius_m));
        if cache.len() >= MAX_INFLATED {
            cache.remove(0);
        }
        cache.push((key, Arc::clone(&g)));
        g
    }
}

/// The global planners by name: the one mapping from a name (scenario files, `plan
/// --planner`) to an [`Algorithm`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GlobalPlannerKind {
    Prm,
    Rrt,
    RrtConnect,
    #[serde(alias = "hybrid_astar")]
    HybridAstar,
}

impl GlobalPlannerKind {
    pub const ALL: [Self; 4] = [Self::Prm, Self::Rrt, Self::RrtConnect, Self::HybridAstar];

    pub fn name(self) -> &'static str {
        match self {
            Self::Prm => "prm",
            Self::Rrt => "rrt",
            Self::RrtConnect => "rrt-connect",
            Self::HybridAstar => "hybrid-astar",
        }
    }

    /// The kind by name (`hybrid_astar` also names Hybrid-A*).
    pub fn from_name(name: &str) -> Option<Self> {
        let name = if name == "hybrid_astar" {
            "hybrid-astar"
        } else {
            name
        };
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Whether it searches the truck's poses itself (no smoothing of a point route).
    pub fn kinodynamic(self) -> bool {
        self == Self::HybridAstar
    }

    /// The algorithm with its parameters: PRM's node count and connection distance, the
    /// RRTs' defaults, and the seed for either.
    pub fn algorithm(self, nodes: usize, connect_m: Option<f64>, seed: u64) -> Algorithm {
        let rrt = RrtParams {
            seed,
            ..RrtParams::default()
        };
        match self {
            Self::Prm => Algorithm::Prm(PrmParams {
                nodes,
                connect_m,
                seed,
            }),
            Self::Rrt => Algorithm::Rrt(rrt),
            Self::RrtConnect => Algorithm::RrtConnect(rrt),
            Self::HybridAstar => Algorithm::HybridAstar(HybridParams::default()),
        }
    }
}

/// Which sampling planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Algorithm {
    Prm(PrmParams),
    /// PRM grown until the query is connected, `nodes` the most samples drawn.
    PrmFirstSolution(PrmParams),
    Rrt(RrtParams),
    RrtConnect(RrtParams),
    /// Hybrid-A* over the truck's poses, forwards and backwards: a manoeuvre, not a route
    /// to smooth.
    HybridAstar(HybridParams),
}

/// A global planning query.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalQuery {
    pub start: Pose2,
    pub goal: Pose2,
    pub algorithm: Algorithm,
    pub collision: CollisionModel,
    /// Inflation radius of the `Inflate` model (Luo: half the wheelbase).
    pub inflate_m: f64,
    /// Smooth into a drivable path. The start and goal headings then count: the route
    /// runs through lead points `lead_m[0]` ahead of the start and `lead_m[1]` behind
    /// the goal.
    pub smooth: bool,
    pub lead_m: [f64; 2],
    /// With `smooth`: points the path passes through, in order, between the route and the
    /// lead-out (e.g. a square turn onto a rack face). The sampler plans to the first.
    pub approach: Vec<[f64; 2]>,
    /// Footprint model: the clearance edges and the smoothed path keep (the smoothed
    /// path is checked with the footprint grown by it in both models).
    pub margin_m: f64,
    pub truck: ForkliftSpec,
    /// With `smooth`: when the point route cannot be smoothed into a drivable path (a start
    /// facing away from the route, no room for a lead), plan a manoeuvre with Hybrid-A*
    /// instead (`None`: report the failure).
    pub manoeuvre_fallback: Option<HybridParams>,
}

/// A global plan: the planner's route (with the lead points when smoothing), its roadmap
/// (PRM), the smoothing result, and the smoothing time beside the route's stages.
#[derive(Debug, Clone)]
pub struct GlobalPlan {
    pub route: Route,
    pub roadmap: Option<Roadmap>,
    /// `None` without `smooth` or without a route.
    pub smoothed: Option<Result<Smoothed, SmoothError>>,
    pub smoothing_s: f64,
    /// Hybrid-A*'s manoeuvre: the plan itself, or the fallback when smoothing failed.
    pub manoeuvre: Option<Manoeuvre>,
    /// Why the smoothed route gave way to the manoeuvre, or why the fallback failed too.
    pub fallback: Option<String>,
}

impl GlobalPlan {
    /// A route and its roadmap, nothing smoothed or manoeuvred yet.
    fn of_route(route: Route, roadmap: Option<Roadmap>) -> Self {
        Self {
            route,
            roadmap,
            smoothed: None,
            smoothing_s: 0.0,
            manoeuvre: None,
            fallback: None,
        }
    }

    /// A drivable path whose swept footprint clears every obstacle.
    pub fn drivable(&self) -> Option<&Smoothed> {
        match &self.smoothed {
            Some(Ok(s)) if s.clear() => Some(s),
            _ => None,
        }
    }

    /// Whether the plan can be driven: a clear smoothed path or a manoeuvre.
    pub fn succeeded(&self) -> bool {
        self.drivable().is_some() || self.manoeuvre.is_some()
    }
}

/// The query's distances in range: a NaN or negative margin would let a path cut an
/// obstacle, and an infinite one abort.
fn check_query(q: &GlobalQuery) -> Result<(), NavError> {
    if !(q.inflate_m.is_finite() && (0.0..=crate::MAX_INFLATION_M).contains(&q.inflate_m)) {
        return Err(NavError::Params(format!(
            "inflation {} m: must lie within 0..{} m",
            q.inflate_m,
            crate::MAX_INFLATION_M
        )));
    }
    forkbench_core::settings::in_ranges(&[
        ("margin_m", q.margin_m, 0.0, MAX_MARGIN_M),
        ("lead_m", q.lead_m[0], 0.0, MAX_LEAD_M),
        ("approach_m", q.lead_m[1], 0.0, MAX_LEAD_M),
    ])
    .map_err(|e| NavError::Params(e.to_string()))
}

/// Most clearance a query may keep around the footprint: a truck's width.
pub const MAX_MARGIN_M: f64 = 2.0;
/// Longest straight lead-in or lead-out a smoothed route may ask for.
pub const MAX_LEAD_M: f64 = 100.0;

/// Plans `q` on `map`.
pub fn plan_global(map: &NavMap, q: &GlobalQuery) -> Result<GlobalPlan, NavError> {
    check_query(q)?;
    let inflated;
    let footprint;
    let space: &dyn FreeSpace = match q.collision {
        CollisionModel::Inflate => {
            inflated = map.inflated(q.inflate_m);
            &*inflated
        }
        CollisionModel::Footprint => {
            footprint = FootprintSpace::on(map, &q.truck, q.margin_m);
            &footprint
        }
    };
    if let Algorithm::HybridAstar(params) = q.algorithm {
        return plan_manoeuvre(map, q, params).map(|m| {
            let route = route_of(&m);
            GlobalPlan {
                manoeuvre: Some(m),
                ..GlobalPlan::of_route(route, None)
            }
        });
    }
    let (from, to) = if q.smooth {
        match (lead_in_and_out(map, space, q), q.manoeuvre_fallback) {
            (Ok(ends), _) => ends,
            (Err(e), Some(params)) => return fallback(map, q, params, e.to_string(), None),
            (Err(e), None) => return Err(e),
        }
    } else {
        ([q.start.x_m, q.start.y_m], [q.goal.x_m, q.goal.y_m])
    };
    crate::check_endpoints(space, from, to)?;
    let (mut route, roadmap) = run_algorithm(space, from, to, &q.algorithm)?;
    let mut plan = GlobalPlan::of_route(route.clone(), roadmap);
    let Some(points) = route.points.take() else {
        return Ok(plan);
    };
    if q.smooth {
        let t0 = Instant::now();
        plan.smoothed = Some(smooth_route(map, space, q, &points));
        plan.smoothing_s = t0.elapsed().as_secs_f64();
        if let (None, Some(params)) = (plan.drivable(), q.manoeuvre_fallback) {
            let why = smoothing_failure(&plan);
            return fallback(map, q, params, why, Some(plan));
        }
    }
    Ok(plan)
}

fn plan_manoeuvre(
    map: &NavMap,
    q: &GlobalQuery,
    params: HybridParams,
) -> Result<Manoeuvre, NavError> {
    let hq = HybridQuery {
        start: q.start,
        goal: q.goal,
        truck: q.truck.clone(),
        margin_m: q.margin_m,
        load: None,
        params,
        approach_m: 0.0,
    };
    plan_hybrid(map, &hq)
}

/// The manoeuvre's positions as the plan's route.
fn route_of(m: &Manoeuvre) -> Route {
    let timing = crate::Timing {
        search_s: m.time_s,
        ..Default::default()
    };
    Route::new(Some(m.polyline()), timing, m.expansions)
}

/// Why a smoothed plan is not drivable, in words.
fn smoothing_failure(plan: &GlobalPlan) -> String {
    match &plan.smoothed {
        Some(Err(e)) => format!("smoothing failed: {e}"),
        Some(Ok(s)) => s.hit.map_or_else(
            || "smoothing failed".to_owned(),
            |h| {
                format!(
                    "the smoothed path's footprint strikes an obstacle at ({:.2}, {:.2}) m",
                    h.x_m, h.y_m
                )
            },
        ),
        None => "no route to smooth".to_owned(),
    }
}

/// The smoothed route could not be had (`why`): a Hybrid-A* manoeuvre instead, keeping
/// the point route and its failed smoothing (when there were any) for the record.
fn fallback(
    map: &NavMap,
    q: &GlobalQuery,
    params: HybridParams,
    why: String,
    point_plan: Option<GlobalPlan>,
) -> Result<GlobalPlan, NavError> {
    let t0 = Instant::now();
    let m = plan_manoeuvre(map, q, params);
    let mut plan = point_plan.unwrap_or_else(|| {
        GlobalPlan::of_route(Route::new(None, crate::Timing::default(), 0), None)
    });
    plan.smoothing_s += t0.elapsed().as_secs_f64();
    match m {
        Ok(m) => {
            plan.fallback = Some(format!("{why}; planned by Hybrid-A* instead"));
            plan.manoeuvre = Some(m);
        }
        Err(e) => plan.fallback = Some(format!("{why}; Hybrid-A* failed too: {e}")),
    }
    Ok(plan)
}

/// The points the sampler connects when the headings count: the lead-in ahead of the
/// start, and the first approach point (or the lead-out) before the goal. The start and
/// goal themselves must be on the map and outside every obstacle.
fn lead_in_and_out(
    map: &NavMap,
    space: &dyn FreeSpace,
    q: &GlobalQuery,
) -> Result<([f64; 2], [f64; 2]), NavError> {
    let ends = ([q.start.x_m, q.start.y_m], [q.goal.x_m, q.goal.y_m]);
    crate::check_endpoints(&map.grid, ends.0, ends.1)?;
    let (from, lead_out) = lead_points(&q.start, &q.goal, q.lead_m);
    let tail: Vec<[f64; 2]> = q.approach.iter().copied().chain([lead_out]).collect();
    let blocked = |what: &str, p: [f64; 2]| {
        NavError::Params(format!(
            "no room for the {what}: ({:.2}, {:.2}) m is too close to an obstacle",
            p[0], p[1]
        ))
    };
    if !space.point_free(from) {
        return Err(blocked("lead-in ahead of the start", from));
    }
    if let Some(&p) = tail.iter().find(|p| !space.point_free(**p)) {
        return Err(blocked("approach to the goal", p));
    }
    if tail.windows(2).any(|w| !space.segment_free(w[0], w[1])) {
        return Err(NavError::Params(
            "the approach to the goal is blocked".into(),
        ));
    }
    Ok((from, tail[0]))
}

fn run_algorithm(
    space: &dyn FreeSpace,
    from: [f64; 2],
    to: [f64; 2],
    a: &Algorithm,
) -> Result<(Route, Option<Roadmap>), NavError> {
    Ok(match a {
        Algorithm::Prm(p) => {
            let (route, map) = plan_prm(space, from, to, p)?;
            (route, Some(map))
        }
        Algorithm::PrmFirstSolution(p) => {
            let (route, map) = crate::plan_prm_first(space, from, to, p)?;
            (route, Some(map))
        }
        Algorithm::Rrt(p) => (plan_rrt(space, from, to, p)?, None),
        Algorithm::RrtConnect(p) => (plan_rrt_connect(space, from, to, p)?, None),
        Algorithm::HybridAstar(_) => {
            return Err(NavError::Params(
                "hybrid-astar plans poses, not a point route".into(),
            ));
        }
    })
}

/// Start → lead-in → route → approach → lead-out → goal, shortcut (the lead legs and
/// approach kept), smoothed.
fn smooth_route(
    map: &NavMap,
    space: &dyn FreeSpace,
    q: &GlobalQuery,
    route: &[[f64; 2]],
) -> Result<Smoothed, SmoothError> {
    let mut pts = vec![[q.start.x_m, q.start.y_m]];
    pts.extend_from_slice(route);
    let (_, lead_out) = lead_points(&q.start, &q.goal, q.lead_m);
    pts.extend(q.approach.iter().skip(1).copied().chain([lead_out]));
    pts.push([q.goal.x_m, q.goal.y_m]);
    let n = pts.len();
    // The route ends at the first approach point (or the lead-out); what follows is fixed.
    let fixed_from = n - 2 - q.approach.len();
    let anchors: Vec<usize> = std::iter::once(1).chain(fixed_from..n - 1).collect();
    let short = shortcut(space, &pts, &anchors);
    let params = SmoothParams::for_curvature(q.truck.max_curvature_per_m());
    // Checked with the footprint grown by the margin; the clearance is the truck's own.
    let parts = (
        truck_parts(&q.truck, q.margin_m),
        truck_parts(&q.truck, 0.0),
    );
    smooth(&short, &map.obstacles, (&parts.0, &parts.1), &params)
}
