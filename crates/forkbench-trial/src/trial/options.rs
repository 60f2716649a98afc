//! A run's choices on top of a scenario file (`TrialOptions`, its `Overrides`), checked once, and their resolution into what a trial runs with.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::ScenarioError;
use crate::components::{ComponentSpec, Role};
use crate::scenario::sensors::PalletSensing;
use crate::scenario::{Scenario, invalid, invalid_setting};
use forkbench_scenario::Catalogue as _;

/// Largest noise scale a run may ask for: far past any sweep's use, and a bound that
/// keeps scaled σ finite and meaningful.
pub const MAX_NOISE_SCALE: f64 = 100.0;

/// What a run changes of a scenario besides its seed, components and replanning: the
/// noise scales and sensing models. A batch records them with every trial, so `replay`
/// rebuilds the trial exactly.
///
/// With the `clap` feature it is the CLI's flag set (each field's flag is its name with
/// dashes, its help its doc), so a knob is one field here; the truck's preset and settings
/// come from the CLI's `--truck PRESET|FILE` instead.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct Overrides {
    /// Scales every pallet-sensing error, 0–100: the Gaussian estimate's σ, and each
    /// scanner's random range error and systematic bias (0 = exact returns; a spot
    /// straddling a depth edge still mixes ranges, which is geometry, not noise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true))]
    pub pallet_noise_scale: Option<f64>,
    /// Scales the localiser's noise, 0–100: the Gaussian σ or the NAV350's reflector
    /// range and bearing σ (0 = exact fixes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true))]
    pub localization_noise_scale: Option<f64>,
    /// Scales the odometry's speed-scale and steering-offset σ, 0–100 (0 = exact
    /// odometry).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true))]
    pub odometry_noise_scale: Option<f64>,
    /// Localise with this kind at its default settings (gaussian: σ around the truth;
    /// nav350: the world's reflectors) instead of each scenario's `[sensors.localizer]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "clap", arg(long, value_name = "KIND"))]
    pub localizer: Option<String>,
    /// Estimate the pallet with this sensing at its default settings (gaussian, tim561,
    /// kinect2 or tim561+kinect2) instead of each scenario's `[sensors.pallet]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "clap", arg(long, value_name = "KIND"))]
    pub pallet_sensing: Option<String>,
    /// Reflectors (comma-separated names) missing from the world while the NAV350's map
    /// keeps them: which legs suffer if they go.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(
        feature = "clap",
        arg(long, value_delimiter = ',', value_name = "NAMES")
    )]
    pub missing_reflectors: Option<Vec<String>>,
    /// Take this preset's actuators and control timing (`ideal`, `realistic`) instead
    /// of the scenario's `[truck]` ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "clap", arg(skip))]
    pub truck_preset: Option<String>,
    /// Actuator and timing settings by dotted path (`steering.dead_time_s`; see
    /// [`super::TRUCK_KNOBS`]), after the preset: a `--truck` file, a sweep's point.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    #[cfg_attr(feature = "clap", arg(skip))]
    pub truck: BTreeMap<String, f64>,
}

/// The noise knobs by the names sweeps and messages use, with their source.
pub const NOISE_KNOBS: [&str; 3] = ["pallet_noise", "localization_noise", "odometry_noise"];

impl Overrides {
    /// Every option's name, as the struct defines it: the manifest's keys, Python's
    /// keywords and (with dashes, `--truck` for the truck's two) the CLI's flags, which
    /// tests check against this list.
    pub fn field_names() -> &'static [&'static str] {
        serde_aux::serde_introspection::serde_introspect::<Overrides>()
    }

    /// The scale of a knob ([`NOISE_KNOBS`]).
    pub fn scale(&self, knob: &str) -> Option<f64> {
        match knob {
            "pallet_noise" => self.pallet_noise_scale,
            "localization_noise" => self.localization_noise_scale,
            "odometry_noise" => self.odometry_noise_scale,
            _ => None,
        }
    }

    /// Sets a knob's scale, or a truck setting by its sweep name or dotted path
    /// ([`super::TRUCK_KNOBS`]); false for a name that is neither.
    pub fn set_scale(&mut self, knob: &str, v: f64) -> bool {
        if let Some(path) = super::truck_path(knob) {
            self.truck.insert(path.to_owned(), v);
            return true;
        }
        let slot = match knob {
            "pallet_noise" => &mut self.pallet_noise_scale,
            "localization_noise" => &mut self.localization_noise_scale,
            "odometry_noise" => &mut self.odometry_noise_scale,
            _ => return false,
        };
        *slot = Some(v);
        true
    }

    /// Every value in range (the scenario aside): what the CLI and Python check alike.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        for knob in NOISE_KNOBS {
            if let Some(v) = self.scale(knob)
                && !(v.is_finite() && (0.0..=MAX_NOISE_SCALE).contains(&v))
            {
                return Err(bad_option(
                    &format!("{knob}_scale"),
                    &format!("{v} must be a number from 0 to {MAX_NOISE_SCALE}"),
                ));
            }
        }
        if self.truck_preset.is_some() || !self.truck.is_empty() {
            // Names and ranges, on the bench's own truck: a scenario's truck is checked again.
            let preset = self.truck_preset.as_deref();
            super::apply_truck(
                &forkbench_core::ForkliftSpec::default(),
                preset,
                &self.truck,
            )?;
        }
        if let Some(names) = &self.missing_reflectors
            && let Some(n) = names.iter().find(|n| n.trim().is_empty())
        {
            return Err(bad_option(
                "missing_reflectors",
                &format!("{n:?} is not a reflector name"),
            ));
        }
        Ok(())
    }
}

/// Per-run choices on top of the scenario file.
#[derive(Debug, Clone, Default)]
pub struct TrialOptions {
    pub seed: Option<u64>,
    /// Planner by name: the scenario's own (by its name) or a registered kind.
    pub planner: Option<String>,
    /// Tracker by name, resolved the same way.
    pub tracker: Option<String>,
    /// Ideal sensors everywhere: no localisation, pallet-sensing or odometry error.
    pub no_noise: bool,
    /// Force replanning on new pallet estimates on or off.
    pub replan: Option<bool>,
    /// Noise scales and sensing models.
    pub overrides: Overrides,
    /// Most wall time one trial may take, external components' answers included
    /// (`None`: `DEFAULT_WALL_BUDGET_S`); past it the trial ends as an error.
    pub wall_budget_s: Option<f64>,
    /// Uncertain parameters pinned to these values instead of drawn (a search's point,
    /// a replay); each must be declared and within its distribution's reach.
    pub uncertain: crate::scenario::uncertain::Values,
}

/// A trial's wall-time budget unless a run sets one: built-in trials take well under a
/// second; this bounds a slow external tracker's ticks (each under its own `timeout_s`).
pub const DEFAULT_WALL_BUDGET_S: f64 = 600.0;
/// The range a run's budget may be set within.
pub const WALL_BUDGET_RANGE_S: (f64, f64) = (0.01, 86_400.0);

impl TrialOptions {
    /// Every value in range, and no knob that contradicts another: the one check the CLI,
    /// batches and Python share (resolving against a scenario runs it too).
    pub fn validate(&self) -> Result<(), ScenarioError> {
        self.overrides.validate()?;
        let (lo, hi) = WALL_BUDGET_RANGE_S;
        if let Some(b) = self.wall_budget_s
            && !(b.is_finite() && (lo..=hi).contains(&b))
        {
            return Err(bad_option(
                "wall_budget_s",
                &format!("{b} s: must lie within {lo}..{hi} s"),
            ));
        }
        if self.no_noise
            && let Some(knob) = NOISE_KNOBS
                .iter()
                .find(|k| self.overrides.scale(k).is_some())
        {
            return Err(bad_option(
                &format!("{knob}_scale"),
                "no noise was asked for (--no-noise): a noise scale has nothing to act on",
            ));
        }
        Ok(())
    }
}

fn bad_option(field: &str, reason: &str) -> ScenarioError {
    invalid("options", field, reason)
}

/// Everything a trial runs with, resolved once from the scenario and the options.
#[derive(Debug, Clone)]
pub struct Resolved {
    pub seed: u64,
    pub planner: ComponentSpec,
    pub tracker: ComponentSpec,
    pub noise: bool,
    pub replan: bool,
    pub pallet_estimate: forkbench_sensors::PalletEstimateConfig,
    /// The pallet sensing, its scanners' errors scaled.
    pub pallet_sensing: PalletSensing,
    /// The localiser, with any missing reflectors.
    pub localizer: ComponentSpec,
    /// The NAV350's settings, its timing as the run's truck preset has it.
    pub nav350: forkbench_sensors::Nav350Config,
    /// The localiser's noise scale (1 unless overridden).
    pub localization_noise_scale: f64,
    /// The odometry's errors, scaled.
    pub odometry: forkbench_sensors::OdometryConfig,
    /// Most wall time the trial may take.
    pub wall_budget_s: f64,
    /// The scenario's truck with the run's actuator and timing changes.
    pub truck: forkbench_core::ForkliftSpec,
    /// The values of the scenario's uncertain parameters this trial runs with.
    pub uncertain: crate::scenario::uncertain::Values,
    /// Where they put the true pallet and the start off the case's.
    pub shift: super::uncertain_apply::Shift,
}

impl TrialOptions {
    /// Resolves these options against `scn`: the one place defaults meet overrides. A
    /// scale that cannot act on what is configured is refused, naming the component and
    /// the knob.
    pub fn resolve(&self, scn: &Scenario) -> Result<Resolved, ScenarioError> {
        self.validate()?;
        let o = &self.overrides;
        let noise = scn.noise.enabled && !self.no_noise;
        let truck = truck_for(scn, o)?;
        // The sensors sit where the run's truck mounts them. Of the truck, only its mounts
        // move the sensing (its other geometry is checked by `scenario_for`), so the
        // scenario is read again on the run's truck only when those differ.
        let sensing = if truck.mounts == scn.truck.mounts {
            scn.sensing_for(o.pallet_sensing.as_deref())?
        } else {
            super::scenario_with(scn, &truck)?.sensing_for(o.pallet_sensing.as_deref())?
        };
        let localizer =
            scn.localizer_for(o.localizer.as_deref(), o.missing_reflectors.as_deref())?;
        if !noise && let Some(knob) = NOISE_KNOBS.iter().find(|k| o.scale(k).is_some()) {
            return Err(invalid(
                &scn.file,
                "noise.enabled",
                &format!("noise is off in this scenario, so {knob}_scale has nothing to act on"),
            ));
        }
        let mut pallet_estimate = scn.noise.pallet_estimate.clone();
        let mut pallet_sensing = match o.pallet_noise_scale {
            Some(s) => {
                pallet_estimate.scale = s;
                scaled_sensing(scn, sensing, s)?
            }
            None => sensing,
        };
        let mut nav350 = scn.noise.nav350.clone();
        super::truck_knobs::sensor_timing_for(
            o.truck_preset.as_deref(),
            &mut nav350,
            &mut pallet_sensing,
        );
        let localization_noise_scale = match o.localization_noise_scale {
            Some(s) => {
                check_localizer_scale(scn, &localizer)?;
                s
            }
            None => 1.0,
        };
        let mut run = Resolved {
            seed: self.seed.unwrap_or(scn.seed),
            planner: scn.component(Role::Planner, self.planner.as_deref())?,
            tracker: scn.component(Role::Tracker, self.tracker.as_deref())?,
            noise,
            replan: self.replan.unwrap_or(scn.replan.enabled),
            pallet_estimate,
            pallet_sensing,
            localizer,
            nav350,
            localization_noise_scale,
            odometry: scaled_odometry(scn, o.odometry_noise_scale)?,
            wall_budget_s: self.wall_budget_s.unwrap_or(DEFAULT_WALL_BUDGET_S),
            truck,
            uncertain: BTreeMap::new(),
            shift: Default::default(),
        };
        with_uncertain(scn, &mut run, &self.uncertain)?;
        Ok(run)
    }

    /// Resolves and also builds the localiser once in `scn`'s world: what a run checks
    /// before its first trial, so a bad override is one error, not an error outcome per
    /// trial.
    pub fn check_against(&self, scn: &Scenario) -> Result<Resolved, ScenarioError> {
        let run = self.resolve(scn)?;
        // A run's own geometry is checked against the scenario once, here, and the
        // localiser on its truck.
        let own = super::scenario_for(scn, &run)?;
        scn.registry
            .check_localizer(&run.localizer, &own)
            .map_err(|e| invalid_setting(&scn.file, "sensors.localizer", &e))?;
        Ok(run)
    }
}

/// `run` with the scenario's uncertain parameters drawn (or `pinned`) and applied.
fn with_uncertain(
    scn: &Scenario,
    run: &mut Resolved,
    pinned: &BTreeMap<String, f64>,
) -> Result<(), ScenarioError> {
    let d = super::uncertain_apply::draw(scn, run.seed, pinned)?;
    if !d.truck.is_empty() {
        run.truck = checked_truck(scn, &run.truck, None, &d.truck)?;
    }
    if let Some(v) = d.detector_latency_s {
        run.pallet_sensing.set_latency_s(v);
    }
    if let Some(v) = d.nav350_latency_s {
        run.nav350.latency_s = v;
    }
    run.shift = d.shift;
    run.uncertain = d.values;
    Ok(())
}

/// This scenario's truck with the run's preset and settings, its control period
/// checked against the physics step.
fn truck_for(scn: &Scenario, o: &Overrides) -> Result<forkbench_core::ForkliftSpec, ScenarioError> {
    if o.truck_preset.is_none() && o.truck.is_empty() {
        return Ok(scn.truck.clone());
    }
    checked_truck(scn, &scn.truck, o.truck_preset.as_deref(), &o.truck)
}

/// `base` with `preset` and `settings` applied, its control period checked against
/// the physics step.
fn checked_truck(
    scn: &Scenario,
    base: &forkbench_core::ForkliftSpec,
    preset: Option<&str>,
    settings: &BTreeMap<String, f64>,
) -> Result<forkbench_core::ForkliftSpec, ScenarioError> {
    let truck = super::apply_truck(base, preset, settings)?;
    truck
        .control
        .steps_per_tick(scn.sim.dt_s)
        .map_err(|e| invalid_setting(&scn.file, "truck", &e))?;
    Ok(truck)
}

fn scaled_sensing(
    scn: &Scenario,
    sensing: PalletSensing,
    s: f64,
) -> Result<PalletSensing, ScenarioError> {
    match sensing {
        PalletSensing::Gaussian => Ok(PalletSensing::Gaussian),
        PalletSensing::Scanner {
            mut sensors,
            detector,
            latency_s,
            min_score,
        } => {
            if sensors.iter().all(|n| !n.scanner.has_noise()) {
                return Err(invalid(
                    &scn.file,
                    "sensors.pallet",
                    &format!(
                        "pallet_noise_scale cannot act: the scanners ({}) have no range \
                         noise or bias to scale",
                        names_of(&sensors)
                    ),
                ));
            }
            for n in &mut sensors {
                n.scanner = n.scanner.scaled_errors(s);
            }
            Ok(PalletSensing::Scanner {
                sensors,
                detector,
                latency_s,
                min_score,
            })
        }
    }
}

/// Refuses a localisation scale the localiser cannot take.
fn check_localizer_scale(scn: &Scenario, spec: &ComponentSpec) -> Result<(), ScenarioError> {
    if scn.registry.localizer_takes_noise_scale(&spec.kind) {
        Ok(())
    } else {
        Err(invalid(
            &scn.file,
            "sensors.localizer",
            &format!(
                "localization_noise_scale cannot act: the {:?} localiser has no noise \
                 model the bench can scale",
                spec.kind
            ),
        ))
    }
}

fn scaled_odometry(
    scn: &Scenario,
    scale: Option<f64>,
) -> Result<forkbench_sensors::OdometryConfig, ScenarioError> {
    let base = &scn.noise.odometry;
    let Some(s) = scale else {
        return Ok(base.clone());
    };
    if base.speed_scale_sigma == 0.0 && base.steer_offset_sigma_rad == 0.0 {
        return Err(invalid(
            &scn.file,
            "noise.odometry",
            "odometry_noise_scale cannot act: both odometry σ are 0",
        ));
    }
    let scaled = forkbench_sensors::OdometryConfig {
        speed_scale_sigma: base.speed_scale_sigma * s,
        steer_offset_sigma_rad: base.steer_offset_sigma_rad * s,
    };
    scaled.validate().map_err(|e| {
        invalid(
            &scn.file,
            "noise.odometry",
            &format!("odometry_noise_scale {s} makes {e}"),
        )
    })?;
    Ok(scaled)
}

fn names_of(sensors: &[crate::scenario::sensors::NamedScanner]) -> String {
    sensors
        .iter()
        .map(|n| n.name.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}
