//! The face-model fit against an analytic ray cast of the pallet's stringers (no noise): within 5 mm and 0.3° at 6.7 m over the faces' angles, where the pocket detector is off by up to half a beam step; and every built-in pallet kind, from its front and its side, found by both detectors where it stands.

use forkbench_core::pallet::{PalletFace, PalletModel};
use forkbench_core::units::wrap_angle;
use forkbench_core::{PalletSpec, Pose2};
use forkbench_sensors::detect::{DetectorConfig, detect};
use forkbench_sensors::face_fit::refine;
use forkbench_sensors::scan::{Errors, RayHit, ScannerConfig, Seen, Surface, WorldView, scan};

/// The pallet's solid parts (stringers or blocks) as boxes, seen exactly.
struct Stringers(Vec<(Pose2, f64, f64)>);

impl Stringers {
    fn of(pallet: &PalletSpec, face: &Pose2) -> Self {
        Self(pallet.part_boxes(face))
    }
}

impl WorldView for Stringers {
    fn cast_ray(&self, _: [f64; 2], _: [f64; 2], _: f64) -> Option<RayHit> {
        None
    }

    fn surfaces_near(&self, _: [f64; 2], _: f64, out: &mut Vec<Surface>) {
        for (c, l, w) in &self.0 {
            out.extend(Surface::rect(c, *l, *w, Seen::Fixed));
        }
    }
}

/// (lateral, heading) error of `got` against `truth`, in the truth's face frame.
fn error(truth: &Pose2, got: &Pose2) -> (f64, f64) {
    let e = truth.to_local(got);
    (e.y_m.hypot(e.x_m), wrap_angle(e.heading_rad))
}

#[test]
fn the_face_fit_is_within_5_mm_and_0_3_degrees_at_6_7_m_without_noise() {
    let pallet = PalletSpec::field_1200();
    let cfg = DetectorConfig::default();
    let scanner = ScannerConfig::tim561();
    let (mut worst_fit, mut worst_pockets) = ((0.0f64, 0.0f64), (0.0f64, 0.0f64));
    let mut n = 0;
    for bearing_deg in [-10.0, -4.3, 0.0, 3.1, 10.0] {
        for turn_deg in [-30.0, -15.0, -7.0, 0.0, 5.0, 15.0, 30.0] {
            let b = f64::to_radians(bearing_deg);
            let face = Pose2::new(6.7 * b.cos(), 6.7 * b.sin(), b + f64::to_radians(turn_deg));
            let world = Stringers::of(&pallet, &face);
            let s = scan::<rand::rngs::ThreadRng>(
                &scanner,
                &world,
                Pose2::new(0.0, 0.0, 0.0),
                Errors::Ideal,
            );
            let Some(first) = detect(&cfg, &s, &pallet, None) else {
                continue;
            };
            n += 1;
            let fit = refine(&cfg, &s, &pallet, &first);
            let (e, h) = error(&face, &fit.face);
            worst_fit = (worst_fit.0.max(e), worst_fit.1.max(h.abs()));
            let (e, h) = error(&face, &first.face);
            worst_pockets = (worst_pockets.0.max(e), worst_pockets.1.max(h.abs()));
        }
    }
    assert!(n >= 30, "found in {n} of 35 placements");
    eprintln!(
        "worst over {n}: face fit {:.1} mm {:.3}°, pockets {:.1} mm {:.3}°",
        worst_fit.0 * 1e3,
        worst_fit.1.to_degrees(),
        worst_pockets.0 * 1e3,
        worst_pockets.1.to_degrees()
    );
    assert!(
        worst_fit.0 <= 0.005 && worst_fit.1.to_degrees() <= 0.3,
        "face fit {worst_fit:?}"
    );
}

/// Over 2–8 m and ±30° with the TiM561's own errors (range noise, the per-scan bias, the
/// light spot), the fit keeps the pocket detector's heading and stays near its lateral
/// error in the median (better head-on and at 30°, worse at 15° beyond 6 m: the README
/// has the table).
#[test]
fn with_the_scanners_errors_the_fit_stays_near_the_pockets() {
    use rand::SeedableRng as _;
    let pallet = PalletSpec::field_1200();
    let cfg = DetectorConfig::default();
    let scanner = ScannerConfig::tim561();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (mut fit, mut pockets) = (vec![], vec![]);
    for range in [2.0, 4.0, 6.7, 8.0] {
        for turn_deg in [-30.0, -15.0, 0.0, 15.0, 30.0] {
            for k in 0..10 {
                let b = f64::to_radians(k as f64 - 4.5);
                let face = Pose2::new(
                    range * b.cos(),
                    range * b.sin(),
                    b + f64::to_radians(turn_deg),
                );
                let world = Stringers::of(&pallet, &face);
                let bias_m = scanner.draw_bias(&mut rng);
                let errors = Errors::Modelled {
                    bias_m,
                    rng: &mut rng,
                };
                let s = scan(&scanner, &world, Pose2::new(0.0, 0.0, 0.0), errors);
                let Some(first) = detect(&cfg, &s, &pallet, None) else {
                    continue;
                };
                let refined = refine(&cfg, &s, &pallet, &first);
                let lat = |d: &Pose2| {
                    let e = face.to_local(d);
                    (e.y_m.abs(), wrap_angle(e.heading_rad).abs())
                };
                fit.push(lat(&refined.face));
                pockets.push(lat(&first.face));
            }
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (mut fl, mut fh): (Vec<f64>, Vec<f64>) = fit.iter().copied().unzip();
    let (mut pl, mut ph): (Vec<f64>, Vec<f64>) = pockets.iter().copied().unzip();
    let (fl, fh, pl, ph) = (
        median(&mut fl),
        median(&mut fh),
        median(&mut pl),
        median(&mut ph),
    );
    eprintln!(
        "{} of 200 found; median lateral {:.1} mm against {:.1}, heading {:.2}° against {:.2}°",
        fit.len(),
        fl * 1e3,
        pl * 1e3,
        fh.to_degrees(),
        ph.to_degrees()
    );
    assert!(fit.len() >= 150, "{}", fit.len());
    assert!(
        fl <= pl * 1.2 && fh <= ph * 1.05,
        "lateral {fl} vs {pl}, heading {fh} vs {ph}"
    );
}

/// (worst distance, worst heading error) of each detector over placements at `range_m`,
/// and how many placements were found.
fn worst(pallet: &PalletSpec, range_m: f64) -> ((f64, f64), (f64, f64), usize, usize) {
    let cfg = DetectorConfig::default();
    let scanner = ScannerConfig::tim561();
    let (mut pockets, mut fit, mut found, mut n) = ((0.0f64, 0.0f64), (0.0f64, 0.0f64), 0, 0);
    for bearing_deg in [-10.0, -3.1, 0.0, 4.3, 10.0] {
        for turn_deg in [-20.0, -7.0, 0.0, 5.0, 20.0] {
            n += 1;
            let b = f64::to_radians(bearing_deg);
            let face = Pose2::new(
                range_m * b.cos(),
                range_m * b.sin(),
                b + f64::to_radians(turn_deg),
            );
            let world = Stringers::of(pallet, &face);
            let s = scan::<rand::rngs::ThreadRng>(
                &scanner,
                &world,
                Pose2::new(0.0, 0.0, 0.0),
                Errors::Ideal,
            );
            let Some(first) = detect(&cfg, &s, pallet, None) else {
                continue;
            };
            found += 1;
            let err = |d: &Pose2| {
                let e = face.to_local(d);
                (e.y_m.hypot(e.x_m), wrap_angle(e.heading_rad).abs())
            };
            let (e, h) = err(&first.face);
            pockets = (pockets.0.max(e), pockets.1.max(h));
            let (e, h) = err(&refine(&cfg, &s, pallet, &first).face);
            fit = (fit.0.max(e), fit.1.max(h));
        }
    }
    (pockets, fit, found, n)
}

#[test]
fn every_kind_from_every_face_is_found_where_it_stands() {
    let faces = [PalletFace::Front, PalletFace::Left];
    let mut report = Vec::new();
    for name in PalletModel::builtin_names() {
        for face in faces {
            let pallet = PalletModel::builtin(name)
                .expect("a built-in kind")
                .entered_from(face)
                .expect("an entry face of the kind");
            for range in [3.0, 6.0] {
                let (p, f, found, n) = worst(&pallet, range);
                report.push((name, face, range, p, f, found, n));
                eprintln!(
                    "{name:>14} {:<5} {range} m: found {found}/{n}; pockets {:.1} mm {:.2}°, face fit {:.1} mm {:.2}°",
                    face.name(),
                    p.0 * 1e3,
                    p.1.to_degrees(),
                    f.0 * 1e3,
                    f.1.to_degrees()
                );
            }
        }
    }
    for (name, face, range, _, fit, found, n) in report {
        // GMA's 35 mm stringer ends are one or two TiM561 beams wide: not asserted.
        if name == "gma-48x40" && face == PalletFace::Front {
            continue;
        }
        assert_eq!(found, n, "{name} {face:?} at {range} m");
        assert!(
            fit.0 <= 0.015 && fit.1.to_degrees() <= 0.7,
            "{name} {face:?} at {range} m: face fit {fit:?}"
        );
    }
}
