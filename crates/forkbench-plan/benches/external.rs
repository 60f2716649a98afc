//! Round-trip cost of the external-planner protocol per plan, beyond the planner's own
//! time (issue target: ≤ 1 ms). The planner is this bench binary itself, started with
//! `--echo-planner`: it answers every request with a precomputed 8.5 m path at 1 cm, so
//! what is timed is forkbench's side (request JSON, pipes, response parsing, the path
//! checks) plus the echo's reading of the request.

use std::io::{BufRead, Write};
use std::path::PathBuf;

use criterion::Criterion;
use forkbench_core::Pose2;
use forkbench_plan::external::ExternalPlanner;
use forkbench_plan::{BsplinePlanner, PlanRequest, Planner};

const LENGTH_M: f64 = 8.5;

fn request() -> PlanRequest {
    PlanRequest::new(Pose2::new(0.0, 0.0, 0.0), Pose2::new(LENGTH_M, 0.0, 0.0))
}

/// The echo planner: hello, then a fixed straight path for every request.
fn echo() {
    let n = (LENGTH_M / 0.01).round() as usize;
    let samples: Vec<[f64; 5]> = (0..=n)
        .map(|i| {
            let s = LENGTH_M * i as f64 / n as f64;
            [s, s, 0.0, 0.0, 0.0]
        })
        .collect();
    let samples = serde_json::to_string(&samples).expect("json");
    let stdin = std::io::stdin();
    let mut out = std::io::stdout().lock();
    for line in stdin.lock().lines() {
        let line = line.expect("stdin");
        let v: serde_json::Value = serde_json::from_str(&line).expect("json");
        let reply = if v["type"] == "hello" {
            r#"{"type":"hello","protocol":"forkbench-planner","version":1}"#.to_owned()
        } else {
            format!(r#"{{"type":"path","id":{},"samples":{samples}}}"#, v["id"])
        };
        writeln!(out, "{reply}")
            .and_then(|()| out.flush())
            .expect("stdout");
    }
}

fn bench(c: &mut Criterion) {
    let exe = std::env::current_exe().expect("own path");
    let settings: toml::Table = toml::from_str(&format!(
        "command = [{:?}, \"--echo-planner\"]",
        exe.display().to_string()
    ))
    .expect("toml");
    let mut external =
        ExternalPlanner::from_settings(&settings, PathBuf::from(".")).expect("settings");
    let req = request();
    external.plan(&req).expect("the echo answers"); // start the process outside the timing
    let mut g = c.benchmark_group("external");
    g.bench_function("round_trip_8.5m", |b| {
        b.iter(|| external.plan(&req).expect("plans"))
    });
    // For scale: the B-spline planner's own time on the same request, in process.
    let mut bspline = BsplinePlanner::default();
    g.bench_function("bspline_in_process_8.5m", |b| {
        b.iter(|| bspline.plan(&req).expect("plans"))
    });
    g.finish();
}

fn main() {
    if std::env::args().any(|a| a == "--echo-planner") {
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
