//! The world sensors see: ray casts into the rapier world hit what geometry says, name the pallet, and never see the truck itself.

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_sensors::scan::{ScannerConfig, Seen, WorldView, scan};
use forkbench_sim::{Obstacle, PalletSpec, Sim, SimConfig};

fn world() -> (Sim, PalletSpec) {
    let pallet = PalletSpec::field_1200();
    let rack = Obstacle {
        centre: Pose2::new(3.0, 4.0, 0.0),
        length_m: 2.0,
        width_m: 1.0,
    };
    let sim = Sim::new(
        &ForkliftSpec::default(),
        &Pose2::new(0.0, 0.0, 0.0),
        &pallet,
        &Pose2::new(5.0, 0.0, 0.0),
        &[rack],
        &SimConfig::default(),
    )
    .expect("valid world");
    (sim, pallet)
}

#[test]
fn rays_hit_stringers_and_racks_where_geometry_says() {
    let (sim, pallet) = world();
    // Straight ahead from the fork root: the centre stringer's face at x = 5 (the
    // truck's own forks, which reach past the root, are not seen).
    let hit = sim
        .cast_ray([0.0, 0.0], [1.0, 0.0], 20.0)
        .expect("the pallet");
    assert!((hit.range_m - 5.0).abs() < 1e-4, "{hit:?}");
    assert_eq!(hit.seen, Seen::Pallet(0));
    assert!((hit.normal[0] + 1.0).abs() < 1e-4, "{hit:?}");
    // Along a pocket's centre line the ray passes through the open pocket.
    let y = pallet.pocket_offsets_m()[1];
    assert!(sim.cast_ray([0.0, y], [1.0, 0.0], 20.0).is_none());
    // Up at the rack: its lower face at y = 3.5.
    let hit = sim
        .cast_ray([3.0, 0.0], [0.0, 1.0], 20.0)
        .expect("the rack");
    assert!((hit.range_m - 3.5).abs() < 1e-4, "{hit:?}");
    assert_eq!(hit.seen, Seen::Fixed);
}

#[test]
fn an_ideal_scan_sees_the_three_stringer_faces_at_their_analytic_ranges() {
    let (sim, pallet) = world();
    let cfg = ScannerConfig::tim561();
    let s = scan::<rand::rngs::ThreadRng>(
        &cfg,
        &sim,
        Pose2::new(0.0, 0.0, 0.0),
        forkbench_sensors::scan::Errors::Ideal,
    );
    let solids = pallet.face_solids();
    let mut on_faces = 0;
    for (i, r) in s.ranges_m.iter().enumerate() {
        let a = s.angle_min_rad + i as f64 * s.angle_step_rad;
        // A beam whose line crosses x = 5 within a stringer's width meets that face.
        let y = 5.0 * a.tan();
        let on_face = a.cos() > 0.0 && solids.iter().any(|[lo, hi]| y > lo + 1e-3 && y < hi - 1e-3);
        if on_face {
            let want = 5.0 / a.cos();
            assert!((r - want).abs() < 1e-3, "beam {i}: {r} vs {want}");
            on_faces += 1;
        }
    }
    // 0.13 m stringers at 5 m, 0.33° apart: four or five beams each.
    assert!(
        (12..=15).contains(&on_faces),
        "{on_faces} beams on the faces"
    );
}

/// The scan's binned caster against rapier's own query pipeline, beam by beam, from
/// several poses among racks at odd angles.
#[test]
fn the_scan_agrees_with_rapiers_ray_casts() {
    let racks: Vec<Obstacle> = (0..12)
        .map(|k| {
            let a = f64::from(k) * 0.52;
            Obstacle {
                centre: Pose2::new(6.0 * a.cos(), 6.0 * a.sin(), 0.3 * f64::from(k)),
                length_m: 1.0 + 0.2 * f64::from(k % 3),
                width_m: 0.4,
            }
        })
        .collect();
    let sim = Sim::new(
        &ForkliftSpec::default(),
        &Pose2::new(0.0, 0.0, 0.0),
        &PalletSpec::field_1200(),
        &Pose2::new(3.0, -1.0, 0.4),
        &racks,
        &SimConfig::default(),
    )
    .expect("valid world");
    let cfg = ScannerConfig::tim561();
    let mut compared = 0;
    for sensor in [
        Pose2::new(0.0, 0.0, 0.0),
        Pose2::new(-1.0, 1.5, 2.0),
        Pose2::new(1.0, -2.0, -1.0),
    ] {
        let s = scan::<rand::rngs::ThreadRng>(
            &cfg,
            &sim,
            sensor,
            forkbench_sensors::scan::Errors::Ideal,
        );
        for (i, r) in s.ranges_m.iter().enumerate() {
            let a = sensor.heading_rad + s.angle_min_rad + i as f64 * s.angle_step_rad;
            let want = sim
                .cast_ray(
                    [sensor.x_m, sensor.y_m],
                    [a.cos(), a.sin()],
                    cfg.range_max_m,
                )
                .map_or(f64::NAN, |h| h.range_m);
            assert!(
                (r.is_nan() && want.is_nan()) || (r - want).abs() < 1e-4,
                "pose {sensor:?} beam {i}: scan {r} vs rapier {want}"
            );
            compared += usize::from(r.is_finite());
        }
    }
    assert!(compared > 500, "{compared} returns compared");
}
