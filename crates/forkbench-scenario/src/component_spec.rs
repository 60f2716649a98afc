//! A component as a scenario names it: `[planner]` / `[tracker]` tables with `kind`, an optional `name`, and settings.

use std::path::PathBuf;

use forkbench_core::settings::{Settings, SettingsError};
use serde::Serialize;

/// The localiser a scenario without `[sensors.localizer]` uses (σ around the truth).
pub const DEFAULT_LOCALIZER: &str = "gaussian";

/// The pocket detector: a scanner's default detector, and the one the Gaussian sensing's
/// `scan` shows.
pub const POCKET_DETECTOR: &str = "pockets";

/// What a constructor knows besides the settings: the component's name and where the
/// defining file lives.
#[derive(Debug, Clone, Default)]
pub struct ComponentContext {
    /// What results are reported under (the table's `name`, or its kind).
    pub name: String,
    /// Directory of the scenario file that configured the component.
    pub dir: PathBuf,
}

/// Which extension point a component fills.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    Planner,
    Tracker,
    Detector,
    Localizer,
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Role::Planner => "planner",
            Role::Tracker => "tracker",
            Role::Detector => "detector",
            Role::Localizer => "localizer",
        })
    }
}

/// One configured component.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentSpec {
    #[serde(skip)]
    pub role: Role,
    /// What results are reported under (default: the kind).
    pub name: String,
    /// The registry entry that builds it.
    pub kind: String,
    /// Its own settings (the table without `kind` and `name`).
    pub settings: Settings,
    /// Directory of the file that configured it (external commands run there).
    #[serde(skip)]
    pub dir: PathBuf,
}

impl ComponentSpec {
    /// A kind with its default settings, named after the kind.
    pub fn of_kind(role: Role, kind: &str) -> Self {
        Self {
            role,
            name: kind.to_owned(),
            kind: kind.to_owned(),
            settings: Settings::new(),
            dir: PathBuf::from("."),
        }
    }

    /// From a scenario value: a bare kind (`planner = "bspline"`, the old form) or a table
    /// with `kind`, optional `name`, and settings. `default_kind` fills a table without
    /// `kind` (old `[tracker]` tables held pure pursuit's settings only).
    pub fn from_value(
        role: Role,
        value: &toml::Value,
        default_kind: Option<&str>,
        dir: PathBuf,
    ) -> Result<Self, SettingsError> {
        let mut settings = match value {
            toml::Value::String(kind) => {
                Settings::from_iter([("kind".to_owned(), kind.as_str().into())])
            }
            toml::Value::Table(t) => t.clone(),
            _ => {
                return Err(SettingsError {
                    field: None,
                    reason: format!("must be a {role} kind or a table with `kind`"),
                });
            }
        };
        let kind = match settings.remove("kind") {
            Some(toml::Value::String(k)) => k,
            Some(_) => return Err(SettingsError::field("kind", "must be a string")),
            None => default_kind
                .map(str::to_owned)
                .ok_or_else(|| SettingsError::field("kind", "missing"))?,
        };
        let name = match settings.remove("name") {
            Some(toml::Value::String(n)) => n,
            Some(_) => return Err(SettingsError::field("name", "must be a string")),
            None => kind.clone(),
        };
        if name.is_empty() || name.len() > 64 || name.chars().any(|c| c.is_control() || c == '/') {
            return Err(SettingsError::field(
                "name",
                "must be 1–64 characters without '/' or control characters",
            ));
        }
        Ok(Self {
            role,
            name,
            kind,
            settings,
            dir,
        })
    }

    pub fn context(&self) -> ComponentContext {
        ComponentContext {
            name: self.name.clone(),
            dir: self.dir.clone(),
        }
    }
}
