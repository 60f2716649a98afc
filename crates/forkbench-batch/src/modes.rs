//! Which replanning modes a batch runs, and the default choice: the one policy the CLI and any other front end apply.

use serde::{Deserialize, Serialize};

/// The replanning modes of a batch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReplanModes {
    /// Each scenario's own `[replan] enabled`.
    Scenario,
    /// Every job replans.
    Replan,
    /// Every job twice, planning once and replanning, on the same seeds.
    Both,
}

impl ReplanModes {
    /// Forcing replanning wins; else the modes asked for; else both modes for the
    /// embedded default scenarios (the papers' mode beside replanning, as the README's
    /// main job reports) and each scenario's own setting for scenario files.
    pub fn choose(force_replan: bool, asked: Option<Self>, embedded_defaults: bool) -> Self {
        match (force_replan, asked) {
            (true, _) => Self::Replan,
            (false, Some(m)) => m,
            (false, None) if embedded_defaults => Self::Both,
            (false, None) => Self::Scenario,
        }
    }

    /// The batch spec's `replan` override and `compare_replanning` for these modes.
    pub fn spec_fields(self) -> (Option<bool>, bool) {
        ((self == Self::Replan).then_some(true), self == Self::Both)
    }
}

impl std::str::FromStr for ReplanModes {
    type Err = forkbench_core::UnknownChoice;

    /// `scenario`, `replan` or `both`; the error quotes the text and names the three.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        match text {
            "scenario" => Ok(Self::Scenario),
            "replan" => Ok(Self::Replan),
            "both" => Ok(Self::Both),
            other => Err(forkbench_core::UnknownChoice::new(
                other,
                "expected \"scenario\", \"replan\" or \"both\"",
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_policy() {
        use ReplanModes::*;
        assert_eq!(ReplanModes::choose(true, Some(Both), true), Replan);
        assert_eq!(ReplanModes::choose(false, Some(Scenario), true), Scenario);
        assert_eq!(ReplanModes::choose(false, None, true), Both);
        assert_eq!(ReplanModes::choose(false, None, false), Scenario);
        assert_eq!(Both.spec_fields(), (None, true));
        assert_eq!(Replan.spec_fields(), (Some(true), false));
        assert_eq!("both".parse::<ReplanModes>(), Ok(Both));
        assert!("Both".parse::<ReplanModes>().is_err());
    }
}
