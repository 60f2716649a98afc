//! A log brought to what the fit needs: runs too short to fit left out, samples thinned to the rate the model resolves, and a bound on the samples fitted, each step said in a note.

use crate::log::{Channel, MIN_RUN_SAMPLES, Run};
use crate::model::{Kind, channel};

/// The sample rate the fit works at: the physics steps at 100 Hz and the dead-time grid is
/// 10 ms, so faster samples add work, not information.
pub const FIT_RATE_HZ: f64 = 100.0;

/// Most samples a fit runs its search over (ten minutes at [`FIT_RATE_HZ`]): the search's
/// work is this times its grid and iterations, so a bound on it bounds the time.
pub const MAX_FIT_SAMPLES: usize = 60_000;

/// Runs of `kind` ready to fit, and what was done to them, as notes for the report.
pub fn prepare(kind: Kind, runs: &[&Run]) -> (Vec<Run>, Vec<String>) {
    let mut notes = Vec::new();
    let long: Vec<&Run> = runs
        .iter()
        .copied()
        .filter(|r| r.t_s.len() >= MIN_RUN_SAMPLES)
        .collect();
    if long.len() < runs.len() {
        notes.push(format!(
            "{} of {} runs shorter than {MIN_RUN_SAMPLES} samples left out",
            runs.len() - long.len(),
            runs.len()
        ));
    }
    let mut every_most = 1;
    let thinned: Vec<Run> = long
        .iter()
        .map(|r| {
            let every = thinning(r);
            every_most = every_most.max(every);
            thin(kind, r, every)
        })
        .collect();
    if every_most > 1 {
        notes.push(format!(
            "samples thinned to about {FIT_RATE_HZ:.0} Hz (every {every_most}th at most) for \
             the fit"
        ));
    }
    (thinned, notes)
}

/// Every how many samples of `r` one is kept to come down to [`FIT_RATE_HZ`].
fn thinning(r: &Run) -> usize {
    let n = r.t_s.len();
    if n < 2 {
        return 1;
    }
    let dt = (r.t_s[n - 1] - r.t_s[0]) / (n - 1) as f64;
    ((1.0 / FIT_RATE_HZ) / dt).floor().max(1.0) as usize
}

/// `r` with every `every`th sample of its time and of `kind`'s channel (the other is
/// dropped: a fit reads one).
fn thin(kind: Kind, r: &Run, every: usize) -> Run {
    let pick = |v: &[f64]| v.iter().step_by(every).copied().collect::<Vec<f64>>();
    let ch = channel(r, kind).map(|c| Channel {
        cmd: pick(&c.cmd),
        measured: pick(&c.measured),
    });
    let (steer, speed) = match kind {
        Kind::Steering => (ch, None),
        Kind::Drive => (None, ch),
    };
    Run {
        t_s: pick(&r.t_s),
        steer,
        speed,
    }
}

/// The training runs cut to [`MAX_FIT_SAMPLES`] in their order (a run that crosses the
/// bound is cut short, kept if [`MIN_RUN_SAMPLES`] remain), with a note when any was.
pub fn within_budget(runs: Vec<&Run>) -> (Vec<Run>, Option<String>) {
    let total: usize = runs.iter().map(|r| r.t_s.len()).sum();
    if total <= MAX_FIT_SAMPLES {
        return (runs.into_iter().cloned().collect(), None);
    }
    let mut left = MAX_FIT_SAMPLES;
    let mut out = Vec::new();
    for r in runs {
        let take = r.t_s.len().min(left);
        if take < MIN_RUN_SAMPLES {
            break;
        }
        let cut = |v: &[f64]| v[..take].to_vec();
        let ch = |c: &Option<Channel>| {
            c.as_ref().map(|c| Channel {
                cmd: cut(&c.cmd),
                measured: cut(&c.measured),
            })
        };
        out.push(Run {
            t_s: cut(&r.t_s),
            steer: ch(&r.steer),
            speed: ch(&r.speed),
        });
        left -= take;
    }
    let note = format!(
        "fitted on the first {MAX_FIT_SAMPLES} of {total} training samples (the most a fit \
         searches over); the held-out runs are validated whole"
    );
    (out, Some(note))
}
