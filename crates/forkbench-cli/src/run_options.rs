//! A run's option flags, defined once for every command that runs trials (`trial`, `mission`, `batch`, `estimate`, `falsify`), resolved into the library's `Overrides`.

/// The flags that change what a run does to its scenarios: the noise scales, the sensing
/// models, the missing reflectors and the truck's actuators. Each is a field of
/// [`forkbench_trial::trial::Overrides`] under the same name (`--truck` gives its preset
/// and its settings).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct RunOptionArgs {
    /// Scale of every pallet-sensing error (Gaussian estimate σ, scanner range noise and
    /// bias), 0–100; 0 = exact returns, the other noise kept.
    #[arg(long, allow_hyphen_values = true)]
    pub pallet_noise_scale: Option<f64>,
    /// Scale of the localiser's noise (Gaussian σ, or the NAV350's reflector range and
    /// bearing σ), 0–100; 0 = exact fixes.
    #[arg(long, allow_hyphen_values = true)]
    pub localization_noise_scale: Option<f64>,
    /// Scale of the odometry's speed-scale and steering-offset σ, 0–100; 0 = exact
    /// odometry.
    #[arg(long, allow_hyphen_values = true)]
    pub odometry_noise_scale: Option<f64>,
    /// Estimate the pallet with this sensing at its default settings: gaussian (the
    /// range-scaled Gaussian around the truth), tim561, kinect2 or tim561+kinect2
    /// (default: each scenario's own [sensors.pallet]).
    #[arg(long, value_name = "KIND")]
    pub pallet_sensing: Option<String>,
    /// Localise with this kind at its default settings: gaussian (σ around the truth) or
    /// nav350 (the world's reflectors) (default: each scenario's own
    /// [sensors.localizer]).
    #[arg(long, value_name = "KIND")]
    pub localizer: Option<String>,
    /// Reflectors (comma-separated names) missing from the world while the NAV350's map
    /// keeps them: which legs suffer if they go.
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub missing_reflectors: Option<Vec<String>>,
    /// The truck's actuators and control timing: a preset (`ideal`, `realistic`) or a
    /// truck file (`[steering]`, `[drive]`, `[control]`, `max_steer_rate_radps`, and an
    /// optional `preset`), applied over each scenario's `[truck]`.
    #[arg(long, value_name = "PRESET|FILE")]
    pub truck: Option<String>,
}

impl RunOptionArgs {
    /// The library's overrides these flags give (a truck file is read here).
    pub fn overrides(&self) -> anyhow::Result<forkbench_trial::trial::Overrides> {
        let (truck_preset, truck) = crate::truck_cmd::truck_settings(self.truck.as_deref())?;
        Ok(forkbench_trial::trial::Overrides {
            pallet_noise_scale: self.pallet_noise_scale,
            localization_noise_scale: self.localization_noise_scale,
            odometry_noise_scale: self.odometry_noise_scale,
            localizer: self.localizer.clone(),
            pallet_sensing: self.pallet_sensing.clone(),
            missing_reflectors: self.missing_reflectors.clone(),
            truck_preset,
            truck,
        })
    }
}
