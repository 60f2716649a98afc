//! What a run may choose of a scenario besides its file: a component by name, another localiser or pallet sensing, reflectors taken away; each checked as the file's own would be.

use crate::sensors::PalletSensing;
use crate::{Catalogue, ComponentSpec, Role, Scenario, ScenarioError, invalid, invalid_setting};

impl<R: Catalogue> Scenario<R> {
    /// The component a run names: the scenario's own when the name is its name, else a
    /// registered kind with default settings (checked by building it once).
    pub fn component(
        &self,
        role: Role,
        name: Option<&str>,
    ) -> Result<ComponentSpec, ScenarioError> {
        let own = match role {
            Role::Planner => &self.planner,
            Role::Tracker => &self.tracker,
            Role::Detector | Role::Localizer => {
                let table = if role == Role::Detector {
                    "sensors.pallet.detector"
                } else {
                    "sensors.localizer"
                };
                return Err(ScenarioError::Invalid {
                    file: self.file.clone(),
                    field: table.into(),
                    reason: format!(
                        "a run does not choose the {role}; the scenario's [{table}] does"
                    ),
                });
            }
        };
        let Some(name) = name.filter(|n| *n != own.name) else {
            return Ok(own.clone());
        };
        if let Some(spec) = self
            .named()
            .iter()
            .find(|s| s.role == role && s.name == name)
        {
            return Ok(spec.clone());
        }
        let spec = ComponentSpec::of_kind(role, name);
        self.registry
            .check(&spec)
            .map_err(|e| ScenarioError::Invalid {
                file: self.file.clone(),
                field: role.to_string(),
                reason: format!(
                    "{name:?} is neither this scenario's {role} ({:?}), nor one a components \
                 file defines (`--components FILE`, or components.toml beside the scenario), \
                 nor a {role} kind usable with default settings: {e}",
                    own.name
                ),
            })?;
        Ok(spec)
    }

    /// The same scenario localising with `kind` (`gaussian`, `nav350`) at its default
    /// settings: how a run compares localisation models on the same seeds.
    pub fn with_localizer(self, kind: &str) -> Result<Self, ScenarioError> {
        let spec = self.localizer_for(Some(kind), None)?;
        self.localizing_with(spec)
    }

    /// The same scenario with `names` missing from the NAV350's world (a layout review's
    /// "what if these go"); its map still holds them.
    pub fn with_missing_reflectors(self, names: &[String]) -> Result<Self, ScenarioError> {
        let spec = self.localizer_for(None, Some(names))?;
        self.localizing_with(spec)
    }

    /// The same scenario with the localiser `spec`, built once in its world to check it.
    fn localizing_with(mut self, spec: ComponentSpec) -> Result<Self, ScenarioError> {
        self.registry
            .check_localizer(&spec, &self)
            .map_err(|e| invalid_setting(&self.file, "sensors.localizer", &e))?;
        self.localizer = spec;
        Ok(self)
    }

    /// The pallet sensing a run names by kind (at its defaults), or the scenario's own.
    pub fn sensing_for(&self, kind: Option<&str>) -> Result<PalletSensing, ScenarioError> {
        match kind {
            Some(k) => crate::sensors::of_kind(k, &self.truck, &self.file),
            None => Ok(self.pallet_sensing.clone()),
        }
    }

    /// The localiser a run's overrides name (the scenario's own, or a kind), with any
    /// missing reflectors.
    pub fn localizer_for(
        &self,
        kind: Option<&str>,
        missing_reflectors: Option<&[String]>,
    ) -> Result<ComponentSpec, ScenarioError> {
        let mut spec = match kind {
            Some(kind) => ComponentSpec::of_kind(Role::Localizer, kind),
            None => self.localizer.clone(),
        };
        if let Some(names) = missing_reflectors {
            if !self.registry.localizer_measures_reflectors(&spec.kind) {
                return Err(invalid(
                    &self.file,
                    "sensors.localizer.missing_reflectors",
                    &format!(
                        "only the nav350 localiser measures reflectors; this scenario's is {:?}",
                        spec.kind
                    ),
                ));
            }
            let list = names
                .iter()
                .map(|n| toml::Value::from(n.as_str()))
                .collect();
            spec.settings
                .insert("missing_reflectors".into(), toml::Value::Array(list));
        }
        Ok(spec)
    }
}
