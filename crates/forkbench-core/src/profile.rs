//! Where a trial's time goes: each stage's exclusive time on the trial's thread, gathered only when a run asks for it (`--profile`).

use std::cell::{Cell, RefCell};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// A part of a trial's work that a profile times on its own. Stages nest: time spent in
/// an inner stage (a scan inside a look) is the inner stage's, not also its parent's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    /// rapier's step of the world, with the truck's actuators and tyre impulses.
    Physics,
    /// Casting one sensor's scan (labelled by the sensor).
    Scan,
    /// The pallet detector on a look's scans (labelled by the detector; an external
    /// one's process round trip included).
    Detect,
    /// The evidence check scoring a detection's candidates against the scans.
    Evidence,
    /// The localiser's readings (NAV350 reflector fixes) and odometry.
    Localise,
    /// The planner, each plan and replan (an external one's round trip included).
    Plan,
    /// The tracker's command each control tick (an external one's round trip included).
    Track,
    /// The step criteria and the entry checks observed each step.
    Criteria,
    /// The safety function and the people and vehicles it watches.
    Safety,
    /// What goes to the recorder (nothing when no recording is asked for).
    Record,
}

impl Stage {
    /// The stage's name in a profile.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Physics => "physics",
            Stage::Scan => "scan",
            Stage::Detect => "detection",
            Stage::Evidence => "evidence check",
            Stage::Localise => "localisation",
            Stage::Plan => "planning",
            Stage::Track => "tracking",
            Stage::Criteria => "criteria",
            Stage::Safety => "safety and people",
            Stage::Record => "recording",
        }
    }
}

/// One stage's share of a trial (or a batch's trials).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageTime {
    /// The stage (`Stage::name`), or "other" for the trial's time outside every stage
    /// (setup, the drive loop's own bookkeeping).
    pub stage: String,
    /// The component or sensor the time is for, where the stage has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub component: Option<String>,
    /// Time in the stage, exclusive of the stages nested in it.
    pub time_ms: f64,
    /// How often the stage was entered.
    pub calls: u64,
}

/// Where a trial's time went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// The trials summed in it (1 for a trial's own).
    #[serde(default = "one")]
    pub trials: u64,
    /// The trial's wall time, from its start to its outcome.
    pub wall_ms: f64,
    /// The CPU time of the trial's thread over the same span: less than `wall_ms` by
    /// the time it waited (an external component's process, the OS's other work).
    pub cpu_ms: f64,
    /// Each stage, largest first, then "other".
    pub stages: Vec<StageTime>,
}

impl Profile {
    /// Names `component` as the one a `stage` entered without a label timed (the
    /// trial's planner and tracker, known once it has run).
    pub fn label(&mut self, stage: Stage, component: &str) {
        for s in &mut self.stages {
            if s.stage == stage.name() && s.component.is_none() {
                s.component = Some(component.to_owned());
            }
        }
    }

    /// The share of the wall time `s` took, in percent.
    pub fn share_pct(&self, s: &StageTime) -> f64 {
        if self.wall_ms > 0.0 {
            100.0 * s.time_ms / self.wall_ms
        } else {
            0.0
        }
    }

    /// The sum of `profiles`, stage by stage (a batch row's or a whole batch's profile).
    pub fn sum<'p>(profiles: impl IntoIterator<Item = &'p Profile>) -> Option<Profile> {
        let mut total: Option<Profile> = None;
        for p in profiles {
            Self::add_into(&mut total, p);
        }
        total
    }

    /// `p` added to `total`, or `total` made of it when it has none yet.
    pub fn add_into(total: &mut Option<Profile>, p: &Profile) {
        match total.as_mut() {
            Some(t) => t.add(p),
            None => *total = Some(p.clone()),
        }
    }

    /// Adds `p` to this profile, stage by stage, largest first again.
    pub fn add(&mut self, p: &Profile) {
        self.trials += p.trials;
        self.wall_ms += p.wall_ms;
        self.cpu_ms += p.cpu_ms;
        for s in &p.stages {
            match self
                .stages
                .iter_mut()
                .find(|x| x.stage == s.stage && x.component == s.component)
            {
                Some(x) => {
                    x.time_ms += s.time_ms;
                    x.calls += s.calls;
                }
                None => self.stages.push(s.clone()),
            }
        }
        sort_stages(&mut self.stages);
    }
}

impl StageTime {
    /// The stage as a profile names it: `tracking (pure_pursuit)`, or the stage alone.
    pub fn label(&self) -> String {
        match &self.component {
            Some(c) => format!("{} ({c})", self.stage),
            None => self.stage.clone(),
        }
    }
}

impl Profile {
    /// The profile as aligned text lines, each starting with `prefix`: a header, then
    /// each stage with its time, share of the wall time and calls.
    pub fn lines(&self, prefix: &str) -> Vec<String> {
        let mut out = vec![format!(
            "{prefix}{:<34} {:>10} {:>7} {:>9}",
            format!("wall {:.1} ms, CPU {:.1} ms", self.wall_ms, self.cpu_ms),
            "time ms",
            "share",
            "calls"
        )];
        for s in &self.stages {
            let name = s.label();
            let calls = if s.stage == OTHER {
                String::new()
            } else {
                s.calls.to_string()
            };
            out.push(format!(
                "{prefix}{name:<34} {:>10.2} {:>6.1}% {calls:>9}",
                s.time_ms,
                self.share_pct(s),
            ));
        }
        out
    }
}

fn one() -> u64 {
    1
}

/// Largest first, "other" last.
fn sort_stages(stages: &mut [StageTime]) {
    stages.sort_by(|a, b| {
        (a.stage == OTHER)
            .cmp(&(b.stage == OTHER))
            .then(b.time_ms.total_cmp(&a.time_ms))
    });
}

const OTHER: &str = "other";

/// The profile being gathered on this thread.
struct Gatherer {
    /// The stages entered and not yet left, innermost last.
    open: Vec<usize>,
    /// When the innermost open stage (or the gap between stages) last began to count.
    since: Instant,
    /// (stage, label, time, calls), in first-entered order.
    totals: Vec<(Stage, Option<String>, Duration, u64)>,
}

impl Gatherer {
    fn charge(&mut self, now: Instant) {
        if let Some(&k) = self.open.last() {
            self.totals[k].2 += now - self.since;
        }
        self.since = now;
    }

    fn slot(&mut self, stage: Stage, label: Option<&str>) -> usize {
        let found = self
            .totals
            .iter()
            .position(|(s, l, ..)| *s == stage && l.as_deref() == label);
        found.unwrap_or_else(|| {
            self.totals
                .push((stage, label.map(str::to_owned), Duration::ZERO, 0));
            self.totals.len() - 1
        })
    }
}

thread_local! {
    static ON: Cell<bool> = const { Cell::new(false) };
    static GATHERER: RefCell<Option<Gatherer>> = const { RefCell::new(None) };
}

/// A stage being timed: it stops counting when dropped.
#[derive(Debug)]
#[must_use = "the stage is timed until this guard is dropped"]
pub struct Timed(bool);

/// Times `stage` until the guard is dropped (nothing, at the cost of one flag read,
/// unless this thread is gathering a profile).
pub fn enter(stage: Stage) -> Timed {
    enter_with(stage, None)
}

/// Times `stage` for `label` (a sensor, a component) until the guard is dropped.
pub fn enter_as(stage: Stage, label: &str) -> Timed {
    enter_with(stage, Some(label))
}

/// Runs `f` timed as `stage`: [`enter`] around one expression.
pub fn timed<T>(stage: Stage, f: impl FnOnce() -> T) -> T {
    let _timed = enter(stage);
    f()
}

fn enter_with(stage: Stage, label: Option<&str>) -> Timed {
    if !ON.with(Cell::get) {
        return Timed(false);
    }
    GATHERER.with_borrow_mut(|g| {
        if let Some(g) = g.as_mut() {
            g.charge(Instant::now());
            let k = g.slot(stage, label);
            g.totals[k].3 += 1;
            g.open.push(k);
        }
    });
    Timed(true)
}

impl Drop for Timed {
    fn drop(&mut self) {
        if !self.0 {
            return;
        }
        GATHERER.with_borrow_mut(|g| {
            if let Some(g) = g.as_mut() {
                g.charge(Instant::now());
                g.open.pop();
            }
        });
    }
}

/// Runs `f` gathering its profile on this thread (a stage entered without a label has
/// no component; [`Profile::label`] names it after).
pub fn gather<T>(f: impl FnOnce() -> T) -> (T, Profile) {
    let (wall, cpu) = (Instant::now(), cpu_time::ThreadTime::try_now().ok());
    GATHERER.with_borrow_mut(|g| {
        *g = Some(Gatherer {
            open: Vec::new(),
            since: wall,
            totals: Vec::new(),
        });
    });
    ON.with(|on| on.set(true));
    let value = f();
    ON.with(|on| on.set(false));
    let wall_ms = wall.elapsed().as_secs_f64() * 1e3;
    let cpu_ms = cpu
        .map(|c| c.elapsed().as_secs_f64() * 1e3)
        .unwrap_or(wall_ms);
    let totals = GATHERER.with_borrow_mut(Option::take).map(|g| g.totals);
    let mut stages: Vec<StageTime> = totals
        .unwrap_or_default()
        .into_iter()
        .map(|(stage, label, d, calls)| StageTime {
            stage: stage.name().to_owned(),
            component: label,
            time_ms: d.as_secs_f64() * 1e3,
            calls,
        })
        .collect();
    let staged: f64 = stages.iter().map(|s| s.time_ms).sum();
    stages.push(StageTime {
        stage: OTHER.to_owned(),
        component: None,
        time_ms: (wall_ms - staged).max(0.0),
        calls: 1,
    });
    sort_stages(&mut stages);
    let profile = Profile {
        trials: 1,
        wall_ms,
        cpu_ms,
        stages,
    };
    (value, profile)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spin(d: Duration) {
        let t = Instant::now();
        while t.elapsed() < d {
            std::hint::black_box(0);
        }
    }

    #[test]
    fn nested_stages_are_exclusive_and_sum_to_the_wall_time() {
        let ((), mut p) = gather(|| {
            let _plan = enter(Stage::Plan);
            spin(Duration::from_millis(4));
            {
                let _scan = enter_as(Stage::Scan, "tim561");
                spin(Duration::from_millis(8));
            }
            drop(_plan);
            let _t = enter(Stage::Track);
            spin(Duration::from_millis(2));
        });
        p.label(Stage::Track, "pure-pursuit");
        let get = |name: &str| p.stages.iter().find(|s| s.stage == name).expect("timed");
        let (plan, scan, track) = (get("planning"), get("scan"), get("tracking"));
        assert!(
            scan.time_ms >= 8.0 && plan.time_ms >= 4.0 && plan.time_ms < 8.0,
            "{p:?}"
        );
        assert_eq!(scan.component.as_deref(), Some("tim561"));
        assert_eq!(track.component.as_deref(), Some("pure-pursuit"));
        assert_eq!(p.stages[0].stage, "scan", "largest first: {p:?}");
        assert_eq!(p.stages.last().expect("a stage").stage, "other");
        let sum: f64 = p.stages.iter().map(|s| s.time_ms).sum();
        assert!(
            (sum - p.wall_ms).abs() < 1e-6 * p.wall_ms.max(1.0),
            "{sum} vs {}",
            p.wall_ms
        );
    }

    #[test]
    fn nothing_is_gathered_outside_a_profiled_run() {
        let t = enter(Stage::Physics);
        assert!(!t.0);
        drop(t);
        let ((), p) = gather(|| {});
        assert_eq!(p.stages.len(), 1, "{p:?}");
    }

    #[test]
    fn profiles_sum_stage_by_stage() {
        let p = |ms: f64| Profile {
            trials: 1,
            wall_ms: ms,
            cpu_ms: ms,
            stages: vec![StageTime {
                stage: "physics".into(),
                component: None,
                time_ms: ms / 2.0,
                calls: 3,
            }],
        };
        let s = Profile::sum([&p(2.0), &p(4.0)]).expect("two profiles");
        assert_eq!(
            (s.wall_ms, s.stages[0].time_ms, s.stages[0].calls),
            (6.0, 3.0, 6)
        );
        assert_eq!(s.trials, 2);
        assert!(Profile::sum(std::iter::empty()).is_none());
    }
}
