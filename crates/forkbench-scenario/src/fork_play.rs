//! The forks' lateral play in the pallet's pockets against the scenario's lateral tolerance: a tolerance wider than the play passes entries that put a fork on a block.

use forkbench_core::{ForkliftSpec, PalletSpec};

/// How far the truck may sit off the pockets' centre line with both forks still inside
/// their pockets: half a pocket's width less half a fork's, less how far the forks'
/// spacing puts them off the pockets' centres.
pub fn lateral_play_m(truck: &ForkliftSpec, pallet: &PalletSpec) -> f64 {
    let centre = pallet.pocket_offsets_m()[0].abs();
    (pallet.pocket_width_m - truck.fork_width_m) / 2.0 - (truck.fork_spacing_m / 2.0 - centre).abs()
}

/// The warning for a lateral tolerance wider than the forks' play (`kind` names the
/// pallet), or none.
pub(crate) fn wide_tolerance(
    lateral_m: f64,
    truck: &ForkliftSpec,
    (pallet, kind): (&PalletSpec, &str),
) -> Option<String> {
    let play = lateral_play_m(truck, pallet);
    (lateral_m > play + 1e-9).then(|| {
        format!(
            "tolerances.lateral_m = {lateral_m} m is wider than the forks' play in the pockets \
             ({play:.3} m for {kind}: pockets {} m wide, forks {} m wide at {} m spacing): an \
             entry off by more than the play passes the lateral check with a fork on a block \
             or stringer (contact_force and pallet_displaced may still catch it)",
            pallet.pocket_width_m, truck.fork_width_m, truck.fork_spacing_m
        )
    })
}
