//! The pick's criteria, each once: its failure, what it measures, and its check against its limit, in the order of blame.

use forkbench_core::{ForkliftSpec, PalletSpec};

use crate::outcome::{Failure, TrialOutcome};
use crate::scenario::Limits;

/// What the pick's criteria read: the outcome's measurements, the limits, the truck and
/// pallet, and what the drive saw.
#[derive(Debug, Clone, Copy)]
pub(super) struct Judged<'a> {
    pub out: &'a TrialOutcome,
    pub tol: &'a Limits,
    pub truck: &'a ForkliftSpec,
    pub pallet: &'a PalletSpec,
    pub collision: bool,
    pub timed_out: bool,
    /// The scenario's time limit.
    pub timeout_s: f64,
    /// The fork middle farthest from its pocket's centre line, laterally.
    pub worst_pocket_miss_m: f64,
}

/// One criterion of the pick: the failure it names, what it measures (for documents and
/// listings), and its check (the value against the limit when broken).
#[derive(Debug, Clone, Copy)]
pub struct Criterion {
    pub failure: Failure,
    pub measures: &'static str,
    check: fn(&Judged<'_>) -> Option<String>,
}

/// The pick's criteria in the order of blame: the first broken one is the verdict.
/// Adding one is a `Failure` variant and a row here.
pub const PICK_CRITERIA: &[Criterion] = &[
    Criterion {
        failure: Failure::Collision,
        measures: "the truck touched a rack or wall",
        check: collision,
    },
    Criterion {
        failure: Failure::ContactForce,
        measures: "the largest fork–pallet force before full depth",
        check: contact_force,
    },
    Criterion {
        failure: Failure::PalletDisplaced,
        measures: "how far the pallet was pushed and turned",
        check: pallet_displaced,
    },
    Criterion {
        failure: Failure::LateralError,
        measures: "the fork root's offset from the pocket centre line at entry",
        check: lateral_error,
    },
    Criterion {
        failure: Failure::HeadingError,
        measures: "the heading off the pallet axis at entry",
        check: heading_error,
    },
    Criterion {
        failure: Failure::Timeout,
        measures: "whether the truck stood at the goal within the time limit",
        check: timeout,
    },
    Criterion {
        failure: Failure::InsertionDepth,
        measures: "how deep the fork tips went past the pallet face",
        check: insertion_depth,
    },
    Criterion {
        failure: Failure::ForkOutsidePocket,
        measures: "the fork middle's lateral distance from its pocket centre",
        check: fork_outside_pocket,
    },
];

/// Every broken criterion, in the order of blame, each with its value and limit.
pub(super) fn broken(j: &Judged<'_>) -> Vec<(Failure, String)> {
    PICK_CRITERIA
        .iter()
        .filter_map(|c| (c.check)(j).map(|why| (c.failure, why)))
        .collect()
}

fn collision(j: &Judged<'_>) -> Option<String> {
    j.collision
        .then(|| "truck touched a rack or wall".to_owned())
}

fn contact_force(j: &Judged<'_>) -> Option<String> {
    (j.out.max_contact_force_n > j.tol.contact_force_n).then(|| {
        format!(
            "fork–pallet contact {:.0} N > {:.0} N before full depth",
            j.out.max_contact_force_n, j.tol.contact_force_n
        )
    })
}

fn pallet_displaced(j: &Judged<'_>) -> Option<String> {
    let (out, tol) = (j.out, j.tol);
    (out.pallet_displacement_m > tol.pallet_displacement_m
        || out.pallet_rotation_rad.abs() > tol.pallet_rotation_rad)
        .then(|| {
            format!(
                "pallet moved {:.3} m and turned {:.2}° (limits {} m, {}°)",
                out.pallet_displacement_m,
                out.pallet_rotation_rad.to_degrees(),
                tol.pallet_displacement_m,
                tol.pallet_rotation_deg()
            )
        })
}

fn lateral_error(j: &Judged<'_>) -> Option<String> {
    let limit = j.tol.lateral_m;
    j.out
        .lateral_error_m
        .filter(|e| e.abs() > limit)
        .map(|e| format!("{e:.3} m off the pocket centre line at entry (limit {limit} m)"))
}

fn heading_error(j: &Judged<'_>) -> Option<String> {
    let tol = j.tol;
    j.out
        .heading_error_rad
        .filter(|e| e.abs() > tol.heading_rad)
        .map(|e| {
            format!(
                "{:.2}° off the pallet axis at entry (limit {}°)",
                e.to_degrees(),
                tol.heading_deg()
            )
        })
}

fn timeout(j: &Judged<'_>) -> Option<String> {
    j.timed_out
        .then(|| format!("not stopped at the goal after {} s", j.timeout_s))
}

fn insertion_depth(j: &Judged<'_>) -> Option<String> {
    (j.out.insertion_depth_m < j.tol.insertion_depth_m).then(|| {
        format!(
            "forks {:.3} m deep (required {} m)",
            j.out.insertion_depth_m, j.tol.insertion_depth_m
        )
    })
}

fn fork_outside_pocket(j: &Judged<'_>) -> Option<String> {
    let clearance = (j.pallet.pocket_width_m - j.truck.fork_width_m) / 2.0;
    let miss = j.worst_pocket_miss_m;
    (miss > clearance).then(|| {
        format!("a fork is {miss:.3} m from its pocket centre (clearance {clearance:.4} m)")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order of blame the README and ARCHITECTURE.md give, each criterion once.
    #[test]
    fn the_pick_is_judged_in_the_documented_order() {
        let names: Vec<_> = PICK_CRITERIA.iter().map(|c| c.failure.name()).collect();
        assert_eq!(
            names,
            [
                "collision",
                "contact_force",
                "pallet_displaced",
                "lateral_error",
                "heading_error",
                "timeout",
                "insertion_depth",
                "fork_outside_pocket"
            ]
        );
    }
}
