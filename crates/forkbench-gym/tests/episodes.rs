//! An environment's setup refuses what it cannot run, and an episode stepped by the scenario's own tracker is the trial the bench runs at that seed, with its reward shaped as documented.

use std::path::Path;
use std::sync::Arc;

use forkbench_gym::{Core, EnvSpec, GymError, Setup, obs};
use forkbench_trial::trial::Control;
use forkbench_trial::{Scenario, TrialOptions, run_trial};

fn field_test() -> Arc<Scenario> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml");
    Arc::new(Scenario::load(&file).expect("the field test loads"))
}

/// Runs an episode under the scenario's tracker to its end: the summed reward and the core.
fn tracker_episode(setup: &Setup, seed: u64) -> (f64, Core, Vec<f32>) {
    let case = setup.scn.cases[0].name.clone();
    let mut core = Core::start(setup, seed, &case).expect("starts");
    let mut total = 0.0;
    let mut steps = 0;
    while !core.ended() {
        let out = core.step(setup, Control::Tracker);
        total += out.reward;
        steps += 1;
        assert!(steps < 100_000, "the episode never ended");
        if out.terminated || out.truncated {
            assert!(core.ended());
        }
    }
    let mut o = vec![0.0f32; setup.obs.size()];
    core.write_obs(setup, &mut o);
    (total, core, o)
}

#[test]
fn a_setup_refuses_what_it_cannot_run() {
    let scn = field_test();
    let setting = |spec: EnvSpec, want: &str| match Setup::new(scn.clone(), spec) {
        Err(GymError::Setting(why)) => assert!(why.contains(want), "{why}"),
        other => panic!("{want}: {other:?}"),
    };
    setting(
        EnvSpec {
            ticks_per_step: 0,
            ..EnvSpec::default()
        },
        "ticks_per_step",
    );
    setting(
        EnvSpec {
            path_points: 1001,
            ..EnvSpec::default()
        },
        "path_points 1001",
    );
    setting(
        EnvSpec {
            episode: "walk".into(),
            ..EnvSpec::default()
        },
        "\"walk\"",
    );
    setting(
        EnvSpec {
            phase_reward: Some(1.0),
            ..EnvSpec::default()
        },
        "needs episode=\"cycle\"",
    );
    setting(
        EnvSpec {
            reward: (f64::NAN, 1.0, 1.0, 1.0),
            ..EnvSpec::default()
        },
        "finite",
    );
    setting(
        EnvSpec {
            render_size: Some((8, 8)),
            ..EnvSpec::default()
        },
        "render_size (8, 8)",
    );
    let mut noisy = EnvSpec::default();
    noisy.overrides.pallet_noise_scale = Some(1000.0);
    for spec in [
        noisy,
        EnvSpec {
            case: Some("nope".into()),
            ..EnvSpec::default()
        },
    ] {
        assert!(matches!(
            Setup::new(scn.clone(), spec),
            Err(GymError::Scenario(_))
        ));
    }
    assert!(forkbench_gym::command(f64::NAN, 0.0, false).is_err());
}

/// The tracker's episode is the bench's trial at the same seed: the same verdict, time
/// and errors; the reward is the shaping plus the verdict's weight, and the same seed
/// gives the same episode.
#[test]
fn the_trackers_episode_is_the_trial_at_its_seed() {
    let scn = field_test();
    let spec = EnvSpec {
        path_points: 4,
        ..EnvSpec::default()
    };
    let setup = Setup::new(scn.clone(), spec).expect("sets up");
    assert_eq!(setup.obs.size(), obs::FIELDS.len() + 2 * 4);
    let (reward, core, last) = tracker_episode(&setup, 3);
    let trial = run_trial(
        &scn,
        &scn.cases[0],
        &TrialOptions {
            seed: Some(3),
            ..TrialOptions::default()
        },
    );
    let episode = core.outcome().expect("judged");
    assert_eq!(episode.success, trial.success);
    assert_eq!(episode.failure, trial.failure);
    assert_eq!(episode.sim_time_s, trial.sim_time_s);
    assert_eq!(episode.lateral_error_m, trial.lateral_error_m);
    assert!(last.iter().all(|v| v.is_finite()), "{last:?}");
    // Shaping alone is bounded by the start's distance to the goal and the time spent;
    // the verdict's weight (10) decides the sign of a clean pick's total.
    if trial.success {
        assert!(reward > 5.0, "{reward}");
    } else {
        assert!(reward < 5.0, "{reward}");
    }
    let (again, _, last_again) = tracker_episode(&setup, 3);
    assert_eq!(reward.to_bits(), again.to_bits());
    assert_eq!(last, last_again);
}
