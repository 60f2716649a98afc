//! A component's settings table (as written in a scenario file) and its typed, checked reading.

use serde::de::DeserializeOwned;

/// The settings of one pluggable component: the keys of its scenario table besides `kind`.
pub type Settings = toml::Table;

/// Why a component's settings were refused: the field (when one is to blame) and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{reason}", field.as_ref().map(|f| format!("{f}: ")).unwrap_or_default())]
pub struct SettingsError {
    pub field: Option<String>,
    pub reason: String,
}

impl SettingsError {
    pub fn field(field: &str, reason: impl Into<String>) -> Self {
        Self {
            field: Some(field.to_owned()),
            reason: reason.into(),
        }
    }
}

/// A word that is none of the choices a setting or flag takes, with what it takes.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{given:?}: {expected}")]
pub struct UnknownChoice {
    pub given: String,
    /// What is taken instead, as a phrase (`expected "scenario", "replan" or "both"`).
    pub expected: String,
}

impl UnknownChoice {
    pub fn new(given: &str, expected: impl Into<String>) -> Self {
        Self {
            given: given.to_owned(),
            expected: expected.into(),
        }
    }
}

/// Checks every `(field, value, lo, hi)`: each value finite and within `[lo, hi]`; the
/// error names the first field outside its range, the range and the value.
pub fn in_ranges(fields: &[(&str, f64, f64, f64)]) -> Result<(), SettingsError> {
    for &(field, value, lo, hi) in fields {
        if !(value.is_finite() && value >= lo && value <= hi) {
            return Err(SettingsError::field(
                field,
                format!("must lie in [{lo}, {hi}] (got {value})"),
            ));
        }
    }
    Ok(())
}

/// Reads `settings` into a component's typed config (which should deny unknown fields);
/// the error names the offending field where serde does.
pub fn parse<T: DeserializeOwned>(settings: &Settings) -> Result<T, SettingsError> {
    T::deserialize(toml::Value::Table(settings.clone())).map_err(|e| {
        let message = e.message().trim().to_owned();
        // serde names unknown and missing fields in backticks: report that field.
        let field = ["unknown field `", "missing field `"]
            .iter()
            .find_map(|p| message.strip_prefix(p))
            .and_then(|rest| rest.split('`').next())
            .map(str::to_owned);
        SettingsError {
            field,
            reason: message,
        }
    })
}

/// Refuses every key of `settings`: for components that take none.
pub fn none(settings: &Settings) -> Result<(), SettingsError> {
    match settings.keys().next() {
        Some(k) => Err(SettingsError::field(
            k,
            "unknown field: this component takes no settings",
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Cfg {
        gain: f64,
    }

    #[test]
    fn unknown_and_wrong_fields_are_named() {
        let t: Settings = toml::from_str("gain = 1.0\ngian = 2.0").expect("toml");
        let e = parse::<Cfg>(&t).expect_err("unknown");
        assert_eq!(e.field.as_deref(), Some("gian"), "{e}");
        let t: Settings = toml::from_str("gain = \"x\"").expect("toml");
        assert!(parse::<Cfg>(&t).is_err());
        let t: Settings = toml::from_str("gain = 0.5").expect("toml");
        assert_eq!(parse::<Cfg>(&t).expect("ok").gain, 0.5);
    }
}
