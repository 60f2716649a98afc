//! Rare failures over a scenario's uncertain parameters: `estimate` (P(event) with its interval) and `falsify` (the most likely failure), each trial one point of `forkbench_rare`'s standard-normal space.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use forkbench_rare::{EstimateSettings, FalsifySettings, Outcome};
use forkbench_trial::outcome::TrialOutcome;
use forkbench_trial::trial::{Overrides, TrialOptions, run_trial};
use forkbench_trial::{Case, Scenario};

use crate::guard::guarded;
pub use crate::rare_store::{OUT_FILES, RareStore, TRIALS_FILE};
use crate::{BatchError, TrialRecord, trial_seed};

fn unknown(name: &str) -> BatchError {
    BatchError::Setting(format!(
        "event {name:?}: failure, contact, or a criterion's name (lateral_error, \
         heading_error, contact_force, pallet_displaced, collision, …)"
    ))
}

/// The event whose probability is estimated or which a search looks for.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Event {
    /// The trial failed, on any criterion.
    Failure,
    /// The trial broke this criterion (its verdict or one of `also_failed`).
    Criterion(String),
    /// The moving truck touched a person or vehicle.
    Contact,
}

impl Event {
    /// `failure`, `contact`, or a criterion's name.
    pub fn parse(s: &str) -> Result<Event, BatchError> {
        match s {
            "failure" => Ok(Event::Failure),
            "contact" => Ok(Event::Contact),
            name => match forkbench_trial::outcome::Failure::from_name(name) {
                // A name the bench itself gives a failure: a fixed criterion's or a
                // built-in step criterion's (any other word could only be a registered
                // phase's, which this command cannot tell from a typo).
                Some(forkbench_trial::outcome::Failure::Criterion(n))
                    if forkbench_trial::step_criteria::step_criterion_name(&n).is_none() =>
                {
                    Err(unknown(name))
                }
                Some(f) => Ok(Event::Criterion(f.name().to_owned())),
                None => Err(unknown(name)),
            },
        }
    }

    /// Whether `o` holds the event, and the trial's margin to it (≤ 0 when it does).
    fn of(&self, o: &TrialOutcome) -> Outcome {
        // A trial that ended before anything was measured stands on the boundary.
        let margin = o.robustness.unwrap_or(0.0);
        match self {
            Event::Failure => Outcome {
                event: !o.success,
                robustness: margin,
            },
            Event::Criterion(name) => Outcome {
                event: o.broke_named(name),
                robustness: margin,
            },
            Event::Contact => {
                let s = o.safety.as_ref();
                Outcome {
                    event: s.is_some_and(|s| s.person_contacts > 0),
                    robustness: s.and_then(|s| s.closest_any_m()).unwrap_or(f64::INFINITY),
                }
            }
        }
    }
}

/// What a search or an estimate runs: one case of a scenario with its components and
/// overrides, the batch seed the trials' other draws (sensor noise) come from, the event.
#[derive(Debug, Clone)]
pub struct RareSetup {
    pub scenario: Scenario,
    pub case: String,
    pub planner: Option<String>,
    pub tracker: Option<String>,
    pub overrides: Overrides,
    pub seed: u64,
    pub event: Event,
    pub jobs: usize,
}

/// Every trial run, in order, with its point.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Tried {
    pub z: Vec<f64>,
    #[serde(flatten)]
    pub record: TrialRecord,
}

struct Runner<'a> {
    setup: &'a RareSetup,
    case: &'a Case,
    pool: rayon::ThreadPool,
    tried: Vec<Tried>,
    store: Option<RareStore>,
    /// The first error writing the store (the run stops at its next stage).
    failed: Option<BatchError>,
}

impl Runner<'_> {
    /// Runs one trial per point, in parallel; trial `k` (counted over the whole run) has
    /// the seed a batch's trial `k` of this case would, so its sensor noise is its own.
    fn eval(&mut self, points: &[Vec<f64>]) -> Result<Vec<Outcome>, StoreFailed> {
        if self.failed.is_some() {
            return Err(StoreFailed);
        }
        let base = self.tried.len();
        // An earlier run of the same settings drew the same points: its trials stand.
        let prior: &[Tried] = self
            .store
            .as_ref()
            .map_or(&[], |st| st.prior.get(base..).unwrap_or(&[]));
        let reused = prior
            .iter()
            .zip(points)
            .take_while(|(t, z)| t.z == **z)
            .count();
        self.tried.extend_from_slice(&prior[..reused]);
        let mut marks: Vec<Outcome> = self.tried[base..]
            .iter()
            .map(|t| self.setup.event.of(&t.record.outcome))
            .collect();
        marks.extend(self.run(&points[reused..]));
        if let Some(st) = &mut self.store
            && let Err(e) = st.append(&self.tried[base + reused..])
        {
            self.failed = Some(e);
            return Err(StoreFailed);
        }
        Ok(marks)
    }

    /// Runs `points` as the next trials.
    fn run(&mut self, points: &[Vec<f64>]) -> Vec<Outcome> {
        let base = self.tried.len() as u64;
        let s = self.setup;
        let scn = &s.scenario;
        let outcomes: Vec<TrialOutcome> = self.pool.install(|| {
            points
                .par_iter()
                .with_max_len(1)
                .enumerate()
                .map(|(i, z)| {
                    let seed = trial_seed(s.seed, &scn.name, &self.case.name, base + i as u64);
                    let opts = TrialOptions {
                        seed: Some(seed),
                        planner: s.planner.clone(),
                        tracker: s.tracker.clone(),
                        overrides: s.overrides.clone(),
                        uncertain: scn.uncertain.at(z),
                        ..TrialOptions::default()
                    };
                    let names = (
                        s.planner.as_deref().unwrap_or(&scn.planner.name),
                        s.tracker.as_deref().unwrap_or(&scn.tracker.name),
                    );
                    guarded(scn, &self.case.name, names, seed, || {
                        run_trial(scn, self.case, &opts)
                    })
                })
                .collect()
        });
        let marks = outcomes.iter().map(|o| s.event.of(o)).collect();
        for (i, (z, outcome)) in points.iter().zip(outcomes).enumerate() {
            self.tried.push(Tried {
                z: z.clone(),
                record: TrialRecord {
                    trial: base + i as u64,
                    overrides: s.overrides.clone(),
                    replan: None,
                    outcome,
                },
            });
        }
        marks
    }
}

/// Most trials a search or an estimate runs: each trial's record is kept in memory
/// (about 1.3 KB a pick as JSON, more there), so this bounds its memory.
pub const MAX_RARE_TRIALS: usize = 250_000;

/// The runner of `setup`, its options and the scenario's parameters checked first.
fn runner(setup: &RareSetup, budget: usize) -> Result<Runner<'_>, BatchError> {
    if !(20..=MAX_RARE_TRIALS).contains(&budget) {
        return Err(BatchError::Setting(format!(
            "budget {budget}: from 20 to {MAX_RARE_TRIALS} trials (every trial's record is kept)"
        )));
    }
    let scn = &setup.scenario;
    if scn.uncertain.is_empty() {
        return Err(BatchError::Setting(format!(
            "{}: declares no [[uncertain]] parameters, so there is nothing to search or \
             weigh (docs/scenario-format.md#uncertain)",
            scn.file
        )));
    }
    let case = scn.pick_case(Some(&setup.case))?;
    TrialOptions {
        planner: setup.planner.clone(),
        tracker: setup.tracker.clone(),
        overrides: setup.overrides.clone(),
        ..TrialOptions::default()
    }
    .check_against(scn)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(setup.jobs.max(1))
        .build()
        .map_err(|e| BatchError::Internal(format!("thread pool: {e}")))?;
    Ok(Runner {
        setup,
        case,
        pool,
        tried: Vec::new(),
        store: None,
        failed: None,
    })
}

/// Writing a run's trials failed; the error is kept in the runner.
#[derive(Debug, thiserror::Error)]
#[error("writing the trials failed")]
struct StoreFailed;

impl Runner<'_> {
    /// The run's result, or the store's error that stopped it.
    fn finish<T>(
        mut self,
        r: Result<T, forkbench_rare::RareError<StoreFailed>>,
    ) -> Result<(T, Vec<Tried>), BatchError> {
        match (r, self.failed.take()) {
            (_, Some(e)) => Err(e),
            (Ok(v), None) => Ok((v, self.tried)),
            (Err(e), None) => Err(BatchError::Rare(e.to_string())),
        }
    }
}

/// P(event) over the scenario's uncertain parameters, and every trial it ran; with a
/// store, its trials are appended as they finish and an earlier run's are reused.
pub fn estimate(
    setup: &RareSetup,
    method: forkbench_rare::Method,
    budget: usize,
    store: Option<RareStore>,
) -> Result<(forkbench_rare::Estimate, Vec<Tried>), BatchError> {
    estimate_with(setup, (method, Default::default()), budget, store)
}

/// [`estimate`] with subset simulation's settings (acting only for its method).
pub fn estimate_with(
    setup: &RareSetup,
    (method, subset): (forkbench_rare::Method, forkbench_rare::SubsetSettings),
    budget: usize,
    store: Option<RareStore>,
) -> Result<(forkbench_rare::Estimate, Vec<Tried>), BatchError> {
    let mut r = runner(setup, budget)?;
    r.store = store;
    let dims = setup.scenario.uncertain.0.len();
    let s = EstimateSettings {
        subset,
        ..EstimateSettings::new(method, dims, budget, setup.seed)
    };
    let e = forkbench_rare::estimate(&s, |p| r.eval(p));
    r.finish(e)
}

/// The most likely failure (and the least robust trial) within `budget` trials; plain
/// Monte Carlo over the same distributions with `monte_carlo`.
pub fn falsify(
    setup: &RareSetup,
    budget: usize,
    monte_carlo: bool,
    store: Option<RareStore>,
) -> Result<(forkbench_rare::Falsified, Vec<Tried>), BatchError> {
    let mut r = runner(setup, budget)?;
    r.store = store;
    let dims = setup.scenario.uncertain.0.len();
    let s = FalsifySettings {
        monte_carlo,
        ..FalsifySettings::new(dims, budget, setup.seed)
    };
    let f = forkbench_rare::falsify(&s, |p| r.eval(p));
    r.finish(f)
}

impl RareSetup {
    /// What a run of this setup is, for its directory's `rare.json`: the build, the
    /// scenario's resolved settings, the case, components, overrides, seed, event and
    /// `what` (the method and budget). A run with equal settings draws the same trials.
    pub fn settings(&self, what: serde_json::Value) -> Result<serde_json::Value, BatchError> {
        let mut scenario =
            serde_json::to_value(crate::manifest::ScenarioEntry::of(&self.scenario)?)
                .map_err(|e| BatchError::Internal(e.to_string()))?;
        if let Some(m) = scenario.as_object_mut() {
            m.remove("file");
        }
        Ok(serde_json::json!({
            "build": crate::build_commit(),
            "scenario": scenario,
            "case": self.case,
            "planner": self.planner,
            "tracker": self.tracker,
            // A component defined by name is fingerprinted by its settings and files, so
            // an edit to it refuses the resume.
            "components": crate::prints::prints_of(
                &self.scenario,
                self.planner.as_slice(),
                self.tracker.as_slice(),
            ),
            "overrides": self.overrides,
            "seed": self.seed,
            "event": self.event,
            "run": what,
        }))
    }
}
