//! What a labelled scan set is drawn from: how many scans, the share with a pallet, where the pallet may stand, and the clutter around it; every number range-checked.

use forkbench_core::SettingsError;
use forkbench_core::settings::in_ranges;
use serde::{Deserialize, Serialize};

/// The clutter kinds a scene can hold.
pub const CLUTTER_KINDS: [&str; 7] = [
    "upright",
    "box",
    "wrapped_load",
    "person",
    "pallet_side",
    "wall",
    "forks",
];

/// Most scans one set may hold (each is a scene and a scan: work, not memory, is bounded
/// by the bytes check below too).
pub const MAX_SCANS: usize = 1_000_000;

/// A set's settings (SI inside; degrees at this interface, as in scenario files).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DatasetSpec {
    /// Scenario (file relative to the spec, or an embedded name) whose pallet (kind and
    /// entry face) the scenes hold and whose scanner settings are used.
    pub scenario: String,
    /// Scanner model (`tim561`, `kinect2`): the scenario's own settings for it when it has
    /// that scanner, else the model's.
    pub scanner: String,
    pub scans: usize,
    pub seed: u64,
    /// Share of the scans with the pallet in view.
    pub present_fraction: f64,
    /// The scanner's range and bias errors; false: ideal rays.
    pub noise: bool,
    /// The face centre's range from the scanner (m) and bearing (degrees, left positive).
    pub range_m: [f64; 2],
    pub bearing_deg: [f64; 2],
    /// How far the face is turned from facing the scanner (degrees).
    pub heading_deg: [f64; 2],
    /// Each scan's prior (where a warehouse system says the pallet stands, what a
    /// detector is handed) is the true face off by a Gaussian error of this σ, each axis
    /// (m) and heading (degrees); a scan without a pallet gets a prior where one would
    /// stand.
    pub prior_error_m: f64,
    pub prior_error_deg: f64,
    pub clutter: ClutterSpec,
}

/// The clutter in each scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ClutterSpec {
    /// Clutter items per scene, drawn uniformly in this range (inclusive).
    pub per_scene: [usize; 2],
    /// Kinds drawn from, uniformly ([`CLUTTER_KINDS`]).
    pub kinds: Vec<String>,
    /// Share of pallet scenes with a wall behind the pallet (0.1–1 m beyond its back).
    pub wall_behind_fraction: f64,
    /// Share of pallet scenes with a box between the scanner and part of the face.
    pub hidden_fraction: f64,
}

impl Default for ClutterSpec {
    fn default() -> Self {
        Self {
            per_scene: [2, 8],
            kinds: CLUTTER_KINDS.iter().map(|k| (*k).to_owned()).collect(),
            wall_behind_fraction: 0.5,
            hidden_fraction: 0.1,
        }
    }
}

impl Default for DatasetSpec {
    fn default() -> Self {
        Self {
            scenario: "field-test".into(),
            scanner: "tim561".into(),
            scans: 2000,
            seed: 1,
            present_fraction: 0.5,
            noise: true,
            range_m: [1.5, 8.0],
            bearing_deg: [-45.0, 45.0],
            heading_deg: [-30.0, 30.0],
            // A choice: a slot's placement tolerance of about a pallet's block width.
            prior_error_m: 0.1,
            prior_error_deg: 3.0,
            clutter: ClutterSpec::default(),
        }
    }
}

impl DatasetSpec {
    /// Every setting in its range; `Err` names the field.
    pub fn validate(&self) -> Result<(), SettingsError> {
        if !(1..=MAX_SCANS).contains(&self.scans) {
            return Err(SettingsError::field(
                "scans",
                format!("must lie in 1–{MAX_SCANS} (got {})", self.scans),
            ));
        }
        in_ranges(&[
            ("present_fraction", self.present_fraction, 0.0, 1.0),
            ("range_m[0]", self.range_m[0], 0.3, 30.0),
            ("range_m[1]", self.range_m[1], 0.3, 30.0),
            ("bearing_deg[0]", self.bearing_deg[0], -180.0, 180.0),
            ("bearing_deg[1]", self.bearing_deg[1], -180.0, 180.0),
            ("heading_deg[0]", self.heading_deg[0], -80.0, 80.0),
            ("heading_deg[1]", self.heading_deg[1], -80.0, 80.0),
            ("prior_error_m", self.prior_error_m, 0.0, 2.0),
            ("prior_error_deg", self.prior_error_deg, 0.0, 45.0),
            (
                "clutter.wall_behind_fraction",
                self.clutter.wall_behind_fraction,
                0.0,
                1.0,
            ),
            (
                "clutter.hidden_fraction",
                self.clutter.hidden_fraction,
                0.0,
                1.0,
            ),
        ])?;
        for (f, r) in [
            ("range_m", self.range_m),
            ("bearing_deg", self.bearing_deg),
            ("heading_deg", self.heading_deg),
        ] {
            if r[0] > r[1] {
                return Err(SettingsError::field(
                    f,
                    "the first bound exceeds the second",
                ));
            }
        }
        let [lo, hi] = self.clutter.per_scene;
        if lo > hi || hi > 64 {
            return Err(SettingsError::field(
                "clutter.per_scene",
                format!("[{lo}, {hi}]: a range within 0–64 items"),
            ));
        }
        if hi > 0 && self.clutter.kinds.is_empty() {
            return Err(SettingsError::field(
                "clutter.kinds",
                "empty, but per_scene asks for clutter",
            ));
        }
        if let Some(k) = self
            .clutter
            .kinds
            .iter()
            .find(|k| !CLUTTER_KINDS.contains(&k.as_str()))
        {
            return Err(SettingsError::field(
                "clutter.kinds",
                format!("{k:?} is not a clutter kind ({})", CLUTTER_KINDS.join(", ")),
            ));
        }
        Ok(())
    }

    /// The spec with the pallet's face drawn only where the scanner sees it: the range
    /// clipped to [`VIEW_RANGE_MARGIN_M`] inside the scanner's reach, the bearing to
    /// [`VIEW_BEARING_MARGIN_DEG`] inside its field of view, so a label that says
    /// "present" is a pallet in view. `Err` names the field the view leaves nothing of;
    /// the `bool` says whether anything was clipped.
    pub fn within_view(
        &self,
        range_max_m: f64,
        fov_rad: f64,
    ) -> Result<(Self, bool), SettingsError> {
        let mut s = self.clone();
        let far = range_max_m - VIEW_RANGE_MARGIN_M;
        let side = (fov_rad / 2.0).to_degrees() - VIEW_BEARING_MARGIN_DEG;
        s.range_m[1] = s.range_m[1].min(far);
        s.bearing_deg = [s.bearing_deg[0].max(-side), s.bearing_deg[1].min(side)];
        if s.range_m[0] > s.range_m[1] {
            return Err(SettingsError::field(
                "range_m",
                format!(
                    "[{}, {}] m lies beyond the scanner's reach ({range_max_m} m, less \
                     {VIEW_RANGE_MARGIN_M} m): no face drawn there is seen",
                    self.range_m[0], self.range_m[1]
                ),
            ));
        }
        if s.bearing_deg[0] > s.bearing_deg[1] {
            return Err(SettingsError::field(
                "bearing_deg",
                format!(
                    "[{}, {}]° lies outside the scanner's view (±{side:.1}°): no face drawn \
                     there is seen",
                    self.bearing_deg[0], self.bearing_deg[1]
                ),
            ));
        }
        let clipped = s != *self;
        Ok((s, clipped))
    }
}

/// How far inside the scanner's reach a drawn face stays: the face's own returns must
/// come back, not only its centre's (a choice).
pub const VIEW_RANGE_MARGIN_M: f64 = 0.2;

/// How far inside the field of view a drawn face's bearing stays: a face at the edge is
/// half cut off (a choice: about the half-width of a pallet's face at 5 m).
pub const VIEW_BEARING_MARGIN_DEG: f64 = 7.0;
