//! The pocket detector's tests: faces found on simulated stringers, candidates ranked, and what it refuses.
use super::*;
use crate::scan::{Errors, RayHit, ScannerConfig, Seen, Surface, WorldView, scan};

/// Boxes (centre pose, length along its heading, width) as a world.
struct Boxes(Vec<(Pose2, f64, f64)>);

impl WorldView for Boxes {
    fn cast_ray(&self, _: [f64; 2], _: [f64; 2], _: f64) -> Option<RayHit> {
        None
    }

    fn surfaces_near(&self, _: [f64; 2], _: f64, out: &mut Vec<Surface>) {
        for (c, l, w) in &self.0 {
            out.extend(Surface::rect(c, *l, *w, Seen::Fixed));
        }
    }
}

fn ideal(world: &Boxes) -> Scan {
    let cfg = ScannerConfig::tim561();
    scan::<rand::rngs::ThreadRng>(&cfg, world, Pose2::new(0.0, 0.0, 0.0), Errors::Ideal)
}

fn assert_close(got: &Pose2, want: &Pose2, tol_m: f64, tol_rad: f64) {
    let dh = forkbench_core::units::wrap_angle(got.heading_rad - want.heading_rad);
    assert!(
        got.distance_to(want) < tol_m && dh.abs() < tol_rad,
        "got {got:?}, want {want:?}"
    );
}

#[test]
fn a_noise_free_scan_gives_the_face_pose() {
    let p = PalletSpec::field_1200();
    for truth in [
        Pose2::new(4.0, 0.3, 10f64.to_radians()),
        Pose2::new(6.5, 1.5, -15f64.to_radians()),
        Pose2::new(2.0, -0.4, 0.0),
    ] {
        let world = Boxes(p.part_boxes(&truth));
        let d = detect(&DetectorConfig::default(), &ideal(&world), &p, None).expect("found");
        assert_eq!(d.stringers, 3);
        // Exact up to the beam spacing: each stringer's edges are known to within
        // one step at its range, so its centre to half of one.
        let half_step = 0.5 * truth.x_m.hypot(truth.y_m) * 0.33f64.to_radians();
        assert_close(&d.face, &truth, half_step + 0.002, 0.5f64.to_radians());
        assert!(d.rms_m < 0.005, "{d:?}");
    }
}

#[test]
fn a_hidden_stringer_leaves_two_and_the_prior_decides() {
    let p = PalletSpec::field_1200();
    let truth = Pose2::new(4.0, 0.0, 0.0);
    let mut boxes = p.part_boxes(&truth);
    // An upright in front of the right-hand stringer (negative y).
    let y = -p.edge_part_m().1;
    boxes.push((Pose2::new(3.0, y, 0.0), 0.1, 0.3));
    let world = Boxes(boxes);
    let prior = Pose2::new(4.1, 0.1, 0.05);
    let d = detect(&DetectorConfig::default(), &ideal(&world), &p, Some(&prior)).expect("found");
    assert_eq!(d.stringers, 2);
    assert_close(&d.face, &truth, 0.01, 0.5f64.to_radians());
}

#[test]
fn no_pallet_is_not_found() {
    let p = PalletSpec::field_1200();
    // A wall and a lone box the width of a stringer.
    let world = Boxes(vec![
        (Pose2::new(6.0, 0.0, 0.0), 0.2, 8.0),
        (Pose2::new(3.0, 1.0, 0.0), 0.5, p.edge_part_m().0),
    ]);
    assert_eq!(
        detect(&DetectorConfig::default(), &ideal(&world), &p, None),
        None
    );
}

/// With the TiM561's errors (20 mm noise, a per-scan bias within ±60 mm, mixed
/// returns at the stringers' edges), the pallet is still found at 4 m and the face
/// heading stays within a few degrees.
#[test]
fn a_modelled_tim561_scan_still_finds_the_pallet() {
    use rand::SeedableRng;
    let p = PalletSpec::field_1200();
    let truth = Pose2::new(4.0, 0.3, 10f64.to_radians());
    let world = Boxes(p.part_boxes(&truth));
    let cfg = ScannerConfig::tim561();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut heading_errors = Vec::new();
    let mut lateral = Vec::new();
    for _ in 0..50 {
        let bias_m = cfg.draw_bias(&mut rng);
        let e = Errors::Modelled {
            bias_m,
            rng: &mut rng,
        };
        let sc = scan(&cfg, &world, Pose2::new(0.0, 0.0, 0.0), e);
        if let Some(d) = detect(&DetectorConfig::default(), &sc, &p, None) {
            let local = truth.to_local(&d.face);
            heading_errors.push(local.heading_rad.abs().to_degrees());
            lateral.push(local.y_m.abs());
        }
    }
    assert!(
        heading_errors.len() >= 45,
        "found in {} of 50",
        heading_errors.len()
    );
    heading_errors.sort_by(f64::total_cmp);
    lateral.sort_by(f64::total_cmp);
    let (h, l) = (
        heading_errors[heading_errors.len() / 2],
        lateral[lateral.len() / 2],
    );
    eprintln!(
        "found in {} of 50; median |heading error| {h:.2}°, |lateral| {l:.3} m",
        lateral.len()
    );
    assert!(
        h < 3.0 && l < 0.03,
        "median |heading| {h}°, |lateral| {l} m"
    );
}
