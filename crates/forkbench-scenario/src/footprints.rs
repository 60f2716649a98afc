//! The truck body's and the pallet's footprints, as overlap and clearance checks use them.

use forkbench_core::{ForkliftSpec, PalletSpec};
use forkbench_geom::Footprint;

/// The truck body's footprint referenced to the fork root: the chassis ends there (forks
/// excluded, since they are meant to enter the pallet).
pub fn truck_footprint(truck: &ForkliftSpec) -> Footprint {
    Footprint {
        length_m: truck.body_length_m,
        width_m: truck.body_width_m,
        centre_ahead_m: -truck.body_length_m / 2.0,
    }
}

/// The pallet's footprint referenced to its face centre.
pub fn pallet_footprint(pallet: &PalletSpec) -> Footprint {
    Footprint {
        length_m: pallet.depth_m,
        width_m: pallet.width_m,
        centre_ahead_m: pallet.depth_m / 2.0,
    }
}

/// Layouts may touch (a pallet against a rack's back, a truck parked flush to a wall):
/// footprints are shrunk by this on every side before the overlap test.
const LAYOUT_TOLERANCE_M: f64 = 1e-3;

/// `fp` shrunk by the layout tolerance on every side, for overlap tests that let shapes touch.
pub fn shrunk(fp: Footprint) -> Footprint {
    Footprint {
        length_m: fp.length_m - 2.0 * LAYOUT_TOLERANCE_M,
        width_m: fp.width_m - 2.0 * LAYOUT_TOLERANCE_M,
        ..fp
    }
}
