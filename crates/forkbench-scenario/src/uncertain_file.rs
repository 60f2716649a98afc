//! `[[uncertain]]` as written and resolved: each entry's distribution, the setting its name moves, and the range it may reach, checked with file and line.

use forkbench_safety::MoverSpec;

use serde::{Deserialize, Serialize};

use super::invalid;
use super::uncertain::{Axis, Dist, MAX_UNCERTAIN, Target, Uncertain, UncertainSet, Z_LIMIT};
use crate::ScenarioError;
use forkbench_core::run_settings::{TRUCK_KNOBS, set, truck_path};
use forkbench_rare::normal;

/// Farthest a pallet or start offset may reach, m and degrees: past it a case is another case.
pub const MAX_OFFSET_M: f64 = 2.0;
pub const MAX_OFFSET_DEG: f64 = 45.0;
/// Longest sensor latency a parameter may reach, s.
pub const MAX_LATENCY_S: f64 = 1.0;

/// Every name an uncertain parameter may take, for messages.
pub fn names_known() -> String {
    let truck: Vec<&str> = TRUCK_KNOBS.iter().map(|(k, _)| *k).collect();
    format!(
        "pallet.x_m, pallet.y_m, pallet.heading_deg, start.x_m, start.y_m, start.heading_deg, \
         detector_latency_s, nav350_latency_s, mover.N.start_s, mover.N.speed_mps, {}",
        truck.join(", ")
    )
}

/// Why an entry's name or reach is refused (the field and file are the caller's).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum Refused {
    #[error(
        "{name:?} is not a setting a parameter can move (known: {})",
        names_known()
    )]
    Unknown { name: String },
    #[error(
        "mover.{rest}: write mover.N.start_s or mover.N.speed_mps, N the [[mover]]'s index from 0"
    )]
    MoverIndex { rest: String },
    #[error("mover.{index}: the scenario has {movers} [[mover]] entries")]
    NoMover { index: usize, movers: usize },
    #[error("mover.{index}.{what}: a mover's start_s or speed_mps")]
    MoverSetting { index: usize, what: String },
    #[error(
        "reaches {lo:.4} to {hi:.4} {unit} (at ±{Z_LIMIT} σ); it must stay within {min} to {max} {unit}"
    )]
    Reach {
        lo: f64,
        hi: f64,
        min: f64,
        max: f64,
        unit: &'static str,
    },
    #[error(
        "the control period must be a whole number of physics steps ([sim] dt_s), which a \
         draw from a distribution almost never is: give each period its own run \
         ([truck.control] period_s, or a truck file per period) instead"
    )]
    ControlPeriod,
    #[error(
        "reaches {lo:.4} to {hi:.4} (at ±{Z_LIMIT} σ), and at {at} the truck's {path} {reason}"
    )]
    Truck {
        lo: f64,
        hi: f64,
        at: f64,
        path: &'static str,
        reason: String,
    },
    #[error("reaches {lo:.4} to {hi:.4} (at ±{Z_LIMIT} σ), and at {at}: {reason}")]
    Mover {
        lo: f64,
        hi: f64,
        at: f64,
        reason: String,
    },
}

/// What `name` moves; the reason when it names nothing.
pub(super) fn target_of(name: &str, movers: &[MoverSpec]) -> Result<Target, Refused> {
    let axis = |a: &str| match a {
        "x_m" => Some(Axis::X),
        "y_m" => Some(Axis::Y),
        "heading_deg" => Some(Axis::Heading),
        _ => None,
    };
    let target = match name.split_once('.') {
        Some(("pallet", a)) => axis(a).map(Target::Pallet),
        Some(("start", a)) => axis(a).map(Target::Start),
        Some(("mover", rest)) => return mover_target(rest, movers),
        _ => match name {
            "detector_latency_s" => Some(Target::DetectorLatency),
            "nav350_latency_s" => Some(Target::Nav350Latency),
            _ => TRUCK_KNOBS
                .iter()
                .find(|(k, _)| *k == name)
                .and_then(|(k, _)| truck_path(k))
                .map(Target::Truck),
        },
    };
    target.ok_or_else(|| Refused::Unknown {
        name: name.to_owned(),
    })
}

fn mover_target(rest: &str, movers: &[MoverSpec]) -> Result<Target, Refused> {
    let (i, what) = rest.split_once('.').unwrap_or((rest, ""));
    let i: usize = i.parse().map_err(|_| Refused::MoverIndex {
        rest: rest.to_owned(),
    })?;
    if i >= movers.len() {
        return Err(Refused::NoMover {
            index: i,
            movers: movers.len(),
        });
    }
    match what {
        "start_s" => Ok(Target::MoverStart(i)),
        "speed_mps" => Ok(Target::MoverSpeed(i)),
        _ => Err(Refused::MoverSetting {
            index: i,
            what: what.to_owned(),
        }),
    }
}

/// Refuses a distribution that reaches past what its target allows, between its values
/// at ±[`Z_LIMIT`]: every value a trial or a search can ask for is checked here, once.
pub(super) fn check_reach(
    target: &Target,
    dist: &Dist,
    movers: &[MoverSpec],
) -> Result<(), Refused> {
    let (lo, hi) = (dist.at(-Z_LIMIT), dist.at(Z_LIMIT));
    let within = |min: f64, max: f64, unit: &'static str| {
        if lo >= min && hi <= max {
            Ok(())
        } else {
            Err(Refused::Reach {
                lo,
                hi,
                min,
                max,
                unit,
            })
        }
    };
    match target {
        Target::Pallet(Axis::Heading) | Target::Start(Axis::Heading) => {
            within(-MAX_OFFSET_DEG, MAX_OFFSET_DEG, "°")
        }
        Target::Pallet(_) | Target::Start(_) => within(-MAX_OFFSET_M, MAX_OFFSET_M, "m"),
        Target::DetectorLatency | Target::Nav350Latency => within(0.0, MAX_LATENCY_S, "s"),
        Target::Truck("control.period_s") => Err(Refused::ControlPeriod),
        Target::Truck(path) => {
            for v in [lo, hi] {
                let mut truck = forkbench_core::ForkliftSpec::default();
                set(&mut truck, path, v);
                truck.validate().map_err(|e| Refused::Truck {
                    lo,
                    hi,
                    at: v,
                    path,
                    reason: e.reason.to_string(),
                })?;
            }
            Ok(())
        }
        Target::MoverStart(i) | Target::MoverSpeed(i) => {
            for v in [lo, hi] {
                let mut m = movers[*i].clone();
                if matches!(target, Target::MoverStart(_)) {
                    m.start_s = [v, v];
                } else {
                    m.speed_mps = v;
                }
                m.validate().map_err(|e| Refused::Mover {
                    lo,
                    hi,
                    at: v,
                    reason: e.to_string(),
                })?;
            }
            Ok(())
        }
    }
}

/// Refuses a detector latency parameter when the pallet is estimated without scans.
pub(super) fn check_sensing(
    set: &UncertainSet,
    gaussian: bool,
    file: &str,
) -> Result<(), ScenarioError> {
    match set.0.iter().find(|u| u.target == Target::DetectorLatency) {
        Some(u) if gaussian => Err(invalid(
            file,
            &format!("uncertain.{}", u.name),
            "the gaussian pallet estimate has no scans, so no latency to vary",
        )),
        _ => Ok(()),
    }
}

/// `[[uncertain]]` as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct UncertainFile {
    name: String,
    dist: String,
    mean: Option<f64>,
    sigma: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    median: Option<f64>,
    sigma_log: Option<f64>,
}

/// Resolves the written entries, each checked with its file and line.
pub(super) fn resolve(
    entries: &[toml::Spanned<UncertainFile>],
    movers: &[forkbench_safety::MoverSpec],
    (file, text): (&str, &str),
) -> Result<UncertainSet, ScenarioError> {
    if entries.len() > MAX_UNCERTAIN {
        return Err(invalid(
            file,
            "uncertain",
            &format!("{} parameters; at most {MAX_UNCERTAIN}", entries.len()),
        ));
    }
    let mut out: Vec<Uncertain> = Vec::new();
    for (i, e) in entries.iter().enumerate() {
        let line = text[..e.span().start.min(text.len())]
            .lines()
            .count()
            .max(1);
        let at = format!("{file}:{line}");
        let u = e.get_ref();
        let field = format!("uncertain[{i}]");
        if out.iter().any(|o| o.name == u.name) {
            return Err(invalid(
                &at,
                &format!("{field}.name"),
                &format!("{:?} is declared twice", u.name),
            ));
        }
        let target = target_of(&u.name, movers)
            .map_err(|why| invalid(&at, &format!("{field}.name"), &why.to_string()))?;
        let dist = dist_of(u).map_err(|(k, why)| invalid(&at, &format!("{field}.{k}"), &why))?;
        check_reach(&target, &dist, movers)
            .map_err(|why| invalid(&at, &format!("{field}.dist"), &why.to_string()))?;
        out.push(Uncertain {
            name: u.name.clone(),
            target,
            dist,
        });
    }
    Ok(UncertainSet(out))
}

/// An entry's numeric keys by name.
type Keys = [(&'static str, Option<f64>); 6];
/// A key and what is wrong with it.
type KeyError = (&'static str, String);

/// The keys an entry writes, checked against those its distribution takes.
fn keys_of(u: &UncertainFile) -> Result<Keys, KeyError> {
    let keys = [
        ("mean", u.mean),
        ("sigma", u.sigma),
        ("min", u.min),
        ("max", u.max),
        ("median", u.median),
        ("sigma_log", u.sigma_log),
    ];
    let wants: &[&str] = match u.dist.as_str() {
        "normal" => &["mean", "sigma"],
        "truncated_normal" => &["mean", "sigma", "min", "max"],
        "uniform" => &["min", "max"],
        "lognormal" => &["median", "sigma_log"],
        other => {
            return Err((
                "dist",
                format!("{other:?}: one of normal, truncated_normal, uniform, lognormal"),
            ));
        }
    };
    let takes = || format!("{} takes {}", u.dist, wants.join(", "));
    for (k, v) in keys {
        match (wants.contains(&k), v) {
            (true, None) => return Err((k, format!("missing: {}", takes()))),
            (false, Some(_)) => {
                return Err((k, format!("not a key of this distribution ({})", takes())));
            }
            (_, Some(x)) if !x.is_finite() => {
                return Err((k, format!("{x} is not a finite number")));
            }
            _ => {}
        }
    }
    Ok(keys)
}

/// The distribution an entry writes: its keys, no others, each finite and in range.
fn dist_of(u: &UncertainFile) -> Result<Dist, KeyError> {
    let keys = keys_of(u)?;
    let get = |k: &str| {
        keys.iter()
            .find(|(n, _)| *n == k)
            .and_then(|(_, v)| *v)
            .unwrap_or(0.0)
    };
    let positive = |k: &'static str| {
        let v = get(k);
        if v > 0.0 {
            Ok(v)
        } else {
            Err((k, format!("{v}: must be above 0")))
        }
    };
    let ordered = || {
        if get("min") < get("max") {
            Ok((get("min"), get("max")))
        } else {
            Err((
                "max",
                format!("{} must exceed min {}", get("max"), get("min")),
            ))
        }
    };
    Ok(match u.dist.as_str() {
        "normal" => Dist::Normal {
            mean: get("mean"),
            sigma: positive("sigma")?,
        },
        "truncated_normal" => {
            let (min, max) = ordered()?;
            let (mean, sigma) = (get("mean"), positive("sigma")?);
            let mass = normal::cdf((max - mean) / sigma) - normal::cdf((min - mean) / sigma);
            if mass < 1e-9 {
                return Err((
                    "min",
                    format!("[{min}, {max}] holds almost none of N({mean}, {sigma}²)"),
                ));
            }
            Dist::TruncatedNormal {
                mean,
                sigma,
                min,
                max,
            }
        }
        "uniform" => {
            let (min, max) = ordered()?;
            Dist::Uniform { min, max }
        }
        _ => {
            let s = positive("sigma_log")?;
            if s > 3.0 {
                return Err(("sigma_log", format!("{s}: at most 3")));
            }
            Dist::LogNormal {
                median: positive("median")?,
                sigma_log: s,
            }
        }
    })
}
