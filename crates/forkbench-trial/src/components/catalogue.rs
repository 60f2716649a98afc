//! The registry as the scenario format's [`Catalogue`]: what a scenario's loader checks its components and phases against.

use std::sync::Arc;

use forkbench_core::settings::SettingsError;
use forkbench_scenario::{Catalogue, ComponentSpec, Context, PhaseSpec, Scenario};

use super::{LocalizerContext, Registry};
use crate::phase::Phase;

impl Catalogue for Registry {
    type Phase = Arc<dyn Phase>;

    fn builtin() -> Arc<Self> {
        Registry::shared()
    }

    fn check(&self, spec: &ComponentSpec) -> Result<(), SettingsError> {
        Registry::check(self, spec)
    }

    /// Builds the localiser in the scenario's world, on its truck, with noise on.
    fn check_localizer(
        &self,
        spec: &ComponentSpec,
        scn: &Scenario<Self>,
    ) -> Result<(), SettingsError> {
        let surfaces = scn.world.fixed_surfaces();
        let cx = LocalizerContext {
            nav350: &scn.noise.nav350,
            noise: true,
            noise_scale: 1.0,
            reflectors: &scn.world.reflector,
            surfaces: &surfaces,
            truck: &scn.truck,
        };
        self.localizer(spec, &cx).map(drop)
    }

    fn detector_takes_pocket_settings(&self, kind: &str) -> bool {
        Registry::detector_takes_pocket_settings(self, kind)
    }

    fn localizer_measures_reflectors(&self, kind: &str) -> bool {
        Registry::localizer_measures_reflectors(self, kind)
    }

    fn phases(
        &self,
        names: &[String],
        settings: &toml::Table,
        cx: &dyn Context,
    ) -> Result<Vec<PhaseSpec<Arc<dyn Phase>>>, (String, String)> {
        crate::phase::resolve(names, settings, cx, self.phase_kinds())
    }
}
