//! What the gate compares besides success: each trial's measures (entry errors, contact force, displacement, robustness, time, the step criteria's), which way each gets worse, and its non-inferiority margin.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use forkbench_trial::TrialOutcome;

/// Which way a measure gets worse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Worse {
    Higher,
    Lower,
}

impl Worse {
    /// +1 when higher is worse: a difference times this is positive when worse.
    pub fn sign(self) -> f64 {
        match self {
            Worse::Higher => 1.0,
            Worse::Lower => -1.0,
        }
    }
}

/// How a measure's default margin is found.
#[derive(Debug, Clone, Copy)]
enum Rule {
    /// A tenth of the scenario's tolerance (its key under `tolerances`), times a unit
    /// factor.
    TenthOf(&'static str, f64),
    /// A fixed amount, with its reason.
    Fixed(f64, &'static str),
    /// A share of the baseline row's median.
    MedianShare(f64),
}

/// A measure the gate knows: its name in the records, which way is worse, its margin.
struct Known {
    name: &'static str,
    worse: Worse,
    rule: Rule,
}

/// The measures every pick reports, and the built-in step criteria's.
const KNOWN: &[Known] = &[
    Known {
        name: "entry_lateral_error_m",
        worse: Worse::Higher,
        rule: Rule::TenthOf("lateral_m", 1.0),
    },
    Known {
        name: "entry_heading_error_rad",
        worse: Worse::Higher,
        rule: Rule::TenthOf("heading_deg", std::f64::consts::PI / 180.0),
    },
    Known {
        name: "max_contact_force_n",
        worse: Worse::Higher,
        rule: Rule::TenthOf("contact_force_n", 1.0),
    },
    Known {
        name: "pallet_displacement_m",
        worse: Worse::Higher,
        rule: Rule::TenthOf("pallet_displacement_m", 1.0),
    },
    Known {
        name: "robustness",
        worse: Worse::Lower,
        rule: Rule::Fixed(
            0.1,
            "a tenth of a limit (robustness is the least margin as a share of its limit)",
        ),
    },
    Known {
        name: "time_s",
        worse: Worse::Higher,
        rule: Rule::MedianShare(0.05),
    },
    // A lateral offset narrows one fork's gap one for one: the lateral error's margin.
    Known {
        name: "fork_tip_clearance_mm",
        worse: Worse::Lower,
        rule: Rule::TenthOf("lateral_m", 1000.0),
    },
    // The handling cycle's phases after the pick, by phase and measure.
    Known {
        name: "place.position_error_m",
        worse: Worse::Higher,
        rule: Rule::Fixed(0.005, PLACE_POSITION),
    },
    Known {
        name: "place.heading_error_rad",
        worse: Worse::Higher,
        rule: Rule::Fixed(0.2 * std::f64::consts::PI / 180.0, PLACE_HEADING),
    },
    Known {
        name: "place.clearance_m",
        worse: Worse::Lower,
        rule: Rule::Fixed(0.01, AS_ENTRY),
    },
    Known {
        name: "carry.cross_track_max_m",
        worse: Worse::Higher,
        rule: Rule::Fixed(0.01, AS_ENTRY),
    },
    Known {
        name: "return.cross_track_max_m",
        worse: Worse::Higher,
        rule: Rule::Fixed(0.01, AS_ENTRY),
    },
    Known {
        name: "carry.final_position_error_m",
        worse: Worse::Higher,
        rule: Rule::Fixed(0.005, PLACE_POSITION),
    },
    Known {
        name: "return.final_position_error_m",
        worse: Worse::Higher,
        rule: Rule::Fixed(0.005, PLACE_POSITION),
    },
];

/// The reasons of the phases' fixed margins.
const PLACE_POSITION: &str = "a tenth of the place phase's default position tolerance (0.05 m)";
const PLACE_HEADING: &str = "a tenth of the place phase's default heading tolerance (2°)";
const AS_ENTRY: &str = "the entry error's default margin (a choice)";

/// The tolerance `key` when a scenario's are unknown: the format's default, read the way
/// the manifest's resolved tolerances are.
fn default_tolerance(key: &str) -> Option<f64> {
    serde_json::to_value(forkbench_trial::Tolerances::default())
        .ok()?
        .get(key)?
        .as_f64()
}

/// A trial's measures, by name with its unit: the entry's absolute lateral and heading
/// errors, the contact force and the pallet's displacement (once the tips reached the
/// face: before it the forks cannot have touched it), the robustness margin, the time
/// (the cycle's, else the pick's; on success only: a failed trial's time is when it
/// stopped), every step criterion's measure, and each later phase's (`place.clearance_m`).
pub fn trial_measures(o: &TrialOutcome) -> BTreeMap<String, f64> {
    let mut m = BTreeMap::new();
    let mut put = |k: &str, v: Option<f64>| {
        if let Some(v) = v.filter(|v| v.is_finite()) {
            m.insert(k.to_owned(), v);
        }
    };
    let at_face = o.lateral_error_m.is_some();
    put("entry_lateral_error_m", o.lateral_error_m.map(f64::abs));
    put("entry_heading_error_rad", o.heading_error_rad.map(f64::abs));
    put(
        "max_contact_force_n",
        at_face.then_some(o.max_contact_force_n),
    );
    put(
        "pallet_displacement_m",
        at_face.then_some(o.pallet_displacement_m),
    );
    put("robustness", o.robustness);
    let time = o.cycle.map_or(o.sim_time_s, |c| c.time_s);
    put("time_s", o.success.then_some(time));
    for (k, v) in &o.measures {
        put(k, Some(*v));
    }
    // The phases after the pick, as `phase.measure`; a heading error counts either way.
    for p in &o.phases {
        for (k, v) in &p.measures {
            let v = if k.ends_with("heading_error_rad") {
                v.abs()
            } else {
                *v
            };
            put(&format!("{}.{k}", p.name), Some(v));
        }
    }
    m
}

/// A gate file's setting for one measure (`[measure.NAME]`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasureSetting {
    /// The worsening allowed before the gate fails, in the measure's unit.
    pub margin: Option<f64>,
    /// Which way it gets worse (needed for a measure the gate does not know).
    pub worse: Option<Worse>,
    /// `false`: not gated (listed as such).
    pub gate: Option<bool>,
}

/// What a gate file sets: margins and directions by measure.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasureSettings {
    #[serde(default)]
    pub measure: BTreeMap<String, MeasureSetting>,
}

/// The largest margin a gate file may set (a bound on every unit the bench uses).
const MAX_MARGIN: f64 = 1e9;

impl MeasureSettings {
    /// Reads a gate file (TOML), checking every setting; errors name the file and field.
    pub fn load(path: &std::path::Path) -> Result<Self, crate::BatchError> {
        let text = crate::read_regular(path, 1 << 20)?;
        let s: MeasureSettings = toml::from_str(&text).map_err(|e| {
            crate::BatchError::Content(format!("{}: {}", path.display(), e.message()))
        })?;
        s.check()
            .map_err(|why| crate::BatchError::Content(format!("{}: {why}", path.display())))?;
        Ok(s)
    }

    /// The gate file's settings, or the defaults without one.
    pub fn load_or_default(path: Option<&std::path::Path>) -> Result<Self, crate::BatchError> {
        path.map_or_else(|| Ok(Self::default()), Self::load)
    }

    /// Every margin finite in [0, 1e9]; a measure the gate does not know says `worse`.
    pub fn check(&self) -> Result<(), MeasureSettingError> {
        for (name, s) in &self.measure {
            let name = name.clone();
            if let Some(margin) = s.margin
                && !(0.0..=MAX_MARGIN).contains(&margin)
            {
                return Err(MeasureSettingError::Margin { name, margin });
            }
            if known(&name).is_none() && s.worse.is_none() && s.gate != Some(false) {
                return Err(MeasureSettingError::Unknown { name });
            }
            if known(&name).is_none() && s.gate != Some(false) && s.margin.is_none() {
                return Err(MeasureSettingError::NoMargin { name });
            }
        }
        Ok(())
    }
}

/// Why a gate file's `[measure.*]` settings were refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasureSettingError {
    #[error(
        "measure.{name}.margin = {margin}: must be a worsening in [0, {MAX_MARGIN}] in the \
         measure's unit"
    )]
    Margin { name: String, margin: f64 },
    #[error(
        "measure.{name}: the gate does not know this measure; say which way it gets worse \
         (worse = \"higher\" or \"lower\") and its margin"
    )]
    Unknown { name: String },
    #[error("measure.{name}.margin: missing; a measure the gate does not know needs its margin")]
    NoMargin { name: String },
}

fn known(name: &str) -> Option<&'static Known> {
    KNOWN.iter().find(|k| k.name == name)
}

/// How one measure is gated in one row: its direction, margin and the margin's reason.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Gated {
    pub worse: Worse,
    pub margin: f64,
    pub source: String,
}

/// How `name` is gated for a scenario with `tolerances` (its resolved settings' JSON,
/// if known) and a baseline `median`; `None`: not gated (unknown, or switched off).
pub(super) fn gated(
    name: &str,
    settings: &MeasureSettings,
    tolerances: Option<&serde_json::Value>,
    median: Option<f64>,
) -> Option<Gated> {
    let set = settings.measure.get(name);
    if set.and_then(|s| s.gate) == Some(false) {
        return None;
    }
    let k = known(name);
    let worse = set.and_then(|s| s.worse).or(k.map(|k| k.worse))?;
    if let Some(m) = set.and_then(|s| s.margin) {
        return Some(Gated {
            worse,
            margin: m,
            source: "the gate file".into(),
        });
    }
    let (margin, source) = match k?.rule {
        Rule::TenthOf(key, unit) => {
            let tol = tolerances
                .and_then(|t| t.get(key))
                .and_then(serde_json::Value::as_f64)
                .or_else(|| default_tolerance(key))?;
            (tol * unit / 10.0, format!("a tenth of tolerances.{key}"))
        }
        Rule::Fixed(m, why) => (m, why.to_owned()),
        Rule::MedianShare(share) => (
            share * median?.abs(),
            format!("{:.0} % of the baseline's median", 100.0 * share),
        ),
    };
    Some(Gated {
        worse,
        margin,
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A handling cycle's record, cut to what the measures read.
    const CYCLE: &str = r#"{"scenario": "warehouse-cycle", "case": "default", "planner": "bspline",
        "tracker": "pure_pursuit", "seed": 1, "noise": true, "success": true, "failure": null,
        "failure_detail": null, "lateral_error_m": -0.0488, "heading_error_rad": 0.00097,
        "final_lateral_error_m": 0.012, "final_heading_error_rad": -0.024,
        "insertion_depth_m": 1.16, "max_steer_rad": 1.0, "max_contact_force_n": 0.0,
        "pallet_displacement_m": 0.0, "pallet_rotation_rad": 0.0, "replans": 0,
        "replans_failed": 0, "path_length_m": 4.2, "sim_time_s": 197.45, "wall_time_ms": 151.2,
        "measures": {"fork_tip_clearance_mm": 77.1}, "robustness": 0.51,
        "cycle": {"time_s": 180.5, "distance_loaded_m": 20.0, "distance_unloaded_m": 21.0},
        "phases": [{"name": "carry", "success": true, "failure": null, "failure_detail": null,
        "time_s": 36.5, "distance_m": 16.6, "loaded": true, "measures": {"cross_track_max_m":
        0.022, "planned_length_m": 12.7}}, {"name": "place", "success": true, "failure": null,
        "failure_detail": null, "time_s": 20.4, "distance_m": 7.2, "loaded": true, "measures":
        {"clearance_m": 0.295, "heading_error_rad": -0.001, "position_error_m": 0.0044}}]}"#;

    #[test]
    fn a_cycle_gives_the_picks_measures_and_its_phases_by_name() {
        let o: TrialOutcome = serde_json::from_str(CYCLE).expect("a record");
        let m = trial_measures(&o);
        assert_eq!(m["entry_lateral_error_m"], 0.0488);
        assert_eq!(m["time_s"], 180.5, "the cycle's time, not the pick's");
        assert_eq!(m["fork_tip_clearance_mm"], 77.1);
        assert_eq!(m["place.heading_error_rad"], 0.001, "either way");
        assert_eq!(m["carry.cross_track_max_m"], 0.022);
        // Known phase measures are gated with their margins; a plan's length is not known.
        let s = MeasureSettings::default();
        let g = gated("place.clearance_m", &s, None, None).expect("gated");
        assert_eq!((g.worse, g.margin), (Worse::Lower, 0.01));
        assert!(gated("carry.planned_length_m", &s, None, None).is_none());
        // Without a manifest the margins take a tenth of the format's default tolerances.
        let lat = gated("entry_lateral_error_m", &s, None, None).expect("gated");
        assert!((lat.margin - 0.01).abs() < 1e-12, "{lat:?}");
        let heading = gated("entry_heading_error_rad", &s, None, None).expect("gated");
        assert!(
            (heading.margin - 0.3f64.to_radians()).abs() < 1e-12,
            "{heading:?}"
        );
        // A failed trial keeps no time; one that never reached the face no entry measures.
        let mut failed = o.clone();
        failed.success = false;
        failed.lateral_error_m = None;
        let m = trial_measures(&failed);
        assert!(!m.contains_key("time_s") && !m.contains_key("max_contact_force_n"));
    }
}
