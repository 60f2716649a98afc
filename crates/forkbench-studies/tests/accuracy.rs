//! The detector accuracy study (`reproduce detector`) on a scenario of its own: the camera decides near, the laser far with its systematic range error.

use std::path::Path;

use forkbench_studies::accuracy::accuracy_study;
use forkbench_trial::{Scenario, World};

fn scenario(extra: &str, pallet: &str) -> Result<Scenario, forkbench_trial::ScenarioError> {
    let text = format!(
        "name = \"s\"\nplanner = \"bspline\"\npallet_kind = \"field-1200\"\n\
         start = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\npallet = {pallet}\n{extra}"
    );
    Scenario::parse(&text, "s.toml", |_: &Path| Ok(World::default()))
}

const NEAR: &str = "{ x_m = 5.0, y_m = 0.4, heading_deg = 5.0 }";

#[test]
fn the_accuracy_study_sees_the_camera_near_and_the_lasers_bias_far() {
    let scn = scenario("[sensors.pallet]\nkind = \"tim561+kinect2\"\n", NEAR).expect("loads");
    let rows = accuracy_study(&scn, 40, 3).expect("study");
    assert_eq!(rows.len(), 9 * 3 * 3);
    let cell = |r: f64, a: f64, l: f64| {
        rows.iter()
            .find(|x| {
                x.range_m == r && (x.angle_rad.to_degrees() - a).abs() < 1e-9 && x.lateral_m == l
            })
            .expect("cell")
    };
    // Sensors are listed shortest reach first: the camera decides at 3 m, head-on, to
    // millimetres.
    let near = cell(3.0, 0.0, 0.0);
    assert_eq!((near.missed, near.by_sensor[0]), (0, 40), "{near:?}");
    assert!(
        near.lateral.bound() < 0.01 && near.along.bound() < 0.01,
        "{near:?}"
    );
    // Beyond the camera's 4.5 m the laser decides, and its along-axis error is its
    // systematic range error: uniform within ±60 mm, σ = 60/√3 ≈ 34.6 mm.
    let far = cell(6.5, 0.0, 0.0);
    assert_eq!(far.by_sensor[1], 40 - far.missed, "{far:?}");
    assert!(far.missed <= 2, "{far:?}");
    assert!(
        (0.026..0.044).contains(&far.along.sigma),
        "along σ {} m",
        far.along.sigma
    );
}
