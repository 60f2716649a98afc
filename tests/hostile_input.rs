//! Hostile input, round two: exports that cannot inject (CSV formulas, Markdown, terminal
//! escapes), special files, records the manifest does not name, duplicate names, maps
//! beyond the world's bounds, planning settings without a bound, long numbers, secrets in a
//! planner's environment. Each was accepted, hung or leaked before.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn forkbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh folder of the test's own: tests run in parallel in one process, so a name used
/// twice would let one test empty the other's folder under it.
fn tmp(name: &str) -> PathBuf {
    static USED: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    {
        let mut used = USED.lock().expect("names");
        assert!(!used.iter().any(|u| u == name), "tmp({name:?}) used twice");
        used.push(name.to_string());
    }
    let d = std::env::temp_dir().join(format!(
        "forkbench-hostile-in-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A pick on the open floor named `name`, with the bspline planner reported as `planner`.
fn pick(dir: &Path, name: &str, planner: &str) -> PathBuf {
    let f = dir.join("pick.toml");
    let body = format!(
        "name = {name:?}\nstart = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\npallet = {{ x_m = 6.5, y_m = 0.5, heading_deg = 5.0 }}\n[planner]\nkind = \"bspline\"\nname = {planner:?}\n"
    );
    std::fs::write(&f, body).expect("write");
    f
}

#[test]
fn csv_and_markdown_cells_cannot_inject() {
    let dir = tmp("exports");
    let scn = pick(&dir, "=cmd|' /C calc'!A0", "@SUM(A1) <b>x");
    let out = dir.join("out");
    let o = forkbench(&[
        "batch",
        scn.to_str().expect("utf8"),
        "--trials",
        "2",
        "--csv",
        "--record",
        "none",
        "--out",
        out.to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let csv = std::fs::read_to_string(out.join("trials.csv")).expect("csv");
    let row = csv.lines().nth(1).expect("a row");
    assert!(row.starts_with("'=cmd"), "{row}");
    assert!(row.contains("'@SUM(A1)"), "{row}");
    let md = std::fs::read_to_string(out.join("summary.md")).expect("md");
    assert!(md.contains("=cmd\\|' /C calc'!A0"), "{md}");
    assert!(md.contains("@SUM(A1) &lt;b&gt;x"), "{md}");
}

#[test]
fn special_files_are_refused_at_once() {
    let dir = tmp("special-outputs");
    let t0 = Instant::now();
    let o = forkbench(&[
        "regress",
        "--baseline",
        "/dev/zero",
        dir.to_str().expect("utf8"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o).contains("not a regular file (a device)"),
        "{}",
        text(&o)
    );
    // A map whose image is a FIFO or a device, or a file that is no PGM (not quoted).
    let fifo = dir.join("fifo.pgm");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo")
            .success()
    );
    for (image, says) in [
        ("fifo.pgm", "not a regular file (a FIFO)"),
        ("/dev/zero", "not a regular file (a device)"),
        ("/etc/passwd", "does not start with P5"),
    ] {
        let yaml = dir.join("m.yaml");
        std::fs::write(&yaml, format!("image: {image}\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")).expect("yaml");
        let o = forkbench(&[
            "plan",
            "prm",
            "--map",
            yaml.to_str().expect("utf8"),
            "--start",
            "1,1,0",
            "--goal",
            "2,2,0",
        ]);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(1), "{t}");
        assert!(t.contains(says) && !t.contains("root"), "{image}: {t}");
    }
    // A map YAML that is really another file: the parser's message quotes none of it.
    let yaml = dir.join("passwd.yaml");
    std::fs::copy("/etc/passwd", &yaml).expect("copy");
    let o = forkbench(&[
        "plan",
        "prm",
        "--map",
        yaml.to_str().expect("utf8"),
        "--start",
        "1,1,0",
        "--goal",
        "2,2,0",
    ]);
    assert!(
        text(&o).contains("passwd.yaml") && !text(&o).contains("root"),
        "{}",
        text(&o)
    );
    assert!(t0.elapsed() < Duration::from_secs(10), "{:?}", t0.elapsed());
}

#[test]
fn duplicate_names_and_maps_beyond_the_bounds_are_refused() {
    let dir = tmp("names");
    let world = dir.join("w.toml");
    std::fs::write(&world, "name = \"w\"\n[[station]]\nname = \"dock\"\nx_m = 0.0\ny_m = 0.0\nheading_deg = 0.0\n[[station]]\nname = \"dock\"\nx_m = 5.0\ny_m = 0.0\nheading_deg = 0.0\n").expect("world");
    let o = forkbench(&[
        "map",
        world.to_str().expect("utf8"),
        "--out",
        dir.to_str().expect("utf8"),
    ]);
    assert!(
        text(&o).contains("station[1].name") && text(&o).contains("also station[0]"),
        "{}",
        text(&o)
    );
    // A map placed 1000 km away: its cells become racks beyond ±10 km.
    let o = forkbench(&[
        "map",
        repo_root()
            .join("worlds/rack-bay.toml")
            .to_str()
            .expect("utf8"),
        "--out",
        dir.to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let yaml = dir.join("rack-bay.yaml");
    let far = std::fs::read_to_string(&yaml)
        .expect("yaml")
        .replace("- -5.0", "- 1000000.0");
    std::fs::write(&yaml, far).expect("write");
    let scn = dir.join("s.toml");
    std::fs::write(&scn, format!("name = \"far\"\nworld = {:?}\nstart = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\npallet = {{ x_m = 6.5, y_m = 0.0, heading_deg = 0.0 }}\nplanner = \"bspline\"\n", yaml.display().to_string())).expect("scn");
    let o = forkbench(&["trial", scn.to_str().expect("utf8")]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("beyond ±10 km"), "{}", text(&o));
}

#[test]
fn planning_without_a_bound_is_refused_at_once() {
    let map = repo_root().join("worlds/warehouse.toml");
    let map = map.to_str().expect("utf8");
    let t0 = Instant::now();
    let o = forkbench(&[
        "plan",
        "prm",
        "--map",
        map,
        "--start",
        "3,3,90",
        "--goal",
        "30.75,10.25,0",
        "--nodes",
        "100000",
        "--connect-m",
        "40",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o).contains("candidate edges, at most 1.250e7"),
        "{}",
        text(&o)
    );
    let o = forkbench(&[
        "map",
        map,
        "--inflate-m",
        "100",
        "--out",
        tmp("inflate").to_str().expect("utf8"),
    ]);
    assert!(
        text(&o).contains("--inflate-m 100: must lie within 0..5 m"),
        "{}",
        text(&o)
    );
    // The shipped mission with 100,000 nodes and 40 m connections: its first leg fails at
    // once, saying why, and the trial does not pretend the pick follows.
    let dir = tmp("mission");
    let src = std::fs::read_to_string(repo_root().join("scenarios/warehouse-mission.toml"))
        .expect("mission");
    let big = src
        .replace("nodes = 500", "nodes = 100000")
        .replace("connect_m = 10.0", "connect_m = 40.0");
    let scn = repo_root()
        .join("crates/forkbench-trial/data/scenarios")
        .join(format!("probe-{}.toml", std::process::id()));
    std::fs::write(&scn, big).expect("write");
    let o = forkbench(&["mission", scn.to_str().expect("utf8")]);
    let _ = std::fs::remove_file(&scn);
    let _ = dir;
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(
        text(&o).contains("planning refused")
            && text(&o).contains("the trial ends without the pick"),
        "{}",
        text(&o)
    );
    assert!(t0.elapsed() < Duration::from_secs(20), "{:?}", t0.elapsed());
}

#[test]
fn numbers_in_messages_are_compact_and_escapes_are_shown_not_obeyed() {
    let o = forkbench(&[
        "plan",
        "bspline",
        "--start",
        "0,0,90",
        "--goal",
        "1e300,6.5,105",
    ]);
    assert!(text(&o).contains("(1e300, 6.5)"), "{}", text(&o));
    assert!(text(&o).len() < 400, "{}", text(&o));
}

#[test]
fn a_planner_gets_only_the_allowed_environment() {
    let dir = tmp("env");
    let script = dir.join("env_planner.py");
    std::fs::write(&script, "import json, os, sys\nfor line in sys.stdin:\n    m = json.loads(line)\n    if m['type'] == 'hello':\n        print(json.dumps({'type': 'hello', 'protocol': 'forkbench-planner', 'version': 1}), flush=True)\n    else:\n        secret = 'SECRET_PROBE' in os.environ\n        print(json.dumps({'type': 'error', 'id': m['id'], 'message': '\\x1b[2K\\r' + ('secret seen' if secret else 'no secret')}), flush=True)\n").expect("script");
    for (allow, says) in [
        ("", "secret seen"),
        ("pass_env = [\"PATH\"]\n", "no secret"),
    ] {
        let scn = dir.join("s.toml");
        std::fs::write(&scn, format!("name = \"env\"\nstart = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\npallet = {{ x_m = 8.0, y_m = 0.0, heading_deg = 0.0 }}\n[planner]\nkind = \"external\"\ncommand = [\"python3\", \"env_planner.py\"]\n{allow}")).expect("scn");
        let o = Command::new(env!("CARGO_BIN_EXE_forkbench"))
            .args(["trial", scn.to_str().expect("utf8"), "--no-noise"])
            .env("SECRET_PROBE", "1")
            .output()
            .expect("runs");
        let t = text(&o);
        assert!(t.contains(says), "{allow}: {t}");
        // The planner's escape is printed as text, not sent to the terminal.
        assert!(!t.contains('\u{1b}') && t.contains("\\u{1b}[2K"), "{t}");
    }
}

#[test]
fn a_failed_output_skips_none_of_the_others_and_stray_records_are_refused() {
    let dir = tmp("outputs");
    let scn = repo_root().join("scenarios/field-test.toml");
    let out = dir.join("out");
    let _ = std::fs::remove_dir_all(&out);
    // The batch's directory (a batch writes only into its own), then `recordings` made a
    // file in it: recording the failed trials cannot work.
    let first = forkbench(&[
        "batch",
        scn.to_str().expect("utf8"),
        "--trials",
        "4",
        "--record",
        "none",
        "--out",
        out.to_str().expect("utf8"),
    ]);
    assert!(
        first.status.code().is_some_and(|c| c == 0 || c == 3),
        "{}",
        text(&first)
    );
    std::fs::write(out.join("recordings"), "in the way").expect("write");
    let junit = dir.join("batch.xml");
    let o = forkbench(&[
        "batch",
        scn.to_str().expect("utf8"),
        "--trials",
        "4",
        "--out",
        out.to_str().expect("utf8"),
        "--csv",
        "--report",
        "--junit",
        junit.to_str().expect("utf8"),
    ]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("| field-test |")
            && t.contains("the trials are intact")
            && t.contains("recordings"),
        "{t}"
    );
    for f in [out.join("trials.csv"), out.join("report.html"), junit] {
        assert!(f.is_file(), "{} was skipped", f.display());
    }
    // A record of a trial index the manifest does not name, the count unchanged.
    let records = out.join("trials.jsonl");
    let edited = std::fs::read_to_string(&records)
        .expect("records")
        .replacen("{\"trial\":0,", "{\"trial\":999,", 1);
    std::fs::write(&records, edited).expect("write");
    let o = forkbench(&[
        "baseline",
        out.to_str().expect("utf8"),
        "--out",
        dir.join("b.json").to_str().expect("utf8"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("does not name"), "{}", text(&o));
}

/// Round three: every user file goes through the one capped reader, so a FIFO or a device
/// as the scenario, its world, `--truck`, `--config` or `reproduce --table` is refused at
/// once, naming it, instead of hanging or reading without end.
#[test]
fn special_files_anywhere_are_refused_at_once() {
    let d = tmp("special");
    let fifo = d.join("fifo");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo")
            .success()
    );
    let f = fifo.to_str().expect("utf-8");
    let world_fifo = d.join("w.toml");
    std::fs::write(
        &world_fifo,
        format!(
            "name = \"x\"\nplanner = \"bspline\"\nworld = \"{f}\"\nstart = {{ x_m = 0, y_m = 0, heading_deg = 0 }}\npallet = {{ x_m = 8, y_m = 0, heading_deg = 0 }}\n"
        ),
    )
    .expect("write");
    let w = world_fifo.to_str().expect("utf-8");
    let pose = ["--start", "0,0,90", "--goal", "1.5,6.5,105"];
    let field = repo_root()
        .join("scenarios/field-test.toml")
        .display()
        .to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["check", f], "a FIFO"),
        (vec!["check", w], "a FIFO"),
        (vec!["coverage", f], "a FIFO"),
        (
            vec!["map", f, "--out", d.to_str().expect("utf-8")],
            "a FIFO",
        ),
        (
            [&["plan", "bspline", "--truck", "/dev/zero"][..], &pose].concat(),
            "a device",
        ),
        (
            [&["plan", "bspline", "--config", f][..], &pose].concat(),
            "a FIFO",
        ),
        (
            vec!["reproduce", "bspline", "--table", "/dev/zero"],
            "a device",
        ),
        (vec!["trial", &field, "--mcap", f], "not a regular file"),
        (
            vec!["trial", &field, "--rrd", f],
            crate::common::rrd_says("not a regular file"),
        ),
    ];
    for (args, want) in cases {
        let t0 = Instant::now();
        let out = forkbench(&args);
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "{args:?} took too long"
        );
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", text(&out));
        assert!(text(&out).contains(want), "{args:?}: {}", text(&out));
    }
}

/// A world's name with terminal escapes and XML's special characters reaches neither the
/// terminal nor the coverage SVG raw.
#[test]
fn a_world_name_cannot_drive_the_terminal_or_break_the_svg() {
    let d = tmp("coverage-name");
    let world = d.join("w.toml");
    std::fs::write(
        &world,
        "name = \"evil\\u001b[2J<b>&\"\n[[wall]]\nx_m = 0.0\ny_m = 0.0\nlength_m = 4.0\nwidth_m = 0.2\n\
         [[reflector]]\nname = \"a\"\nx_m = 0.0\ny_m = 1.0\n",
    )
    .expect("write");
    let svg = d.join("cov.svg");
    let out = forkbench(&[
        "coverage",
        world.to_str().expect("utf-8"),
        "--plot",
        svg.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(!out.stdout.contains(&0x1b), "{}", text(&out));
    let drawn = std::fs::read_to_string(&svg).expect("svg");
    assert!(!drawn.contains('\u{1b}'), "raw escape in the SVG");
    assert!(!drawn.contains("<b>"), "raw markup in the SVG");
    let _ = std::fs::remove_dir_all(&d);
}

/// A plot that cannot be written is an error naming it (a missing folder, a file-size
/// limit), and nothing half written is left at its name.
#[test]
fn plot_write_failures_are_reported_and_leave_no_truncated_file() {
    let d = tmp("plots");
    let world = repo_root().join("worlds/warehouse.toml");
    let w = world.to_str().expect("utf-8");
    let out = forkbench(&["coverage", w, "--plot", "/nonexistent-dir/cov.png"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    assert!(
        text(&out).contains("/nonexistent-dir/cov.png"),
        "{}",
        text(&out)
    );
    for name in ["cov.png", "cov.svg"] {
        let target = d.join(name);
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -f 20; exec \"$0\" coverage {w} --plot {}",
                target.display()
            ))
            .arg(env!("CARGO_BIN_EXE_forkbench"))
            .output()
            .expect("sh runs");
        assert_eq!(out.status.code(), Some(1), "{name}: {}", text(&out));
        assert!(text(&out).contains("File too large"), "{}", text(&out));
        assert!(!target.exists(), "{name} was left half written");
    }
    let leftovers = std::fs::read_dir(&d).expect("dir").count();
    assert_eq!(leftovers, 0, "temporary files left in {}", d.display());
}

/// An interrupt or a termination kills the external children (each in its own process
/// group, out of a terminal's reach) before forkbench exits with 128 + the signal.
#[test]
fn interrupting_forkbench_kills_its_external_detector() {
    for (signal, code) in [("INT", 130), ("TERM", 143)] {
        let d = tmp(&format!("interrupt-{signal}"));
        let marker = format!("forkbench-sleeper-{}-{signal}", std::process::id());
        std::fs::write(
            d.join("sleeper.py"),
            format!(
                "import json, sys, time\n# {marker}\nprint(json.dumps({{\"type\": \"hello\", \
                 \"protocol\": \"forkbench-detector\", \"version\": 1, \"name\": \"sleeper\"}}), \
                 flush=True)\nsys.stdin.readline()\ntime.sleep(600)\n"
            ),
        )
        .expect("write");
        let scn = d.join("s.toml");
        std::fs::write(
            &scn,
            format!(
                "name = \"s\"\nplanner = \"bspline\"\nstart = {{ x_m = 0, y_m = 0, heading_deg = 0 }}\n\
                 pallet = {{ x_m = 6, y_m = 0, heading_deg = 0 }}\n[sensors.pallet]\nkind = \"tim561\"\n\
                 [sensors.pallet.detector]\nkind = \"external\"\ncommand = [\"python3\", \"sleeper.py\", \"{marker}\"]\n\
                 timeout_s = 300.0\n"
            ),
        )
        .expect("write");
        // Its output kept, so a run that ends otherwise says how.
        let log = std::fs::File::create(d.join("out.txt")).expect("log");
        let mut child = Command::new(env!("CARGO_BIN_EXE_forkbench"))
            .args(["trial", scn.to_str().expect("utf-8")])
            .stdout(log.try_clone().expect("log"))
            .stderr(log)
            .spawn()
            .expect("spawns");
        let running = || {
            Command::new("pgrep")
                .args(["-f", &marker])
                .output()
                .is_ok_and(|o| o.status.success())
        };
        let t0 = Instant::now();
        while !running() && t0.elapsed() < Duration::from_secs(20) {
            std::thread::sleep(Duration::from_millis(100));
        }
        assert!(running(), "the detector never started");
        std::thread::sleep(Duration::from_millis(300));
        let pid = child.id().to_string();
        assert!(
            Command::new("kill")
                .args([&format!("-{signal}"), &pid])
                .status()
                .expect("kill")
                .success()
        );
        let status = child.wait().expect("waits");
        let said = std::fs::read_to_string(d.join("out.txt")).unwrap_or_default();
        assert_eq!(status.code(), Some(code), "{signal}: {said}");
        std::thread::sleep(Duration::from_millis(200));
        assert!(
            !running(),
            "the detector outlived forkbench after SIG{signal}"
        );
    }
}

/// A detector that leaves a child in a session of its own (setsid) and a daemon
/// (double fork, its parent gone) does not leave either behind when a normal trial ends.
#[test]
fn a_detectors_setsid_child_and_daemon_do_not_outlive_the_trial() {
    let d = tmp("setsid");
    let marker = format!("{}", 700_000 + std::process::id() % 90_000);
    std::fs::write(
        d.join("leaver.py"),
        format!(
            "import json, os, subprocess, sys\n\
             subprocess.Popen(['sleep', '{marker}'], start_new_session=True)\n\
             if os.fork() == 0:\n    os.setsid()\n    if os.fork() == 0:\n        os.execvp('sleep', ['sleep', '{marker}.5'])\n    os._exit(0)\n\
             for line in sys.stdin:\n    m = json.loads(line)\n    \
             r = {{\"type\": \"hello\", \"protocol\": \"forkbench-detector\", \"version\": 1, \
             \"name\": \"leaver\"}} if m.get(\"type\") == \"hello\" else {{\"type\": \"none\", \
             \"id\": m[\"id\"]}}\n    print(json.dumps(r), flush=True)\n"
        ),
    )
    .expect("write");
    let scn = d.join("s.toml");
    std::fs::write(
        &scn,
        "name = \"s\"\nplanner = \"bspline\"\nstart = { x_m = 0, y_m = 0, heading_deg = 0 }\n\
         pallet = { x_m = 6, y_m = 0, heading_deg = 0 }\n[sensors.pallet]\nkind = \"tim561\"\n\
         [sensors.pallet.detector]\nkind = \"external\"\ncommand = [\"python3\", \"leaver.py\"]\n",
    )
    .expect("write");
    let out = forkbench(&["trial", scn.to_str().expect("utf-8"), "--json"]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("\"pallet_not_found\""),
        "{}",
        text(&out)
    );
    let left = |needle: &str| {
        Command::new("pgrep")
            .args(["-f", needle])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    std::thread::sleep(Duration::from_millis(200));
    assert!(
        !left(&format!("sleep {marker}$")),
        "the setsid child outlived the trial"
    );
    assert!(
        !left(&format!("sleep {marker}.5")),
        "the daemon outlived the trial"
    );
}
