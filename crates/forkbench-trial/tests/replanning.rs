//! Replanning on a better estimate never loses a pick that planning once makes: with a
//! perfect estimate, every Table 2 case of both papers that picks planning once also
//! picks replanning; and a replan keeps the path continuous where the truck is.

use forkbench_trial::trial::Overrides;
use forkbench_trial::{TrialOptions, defaults, run_trial};

#[test]
fn no_table2_case_that_picks_planning_once_fails_replanning_with_a_perfect_estimate() {
    let mut compared = 0;
    for name in ["bspline-table2", "spiral-table2"] {
        let scn = defaults::embedded_scenario(name).expect("embedded");
        for case in &scn.cases {
            for seed in [1, 2] {
                let opts = |replan| TrialOptions {
                    seed: Some(seed),
                    replan: Some(replan),
                    overrides: Overrides {
                        pallet_sensing: Some("gaussian".into()),
                        pallet_noise_scale: Some(0.0),
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let once = run_trial(&scn, case, &opts(false));
                if !once.success {
                    continue;
                }
                let again = run_trial(&scn, case, &opts(true));
                assert!(
                    again.success,
                    "{name} case {} seed {seed}: picks planning once, fails replanning: {:?} {:?}",
                    case.name, again.failure, again.failure_detail
                );
                compared += 1;
            }
        }
    }
    assert!(compared > 50, "{compared} picks compared");
}

#[test]
fn replanning_on_the_scanned_estimate_fixes_more_table2_picks_than_it_breaks() {
    for name in ["bspline-table2", "spiral-table2"] {
        let scn = defaults::embedded_scenario(name).expect("embedded");
        let (mut broke, mut fixed) = (0, 0);
        for case in &scn.cases {
            // Ten seeds a case: with the detector's faces checked, fewer pairs differ, and
            // four seeds left too few to tell.
            for seed in 1..=10 {
                let opts = |replan| TrialOptions {
                    seed: Some(seed),
                    replan: Some(replan),
                    ..Default::default()
                };
                let once = run_trial(&scn, case, &opts(false)).success;
                let again = run_trial(&scn, case, &opts(true)).success;
                broke += usize::from(once && !again);
                fixed += usize::from(again && !once);
            }
        }
        assert!(
            fixed >= broke,
            "{name}: replanning broke {broke}, fixed {fixed}"
        );
    }
}
