//! A run's changes to the truck: a named preset, single settings by their dotted names (a `--truck` file, a sweep; the format's `truck_file`), and the sensors' timing under the `ideal` preset.

pub use forkbench_core::run_settings::{TRUCK_GEOMETRY, TRUCK_KNOBS, is_geometry, truck_path};
pub use forkbench_scenario::truck_file::{TruckSettings, apply_truck, read_truck_text};

/// The sensors' timing under `preset`: the `ideal` truck is the bench's first one as it
/// was sensed too, a NAV350 delivering each fix at once, scans taken in an instant,
/// their estimates used at once and the detector's own face taken unchecked (evidence
/// threshold 0), so it reproduces the records made before these were modelled; any other
/// preset leaves the sensors as configured.
pub(crate) fn sensor_timing_for(
    preset: Option<&str>,
    nav350: &mut forkbench_sensors::Nav350Config,
    sensing: &mut crate::scenario::sensors::PalletSensing,
) {
    if preset != Some("ideal") {
        return;
    }
    nav350.latency_s = 0.0;
    if let crate::scenario::sensors::PalletSensing::Scanner {
        sensors,
        latency_s,
        min_score,
        ..
    } = sensing
    {
        *latency_s = 0.0;
        *min_score = 0.0;
        for n in sensors {
            n.scanner.sweep_s = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use forkbench_core::ForkliftSpec;
    use forkbench_core::actuators::Actuators;
    use std::collections::BTreeMap;

    #[test]
    fn a_setting_lands_where_its_path_says_and_bad_ones_are_named() {
        let truck = ForkliftSpec::default();
        let mut s = BTreeMap::new();
        s.insert("steering.dead_time_s".to_owned(), 0.2);
        s.insert("drive.brake_limit_mps2".to_owned(), 1.5);
        let t = apply_truck(&truck, None, &s).expect("valid");
        assert_eq!(t.steering.dead_time_s, 0.2);
        assert_eq!(t.drive.brake_limit_mps2, Some(1.5));
        s.insert("steering.dead_time_s".to_owned(), 9.0);
        let e = apply_truck(&truck, None, &s).expect_err("9 s").to_string();
        assert!(e.contains("steering.dead_time_s"), "{e}");
        let mut g = BTreeMap::new();
        g.insert("wheelbase_m".to_owned(), 2.0);
        let t = apply_truck(&truck, None, &g).expect("geometry is a truck setting");
        assert_eq!(t.wheelbase_m, 2.0);
        g.insert("wheel_base".to_owned(), 2.0);
        let e = apply_truck(&truck, None, &g)
            .expect_err("unknown")
            .to_string();
        assert!(
            e.contains("wheel_base") && e.contains("not a truck setting"),
            "{e}"
        );
    }

    /// A setting over the first truck keeps the rest of it (its unlimited rates too).
    #[test]
    fn a_setting_over_the_ideal_preset_keeps_the_rest_ideal() {
        let mut s = BTreeMap::new();
        s.insert("steering.dead_time_s".to_owned(), 0.1);
        let t = apply_truck(&ForkliftSpec::default(), Some("ideal"), &s).expect("valid");
        assert_eq!(t.steering.accel_limit_radps2, None);
        assert!(t.drive.is_ideal() && t.control.is_ideal());
        assert_eq!(t.steering.time_constant_s, 0.0);
    }

    #[test]
    fn a_preset_then_settings() {
        let truck = ForkliftSpec::default();
        let mut s = BTreeMap::new();
        s.insert("control.period_s".to_owned(), 0.05);
        let t = apply_truck(&truck, Some("realistic"), &s).expect("valid");
        assert_eq!(t.steering, Actuators::REALISTIC.steering);
        assert_eq!(t.control.period_s, Some(0.05));
        assert!(apply_truck(&truck, Some("sporty"), &s).is_err());
        let f = read_truck_text(
            "preset = \"ideal\"\n[steering]\ndead_time_s = 0.1\n",
            "t.toml",
        )
        .expect("valid file");
        assert_eq!(f.preset.as_deref(), Some("ideal"));
        assert_eq!(f.settings.get("steering.dead_time_s"), Some(&0.1));
        assert!(read_truck_text("wheel_base_m = 2.0", "t.toml").is_err());
    }
}
