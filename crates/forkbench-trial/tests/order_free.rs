//! The layout of a file never changes an outcome: a world's reflectors and a custom pallet's blocks listed in another order give the same trials, to the bit.

use std::path::Path;

use forkbench_trial::{Scenario, TrialOptions, World, run_trial};

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// `text` with the tables headed `header` (each from its header line to the next table)
/// in reverse order, every other line where it was.
fn reverse_tables(text: &str, header: &str) -> String {
    let mut chunks: Vec<Vec<&str>> = vec![Vec::new()];
    for line in text.lines() {
        if line.trim_start().starts_with('[') {
            chunks.push(Vec::new());
        }
        chunks.last_mut().expect("a chunk").push(line);
    }
    let is_ours = |c: &Vec<&str>| c.first().is_some_and(|l| l.trim() == header);
    let mut ours: Vec<Vec<&str>> = chunks.iter().filter(|c| is_ours(c)).cloned().collect();
    assert!(ours.len() > 2, "{header}: too few tables to reorder");
    let mut out = Vec::new();
    for c in &chunks {
        let c = if is_ours(c) {
            ours.pop().expect("one each")
        } else {
            c.clone()
        };
        out.extend(c);
    }
    out.join("\n") + "\n"
}

/// The block lines of an inline `block = [ … ]` array in reverse order.
fn reverse_blocks(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let start = lines
        .iter()
        .position(|l| l.starts_with("block = ["))
        .expect("block")
        + 1;
    let end = start
        + lines[start..]
            .iter()
            .position(|l| l.starts_with(']'))
            .expect("]");
    let mut out: Vec<&str> = lines[..start].to_vec();
    out.extend(lines[start..end].iter().rev());
    out.extend(&lines[end..]);
    out.join("\n") + "\n"
}

/// `v` without the wall-clock timings, which no two runs share.
fn untimed(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            m.retain(|k, _| !(k.ends_with("time_ms") || k == "planning_time_s"));
            m.values_mut().for_each(untimed);
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(untimed),
        _ => {}
    }
}

/// How many of two runs' outcomes differ (beyond wall-clock timings).
fn differing(a: &[serde_json::Value], b: &[serde_json::Value]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// The outcomes of seeds 1..=n as JSON without timings, each with its seed.
fn outcomes(scn: &Scenario, n: u64) -> Vec<serde_json::Value> {
    use rayon::prelude::*;
    (1..=n)
        .into_par_iter()
        .map(|seed| {
            let opts = TrialOptions {
                seed: Some(seed),
                ..TrialOptions::default()
            };
            let mut v = serde_json::to_value(run_trial(scn, &scn.cases[0], &opts)).expect("json");
            untimed(&mut v);
            v
        })
        .collect()
}

#[test]
fn reversed_reflectors_give_the_same_rack_picks() {
    let file = root().join("scenarios/rack-pick.toml");
    let text = std::fs::read_to_string(&file).expect("scenario");
    let world = std::fs::read_to_string(root().join("worlds/rack-bay.toml")).expect("world");
    let reversed = reverse_tables(&world, "[[reflector]]");
    assert_ne!(world, reversed);
    let load = |w: &str| {
        Scenario::parse(&text, "rack-pick.toml", |_| {
            World::parse(w, "rack-bay.toml")
        })
        .expect("loads")
    };
    assert_eq!(
        differing(
            &outcomes(&load(&world), 12),
            &outcomes(&load(&reversed), 12)
        ),
        0
    );
}

#[test]
fn reversed_pallet_blocks_give_the_same_picks() {
    let file = root().join("scenarios/pallets/dusseldorf-custom.toml");
    let text = std::fs::read_to_string(&file).expect("scenario");
    let reversed = reverse_blocks(&text);
    assert_ne!(text, reversed);
    let dir = file.parent().expect("folder").to_owned();
    let load = |t: &str| {
        Scenario::parse(t, "dusseldorf-custom.toml", |w| World::load(&dir.join(w))).expect("loads")
    };
    assert_eq!(
        differing(&outcomes(&load(&text), 12), &outcomes(&load(&reversed), 12)),
        0
    );
}
