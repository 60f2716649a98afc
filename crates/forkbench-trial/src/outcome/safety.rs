//! What a trial's safety function did and how near the truck came to people: the outcome's `safety` record.

use serde::{Deserialize, Serialize};

/// What the safety function did, and how near the truck came to each person or vehicle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafetyOutcome {
    /// Whether a safety function watched fields (movers alone: contacts are judged, no
    /// field stops the truck).
    pub monitored: bool,
    /// Protective-field stops, and of them those with no person or vehicle in the field
    /// (racks, walls, reflector posts).
    pub stops: u32,
    pub false_trips: u32,
    /// Time the truck was held stopped.
    pub stop_time_s: f64,
    /// Warning-field slowdowns, and the time the speed was held down.
    pub slowdowns: u32,
    pub slowdown_time_s: f64,
    /// Times the moving truck touched a person or vehicle, and the first.
    pub person_contacts: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_contact: Option<String>,
    /// Each mover's least gap to the truck while it moved, in `[[mover]]` order (`None`:
    /// never measured).
    pub closest_m: Vec<Option<f64>>,
}

impl SafetyOutcome {
    /// The least gap to any mover.
    pub fn closest_any_m(&self) -> Option<f64> {
        self.closest_m.iter().flatten().copied().reduce(f64::min)
    }
}
