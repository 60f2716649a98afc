//! The pick's fixed criteria, each a row: its failure, what it measures, whether a breach is final, the verdict's row, its check against its limit and its margin; each row is a `StepCriterion` judged on the pick's measurements, first in the order of blame.

use super::{Judged, StepCriterion, StepView};
use crate::outcome::{Failure, TrialOutcome};
use crate::tolerances::Limits;

/// One line of a verdict's table: what a criterion measured against its limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    pub label: &'static str,
    /// The value with its unit (`—` when nothing was measured).
    pub value: String,
    /// The limit with its unit.
    pub limit: String,
}

/// One criterion of the pick: the failure it names, what it measures (for documents and
/// listings), whether a breach is final, the verdict's row (from a judged outcome), and
/// its check (the value against the limit when broken).
#[derive(Debug, Clone)]
pub struct Criterion {
    pub failure: Failure,
    pub measures: &'static str,
    /// No later step can undo a breach (the truck touched a rack, the entry is past), so
    /// a pick a caller drives ends on it; a breach that is not final may still mend
    /// (the forks not deep yet).
    pub irreversible: bool,
    reading: Option<fn(&TrialOutcome, &Limits) -> Reading>,
    check: fn(&Judged<'_>) -> Option<String>,
    /// Signed margin to its limit, (limit − measured) / limit: negative exactly when
    /// broken; −1 when broken for a criterion with no continuous measure; `None` when
    /// nothing was measured (the forks never reached the face) or when the measure is a
    /// target the drive holds (a depth reached).
    margin: fn(&Judged<'_>) -> Option<f64>,
}

impl Criterion {
    /// What it measured in `out` against `tol`, for a verdict's table (`None`: its
    /// measurement is not kept in the outcome).
    pub fn reading(&self, out: &TrialOutcome, tol: &Limits) -> Option<Reading> {
        self.reading.map(|r| r(out, tol))
    }
}

/// The row as a criterion of every pick: it measures nothing itself (its measurements
/// are the outcome's own fields, `PickMeasures`), so it judges what it is handed.
impl StepCriterion for Criterion {
    fn name(&self) -> &'static str {
        self.failure.fixed_name().unwrap_or("criterion")
    }
    fn measure(&self) -> Option<&'static str> {
        None
    }
    fn describe(&self) -> &'static str {
        self.measures
    }
    fn observe(&mut self, _view: &StepView<'_>) {}
    fn value(&self) -> Option<f64> {
        None
    }
    fn broken(&self) -> Option<String> {
        None
    }
    fn irreversible(&self) -> bool {
        self.irreversible
    }
    fn judge(&self, judged: &Judged<'_>) -> Option<String> {
        (self.check)(judged)
    }
    fn margin(&self, judged: &Judged<'_>) -> Option<f64> {
        (self.margin)(judged)
    }
}

/// Row `I` of [`PICK_CRITERIA`], fresh for one trial (a registry lists criteria by their
/// constructors).
pub(super) fn row<const I: usize>() -> Box<dyn StepCriterion> {
    Box::new(PICK_CRITERIA[I].clone())
}

impl TrialOutcome {
    /// Whether the trial broke `failure`: its verdict, or one of `also_failed`.
    pub fn broke(&self, failure: &Failure) -> bool {
        self.broke_named(failure.name())
    }

    /// Whether the trial broke the criterion called `name` (a failure's name stands for
    /// one failure): its verdict, or one of `also_failed`.
    pub fn broke_named(&self, name: &str) -> bool {
        self.failure.as_ref().is_some_and(|f| f.name() == name)
            || self
                .also_failed
                .iter()
                .any(|a| a.split(':').next() == Some(name))
    }
}

/// The pick's fixed criteria in the order of blame, before every other
/// [`StepCriterion`]: the first broken one is the verdict. Adding one is a `Failure`
/// variant, a row here and its constructor in [`super::STEP_CRITERIA`].
pub const PICK_CRITERIA: &[Criterion] = &[
    Criterion {
        failure: Failure::Collision,
        measures: "the truck touched a rack or wall",
        irreversible: true,
        reading: None,
        check: collision,
        margin: |j| j.m.collision.then_some(-1.0),
    },
    Criterion {
        failure: Failure::ContactForce,
        measures: "the largest fork–pallet force before full depth",
        irreversible: true,
        reading: Some(|o, t| Reading {
            label: "max contact force",
            value: format!("{:.0} N", o.max_contact_force_n),
            limit: format!("{:.0} N", t.contact_force_n),
        }),
        check: contact_force,
        margin: |j| Some(ratio(j.tol.contact_force_n, j.m.max_contact_force_n)),
    },
    Criterion {
        failure: Failure::PalletDisplaced,
        measures: "how far the pallet was pushed and turned",
        irreversible: true,
        reading: Some(|o, t| Reading {
            label: "pallet moved, turned",
            value: format!(
                "{:.3} m, {:.2}°",
                o.pallet_displacement_m,
                o.pallet_rotation_rad.to_degrees()
            ),
            limit: format!(
                "{} m, {}°",
                t.pallet_displacement_m,
                t.pallet_rotation_deg()
            ),
        }),
        check: pallet_displaced,
        margin: |j| {
            Some(
                ratio(j.tol.pallet_displacement_m, j.m.pallet_displacement_m).min(ratio(
                    j.tol.pallet_rotation_rad,
                    j.m.pallet_rotation_rad.abs(),
                )),
            )
        },
    },
    Criterion {
        failure: Failure::LateralError,
        measures: "the fork root's offset from the pocket centre line at entry",
        irreversible: true,
        reading: Some(|o, t| Reading {
            label: "lateral offset at entry",
            value: o
                .lateral_error_m
                .map_or("—".into(), |v| format!("{v:.3} m")),
            limit: format!("{} m", t.lateral_m),
        }),
        check: lateral_error,
        margin: |j| j.m.lateral_error_m.map(|e| ratio(j.tol.lateral_m, e.abs())),
    },
    Criterion {
        failure: Failure::HeadingError,
        measures: "the heading off the pallet axis at entry",
        irreversible: true,
        reading: Some(|o, t| Reading {
            label: "heading at entry",
            value: o
                .heading_error_rad
                .map_or("—".into(), |v| format!("{:.2}°", v.to_degrees())),
            limit: format!("{}°", t.heading_deg()),
        }),
        check: heading_error,
        margin: |j| {
            j.m.heading_error_rad
                .map(|e| ratio(j.tol.heading_rad, e.abs()))
        },
    },
    Criterion {
        failure: Failure::Timeout,
        measures: "whether the truck stood at the goal within the time limit",
        irreversible: false,
        reading: None,
        check: timeout,
        margin: |j| j.m.timed_out.then_some(-1.0),
    },
    Criterion {
        failure: Failure::InsertionDepth,
        measures: "how deep the fork tips went past the pallet face",
        irreversible: false,
        reading: Some(|o, t| Reading {
            label: "fork depth",
            value: Some(o.insertion_depth_m)
                .filter(|v| v.is_finite())
                .map_or("—".into(), |v| format!("{v:.3} m")),
            limit: format!("≥ {} m", t.insertion_depth_m),
        }),
        check: insertion_depth,
        // Only a shortfall counts: the drive holds the forks at their target depth, so a
        // met depth's margin is the same in every pick and says nothing of how near it
        // came to failing.
        margin: |j| {
            let need = j.tol.insertion_depth_m;
            Some(j.m.insertion_depth_m)
                .filter(|d| d.is_finite() && *d < need)
                .map(|d| (d - need) / need)
        },
    },
    Criterion {
        failure: Failure::ForkOutsidePocket,
        measures: "the fork middle's lateral distance from its pocket centre",
        irreversible: false,
        reading: None,
        check: fork_outside_pocket,
        margin: |j| {
            let clearance = (j.pallet.pocket_width_m - j.truck.fork_width_m) / 2.0;
            Some(ratio(clearance, j.m.worst_pocket_miss_m))
        },
    },
];

/// (limit − measured) / limit, for a limit above zero (else the sign alone).
fn ratio(limit: f64, measured: f64) -> f64 {
    if limit > 0.0 {
        (limit - measured) / limit
    } else if measured > limit {
        -1.0
    } else {
        0.0
    }
}

fn collision(j: &Judged<'_>) -> Option<String> {
    j.m.collision
        .then(|| "truck touched a rack or wall".to_owned())
}

fn contact_force(j: &Judged<'_>) -> Option<String> {
    (j.m.max_contact_force_n > j.tol.contact_force_n).then(|| {
        format!(
            "fork–pallet contact {:.0} N > {:.0} N before full depth",
            j.m.max_contact_force_n, j.tol.contact_force_n
        )
    })
}

fn pallet_displaced(j: &Judged<'_>) -> Option<String> {
    let (m, tol) = (&j.m, j.tol);
    (m.pallet_displacement_m > tol.pallet_displacement_m
        || m.pallet_rotation_rad.abs() > tol.pallet_rotation_rad)
        .then(|| {
            let by = if m.mast_contact_force_n > 0.0 {
                format!(
                    ", pushed by the truck's mast face ({:.0} N)",
                    m.mast_contact_force_n
                )
            } else {
                String::new()
            };
            format!(
                "pallet moved {:.3} m and turned {:.2}° (limits {} m, {}°){by}",
                m.pallet_displacement_m,
                m.pallet_rotation_rad.to_degrees(),
                tol.pallet_displacement_m,
                tol.pallet_rotation_deg()
            )
        })
}

fn lateral_error(j: &Judged<'_>) -> Option<String> {
    let limit = j.tol.lateral_m;
    j.m.lateral_error_m
        .filter(|e| e.abs() > limit)
        .map(|e| format!("{e:.3} m off the pocket centre line at entry (limit {limit} m)"))
}

fn heading_error(j: &Judged<'_>) -> Option<String> {
    let tol = j.tol;
    j.m.heading_error_rad
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
    j.m.timed_out
        .then(|| format!("not stopped at the goal after {} s", j.timeout_s))
}

fn insertion_depth(j: &Judged<'_>) -> Option<String> {
    (j.m.insertion_depth_m < j.tol.insertion_depth_m).then(|| {
        format!(
            "forks {:.3} m deep (required {} m)",
            j.m.insertion_depth_m, j.tol.insertion_depth_m
        )
    })
}

fn fork_outside_pocket(j: &Judged<'_>) -> Option<String> {
    let clearance = (j.pallet.pocket_width_m - j.truck.fork_width_m) / 2.0;
    let miss = j.m.worst_pocket_miss_m;
    (miss > clearance).then(|| {
        format!("a fork is {miss:.3} m from its pocket centre (clearance {clearance:.4} m)")
    })
}

#[cfg(test)]
mod tests {
    use super::super::PickMeasures;
    use super::*;
    use forkbench_core::{ForkliftSpec, PalletSpec};

    /// Every broken row, in the order of blame.
    fn broken(j: &Judged<'_>) -> Vec<(Failure, String)> {
        PICK_CRITERIA
            .iter()
            .filter_map(|c| c.judge(j).map(|why| (c.failure.clone(), why)))
            .collect()
    }

    /// Whether a row whose breach is final is broken.
    fn broken_for_good(j: &Judged<'_>) -> bool {
        PICK_CRITERIA
            .iter()
            .any(|c| c.irreversible && c.judge(j).is_some())
    }

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

    /// Every row is registered, in its order, at the head of the built-in criteria.
    #[test]
    fn the_rows_lead_the_registered_criteria() {
        let built: Vec<_> = super::super::STEP_CRITERIA
            .iter()
            .map(|c| c().name())
            .collect();
        let rows: Vec<_> = PICK_CRITERIA.iter().map(|c| c.name()).collect();
        assert_eq!(built[..rows.len()], rows[..]);
        assert_eq!(built.len(), rows.len() + 1, "{built:?}");
    }

    /// Measurements of a pick well inside every limit, mid-approach: standing off the
    /// face, nothing touched.
    fn clean() -> PickMeasures {
        PickMeasures {
            collision: false,
            timed_out: false,
            max_contact_force_n: 0.0,
            mast_contact_force_n: 0.0,
            pallet_displacement_m: 0.0,
            pallet_rotation_rad: 0.0,
            lateral_error_m: Some(0.0),
            heading_error_rad: Some(0.0),
            insertion_depth_m: -1.0,
            worst_pocket_miss_m: 0.0,
        }
    }

    /// A caller-driven pick ends on a breach no later step can mend (a touched rack, a
    /// pushed pallet, an entry off the line) and not on one that may still mend (the
    /// forks short of their depth, out of time).
    #[test]
    fn only_final_breaches_end_a_pick_early() {
        let (tol, truck, pallet) = (
            Limits::default(),
            ForkliftSpec::default(),
            PalletSpec::field_1200(),
        );
        let judged = |m| Judged {
            m,
            tol: &tol,
            truck: &truck,
            pallet: &pallet,
            timeout_s: 60.0,
        };
        let m = clean();
        // Short of depth: broken, but not for good.
        assert_eq!(broken(&judged(m))[0].0, Failure::InsertionDepth);
        assert!(!broken_for_good(&judged(m)));
        let timed_out = PickMeasures {
            timed_out: true,
            ..m
        };
        assert!(!broken_for_good(&judged(timed_out)));
        for (name, breach) in [
            (
                "collision",
                PickMeasures {
                    collision: true,
                    ..m
                },
            ),
            (
                "contact_force",
                PickMeasures {
                    max_contact_force_n: 1e6,
                    ..m
                },
            ),
            (
                "pallet_displaced",
                PickMeasures {
                    pallet_rotation_rad: 1.0,
                    ..m
                },
            ),
            (
                "lateral_error",
                PickMeasures {
                    lateral_error_m: Some(1.0),
                    ..m
                },
            ),
            (
                "heading_error",
                PickMeasures {
                    heading_error_rad: Some(1.0),
                    ..m
                },
            ),
        ] {
            assert_eq!(broken(&judged(breach))[0].0.name(), name);
            assert!(broken_for_good(&judged(breach)), "{name}");
        }
    }
}
