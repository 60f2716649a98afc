//! Occupancy grids: rasterised obstacles, segment checks that walk cells, and map_server maps written and read back.

use forkbench_core::Pose2;
use forkbench_core::geometry::Obstacle;
use forkbench_nav::{Cell, MapError, OccupancyGrid, read_map, write_map};

fn rack(x: f64, y: f64, heading_deg: f64, length_m: f64, width_m: f64) -> Obstacle {
    Obstacle {
        centre: Pose2::new(x, y, heading_deg.to_radians()),
        length_m,
        width_m,
    }
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-nav-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

/// Two racks 2 m apart along x, an aisle between them.
fn aisle() -> OccupancyGrid {
    let racks = [rack(0.0, 0.0, 0.0, 1.0, 6.0), rack(3.0, 0.0, 0.0, 1.0, 6.0)];
    OccupancyGrid::from_obstacles(&racks, &[], 0.05, 1.0).expect("grid")
}

#[test]
fn obstacles_occupy_every_cell_they_touch_and_nothing_else() {
    let g = aisle();
    // Racks span x −0.5..0.5 and 2.5..3.5, y −3..3; one metre of margin around.
    assert_eq!(g.origin_m, [-1.5, -4.0]);
    assert_eq!((g.width, g.height), (120, 160));
    assert!(!g.is_free([0.0, 0.0]) && !g.is_free([3.0, 2.9]));
    assert!(g.is_free([1.5, 0.0]) && g.is_free([0.6, 0.0]) && g.is_free([0.0, 3.1]));
    assert!(!g.is_free([-2.0, 0.0]), "off the map is not free");
    let (free, occupied, unknown) = g.counts();
    // Each rack is 1 × 6 m: 20 × 120 cells exactly, since its edges lie on cell edges.
    assert_eq!(occupied, 2 * 20 * 120);
    assert_eq!((free + occupied, unknown), (120 * 160, 0));
    // A turned rack occupies at least its area and every cell under its centre line.
    let turned = OccupancyGrid::from_obstacles(&[rack(0.0, 0.0, 30.0, 2.0, 0.5)], &[], 0.05, 0.5)
        .expect("grid");
    let (_, occ, _) = turned.counts();
    assert!(occ as f64 * 0.0025 >= 1.0, "{occ} cells");
    for s in [-0.99, -0.5, 0.0, 0.5, 0.99] {
        let (c, sn) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        assert!(!turned.is_free([s * c, s * sn]), "centre line at {s}");
    }
}

#[test]
fn segments_are_free_only_when_every_crossed_cell_is() {
    let g = aisle();
    assert!(g.segment_free([1.5, -2.9], [1.5, 2.9]), "along the aisle");
    assert!(
        g.segment_free([0.6, -2.0], [2.4, 2.0]),
        "diagonally across it"
    );
    assert!(!g.segment_free([1.5, 0.0], [-1.0, 0.0]), "through a rack");
    assert!(
        !g.segment_free([0.6, 3.6], [-0.6, 2.9]),
        "clipping a rack's corner"
    );
    assert!(
        g.segment_free([-1.0, 3.5], [4.0, 3.5]),
        "past the racks' ends"
    );
    assert!(!g.segment_free([1.5, 0.0], [1.5, 9.0]), "off the map");
    assert!(
        g.segment_free([1.5, 0.0], [1.5, 0.0]),
        "a point in a free cell"
    );
}

#[test]
fn a_written_map_reads_back_the_same() {
    let mut g = aisle();
    g.set(3, 4, Cell::Unknown);
    let dir = tmp("roundtrip");
    let yaml = write_map(&g, &dir, "aisle").expect("writes");
    let text = std::fs::read_to_string(&yaml).expect("yaml");
    for key in [
        "image: aisle.pgm",
        "resolution: 0.05",
        "occupied_thresh: 0.65",
        "free_thresh: 0.196",
        "mode: trinary",
    ] {
        assert!(text.contains(key), "{key} in {text}");
    }
    let back = read_map(&yaml).expect("reads");
    // Compared field by field: a failing whole-grid comparison would print every cell.
    assert_eq!(
        (back.width, back.height, back.origin_m, back.resolution_m),
        (g.width, g.height, g.origin_m, g.resolution_m)
    );
    assert_eq!(back.counts(), g.counts());
    assert!(back == g, "the cells differ");
}

#[test]
fn bad_maps_name_the_file_and_the_reason() {
    let g = aisle();
    let dir = tmp("bad");
    let yaml = write_map(&g, &dir, "m").expect("writes");
    let good = std::fs::read_to_string(&yaml).expect("yaml");
    let cases: [(&str, String, &str); 5] = [
        (
            "resolution",
            good.replace("resolution: 0.05", "resolution: -1"),
            "field `resolution`",
        ),
        (
            "thresholds",
            good.replace("free_thresh: 0.196", "free_thresh: 0.9"),
            "free_thresh",
        ),
        (
            "no image",
            good.replace("m.pgm", "missing.pgm"),
            "missing.pgm",
        ),
        ("not yaml", "image: [".to_owned(), "m.yaml"),
        (
            "mode",
            good.replace("mode: trinary", "mode: raw"),
            "field `mode`",
        ),
    ];
    for (what, text, want) in cases {
        std::fs::write(&yaml, text).expect("write");
        let e = read_map(&yaml).expect_err(what).to_string();
        assert!(e.contains(want), "{what}: {e}");
    }
    std::fs::write(&yaml, &good).expect("write");
    let pgm = dir.join("m.pgm");
    let full = std::fs::read(&pgm).expect("pgm");
    for (what, bytes, want) in [
        ("truncated", full[..full.len() / 2].to_vec(), "pixel bytes"),
        (
            "ascii",
            b"P2\n2 2\n255\n0 0 0 0\n".to_vec(),
            "does not start with P5",
        ),
        ("16-bit", b"P5\n2 2\n65535\n".to_vec(), "8-bit"),
    ] {
        std::fs::write(&pgm, bytes).expect("write");
        let e = read_map(&yaml).expect_err(what);
        assert!(matches!(e, MapError::Image { .. }), "{what}: {e}");
        assert!(
            e.to_string().contains("m.pgm") && e.to_string().contains(want),
            "{what}: {e}"
        );
    }
}

#[test]
fn degenerate_worlds_are_errors_not_panics() {
    let bad = [rack(0.0, 0.0, 0.0, 0.0, 1.0)];
    assert!(OccupancyGrid::from_obstacles(&bad, &[], 0.05, 1.0).is_err());
    let nan = [rack(f64::NAN, 0.0, 0.0, 1.0, 1.0)];
    assert!(OccupancyGrid::from_obstacles(&nan, &[], 0.05, 1.0).is_err());
    assert!(
        OccupancyGrid::from_obstacles(&[], &[], 0.05, 1.0).is_err(),
        "no extent"
    );
    let huge = [rack(0.0, 0.0, 0.0, 9000.0, 9000.0)];
    let e = OccupancyGrid::from_obstacles(&huge, &[], 0.05, 1.0).expect_err("too large");
    assert!(e.to_string().contains("coarser resolution"), "{e}");
    assert!(
        OccupancyGrid::from_obstacles(&[rack(0.0, 0.0, 0.0, 1.0, 1.0)], &[], 0.0, 1.0).is_err()
    );
}

/// A wall across the map with one gap near its top: every planner must go through it.
fn wall_with_gap() -> OccupancyGrid {
    let walls = [
        rack(5.0, -2.0, 0.0, 0.4, 12.0),
        rack(5.0, 9.0, 0.0, 0.4, 6.0),
    ];
    let g = OccupancyGrid::from_obstacles(&walls, &[[0.0, -8.0], [10.0, 12.0]], 0.05, 0.0)
        .expect("grid");
    g.inflated(0.3)
}

fn assert_valid(g: &OccupancyGrid, pts: &[[f64; 2]], start: [f64; 2], goal: [f64; 2]) {
    assert_eq!(pts.first(), Some(&start));
    assert_eq!(pts.last(), Some(&goal));
    for w in pts.windows(2) {
        assert!(
            g.segment_free(w[0], w[1]),
            "edge {:?} → {:?} is blocked",
            w[0],
            w[1]
        );
    }
    // The wall spans y −8..4 and 6..12 at x 4.8..5.2: the path crosses x = 5 in the gap.
    let crossing = pts
        .windows(2)
        .find(|w| (w[0][0] - 5.0) * (w[1][0] - 5.0) <= 0.0)
        .expect("crosses");
    let t = (5.0 - crossing[0][0]) / (crossing[1][0] - crossing[0][0]);
    let y = crossing[0][1] + t * (crossing[1][1] - crossing[0][1]);
    assert!((4.3..5.7).contains(&y), "crosses the wall at y = {y}");
}

#[test]
fn inflation_grows_obstacles_by_the_radius() {
    let g = OccupancyGrid::from_obstacles(&[rack(0.0, 0.0, 0.0, 1.0, 1.0)], &[], 0.05, 2.0)
        .expect("grid");
    let big = g.inflated(0.5);
    assert!(!big.is_free([0.95, 0.0]) && big.is_free([1.1, 0.0]));
    // Corners round off: (0.75, 0.75) is 0.35 m from the corner, (0.9, 0.9) 0.57 m.
    assert!(!big.is_free([0.75, 0.75]) && big.is_free([0.9, 0.9]));
    assert!(big.counts().1 > g.counts().1 * 3);
}

#[test]
fn prm_finds_the_gap_with_a_valid_route_and_is_reproducible() {
    use forkbench_nav::{PrmParams, plan_prm};
    let g = wall_with_gap();
    let (start, goal) = ([1.0, 0.0], [9.0, 0.0]);
    let p = PrmParams {
        nodes: 500,
        connect_m: Some(10.0),
        seed: 7,
    };
    let (route, map) = plan_prm(&g, start, goal, &p).expect("plans");
    let pts = route.points.clone().expect("a path through the gap");
    assert_valid(&g, &pts, start, goal);
    assert!(
        route.length_m > 8.0 * 1.2,
        "around the wall: {}",
        route.length_m
    );
    assert!(map.edge_count() > 100);
    let (again, _) = plan_prm(&g, start, goal, &p).expect("plans");
    assert_eq!(again.points, route.points, "same seed, same route");
    // Too few nodes to find the gap, or too short a connection distance: no path.
    let few = PrmParams {
        nodes: 3,
        connect_m: Some(10.0),
        seed: 7,
    };
    assert!(!plan_prm(&g, start, goal, &few).expect("plans").0.found());
    let short = PrmParams {
        nodes: 500,
        connect_m: Some(0.05),
        seed: 7,
    };
    assert!(!plan_prm(&g, start, goal, &short).expect("plans").0.found());
}

#[test]
fn astar_finds_the_shortest_route_on_the_roadmap() {
    use forkbench_nav::{Roadmap, astar};
    // A square with a diagonal: 0–1–2 (2 m) against 0–3–2 via a longer detour.
    let map = Roadmap {
        nodes: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 3.0]],
        edges: vec![
            vec![(1, 1.0), (3, 3.0)],
            vec![(0, 1.0), (2, 1.0)],
            vec![(1, 1.0), (3, 2.24)],
            vec![(0, 3.0), (2, 2.24)],
        ],
    };
    assert_eq!(astar(&map, 0, 2), Some(vec![0, 1, 2]));
    let split = Roadmap {
        nodes: vec![[0.0, 0.0], [1.0, 0.0]],
        edges: vec![vec![], vec![]],
    };
    assert_eq!(astar(&split, 0, 1), None);
}

#[test]
fn rrt_and_rrt_connect_find_the_gap() {
    use forkbench_nav::{RrtParams, plan_rrt, plan_rrt_connect};
    let g = wall_with_gap();
    let (start, goal) = ([1.0, 0.0], [9.0, 0.0]);
    let p = RrtParams {
        step_m: 0.5,
        seed: 3,
        ..RrtParams::default()
    };
    for (name, route) in [
        ("rrt", plan_rrt(&g, start, goal, &p).expect("plans")),
        (
            "rrt-connect",
            plan_rrt_connect(&g, start, goal, &p).expect("plans"),
        ),
    ] {
        let pts = route.points.unwrap_or_else(|| panic!("{name}: no path"));
        assert_valid(&g, &pts, start, goal);
    }
}

#[test]
fn endpoints_in_obstacles_or_off_the_map_are_refused() {
    use forkbench_nav::{NavError, PrmParams, plan_prm};
    let g = wall_with_gap();
    let p = PrmParams {
        nodes: 50,
        connect_m: None,
        seed: 1,
    };
    let e = plan_prm(&g, [5.0, 0.0], [9.0, 0.0], &p).expect_err("start in the wall");
    assert!(matches!(e, NavError::Blocked { which: "start", .. }), "{e}");
    let e = plan_prm(&g, [1.0, 0.0], [50.0, 0.0], &p).expect_err("goal off the map");
    assert!(matches!(e, NavError::OffMap { which: "goal", .. }), "{e}");
}
