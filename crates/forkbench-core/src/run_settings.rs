//! The truck settings a run may change (actuators, control timing and geometry), by their sweep names and dotted paths, and how one is set.

use crate::ForkliftSpec;

/// The truck settings a run may change, by their names in a sweep and their dotted paths
/// in a truck file: the actuators and the control timing. The geometry is the scenario's.
pub const TRUCK_KNOBS: [(&str, &str); 14] = [
    ("steering_rate_limit_radps", "max_steer_rate_radps"),
    ("steering_dead_time_s", "steering.dead_time_s"),
    ("steering_time_constant_s", "steering.time_constant_s"),
    ("steering_accel_limit_radps2", "steering.accel_limit_radps2"),
    ("steering_deadband_rad", "steering.deadband_rad"),
    ("steering_backlash_rad", "steering.backlash_rad"),
    ("steering_offset_rad", "steering.offset_rad"),
    ("drive_dead_time_s", "drive.dead_time_s"),
    ("drive_time_constant_s", "drive.time_constant_s"),
    ("drive_accel_limit_mps2", "drive.accel_limit_mps2"),
    ("drive_brake_limit_mps2", "drive.brake_limit_mps2"),
    ("drive_creep_speed_mps", "drive.creep_speed_mps"),
    ("control_period_s", "control.period_s"),
    ("control_transport_delay_s", "control.transport_delay_s"),
];

/// The truck's geometry and mass, by the names a truck file, a sweep and a `[truck]`
/// table share: a run that changes one runs its trials against the scenario as if its
/// `[truck]` table said so (every check and every derived figure follows).
pub const TRUCK_GEOMETRY: [&str; 15] = [
    "layout",
    "wheelbase_m",
    "max_steer_rad",
    "body_length_m",
    "body_width_m",
    "mass_kg",
    "fork_length_m",
    "fork_width_m",
    "fork_spacing_m",
    "fork_root_ahead_of_front_axle_m",
    "max_speed_mps",
    "rated_capacity_kg",
    "fork_thickness_m",
    "axle_load_fixed_kg",
    "axle_load_steered_kg",
];

/// The dotted path of a sweep knob's name, or of a dotted path itself (the geometry's
/// names are their own paths).
pub fn truck_path(name: &str) -> Option<&'static str> {
    TRUCK_KNOBS
        .iter()
        .find(|(k, p)| *k == name || *p == name)
        .map(|(_, p)| *p)
        .or_else(|| TRUCK_GEOMETRY.iter().find(|g| **g == name).copied())
}

/// Whether `path` names the truck's geometry, mass or a sensor's mount (not its
/// actuators or timing).
pub fn is_geometry(path: &str) -> bool {
    TRUCK_GEOMETRY.contains(&path) || mount_path(path).is_some()
}

/// A sensor mount's dotted path (`mount.<sensor>.<field>`) as its sensor and field.
pub fn mount_path(path: &str) -> Option<(&str, &str)> {
    path.strip_prefix("mount.")?.split_once('.')
}

/// Sets the truck's setting at `path` (one of [`TRUCK_KNOBS`]); false for another path.
/// Set field by field, not through the serialised form, which leaves out what equals
/// the first truck's.
pub fn set(t: &mut ForkliftSpec, path: &str, v: f64) -> bool {
    let (st, dr, ct) = (&mut t.steering, &mut t.drive, &mut t.control);
    match path {
        "max_steer_rate_radps" => t.max_steer_rate_radps = v,
        "steering.dead_time_s" => st.dead_time_s = v,
        "steering.time_constant_s" => st.time_constant_s = v,
        "steering.accel_limit_radps2" => st.accel_limit_radps2 = Some(v),
        "steering.deadband_rad" => st.deadband_rad = v,
        "steering.backlash_rad" => st.backlash_rad = v,
        "steering.offset_rad" => st.offset_rad = v,
        "drive.dead_time_s" => dr.dead_time_s = v,
        "drive.time_constant_s" => dr.time_constant_s = Some(v),
        "drive.accel_limit_mps2" => dr.accel_limit_mps2 = Some(v),
        "drive.brake_limit_mps2" => dr.brake_limit_mps2 = Some(v),
        "drive.creep_speed_mps" => dr.creep_speed_mps = v,
        "control.period_s" => ct.period_s = Some(v),
        "control.transport_delay_s" => ct.transport_delay_s = v,
        _ => match mount_path(path) {
            Some((sensor, field)) => return t.mounts.set(sensor, field, v),
            None => return set_geometry(t, path, v),
        },
    }
    true
}

/// Sets a geometry field ([`TRUCK_GEOMETRY`]); false for another path.
fn set_geometry(t: &mut ForkliftSpec, path: &str, v: f64) -> bool {
    match path {
        "layout" => match crate::TruckLayout::from_code(v) {
            Some(l) => t.layout = l,
            None => return false,
        },
        "wheelbase_m" => t.wheelbase_m = v,
        "max_steer_rad" => t.max_steer_rad = v,
        "body_length_m" => t.body_length_m = v,
        "body_width_m" => t.body_width_m = v,
        "mass_kg" => t.mass_kg = v,
        "fork_length_m" => t.fork_length_m = v,
        "fork_width_m" => t.fork_width_m = v,
        "fork_spacing_m" => t.fork_spacing_m = v,
        "fork_root_ahead_of_front_axle_m" => t.fork_root_ahead_of_front_axle_m = v,
        "max_speed_mps" => t.max_speed_mps = v,
        "rated_capacity_kg" => t.rated_capacity_kg = v,
        "fork_thickness_m" => t.fork_thickness_m = Some(v),
        "axle_load_fixed_kg" => t.axle_load_fixed_kg = Some(v),
        "axle_load_steered_kg" => t.axle_load_steered_kg = Some(v),
        _ => return false,
    }
    true
}
