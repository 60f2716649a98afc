//! A components file: external (or configured built-in) planners, trackers and detectors defined once by name, usable with `--planner` / `--tracker` on any scenario and `detect --detector`.

use std::path::Path as FsPath;

use serde::Deserialize;

use super::{Scenario, invalid, invalid_setting, read};
use crate::Catalogue;
use crate::ScenarioError;
use crate::component_spec::{ComponentSpec, Role};

/// The file found beside a scenario and used with it without being asked for.
pub const BESIDE: &str = "components.toml";

/// Most components one file may define.
const MAX_NAMED: usize = 64;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NamedFile {
    #[serde(default)]
    planner: Vec<toml::Spanned<toml::Value>>,
    #[serde(default)]
    tracker: Vec<toml::Spanned<toml::Value>>,
    #[serde(default)]
    detector: Vec<toml::Spanned<toml::Value>>,
}

/// The components `path` defines (`[[planner]]`, `[[tracker]]` and `[[detector]]` tables,
/// each with a `name` and a `kind`), each checked against `registry`; external commands
/// run in the file's directory. Errors name the file, line and field.
pub fn load_components(
    path: &FsPath,
    registry: &impl Catalogue,
) -> Result<Vec<ComponentSpec>, ScenarioError> {
    let file = path.display().to_string();
    let text = read(path)?;
    let f: NamedFile = super::parse(&text, &file)?;
    let dir = forkbench_plan::external::dir_of(path);
    let mut out: Vec<ComponentSpec> = Vec::new();
    let roles = [
        (Role::Planner, &f.planner),
        (Role::Tracker, &f.tracker),
        (Role::Detector, &f.detector),
    ];
    for (role, list) in roles {
        for (i, v) in list.iter().enumerate() {
            let line = text[..v.span().start.min(text.len())]
                .lines()
                .count()
                .max(1);
            let at = format!("{file}:{line}");
            let field = format!("{role}[{i}]");
            let has_name = v.get_ref().get("name").is_some();
            if !has_name {
                return Err(invalid(
                    &at,
                    &format!("{field}.name"),
                    "missing: a defined component is used by its name",
                ));
            }
            let spec = ComponentSpec::from_value(role, v.get_ref(), None, dir.clone())
                .and_then(|s| registry.check(&s).map(|()| s))
                .map_err(|e| invalid_setting(&at, &field, &e))?;
            // A file adds names; a built-in kind's name would make `--planner bspline`
            // run whatever the file says while every record says bspline.
            if registry
                .check(&ComponentSpec::of_kind(role, &spec.name))
                .is_ok()
            {
                return Err(invalid(
                    &at,
                    &format!("{field}.name"),
                    &format!(
                        "{:?} is the name of a built-in {role}; this file defines it as kind {:?}: a components file adds names and never redefines a built-in, so name it otherwise",
                        spec.name, spec.kind
                    ),
                ));
            }
            if out.iter().any(|o| o.role == role && o.name == spec.name) {
                return Err(invalid(
                    &at,
                    &format!("{field}.name"),
                    &format!("{:?} is defined twice", spec.name),
                ));
            }
            out.push(spec);
        }
    }
    if out.len() > MAX_NAMED {
        return Err(invalid(
            &file,
            "planner",
            &format!("defines {} components; at most {MAX_NAMED}", out.len()),
        ));
    }
    Ok(out)
}

impl<R: Catalogue> Scenario<R> {
    /// The scenario with `named` usable by name (`--planner NAME`, `--tracker NAME`); a
    /// name is the scenario's own component's only when it is that one.
    pub fn with_named(mut self, named: Vec<ComponentSpec>) -> Self {
        for spec in named {
            self.named
                .retain(|o| !(o.role == spec.role && o.name == spec.name));
            self.named.push(spec);
        }
        self
    }

    /// [`Scenario::with_named`] with the components of the file at `path`.
    pub fn with_components_file(self, path: &FsPath) -> Result<Self, ScenarioError> {
        let named = load_components(path, &*self.registry)?;
        let mut scn = self.with_named(named);
        scn.read_from.push(path.to_path_buf());
        Ok(scn)
    }

    /// The components defined for use by name (a components file's).
    pub fn named(&self) -> &[ComponentSpec] {
        &self.named
    }
}
