//! ROS 2 bags (`--ros2`): a rosbag2 directory whose metadata.yaml counts its MCAP's messages, the MCAP `ros2` profile, every message CDR with a ros2msg schema, and the scans equal to the ones the Foxglove MCAP of the same trial holds.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use forkbench_log::ros2::{cdr::CdrReader, msgs::decode_laser_scan};
use mcap::records::Record;

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("forkbench-ros2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

fn repo(path: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path);
    p.to_str().expect("utf-8").to_owned()
}

/// Profile, (schema name, encoding) per schema id, and (topic, schema id, encoding) per
/// channel id, read record by record.
type Layout = (
    String,
    BTreeMap<u16, (String, String)>,
    BTreeMap<u16, (String, u16, String)>,
);

fn layout(bytes: &[u8]) -> Layout {
    let (mut profile, mut schemas, mut channels) =
        (String::new(), BTreeMap::new(), BTreeMap::new());
    for r in mcap::read::LinearReader::new(bytes).expect("an MCAP file") {
        match r.expect("a record") {
            Record::Header(h) => profile = h.profile,
            Record::Schema { header, .. } => {
                schemas.insert(header.id, (header.name, header.encoding));
            }
            Record::Channel(c) => {
                channels.insert(c.id, (c.topic, c.schema_id, c.message_encoding));
            }
            _ => {}
        }
    }
    (profile, schemas, channels)
}

/// The bytes of a bag directory's one MCAP, after checking the directory holds it and a
/// `metadata.yaml` that names it and counts each topic's messages as the MCAP holds them.
fn bag_bytes(dir: &Path) -> Vec<u8> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("a bag directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort_by_key(|n| n != "metadata.yaml");
    assert!(
        names.len() == 2 && names[0] == "metadata.yaml" && names[1].ends_with("_0.mcap"),
        "{names:?}"
    );
    let bytes = std::fs::read(dir.join(&names[1])).expect("the MCAP");
    let yaml = std::fs::read_to_string(dir.join("metadata.yaml")).expect("metadata.yaml");
    assert!(yaml.contains(&format!("- path: {}", names[1])), "{yaml}");
    let mut total = 0;
    for (topic, ms) in messages(&bytes) {
        let entry = format!("name: {topic}\n");
        let at = yaml
            .find(&entry)
            .unwrap_or_else(|| panic!("{topic} not listed: {yaml}"));
        let count = yaml[at..]
            .lines()
            .find_map(|l| l.trim().strip_prefix("message_count: "))
            .expect("a count");
        assert_eq!(count, ms.len().to_string(), "{topic}");
        total += ms.len();
    }
    assert!(
        yaml.contains(&format!("  message_count: {total}\n")),
        "{yaml}"
    );
    bytes
}

/// Each topic's messages, in order.
fn messages(bytes: &[u8]) -> BTreeMap<String, Vec<Vec<u8>>> {
    let mut out: BTreeMap<String, Vec<Vec<u8>>> = BTreeMap::new();
    for m in mcap::MessageStream::new(bytes).expect("an MCAP file") {
        let m = m.expect("a message");
        out.entry(m.channel.topic.clone())
            .or_default()
            .push(m.data.to_vec());
    }
    out
}

fn valid_ros2_name(topic: &str) -> bool {
    topic.starts_with('/')
        && topic[1..].split('/').all(|t| {
            t.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
                && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        })
}

#[test]
fn a_trial_writes_a_ros2_bag_whose_scans_equal_the_mcap_ones() {
    let (bag, mcap) = (tmp("field.ros2"), tmp("field.mcap"));
    let out = Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args([
            "trial",
            &repo("scenarios/field-test.toml"),
            "--json",
            "--force",
            "--replan",
        ])
        .args([
            "--ros2",
            bag.to_str().expect("utf-8"),
            "--mcap",
            mcap.to_str().expect("utf-8"),
        ])
        .output()
        .expect("runs");
    assert!(
        out.status.code().is_some_and(|c| c == 0 || c == 3),
        "{out:?}"
    );
    let outcome: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let bytes = bag_bytes(&bag);
    let (profile, schemas, channels) = layout(&bytes);
    assert_eq!(profile, "ros2");
    assert!(schemas.values().all(|(_, e)| e == "ros2msg"), "{schemas:?}");
    for (topic, schema, encoding) in channels.values() {
        assert_eq!(encoding, "cdr", "{topic}");
        assert!(valid_ros2_name(topic), "{topic}");
        assert!(
            schemas[schema].0.contains("/msg/"),
            "{topic}: {:?}",
            schemas[schema]
        );
    }
    let ros = messages(&bytes);
    let foxglove = messages(&std::fs::read(&mcap).expect("mcap"));
    let pairs: Vec<(&Vec<u8>, &Vec<u8>)> = ["/scan/sensors/tim561", "/scan/sensors/kinect2"]
        .iter()
        .flat_map(|t| {
            assert_eq!(ros[*t].len(), foxglove[*t].len(), "{t}");
            ros[*t].iter().zip(&foxglove[*t])
        })
        .collect();
    assert!(pairs.len() >= 4, "{}", pairs.len());
    for (a, b) in pairs {
        let scan = decode_laser_scan(a).expect("a LaserScan");
        let json: serde_json::Value = serde_json::from_slice(b).expect("JSON");
        let ranges = json["ranges"].as_array().expect("ranges");
        assert_eq!(scan.ranges_m.len(), ranges.len());
        for (r, j) in scan.ranges_m.iter().zip(ranges) {
            match j.as_f64() {
                Some(v) => assert_eq!(*r, v as f32),
                None => assert!(r.is_infinite()),
            }
        }
        assert!(scan.frame_id.starts_with("scanner_"), "{}", scan.frame_id);
    }
    // The outcome, a std_msgs/String of the outcome's JSON.
    let last = ros["/forkbench/outcome"].last().expect("an outcome");
    let text = CdrReader::new(last)
        .and_then(|mut r| r.string())
        .expect("a string");
    let theirs: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(theirs["success"], outcome["success"]);
    assert_eq!(theirs["seed"], outcome["seed"]);
    for t in [
        "/tf",
        "/forkbench/scene",
        "/forkbench/pose",
        "/forkbench/plan",
        "/rosout",
    ] {
        assert!(
            ros.contains_key(t),
            "{t}: {:?}",
            ros.keys().collect::<Vec<_>>()
        );
    }
}

#[test]
fn a_mission_bag_has_its_map_and_routes_and_a_batch_refuses_bags_of_nothing() {
    let bag = tmp("mission.ros2");
    let out = Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args([
            "mission",
            &repo("scenarios/warehouse-mission.toml"),
            "--seed",
            "1",
            "--force",
        ])
        .args(["--ros2", bag.to_str().expect("utf-8")])
        .output()
        .expect("runs");
    assert!(
        out.status.code().is_some_and(|c| c == 0 || c == 3),
        "{out:?}"
    );
    let ros = messages(&bag_bytes(&bag));
    assert!(
        ros.keys().any(|t| t.starts_with("/grid/nav")),
        "{:?}",
        ros.keys()
    );
    assert!(ros.contains_key("/markers"), "{:?}", ros.keys());
    let dir = tmp("nothing");
    let out = Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args([
            "batch",
            &repo("scenarios/field-test.toml"),
            "--trials",
            "1",
            "--record",
            "none",
        ])
        .args(["--ros2", "--out", dir.to_str().expect("utf-8")])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--record none records none"));
}

/// A bag's name ending .mcap is refused (the bag is a directory), and `--force` replaces
/// only a bag directory forkbench wrote: one holding anything else is refused and kept.
#[test]
fn a_bag_directory_replaces_only_a_bag_forkbench_wrote() {
    let run = |bag: &Path, force: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_forkbench"));
        c.args(["trial", &repo("scenarios/field-test.toml"), "--no-noise"])
            .args(["--ros2", bag.to_str().expect("utf-8")]);
        if force {
            c.arg("--force");
        }
        c.output().expect("runs")
    };
    let named = tmp("named.mcap");
    let out = run(&named, true);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("rosbag2 directory"));
    assert!(!named.exists());
    let bag = tmp("again.ros2");
    assert!(run(&bag, false).status.success());
    let first = bag_bytes(&bag);
    let out = run(&bag, false);
    assert_eq!(out.status.code(), Some(1), "exists, no --force");
    assert!(run(&bag, true).status.success());
    let counts = |b: &[u8]| -> Vec<(String, usize)> {
        messages(b).into_iter().map(|(t, m)| (t, m.len())).collect()
    };
    assert_eq!(
        counts(&bag_bytes(&bag)),
        counts(&first),
        "replaced by the same trial"
    );
    std::fs::write(bag.join("notes.txt"), "mine").expect("write");
    let out = run(&bag, true);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("notes.txt"));
    assert_eq!(
        std::fs::read_to_string(bag.join("notes.txt"))
            .ok()
            .as_deref(),
        Some("mine")
    );
}

fn detect(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .arg("detect")
        .args(args)
        .output()
        .expect("runs")
}

/// A bag that rosbags wrote (tools/rosbags_fixture.py: TiM561 scans from 2.5 to 8 m and
/// ±30°, no return as NaN in some scans and +∞ in others, legs in front of the pallet,
/// two scans with the pallet behind the truck) is read and scored against its labels.
#[test]
fn detect_reads_a_bag_rosbags_wrote_and_scores_it_against_labels() {
    let lines = tmp("fixture.jsonl");
    let out = detect(&[
        &repo("tests/data/rosbags-tim561/bag"),
        "--labels",
        &repo("tests/data/rosbags-tim561/labels.json"),
        "--out",
        lines.to_str().expect("utf-8"),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(
        (s["scans"].as_u64(), s["unusable"].as_u64()),
        (Some(14), Some(0)),
        "{s}"
    );
    let sc = &s["scores"];
    assert_eq!(sc["labelled"], 14);
    assert_eq!(sc["false_positives"], 0, "{sc}");
    assert!(sc["true_positives"].as_u64().expect("count") >= 9, "{sc}");
    assert!(
        sc["lateral_error_m"]["p95"].as_f64().expect("p95") < 0.03,
        "{sc}"
    );
    let text = std::fs::read_to_string(&lines).expect("lines");
    let rows: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    assert_eq!(rows.len(), 14);
    assert!(
        rows.iter()
            .all(|r| r["frame_id"] == "laser" && r["beams"] == 819)
    );
    // The pallet behind the truck (scans 12 and 13) is not found.
    assert!(rows[12]["found"] == false && rows[13]["found"] == false);
}

/// The scans a trial simulates, through its ROS 2 bag and `detect` in the map frame (placed
/// by the bag's /tf), give the trial's own detections.
#[test]
fn a_trials_scans_through_its_bag_and_detect_give_its_estimates() {
    let (bag, lines) = (tmp("replan.ros2"), tmp("replan.jsonl"));
    let out = Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args([
            "trial",
            &repo("scenarios/field-test.toml"),
            "--replan",
            "--seed",
            "3",
        ])
        .args(["--force", "--ros2", bag.to_str().expect("utf-8")])
        .output()
        .expect("runs");
    assert!(
        out.status.code().is_some_and(|c| c == 0 || c == 3),
        "{out:?}"
    );
    // At the trial's own threshold (its default, `detect`'s too).
    let out = detect(&[
        bag.to_str().expect("utf-8"),
        "--frame",
        "map",
        "--out",
        lines.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<serde_json::Value> = std::fs::read_to_string(&lines)
        .expect("lines")
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON"))
        .collect();
    let msgs = messages(&bag_bytes(&bag));
    let detections = &msgs["/pose/sensors/pallet_detection"];
    assert!(detections.len() >= 2, "{}", detections.len());
    for d in detections {
        let mut r = CdrReader::new(d).expect("CDR");
        let stamp = f64::from(r.i32().expect("sec")) + f64::from(r.u32().expect("ns")) * 1e-9;
        r.string().expect("frame");
        let v: Vec<f64> = (0..7).map(|_| r.f64().expect("f64")).collect();
        let heading = (2.0 * v[6] * v[5])
            .atan2(1.0 - 2.0 * v[5] * v[5])
            .to_degrees();
        let same = rows.iter().any(|row| {
            let f = &row["face"];
            row["stamp_s"]
                .as_f64()
                .is_some_and(|t| (t - stamp).abs() < 1e-6)
                && (f["x_m"].as_f64().unwrap_or(f64::NAN) - v[0]).abs() < 1e-5
                && (f["y_m"].as_f64().unwrap_or(f64::NAN) - v[1]).abs() < 1e-5
                && (f["heading_deg"].as_f64().unwrap_or(f64::NAN) - heading).abs() < 1e-3
        });
        assert!(
            same,
            "no scan at {stamp} s gives ({}, {}, {heading}°): {rows:?}",
            v[0], v[1]
        );
    }
}

/// A scan whose angle fields disagree with its range count is reported, the others read;
/// a truncated bag keeps the lines read before the cut; a file without laser scans names
/// the topics it has.
#[test]
fn detect_reports_malformed_scans_truncated_bags_and_missing_topics() {
    use forkbench_log::ros2::cdr::CdrWriter;
    let bag = tmp("malformed.mcap");
    {
        let f = std::io::BufWriter::new(std::fs::File::create(&bag).expect("file"));
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
        // A transform message cut short: reported, not skipped.
        let tf_schema = w
            .add_schema("tf2_msgs/msg/TFMessage", "ros2msg", b"")
            .expect("schema");
        let tf = w
            .add_channel(tf_schema, "/tf", "cdr", &BTreeMap::new())
            .expect("channel");
        let mut c = CdrWriter::new();
        c.u32(3);
        let tf_header = mcap::records::MessageHeader {
            channel_id: tf,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        };
        w.write_to_known_channel(&tf_header, &c.into_bytes())
            .expect("message");
        for (i, angle_max) in [1.0f32, 2.0, 1.0].iter().enumerate() {
            let mut c = CdrWriter::new();
            c.i32(i as i32);
            c.u32(0);
            c.string("laser");
            for v in [-1.0, *angle_max, 0.02, 0.0, 0.0, 0.05, 10.0] {
                c.f32(v);
            }
            c.f32_seq(&[f32::NAN; 101]);
            c.f32_seq(&[]);
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: i as u32,
                log_time: i as u64,
                publish_time: i as u64,
            };
            w.write_to_known_channel(&header, &c.into_bytes())
                .expect("message");
        }
        w.finish().expect("finish");
    }
    let lines = tmp("malformed.jsonl");
    let out = detect(&[
        bag.to_str().expect("utf-8"),
        "--out",
        lines.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("1 of 3 scans could not be used")
            && err.contains("150.0 increments, but the scan has 101 ranges"),
        "{err}"
    );
    // The summary counts the transform message that could not be decoded.
    let out = detect(&[
        bag.to_str().expect("utf-8"),
        "--out",
        lines.to_str().expect("utf-8"),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let summary: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("the summary is still printed");
    assert_eq!(summary["bad_transforms"], 1, "{summary}");
    assert_eq!(
        std::fs::read_to_string(&lines)
            .expect("lines")
            .lines()
            .count(),
        3
    );
    // The fixture cut in the middle of its data.
    let whole = std::fs::read(repo("tests/data/rosbags-tim561/bag/bag.mcap")).expect("bag");
    let cut = tmp("cut.mcap");
    std::fs::write(&cut, &whole[..whole.len() * 2 / 3]).expect("write");
    let out = detect(&[
        cut.to_str().expect("utf-8"),
        "--out",
        lines.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("not a readable MCAP file") && err.contains("after "),
        "{err}"
    );
    let kept = std::fs::read_to_string(&lines)
        .expect("lines")
        .lines()
        .count();
    assert!(kept > 0 && kept < 14, "{kept}");
    // A recording with no laser scans (a mission bag's topics are named).
    let plain = tmp("noscan.mcap");
    std::fs::write(&plain, b"not an mcap at all").expect("write");
    let out = detect(&[plain.to_str().expect("utf-8")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a readable MCAP file"));
    let fixture = repo("tests/data/rosbags-tim561/bag");
    let out = detect(&[&fixture, "--topic", "/nope"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--topic /nope: not a laser-scan topic"));
}
