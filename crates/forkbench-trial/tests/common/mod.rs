//! What the committed-outcome tests share: reading the records, finding a record's scenario and case, and re-running every record to list those that differ.

use forkbench_trial::{Case, Scenario};
use rayon::prelude::*;
use serde_json::Value;

/// One JSON record per line.
pub fn records(jsonl: &str) -> Vec<Value> {
    jsonl
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect()
}

/// A string field of a record.
pub fn text(record: &Value, field: &str) -> String {
    record[field].as_str().expect("string field").to_owned()
}

/// The scenario and case a record was run on.
#[allow(dead_code)] // the session test finds its shared scenarios itself
pub fn case_of<'a>(scenarios: &'a [Scenario], record: &Value) -> (&'a Scenario, &'a Case) {
    let name = text(record, "scenario");
    let scn = scenarios.iter().find(|x| x.name == name).expect("scenario");
    (scn, scn.case(&text(record, "case")).expect("case"))
}

/// Re-runs every record (in parallel) and fails naming how many differ and the first.
pub fn assert_reruns_equal(want: &[Value], rerun: impl Fn(&Value) -> Value + Sync) {
    let differing: Vec<String> = want
        .par_iter()
        .filter(|w| rerun(w) != **w)
        .map(|w| {
            format!(
                "{} / {} / {} / replan {} / seed {}",
                w["scenario"], w["case"], w["planner"], w["replan"], w["seed"]
            )
        })
        .collect();
    assert!(
        differing.is_empty(),
        "{} of {} trials differ, first: {:?}",
        differing.len(),
        want.len(),
        differing.first()
    );
}
