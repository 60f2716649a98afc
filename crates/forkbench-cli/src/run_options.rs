//! A run's option flags for every command that runs trials (`trial`, `mission`, `batch`, `estimate`, `falsify`): the library's `Overrides` as flags, and `--truck` read into its preset and settings.

use forkbench_trial::trial::Overrides;

/// The flags that change what a run does to its scenarios: every field of
/// [`Overrides`] (its flag is its name with dashes, its help its doc), and `--truck`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct RunOptionArgs {
    #[command(flatten)]
    pub options: Overrides,
    /// The truck: a preset of actuators and timing (`ideal`, `realistic`), or a truck
    /// file (a whole truck as `trucks/*.toml`, or some of its keys: geometry, mass,
    /// `[steering]`, `[drive]`, `[control]`, an optional `preset`), applied over each
    /// scenario's `[truck]` as if that table said so.
    #[arg(long, value_name = "PRESET|FILE")]
    pub truck: Option<String>,
}

impl RunOptionArgs {
    /// The library's overrides these flags give (a truck file is read here).
    pub fn overrides(&self) -> anyhow::Result<Overrides> {
        let (truck_preset, truck) = crate::truck_cmd::truck_settings(self.truck.as_deref())?;
        Ok(Overrides {
            truck_preset,
            truck,
            ..self.options.clone()
        })
    }

    /// The truck file `--truck` names, if it names one (not a preset): an input no output
    /// of the run may replace.
    pub fn truck_file(&self) -> Option<std::path::PathBuf> {
        self.truck
            .as_deref()
            .filter(|t| forkbench_core::actuators::Actuators::preset(t).is_none())
            .map(std::path::PathBuf::from)
    }
}
