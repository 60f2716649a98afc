//! `forkbench reproduce`: a paper's Table 2 beside this project's results, as markdown or JSON.

use std::fmt::Write as _;
use std::path::Path as FsPath;

use forkbench_core::ForkliftSpec;
use forkbench_plan::reproduce::{BsplineTable, SpiralTable, reproduce_bspline, reproduce_spiral};
use forkbench_plan::{BsplineConfig, Plan, SpiralConfig};
use serde_json::json;

use forkbench_report::plans as plot;

fn median(v: Vec<f64>) -> f64 {
    forkbench_core::quantile::quantile(v, 0.5).unwrap_or(f64::NAN)
}

pub fn run(
    bspline: bool,
    table: Option<&FsPath>,
    json: bool,
    plot_file: Option<&FsPath>,
) -> anyhow::Result<()> {
    let truck = ForkliftSpec::default();
    let read = |p: &FsPath| crate::read_input(p);
    let planner = if bspline { "bspline" } else { "spiral" };
    let (text, plans) = match bspline {
        true => {
            let t = match table {
                Some(p) => BsplineTable::parse(&read(p)?, &p.display().to_string())?,
                None => BsplineTable::embedded(),
            };
            let rows = reproduce_bspline(&t, &BsplineConfig::default(), &truck)?;
            let text = if json {
                bspline_json(&t, &rows)
            } else {
                bspline_markdown(&t, &rows)
            };
            (
                text,
                rows.into_iter()
                    .map(|(r, p)| (r.name, p))
                    .collect::<Vec<_>>(),
            )
        }
        false => {
            let t = match table {
                Some(p) => SpiralTable::parse(&read(p)?, &p.display().to_string())?,
                None => SpiralTable::embedded(),
            };
            let rows = reproduce_spiral(&t, &SpiralConfig::default(), &truck)?;
            let text = if json {
                spiral_json(&t, &rows)
            } else {
                spiral_markdown(&t, &rows)
            };
            (
                text,
                rows.into_iter()
                    .map(|(r, p)| (r.name, p))
                    .collect::<Vec<_>>(),
            )
        }
    };
    if let Some(file) = plot_file {
        let series: Vec<plot::Series> = plans
            .iter()
            .map(|(name, p): &(String, Plan)| plot::Series {
                label: format!("#{name}"),
                path: &p.path,
                control_polygon: p.control_polygon_m.clone().filter(|_| plans.len() == 1),
            })
            .collect();
        plot::draw_plans(
            file,
            &format!("{planner}: reproduction of Table 2"),
            &series,
            &truck,
        )?;
    }
    let mut text = text;
    if let (Some(file), false) = (plot_file, json) {
        let _ = writeln!(text, "\nplot: {}", file.display());
    }
    crate::emit(&text)
}

fn bspline_json(
    t: &BsplineTable,
    rows: &[(forkbench_plan::reproduce::BsplineRow, Plan)],
) -> String {
    let r: Vec<_> = rows.iter().map(|(r, _)| r).collect();
    let out = json!({
        "planner": "bspline",
        "paper": t.paper,
        "median_solve_time_us": median(r.iter().map(|r| r.solve_time_us).collect()),
        "rows": r,
    });
    format!("{out}\n")
}

fn bspline_markdown(
    t: &BsplineTable,
    rows: &[(forkbench_plan::reproduce::BsplineRow, Plan)],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {}\n", t.paper);
    let _ = writeln!(
        s,
        "Paper's max |κ| is its (L1, L2) measured with this project's code; Δ = ours − paper.\n"
    );
    let _ = writeln!(
        s,
        "| # | D (mm) | θ (°) | paper L1 (mm) | paper L2 (mm) | paper max κ (1/m) | L1 (mm) | L2 (mm) | max κ (1/m) | Δ max κ | max steer (rad) | endpoint err (m) | solve (µs) |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (r, _) in rows {
        let _ = writeln!(
            s,
            "| {} | {:.0} | {:.0} | {:.1} | {:.1} | {:.6} | {:.1} | {:.1} | {:.6} | {:+.2} % | {:.4} | {:.1e} | {:.0} |",
            r.name,
            r.lateral_offset_m * 1000.0,
            r.pallet_angle_deg,
            r.paper_l1_m * 1000.0,
            r.paper_l2_m * 1000.0,
            r.paper_max_curvature_per_m,
            r.l1_m * 1000.0,
            r.l2_m * 1000.0,
            r.max_curvature_per_m,
            100.0 * (r.max_curvature_per_m / r.paper_max_curvature_per_m - 1.0),
            r.max_steer_rad,
            r.endpoint_error_m,
            r.solve_time_us
        );
    }
    let _ = writeln!(s, "\nFigures the paper printed:\n");
    for (r, _) in rows {
        if let (Some(steer), Some(k)) = (r.reported_max_steer_rad, r.reported_max_curvature_per_m) {
            let _ = writeln!(
                s,
                "- scenario {}: paper max steering {:.4} rad, max |κ| {:.4e} mm⁻¹; ours {:.4} rad, {:.4e} mm⁻¹",
                r.name,
                steer.abs(),
                k / 1000.0,
                r.max_steer_rad,
                r.max_curvature_per_m / 1000.0
            );
        }
    }
    let _ = writeln!(
        s,
        "\nmedian solve time {:.0} µs over {} scenarios (this run, wall clock; see the criterion bench)",
        median(rows.iter().map(|(r, _)| r.solve_time_us).collect()),
        rows.len()
    );
    s
}

fn spiral_json(t: &SpiralTable, rows: &[(forkbench_plan::reproduce::SpiralRow, Plan)]) -> String {
    let r: Vec<_> = rows.iter().map(|(r, _)| r).collect();
    let out = json!({
        "planner": "spiral",
        "paper": t.paper,
        "median_solve_time_us": median(r.iter().map(|r| r.solve_time_us).collect()),
        "rows": r,
    });
    format!("{out}\n")
}

fn spiral_markdown(
    t: &SpiralTable,
    rows: &[(forkbench_plan::reproduce::SpiralRow, Plan)],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {}\n", t.paper);
    let _ = writeln!(
        s,
        "Cost J = normalised ∫½κ² ds. The paper's J and endpoint error are its (b, c, s_f) evaluated with this project's integration.\n"
    );
    let _ = writeln!(
        s,
        "| # | K0 (1/m) | Y_f (m) | Θ_f (°) | paper b | paper c | paper s_f | paper J | paper endpoint err (cm) | b | c | s_f | s_f window | J | ΔJ | endpoint err (m) | max κ (1/m) | max steer (rad) | solve (µs) |"
    );
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for (r, _) in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.0} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.4} | {:.4} | {:.4} | {:.4}–{:.4}{} | {:.4} | {:+.1} % | {:.1e} | {:.4} | {:.4} | {:.0} |",
            r.name,
            r.start_curvature_per_m,
            r.goal_lateral_m,
            r.goal_heading_rad.to_degrees(),
            r.paper_b,
            r.paper_c,
            r.paper_sf,
            r.paper_cost,
            r.paper_endpoint_error_m * 100.0,
            r.b,
            r.c,
            r.sf,
            r.window_lo,
            r.window_hi,
            r.sf_at_bound.map(|b| format!(" ({b})")).unwrap_or_default(),
            r.cost,
            100.0 * (r.cost / r.paper_cost - 1.0),
            r.endpoint_error_m,
            r.max_curvature_per_m,
            r.max_steer_rad,
            r.solve_time_us
        );
    }
    let _ = writeln!(s);
    s.push_str(&window_bounds(rows));
    s.push_str(&paper_comparison(rows));
    let _ = writeln!(
        s,
        "\nmedian solve time {:.0} µs over {} scenarios (this run, wall clock; see the criterion bench)",
        median(rows.iter().map(|(r, _)| r.solve_time_us).collect()),
        rows.len()
    );
    s
}

/// Which rows' optimum sits at a bound of the length window, and how many inside it.
fn window_bounds(rows: &[(forkbench_plan::reproduce::SpiralRow, Plan)]) -> String {
    let mut s = String::new();
    for bound in ["short end", "long end"] {
        let at: Vec<&str> = rows
            .iter()
            .filter(|(r, _)| r.sf_at_bound == Some(bound))
            .map(|(r, _)| r.name.as_str())
            .collect();
        let _ = writeln!(
            s,
            "The optimum sits at the window's {bound} on rows: {}.",
            if at.is_empty() {
                "none".to_string()
            } else {
                at.join(", ")
            }
        );
    }
    let interior = rows.iter().filter(|(r, _)| r.sf_at_bound.is_none()).count();
    let _ = writeln!(s, "It lies inside the window on {interior} rows.\n");
    s
}

/// Rows where our cost is above the paper's (and why), and the paper's reported endpoint errors.
fn paper_comparison(rows: &[(forkbench_plan::reproduce::SpiralRow, Plan)]) -> String {
    let mut s = String::new();
    let higher: Vec<_> = rows.iter().filter(|(r, _)| r.cost > r.paper_cost).collect();
    if higher.is_empty() {
        let _ = writeln!(s, "Our cost is at or below the paper's on every row.");
    } else {
        let _ = writeln!(
            s,
            "Rows where our cost is higher than the paper's: the paper's (b, c, s_f) does not reach the goal, so its cost belongs to a different, easier endpoint:\n"
        );
        for (r, _) in higher {
            let _ = writeln!(
                s,
                "- #{}: J {:.4} vs paper {:.4} (+{:.2} %); the paper's path ends {:.2} cm from the goal, ours {:.1e} m",
                r.name,
                r.cost,
                r.paper_cost,
                100.0 * (r.cost / r.paper_cost - 1.0),
                r.paper_endpoint_error_m * 100.0,
                r.endpoint_error_m
            );
        }
    }
    for (r, _) in rows {
        if let Some(e) = r.reported_endpoint_error_m {
            let _ = writeln!(
                s,
                "- #{}: paper reports endpoint error {:.2} cm; its (b, c, s_f) measured here: {:.2} cm",
                r.name,
                e * 100.0,
                r.paper_endpoint_error_m * 100.0
            );
        }
    }
    s
}
