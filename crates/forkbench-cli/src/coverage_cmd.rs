//! `forkbench coverage WORLD`: where a NAV350 sees enough reflectors for a fix and how good the fix is, as a summary, JSON or a heatmap.

use std::path::PathBuf;

use forkbench_sensors::reflectors::ReflectorNavConfig;
use forkbench_studies::coverage::{Coverage, coverage};

#[derive(Debug, clap::Args)]
pub struct CoverageArgs {
    /// World file (racks, walls and [[reflector]] entries).
    world: PathBuf,
    /// Cell size.
    #[arg(long, default_value_t = 0.25)]
    resolution_m: f64,
    /// Reflectors (comma-separated names) to leave out: what the layout covers if they go.
    #[arg(long, value_delimiter = ',')]
    missing_reflectors: Vec<String>,
    #[arg(long)]
    json: bool,
    /// Draw the heatmap with racks, walls and reflectors to FILE (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub fn run(a: &CoverageArgs) -> anyhow::Result<()> {
    let full = forkbench_trial::World::load(&a.world)?;
    let world = full.without_reflectors(&a.missing_reflectors)?;
    let missing: Vec<[f64; 2]> = full
        .reflector
        .iter()
        .filter(|r| a.missing_reflectors.contains(&r.name))
        .map(|r| [r.x_m, r.y_m])
        .collect();
    let cfg = ReflectorNavConfig::default();
    let t0 = std::time::Instant::now();
    let cov = coverage(&world, a.resolution_m, &cfg)?;
    let elapsed_s = t0.elapsed().as_secs_f64();
    if let Some(file) = &a.plot {
        forkbench_report::coverage::draw_coverage(file, &world, &cov, &missing)?;
    }
    if a.json {
        // Streamed, not built as a JSON tree: a map of millions of cells would hold
        // gigabytes as one.
        #[derive(serde::Serialize)]
        struct Out<'a> {
            world: &'a str,
            resolution_m: f64,
            reflectors: &'a [forkbench_sensors::reflectors::Reflector],
            cells: &'a [forkbench_studies::coverage::CoverageCell],
        }
        let out = Out {
            world: &world.name,
            resolution_m: cov.resolution_m,
            reflectors: &world.reflector,
            cells: &cov.cells,
        };
        return crate::emit_json_line(&out);
    }
    // A world's name is the user's text: no control characters reach a terminal or SVG.
    crate::emit(&summary(
        &forkbench_trial::text::one_line(&world.name),
        &cov,
        elapsed_s,
    ))
}

fn summary(name: &str, cov: &Coverage, elapsed_s: f64) -> String {
    let n = cov.cells.len();
    let mut sigmas: Vec<f64> = cov.cells.iter().filter_map(|c| c.sigma_m).collect();
    sigmas.sort_by(f64::total_cmp);
    let q = |p: f64| forkbench_core::quantile::percentile_sorted(&sigmas, p);
    let mm = |v: Option<f64>| v.map_or("—".to_owned(), |v| format!("{:.1} mm", 1e3 * v));
    format!(
        "{name}: {n} free cells at {} m; {} ({:.1} %) see at least 3 reflectors\n\
         predicted fix 1σ: median {}, 95th percentile {}, worst {}\n\
         {:.2} s\n",
        cov.resolution_m,
        sigmas.len(),
        100.0 * sigmas.len() as f64 / n.max(1) as f64,
        mm(q(0.5)),
        mm(q(0.95)),
        mm(sigmas.last().copied()),
        elapsed_s
    )
}
