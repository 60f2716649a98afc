//! A scenario's `[safety]` settings: the safety scanner, the truck's response, the supplements, and the speed ranges that switch field sets.

use forkbench_core::SettingsError;
use forkbench_core::settings::in_ranges;
use serde::{Deserialize, Serialize};

/// Most field sets (speed ranges) a configuration may switch between.
pub const MAX_SPEED_RANGES: usize = 16;

/// The safety laser scanner's properties that size its fields (an S300-class device by
/// default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SafetyScannerSpec {
    /// TZ: the scanner's measurement tolerance range.
    pub tolerance_m: f64,
    /// Time from an object entering the protective field to the safety outputs switching
    /// off (basic response time with multiple sampling).
    pub response_time_s: f64,
    /// Smallest object the protective field detects (70 mm: a leg); with the fields'
    /// reach it sets the angle between beams.
    pub resolution_m: f64,
    /// Each scanner's field of view. The two scanners sit at diagonal corners (the fork
    /// root's left facing forward-left, the chassis' rear right facing back-right), so at
    /// 270° they see all round the truck.
    pub fov_deg: f64,
    /// The range errors the scanner makes, which TZ and Z_R budget for.
    pub range_error: RangeError,
}

/// How the safety scanner's ranges err.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RangeError {
    /// Exact ranges.
    None,
    /// The worst case the formula's supplements budget for: every range reads long by the
    /// tolerance TZ, and by Z_R more where the reflector supplement applies (a
    /// retroreflector's glare), so an object shows that much further from the scanner.
    #[default]
    WorstCase,
}

impl Default for SafetyScannerSpec {
    fn default() -> Self {
        Self {
            tolerance_m: 0.1,
            response_time_s: 0.08,
            resolution_m: 0.07,
            fov_deg: 270.0,
            range_error: RangeError::WorstCase,
        }
    }
}

/// Whether the reflector supplement Z_R applies (a retroreflector within 6 m of the
/// protective field).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReflectorsNear {
    /// When the world has reflector posts (the NAV350's landmarks are retroreflectors).
    #[default]
    Auto,
    Yes,
    No,
}

/// How the truck's safety fields are sized (`[safety]` in a scenario).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SafetyConfig {
    /// Upper speed of each field set's range, ascending; the first range starts at
    /// standstill, and the last must reach the truck's top speed.
    pub speed_ranges_mps: Vec<f64>,
    /// The vehicle control's response time, signal propagation included (S_AnF's time).
    pub controller_response_s: f64,
    /// The truck's clearance above the floor (under 120 mm adds Z_F).
    pub ground_clearance_m: f64,
    pub reflectors_near: ReflectorsNear,
    /// Z_G: a general supplement (100 mm for an S300).
    pub general_supplement_m: f64,
    /// Z_B: a supplement for braking force that decreases in service, from the vehicle's
    /// documentation.
    pub braking_supplement_m: f64,
    pub scanner: SafetyScannerSpec,
    /// Whether the safety function runs in trials (off: the scenario only sizes fields).
    pub monitor: bool,
    /// The protective fields a trial monitors, as a multiple of the sized S_L (below 1:
    /// fields shorter than the formula gives).
    pub field_length_scale: f64,
    /// How much further ahead each warning field reaches than its protective field (and
    /// half that wider on each side).
    pub warning_margin_m: f64,
    /// The speed a warning-field intrusion holds the truck to.
    pub warning_speed_mps: f64,
    /// How long the fields must stay clear before a stopped truck drives on.
    pub resume_dwell_s: f64,
    /// In the pick's and the place's entry the fields are muted once the fork tips come
    /// this close to the target (the pallet face the truck aims at; where the place's
    /// path leaves the tips): the pallet or the slot between rack uprights is the
    /// target, not an obstacle. Muted while driving forwards until that part of the
    /// cycle ends; backing out is watched. Absent (the default), each field is muted
    /// only once the target would itself enter it: the warning field at its reach, the
    /// protective field at its length S_L (the stopping distance at the speed in force
    /// with the supplements), so a person crossing before that point is seen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mute_near_target_m: Option<f64>,
    /// Field sets drawn by hand (`[[safety.field_set]]`), each replacing the sized fields
    /// of one speed range and direction.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub field_set: Vec<crate::custom::FieldSetSpec>,
}

impl Default for SafetyConfig {
    fn default() -> Self {
        Self {
            speed_ranges_mps: vec![0.3, 0.6, 0.8],
            controller_response_s: 0.1,
            ground_clearance_m: 0.1,
            reflectors_near: ReflectorsNear::Auto,
            general_supplement_m: 0.1,
            braking_supplement_m: 0.0,
            scanner: SafetyScannerSpec::default(),
            monitor: true,
            field_length_scale: 1.0,
            warning_margin_m: 1.0,
            warning_speed_mps: 0.3,
            resume_dwell_s: 1.0,
            mute_near_target_m: None,
            field_set: Vec::new(),
        }
    }
}

impl SafetyConfig {
    /// Every value in its range, and speed ranges that leave no gap up to the truck's top
    /// speed; the error names the field.
    pub fn validate(&self, truck_max_speed_mps: f64) -> Result<(), SettingsError> {
        in_ranges(&[
            (
                "controller_response_s",
                self.controller_response_s,
                0.0,
                2.0,
            ),
            ("ground_clearance_m", self.ground_clearance_m, 0.0, 1.0),
            ("general_supplement_m", self.general_supplement_m, 0.0, 1.0),
            ("braking_supplement_m", self.braking_supplement_m, 0.0, 5.0),
            ("scanner.tolerance_m", self.scanner.tolerance_m, 0.0, 0.5),
            (
                "scanner.response_time_s",
                self.scanner.response_time_s,
                0.01,
                2.0,
            ),
            ("scanner.resolution_m", self.scanner.resolution_m, 0.03, 0.2),
            ("scanner.fov_deg", self.scanner.fov_deg, 90.0, 360.0),
            ("field_length_scale", self.field_length_scale, 0.1, 3.0),
            ("warning_margin_m", self.warning_margin_m, 0.0, 5.0),
            ("warning_speed_mps", self.warning_speed_mps, 0.05, 2.0),
            ("resume_dwell_s", self.resume_dwell_s, 0.0, 30.0),
        ])?;
        if let Some(d) = self.mute_near_target_m {
            in_ranges(&[("mute_near_target_m", d, 0.0, 10.0)])?;
        }
        self.check_ranges(truck_max_speed_mps)
    }

    /// Each drawn field set valid for `truck` and one of the speed ranges, no range and
    /// direction drawn twice; the error carries the field set's index.
    pub fn validate_field_sets(
        &self,
        truck: &crate::custom::Footprint,
    ) -> Result<(), (usize, SettingsError)> {
        for (k, f) in self.field_set.iter().enumerate() {
            f.validate(&self.speed_ranges_mps, truck)
                .map_err(|e| (k, e))?;
            let twice = self.field_set[..k]
                .iter()
                .any(|g| g.speed_max_mps == f.speed_max_mps && g.direction == f.direction);
            if twice {
                let why = format!(
                    "the {} m/s range is drawn twice for {} travel",
                    f.speed_max_mps,
                    f.direction.name()
                );
                return Err((k, SettingsError::field("speed_max_mps", why)));
            }
        }
        Ok(())
    }

    fn check_ranges(&self, truck_max_speed_mps: f64) -> Result<(), SettingsError> {
        let field = "speed_ranges_mps";
        let r = &self.speed_ranges_mps;
        if r.is_empty() || r.len() > MAX_SPEED_RANGES {
            return Err(SettingsError::field(
                field,
                format!("must list 1 to {MAX_SPEED_RANGES} speeds (got {})", r.len()),
            ));
        }
        // Twice the truck's top speed bounds the braking runs (and catches a typo).
        let most = 2.0 * truck_max_speed_mps;
        if let Some(v) = r
            .iter()
            .find(|v| !(v.is_finite() && **v > 0.0 && **v <= most))
        {
            return Err(SettingsError::field(
                field,
                format!(
                    "each speed must lie in (0, {most}] m/s, twice the truck's top speed (got {v})"
                ),
            ));
        }
        if let Some(w) = r.windows(2).find(|w| w[1] <= w[0]) {
            return Err(SettingsError::field(
                field,
                format!(
                    "must ascend: {} m/s after {} m/s would overlap the ranges",
                    w[1], w[0]
                ),
            ));
        }
        let last = r[r.len() - 1];
        if last < truck_max_speed_mps {
            return Err(SettingsError::field(
                field,
                format!(
                    "the last range ends at {last} m/s, below the truck's top speed \
                     {truck_max_speed_mps} m/s: no field set would cover it"
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_gapped_or_short_ranges_are_refused_by_field() {
        let with = |r: Vec<f64>| SafetyConfig {
            speed_ranges_mps: r,
            ..SafetyConfig::default()
        };
        assert!(with(vec![0.3, 0.6, 0.8]).validate(0.8).is_ok());
        for (ranges, says) in [
            (vec![0.6, 0.3, 0.8], "must ascend"),
            (vec![0.3, 0.3, 0.8], "must ascend"),
            (vec![0.3, 0.6], "below the truck's top speed"),
            (vec![], "1 to 16"),
            (vec![-0.1, 0.8], "(0, 1.6]"),
            (vec![f64::NAN, 0.8], "(0, 1.6]"),
            (vec![0.8, 5.0], "(0, 1.6]"),
        ] {
            let e = with(ranges.clone()).validate(0.8).expect_err("refused");
            assert_eq!(e.field.as_deref(), Some("speed_ranges_mps"), "{ranges:?}");
            assert!(e.reason.contains(says), "{ranges:?}: {e}");
        }
        let mut c = SafetyConfig::default();
        c.scanner.response_time_s = -1.0;
        let e = c.validate(0.8).expect_err("negative time");
        assert_eq!(e.field.as_deref(), Some("scanner.response_time_s"));
    }
}
