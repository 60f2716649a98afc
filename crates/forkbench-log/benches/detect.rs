//! `forkbench detect`'s speed: every scan of a ROS 2 bag read, decoded and run through a detector (target ≥ 2,000 scans/s on one core with the built-in one).

use std::collections::BTreeMap;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use forkbench_core::PalletSpec;
use forkbench_log::detect::{DetectOptions, detect_bag};
use forkbench_sensors::detector::{PalletDetector, Pockets};
use forkbench_sensors::face_fit::FaceFit;

/// Copies the rosbags fixture's scans (TiM561, 819 beams) `times` times into one bag.
fn big_bag(times: usize) -> (std::path::PathBuf, usize) {
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/rosbags-tim561/bag/bag.mcap");
    let bytes = std::fs::read(&fixture).expect("the fixture bag");
    let scans: Vec<Vec<u8>> = mcap::MessageStream::new(&bytes)
        .expect("an MCAP file")
        .map(|m| m.expect("a message").data.to_vec())
        .collect();
    let out = std::env::temp_dir().join(format!("forkbench-bench-{}.mcap", std::process::id()));
    let f = std::io::BufWriter::new(std::fs::File::create(&out).expect("file"));
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .create(f)
        .expect("writer");
    let schema = w
        .add_schema("sensor_msgs/msg/LaserScan", "ros2msg", b"")
        .expect("schema");
    let ch = w
        .add_channel(schema, "/scan", "cdr", &BTreeMap::new())
        .expect("channel");
    let mut n = 0;
    for _ in 0..times {
        for s in &scans {
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: n as u32,
                log_time: n as u64,
                publish_time: n as u64,
            };
            w.write_to_known_channel(&header, s).expect("message");
            n += 1;
        }
    }
    w.finish().expect("finish");
    (out, n)
}

fn bench(c: &mut Criterion) {
    let (bag, n) = big_bag(150);
    let pallet = PalletSpec::field_1200();
    let mut g = c.benchmark_group("detect");
    g.throughput(Throughput::Elements(n as u64));
    g.sample_size(10);
    let detectors: [(&str, Box<dyn PalletDetector>); 2] = [
        ("pockets", Box::new(Pockets::default())),
        ("face_fit", Box::new(FaceFit::default())),
    ];
    for (name, mut d) in detectors {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut found = 0;
                detect_bag(
                    &bag,
                    &DetectOptions::default(),
                    d.as_mut(),
                    &pallet,
                    &mut |r| {
                        found += usize::from(r.found);
                    },
                )
                .expect("reads");
                found
            })
        });
    }
    g.finish();
    let _ = std::fs::remove_file(bag);
}

criterion_group!(benches, bench);
criterion_main!(benches);
