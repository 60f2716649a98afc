//! The field sizing against a hand computation, and the physics' braking against the analytic stop of its speed controller.

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};
use forkbench_safety::{
    Load, ReflectorsNear, STOPPED_MPS, SafetyConfig, braking_distance, size_fields,
};
use forkbench_sim::{Sim, SimConfig};

/// The front (drive, braked) axle's share of the static weight, empty or at rated load.
fn front_share(truck: &ForkliftSpec, cfg: &SimConfig, pallet: &PalletSpec, load: Load) -> f64 {
    let o = Pose2::new(0.0, 0.0, 0.0);
    let mut spec = pallet.clone();
    let at = match load {
        Load::Empty => Pose2::new(-100.0, 0.0, 0.0),
        Load::Rated => {
            spec.payload_kg = truck.rated_capacity_kg - spec.mass_kg;
            Pose2::new(0.02, 0.0, 0.0)
        }
    };
    let mut sim = Sim::new(truck, &o, &spec, &at, &[], cfg).expect("world");
    if load == Load::Rated {
        sim.lift().expect("lift");
    }
    let [front, rear] = sim.axle_loads_n();
    front / (front + rear)
}

/// The stop a proportional speed controller (gain k) makes with its deceleration capped
/// at the smaller of its limit and the drive axle's grip: constant deceleration down to
/// the speed where the controller asks for less, then an exponential tail to `STOPPED_MPS`.
fn analytic_stop_m(v: f64, k: f64, decel_mps2: f64) -> f64 {
    let v1 = decel_mps2 / k;
    if v <= v1 {
        return (v - STOPPED_MPS) / k;
    }
    (v * v - v1 * v1) / (2.0 * decel_mps2) + (v1 - STOPPED_MPS) / k
}

#[test]
fn braking_in_the_physics_matches_the_controllers_analytic_stop() {
    let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
    let mut cases = 0;
    for mu in [0.8, 0.1, 0.05] {
        let cfg = SimConfig {
            tyre_friction: mu,
            ..SimConfig::default()
        };
        for load in [Load::Empty, Load::Rated] {
            let grip = mu * 9.81 * front_share(&truck, &cfg, &pallet, load);
            // The drive's own braking limit and speed loop (the default truck's), and
            // the distance run at speed before the stop command reaches the drive.
            let d = &truck.drive;
            let decel = d.brake_limit_mps2.unwrap_or(cfg.max_accel_mps2).min(grip);
            let gain = d
                .time_constant_s
                .map_or(cfg.speed_gain_per_s, |tau| 1.0 / tau);
            let delay_s = truck.drive_delay_s();
            for v in [0.3, 0.6, 0.8] {
                let b = braking_distance(&truck, &cfg, &pallet, v, load).expect("brakes");
                let want = v * delay_s + analytic_stop_m(v, gain, decel);
                let err = (b.distance_m - want).abs();
                assert!(
                    err <= 0.01 + 0.03 * want,
                    "μ {mu}, {load:?}, {v} m/s: {:.4} m in the physics, {want:.4} m analytic",
                    b.distance_m
                );
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 18);
}

#[test]
fn an_empty_counterbalance_truck_brakes_longer_on_a_slippery_floor() {
    // Empty, the counterweight rests on the steer axle, so the braked drive axle carries
    // little; the load moves weight onto it.
    let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
    let cfg = SimConfig {
        tyre_friction: 0.1,
        ..SimConfig::default()
    };
    let empty = braking_distance(&truck, &cfg, &pallet, 0.8, Load::Empty).expect("empty");
    let rated = braking_distance(&truck, &cfg, &pallet, 0.8, Load::Rated).expect("rated");
    assert!(
        empty.distance_m > 1.3 * rated.distance_m,
        "{empty:?} {rated:?}"
    );
}

#[test]
fn protective_fields_match_a_hand_computation_at_three_speeds_empty_and_loaded() {
    let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
    let sim = SimConfig {
        tyre_friction: 0.1,
        ..SimConfig::default()
    };
    let cfg = SafetyConfig::default();
    let sized = size_fields(&cfg, &truck, &sim, &pallet, true).expect("sized");
    assert_eq!(sized.fields.len(), 6);
    // By hand, in millimetres: controller 100 ms and scanner 80 ms at each speed, then
    // TZ 100, Z_R 350 (reflectors in the world), Z_F 150 (100 mm ground clearance is
    // under 120 mm), Z_G 100.
    let by_hand_mm = [(0.3, 30.0 + 24.0), (0.6, 60.0 + 48.0), (0.8, 80.0 + 64.0)];
    let supplements_mm = 100.0 + 350.0 + 150.0 + 100.0;
    let mut rows = sized.fields.iter();
    for (v, response_mm) in by_hand_mm {
        for load in [Load::Empty, Load::Rated] {
            let f = rows.next().expect("a row per speed and load");
            assert_eq!((f.speed_max_mps, f.load), (v, load));
            let braking = braking_distance(&truck, &sim, &pallet, v, load).expect("brakes");
            let want_mm = braking.distance_m * 1e3 + response_mm + supplements_mm;
            assert!(
                (f.length_m * 1e3 - want_mm).abs() < 1e-6,
                "{v} m/s {load:?}: S_L {} mm, by hand {want_mm} mm",
                f.length_m * 1e3
            );
            let width_mm = match load {
                Load::Empty => 1200.0,
                Load::Rated => 1200.0_f64.max(pallet.width_m * 1e3),
            } + 2.0 * (100.0 + 350.0 + 150.0);
            assert!((f.width_m * 1e3 - width_mm).abs() < 1e-6, "{f:?}");
        }
    }
    // The supplements follow their conditions.
    let bare = SafetyConfig {
        reflectors_near: ReflectorsNear::Auto,
        ground_clearance_m: 0.12,
        general_supplement_m: 0.0,
        ..SafetyConfig::default()
    };
    let sized = size_fields(&bare, &truck, &sim, &pallet, false).expect("sized");
    let f = &sized.fields[0];
    assert_eq!((f.reflector_m, f.floor_m, f.general_m), (0.0, 0.0, 0.0));
    assert!((f.length_m - (f.stopping_m + f.tolerance_m)).abs() < 1e-12);
}
