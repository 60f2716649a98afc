//! Reflector coverage: the warehouse's layout gives most free cells a fix with millimetre σ, removing an aisle's reflectors leaves it without one, and bad reflectors are refused at load naming the field.

use forkbench_sensors::reflectors::ReflectorNavConfig;
use forkbench_studies::coverage::coverage;
use forkbench_trial::World;
use forkbench_trial::defaults::embedded_world;

#[test]
fn the_warehouse_layout_covers_its_aisles_and_losing_one_aisles_reflectors_shows() {
    let cfg = ReflectorNavConfig::default();
    let full = embedded_world("warehouse.toml").expect("world");
    let cov = coverage(&full, 0.5, &cfg).expect("coverage");
    let with_fix = cov.cells.iter().filter(|c| c.sigma_m.is_some()).count();
    assert!(
        with_fix * 10 > cov.cells.len() * 9,
        "{with_fix} of {}",
        cov.cells.len()
    );
    // The aisle between rows 1 and 2 (y 5.75–11.75 m, x 10–35 m) is covered everywhere.
    let aisle = |c: &&forkbench_studies::coverage::CoverageCell| {
        (10.0..35.0).contains(&c.x_m) && (6.5..11.0).contains(&c.y_m)
    };
    assert!(
        cov.cells
            .iter()
            .filter(aisle)
            .all(|c| c.sigma_m.is_some_and(|s| s < 0.005))
    );
    // Without the reflectors that face that aisle and its ends, its middle has no fix.
    let mut degraded = full.clone();
    degraded.reflector.retain(|r| {
        !(r.name.starts_with("row1-north")
            || r.name.starts_with("row2-south")
            || r.name.starts_with("east-8.75")
            || r.name.starts_with("shelf-frame0"))
    });
    let cov = coverage(&degraded, 0.5, &cfg).expect("coverage");
    let middle = |c: &&forkbench_studies::coverage::CoverageCell| {
        (14.0..31.0).contains(&c.x_m) && (7.5..10.0).contains(&c.y_m)
    };
    let lost = cov
        .cells
        .iter()
        .filter(middle)
        .filter(|c| c.sigma_m.is_none())
        .count();
    let all = cov.cells.iter().filter(middle).count();
    assert!(
        lost * 2 > all,
        "{lost} of {all} middle cells lost their fix"
    );
}

#[test]
fn bad_reflectors_are_refused_naming_the_field() {
    let base = "name = \"w\"\n[[wall]]\nx_m = 0.0\ny_m = 0.0\nlength_m = 4.0\nwidth_m = 0.2\n";
    for (extra, field) in [
        (
            "[[reflector]]\nname = \"a\"\nx_m = 0.5\ny_m = 0.0\n",
            "reflector[0]",
        ),
        (
            "[[reflector]]\nname = \"a\"\nx_m = 0.5\ny_m = 1.0\n[[reflector]]\nname = \"a\"\nx_m = 1.5\ny_m = 1.0\n",
            "reflector[1].name",
        ),
        (
            "[[reflector]]\nname = \"a\"\nx_m = nan\ny_m = 1.0\n",
            "reflector[0].x_m",
        ),
        ("[[reflector]]\nname = \"a\"\nx_m = 1.0\n", "reflector"),
    ] {
        let e = World::parse(&format!("{base}{extra}"), "w.toml")
            .expect_err(extra)
            .to_string();
        assert!(e.contains(field) && e.contains("w.toml"), "{extra}: {e}");
    }
}

/// The work of a coverage map is bounded by cells × (racks, walls and reflectors), and
/// a tiny resolution is refused with cell counts that do not wrap.
#[test]
fn coverage_work_is_bounded() {
    let mut text = String::from("name = \"checker\"\n");
    // A 60 × 60 m floor of 2,500 small racks: 4 M cells at 3 cm would take ~1e10 tests.
    for i in 0..50 {
        for j in 0..50 {
            text += &format!(
                "[[rack]]\nx_m = {}\ny_m = {}\nlength_m = 0.3\nwidth_m = 0.3\n",
                1.2 * f64::from(i),
                1.2 * f64::from(j)
            );
        }
    }
    let world = World::parse(&text, "checker.toml").expect("loads");
    let cfg = ReflectorNavConfig::default();
    let t0 = std::time::Instant::now();
    let err = coverage(&world, 0.03, &cfg)
        .expect_err("bounded")
        .to_string();
    assert!(err.contains("tests, more than"), "{err}");
    assert!(t0.elapsed().as_secs_f64() < 2.0);
    let err = coverage(&world, 1e-300, &cfg)
        .expect_err("tiny")
        .to_string();
    assert!(
        err.contains("e") && !err.contains("18446744073709551615"),
        "{err}"
    );
    // A coarse map of the same world is made.
    assert!(coverage(&world, 1.0, &cfg).is_ok());
}

/// A reflector exactly on a turned wall's face (its coordinates rounded by the turn) is
/// accepted and seen from in front of the face, and not from behind the wall.
#[test]
fn a_reflector_on_a_face_is_accepted_and_seen_from_its_side_only() {
    let h = 30f64.to_radians();
    let wall = forkbench_core::Pose2::new(0.0, 0.0, h);
    let on_face = wall.to_world(&forkbench_core::Pose2::new(0.5, 0.1, 0.0));
    let text = format!(
        "name = \"w\"\n[[wall]]\nx_m = 0.0\ny_m = 0.0\nheading_deg = 30.0\nlength_m = 4.0\n\
         width_m = 0.2\n[[reflector]]\nname = \"a\"\nx_m = {:?}\ny_m = {:?}\n",
        on_face.x_m, on_face.y_m
    );
    let world = World::parse(&text, "w.toml").expect("a reflector on the face loads");
    let cfg = ReflectorNavConfig::default();
    let cov = coverage(&world, 0.25, &cfg).expect("coverage");
    let side = |c: &forkbench_studies::coverage::CoverageCell| {
        let l = wall.to_local(&forkbench_core::Pose2::new(c.x_m, c.y_m, 0.0));
        (l.x_m.abs() < 1.5).then_some(l.y_m)
    };
    let front: Vec<_> = cov
        .cells
        .iter()
        .filter(|c| side(c).is_some_and(|y| (1.0..3.0).contains(&y)))
        .collect();
    let behind: Vec<_> = cov
        .cells
        .iter()
        .filter(|c| side(c).is_some_and(|y| (-3.0..-1.0).contains(&y)))
        .collect();
    assert!(!front.is_empty() && !behind.is_empty());
    assert!(front.iter().all(|c| c.visible == 1), "seen from the front");
    assert!(
        behind.iter().all(|c| c.visible == 0),
        "hidden behind the wall"
    );
}
