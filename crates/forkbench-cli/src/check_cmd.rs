//! `forkbench check SCENARIO`: loads a scenario as a run would, and prints what it resolved to and how the forks fit the pallet (JSON: the whole resolved scenario).

use std::path::PathBuf;

use anyhow::Context as _;
use forkbench_trial::Scenario;
use forkbench_trial::text::one_line;

#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    scenario: PathBuf,
    /// The whole resolved scenario (SI units) and the fork fit, as one JSON object.
    #[arg(long)]
    json: bool,
}

pub fn run(a: &CheckArgs) -> anyhow::Result<()> {
    let scn = forkbench_trial::defaults::load_scenario(&a.scenario)?;
    crate::warn_slips(&scn);
    let fit = scn.fork_fit();
    if a.json {
        let v = serde_json::json!({
            "scenario": scn,
            "pallet_kind": scn.pallet_kind,
            "fork_fit": fit,
            "truck": whole_truck(&scn.truck),
        });
        let text = serde_json::to_string_pretty(&v).context("serialising the scenario")?;
        return crate::emit(&(text + "\n"));
    }
    crate::emit(&summary(&scn))
}

/// The pallet sensing in one line: scanners, detector, latency and threshold.
fn sensing_line(scn: &Scenario) -> String {
    match &scn.pallet_sensing {
        forkbench_trial::scenario::sensors::PalletSensing::Gaussian => {
            forkbench_trial::scenario::sensors::GAUSSIAN_SENSING.to_owned()
        }
        forkbench_trial::scenario::sensors::PalletSensing::Scanner {
            sensors,
            detector,
            latency_s,
            min_score,
        } => {
            let names: Vec<&str> = sensors.iter().map(|s| s.name.as_str()).collect();
            format!(
                "{} with detector {} ({latency_s} s late, faces taken at evidence ≥ {min_score})",
                names.join(" + "),
                detector.kind
            )
        }
    }
}

fn summary(scn: &Scenario) -> String {
    let fit = scn.fork_fit();
    let w = &scn.world;
    let sensing = sensing_line(scn);
    let yes = |ok: bool| if ok { "ok" } else { "REFUSED" };
    let mut lines = vec![
        format!("scenario     {} ({})", one_line(&scn.name), scn.file),
        format!(
            "world        {}: {} walls, {} racks, {} clutter items, {} slots, {} stations, {} reflectors",
            one_line(&w.name),
            w.wall.len(),
            w.rack.len(),
            w.clutter.len(),
            w.pallet_slot.len(),
            w.station.len(),
            w.reflector.len()
        ),
        format!(
            "components   planner {} ({}), tracker {} ({}), localiser {}, pallet sensing {sensing}",
            scn.planner.name,
            scn.planner.kind,
            scn.tracker.name,
            scn.tracker.kind,
            scn.localizer.kind
        ),
        pallet_line(scn),
        format!(
            "forks        spacing {:.3} m, pockets allow {:.3}..{:.3} m: {}",
            fit.fork_spacing_m,
            fit.spacing_range_m[0],
            fit.spacing_range_m[1],
            yes(fit.spacing_ok())
        ),
        format!(
            "depth        insertion {:.3} m required, {:.3} m aimed for; forks {:.3} m, pallet {:.3} m deep: {}",
            fit.insertion_depth_m,
            fit.insertion_target_m,
            fit.fork_length_m,
            fit.pallet_depth_m,
            yes(fit.depth_ok() && fit.target_ok())
        ),
        format!(
            "limits       lateral {} m, heading {:.2}°, contact {} N, pallet moved {} m",
            scn.tolerances.lateral_m,
            scn.tolerances.heading_deg(),
            scn.tolerances.contact_force_n,
            scn.tolerances.pallet_displacement_m
        ),
        truck_line(&scn.truck),
        steering_line(&scn.truck),
        drive_line(&scn.truck),
        format!("seed         {}; timeout {} s", scn.seed, scn.timeout_s),
    ];
    if let Some(m) = &scn.mission {
        let via: Vec<&str> = m.via.iter().map(|v| v.name.as_str()).collect();
        lines.push(format!(
            "mission      {} → {} → the pick",
            m.start.name,
            if via.is_empty() {
                "–".to_owned()
            } else {
                via.join(" → ")
            }
        ));
    }
    lines.extend(uncertain(scn));
    lines.extend(cases(scn));
    lines.join("\n") + "\n"
}

/// Each uncertain parameter: its distribution and the range a trial or a search reaches.
fn uncertain(scn: &Scenario) -> Vec<String> {
    use forkbench_trial::scenario::uncertain::Z_LIMIT;
    scn.uncertain
        .0
        .iter()
        .map(|u| {
            format!(
                "uncertain    {}: {}, reaching {:.4} to {:.4}",
                u.name,
                u.dist,
                u.dist.at(-Z_LIMIT),
                u.dist.at(Z_LIMIT)
            )
        })
        .collect()
}

/// The steering actuator as it will act (docs/truck.md).
fn steering_line(t: &forkbench_core::ForkliftSpec) -> String {
    let s = &t.steering;
    let acc = s
        .accel_limit_radps2
        .map_or("unlimited".to_owned(), |a| format!("{a} rad/s²"));
    format!(
        "steering     dead time {} s (+ transport {} s), lag {} s, rate {} rad/s, acceleration {acc}, \
         deadband {} rad, backlash {} rad, offset {} rad",
        s.dead_time_s,
        t.control.transport_delay_s,
        s.time_constant_s,
        t.max_steer_rate_radps,
        s.deadband_rad,
        s.backlash_rad,
        s.offset_rad
    )
}

/// The drive and the controller's period as they will act.
fn drive_line(t: &forkbench_core::ForkliftSpec) -> String {
    let d = &t.drive;
    let or_sim =
        |v: Option<f64>, unit: &str| v.map_or("[sim]'s".to_owned(), |v| format!("{v} {unit}"));
    format!(
        "drive        dead time {} s, speed loop τ {}, acceleration {}, braking {}, creep below {} m/s; \
         control every {}",
        d.dead_time_s,
        or_sim(d.time_constant_s, "s"),
        or_sim(d.accel_limit_mps2, "m/s²"),
        or_sim(d.brake_limit_mps2, "m/s²"),
        d.creep_speed_mps,
        t.control
            .period_s
            .map_or("physics step".to_owned(), |p| format!("{p} s"))
    )
}

/// One line per case (the first 20).
fn cases(scn: &Scenario) -> Vec<String> {
    let mut lines = vec![format!("cases        {}", scn.cases.len())];
    for c in scn.cases.iter().take(20) {
        lines.push(format!(
            "  {:<20} start ({:.3}, {:.3}, {:.2}°), pallet face ({:.3}, {:.3}, {:.2}°)",
            one_line(&c.name),
            c.start.x_m,
            c.start.y_m,
            c.start.heading_rad.to_degrees(),
            c.pallet.x_m,
            c.pallet.y_m,
            c.pallet.heading_rad.to_degrees()
        ));
    }
    if scn.cases.len() > 20 {
        lines.push(format!(
            "  … and {} more (--json lists all)",
            scn.cases.len() - 20
        ));
    }
    lines
}

/// The pallet: its kind and face, size, pockets and parts.
fn pallet_line(scn: &forkbench_trial::Scenario) -> String {
    let p = &scn.pallet;
    let height = p
        .pocket_height_m
        .map_or(String::new(), |h| format!(", {h:.3} m high"));
    format!(
        "pallet       {}: {:.3} m deep × {:.3} m wide, {} parts; pockets {:.4} m wide{height} at ±{:.4} m",
        scn.pallet_kind,
        p.depth_m,
        p.width_m,
        p.parts().len(),
        p.pocket_width_m,
        p.pocket_offsets_m()[0]
    )
}

/// The truck's geometry and mass in one line: what its type sheet gives.
fn truck_line(t: &forkbench_core::ForkliftSpec) -> String {
    format!(
        "truck        {}\n             wheelbase {:.3} m, lock {:.1}° (turn radius {:.3} m), {:.0} kg, rated {:.0} kg, body {:.3} × {:.3} m, forks {:.3} m × {:.3} m at {:.3} m spacing, root {:.3} m ahead of the fixed axle, ≤ {} m/s",
        t.layout.describe(),
        t.wheelbase_m,
        t.max_steer_rad.to_degrees(),
        t.min_turn_radius_m(),
        t.mass_kg,
        t.rated_capacity_kg,
        t.body_length_m,
        t.body_width_m,
        t.fork_length_m,
        t.fork_width_m,
        t.fork_spacing_m,
        t.fork_root_ahead_of_front_axle_m,
        t.max_speed_mps
    ) + &mass_centre_line(t)
        + &mounts_line(t)
}

/// Where the truck carries its sensors, when its file or table says.
fn mounts_line(t: &forkbench_core::ForkliftSpec) -> String {
    if t.mounts.is_empty() {
        return "\n             sensors at their models' mounts or the scenario's [sensors] (the truck mounts none)".to_owned();
    }
    let each: Vec<String> = t
        .mounts
        .iter()
        .map(|(n, m)| {
            format!(
                "{n} at ({:.3}, {:.3}) m facing {:.1}°",
                m.x_m,
                m.y_m,
                m.heading_rad.to_degrees()
            )
        })
        .collect();
    format!(
        "\n             mounts (fork-root frame) {}",
        each.join(", ")
    )
}

/// Where the unladen mass sits, and what placed it.
fn mass_centre_line(t: &forkbench_core::ForkliftSpec) -> String {
    let behind_m = -t.mass_centre_ahead_of_front_axle_m();
    let by = match (t.axle_load_fixed_kg, t.axle_load_steered_kg) {
        (Some(f), Some(s)) => format!("from its axle loads, {f:.0} kg fixed / {s:.0} kg steered"),
        _ => "at the chassis centre (no axle loads declared)".to_owned(),
    };
    format!(
        "\n             mass centre {behind_m:.3} m behind the fixed axle ({:.0} % on the steered wheel), {by}",
        100.0 * behind_m / t.wheelbase_m
    )
}

/// The whole truck as JSON: every field, the actuators and control timing included even
/// where they equal the defaults (which the scenario's own serialisation leaves out).
fn whole_truck(t: &forkbench_core::ForkliftSpec) -> serde_json::Value {
    let mut v = serde_json::to_value(t).unwrap_or_default();
    if let Some(m) = v.as_object_mut() {
        m.insert("rated_capacity_kg".into(), t.rated_capacity_kg.into());
        m.insert("layout".into(), t.layout.key().into());
        m.insert(
            "steering".into(),
            serde_json::to_value(&t.steering).unwrap_or_default(),
        );
        m.insert(
            "drive".into(),
            serde_json::to_value(&t.drive).unwrap_or_default(),
        );
        m.insert(
            "control".into(),
            serde_json::to_value(&t.control).unwrap_or_default(),
        );
        m.insert(
            "mounts".into(),
            serde_json::to_value(&t.mounts).unwrap_or_default(),
        );
        m.insert("max_curvature_per_m".into(), t.max_curvature_per_m().into());
        m.insert(
            "mass_centre_ahead_of_front_axle_m".into(),
            t.mass_centre_ahead_of_front_axle_m().into(),
        );
    }
    v
}
