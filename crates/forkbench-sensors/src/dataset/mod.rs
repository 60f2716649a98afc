//! Labelled scans on demand: randomised scenes (a pallet or none, clutter around it) scanned by a scanner model, each with the truth a detector is scored against.

mod scene;
mod spec;

pub use scene::Scene;
pub use spec::{
    CLUTTER_KINDS, ClutterSpec, DatasetSpec, MAX_SCANS, VIEW_BEARING_MARGIN_DEG,
    VIEW_RANGE_MARGIN_M,
};

use forkbench_core::hash::fnv1a;
use forkbench_core::signal::Scan;
use forkbench_core::{PalletSpec, Pose2};
use rand::{RngExt as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use crate::scan::{Errors, ScannerConfig, scan};

/// One scan and its truth, in the scanner's own frame (x ahead, y left).
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    pub index: usize,
    pub scan: Scan,
    /// The pallet's face centre, heading into the pallet; `None`: no pallet in the scene.
    pub face: Option<Pose2>,
    /// Where the detector is told to look: the face (or, without a pallet, where one
    /// would stand) off by the spec's prior error.
    pub prior: Pose2,
    /// The clutter placed, in order.
    pub clutter: Vec<&'static str>,
}

/// A random stream of scan `index` for one purpose: keyed by what it is for, so a
/// setting that draws more of one leaves the others' draws as they were.
fn stream(seed: u64, index: usize, purpose: &str) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(fnv1a(
        format!("dataset {seed} scan {index} {purpose}").into_bytes(),
    ))
}

/// Scan `index` of the set `spec` describes, of `pallet` seen by `scanner` (its mount
/// ignored: the scan is in the scanner's frame).
pub fn sample(
    spec: &DatasetSpec,
    pallet: &PalletSpec,
    scanner: &ScannerConfig,
    index: usize,
) -> Sample {
    let mut presence = stream(spec.seed, index, "presence");
    let present = presence.random_bool(spec.present_fraction);
    let face = present.then(|| scene::draw_face(spec, &mut stream(spec.seed, index, "pallet")));
    let prior = prior_of(spec, face, index);
    let view = (scanner.range_max_m, scanner.fov_rad / 2.0);
    let scene = scene::build(
        spec,
        pallet,
        face.as_ref(),
        view,
        &mut stream(spec.seed, index, "clutter"),
    );
    let sensor = Pose2::new(0.0, 0.0, 0.0);
    let scan = if spec.noise {
        let mut bias = stream(spec.seed, index, "bias");
        let bias_m = scanner.draw_bias(&mut bias);
        let mut rng = stream(spec.seed, index, "noise");
        let errors = Errors::Modelled {
            bias_m,
            rng: &mut rng,
        };
        scan(scanner, &scene, sensor, errors)
    } else {
        scan::<ChaCha8Rng>(scanner, &scene, sensor, Errors::Ideal)
    };
    Sample {
        index,
        scan,
        face,
        prior,
        clutter: scene.clutter,
    }
}

/// The prior of scan `index`: its face (or one drawn where a pallet would stand) off by
/// a Gaussian error of the spec's σ, from streams of their own.
fn prior_of(spec: &DatasetSpec, face: Option<Pose2>, index: usize) -> Pose2 {
    let at =
        face.unwrap_or_else(|| scene::draw_face(spec, &mut stream(spec.seed, index, "prior slot")));
    let mut rng = stream(spec.seed, index, "prior");
    let mut z = || -> f64 { rng.sample(rand_distr::StandardNormal) };
    Pose2::new(
        at.x_m + spec.prior_error_m * z(),
        at.y_m + spec.prior_error_m * z(),
        at.heading_rad + spec.prior_error_deg.to_radians() * z(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_keyed_by_seed_and_index_and_hold_what_they_say() {
        let spec = DatasetSpec {
            scans: 40,
            ..DatasetSpec::default()
        };
        let p = PalletSpec::field_1200();
        let cfg = ScannerConfig::tim561();
        let bits =
            |s: &Sample| -> Vec<u64> { s.scan.ranges_m.iter().map(|r| r.to_bits()).collect() };
        let a = sample(&spec, &p, &cfg, 7);
        let again = sample(&spec, &p, &cfg, 7);
        assert!(bits(&a) == bits(&again) && a.face == again.face && a.clutter == again.clutter);
        assert!(bits(&a) != bits(&sample(&spec, &p, &cfg, 8)));
        let present = (0..40)
            .filter(|i| sample(&spec, &p, &cfg, *i).face.is_some())
            .count();
        assert!((10..=30).contains(&present), "{present}");
        // Without noise, a present pallet's face returns at its range.
        let ideal = DatasetSpec {
            noise: false,
            ..spec.clone()
        };
        for i in 0..40 {
            let s = sample(&ideal, &p, &cfg, i);
            let Some(f) = s.face else { continue };
            if s.clutter.contains(&"occluder") {
                continue;
            }
            let b = f.y_m.atan2(f.x_m);
            let k = ((b - s.scan.angle_min_rad) / s.scan.angle_step_rad).round() as usize;
            let r = f.x_m.hypot(f.y_m);
            let near = s.scan.ranges_m[k.saturating_sub(40)..(k + 40).min(s.scan.ranges_m.len())]
                .iter()
                .any(|x| (x - r).abs() < 0.3);
            assert!(near, "scan {i}: nothing near the face at {r:.2} m");
        }
    }
}
