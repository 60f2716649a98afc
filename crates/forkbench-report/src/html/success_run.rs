//! The report's success-run section: per row the reliability its trials demonstrate at the stated confidence, and the clean trials that would show the target.

use std::fmt::Write as _;

use forkbench_batch::{self as batch, Summary};

use super::svg::esc;

/// The heading and table (empty when no row has the figures: a summary from before).
pub fn table(s: &Summary) -> String {
    let Some(first) = s.rows.iter().find_map(|r| r.success_run) else {
        return String::new();
    };
    let mut h = format!(
        "<h2>Success run (ASTM F3499 style)</h2><p>The reliability each row demonstrates at \
         {:.0} % confidence (the one-sided Clopper–Pearson lower bound of its success rate), \
         and how many more trials, all successes, would show R {}. {} successes in a row \
         with no failure show it.</p><table><tr><th>scenario</th><th>planner</th>\
         <th>tracker</th><th>mode</th><th>successes</th><th>R demonstrated</th>\
         <th>more clean trials for R {}</th></tr>",
        100.0 * first.confidence,
        first.target,
        first.success_run_for_target,
        first.target
    );
    for r in &s.rows {
        let Some(run) = r.success_run else { continue };
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{} of {}</td><td>{:.4}</td><td>{}</td></tr>",
            esc(&r.scenario),
            esc(&r.planner),
            esc(&r.tracker),
            batch::mode_name(r.replan),
            r.successes,
            r.trials,
            run.demonstrated,
            run.more_clean_trials
                .map_or("over a million".to_owned(), |m| m.to_string())
        );
    }
    h + "</table>"
}
