//! `forkbench corridor` and `reproduce corridor`: minimum widths and G regions per turning mode.

use std::fmt::Write as _;
use std::path::{Path as FsPath, PathBuf};

use forkbench_corridor::{CorridorQuery, CorridorRun, Junction, Vehicle, analyse, check_regions};

pub use forkbench_corridor::amv;

/// Parses "0.56x0.40" (metres).
pub fn parse_vehicle(text: &str) -> Result<Vehicle, String> {
    let (l, w) = text.split_once(['x', 'X']).ok_or_else(|| {
        format!("--vehicle {text:?}: expected LENGTHxWIDTH in metres, e.g. 0.56x0.40")
    })?;
    let num = |s: &str, what: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|e| format!("--vehicle {text:?}: {what} {s:?}: {e}"))
    };
    Ok(Vehicle {
        length_m: num(l, "length")?,
        width_m: num(w, "width")?,
        kinematic_ahead_m: 0.0,
        min_radius_m: 0.0,
    })
}

/// `l` or `t` (either case).
pub fn parse_junction(text: &str) -> Result<Junction, String> {
    match text {
        "l" | "L" => Ok(Junction::L),
        "t" | "T" => Ok(Junction::T),
        _ => Err(format!(
            "--junction {text:?}: expected l (a bend) or t (a T junction)"
        )),
    }
}

/// Bend angles in degrees from `--sweep-angles` (a newtype: clap would read a bare
/// `Vec<f64>` as a list of separate values).
#[derive(Debug, Clone, PartialEq)]
pub struct Angles(pub Vec<f64>);

/// Parses "A:B:STEP" in degrees.
pub fn parse_sweep(text: &str) -> Result<Angles, String> {
    let parts: Vec<&str> = text.split(':').collect();
    let nums: Result<Vec<f64>, _> = parts.iter().map(|p| p.trim().parse::<f64>()).collect();
    match nums.as_deref() {
        Ok([a, b, step]) if *step > 0.0 && b >= a => {
            let n = ((b - a) / step + 1e-9).floor() as usize;
            Ok(Angles((0..=n).map(|i| a + i as f64 * step).collect()))
        }
        _ => Err(format!(
            "--sweep-angles {text:?}: expected A:B:STEP in degrees with STEP > 0 and B ≥ A"
        )),
    }
}

/// `forkbench corridor`, as parsed.
#[derive(Debug, clap::Args)]
pub struct CorridorCli {
    /// Vehicle LENGTHxWIDTH in metres (default: the paper's AMV 0.56x0.40).
    #[arg(long, value_parser = parse_vehicle, conflicts_with = "truck")]
    pub vehicle: Option<forkbench_corridor::Vehicle>,
    /// The forklift body (--truck-spec or the A30 defaults), adds the `truck` mode.
    #[arg(long)]
    pub truck: bool,
    /// Forklift spec TOML for --truck.
    #[arg(long, requires = "truck")]
    pub truck_spec: Option<PathBuf>,
    /// Corridor width (m): also compute the G regions and compare with circle inflation.
    #[arg(long, allow_negative_numbers = true)]
    pub width: Option<f64>,
    /// Junction: `l` (a bend of --angle) or `t` (from the stem of a T into its right
    /// arm, 90°).
    #[arg(long, value_parser = parse_junction, default_value = "l")]
    pub junction: forkbench_corridor::Junction,
    /// Bend angle (degrees).
    #[arg(long, conflicts_with = "sweep_angles", allow_negative_numbers = true)]
    pub angle: Option<f64>,
    /// Bend angles A:B:STEP (degrees).
    #[arg(long, value_parser = parse_sweep)]
    pub sweep_angles: Option<Angles>,
    /// Grid cell (m); default Wc/40 (1 cm for the AMV, 3 cm for the A30).
    #[arg(long, allow_negative_numbers = true)]
    pub resolution: Option<f64>,
    /// W_min vs θ, or with --width and one angle the G regions (.svg or .png).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

impl CorridorCli {
    /// The run these arguments ask for (the truck spec read, defaults filled in).
    pub fn resolve(&self) -> anyhow::Result<Args<'_>> {
        let v = if self.truck {
            Vehicle::forklift(&crate::load_truck(self.truck_spec.as_ref())?)
        } else {
            self.vehicle.unwrap_or_else(amv)
        };
        let angles_deg = self
            .sweep_angles
            .clone()
            .map_or_else(|| vec![self.angle.unwrap_or(90.0)], |a| a.0);
        Ok(Args {
            vehicle: v,
            junction: self.junction,
            width_m: self.width,
            angles_deg,
            cell_m: self.resolution.unwrap_or(v.width_m / 40.0),
            plot: self.plot.as_deref(),
            json: self.json,
        })
    }
}

/// Options of one `corridor` run.
#[derive(Debug)]
pub struct Args<'a> {
    pub vehicle: Vehicle,
    pub junction: Junction,
    pub width_m: Option<f64>,
    pub angles_deg: Vec<f64>,
    pub cell_m: f64,
    pub plot: Option<&'a FsPath>,
    pub json: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let CorridorRun { rows, regions } = analyse(&CorridorQuery {
        vehicle: a.vehicle,
        junction: a.junction,
        width_m: a.width_m,
        angles_deg: a.angles_deg.clone(),
        cell_m: a.cell_m,
    })?;
    if let Some(p) = a.plot {
        let one = a.width_m.is_some() && a.angles_deg.len() == 1;
        forkbench_report::corridor::draw_corridor(
            p,
            &a.vehicle,
            &rows,
            one.then_some(regions.as_slice()),
        )?;
    }
    if a.json {
        let doc = serde_json::json!({
            "vehicle": {"length_m": a.vehicle.length_m, "width_m": a.vehicle.width_m},
            "junction": a.junction.name(),
            "resolution_m": a.cell_m,
            "rows": rows,
        });
        crate::emit(&format!("{}\n", serde_json::to_string_pretty(&doc)?))?;
        return Ok(());
    }
    let v = &a.vehicle;
    let mut out = format!(
        "vehicle {:.3} × {:.3} m (Li {:.3} m, L0 {:.3} m), {} junction, resolution {:.3} m / 1°\n\n",
        v.length_m,
        v.width_m,
        v.inscribed_m(),
        v.circumscribed_m(),
        a.junction.name(),
        a.cell_m
    );
    out.push_str("| angle (°) | mode | W_min (m) | oblique closed form (m) | G area (m²) |\n|---|---|---|---|---|\n");
    for r in &rows {
        let _ = writeln!(
            out,
            "| {:.2} | {} | {} | {} | {} |",
            r.angle_deg,
            r.mode.name(),
            r.min_width_m
                .map_or("no passage".into(), |w| format!("{w:.4}")),
            r.closed_form_m.map_or(String::new(), |w| format!("{w:.4}")),
            r.g_area_m2.map_or(String::new(), |g| format!("{g:.4}")),
        );
    }
    if !regions.is_empty() {
        out.push_str("\nAgainst circle inflation (areas in m², within the searched legs):\n\n| angle (°) | mode | G | inscribed claims | inscribed wrong | circumscribed claims | circumscribed wrongly blocks | G passages swept clean (parry2d, 1 mm / 0.1°) | inscribed-wrong positions colliding at every heading | …confirmed (colliding, or outside G at half the cell) | …of those beyond G's edge (1 cell, truck 2), confirmed |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (deg, c, val) in check_regions(&regions) {
            let _ = writeln!(
                out,
                "| {deg:.2} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {}/{} | {}/{} | {}/{} | {}/{} |",
                c.mode.name(),
                c.g_area_m2,
                c.inscribed_area_m2,
                c.inscribed_wrong_m2,
                c.circumscribed_area_m2,
                c.circumscribed_wrong_m2,
                val.g_passed,
                val.g_sampled,
                val.inscribed_wrong_colliding,
                val.inscribed_wrong_sampled,
                val.inscribed_wrong_confirmed,
                val.inscribed_wrong_sampled,
                val.inscribed_wrong_beyond_edge_confirmed,
                val.inscribed_wrong_beyond_edge,
            );
        }
    }
    crate::emit(&out)
}

/// `reproduce corridor`: the library's sections (the paper's AMV, then the A30 truck).
pub fn reproduce(json: bool, plot: Option<&FsPath>) -> anyhow::Result<()> {
    let worst = forkbench_corridor::reproduce::worst_oblique_angle_deg(&amv());
    if !json {
        crate::emit(&format!(
            "# Quan & Wang 2021, corridor bends\n\nThe paper's equations 1–3 and Table 1 are not in its text; oblique translation has a closed form (Lc·sin θ + Wc·cos θ), the rest is searched. Worst angle for oblique translation: arctan(Lc/Wc) = {worst:.2}°.\n"
        ))?;
    }
    // JSON and the plot cover the first section (the paper's AMV); text shows them all.
    for (i, (title, q)) in forkbench_corridor::reproduce::reproduction()
        .into_iter()
        .enumerate()
    {
        if json && i > 0 {
            break;
        }
        if !json {
            crate::emit(&format!("\n## {title}\n\n"))?;
        }
        run(&Args {
            vehicle: q.vehicle,
            junction: q.junction,
            width_m: q.width_m,
            angles_deg: q.angles_deg,
            cell_m: q.cell_m,
            plot: if i == 0 { plot } else { None },
            json,
        })?;
    }
    Ok(())
}
