//! What the report's charts aggregate, from the manifest's typed settings: success over the papers' case geometry, and entry errors grouped by the limits that judge them.

use std::collections::BTreeMap;

use forkbench_core::{ForkliftSpec, Pose2};
use serde::Deserialize;

use crate::manifest::ScenarioEntry;
use crate::{Manifest, TrialRecord, mode_name};

/// A case's poses as the manifest's resolved settings hold them.
#[derive(Debug, Deserialize)]
struct CasePoses {
    name: String,
    start: Pose2,
    pallet: Pose2,
}

/// The settings the geometry needs; the gap before `[pick]` existed is the old constant.
#[derive(Debug, Deserialize)]
struct GeometrySettings {
    truck: ForkliftSpec,
    cases: Vec<CasePoses>,
    #[serde(default)]
    pick: Option<PickGap>,
}

#[derive(Debug, Deserialize)]
struct PickGap {
    pre_entry_gap_m: f64,
}

/// (successes, trials) per (goal lateral offset in cm, pallet angle in 0.1°) cell.
pub type CaseCells = BTreeMap<(i64, i64), (u64, u64)>;

impl ScenarioEntry {
    /// (goal lateral offset D in cm, right positive; pallet angle θ in °) of each case, as
    /// the papers' Table 2 gives them: the pre-entry goal ([`forkbench_trial::trial::goal_for`]
    /// with the fork tips the pick's gap before the face) in the start pose's frame. `None`
    /// when the settings do not hold a truck and posed cases.
    pub fn case_geometry(&self) -> Option<BTreeMap<String, (f64, f64)>> {
        let s = GeometrySettings::deserialize(&self.settings).ok()?;
        let gap_m = s.pick.map_or(forkbench_trial::trial::APPROACH_GAP_M, |p| {
            p.pre_entry_gap_m
        });
        let cells = s.cases.iter().map(|c| {
            let goal = forkbench_trial::trial::goal_for(&c.pallet, &s.truck, -gap_m);
            let local = c.start.to_local(&goal);
            let lateral_cm = (-local.y_m * 100.0).round();
            let angle_deg = (local.heading_rad.to_degrees() * 10.0).round() / 10.0;
            (c.name.clone(), (lateral_cm, angle_deg))
        });
        Some(cells.collect())
    }

    /// The lateral (m) and heading (°) limits at entry the scenario judges by.
    pub fn entry_limits(&self) -> Option<(f64, f64)> {
        let t = self.settings.get("tolerances")?;
        Some((
            t.get("lateral_m")?.as_f64()?,
            t.get("heading_deg")?.as_f64()?,
        ))
    }
}

/// Success per case cell of each scenario with at least `min_cases` cases, per
/// (scenario, planner, tracker, replanning), in that order.
pub fn case_grids(
    manifest: &Manifest,
    records: &[TrialRecord],
    min_cases: usize,
) -> BTreeMap<(String, String, String, bool), CaseCells> {
    let mut grids = BTreeMap::new();
    for sc in &manifest.scenarios {
        let Some(geo) = sc.case_geometry().filter(|g| g.len() >= min_cases) else {
            continue;
        };
        for r in records.iter().filter(|r| r.outcome.scenario == sc.name) {
            let Some(&(lat, ang)) = geo.get(&r.outcome.case) else {
                continue;
            };
            let o = &r.outcome;
            let row = (sc.name.clone(), o.planner.clone(), o.tracker.clone());
            let key = (row.0, row.1, row.2, r.replan.unwrap_or(false));
            let c: &mut (u64, u64) = grids
                .entry(key)
                .or_insert_with(CaseCells::new)
                .entry((lat as i64, (ang * 10.0) as i64))
                .or_default();
            c.0 += u64::from(o.success);
            c.1 += 1;
        }
    }
    grids
}

/// Entry errors (|lateral| in mm, |heading| in °) per `planner / tracker / mode`, of the
/// trials judged by one pair of limits.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorGroup {
    /// (lateral m, heading °); `None` for scenarios whose manifest holds none.
    pub limits: Option<(f64, f64)>,
    pub scenarios: Vec<String>,
    pub lateral_mm: BTreeMap<String, Vec<f64>>,
    pub heading_deg: BTreeMap<String, Vec<f64>>,
}

/// The trials' entry errors, a group per distinct pair of limits (each scenario's own),
/// in the manifest's order of first use.
pub fn error_groups(manifest: &Manifest, records: &[TrialRecord]) -> Vec<ErrorGroup> {
    let mut groups: Vec<ErrorGroup> = Vec::new();
    for sc in &manifest.scenarios {
        let limits = sc.entry_limits();
        let g = match groups.iter().position(|g| g.limits == limits) {
            Some(i) => &mut groups[i],
            None => {
                groups.push(ErrorGroup {
                    limits,
                    scenarios: Vec::new(),
                    lateral_mm: BTreeMap::new(),
                    heading_deg: BTreeMap::new(),
                });
                groups.last_mut().expect("just pushed")
            }
        };
        g.scenarios.push(sc.name.clone());
        for r in records.iter().filter(|r| r.outcome.scenario == sc.name) {
            let o = &r.outcome;
            let key = format!(
                "{} / {} / {}",
                o.planner,
                o.tracker,
                mode_name(r.replan.unwrap_or(false))
            );
            if let Some(v) = o.lateral_error_m {
                g.lateral_mm
                    .entry(key.clone())
                    .or_default()
                    .push(v.abs() * 1e3);
            }
            if let Some(v) = o.heading_error_rad {
                g.heading_deg
                    .entry(key)
                    .or_default()
                    .push(v.abs().to_degrees());
            }
        }
    }
    groups
}
