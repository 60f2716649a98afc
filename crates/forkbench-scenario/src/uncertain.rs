//! Uncertain parameters (`[[uncertain]]`): what a scenario leaves to chance, each a distribution over one setting, drawn per trial from a stream keyed by its name.

use std::collections::BTreeMap;

use rand::RngExt as _;
use serde::Serialize;

use super::invalid;
use crate::ScenarioError;
use forkbench_rare::normal;

/// How far a draw reaches in standard-normal terms: beyond ±6 the nominal probability is
/// 2e-9, below any probability this bench estimates, so clamping there moves no
/// estimate beyond that; it bounds every value a search can ask for, so the load-time
/// range check covers them all.
pub const Z_LIMIT: f64 = 6.0;

/// Most uncertain parameters a scenario may declare.
pub const MAX_UNCERTAIN: usize = 64;

/// A distribution, each written with its own keys.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "dist", rename_all = "snake_case")]
pub enum Dist {
    Normal {
        mean: f64,
        sigma: f64,
    },
    TruncatedNormal {
        mean: f64,
        sigma: f64,
        min: f64,
        max: f64,
    },
    Uniform {
        min: f64,
        max: f64,
    },
    LogNormal {
        median: f64,
        sigma_log: f64,
    },
}

impl std::fmt::Display for Dist {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Dist::Normal { mean, sigma } => write!(f, "normal(mean {mean}, σ {sigma})"),
            Dist::TruncatedNormal {
                mean,
                sigma,
                min,
                max,
            } => {
                write!(f, "normal(mean {mean}, σ {sigma}) within [{min}, {max}]")
            }
            Dist::Uniform { min, max } => write!(f, "uniform [{min}, {max}]"),
            Dist::LogNormal { median, sigma_log } => {
                write!(f, "lognormal(median {median}, σ_log {sigma_log})")
            }
        }
    }
}

impl Dist {
    /// The value at standard-normal `z` (its quantile at Φ(z)), `z` clamped to ±[`Z_LIMIT`].
    pub fn at(&self, z: f64) -> f64 {
        let z = z.clamp(-Z_LIMIT, Z_LIMIT);
        match *self {
            Dist::Normal { mean, sigma } => mean + sigma * z,
            Dist::TruncatedNormal {
                mean,
                sigma,
                min,
                max,
            } => {
                let (a, b) = (
                    normal::cdf((min - mean) / sigma),
                    normal::cdf((max - mean) / sigma),
                );
                let u = a + normal::cdf(z) * (b - a);
                (mean + sigma * normal::quantile(u)).clamp(min, max)
            }
            Dist::Uniform { min, max } => min + (max - min) * normal::cdf(z),
            Dist::LogNormal { median, sigma_log } => median * (sigma_log * z).exp(),
        }
    }
}

/// What an uncertain parameter moves.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// The true pallet's offset from the case's, in the pallet's frame (along its
    /// heading, to its left, turned); where the truck was told it is stays the case's.
    Pallet(Axis),
    /// The truck's start offset from the case's, in the start's frame.
    Start(Axis),
    /// An actuator or timing setting by its dotted path (absolute value).
    Truck(&'static str),
    /// `[sensors.pallet] latency_s` (absolute).
    DetectorLatency,
    /// `[noise.nav350] latency_s` (absolute).
    Nav350Latency,
    /// A `[[mover]]`'s start time (absolute, instead of its drawn one), by index.
    MoverStart(usize),
    /// A `[[mover]]`'s walking speed (absolute), by index.
    MoverSpeed(usize),
}

/// An offset's axis; the heading's value is in degrees at the interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
    Heading,
}

/// One uncertain parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Uncertain {
    pub name: String,
    pub target: Target,
    pub dist: Dist,
}

/// The parameters' values of one trial, by name (headings in degrees, as named).
pub type Values = BTreeMap<String, f64>;

/// A scenario's uncertain parameters.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
#[serde(transparent)]
pub struct UncertainSet(pub Vec<Uncertain>);

impl UncertainSet {
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The values of a trial seeded `seed`: each drawn from the stream its name keys,
    /// unless `pinned` gives it (a search's point, a replay).
    pub fn values(&self, seed: u64, pinned: &Values) -> Values {
        self.0
            .iter()
            .map(|u| {
                let v = pinned.get(&u.name).copied().unwrap_or_else(|| {
                    let mut rng = stream_of(seed, &u.name);
                    u.dist.at(rng.sample(rand_distr::StandardNormal))
                });
                (u.name.clone(), v)
            })
            .collect()
    }

    /// The values at the standard-normal point `z` (one coordinate per parameter, in
    /// declaration order).
    pub fn at(&self, z: &[f64]) -> Values {
        self.0
            .iter()
            .zip(z)
            .map(|(u, &z)| (u.name.clone(), u.dist.at(z)))
            .collect()
    }

    /// Refuses pinned values of undeclared parameters, or outside their declared range.
    pub fn check_pinned(&self, pinned: &Values) -> Result<(), ScenarioError> {
        for (name, v) in pinned {
            let Some(u) = self.0.iter().find(|u| &u.name == name) else {
                let known: Vec<&str> = self.0.iter().map(|u| u.name.as_str()).collect();
                return Err(invalid(
                    "options",
                    &format!("uncertain.{name}"),
                    &format!(
                        "not an uncertain parameter of this scenario (declared: {})",
                        list(&known)
                    ),
                ));
            };
            let (lo, hi) = (u.dist.at(-Z_LIMIT), u.dist.at(Z_LIMIT));
            if !(v.is_finite() && (lo..=hi).contains(v)) {
                return Err(invalid(
                    "options",
                    &format!("uncertain.{name}"),
                    &format!("{v} is outside what its distribution reaches ({lo} to {hi})"),
                ));
            }
        }
        Ok(())
    }
}

fn list(names: &[&str]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

/// The stream of parameter `name` under `seed` (FNV-1a of the name: adding a parameter
/// moves no other's draws).
fn stream_of(seed: u64, name: &str) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng as _;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in format!("uncertain {name}").bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ h)
}
