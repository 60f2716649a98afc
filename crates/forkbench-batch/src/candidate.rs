//! A candidate gated against what you ship: its component's name mapped onto the baseline's (`regress --as mypp=pure_pursuit`), so its trials pair with the shipped component's at the same seeds.

use std::collections::BTreeSet;

use crate::{BatchError, TrialRecord};

/// One mapping, `CANDIDATE=SHIPPED`: the results' planner or tracker `from` is compared
/// as the baseline's `to`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mapping {
    pub from: String,
    pub to: String,
}

impl std::str::FromStr for Mapping {
    type Err = forkbench_core::UnknownChoice;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.split_once('=') {
            Some((from, to)) if !from.trim().is_empty() && !to.trim().is_empty() => Ok(Self {
                from: from.trim().to_owned(),
                to: to.trim().to_owned(),
            }),
            _ => Err(forkbench_core::UnknownChoice::new(
                s,
                "give CANDIDATE=SHIPPED (e.g. mypp=pure_pursuit)",
            )),
        }
    }
}

/// The records with each mapped planner and tracker renamed. Refused: a name the results
/// do not have, a target the baseline (its planners and trackers, `shipped`) does not
/// have (a typo would read as every row missing), a name mapped twice, or a target the
/// results already run (two components would merge into one row).
pub fn map_components(
    records: &[TrialRecord],
    mappings: &[Mapping],
    shipped: &BTreeSet<&str>,
) -> Result<Vec<TrialRecord>, BatchError> {
    let names: BTreeSet<&str> = records
        .iter()
        .flat_map(|r| [r.outcome.planner.as_str(), r.outcome.tracker.as_str()])
        .collect();
    let mut seen = BTreeSet::new();
    let mut onto: std::collections::BTreeMap<&str, &str> = Default::default();
    for m in mappings {
        let refuse = |why: String| {
            Err(BatchError::Setting(format!(
                "--as {}={}: {why}",
                m.from, m.to
            )))
        };
        for (name, set, whose) in [
            (&m.from, &names, "the results (they have"),
            (&m.to, shipped, "the baseline (it has"),
        ] {
            if !set.contains(name.as_str()) {
                let known: Vec<&str> = set.iter().copied().collect();
                return refuse(format!(
                    "no planner or tracker named {name:?} in {whose}: {})",
                    known.join(", ")
                ));
            }
        }
        if !seen.insert(m.from.as_str()) {
            return refuse(format!("{:?} is mapped twice", m.from));
        }
        if let Some(first) = onto.insert(m.to.as_str(), m.from.as_str()) {
            return refuse(format!(
                "{first:?} is mapped onto {:?} too: two candidates' trials would merge into one row",
                m.to
            ));
        }
        if names.contains(m.to.as_str()) && m.to != m.from {
            return refuse(format!(
                "the results also run {:?}: mapping onto it would merge two components' trials",
                m.to
            ));
        }
    }
    let rename = |name: &str| {
        mappings
            .iter()
            .find(|m| m.from == name)
            .map_or_else(|| name.to_owned(), |m| m.to.clone())
    };
    Ok(records
        .iter()
        .map(|r| {
            let mut r = r.clone();
            r.outcome.planner = rename(&r.outcome.planner);
            r.outcome.tracker = rename(&r.outcome.tracker);
            r
        })
        .collect())
}
