//! `forkbench scan`: one scan of a scenario's world from the truck, the detector's estimate beside the truth, as text, JSON or a plot.

use std::path::PathBuf;

use forkbench_core::Pose2;
use forkbench_trial::trial::{ScanReport, scan_once};
use serde_json::json;

#[derive(Debug, clap::Args)]
pub struct ScanArgs {
    /// Scenario file.
    scenario: PathBuf,
    /// Case by name (required when the scenario has several).
    #[arg(long)]
    case: Option<String>,
    /// Fork-root pose to scan from, `x,y,heading_deg` (default: the case's start).
    #[arg(long, value_parser = crate::parse_pose, allow_hyphen_values = true)]
    at: Option<Pose2>,
    /// Scanner model (the scenario's own settings for it when it has that scanner).
    #[arg(long, default_value = "tim561")]
    sensor: String,
    /// Seed of the pallet's jitter and the scanner's noise and bias.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Ideal rays: no noise, no bias, no beam divergence.
    #[arg(long)]
    no_noise: bool,
    #[arg(long)]
    json: bool,
    /// Draw the scan, the pallet and the estimate to FILE (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub fn run(a: &ScanArgs) -> anyhow::Result<()> {
    let scn = forkbench_trial::defaults::load_scenario(&a.scenario)?;
    let cfg = scn
        .pallet_sensing
        .scanner_or_preset(&a.sensor)
        .map_err(|e| anyhow::anyhow!("--sensor {e}"))?;
    let case = scn.pick_case(a.case.as_deref())?;
    if let Some(at) = &a.at {
        check_at(at, &scn, case)?;
    }
    let report = scan_once(&scn, case, (&a.sensor, &cfg), a.at, a.seed, a.no_noise)?;
    if let Some(file) = &a.plot {
        forkbench_report::scan::draw_scan(file, &report, &scn.pallet)?;
    }
    if a.json {
        return crate::emit(&format!("{}\n", to_json(&report)));
    }
    crate::emit(&text(&report))
}

/// `--at` within the world's extent and with the truck outside the pallet.
fn check_at(
    at: &Pose2,
    scn: &forkbench_trial::Scenario,
    case: &forkbench_trial::scenario::Case,
) -> anyhow::Result<()> {
    let lim = forkbench_trial::scenario::MAX_WORLD_EXTENT_M;
    if !(at.x_m.abs() <= lim && at.y_m.abs() <= lim && at.heading_rad.is_finite()) {
        anyhow::bail!("--at ({}, {}) m: must lie within ±{lim} m", at.x_m, at.y_m);
    }
    let fp = forkbench_trial::scenario::pallet_footprint(&scn.pallet);
    let mut pallet = forkbench_geom::Obstacles::new();
    pallet.add_rect(&fp.centre(&case.pallet), fp.length_m, fp.width_m);
    if forkbench_nav::truck_parts(&scn.truck, 0.0)
        .iter()
        .any(|part| pallet.collides(part, at))
    {
        anyhow::bail!(
            "--at ({:.2}, {:.2}) m: the truck would stand in the pallet; scan from outside it",
            at.x_m,
            at.y_m
        );
    }
    Ok(())
}

fn pose_json(p: &Pose2) -> serde_json::Value {
    json!({"x_m": p.x_m, "y_m": p.y_m, "heading_rad": p.heading_rad})
}

fn to_json(r: &ScanReport) -> serde_json::Value {
    let s = &r.scan;
    let beams: Vec<_> = s
        .ranges_m
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let range = v.is_finite().then_some(*v);
            json!({"angle_rad": s.angle_min_rad + i as f64 * s.angle_step_rad, "range_m": range})
        })
        .collect();
    let detection = r
        .estimate
        .map(|d| json!({"stringers": d.stringers, "points": d.points, "rms_m": d.rms_m}));
    json!({
        "sensor": r.sensor,
        "detector": r.detector,
        "sensor_pose": pose_json(&s.sensor),
        "fork_root": pose_json(&r.fork_root),
        "beams": beams,
        "truth": pose_json(&r.truth),
        "estimate": r.estimate.map(|d| pose_json(&d.face)),
        "detection": detection,
    })
}

fn text(r: &ScanReport) -> String {
    let s = &r.scan;
    let returns = s.ranges_m.iter().filter(|v| v.is_finite()).count();
    let deg = |p: &Pose2| {
        format!(
            "({:.3}, {:.3}) m, {:.2}°",
            p.x_m,
            p.y_m,
            p.heading_rad.to_degrees()
        )
    };
    let mut out = format!(
        "{} from {}: {} beams, {} returns (detector {})\npallet face (truth) {}\n",
        r.sensor,
        deg(&s.sensor),
        s.ranges_m.len(),
        returns,
        forkbench_trial::text::one_line(&r.detector),
        deg(&r.truth)
    );
    match &r.estimate {
        Some(d) => {
            let e = r.truth.to_local(&d.face);
            out += &format!(
                "estimate            {}  ({} stringers, {} points, RMS {:.1} mm)\n\
                 error in the pallet frame: along {:+.3} m, lateral {:+.3} m, heading {:+.2}°\n",
                deg(&d.face),
                d.stringers,
                d.points,
                1e3 * d.rms_m,
                e.x_m,
                e.y_m,
                forkbench_core::units::wrap_angle(e.heading_rad).to_degrees()
            );
        }
        None => out += "estimate            not found\n",
    }
    out
}
