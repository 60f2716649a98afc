//! Carrying a load: the lifted pallet rides on the forks, moves the axle loads, changes the braking limit, and slides off when pushed harder than its friction.

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_sim::{LiftError, PalletSpec, Sim, SimConfig};

const G_MPS2: f64 = 9.81;

/// A truck at the origin heading +x with its forks 1.55 m under a field pallet carrying
/// `payload_kg`.
fn under_pallet(payload_kg: f64, cfg: &SimConfig) -> Sim {
    let pallet = PalletSpec::field_1200().with_payload(payload_kg);
    Sim::new(
        &ForkliftSpec::default(),
        &Pose2::new(0.0, 0.0, 0.0),
        &pallet,
        &Pose2::new(0.05, 0.0, 0.0),
        &[],
        cfg,
    )
    .expect("valid world")
}

/// The centre of mass ahead of the front axle of the truck (its chassis centre) and a
/// load at the pallet's centre, by hand.
fn loaded_com_ahead_m(payload_kg: f64) -> (f64, f64) {
    let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
    let chassis_centre = truck.fork_root_ahead_of_front_axle_m - truck.body_length_m / 2.0;
    let load_centre = truck.fork_root_ahead_of_front_axle_m + 0.05 + pallet.depth_m / 2.0;
    let load = pallet.mass_kg + payload_kg;
    let mass = truck.mass_kg + load;
    (
        (truck.mass_kg * chassis_centre + load * load_centre) / mass,
        mass,
    )
}

#[test]
fn a_lifted_pallet_rides_rigidly_on_the_forks() {
    let mut sim = under_pallet(800.0, &SimConfig::default());
    sim.lift().expect("forks under the pallet");
    assert!(sim.carrying());
    let on_forks = sim.fork_root_pose().to_local(&sim.pallet_pose());
    let start = sim.pallet_pose();
    while sim.time_s() < 12.0 {
        let steer = if sim.time_s() < 6.0 { 0.4 } else { -0.4 };
        sim.step(-0.6, steer);
    }
    let now = sim.fork_root_pose().to_local(&sim.pallet_pose());
    assert!(
        now.distance_to(&on_forks) < 1e-3 && (now.heading_rad - on_forks.heading_rad).abs() < 1e-3,
        "the load moved on the forks: {on_forks:?} → {now:?}"
    );
    assert!(sim.pallet_pose().distance_to(&start) > 4.0, "carried along");
    assert!(
        !sim.load_shifted(),
        "peak {} m/s²",
        sim.peak_load_accel_mps2()
    );
}

#[test]
fn the_load_moves_weight_from_the_rear_axle_to_the_front() {
    let mut sim = under_pallet(1000.0, &SimConfig::default());
    let truck = ForkliftSpec::default();
    let [front0, rear0] = sim.axle_loads_n();
    sim.lift().expect("forks under the pallet");
    let [front, rear] = sim.axle_loads_n();
    let (com_ahead_m, mass_kg) = loaded_com_ahead_m(1000.0);
    let rear_share = -com_ahead_m / truck.wheelbase_m;
    let want = [
        mass_kg * G_MPS2 * (1.0 - rear_share),
        mass_kg * G_MPS2 * rear_share,
    ];
    for (got, want) in [front, rear].iter().zip(want) {
        assert!(
            (got / want - 1.0).abs() < 1e-4,
            "axle load {got} N vs {want} N"
        );
    }
    assert!(rear < rear0 && front > front0 + 1000.0 * G_MPS2);
    // Setting it down gives the empty truck's loads back.
    sim.lower();
    let [f, r] = sim.axle_loads_n();
    assert!((f - front0).abs() < 1e-6 * front0 && (r - rear0).abs() < 1e-6 * rear0);
}

/// Distance from `speed_mps` to standstill with a zero speed command.
fn stopping_distance_m(sim: &mut Sim, speed_mps: f64) -> f64 {
    while (sim.speed_mps() - speed_mps).abs() > 1e-3 && sim.time_s() < 20.0 {
        sim.step(speed_mps, 0.0);
    }
    let from = sim.front_axle_pose();
    while sim.speed_mps().abs() > 1e-4 {
        sim.step(0.0, 0.0);
    }
    sim.front_axle_pose().distance_to(&from)
}

/// Stopping distance with a speed controller of gain k and accel limit, on drive tyres
/// that brake at most `grip` m/s²: constant deceleration down to the speed where k v
/// drops below it, then the controller's exponential tail (v₁/k).
/// The truck's drive sets the gain and the braking limit, and runs at `v0` until the
/// stop command reaches it (its dead time and the transport delay).
fn analytic_stop_m(v0: f64, grip_mps2: f64, cfg: &SimConfig) -> f64 {
    let d = ForkliftSpec::default();
    let limit = d.drive.brake_limit_mps2.unwrap_or(cfg.max_accel_mps2);
    let gain = d
        .drive
        .time_constant_s
        .map_or(cfg.speed_gain_per_s, |tau| 1.0 / tau);
    let delay_s = d.drive_delay_s();
    let a = grip_mps2.min(limit);
    let v1 = a / gain;
    v0 * delay_s + (v0 * v0 - v1 * v1) / (2.0 * a) + v1 / gain
}

/// On a wet floor the drive tyres limit braking; the load pressing on the front (drive)
/// axle lets the loaded truck brake harder than the empty one.
#[test]
fn on_a_slippery_floor_the_loaded_truck_stops_shorter() {
    let cfg = SimConfig {
        tyre_friction: 0.08,
        ..SimConfig::default()
    };
    let truck = ForkliftSpec::default();
    let mut empty = under_pallet(1000.0, &cfg);
    let empty_front_share = 1.0
        + (truck.fork_root_ahead_of_front_axle_m - truck.body_length_m / 2.0) / truck.wheelbase_m;
    let mut loaded = under_pallet(1000.0, &cfg);
    loaded.lift().expect("forks under the pallet");
    let loaded_front_share = 1.0 + loaded_com_ahead_m(1000.0).0 / truck.wheelbase_m;
    // Reverse out, so the empty truck leaves the pallet behind.
    let d_empty = stopping_distance_m(&mut empty, -0.8);
    let d_loaded = stopping_distance_m(&mut loaded, -0.8);
    let want_empty = analytic_stop_m(0.8, 0.08 * G_MPS2 * empty_front_share, &cfg);
    let want_loaded = analytic_stop_m(0.8, 0.08 * G_MPS2 * loaded_front_share, &cfg);
    println!(
        "stopping from 0.8 m/s at μ 0.08: empty {d_empty:.3} m (by hand {want_empty:.3}), loaded {d_loaded:.3} m (by hand {want_loaded:.3})"
    );
    assert!(
        (d_empty / want_empty - 1.0).abs() < 0.03,
        "{d_empty} vs {want_empty}"
    );
    assert!(
        (d_loaded / want_loaded - 1.0).abs() < 0.03,
        "{d_loaded} vs {want_loaded}"
    );
    assert!(d_loaded < 0.85 * d_empty);
}

/// Braking at 1 m/s² holds a load on forks with friction 0.3 (2.9 m/s²) and throws one
/// off forks with friction 0.05 (0.49 m/s²).
#[test]
fn a_load_slides_off_when_the_truck_decelerates_harder_than_its_friction() {
    for (fork_friction, shifts) in [(0.3, false), (0.05, true)] {
        let cfg = SimConfig {
            fork_friction,
            ..SimConfig::default()
        };
        let mut sim = under_pallet(600.0, &cfg);
        sim.lift().expect("forks under the pallet");
        stopping_distance_m(&mut sim, -0.8);
        assert_eq!(sim.load_shifted(), shifts, "fork friction {fork_friction}");
        assert_eq!(sim.carrying(), !shifts);
        assert!(sim.peak_load_accel_mps2() > 0.9 && sim.peak_load_accel_mps2() < 1.5);
    }
}

#[test]
fn lifting_is_refused_without_forks_under_or_beyond_the_rating() {
    let mut sim = under_pallet(0.0, &SimConfig::default());
    while sim.time_s() < 3.0 {
        sim.step(-0.5, 0.0);
    }
    assert!(matches!(sim.lift(), Err(LiftError::NotUnder { .. })));
    let mut heavy = under_pallet(3000.0, &SimConfig::default());
    let err = heavy.lift().expect_err("3,025 kg on a 3,000 kg truck");
    assert!(matches!(err, LiftError::OverCapacity { .. }), "{err}");
    assert!(!heavy.carrying());
    let mut ok = under_pallet(0.0, &SimConfig::default());
    ok.lift().expect("forks under");
    assert_eq!(ok.lift(), Err(LiftError::AlreadyCarrying));
}

/// A set-down pallet stands on the floor again: the truck backs out without it.
#[test]
fn a_lowered_pallet_stays_where_it_was_put() {
    let mut sim = under_pallet(500.0, &SimConfig::default());
    sim.lift().expect("forks under the pallet");
    while sim.time_s() < 5.0 {
        // A bend, then straight, so backing out straight draws the forks from the pockets.
        sim.step(0.3, if sim.time_s() < 3.0 { 0.2 } else { 0.0 });
    }
    while sim.speed_mps().abs() > 1e-4 {
        sim.step(0.0, 0.0);
    }
    sim.lower();
    let put = sim.pallet_pose();
    while sim.time_s() < 14.0 {
        sim.step(-0.3, 0.0);
    }
    assert!(!sim.carrying());
    assert!(
        sim.pallet_pose().distance_to(&put) < 0.01,
        "{put:?} → {:?}",
        sim.pallet_pose()
    );
    let gap = sim.fork_root_pose().distance_to(&put);
    assert!(
        gap > ForkliftSpec::default().fork_length_m,
        "the forks are out: fork root {gap:.3} m from the pallet face"
    );
}

/// Mean fork–stringer force over the last 2 of 8 s of a fork pushing a pallet's centre
/// stringer at 0.5 m/s.
fn steady_push_force_n(payload_kg: f64) -> f64 {
    let spec = ForkliftSpec::default();
    let pallet_pose = Pose2::new(3.0, spec.fork_spacing_m / 2.0, 0.0);
    let mut sim = Sim::new(
        &spec,
        &Pose2::new(0.0, 0.0, 0.0),
        &PalletSpec::field_1200().with_payload(payload_kg),
        &pallet_pose,
        &[],
        &SimConfig::default(),
    )
    .expect("valid world");
    let (mut sum, mut n) = (0.0, 0);
    while sim.time_s() < 8.0 {
        sim.step(0.5, 0.0);
        if sim.time_s() > 6.0 {
            sum += sim.pallet_contact_force_n();
            n += 1;
        }
    }
    sum / f64::from(n)
}

/// The payload presses the pallet on the floor: sliding it takes μ (pallet + payload) g.
#[test]
fn pushing_a_loaded_pallet_takes_its_floor_friction() {
    let mu = SimConfig::default().pallet_floor_friction;
    for payload_kg in [0.0, 400.0, 800.0] {
        let want = mu * (PalletSpec::field_1200().mass_kg + payload_kg) * G_MPS2;
        let got = steady_push_force_n(payload_kg);
        assert!(
            (got / want - 1.0).abs() < 0.1,
            "payload {payload_kg} kg: {got:.0} N vs μ m g {want:.0} N"
        );
    }
}

/// The carried pallet is part of the truck: driving it into a wall is a contact, and
/// it comes when the pallet's far edge (ahead of the fork tips, 1.15 m in) reaches it.
#[test]
fn a_carried_pallet_touches_what_it_is_driven_into() {
    let face_x = ForkliftSpec::default().fork_length_m - 1.15;
    let wall_face_x = face_x + 1.2 + 0.5;
    let wall = forkbench_sim::Obstacle {
        centre: Pose2::new(wall_face_x + 0.1, 0.0, 0.0),
        length_m: 0.2,
        width_m: 4.0,
    };
    let mut sim = Sim::new(
        &ForkliftSpec::default(),
        &Pose2::new(0.0, 0.0, 0.0),
        &PalletSpec::field_1200().with_payload(300.0),
        &Pose2::new(face_x, 0.0, 0.0),
        &[wall],
        &SimConfig::default(),
    )
    .expect("valid world");
    sim.lift().expect("forks under the pallet");
    while !sim.obstacle_contact() && sim.time_s() < 10.0 {
        sim.step(0.3, 0.0);
    }
    assert!(sim.obstacle_contact(), "never touched the wall");
    let front_x = sim.pallet_pose().x_m + 1.2;
    assert!(
        (front_x - wall_face_x).abs() < 0.03,
        "pallet front at {front_x} m, wall at {wall_face_x} m"
    );
}

/// Declared axle loads (VDI 2198 line 2.3) put the unladen mass where they say: the static
/// loads on the two axles are the declared ones, whatever the chassis's outline.
#[test]
fn declared_axle_loads_are_the_static_axle_loads() {
    let truck = ForkliftSpec {
        mass_kg: 3000.0,
        axle_load_fixed_kg: Some(1200.0),
        axle_load_steered_kg: Some(1800.0),
        ..ForkliftSpec::default()
    };
    let sim = Sim::new(
        &truck,
        &Pose2::new(0.0, 0.0, 0.0),
        &PalletSpec::field_1200(),
        &Pose2::new(4.0, 0.0, 0.0),
        &[],
        &SimConfig::default(),
    )
    .expect("valid world");
    let [fixed, steered] = sim.axle_loads_n();
    assert!((fixed - 1200.0 * G_MPS2).abs() < 1e-6, "{fixed}");
    assert!((steered - 1800.0 * G_MPS2).abs() < 1e-6, "{steered}");
}
