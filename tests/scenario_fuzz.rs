//! Mutated scenario files (huge, tiny, negative, non-finite numbers; dropped keys; wrong types) never abort, hang or exhaust memory: exit 0, 1 or 3 with a message.

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
    let t0 = Instant::now();
    let child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 2097152; exec timeout -s KILL {} '{}' trial '{}' 2>&1",
            limit.as_secs(),
            env!("CARGO_BIN_EXE_forkbench"),
            file.display()
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
