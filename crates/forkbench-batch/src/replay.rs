//! One trial to re-run from its record: the JSON line read, its scenario found, the outcome judged against it.

use std::path::Path;

use forkbench_trial::{Case, Scenario, TrialOptions, TrialOutcome, defaults};

use crate::manifest::ScenarioEntry;
use crate::{BatchError, Manifest, TrialRecord};

/// A recorded trial and the scenario it came from, ready to run again.
#[derive(Debug)]
pub struct Replay {
    pub record: TrialRecord,
    pub scenario: Scenario,
}

impl Replay {
    /// Reads line `line` (1-based) of `file` and finds its scenario ([`Replay::find`]).
    pub fn load(file: &Path, line: usize, scenario: Option<&Path>) -> Result<Self, BatchError> {
        let record = Self::read_record(file, line)?;
        let scenario = scenario.map(Scenario::load).transpose()?;
        Self::find(record, scenario, Some(file))
    }

    /// The trial record on line `line` (1-based) of `file`.
    pub fn read_record(file: &Path, line: usize) -> Result<TrialRecord, BatchError> {
        if line == 0 {
            return Err(BatchError::Setting(
                "line 0: lines are numbered from 1".into(),
            ));
        }
        let text = crate::read_regular(file, crate::MAX_RECORDS_BYTES)?;
        let Some(raw) = text.lines().nth(line - 1) else {
            return Err(BatchError::Setting(format!(
                "{}: has no line {line}",
                file.display()
            )));
        };
        serde_json::from_str(raw).map_err(|e| BatchError::Record {
            path: file.display().to_string(),
            line,
            message: format!("not a trial record: {e}"),
        })
    }

    /// A record and its scenario: `scenario` when given, else the file the batch's
    /// manifest beside `records` names for it, else the embedded scenario of that name.
    pub fn find(
        record: TrialRecord,
        scenario: Option<Scenario>,
        records: Option<&Path>,
    ) -> Result<Self, BatchError> {
        let name = &record.outcome.scenario;
        let scenarios = match (scenario, records) {
            (Some(s), _) => vec![s],
            (None, Some(file)) => candidates(file, name)?,
            (None, None) => defaults::default_scenarios()?,
        };
        let where_ = records.map_or_else(String::new, |f| {
            format!(" or in a manifest.json beside {}", f.display())
        });
        let scenario = scenarios
            .into_iter()
            .find(|s| &s.name == name)
            .ok_or_else(|| {
                BatchError::Setting(format!(
                    "no scenario named {name:?} among the embedded ones{where_}; pass its \
                     file with --scenario"
                ))
            })?;
        Ok(Self { record, scenario })
    }

    /// The recorded trial's case.
    pub fn case(&self) -> Result<&Case, BatchError> {
        Ok(self.scenario.case(&self.record.outcome.case)?)
    }

    /// The recorded trial's options (its seed, components, mode and knobs).
    pub fn options(&self) -> TrialOptions {
        self.record.options()
    }

    /// Whether `outcome` is the recorded one: wall-clock times (the trial's and each
    /// leg's planning) are all a rerun may change.
    pub fn reproduces(&self, outcome: &TrialOutcome) -> bool {
        let value = |o: &TrialOutcome| serde_json::to_value(o.without_wall_times()).ok();
        let now = value(outcome);
        now.is_some() && now == value(&self.record.outcome)
    }
}

/// The scenarios a record may come from: the file the batch's manifest (beside the
/// records) names for it, else the embedded defaults.
fn candidates(records: &Path, name: &str) -> Result<Vec<Scenario>, BatchError> {
    let dir = records.parent().unwrap_or(Path::new("."));
    let embedded = defaults::default_scenarios()?;
    let entry = Manifest::read(dir)
        .ok()
        .flatten()
        .and_then(|m| m.scenarios.into_iter().find(|s| s.name == name));
    let Some(entry) = entry else {
        return Ok(embedded);
    };
    if embedded
        .iter()
        .any(|s| s.name == name && s.file == entry.file)
    {
        return Ok(embedded);
    }
    let file = Path::new(&entry.file);
    let named = |why: &str| {
        BatchError::Setting(format!(
            "{}'s manifest names {} for scenario {name:?}, {why}; pass its file with --scenario",
            dir.display(),
            forkbench_trial::text::visible(&entry.file)
        ))
    };
    // A manifest is a file anyone may have handed over: a path outside the batch's
    // directory is used only when it holds the very scenario the batch ran, and what
    // it holds otherwise is never quoted (nor its components run).
    let inside = match (file.canonicalize(), dir.canonicalize()) {
        (Ok(f), Ok(d)) => f.starts_with(d),
        _ => false,
    };
    match Scenario::load(file) {
        Err(e) if inside => Err(named(&format!("which does not load: {e}"))),
        Err(_) => Err(named(
            "outside the batch's directory, which does not load as a scenario",
        )),
        Ok(scn) if inside => Ok(vec![scn]),
        Ok(scn) if ScenarioEntry::of(&scn)?.settings_hash == entry.settings_hash => Ok(vec![scn]),
        Ok(_) => Err(named(
            "outside the batch's directory, whose settings are not the ones the batch ran",
        )),
    }
}
