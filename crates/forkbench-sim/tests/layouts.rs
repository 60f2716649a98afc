//! Axle layouts in the physics: a steered drive wheel drives where it points, turns the truck on the spot at 90°, and follows the same kinematics as a counterbalance truck below that.

use forkbench_core::{ForkliftSpec, Pose2, TruckLayout};
use forkbench_sim::{PalletSpec, Sim, SimConfig};

fn stacker() -> ForkliftSpec {
    ForkliftSpec {
        layout: TruckLayout::PalletStacker,
        wheelbase_m: 1.3,
        max_steer_rad: std::f64::consts::FRAC_PI_2,
        body_length_m: 1.0,
        body_width_m: 0.8,
        mass_kg: 1050.0,
        fork_length_m: 1.15,
        fork_width_m: 0.18,
        fork_root_ahead_of_front_axle_m: -0.7,
        ..ForkliftSpec::default()
    }
}

fn sim(spec: &ForkliftSpec) -> Sim {
    Sim::new(
        spec,
        &Pose2::new(0.0, 0.0, 0.0),
        &PalletSpec::field_1200(),
        &Pose2::new(100.0, 100.0, 0.0),
        &[],
        &SimConfig::default(),
    )
    .expect("valid world")
}

/// With its wheel at 90° a stacker turns about its load axle: the axle's centre stays
/// where it was while the truck's heading turns, at the top speed over the wheelbase.
#[test]
fn a_stacker_turns_on_the_spot_with_its_wheel_at_90_degrees() {
    let spec = stacker();
    let mut s = sim(&spec);
    let lock = spec.max_steer_rad;
    // The wheel turns to its lock standing, then drives.
    while s.time_s() < 3.0 {
        s.step(0.0, lock);
    }
    let a0 = s.front_axle_pose();
    while s.time_s() < 6.0 {
        s.step(0.5, lock);
    }
    let a = s.front_axle_pose();
    assert!(
        (a.x_m - a0.x_m).hypot(a.y_m - a0.y_m) < 0.02,
        "the load axle moved from {a0:?} to {a:?}"
    );
    assert!(a.heading_rad - a0.heading_rad > 1.0, "turned {a:?}");
    let yaw = s.yaw_rate_radps().abs();
    let expected = spec.max_speed_mps / spec.wheelbase_m;
    assert!(
        (yaw / expected - 1.0).abs() < 0.1,
        "yaw rate {yaw} rad/s against {expected}"
    );
}

/// Below 90° a steered drive wheel follows the single-track kinematics about the fixed
/// axle, as the counterbalance truck does: the same constant-steer circle (while the
/// wheel's own speed, 0.4 m/s over the steering angle's cosine, stays under the top speed).
#[test]
fn a_steered_drive_wheel_drives_the_kinematic_circle() {
    for (spec, steer) in [(stacker(), 0.6), (stacker(), 1.0)] {
        let mut s = sim(&spec);
        while s.time_s() < 6.0 {
            s.step(0.4, steer);
        }
        let expected_yaw = 0.4 * steer.tan() / spec.wheelbase_m;
        let yaw = s.yaw_rate_radps();
        assert!(
            (yaw / expected_yaw - 1.0).abs() < 0.05,
            "steer {steer}: yaw rate {yaw} against {expected_yaw}"
        );
        assert!(
            (s.speed_mps() - 0.4).abs() < 0.02,
            "steer {steer}: speed {}",
            s.speed_mps()
        );
    }
}

/// The traction acts where the layout puts it: the same truck with its wheel turned 60°
/// and no speed yet, driven from the fixed axle, starts straight ahead; driven at its
/// steered wheel, it starts by turning.
#[test]
fn the_traction_acts_at_the_steered_wheel_only_for_a_steered_drive() {
    let turned = 1.0;
    let mut yaw = Vec::new();
    for layout in [TruckLayout::Counterbalance, TruckLayout::PalletStacker] {
        let spec = ForkliftSpec {
            layout,
            max_steer_rad: 1.2,
            ..stacker()
        };
        let mut s = sim(&spec);
        // Turn the wheel while standing, then drive off.
        while s.time_s() < 2.0 {
            s.step(0.0, turned);
        }
        let h0 = s.front_axle_pose().heading_rad;
        for _ in 0..20 {
            s.step(0.4, turned);
        }
        yaw.push((s.front_axle_pose().heading_rad - h0).abs());
    }
    assert!(yaw[1] > yaw[0], "heading change {yaw:?}");
}

/// A counterbalance truck's lock stops short of 90°; a steered drive wheel's reaches it,
/// and no layout's passes it.
#[test]
fn the_lock_is_checked_against_the_layout() {
    let right = std::f64::consts::FRAC_PI_2;
    let counter = ForkliftSpec {
        max_steer_rad: right,
        ..ForkliftSpec::default()
    };
    let e = counter.validate().expect_err("90° counterbalance");
    assert_eq!(e.field.as_deref(), Some("max_steer_rad"));
    assert!(e.reason.contains("pallet_stacker"), "{}", e.reason);
    assert!(stacker().validate().is_ok());
    let past = ForkliftSpec {
        max_steer_rad: 1.7,
        ..stacker()
    };
    assert!(past.validate().is_err());
    assert!(stacker().max_curvature_per_m().is_finite());
}
