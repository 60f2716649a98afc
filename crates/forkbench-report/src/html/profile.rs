//! The report's profile section (`batch --profile`): where the trials' time went, stage by stage, for the batch and per row.

use std::fmt::Write as _;

use forkbench_batch::{self as batch, Summary};
use forkbench_core::profile::Profile;

use super::svg::esc;

/// The heading, the batch's stages and each row's largest ones (empty when the batch was
/// not profiled).
pub fn table(s: &Summary) -> String {
    let Some(total) = &s.profile else {
        return String::new();
    };
    let mut h = format!(
        "<h2>Where the time went</h2><p>{} profiled trials: {:.2} s of wall time on their \
         threads ({:.2} s of CPU), summed over the jobs. Each stage's time excludes the \
         stages inside it; an external component's time includes its process's round \
         trip.</p><table data-plot=\"profile\"><tr><th>stage</th><th>component</th>\
         <th>time (s)</th><th>share</th><th>per trial (ms)</th><th>calls</th></tr>",
        total.trials,
        total.wall_ms / 1e3,
        total.cpu_ms / 1e3
    );
    for st in &total.stages {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.1} %</td><td>{:.3}</td><td>{}</td></tr>",
            esc(&st.stage),
            esc(st.component.as_deref().unwrap_or("")),
            st.time_ms / 1e3,
            total.share_pct(st),
            st.time_ms / total.trials.max(1) as f64,
            st.calls
        );
    }
    h.push_str("</table><h3>Per row: time per trial and its three largest stages</h3><table><tr><th>scenario</th><th>planner</th><th>tracker</th><th>mode</th><th>trials</th><th>ms per trial</th><th>largest stages</th></tr>");
    for r in &s.rows {
        let Some(p) = &r.profile else { continue };
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{}</td></tr>",
            esc(&r.scenario),
            esc(&r.planner),
            esc(&r.tracker),
            batch::mode_name(r.replan),
            p.trials,
            p.wall_ms / p.trials.max(1) as f64,
            esc(&largest(p))
        );
    }
    h.push_str("</table>");
    h
}

/// "physics P %, tracking Q %, …": the three largest stages other than "other".
fn largest(p: &Profile) -> String {
    p.stages
        .iter()
        .filter(|s| s.stage != "other")
        .take(3)
        .map(|s| format!("{} {:.0} %", s.label(), p.share_pct(s)))
        .collect::<Vec<_>>()
        .join(", ")
}
