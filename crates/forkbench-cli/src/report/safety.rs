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
    let m = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.2}"));
    for r in &s.rows {
        let Some(x) = &r.safety else {
            continue;
        };
        any = true;
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.1}</td><td>{:.2}</td><td>{:.1}</td><td>{} / {}</td></tr>",
            esc(&r.scenario),
            esc(&r.planner),
            esc(&r.tracker),
            forkbench_batch::mode_name(r.replan),
            x.trials,
            x.trials_with_contact,
            x.stops_per_trial,
            x.false_trips_per_trial,
            x.stop_time_per_trial_s,
            x.slowdowns_per_trial,
            x.slowdown_time_per_trial_s,
            m(x.closest_min_m),
            m(x.closest_median_m),
        );
    }
    if any { h + "</table>" } else { String::new() }
}
