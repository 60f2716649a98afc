//! Round four of hostile input: maps and worlds at the edge of the extent, numbers that are not numbers, and trial counts past what a process can hold, each refused at once with a message, or planned within bounded memory.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::common::{forkbench, s, text, tmp_in};

fn tmp(name: &str) -> PathBuf {
    tmp_in("forkbench-hostile4", name)
}

/// `forkbench args`, which must exit 1 (bad input) or 2 (clap's usage error) at once,
/// saying `want`.
fn refused(args: &[&str], want: &str) {
    let t0 = Instant::now();
    let o = forkbench(args);
    assert!(
        t0.elapsed() < Duration::from_secs(20),
        "{args:?} took {:?}",
        t0.elapsed()
    );
    assert!(
        matches!(o.status.code(), Some(1 | 2)),
        "{args:?}: {}",
        text(&o)
    );
    assert!(text(&o).contains(want), "{args:?}: {}", text(&o));
    assert!(!text(&o).contains("panicked"), "{args:?}: {}", text(&o));
}

/// A 4 × 4 free map_server map at `resolution` metres per cell.
fn map_at(name: &str, resolution: &str) -> PathBuf {
    let pgm = tmp(&format!("{name}.pgm"));
    let mut bytes = b"P5\n4 4\n255\n".to_vec();
    bytes.extend([254u8; 16]);
    std::fs::write(&pgm, bytes).expect("pgm");
    let yaml = tmp(&format!("{name}.yaml"));
    std::fs::write(
        &yaml,
        format!(
            "image: {name}.pgm\nresolution: {resolution}\norigin: [0, 0, 0]\nnegate: 0\n\
             occupied_thresh: 0.65\nfree_thresh: 0.196\n"
        ),
    )
    .expect("yaml");
    yaml
}

/// `plan --map` reads a map under the scenario loader's bounds: a resolution that spreads
/// the map past ±10 km is refused naming the field, where it used to panic or abort.
#[test]
fn plan_map_resolution_beyond_the_world_is_refused() {
    for (name, res) in [("huge", "1e20"), ("far", "1e4")] {
        let map = map_at(name, res);
        refused(
            &[
                "plan",
                "hybrid-astar",
                "--map",
                s(&map),
                "--start",
                "1,1,0",
                "--goal",
                "2,2,0",
            ],
            "resolution",
        );
    }
    // A coarse map inside the extent plans (the heuristic's cells follow the map's).
    let map = map_at("coarse", "50");
    let o = forkbench(&[
        "plan",
        "hybrid-astar",
        "--map",
        s(&map),
        "--start",
        "30,30,0",
        "--goal",
        "150,150,0",
    ]);
    assert!(o.status.success(), "{}", text(&o));
}

/// A world whose walls stand at ±9,990 m (inside the extent) is planned on with
/// Hybrid-A*: its heuristic grid is capped, so it neither aborts on allocation nor
/// outruns the time budget.
#[test]
fn hybrid_astar_on_a_world_at_the_extent_s_edge_plans_in_bounded_memory() {
    let world = tmp("edge.toml");
    std::fs::write(
        &world,
        "name = \"edge\"\n\
         [[wall]]\nx_m = -9990\ny_m = 0\nlength_m = 0.2\nwidth_m = 1\n\
         [[wall]]\nx_m = 9990\ny_m = 0\nlength_m = 0.2\nwidth_m = 1\n\
         [[wall]]\nx_m = 0\ny_m = 9990\nlength_m = 1\nwidth_m = 0.2\n\
         [[wall]]\nx_m = 0\ny_m = -9990\nlength_m = 1\nwidth_m = 0.2\n",
    )
    .expect("world");
    let t0 = Instant::now();
    let o = forkbench(&[
        "plan",
        "hybrid-astar",
        "--map",
        s(&world),
        "--resolution-m",
        "2.5",
        "--start",
        "0,0,0",
        "--goal",
        "10,5,0",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(t0.elapsed() < Duration::from_secs(30), "{:?}", t0.elapsed());
}

/// Numbers that are not numbers, or out of range, are refused by name before anything
/// runs: a NaN margin used to plan a path through a rack with exit 0.
#[test]
fn plan_numbers_out_of_range_are_refused_by_name() {
    let world = crate::common::repo_root().join("worlds/warehouse.toml");
    let base = [
        "plan",
        "prm",
        "--map",
        s(&world),
        "--start",
        "2,2,0",
        "--goal",
        "5,2,0",
    ];
    for (extra, want) in [
        (&["--margin-m", "NaN"][..], "margin_m"),
        (&["--margin-m", "inf"][..], "margin_m"),
        (&["--margin-m=-0.5"][..], "margin_m"),
        (&["--smooth", "--lead-m", "NaN"][..], "lead_m"),
        (&["--smooth", "--approach-m", "inf"][..], "approach_m"),
        (&["--nodes", "0"][..], "--nodes"),
        (&["--start-curvature", "NaN"][..], "curvature"),
        (
            &["--start-curvature", "0.5"][..],
            "--start-curvature is for pick planners",
        ),
    ] {
        refused(&[&base[..], extra].concat(), want);
    }
    refused(&["corridor", "--resolution", "1e-9"], "resolution_m");
}

/// A batch whose records could not be held is refused before a trial or a job list is
/// made, with the way out (fewer trials, or shards); a shard's share is what counts.
#[test]
fn a_batch_too_large_to_hold_is_refused_at_once() {
    let field = crate::common::repo_root().join("scenarios/field-test.toml");
    let out = tmp("huge-batch");
    refused(
        &[
            "batch",
            s(&field),
            "--out",
            s(&out),
            "--trials",
            "100000000",
        ],
        "--shard",
    );
    refused(
        &["batch", s(&field), "--out", s(&out), "--jobs", "0"],
        "jobs 0: at least 1",
    );
    assert!(!out.join("trials.jsonl").exists());
}

/// A mission whose world cannot be rasterised at its `resolution_m` is refused at load,
/// naming the field, instead of every trial failing.
#[test]
fn a_mission_resolution_that_cannot_rasterise_is_refused_at_load() {
    let root = crate::common::repo_root();
    let text = std::fs::read_to_string(root.join("scenarios/warehouse-mission.toml"))
        .expect("scenario")
        .replace(
            "world = \"",
            &format!("world = \"{}/scenarios/", root.display()),
        )
        .replace("[mission.global]", "[mission.global]\nresolution_m = 0.001");
    let f = tmp("fine-mission.toml");
    std::fs::write(&f, text).expect("write");
    refused(&["check", s(&f)], "mission.global.resolution_m");
}

/// A map YAML nested deep (a megabyte of brackets, which a YAML parser takes minutes
/// over) is refused before parsing, naming the line.
#[test]
fn a_deeply_nested_map_yaml_is_refused_before_parsing() {
    let deep = tmp("deep.yaml");
    let n = 200_000;
    std::fs::write(
        &deep,
        format!("image: m.pgm\nx: {}{}\n", "[".repeat(n), "]".repeat(n)),
    )
    .expect("yaml");
    refused(
        &[
            "plan",
            "hybrid-astar",
            "--map",
            s(&deep),
            "--start",
            "1,1,0",
            "--goal",
            "2,2,0",
        ],
        "line 2: brackets nest deeper",
    );
}

/// `replay` follows a manifest's scenario path only to the scenario the batch ran: a
/// manifest edited to name another file (here a secret-looking one, and a scenario with
/// other settings) is refused without quoting it; the batch's own file still replays.
#[test]
fn replay_follows_a_manifest_only_to_the_scenario_the_batch_ran() {
    let root = crate::common::repo_root();
    let scn = tmp("replay-own.toml");
    let own = std::fs::read_to_string(root.join("scenarios/field-test.toml"))
        .expect("field test")
        .replace("name = \"field-test\"", "name = \"own\"");
    std::fs::write(&scn, &own).expect("write");
    let out = tmp("replay-batch");
    let o = forkbench(&[
        "batch",
        s(&scn),
        "--trials",
        "1",
        "--record",
        "none",
        "--force-new",
        "--out",
        s(&out),
    ]);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{}", text(&o));
    let records = out.join("trials.jsonl");
    let replay = || forkbench(&["replay", s(&records), "--line", "1"]);
    assert!(text(&replay()).contains("identical to the recorded outcome"));
    let manifest = out.join("manifest.json");
    let original = std::fs::read_to_string(&manifest).expect("manifest");
    let secret = tmp("secret.txt");
    std::fs::write(&secret, "root:SECRET-HASH:19000:0:99999:7:::\n").expect("secret");
    let other = tmp("replay-other.toml");
    std::fs::write(&other, own.replace("seed = 1", "seed = 2")).expect("other");
    for (target, why) in [
        (&secret, "does not load"),
        (&other, "not the ones the batch ran"),
    ] {
        let edited = original.replace(
            &format!(
                "\"file\": {}",
                serde_json::to_string(s(&scn)).expect("json")
            ),
            &format!(
                "\"file\": {}",
                serde_json::to_string(s(target)).expect("json")
            ),
        );
        assert_ne!(edited, original, "the manifest names the scenario's file");
        std::fs::write(&manifest, edited).expect("edit");
        let o = replay();
        assert_eq!(o.status.code(), Some(1), "{}", text(&o));
        assert!(text(&o).contains(why), "{}", text(&o));
        assert!(!text(&o).contains("SECRET"), "{}", text(&o));
    }
}

/// A custom pallet's name with terminal escapes reaches the terminal as visible text,
/// and a point written with a third number is refused, naming the field.
#[test]
fn names_print_escaped_and_points_have_exactly_two_numbers() {
    let root = crate::common::repo_root();
    let custom = std::fs::read_to_string(root.join("scenarios/pallets/dusseldorf-custom.toml"))
        .expect("scenario")
        .replace(
            "name = \"dusseldorf\"",
            "name = \"evil\\u001b]0;owned\\u0007\\u001b[2J\"",
        )
        .replace(
            "world = \"",
            &format!("world = \"{}/scenarios/pallets/", root.display()),
        );
    let f = tmp("escaped.toml");
    std::fs::write(&f, custom).expect("write");
    let o = forkbench(&["check", s(&f)]);
    assert!(o.status.success(), "{}", text(&o));
    let shown = String::from_utf8_lossy(&o.stdout);
    assert!(
        !shown.contains('\u{1b}') && !shown.contains('\u{7}'),
        "{shown:?}"
    );
    assert!(shown.contains("evil\\u{1b}"), "{shown}");
    let field = std::fs::read_to_string(root.join("scenarios/field-test.toml")).expect("field");
    let p3 = tmp("three.toml");
    std::fs::write(
        &p3,
        format!(
            "{field}\n[[mover]]\nkind = \"person\"\nroute = [[1, 5, 99], [2, 5]]\nspeed_mps = 1.2\n"
        ),
    )
    .expect("write");
    refused(&["check", s(&p3)], "expected 2 numbers");
}

/// A global planner that searched and found no path exits 3, whichever planner: PRM with
/// too few samples as Hybrid-A* boxed in.
#[test]
fn no_path_is_exit_3_for_every_global_planner() {
    let world = crate::common::repo_root().join("worlds/warehouse.toml");
    let prm = forkbench(&[
        "plan",
        "prm",
        "--map",
        s(&world),
        "--start",
        "3,3,90",
        "--goal",
        "30.75,10.25,0",
        "--nodes",
        "5",
        "--connect-m",
        "2",
    ]);
    assert_eq!(prm.status.code(), Some(3), "{}", text(&prm));
    assert!(text(&prm).contains("no path"), "{}", text(&prm));
    let boxed = tmp("boxed.toml");
    std::fs::write(
        &boxed,
        "name = \"boxed\"\n\
         [[wall]]\nx_m = 10\ny_m = 0\nlength_m = 0.2\nwidth_m = 20\n\
         [[wall]]\nx_m = -10\ny_m = 0\nlength_m = 0.2\nwidth_m = 20\n\
         [[wall]]\nx_m = 0\ny_m = 10\nlength_m = 20\nwidth_m = 0.2\n\
         [[wall]]\nx_m = 0\ny_m = -10\nlength_m = 20\nwidth_m = 0.2\n\
         [[wall]]\nx_m = 0\ny_m = 0\nlength_m = 0.2\nwidth_m = 20\n",
    )
    .expect("world");
    let hybrid = forkbench(&[
        "plan",
        "hybrid-astar",
        "--map",
        s(&boxed),
        "--start",
        "-5,0,90",
        "--goal",
        "5,0,90",
    ]);
    assert_eq!(hybrid.status.code(), Some(3), "{}", text(&hybrid));
}

/// `batch --junit` naming one of the batch's inputs (its scenario) or outputs is refused
/// before anything runs, and the file is left as it was.
#[test]
fn batch_junit_never_replaces_an_input() {
    let root = crate::common::repo_root();
    let scn = tmp("junit-input.toml");
    std::fs::copy(root.join("scenarios/field-test.toml"), &scn).expect("copy");
    let before = std::fs::read_to_string(&scn).expect("read");
    let out = tmp("junit-out");
    refused(
        &[
            "batch",
            s(&scn),
            "--trials",
            "1",
            "--out",
            s(&out),
            "--junit",
            s(&scn),
        ],
        "junit-input.toml",
    );
    assert_eq!(std::fs::read_to_string(&scn).expect("kept"), before);
}

/// `detect` reports each located face's evidence score and counts the faces its
/// threshold turned down; `--min-score` is range-checked. (Turning faces down is
/// measured on simulated façades in `sensors/src/evidence.rs`.)
#[test]
fn detect_reports_the_evidence_score_and_applies_its_threshold() {
    let field = crate::common::repo_root().join("scenarios/field-test.toml");
    let mcap = tmp("evidence.mcap");
    crate::common::record_field_mcap(&mcap);
    let lines = tmp("evidence.jsonl");
    let run = |min: &str| {
        forkbench(&[
            "detect",
            s(&mcap),
            "--scenario",
            s(&field),
            "--min-score",
            min,
            "--out",
            s(&lines),
            "--json",
        ])
    };
    let o = run("0.5");
    assert!(o.status.success(), "{}", text(&o));
    let first: serde_json::Value = serde_json::from_str(
        std::fs::read_to_string(&lines)
            .expect("lines")
            .lines()
            .next()
            .expect("a line"),
    )
    .expect("json");
    let score = first["score"].as_f64().expect("a score");
    assert!(first["found"] == true && score > 0.5, "{first}");
    // The summary counts what the threshold turned down (none of a simulated face).
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("summary");
    assert_eq!(
        (v["found"].as_u64(), v["rejected"].as_u64()),
        (Some(1), Some(0)),
        "{v}"
    );
    refused(&["detect", s(&mcap), "--min-score", "1.5"], "--min-score");
}
