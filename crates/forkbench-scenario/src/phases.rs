//! The phase list after the pick (`phases`, `[phase.NAME]`), built through the catalogue against the scenario's world, pallet and mission; errors at their line.

use forkbench_core::{PalletSpec, Pose2};

use super::checks::at_line;
use super::file::ScenarioFile;
use super::{World, invalid};
use crate::ScenarioError;
use crate::footprints::{pallet_footprint, shrunk};

/// The phases after the pick from `phases` and `[phase.NAME]`; errors name the line.
pub(super) fn resolve<R: crate::Catalogue>(
    f: &ScenarioFile,
    (world, pallet, mission): (&World, &PalletSpec, Option<&super::mission::MissionSpec>),
    (text, file): (&str, &str),
    catalogue: &R,
) -> Result<Vec<crate::PhaseSpec<R::Phase>>, ScenarioError> {
    let names = f.phases.as_ref();
    let list = names.map_or_else(|| vec![crate::PICK.to_owned()], |n| n.get_ref().clone());
    let cx = Site {
        world,
        pallet,
        mission,
    };
    catalogue
        .phases(&list, &f.phase, &cx)
        .map_err(|(field, reason)| {
            // A phase's settings are at their table's header; the list's errors, and those of
            // a phase without a table, at the list.
            let list_at = || {
                names.map_or_else(
                    || file.to_owned(),
                    |n| {
                        let line = text[..n.span().start.min(text.len())].matches('\n').count();
                        format!("{file}:{}", line + 1)
                    },
                )
            };
            let at = match field.split_once('.') {
                Some(("phase", name)) => {
                    let at = at_line(file, text, &format!("[phase.{name}]"));
                    if at == file { list_at() } else { at }
                }
                _ => list_at(),
            };
            invalid(&at, &field, &reason)
        })
}

/// The scenario's world, pallet and mission, as a phase's settings are checked against them.
struct Site<'a> {
    world: &'a World,
    pallet: &'a PalletSpec,
    mission: Option<&'a super::mission::MissionSpec>,
}

impl crate::catalogue::Context for Site<'_> {
    fn pallet(&self) -> &PalletSpec {
        self.pallet
    }

    fn slot_pose(&self, name: &str) -> Option<Pose2> {
        self.world.slot_pose(name)
    }

    fn slot_names(&self) -> Vec<String> {
        self.world
            .pallet_slot
            .iter()
            .map(|s| s.name.clone())
            .collect()
    }

    fn station_pose(&self, name: &str) -> Option<Pose2> {
        self.world.station_pose(name)
    }

    fn station_names(&self) -> Vec<String> {
        self.world.station.iter().map(|s| s.name.clone()).collect()
    }

    fn pallet_overlaps(&self, at: &Pose2) -> Option<String> {
        let (obstacles, mut labels) = self.world.footprint_obstacles();
        let hit = obstacles.hit(&shrunk(pallet_footprint(self.pallet)), at)?;
        Some(labels.swap_remove(hit))
    }

    fn mission_start(&self) -> Option<(String, Pose2)> {
        self.mission.map(|m| (m.start.name.clone(), m.start.pose))
    }
}
