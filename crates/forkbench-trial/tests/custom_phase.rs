//! A phase from outside the crate: registered by name as a planner is, listed in a scenario after the built-in ones, driven by the one drive loop, judged and measured like them; refused where it is not registered.

use std::path::Path;
use std::sync::Arc;

use forkbench_trial::phase::{
    Failed, Phase, PhaseHost, PhaseKind, PhaseRun, defaults_of, open_loop, settings,
};
use forkbench_trial::{Failure, Recorder, Registry, Scenario, TrialOptions, World, run_trial};
use serde::{Deserialize, Serialize};

/// `[phase.creep]`: the loaded truck creeps forward at `speed_mps` for `time_s`, and
/// fails when it crept less than `min_distance_m`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct Creep {
    speed_mps: f64,
    time_s: f64,
    min_distance_m: f64,
}

impl Default for Creep {
    fn default() -> Self {
        Creep {
            speed_mps: 0.2,
            time_s: 3.0,
            min_distance_m: 0.05,
        }
    }
}

impl Phase for Creep {
    fn run<'t>(&'t self, t: &'t mut dyn PhaseHost, rec: &'t mut dyn Recorder) -> PhaseRun<'t> {
        Box::pin(async move {
            let on_forks = |t: &dyn PhaseHost| {
                let root = t.sim().fork_root_pose();
                root.to_local(&t.sim().pallet_pose())
            };
            let (before, start) = (on_forks(t), t.sim().fork_root_pose());
            let end_s = t.sim().time_s() + self.time_s;
            let speed = self.speed_mps;
            t.drive_under(self.time_s + 1.0, rec, &mut |t, pose| {
                Ok((t.sim().time_s() < end_s).then(|| open_loop(speed, 0.0, &pose)))
            })
            .await?;
            let crept = t.sim().fork_root_pose().distance_to(&start);
            t.record_measure("crept_m", crept);
            t.record_measure("load_shift_m", on_forks(t).distance_to(&before));
            if crept < self.min_distance_m {
                return Err::<(), Failed>(Failed::new(
                    Failure::criterion("creep_distance"),
                    format!("crept {crept:.3} m (at least {} m)", self.min_distance_m),
                ));
            }
            Ok(())
        })
    }
}

fn creep_kind() -> PhaseKind {
    PhaseKind::new(
        "creep",
        &["lift", "reverse_out"],
        (Some(true), None),
        |table, _cx| {
            let c: Creep = settings(table)?;
            if !(c.speed_mps.is_finite() && (0.0..=1.0).contains(&c.speed_mps)) {
                return Err(forkbench_core::SettingsError::field(
                    "speed_mps",
                    format!("must lie in 0–1 m/s (got {})", c.speed_mps),
                ));
            }
            Ok(Box::new(c))
        },
        defaults_of::<Creep>(),
    )
}

/// rack-pick-cycle with a creep after the reverse-out, loaded against `registry`.
fn scenario(registry: Arc<Registry>, creep: &str) -> Result<Scenario, String> {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios"));
    let text = std::fs::read_to_string(dir.join("rack-pick-cycle.toml")).expect("scenario");
    let text = text.replace(
        r#"phases = ["pick", "lift", "reverse_out"]"#,
        r#"phases = ["pick", "lift", "reverse_out", "creep"]"#,
    ) + &format!("\n[phase.creep]\n{creep}\n");
    Scenario::parse_with(&text, "creep.toml", |w| World::load(&dir.join(w)), registry)
        .map_err(|e| e.to_string())
}

fn seed(s: u64) -> TrialOptions {
    TrialOptions {
        seed: Some(s),
        ..TrialOptions::default()
    }
}

#[test]
fn a_registered_phase_runs_after_the_built_in_ones_and_is_judged() {
    let registry = Arc::new(Registry::builtin().with_phase(creep_kind()));
    let scn = scenario(registry.clone(), "time_s = 2.0").expect("loads");
    let out = run_trial(&scn, &scn.cases[0], &seed(3));
    assert!(out.success, "{}", out.verdict_line());
    let names: Vec<_> = out.phases.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["pick", "lift", "reverse_out", "creep"]);
    let creep = &out.phases[3];
    assert!(creep.loaded);
    // 2 s at up to 0.2 m/s, from standing: it moved, and less than 0.4 m.
    let crept = creep.measures["crept_m"];
    assert!(crept > 0.05 && crept < 0.4, "{crept}");
    assert!(creep.measures["load_shift_m"] < 0.05);
    assert!((creep.time_s - 2.0).abs() < 0.05, "{}", creep.time_s);

    // Its own criterion fails the cycle, named like a built-in phase's.
    let strict = scenario(registry, "time_s = 2.0\nmin_distance_m = 5.0").expect("loads");
    let out = run_trial(&strict, &strict.cases[0], &seed(3));
    assert!(!out.success);
    assert_eq!(out.failure, Some(Failure::criterion("creep_distance")));
    assert!(
        out.failure_detail
            .as_deref()
            .unwrap_or("")
            .starts_with("creep: ")
    );
}

#[test]
fn a_phase_is_refused_where_it_is_not_registered_or_its_settings_are_bad() {
    let err = scenario(Registry::shared(), "").expect_err("not registered");
    assert!(
        err.contains("creep.toml:") && err.contains("no phase \"creep\""),
        "{err}"
    );
    assert!(
        err.contains("lift, reverse_out, carry, place, return"),
        "{err}"
    );
    let registry = Arc::new(Registry::builtin().with_phase(creep_kind()));
    let err = scenario(registry.clone(), "speed_mps = 3.0").expect_err("bad setting");
    assert!(
        err.contains("phase.creep") && err.contains("speed_mps"),
        "{err}"
    );
    let err = scenario(registry, "sped_mps = 0.1").expect_err("unknown key");
    assert!(err.contains("sped_mps"), "{err}");
}

/// A record whose verdict is a registered phase's own criterion reads back as written,
/// as a batch's summary and gate read it; a name no criterion can have is refused.
#[test]
fn a_custom_criterion_in_a_record_reads_back() {
    let registry = Arc::new(Registry::builtin().with_phase(creep_kind()));
    let strict = scenario(registry, "time_s = 1.0\nmin_distance_m = 5.0").expect("loads");
    let out = run_trial(&strict, &strict.cases[0], &seed(4));
    let line = serde_json::to_string(&out).expect("serialises");
    assert!(line.contains(r#""failure":"creep_distance""#), "{line}");
    let back: forkbench_trial::TrialOutcome = serde_json::from_str(&line).expect("reads back");
    assert_eq!(back.failure, Some(Failure::criterion("creep_distance")));
    let bad = line.replace("creep_distance", "Creep Distance!");
    let err = serde_json::from_str::<forkbench_trial::TrialOutcome>(&bad).expect_err("refused");
    assert!(err.to_string().contains("unknown failure"), "{err}");
}

/// A failure's name is owned, not interned: records may carry any number of distinct
/// criterion names (a long-lived process reading many batches), each read back as itself
/// and written out again unchanged.
#[test]
fn any_number_of_criterion_names_read_back() {
    for i in 0..2_000 {
        let name = format!("site_check_{i}");
        let json = format!("\"{name}\"");
        let f: Failure = serde_json::from_str(&json).expect("a criterion name reads back");
        assert_eq!(f, Failure::criterion(name.clone()));
        assert_eq!(f.name(), name);
        assert_eq!(serde_json::to_string(&f).expect("writes"), json);
    }
    let long = "a".repeat(65);
    assert!(Failure::from_name(&long).is_none(), "a name over 64 bytes");
    assert_eq!(Failure::from_name("timeout"), Some(Failure::Timeout));
}
