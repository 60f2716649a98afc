//! The spiral planner's cost against an independent optimiser (scipy SLSQP over all five coefficients and the length, `tools/spiral_reference.py`): within 1 % on every goal the reference solves, in the paper's window and the wide one.

use crate::common::reference;
use forkbench_core::ForkliftSpec;
use forkbench_plan::spiral::{self, SpiralConfig, SpiralProblem, window_bound};

#[test]
fn reference_solves_the_same_problem() {
    let r = reference();
    assert!((r.kappa_max_per_m - ForkliftSpec::default().max_curvature_per_m()).abs() < 1e-12);
    for g in &r.goals {
        let prob = SpiralProblem::from_request(&g.request(), 0.0);
        let (lo, hi) = prob.length_window(g.length_window);
        assert!(
            (lo - g.window[0]).abs() < 1e-12 && (hi - g.window[1]).abs() < 1e-12,
            "{}: window",
            g.name
        );
    }
}

#[test]
fn cost_is_within_one_percent_of_the_independent_optimum() {
    let r = reference();
    let (mut checked, mut cheaper, mut refused_unsolved) = (0, 0, 0);
    let mut at = [0usize; 3]; // reference optimum at the short end, inside, at the long end
    let mut worst = (0.0f64, String::new());
    let mut failures = Vec::new();
    for g in &r.goals {
        let cfg = SpiralConfig {
            enforce_length_window: g.length_window,
            ..SpiralConfig::default()
        };
        let req = g.request();
        let res = spiral::plan(&req, &cfg);
        let Some(ref_cost) = g.cost else {
            // The reference found nothing: a plan we do return must still be feasible.
            match res {
                Ok(p) => {
                    let m = p.path.metrics(&req.start, &req.goal, &req.truck);
                    assert!(m.endpoint_position_error_m < 1e-6, "{}", g.name);
                    assert!(m.max_abs_curvature_per_m <= r.kappa_max_per_m * (1.0 + 1e-9));
                }
                Err(_) => refused_unsolved += 1,
            }
            continue;
        };
        let sf_ref = g.sf.expect("sf with cost");
        at[match window_bound(sf_ref, (g.window[0], g.window[1])) {
            Some("short end") => 0,
            Some(_) => 2,
            None => 1,
        }] += 1;
        let p = match res {
            Ok(p) => p,
            Err(e) => {
                failures.push(format!(
                    "{} (window {}): the reference found J {ref_cost:.5} at s_f {sf_ref:.4}, we refused: {e}",
                    g.name, g.length_window
                ));
                continue;
            }
        };
        let excess = p.cost / ref_cost - 1.0;
        if excess > worst.0 {
            worst = (excess, g.name.clone());
        }
        if excess > 0.01 {
            failures.push(format!(
                "{} (window {}): J {:.5} at s_f {:.4} vs reference {ref_cost:.5} at s_f {sf_ref:.4}",
                g.name, g.length_window, p.cost, p.params.sf
            ));
        }
        cheaper += usize::from(excess < -1e-3);
        checked += 1;
    }
    eprintln!(
        "{checked} goals checked; worst excess {:+.4} % ({}); {cheaper} cheaper than the reference by > 0.1 %; \
         reference optimum at short end / inside / long end: {at:?}; {refused_unsolved} refused where the reference found nothing",
        100.0 * worst.0,
        worst.1
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The set must exercise optima at both bounds and inside the window.
    assert!(at.iter().all(|&n| n >= 10), "{at:?}");
    assert!(checked >= 300, "{checked}");
}
