//! The report's safety table: per row with people or safety fields, the contacts, stops, false trips, slowdowns and the time they cost.

use std::fmt::Write as _;

use forkbench_batch::Summary;

use super::svg::esc;

/// The table, or nothing when no row had people or fields.
pub fn safety_table(s: &Summary) -> String {
    let mut h = String::from(
        "<table><tr><th>scenario</th><th>planner</th><th>tracker</th><th>mode</th><th>trials</th><th>with a contact</th><th>stops per trial</th><th>false trips per trial</th><th>stopped per trial (s)</th><th>slowdowns per trial</th><th>slowed per trial (s)</th><th>closest min / median (m)</th></tr>",
    );
    let mut any = false;
    for r in &s.rows {
        let Some(x) = &r.safety else {
            continue;
        };
        any = true;
        let cells: String = x
            .cells()
            .iter()
            .map(|c| format!("<td>{}</td>", esc(c)))
            .collect();
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td>{cells}</tr>",
            esc(&r.scenario),
            esc(&r.planner),
            esc(&r.tracker),
            forkbench_batch::mode_name(r.replan),
        );
    }
    if any { h + "</table>" } else { String::new() }
}
