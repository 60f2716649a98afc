//! A scenario's `[safety]` table: checked at load against its truck, and the protective fields it sizes.

use forkbench_safety::{FieldSizing, Footprint};

use super::checks::at_line;
use super::file::ScenarioFile;
use super::{Scenario, World, invalid, invalid_setting};
use crate::ScenarioError;
use forkbench_core::geometry::Obstacle;
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_safety::MoverSpec;

/// The `[safety]` settings in range, their speed ranges covering the truck's top speed;
/// the error names the file, the line of the key and the field.
pub(super) fn check(f: &ScenarioFile, (file, text): (&str, &str)) -> Result<(), ScenarioError> {
    let Some(s) = &f.safety else {
        return Ok(());
    };
    s.validate(f.truck.max_speed_mps).map_err(|e| {
        let key = e
            .field
            .as_deref()
            .map(|k| k.rsplit('.').next().unwrap_or(k));
        invalid_setting(&key_line(file, text, key), "safety", &e)
    })?;
    let truck = Footprint::of(&f.truck, s.scanner.tolerance_m);
    s.validate_field_sets(&truck).map_err(|(k, e)| {
        let at = text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.trim_start().starts_with("[[safety.field_set]]"))
            .nth(k)
            .map_or_else(|| file.to_owned(), |(n, _)| format!("{file}:{}", n + 1));
        invalid_setting(&at, &format!("safety.field_set[{k}]"), &e)
    })
}

/// `file:line` of `key` within the `[safety]` tables (else of `[safety]`, else the file).
fn key_line(file: &str, text: &str, key: Option<&str>) -> String {
    let Some(start) = text
        .lines()
        .position(|l| l.trim_start().starts_with("[safety"))
    else {
        return file.to_owned();
    };
    let after: String = text.lines().skip(start).collect::<Vec<_>>().join("\n");
    let at = key.map(|k| at_line("", &after, k)).unwrap_or_default();
    match at.strip_prefix(':').and_then(|n| n.parse::<usize>().ok()) {
        Some(n) => format!("{file}:{}", start + n),
        None => format!("{file}:{}", start + 1),
    }
}

/// Each `[[mover]]` in range, its route clear of the world's racks and walls (a person's
/// body, a vehicle's outline, along every leg of the route); errors name the line of
/// the mover's table and the field.
pub(super) fn check_movers(
    f: &ScenarioFile,
    world: &World,
    (file, text): (&str, &str),
) -> Result<(), ScenarioError> {
    let tables: Vec<usize> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with("[[mover]]"))
        .map(|(i, _)| i + 1)
        .collect();
    let obstacles = world.obstacles();
    // The same racks and walls, in the same order, by name.
    let labels = world.footprint_obstacles().1;
    let points: usize = f.mover.iter().map(|m| m.route.len()).sum();
    if points > MAX_MOVER_ROUTE_POINTS {
        return Err(invalid(
            file,
            "mover",
            &format!(
                "the movers' routes list {points} points in all; at most \
                 {MAX_MOVER_ROUTE_POINTS} (every point is stepped and sensed each physics step)"
            ),
        ));
    }
    for (k, m) in f.mover.iter().enumerate() {
        let at = tables
            .get(k)
            .map_or_else(|| file.to_owned(), |n| format!("{file}:{n}"));
        let prefix = format!("mover[{k}]");
        m.validate()
            .map_err(|e| invalid_setting(&at, &prefix, &e))?;
        if let Some(why) = route_blocked(m, &obstacles, &labels) {
            return Err(invalid(&at, &format!("{prefix}.route"), &why));
        }
    }
    Ok(())
}

/// Where a mover's route runs through an obstacle, if it does. A body carried along a
/// straight leg, heading along it, sweeps exactly one rectangle (the leg's length plus
/// its own), so each leg costs one exact test per obstacle whatever its length.
fn route_blocked(m: &MoverSpec, obstacles: &[Obstacle], labels: &[String]) -> Option<String> {
    let (l, w) = m.body_m();
    for (k, leg) in m.route.windows(2).enumerate() {
        let (a, b) = (leg[0], leg[1]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
        let centre = Pose2::new((a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, heading);
        let swept = (centre, len + l, w);
        let hit = obstacles.iter().position(|o| {
            forkbench_safety::rect_gap_m(&(o.centre, o.length_m, o.width_m), &swept) <= 0.0
        });
        if let Some(o) = hit {
            let name = labels.get(o).map_or("a rack or wall", String::as_str);
            return Some(format!(
                "leg {k} from ({:.2}, {:.2}) m to ({:.2}, {:.2}) m runs through {name}",
                a[0], a[1], b[0], b[1]
            ));
        }
    }
    None
}

/// Most route points over all of a scenario's movers: each is stepped, sensed and judged
/// every physics step, so the total bounds a trial's work, not the count of movers.
pub const MAX_MOVER_ROUTE_POINTS: usize = 4096;

impl<R: crate::Catalogue> Scenario<R> {
    /// The truck's outline drawn fields are checked against: fork tips, chassis' rear,
    /// width, and the scanner's tolerance as the margin.
    pub fn safety_footprint(&self) -> Footprint {
        let cfg = self.safety.clone().unwrap_or_default();
        Footprint::of(&self.truck, cfg.scanner.tolerance_m)
    }

    /// The protective field of each of the scenario's speed ranges, empty and at rated
    /// load, braking on its floor (`[sim] tyre_friction`); Z_R follows the world's
    /// reflectors unless `[safety] reflectors_near` says otherwise. Without `[safety]`,
    /// its defaults.
    pub fn safety_fields(&self) -> Result<FieldSizing, ScenarioError> {
        self.safety_fields_for(&self.truck)
    }

    /// The same for `truck` (a run's, whose actuators may differ from the scenario's).
    pub fn safety_fields_for(&self, truck: &ForkliftSpec) -> Result<FieldSizing, ScenarioError> {
        let cfg = self.safety.clone().unwrap_or_default();
        forkbench_safety::size_fields(
            &cfg,
            truck,
            &self.sim,
            &self.pallet,
            !self.world.reflector.is_empty(),
        )
        .map_err(|e| ScenarioError::Invalid {
            file: self.file.clone(),
            field: "safety".to_owned(),
            reason: e.to_string(),
        })
    }
}
