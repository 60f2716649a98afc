//! Mutated scenario files (huge, tiny, negative, non-finite numbers; dropped keys; wrong types), mutated map files (YAML and PGM) and corrupted external-planner answers never abort, hang or exhaust memory: exit 0, 1 or 3 with a message.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// Values a mutation writes over a number.
const NUMBERS: [&str; 14] = [
    "0",
    "-1",
    "1e-9",
    "1e9",
    "1e300",
    "-1e300",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "0.5",
    "123456789012",
    "-0.0",
    "2.5e-5",
];

/// A small deterministic generator (SplitMix64): the campaign is reproducible.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every numeric leaf of a TOML document, as a path of keys and indices.
fn number_paths(v: &toml::Value, path: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        toml::Value::Integer(_) | toml::Value::Float(_) => out.push(path.clone()),
        toml::Value::Table(t) => {
            for (k, x) in t {
                path.push(k.clone());
                number_paths(x, path, out);
                path.pop();
            }
        }
        toml::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                path.push(i.to_string());
                number_paths(x, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

fn leaf<'a>(v: &'a mut toml::Value, path: &[String]) -> &'a mut toml::Value {
    path.iter().fold(v, |v, k| match v {
        toml::Value::Table(t) => t.get_mut(k).expect("key"),
        toml::Value::Array(a) => &mut a[k.parse::<usize>().expect("index")],
        _ => unreachable!("paths lead through tables and arrays"),
    })
}

/// One mutated copy of a shipped scenario, as TOML text.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut doc: toml::Value = toml::from_str(text).expect("shipped scenario parses");
    if let Some(w) = doc.get("world").and_then(|w| w.as_str()) {
        // Resolve the world from the shipped file's folder, wherever the copy is.
        let abs = repo_root().join("scenarios").join(w);
        doc.as_table_mut()
            .expect("table")
            .insert("world".into(), abs.display().to_string().into());
    }
    for _ in 0..1 + rng.below(3) {
        // Earlier mutations may have dropped or retyped leaves: list them afresh.
        let mut paths = Vec::new();
        number_paths(&doc, &mut Vec::new(), &mut paths);
        if paths.is_empty() {
            break;
        }
        let p = &paths[rng.below(paths.len())];
        let replacement = NUMBERS[rng.below(NUMBERS.len())];
        match rng.below(10) {
            // Mostly numbers; sometimes a wrong type or a dropped key.
            0 => *leaf(&mut doc, p) = toml::Value::String("x".into()),
            1 if p.len() > 1 => {
                let (last, parent) = p.split_last().expect("non-empty");
                if let toml::Value::Table(t) = leaf(&mut doc, parent) {
                    t.remove(last);
                }
            }
            _ => {
                let num: toml::Value = toml::from_str::<toml::Table>(&format!("v = {replacement}"))
                    .expect("valid number")
                    .remove("v")
                    .expect("v");
                *leaf(&mut doc, p) = num;
            }
        }
    }
    toml::to_string(&doc).expect("serialises")
}

/// Runs the binary on a file under a 2 GiB address-space limit and a wall-clock limit.
fn run_limited(file: &Path, limit: Duration) -> (Option<i32>, String, Duration) {
    run_args_limited(&format!("trial '{}'", file.display()), limit)
}

/// Runs the binary with `args` (shell words) under the same limits.
fn run_args_limited(args: &str, limit: Duration) -> (Option<i32>, String, Duration) {
    let t0 = Instant::now();
    let child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 2097152; exec timeout -s KILL {} '{}' {args} 2>&1",
            limit.as_secs(),
            env!("CARGO_BIN_EXE_forkbench"),
        ))
        .output()
        .expect("sh runs");
    (
        child.status.code(),
        String::from_utf8_lossy(&child.stdout).into_owned(),
        t0.elapsed(),
    )
}

#[test]
fn mutated_scenarios_exit_cleanly_within_bounds() {
    let cases: usize = std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(48);
    let seed: u64 = std::env::var("FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(21);
    let sources: Vec<String> = ["field-test.toml", "rack-pick.toml"]
        .iter()
        .map(|f| std::fs::read_to_string(repo_root().join("scenarios").join(f)).expect("readable"))
        .collect();
    let dir = std::env::temp_dir().join(format!("forkbench-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let mut rng = Rng(seed);
    let mut codes = [0usize; 4];
    for i in 0..cases {
        let text = mutate(&sources[i % sources.len()], &mut rng);
        let file = dir.join(format!("case-{i}.toml"));
        std::fs::write(&file, &text).expect("write");
        let (code, output, took) = run_limited(&file, Duration::from_secs(60));
        let ok = matches!(code, Some(0 | 1 | 3));
        assert!(
            ok && !output.contains("panicked") && took < Duration::from_secs(60),
            "case {i} (seed {seed}): exit {code:?} after {took:?}\n{output}\n--- file ---\n{text}"
        );
        if code == Some(1) {
            assert!(
                output.contains("error:"),
                "case {i}: exit 1 without a message\n{output}"
            );
        }
        codes[code.map_or(0, |c| c as usize).min(3)] += 1;
    }
    eprintln!(
        "{cases} mutated scenarios (seed {seed}): exit 0 {}, exit 1 {}, exit 3 {}",
        codes[0], codes[1], codes[3]
    );
}

fn fuzz_settings(default_cases: usize) -> (usize, u64) {
    let cases = std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default_cases);
    let seed = std::env::var("FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(21);
    (cases, seed)
}

fn assert_clean(
    what: &str,
    (code, output, took): (Option<i32>, String, Duration),
    limit: Duration,
) {
    assert!(
        matches!(code, Some(0 | 1 | 3)) && !output.contains("panicked") && took < limit,
        "{what}: exit {code:?} after {took:?}\n{output}"
    );
    if code == Some(1) {
        assert!(
            output.contains("error:"),
            "{what}: exit 1 without a message\n{output}"
        );
    }
}

/// A map_server map's YAML and PGM, mutated: numbers, truncation, header tokens, bytes.
fn mutate_map(yaml: &str, pgm: &[u8], rng: &mut Rng) -> (String, Vec<u8>) {
    let mut yaml = yaml.to_owned();
    let mut pgm = pgm.to_vec();
    match rng.below(5) {
        0 => {
            let keys = [
                "resolution: ",
                "occupied_thresh: ",
                "free_thresh: ",
                "negate: ",
            ];
            let k = keys[rng.below(keys.len())];
            let v = NUMBERS[rng.below(NUMBERS.len())];
            yaml = yaml
                .lines()
                .map(|l| {
                    if l.starts_with(k) {
                        format!("{k}{v}")
                    } else {
                        l.to_owned()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n");
        }
        1 => {
            let v = NUMBERS[rng.below(NUMBERS.len())];
            yaml = yaml
                .lines()
                .map(|l| {
                    if l.starts_with("origin:") {
                        format!("origin: [{v}, {v}, 0]")
                    } else {
                        l.to_owned()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n");
        }
        2 => pgm.truncate(rng.below(pgm.len().max(1))),
        3 => {
            let text = String::from_utf8_lossy(&pgm[..pgm.len().min(40)]).into_owned();
            let header_end = text.find("\n255").map_or(20, |i| i + 4);
            let dims = ["0 0", "99999999 99999999", "-3 7", "x y", "65536 65536"][rng.below(5)];
            let mut out = format!("P5\n{dims}\n255").into_bytes();
            out.extend_from_slice(&pgm[header_end.min(pgm.len())..]);
            pgm = out;
        }
        _ => {
            for _ in 0..1 + rng.below(50) {
                let i = rng.below(pgm.len().max(1));
                if let Some(b) = pgm.get_mut(i) {
                    *b = rng.next() as u8;
                }
            }
        }
    }
    (yaml, pgm)
}

#[test]
fn mutated_maps_exit_cleanly_within_bounds() {
    let (cases, seed) = fuzz_settings(16);
    let dir = std::env::temp_dir().join(format!("forkbench-fuzz-maps-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let world = repo_root().join("worlds/rack-bay.toml");
    let args = format!("map '{}' --out '{}'", world.display(), dir.display());
    assert_clean(
        "writing the map",
        run_args_limited(&args, Duration::from_secs(60)),
        Duration::from_secs(60),
    );
    let yaml = std::fs::read_to_string(dir.join("rack-bay.yaml")).expect("yaml");
    let pgm = std::fs::read(dir.join("rack-bay.pgm")).expect("pgm");
    let mut rng = Rng(seed);
    for i in 0..cases {
        let (y, p) = mutate_map(&yaml, &pgm, &mut rng);
        let case = dir.join(format!("case-{i}"));
        std::fs::create_dir_all(&case).expect("dir");
        std::fs::write(case.join("rack-bay.yaml"), &y).expect("write");
        std::fs::write(case.join("rack-bay.pgm"), &p).expect("write");
        let args = format!(
            "plan prm --map '{}' --start -4,9.3,0 --goal 4,9.3,0 --nodes 200",
            case.join("rack-bay.yaml").display()
        );
        let limit = Duration::from_secs(60);
        assert_clean(
            &format!("map case {i} (seed {seed})"),
            run_args_limited(&args, limit),
            limit,
        );
    }
}

#[test]
fn corrupted_planner_answers_exit_cleanly_within_bounds() {
    let (cases, seed) = fuzz_settings(16);
    let dir = std::env::temp_dir().join(format!("forkbench-fuzz-planner-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let script = repo_root().join("tests/fuzz_planner.py");
    for i in 0..cases {
        let file = dir.join(format!("case-{i}.toml"));
        let text = format!(
            "name = \"fuzz\"\nstart = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\npallet = {{ x_m = 8.0, y_m = 0.0, heading_deg = 0.0 }}\n[planner]\nkind = \"external\"\ncommand = [\"python3\", {:?}, \"{}\"]\ntimeout_s = 5.0\n",
            script.display().to_string(),
            seed.wrapping_mul(1000).wrapping_add(i as u64)
        );
        std::fs::write(&file, text).expect("write");
        let limit = Duration::from_secs(60);
        let r = run_limited(&file, limit);
        assert!(
            !r.1.contains('\u{1b}'),
            "case {i}: a raw escape reached the terminal\n{}",
            r.1
        );
        assert_clean(&format!("planner case {i} (seed {seed})"), r, limit);
    }
}
