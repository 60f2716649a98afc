//! Where a truck's unladen mass lies between its axles: from its declared axle loads (VDI 2198 line 2.3) or its chassis centre, and the refusal of a truck that would tip or leave an axle without grip.

use crate::vehicle::{ForkliftSpec, SpecError};

/// The least share of the unladen weight either axle may carry: a choice. Below it that
/// axle's tyres pass too little side force to hold the truck in a turn (in the tyre model,
/// grip is μ times the axle's load), and real trucks' type sheets (VDI 2198 line 2.3) put
/// a quarter or more on each.
pub const MIN_AXLE_SHARE: f64 = 0.05;

/// How far a declared service weight may differ from the sum of the declared axle loads:
/// a choice, for sheets that round each figure.
const AXLE_SUM_TOLERANCE: f64 = 0.02;

/// `field` refused: `reason`, with the value given.
fn refused(field: &str, value: f64, reason: &str) -> SpecError {
    SpecError::field(field, format!("{reason} (got {value})"))
}

impl ForkliftSpec {
    /// Where the unladen truck's centre of mass lies ahead of the fixed axle: from the
    /// declared axle loads (the moment balance about the fixed axle), else the chassis
    /// centre.
    pub fn mass_centre_ahead_of_front_axle_m(&self) -> f64 {
        match (self.axle_load_fixed_kg, self.axle_load_steered_kg) {
            (Some(f), Some(s)) => -self.wheelbase_m * s / (f + s),
            _ => self.fork_root_ahead_of_front_axle_m - self.body_length_m / 2.0,
        }
    }

    /// The axle loads, when declared, are both given, sum to the service weight, and the
    /// centre of mass leaves each axle at least [`MIN_AXLE_SHARE`] of the weight: a truck
    /// whose mass lies behind its steered wheel would tip, and one axle would slide.
    pub(crate) fn validate_mass_centre(&self) -> Result<(), SpecError> {
        let declared = match (self.axle_load_fixed_kg, self.axle_load_steered_kg) {
            (None, None) => false,
            (Some(f), Some(s)) => {
                crate::settings::in_ranges(&[
                    ("axle_load_fixed_kg", f, 0.0, 100_000.0),
                    ("axle_load_steered_kg", s, 0.0, 100_000.0),
                ])?;
                let sum = f + s;
                if (self.mass_kg - sum).abs() > AXLE_SUM_TOLERANCE * sum {
                    let side = if self.mass_kg < sum { "below" } else { "above" };
                    return Err(refused(
                        "mass_kg",
                        self.mass_kg,
                        &format!(
                            "{side} the axle loads it declares ({f} kg + {s} kg = {sum} kg): \
                             VDI 2198's service weight (line 2.1) is their sum (line 2.3)"
                        ),
                    ));
                }
                true
            }
            (Some(_), None) | (None, Some(_)) => {
                let missing = match self.axle_load_fixed_kg {
                    Some(_) => "axle_load_steered_kg",
                    None => "axle_load_fixed_kg",
                };
                return Err(SpecError::field(
                    missing,
                    "must be given with the other axle's load: together they place the \
                     centre of mass (VDI 2198 line 2.3)",
                ));
            }
        };
        let steered = -self.mass_centre_ahead_of_front_axle_m() / self.wheelbase_m;
        if (MIN_AXLE_SHARE..=1.0 - MIN_AXLE_SHARE).contains(&steered) {
            return Ok(());
        }
        let (axle, share) = match steered < MIN_AXLE_SHARE {
            true => ("steered wheel", steered),
            false => ("fixed axle", 1.0 - steered),
        };
        let carries = format!(
            "the {axle} would carry {:.0} % of the unladen weight (at least {:.0} % needed to \
             hold a turn; below 0 the truck tips)",
            100.0 * share,
            100.0 * MIN_AXLE_SHARE
        );
        Err(match declared {
            true => SpecError::field(
                match steered < MIN_AXLE_SHARE {
                    true => "axle_load_steered_kg",
                    false => "axle_load_fixed_kg",
                },
                carries,
            ),
            false => refused(
                "body_length_m",
                self.body_length_m,
                &format!(
                    "without declared axle loads the bench puts the mass at the chassis \
                     centre, {:.3} m from the fixed axle: {carries}; declare \
                     axle_load_fixed_kg and axle_load_steered_kg (VDI 2198 line 2.3)",
                    -self.mass_centre_ahead_of_front_axle_m()
                ),
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TruckLayout;

    /// Issue 77: a drawn stacker whose chassis centre lay behind its steered wheel left
    /// the load wheels no load, so no side grip: it spun off its path with nothing named.
    /// Now such a truck is refused at load, and declared axle loads place the mass.
    #[test]
    fn the_mass_centre_lies_between_the_axles_or_the_truck_is_refused() {
        let stacker = ForkliftSpec {
            layout: TruckLayout::PalletStacker,
            wheelbase_m: 1.25,
            max_steer_rad: 0.8,
            body_length_m: 2.94,
            mass_kg: 1500.0,
            fork_length_m: 1.0,
            fork_root_ahead_of_front_axle_m: -0.43,
            ..ForkliftSpec::default()
        };
        let e = stacker
            .validate()
            .expect_err("mass behind the steered wheel");
        assert_eq!(e.field.as_deref(), Some("body_length_m"));
        assert!(
            e.reason.contains("-52 %") && e.reason.contains("axle_load_fixed_kg"),
            "{e:?}"
        );
        let declared = ForkliftSpec {
            axle_load_fixed_kg: Some(500.0),
            axle_load_steered_kg: Some(1000.0),
            ..stacker.clone()
        };
        declared.validate().expect("axle loads place the mass");
        assert!((declared.mass_centre_ahead_of_front_axle_m() + 1.25 * 2.0 / 3.0).abs() < 1e-12);
        let light = ForkliftSpec {
            mass_kg: 1400.0,
            ..declared.clone()
        };
        let e = light.validate().expect_err("mass below its axle loads");
        assert_eq!(e.field.as_deref(), Some("mass_kg"));
        assert!(e.reason.starts_with("below the axle loads"), "{e:?}");
        let half = ForkliftSpec {
            axle_load_steered_kg: None,
            ..declared.clone()
        };
        let e = half.validate().expect_err("one axle only");
        assert_eq!(e.field.as_deref(), Some("axle_load_steered_kg"));
        let tail = ForkliftSpec {
            axle_load_fixed_kg: Some(30.0),
            axle_load_steered_kg: Some(1470.0),
            ..declared
        };
        let e = tail.validate().expect_err("2 % on the load wheels");
        assert_eq!(e.field.as_deref(), Some("axle_load_fixed_kg"));
        // The A30 without axle loads: its mass at the chassis centre, 48 % on the rear.
        let a30 = ForkliftSpec::default();
        assert_eq!(a30.mass_centre_ahead_of_front_axle_m(), 0.45 - 2.45 / 2.0);
    }
}
