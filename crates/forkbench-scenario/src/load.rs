//! Loading a scenario from its file: its world, truck file and a components file beside it, and the list of files it was read from.

use std::cell::RefCell;
use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use crate::input::read;
use crate::{Catalogue, Scenario, ScenarioError, World, named, truck_file};

impl<R: Catalogue> Scenario<R> {
    /// Loads `path`, checking its components against the built-in catalogue.
    pub fn load(path: &FsPath) -> Result<Self, ScenarioError> {
        Self::load_with(path, R::builtin())
    }

    /// Loads with a registry that may hold the caller's own components.
    pub fn load_with(path: &FsPath, registry: Arc<R>) -> Result<Self, ScenarioError> {
        let file = path.display().to_string();
        let text = read(path)?;
        let dir = forkbench_plan::external::dir_of(path);
        let read_from = RefCell::new(vec![path.to_path_buf()]);
        let load_world = |world: &FsPath| {
            read_from.borrow_mut().push(dir.join(world));
            World::load(&dir.join(world))
        };
        let load_truck = |p: &str| {
            read_from.borrow_mut().push(dir.join(p));
            truck_file::read_truck_file(&dir.join(p))
        };
        let layout = Self::parse_layout(&text, &file, load_world, &load_truck, None)?;
        let mut scn = layout.with_components(&text, registry, dir.clone())?;
        scn.read_from = read_from.into_inner();
        // The documented rule: a components file beside the scenario comes with it.
        let beside = dir.join(named::BESIDE);
        match beside.is_file() {
            true => scn.with_components_file(&beside),
            false => Ok(scn),
        }
    }

    /// The files this scenario was read from: its own, its world's and truck's, and the
    /// components files it took (none for an embedded or parsed scenario).
    pub fn files(&self) -> &[PathBuf] {
        &self.read_from
    }
}
