//! NAV350 reflector positioning: line of sight against an independent segment-versus-rectangle clip, the least-squares fix exact without noise and as spread as predicted with it, no fix from two reflectors, ambiguous associations dropped.

use forkbench_core::Pose2;
use forkbench_sensors::reflectors::{
    Observation, Reflector, ReflectorNavConfig, associate, measure, predicted_sigma_m, solve,
    visible,
};
use forkbench_sensors::scan::{Seen, Surface};
use forkbench_sensors::sight::Sight;
use rand::{RngExt as _, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn refl(name: &str, x: f64, y: f64) -> Reflector {
    Reflector {
        name: name.into(),
        x_m: x,
        y_m: y,
    }
}

/// Liang–Barsky: whether the segment a→b enters the rectangle (centre, length along the
/// heading, width), clipped in the rectangle's own frame.
fn clips(a: [f64; 2], b: [f64; 2], c: &Pose2, length: f64, width: f64) -> bool {
    let la = c.to_local(&Pose2::new(a[0], a[1], 0.0));
    let lb = c.to_local(&Pose2::new(b[0], b[1], 0.0));
    let d = [lb.x_m - la.x_m, lb.y_m - la.y_m];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d[0], la.x_m + length / 2.0),
        (d[0], length / 2.0 - la.x_m),
        (-d[1], la.y_m + width / 2.0),
        (d[1], width / 2.0 - la.y_m),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    t0 <= t1
}

type Rect = (Pose2, f64, f64);

fn random_rects(rng: &mut ChaCha8Rng) -> Vec<Rect> {
    (0..4)
        .map(|_| {
            let c = Pose2::new(
                rng.random_range(2.0..18.0),
                rng.random_range(2.0..18.0),
                rng.random_range(-1.5..1.5),
            );
            (c, rng.random_range(0.2..4.0), rng.random_range(0.1..1.0))
        })
        .collect()
}

#[test]
fn line_of_sight_matches_an_independent_clip() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let cfg = ReflectorNavConfig::default();
    let (mut blocked, mut clear) = (0, 0);
    for _ in 0..300 {
        let rects = random_rects(&mut rng);
        let fixed: Vec<Surface> = rects
            .iter()
            .flat_map(|(c, l, w)| Surface::rect(c, *l, *w, Seen::Fixed))
            .collect();
        let at = [rng.random_range(0.0..20.0), rng.random_range(0.0..20.0)];
        let r = refl(
            "r",
            rng.random_range(0.0..20.0),
            rng.random_range(0.0..20.0),
        );
        // Both ends outside every rectangle: line of sight is about what lies between.
        let inside = |p: [f64; 2]| rects.iter().any(|(c, l, w)| clips(p, p, c, *l, *w));
        if inside(at) || inside([r.x_m, r.y_m]) || (r.x_m - at[0]).hypot(r.y_m - at[1]) < 0.5 {
            continue;
        }
        let want = !rects
            .iter()
            .any(|(c, l, w)| clips(at, [r.x_m, r.y_m], c, *l, *w));
        let got = !visible(at, std::slice::from_ref(&r), &Sight::new(&fixed), &cfg).is_empty();
        assert_eq!(got, want, "from {at:?} to {r:?} past {rects:?}");
        if want {
            clear += 1;
        } else {
            blocked += 1;
        }
    }
    assert!(
        blocked > 30 && clear > 30,
        "{blocked} blocked, {clear} clear"
    );
    // Pallets never block: they lie below the scanner's plane.
    let pallet = Surface::rect(&Pose2::new(5.0, 0.0, 0.0), 1.2, 1.2, Seen::Pallet(0));
    assert_eq!(
        visible(
            [0.0, 0.0],
            &[refl("a", 10.0, 0.0)],
            &Sight::new(&pallet),
            &cfg
        ),
        vec![0]
    );
}

fn ring(n: usize, radius: f64) -> Vec<Reflector> {
    (0..n)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / n as f64 + 0.3;
            refl(&format!("r{k}"), radius * a.cos(), radius * a.sin())
        })
        .collect()
}

fn exact_observations(truth: &Pose2, map: &[Reflector]) -> Vec<Observation> {
    map.iter()
        .map(|r| {
            let (dx, dy) = (r.x_m - truth.x_m, r.y_m - truth.y_m);
            Observation {
                range_m: dx.hypot(dy),
                bearing_rad: forkbench_core::units::wrap_angle(dy.atan2(dx) - truth.heading_rad),
            }
        })
        .collect()
}

#[test]
fn the_fix_is_exact_without_noise_and_as_spread_as_predicted_with_it() {
    let cfg = ReflectorNavConfig::default();
    let map = ring(5, 10.0);
    let truth = Pose2::new(1.3, -0.7, 0.4);
    let exact = exact_observations(&truth, &map);
    let predicted = Pose2::new(1.35, -0.66, 0.405);
    let pairs = associate(&exact, &predicted, &map, &cfg);
    assert_eq!(pairs.len(), 5);
    let fix = solve(&exact, &pairs, &map, &predicted, &cfg).expect("fix");
    assert!(
        fix.pose.distance_to(&truth) < 1e-9
            && (fix.pose.heading_rad - truth.heading_rad).abs() < 1e-12,
        "{fix:?}"
    );
    assert!(fix.mean_deviation_m < 1e-9 && fix.used.len() == 5);
    // With noise: the radial RMS error over many fixes is the predicted σ.
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let seen: Vec<usize> = (0..map.len()).collect();
    let n = 3000;
    let ss: f64 = (0..n)
        .map(|_| {
            let obs = measure(&truth, &map, &seen, &cfg, &mut rng);
            let pairs = associate(&obs, &truth, &map, &cfg);
            let f = solve(&obs, &pairs, &map, &truth, &cfg).expect("fix");
            f.pose.distance_to(&truth).powi(2)
        })
        .sum();
    let rms = (ss / n as f64).sqrt();
    let pts: Vec<[f64; 2]> = map.iter().map(|r| [r.x_m, r.y_m]).collect();
    let sigma = predicted_sigma_m([truth.x_m, truth.y_m], &pts, &cfg).expect("σ");
    assert!(
        (rms / sigma - 1.0).abs() < 0.06,
        "rms {rms} vs predicted {sigma}"
    );
    // The calibration: four reflectors around at 10 m give ±4 mm per axis as 2σ.
    let four: Vec<[f64; 2]> = ring(4, 10.0).iter().map(|r| [r.x_m, r.y_m]).collect();
    let per_axis = predicted_sigma_m([0.0, 0.0], &four, &cfg).expect("σ") / 2f64.sqrt();
    assert!((per_axis - 0.002).abs() < 1e-4, "{per_axis}");
}

#[test]
fn two_reflectors_give_no_fix_and_ambiguity_is_dropped() {
    let cfg = ReflectorNavConfig::default();
    let map = ring(2, 8.0);
    let truth = Pose2::new(0.0, 0.0, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let obs = measure(&truth, &map, &[0, 1], &cfg, &mut rng);
    let pairs = associate(&obs, &truth, &map, &cfg);
    assert_eq!(pairs.len(), 2);
    assert!(solve(&obs, &pairs, &map, &truth, &cfg).is_none());
    assert!(predicted_sigma_m([0.0, 0.0], &[[8.0, 0.0], [0.0, 8.0]], &cfg).is_none());
    // Two map reflectors 0.3 m apart, both within the gate: neither is used.
    let close = vec![refl("a", 5.0, 0.0), refl("b", 5.0, 0.3)];
    let obs = measure(&truth, &close, &[0], &cfg, &mut rng);
    assert!(associate(&obs, &truth, &close, &cfg).is_empty());
}

mod localiser {
    use super::*;
    use forkbench_sensors::{Localizer, LocalizerInput, ReflectorNav, ReflectorNavSettings};

    fn room() -> Vec<Reflector> {
        vec![
            refl("a", 0.0, 0.0),
            refl("b", 10.0, 0.0),
            refl("c", 10.0, 8.0),
            refl("d", 0.0, 8.0),
        ]
    }

    fn sweep_at(nav: &mut ReflectorNav, truth: Pose2) -> forkbench_sensors::Reading {
        let input = LocalizerInput {
            t_s: 0.0,
            truth,
            predicted: Some(Pose2::new(
                truth.x_m + 0.05,
                truth.y_m - 0.03,
                truth.heading_rad,
            )),
            odometry: None,
            occluders: Vec::new(),
        };
        nav.update(&input, &mut ChaCha8Rng::seed_from_u64(1))
            .expect("a reading at t = 0")
    }

    #[test]
    fn a_person_in_the_sight_line_hides_a_reflector_for_that_sweep() {
        let fresh = || {
            ReflectorNav::new(
                ReflectorNavSettings::default(),
                &room(),
                &[],
                (8.0, 0.0),
                0.0,
            )
        };
        let truth = Pose2::new(4.0, 3.0, 0.0);
        assert_eq!(sweep_at(&mut fresh(), truth).detected, 4);
        let mut nav = fresh();
        let sensor = truth.to_world(&ReflectorNavSettings::default().mount);
        // A leg's edge across the line to reflector a at (0, 0), halfway.
        let mid = [sensor.x_m / 2.0, sensor.y_m / 2.0];
        let leg = [
            [mid[0] - 0.05, mid[1] + 0.05],
            [mid[0] + 0.05, mid[1] - 0.05],
        ];
        let input = LocalizerInput {
            t_s: 0.0,
            truth,
            predicted: Some(truth),
            odometry: None,
            occluders: vec![leg],
        };
        let r = nav
            .update(&input, &mut ChaCha8Rng::seed_from_u64(1))
            .expect("a reading at t = 0");
        assert_eq!(r.detected, 3);
    }

    #[test]
    fn a_mounted_scanner_without_noise_returns_the_true_fork_root() {
        let settings = ReflectorNavSettings {
            mount: Pose2::new(-0.8, 0.2, 0.1),
            ..ReflectorNavSettings::default()
        };
        let mut nav = ReflectorNav::new(settings, &room(), &[], (8.0, 0.0), 0.0);
        let truth = Pose2::new(4.0, 3.0, 0.7);
        let r = sweep_at(&mut nav, truth);
        let pose = r.pose.expect("four reflectors in sight");
        assert!(pose.distance_to(&truth) < 1e-9, "{pose:?}");
        assert!((pose.heading_rad - truth.heading_rad).abs() < 1e-9);
        let fix = r.fix.expect("the device's report");
        assert_eq!((fix.used.len(), r.detected), (4, 4));
        assert!(fix.mean_deviation_m < 1e-9);
    }

    #[test]
    fn a_wall_hiding_two_of_four_reflectors_leaves_no_fix() {
        // A wall along x = 7 hides the east pair from a truck at x = 4.
        let wall = Surface::rect(&Pose2::new(7.0, 4.0, 0.0), 0.2, 20.0, Seen::Fixed);
        let mut nav = ReflectorNav::new(
            ReflectorNavSettings::default(),
            &room(),
            &wall,
            (8.0, 0.0),
            0.0,
        );
        let r = sweep_at(&mut nav, Pose2::new(4.0, 3.0, 0.0));
        assert_eq!((r.pose, r.detected), (None, 2));
    }

    #[test]
    fn a_missing_reflector_is_not_measured_but_stays_in_the_map() {
        let settings = ReflectorNavSettings {
            missing_reflectors: vec!["c".into(), "d".into()],
            ..ReflectorNavSettings::default()
        };
        settings.validate(&room()).expect("names exist");
        let mut nav = ReflectorNav::new(settings, &room(), &[], (8.0, 0.0), 0.0);
        let r = sweep_at(&mut nav, Pose2::new(4.0, 3.0, 0.0));
        assert_eq!((r.pose, r.detected), (None, 2));
        let bad = ReflectorNavSettings {
            missing_reflectors: vec!["e".into()],
            ..ReflectorNavSettings::default()
        };
        let e = bad.validate(&room()).expect_err("unknown name");
        assert_eq!(e.field.as_deref(), Some("missing_reflectors"));
    }

    /// The fix a truck driving at 1 m/s while turning gets at the end of its first
    /// sweeps, with or without the speed input (exact odometry, no noise).
    fn moving_fix_error(speed_input: bool) -> f64 {
        let settings = ReflectorNavSettings {
            speed_input,
            ..ReflectorNavSettings::default()
        };
        let mut nav = ReflectorNav::new(settings, &room(), &[], (8.0, 0.0), 0.0);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let pose_at = |t: f64| Pose2::new(2.0 + t, 2.0 + 0.3 * t * t, 0.6 * t);
        let mut worst = 0.0f64;
        for k in 0..=150 {
            let t = k as f64 * 0.01;
            let truth = pose_at(t);
            let input = LocalizerInput {
                t_s: t,
                truth,
                predicted: Some(truth),
                // Odometry in a frame of its own: only its increments matter.
                odometry: Some(Pose2::new(
                    truth.x_m - 50.0,
                    truth.y_m + 7.0,
                    truth.heading_rad,
                )),
                occluders: Vec::new(),
            };
            if let Some(r) = nav.update(&input, &mut rng)
                && t > 0.2
            {
                let pose = r.pose.expect("four reflectors in sight");
                worst = worst.max(pose.distance_to(&truth));
            }
        }
        worst
    }

    #[test]
    fn the_speed_input_removes_the_sweeps_motion_smear() {
        let (with, without) = (moving_fix_error(true), moving_fix_error(false));
        // A reflector is measured up to one period (0.125 m at 1 m/s) before the sweep
        // ends: without the input the fix is centimetres off, with it exact.
        assert!(without > 0.02, "without the speed input: {without} m");
        assert!(with < 1e-3, "with it: {with} m");
    }
}
