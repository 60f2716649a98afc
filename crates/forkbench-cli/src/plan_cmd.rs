//! `forkbench plan`: one path, printed as text or JSON, optionally plotted.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use forkbench_core::Settings;
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_plan::{PlanParams, PlanRequest};
use forkbench_trial::{ComponentSpec, Registry, Role};
use serde_json::json;

use forkbench_report::plans as plot;

/// `forkbench plan`, as parsed.
#[derive(Debug, clap::Args)]
pub struct PlanCli {
    /// Planner kind (bspline, spiral, external, or one a library user registered).
    pub planner: String,
    /// Start pose of the fork root: x_m,y_m,heading_deg
    #[arg(long, value_parser = crate::parse_pose, allow_hyphen_values = true)]
    pub start: Pose2,
    /// Goal pose (pallet pocket centre): x_m,y_m,heading_deg
    #[arg(long, value_parser = crate::parse_pose, allow_hyphen_values = true)]
    pub goal: Pose2,
    /// Path curvature at the start in m⁻¹ (from the current steering angle; spiral only).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_curvature)]
    pub start_curvature: f64,
    /// Forklift spec overrides (TOML with fields of ForkliftSpec).
    #[arg(long)]
    pub truck: Option<PathBuf>,
    /// Planner settings: a TOML file with the keys of a scenario's [planner] table
    /// (without `kind`); for hybrid-astar, the keys of `[mission.global.hybrid]`.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Spiral: search lengths outside the paper's window 1 + θ²/5 ≤ s_f ≤ 2 + θ²/5.
    #[arg(long)]
    pub no_length_window: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Draw path, curvature and steering to FILE (.svg or .png).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Global planners (prm, rrt, rrt-connect, hybrid-astar): the map, a world TOML or a
    /// ROS map_server YAML.
    #[arg(long)]
    pub map: Option<PathBuf>,
    /// PRM: samples drawn over the map (the paper's 500); with --first-solution, the
    /// most samples drawn before giving up (default 5000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub nodes: Option<u64>,
    /// PRM: grow the roadmap one sample at a time, each joined to its 10 nearest
    /// neighbours within --connect-m (OMPL's PRM strategy), and stop as soon as start
    /// and goal are connected: the time to a first solution.
    #[arg(long)]
    pub first_solution: bool,
    /// PRM: connection distance in metres, or `inf`.
    #[arg(long, default_value = "10", value_parser = crate::route_cmd::parse_connect)]
    pub connect_m: f64,
    /// Global planners: seed of the samples.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Global planners: plan this many times in one process (the map loaded once), with
    /// seeds --seed, --seed + 1, …; one report (one JSON line with --json) per plan.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs: u64,
    /// Global planners: cell size when the map is a world file.
    #[arg(long, default_value_t = 0.05)]
    pub resolution_m: f64,
    /// Global planners: obstacle inflation (default 0.5 × wheelbase, as the paper).
    #[arg(long)]
    pub inflate_m: Option<f64>,
    /// Global planners: `inflate` (the paper: obstacles grown by 0.5 × wheelbase; the
    /// default of prm, rrt and rrt-connect) or `footprint` (the chassis and forks swept
    /// along each edge; hybrid-astar's only model).
    #[arg(long)]
    pub collision: Option<forkbench_nav::CollisionModel>,
    /// Global planners: smooth the route into a drivable path (κ ≤ κ_max, clothoid
    /// corners) from the start heading to the goal heading, its swept footprint checked.
    #[arg(long)]
    pub smooth: bool,
    /// With --smooth: the straight lead-in after the start and lead-out before the goal
    /// that fix the headings.
    #[arg(long, default_value_t = 2.5)]
    pub lead_m: f64,
    /// With --smooth: the straight lead-out before the goal (default: --lead-m).
    #[arg(long)]
    pub approach_m: Option<f64>,
    /// Clearance kept around the footprint (default 0.15 m with `footprint`, 0 with
    /// `inflate`, as the paper).
    #[arg(long)]
    pub margin_m: Option<f64>,
    /// With --smooth: report a route that cannot be smoothed as failed, instead of
    /// planning a manoeuvre (forwards and backwards) with Hybrid-A*.
    #[arg(long)]
    pub no_fallback: bool,
}

impl PlanCli {
    /// Flags of point planners that cannot act on Hybrid-A*, refused by name.
    fn refuse_for_manoeuvres(&self) -> anyhow::Result<()> {
        let why =
            |flag: &str, reason: &str| anyhow::anyhow!("plan {}: {flag} {reason}", self.planner);
        if self.smooth {
            return Err(why(
                "--smooth",
                "is for point routes: hybrid-astar plans drivable manoeuvres",
            ));
        }
        if self.collision == Some(forkbench_nav::CollisionModel::Inflate) {
            return Err(why(
                "--collision inflate",
                "is for point planners: hybrid-astar checks the truck's footprint (--collision footprint)",
            ));
        }
        if self.nodes.is_some() || self.first_solution {
            return Err(why("--nodes/--first-solution", "are PRM settings"));
        }
        Ok(())
    }

    /// Hybrid-A*'s settings: `--config` (keys of `[mission.global.hybrid]`) for
    /// hybrid-astar, the defaults for the others' fallback; refused for a point planner.
    fn hybrid_params(
        &self,
        planner: forkbench_nav::GlobalPlannerKind,
    ) -> anyhow::Result<forkbench_nav::hybrid::HybridParams> {
        let Some(p) = &self.config else {
            return Ok(Default::default());
        };
        if !planner.kinodynamic() {
            anyhow::bail!(
                "plan {}: --config is for pick planners and hybrid-astar (its settings); {} has none",
                self.planner,
                self.planner
            );
        }
        let text = crate::read_input(p)?;
        let params: forkbench_nav::hybrid::HybridParams =
            toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))?;
        params
            .check()
            .map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))?;
        Ok(params)
    }

    /// A global planner's arguments, when `planner` is one.
    pub fn route(&self) -> anyhow::Result<Option<crate::route_cmd::RouteArgs>> {
        let kind = forkbench_nav::GlobalPlannerKind::from_name(&self.planner);
        if self.first_solution && kind != Some(forkbench_nav::GlobalPlannerKind::Prm) {
            anyhow::bail!("plan {}: --first-solution is for prm", self.planner);
        }
        let Some(planner) = kind else {
            return Ok(None);
        };
        if self.start_curvature != 0.0 {
            anyhow::bail!(
                "plan {}: --start-curvature is for pick planners (a global plan starts from rest)",
                self.planner
            );
        }
        if planner.kinodynamic() {
            self.refuse_for_manoeuvres()?;
        }
        let hybrid = self.hybrid_params(planner)?;
        let map = self.map.clone().ok_or_else(|| {
            anyhow::anyhow!(
                "plan {}: --map WORLD.toml|MAP.yaml is required",
                self.planner
            )
        })?;
        let collision = self.collision.unwrap_or(if planner.kinodynamic() {
            forkbench_nav::CollisionModel::Footprint
        } else {
            forkbench_nav::CollisionModel::Inflate
        });
        Ok(Some(crate::route_cmd::RouteArgs {
            planner,
            map,
            start: self.start,
            goal: self.goal,
            nodes: self
                .nodes
                .map(|n| usize::try_from(n).unwrap_or(usize::MAX))
                .unwrap_or(if self.first_solution { 5000 } else { 500 }),
            first_solution: self.first_solution,
            runs: self.runs as usize,
            connect_m: self.connect_m.is_finite().then_some(self.connect_m),
            seed: self.seed,
            resolution_m: self.resolution_m,
            inflate_m: self.inflate_m,
            collision,
            smooth: self.smooth,
            fallback: self.smooth && !self.no_fallback,
            hybrid,
            lead_m: self.lead_m,
            approach_m: self.approach_m,
            margin_m: self.margin_m.unwrap_or(collision.default_margin_m()),
            truck: crate::load_truck(self.truck.as_ref())?,
            json: self.json,
            plot: self.plot.clone(),
        }))
    }

    /// Reads the truck and settings files into the planning arguments.
    pub fn resolve(self) -> anyhow::Result<PlanArgs> {
        let truck = crate::load_truck(self.truck.as_ref())?;
        let mut settings = match &self.config {
            Some(p) => {
                let text = crate::read_input(p)?;
                toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))?
            }
            None => Settings::new(),
        };
        if self.no_length_window {
            settings.insert("enforce_length_window".into(), false.into());
        }
        Ok(PlanArgs {
            config_dir: self.config.as_deref().map(forkbench_plan::external::dir_of),
            planner: self.planner,
            settings,
            start: self.start,
            goal: self.goal,
            start_curvature_per_m: self.start_curvature,
            truck,
            json: self.json,
            plot: self.plot,
        })
    }
}

#[derive(Debug)]
pub struct PlanArgs {
    /// A registered planner kind.
    pub planner: String,
    /// Its settings (the keys of a scenario's [planner] table).
    pub settings: Settings,
    /// Where an external planner's command runs: the settings file's directory.
    pub config_dir: Option<PathBuf>,
    pub start: Pose2,
    pub goal: Pose2,
    pub start_curvature_per_m: f64,
    pub truck: ForkliftSpec,
    pub json: bool,
    pub plot: Option<PathBuf>,
}

pub fn run(a: PlanArgs) -> anyhow::Result<()> {
    let mut req = PlanRequest::new(a.start, a.goal);
    req.start_curvature_per_m = a.start_curvature_per_m;
    req.truck = a.truck.clone();
    let mut spec = ComponentSpec::of_kind(Role::Planner, &a.planner);
    spec.settings = a.settings.clone();
    spec.dir = a.config_dir.clone().unwrap_or_else(|| PathBuf::from("."));
    let mut planner = Registry::shared()
        .planner(&spec)
        .map_err(|e| anyhow::anyhow!("planner {:?}: {e}", a.planner))?;
    let t0 = Instant::now();
    let plan = planner.plan(&req)?;
    let solve_time_us = t0.elapsed().as_secs_f64() * 1e6;
    let m = plan.path.metrics(&a.start, &a.goal, &a.truck);
    if let Some(file) = &a.plot {
        let polygon = plan.control_polygon_m.clone();
        let title = format!("{} plan", a.planner);
        plot::draw_plans(
            file,
            &title,
            &[plot::Series {
                label: a.planner.to_string(),
                path: &plan.path,
                control_polygon: polygon,
            }],
            &a.truck,
        )?;
    }
    let text = if a.json {
        json_report(&a, &plan, &m, solve_time_us)
    } else {
        text_report(&a, &plan, &m, solve_time_us)
    };
    crate::emit(&text)
}

/// `--json`: the plan, its metrics and the samples as one object.
fn json_report(
    a: &PlanArgs,
    plan: &forkbench_plan::Plan,
    m: &forkbench_core::PathMetrics,
    solve_time_us: f64,
) -> String {
    let pose = |p: &Pose2| json!({"x_m": p.x_m, "y_m": p.y_m, "heading_rad": p.heading_rad});
    let out = json!({
        "planner": a.planner,
        "start": pose(&a.start),
        "goal": pose(&a.goal),
        "start_curvature_per_m": a.start_curvature_per_m,
        "params": plan.params,
        "cost": plan.cost,
        "max_curvature_per_m": m.max_abs_curvature_per_m,
        "max_steer_rad": m.max_steer_rad,
        "length_m": m.length_m,
        "endpoint_error_m": m.endpoint_position_error_m,
        "endpoint_heading_error_rad": m.endpoint_heading_error_rad,
        "max_curvature_jump_per_m": m.max_curvature_jump_per_m,
        "solve_time_us": solve_time_us,
        "samples": plan.path.samples,
    });
    format!("{out}\n")
}

/// The plan and its metrics as aligned text lines.
fn text_report(
    a: &PlanArgs,
    plan: &forkbench_plan::Plan,
    m: &forkbench_core::PathMetrics,
    solve_time_us: f64,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "planner              {}", a.planner);
    match &plan.params {
        PlanParams::Bspline { l1_m, l2_m, .. } => {
            let _ = writeln!(s, "handles L1, L2       {l1_m:.4} m, {l2_m:.4} m");
        }
        PlanParams::Spiral(p) => {
            let _ = writeln!(
                s,
                "spiral (normalised)  a={:.5} b={:.5} c={:.5} d={:.5} e={:.5} s_f={:.5}",
                p.a, p.b, p.c, p.d, p.e, p.sf
            );
            let _ = writeln!(s, "scale R, mirrored    {:.4} m, {}", p.scale_m, p.mirrored);
            let _ = writeln!(s, "cost ∫½κ² (norm.)    {:.6}", plan.cost);
        }
        PlanParams::Other(info) => {
            let _ = writeln!(s, "planner info         {info}");
            let _ = writeln!(s, "cost                 {:.6}", plan.cost);
        }
    }
    let _ = writeln!(s, "length               {:.4} m", m.length_m);
    let _ = writeln!(
        s,
        "max |κ|              {:.6} m⁻¹ (κ_max {:.4})",
        m.max_abs_curvature_per_m,
        a.truck.max_curvature_per_m()
    );
    let _ = writeln!(
        s,
        "max steering         {:.4} rad ({:.2}°; α_max {:.4} rad)",
        m.max_steer_rad,
        m.max_steer_rad.to_degrees(),
        a.truck.max_steer_rad
    );
    let _ = writeln!(
        s,
        "endpoint error       {:.3e} m, {:.3e} rad",
        m.endpoint_position_error_m, m.endpoint_heading_error_rad
    );
    let _ = writeln!(
        s,
        "samples              {} (≤ {:.3} m apart)",
        plan.path.samples.len(),
        m.max_sample_spacing_m
    );
    let _ = writeln!(s, "solve time           {solve_time_us:.0} µs");
    if let Some(file) = &a.plot {
        let _ = writeln!(s, "plot                 {}", file.display());
    }
    s
}

/// `--start-curvature`: a finite curvature a truck can steer to (at most 10 /m).
fn parse_curvature(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && v.abs() <= 10.0 => Ok(v),
        _ => Err(format!("{text:?}: expected a curvature in 1/m within ±10")),
    }
}
