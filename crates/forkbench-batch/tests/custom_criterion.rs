//! A step criterion written outside the crates and registered with `Registry::with_step_criterion`: every pick on that registry measures and judges it, and the CSV gains its column.

use std::path::Path;
use std::sync::Arc;

use forkbench_batch::TrialRecord;
use forkbench_trial::trial::{StepCriterion, StepView};
use forkbench_trial::{Failure, Registry, Scenario, TrialOptions, run_trial};

/// How far the fork root travels during the pick, against a limit of 1 m (every pick of
/// the field test drives further, so it always breaks).
#[derive(Debug, Default)]
struct PickTravel {
    last: Option<[f64; 2]>,
    travelled_m: Option<f64>,
}

fn pick_travel() -> Box<dyn StepCriterion> {
    Box::new(PickTravel::default())
}

impl StepCriterion for PickTravel {
    fn name(&self) -> &'static str {
        "pick_travel"
    }
    fn measure(&self) -> Option<&'static str> {
        Some("pick_travel_m")
    }
    fn describe(&self) -> &'static str {
        "how far the fork root travels during the pick"
    }
    fn observe(&mut self, v: &StepView<'_>) {
        let here = [v.fork_root.x_m, v.fork_root.y_m];
        let step = self
            .last
            .map_or(0.0, |p| (here[0] - p[0]).hypot(here[1] - p[1]));
        self.travelled_m = Some(self.travelled_m.unwrap_or(0.0) + step);
        self.last = Some(here);
    }
    fn value(&self) -> Option<f64> {
        self.travelled_m
    }
    fn broken(&self) -> Option<String> {
        self.travelled_m
            .filter(|m| *m > 1.0)
            .map(|m| format!("the forks travelled {m:.2} m (limit 1 m)"))
    }
    fn irreversible(&self) -> bool {
        false
    }
}

fn field_test(registry: Arc<Registry>) -> Scenario {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml");
    Scenario::load_with(&file, registry).expect("field test loads")
}

#[test]
fn a_registered_step_criterion_is_measured_judged_and_exported() {
    let opts = TrialOptions {
        seed: Some(3),
        no_noise: true,
        ..TrialOptions::default()
    };
    let plain = field_test(Registry::shared());
    let before = run_trial(&plain, &plain.cases[0], &opts);
    assert!(before.success, "{}", before.verdict_line());
    assert!(!before.measures.contains_key("pick_travel_m"));

    let registry = Arc::new(Registry::builtin().with_step_criterion(pick_travel));
    let scn = field_test(registry);
    let out = run_trial(&scn, &scn.cases[0], &opts);
    let travelled = out.measures["pick_travel_m"];
    assert!(travelled > 1.0, "{travelled}");
    // The built-in criterion still measures, and the new one is judged after it.
    assert!(out.measures.contains_key("fork_tip_clearance_mm"));
    assert!(!out.success);
    assert_eq!(out.failure, Some(Failure::criterion("pick_travel")));
    let detail = out.failure_detail.clone().unwrap_or_default();
    assert!(detail.contains("the forks travelled"), "{detail}");
    // Everything else is the trial without it: the criterion only observes.
    assert_eq!(out.sim_time_s, before.sim_time_s);
    assert_eq!(out.lateral_error_m, before.lateral_error_m);

    let record = TrialRecord {
        trial: 0,
        overrides: Default::default(),
        replan: Some(false),
        outcome: out,
    };
    let dir = std::env::temp_dir().join(format!("forkbench-criterion-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let csv_file = dir.join("trials.csv");
    forkbench_batch::write_csv(&[record], &csv_file).expect("csv");
    let csv = std::fs::read_to_string(&csv_file).expect("csv");
    let header = csv.lines().next().unwrap_or("");
    assert!(
        header.ends_with("fork_tip_clearance_mm,pick_travel_m"),
        "{header}"
    );
}
