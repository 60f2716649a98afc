//! Physics sanity: the rigid-body truck follows the rear-steer kinematics, and forks push pallets.

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_sim::{PalletSpec, Sim, SimConfig};

/// Drives a constant-steer circle; returns (measured front-axle radius, worst side slip).
fn circle(steer_rad: f64, speed_mps: f64) -> (f64, f64) {
    let spec = ForkliftSpec::default();
    // Pallet far away so it never interferes.
    let mut sim = Sim::new(
        &spec,
        &Pose2::new(0.0, 0.0, 0.0),
        &PalletSpec::field_1200(),
        &Pose2::new(100.0, 100.0, 0.0),
        &[],
        &SimConfig::default(),
    )
    .expect("valid world");
    // Let speed and steering settle for 5 s.
    while sim.time_s() < 5.0 {
        sim.step(speed_mps, steer_rad);
    }
    let r_expected = spec.wheelbase_m / steer_rad.tan();
    let period = 2.0 * std::f64::consts::PI * r_expected / speed_mps;
    let t_end = sim.time_s() + period;
    let mut pts = Vec::new();
    let mut slip = 0.0_f64;
    while sim.time_s() < t_end {
        sim.step(speed_mps, steer_rad);
        let a = sim.front_axle_pose();
        pts.push([a.x_m, a.y_m]);
        slip = slip.max(sim.lateral_speed_mps().abs());
    }
    let n = pts.len() as f64;
    let c = [
        pts.iter().map(|p| p[0]).sum::<f64>() / n,
        pts.iter().map(|p| p[1]).sum::<f64>() / n,
    ];
    let r = pts
        .iter()
        .map(|p| (p[0] - c[0]).hypot(p[1] - c[1]))
        .sum::<f64>()
        / n;
    (r, slip)
}

#[test]
fn constant_steer_circle_has_the_kinematic_radius() {
    let spec = ForkliftSpec::default();
    for steer in [0.2, 0.5, 0.8] {
        let (r, _) = circle(steer, 0.5);
        let expected = spec.wheelbase_m / f64::tan(steer);
        assert!(
            (r / expected - 1.0).abs() < 0.02,
            "α {steer}: radius {r} vs {expected}"
        );
    }
}

#[test]
fn full_lock_turns_on_the_minimum_radius() {
    let spec = ForkliftSpec::default();
    let (r, _) = circle(spec.max_steer_rad, 0.4);
    assert!((r - 0.9407).abs() / 0.9407 < 0.02, "radius {r}");
}

#[test]
fn no_side_slip_at_picking_speed() {
    let (_, slip) = circle(0.5, 0.8);
    assert!(slip < 0.005, "side slip {slip} m/s");
}

#[test]
fn a_fork_striking_a_stringer_pushes_the_pallet() {
    let spec = ForkliftSpec::default();
    // Pallet shifted sideways so the left fork meets the centre stringer head on.
    let pallet = PalletSpec::field_1200();
    let fork_y = spec.fork_spacing_m / 2.0;
    let start = Pose2::new(0.0, 0.0, 0.0);
    let pallet_pose = Pose2::new(3.0, fork_y, 0.0);
    let mut sim = Sim::new(
        &spec,
        &start,
        &pallet,
        &pallet_pose,
        &[],
        &SimConfig::default(),
    )
    .expect("valid");
    let mut peak = 0.0_f64;
    while sim.time_s() < 8.0 {
        sim.step(0.5, 0.0);
        peak = peak.max(sim.pallet_contact_force_n());
    }
    let moved = sim.pallet_pose().distance_to(&pallet_pose);
    assert!(peak > 100.0, "contact force {peak} N");
    assert!(moved > 0.5, "pallet moved {moved} m");
}

#[test]
fn straight_entry_into_the_pockets_touches_nothing() {
    let spec = ForkliftSpec::default();
    let start = Pose2::new(0.0, 0.0, 0.0);
    let pallet_pose = Pose2::new(3.0, 0.0, 0.0);
    let mut sim = Sim::new(
        &spec,
        &start,
        &PalletSpec::field_1200(),
        &pallet_pose,
        &[],
        &SimConfig::default(),
    )
    .expect("valid");
    let mut peak = 0.0_f64;
    // Drive until the fork root is 5 cm short of the pallet face.
    while sim.fork_root_pose().x_m < 2.95 && sim.time_s() < 20.0 {
        sim.step(0.3, 0.0);
        peak = peak.max(sim.pallet_contact_force_n());
    }
    assert!(peak < 1.0, "contact force {peak} N");
    assert!(sim.pallet_pose().distance_to(&pallet_pose) < 1e-4);
}
