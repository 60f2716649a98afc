//! `forkbench safety-fields SCENARIO`: the protective field per speed range with each term of the scanner makers' formula, braking measured in the physics.

use std::path::PathBuf;

use anyhow::Context as _;

#[derive(Debug, clap::Args)]
pub struct SafetyFieldsArgs {
    scenario: PathBuf,
    /// Also write the sizing (settings, every term in metres) as JSON to FILE.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the JSON instead of the table.
    #[arg(long)]
    json: bool,
}

pub fn run(a: &SafetyFieldsArgs) -> anyhow::Result<()> {
    let scn = forkbench_trial::defaults::load_scenario(&a.scenario)?;
    crate::warn_slips(&scn);
    let sizing = scn.safety_fields()?;
    let json = serde_json::to_string_pretty(&sizing).context("serialising the sizing")? + "\n";
    if let Some(out) = &a.out {
        forkbench_core::files::write_atomic(out, json.as_bytes())
            .with_context(|| format!("writing {}", out.display()))?;
    }
    if a.json {
        return crate::emit(&json);
    }
    let source = if scn.safety.is_some() {
        "its [safety]"
    } else {
        "the [safety] defaults"
    };
    crate::emit(&format!(
        "{} ({source}):\n{}{}",
        scn.name,
        forkbench_safety::text(&sizing),
        forkbench_safety::drawn_text(&sizing, &scn.safety_footprint())
    ))
}
