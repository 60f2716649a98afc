//! Round trip of the external-tracker protocol per control tick (issue target: ≤ 100 µs):
//! forkbench's side alone against an echo tracker (this bench binary, started with
//! `--echo-tracker`, answers every tick with a fixed command), and the Python Stanley
//! example (`examples/trackers/stanley.py`) as a user would run it.

use std::io::{BufRead, Write};
use std::path::PathBuf;

use criterion::Criterion;
use forkbench_core::{ForkliftSpec, Path, Pose2};
use forkbench_track::{ExternalTracker, Tracker, TrackerInput};

/// The echo tracker: hello, `ok` to resets, a fixed command to ticks.
fn echo() {
    let stdin = std::io::stdin();
    let mut out = std::io::stdout().lock();
    for line in stdin.lock().lines() {
        let line = line.expect("stdin");
        let v: serde_json::Value = serde_json::from_str(&line).expect("json");
        let reply = match v["type"].as_str() {
            Some("hello") => {
                r#"{"type":"hello","protocol":"forkbench-tracker","version":1}"#.to_owned()
            }
            Some("reset") => format!(r#"{{"type":"ok","id":{}}}"#, v["id"]),
            _ => format!(
                r#"{{"type":"command","id":{},"speed_mps":0.8,"steer_rad":0.01,"done":false}}"#,
                v["id"]
            ),
        };
        writeln!(out, "{reply}")
            .and_then(|()| out.flush())
            .expect("stdout");
    }
}

/// A tracker running `command` in `dir`, reset onto an 8.5 m straight path.
fn started(command: &str, dir: PathBuf, truck: &ForkliftSpec) -> ExternalTracker {
    let settings: toml::Table = toml::from_str(&format!("command = {command}")).expect("toml");
    let mut t = ExternalTracker::from_settings(&settings, dir, "bench").expect("settings");
    t.reset(
        &Path::straight(&Pose2::new(0.0, 0.0, 0.0), 8.5, 0.01),
        truck,
    );
    assert_eq!(t.fault(), None, "the tracker takes the path");
    t
}

fn bench(c: &mut Criterion) {
    let truck = ForkliftSpec::default();
    let exe = std::env::current_exe().expect("own path");
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/trackers");
    let echo_command = format!("[{:?}, \"--echo-tracker\"]", exe.display().to_string());
    let mut trackers = [
        (
            "round_trip_echo",
            started(&echo_command, ".".into(), &truck),
        ),
        (
            "round_trip_python_stanley",
            started("[\"python3\", \"stanley.py\"]", examples, &truck),
        ),
    ];
    let mut g = c.benchmark_group("external_tracker");
    for (label, tracker) in &mut trackers {
        let mut t_s = 0.0;
        g.bench_function(*label, |b| {
            b.iter(|| {
                t_s += 0.01;
                let input = TrackerInput {
                    t_s,
                    pose: Pose2::new(1.0, 0.02, 0.01),
                    speed_mps: 0.8,
                    steer_rad: 0.0,
                    fix_measured_s: None,
                    truck: &truck,
                };
                tracker.command(&input)
            })
        });
        assert_eq!(tracker.fault(), None, "{label} answered every tick");
    }
    g.finish();
}

fn main() {
    if std::env::args().any(|a| a == "--echo-tracker") {
        echo();
        return;
    }
    let mut c = Criterion::default()
        .sample_size(50)
        .measurement_time(std::time::Duration::from_secs(3))
        .configure_from_args();
    bench(&mut c);
    c.final_summary();
}
