//! Field sets an integrator draws (`[[safety.field_set]]`): convex protective and warning polygons in the truck's frame for one speed range and direction, checked against the truck's footprint margin.

use forkbench_core::SettingsError;
use serde::{Deserialize, Serialize};

/// Most corners a drawn field may have, and how far from the fork root any may lie.
pub const MAX_FIELD_POINTS: usize = 64;
pub const MAX_FIELD_REACH_M: f64 = 30.0;

/// Which way the truck drives while a field set is in force.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    Forward,
    Reverse,
}

impl Direction {
    /// As the scenario file writes it.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Forward => "forward",
            Direction::Reverse => "reverse",
        }
    }
}

/// One drawn field set: it replaces the sized fields of the speed range ending at
/// `speed_max_mps` for travel in `direction`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSetSpec {
    /// The top of the speed range it is for (one of `speed_ranges_mps`).
    pub speed_max_mps: f64,
    pub direction: Direction,
    /// A convex polygon `[[x_m, y_m], …]` in the fork-root frame (x forward, y left).
    #[serde(deserialize_with = "forkbench_core::exact::arrays")]
    pub protective: Vec<[f64; 2]>,
    #[serde(deserialize_with = "forkbench_core::exact::arrays")]
    pub warning: Vec<[f64; 2]>,
}

/// The truck's outline a drawn field must reach beyond, in the fork-root frame.
#[derive(Debug, Clone, Copy)]
pub struct Footprint {
    /// The fork tips ahead of the fork root, the chassis' rear behind it, the wider of
    /// the truck and its load.
    pub front_m: f64,
    pub rear_m: f64,
    pub width_m: f64,
    /// The margin beyond the leading edge the protective field must cover (TZ).
    pub margin_m: f64,
}

impl Footprint {
    /// The truck's own outline, with the scanner's tolerance `margin_m` as the margin.
    pub fn of(truck: &forkbench_core::ForkliftSpec, margin_m: f64) -> Self {
        Footprint {
            front_m: truck.fork_length_m,
            rear_m: truck.body_length_m,
            width_m: truck.body_width_m,
            margin_m,
        }
    }
}

impl FieldSetSpec {
    /// Both polygons convex, finite and within reach, the protective one covering the
    /// band `margin_m` deep beyond the truck's leading edge, `margin_m` wider on each
    /// side; the error names the field.
    pub fn validate(&self, ranges: &[f64], truck: &Footprint) -> Result<(), SettingsError> {
        if !ranges.contains(&self.speed_max_mps) {
            return Err(SettingsError::field(
                "speed_max_mps",
                format!(
                    "no speed range ends at {} m/s (speed_ranges_mps: {ranges:?})",
                    self.speed_max_mps
                ),
            ));
        }
        convex("protective", &self.protective)?;
        convex("warning", &self.warning)?;
        let band = self.margin_band(truck);
        if let Some(c) = band
            .iter()
            .find(|c| !crate::contains(&ccw(&self.protective), **c))
        {
            return Err(SettingsError::field(
                "protective",
                format!(
                    "does not contain the truck's footprint margin: ({:.2}, {:.2}) m, {} m \
                     beyond its {} edge and beside it, lies outside",
                    c[0],
                    c[1],
                    truck.margin_m,
                    if self.direction == Direction::Forward {
                        "leading (fork tips')"
                    } else {
                        "leading (the chassis' rear)"
                    }
                ),
            ));
        }
        Ok(())
    }

    /// The corners of the band just beyond the leading edge (slightly inside, so a
    /// field drawn exactly on it passes).
    fn margin_band(&self, t: &Footprint) -> [[f64; 2]; 4] {
        let m = t.margin_m * (1.0 - 1e-6);
        let y = t.width_m / 2.0 + m;
        let (near, far) = match self.direction {
            Direction::Forward => (t.front_m, t.front_m + m),
            Direction::Reverse => (-t.rear_m, -t.rear_m - m),
        };
        [[near, -y], [far, -y], [far, y], [near, y]]
    }

    /// How far the protective field reaches straight beyond the leading edge, along the
    /// truck's centre line.
    pub fn reach_m(&self, truck: &Footprint) -> f64 {
        let poly = ccw(&self.protective);
        let n = poly.len();
        let along = |x: f64| match self.direction {
            Direction::Forward => x - truck.front_m,
            Direction::Reverse => -truck.rear_m - x,
        };
        (0..n)
            .filter_map(|i| {
                let (a, b) = (poly[i], poly[(i + 1) % n]);
                if (a[1] > 0.0) == (b[1] > 0.0) {
                    return (a[1] == 0.0).then_some(along(a[0]));
                }
                let x = a[0] + (0.0 - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                Some(along(x))
            })
            .fold(0.0, f64::max)
    }

    /// The polygons counter-clockwise, as the detection wants them.
    pub fn polygons(&self) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
        (ccw(&self.protective), ccw(&self.warning))
    }
}

fn signed_area(p: &[[f64; 2]]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

fn ccw(p: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut v = p.to_vec();
    if signed_area(&v) < 0.0 {
        v.reverse();
    }
    v
}

/// 3 to [`MAX_FIELD_POINTS`] finite corners within reach, turning one way only (convex,
/// not self-intersecting), with an area.
fn convex(field: &str, p: &[[f64; 2]]) -> Result<(), SettingsError> {
    let n = p.len();
    if !(3..=MAX_FIELD_POINTS).contains(&n) {
        return Err(SettingsError::field(
            field,
            format!("must list 3 to {MAX_FIELD_POINTS} corners (got {n})"),
        ));
    }
    if let Some(c) = p.iter().find(|c| {
        !c.iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_FIELD_REACH_M)
    }) {
        return Err(SettingsError::field(
            field,
            format!(
                "corner {c:?} must be finite and within {MAX_FIELD_REACH_M} m of the fork root"
            ),
        ));
    }
    let area = signed_area(p);
    if area.abs() < 1e-6 {
        return Err(SettingsError::field(field, "has no area"));
    }
    let turns_one_way = (0..n).all(|i| {
        let (a, b, c) = (p[i], p[(i + 1) % n], p[(i + 2) % n]);
        let cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
        cross * area.signum() >= -1e-12
    });
    // Turning one way with a total turn of one revolution: the angle sum rules out a
    // star drawn with every turn the same way.
    let turn: f64 = (0..n)
        .map(|i| {
            let (a, b, c) = (p[i], p[(i + 1) % n], p[(i + 2) % n]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
            (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1])
        })
        .sum();
    if !turns_one_way || (turn.abs() - std::f64::consts::TAU).abs() > 1e-6 {
        return Err(SettingsError::field(
            field,
            "must be convex, its corners in order round it (split a concave field into \
             field sets the truck switches between)",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRUCK: Footprint = Footprint {
        front_m: 1.6,
        rear_m: 2.45,
        width_m: 1.2,
        margin_m: 0.1,
    };

    fn forward(protective: Vec<[f64; 2]>) -> FieldSetSpec {
        FieldSetSpec {
            speed_max_mps: 0.3,
            direction: Direction::Forward,
            warning: protective.clone(),
            protective,
        }
    }

    #[test]
    fn a_field_round_the_forks_passes_and_one_short_of_the_margin_is_refused() {
        let good = forward(vec![[0.0, -1.0], [2.5, -1.0], [2.5, 1.0], [0.0, 1.0]]);
        assert!(good.validate(&[0.3, 0.8], &TRUCK).is_ok());
        assert!((good.reach_m(&TRUCK) - 0.9).abs() < 1e-9);
        let clockwise = forward(vec![[0.0, 1.0], [2.5, 1.0], [2.5, -1.0], [0.0, -1.0]]);
        assert!(clockwise.validate(&[0.3], &TRUCK).is_ok());
        let short = forward(vec![[0.0, -1.0], [1.65, -1.0], [1.65, 1.0], [0.0, 1.0]]);
        let e = short
            .validate(&[0.3], &TRUCK)
            .expect_err("5 cm beyond the tips");
        assert_eq!(e.field.as_deref(), Some("protective"));
        assert!(e.reason.contains("footprint margin"), "{}", e.reason);
        let narrow = forward(vec![[0.0, -0.65], [2.5, -0.65], [2.5, 0.65], [0.0, 0.65]]);
        assert!(narrow.validate(&[0.3], &TRUCK).is_err(), "not 0.1 m beside");
    }

    #[test]
    fn concave_unknown_range_and_degenerate_fields_are_refused_by_field() {
        let mut f = forward(vec![
            [0.0, -1.0],
            [2.5, -1.0],
            [1.0, 0.0],
            [2.5, 1.0],
            [0.0, 1.0],
        ]);
        let e = f.validate(&[0.3], &TRUCK).expect_err("concave");
        assert!(e.reason.contains("convex"), "{}", e.reason);
        f.protective = vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]];
        assert!(
            f.validate(&[0.3], &TRUCK)
                .expect_err("flat")
                .reason
                .contains("area")
        );
        f.protective = vec![[0.0, -1.0], [2.5, -1.0], [2.5, 1.0], [0.0, 1.0]];
        let e = f
            .validate(&[0.6], &TRUCK)
            .expect_err("no range ends at 0.3");
        assert_eq!(e.field.as_deref(), Some("speed_max_mps"));
        f.warning = vec![[0.0, 0.0], [f64::NAN, 1.0], [1.0, 1.0]];
        assert_eq!(
            f.validate(&[0.3], &TRUCK)
                .expect_err("NaN")
                .field
                .as_deref(),
            Some("warning")
        );
    }
}
