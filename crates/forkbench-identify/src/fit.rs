//! The fit: the dead time on a grid, the time constant and limits by output-error least squares (Nelder–Mead in log space), limits the log never reaches left unidentified, and the held-out validation.

use std::collections::BTreeMap;

use crate::log::{ActuatorLog, Run};
use crate::model::{Kind, Params, channel, fit_percent, simulate};
use crate::{ChannelFit, IdentifyError, Trace};

/// Largest dead time searched.
const MAX_DEAD_TIME_S: f64 = 0.6;
/// Horizons of the rollout error.
pub const HORIZONS_S: [f64; 3] = [0.5, 1.0, 2.0];
/// A limit whose removal raises the squared error by less than this share is not seen in
/// the log: the log never drove the actuator into it.
const LIMIT_SEEN: f64 = 0.005;

/// Sum of squared output errors of `p` over `runs`.
fn sse(kind: Kind, p: &Params, runs: &[&Run]) -> f64 {
    runs.iter()
        .filter_map(|r| channel(r, kind).map(|ch| (r, ch)))
        .map(|(r, ch)| {
            let y = simulate(kind, p, &r.t_s, ch, 0, r.t_s.len());
            y.iter()
                .zip(&ch.measured)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
        })
        .sum()
}

/// Parameters from a point of the search (log time constant, log limits).
fn params(kind: Kind, d: f64, x: &[f64]) -> Params {
    Params {
        dead_time_s: d,
        time_constant_s: x[0].exp(),
        limit_up: Some(x[1].exp()),
        limit_down: match kind {
            Kind::Steering => None,
            Kind::Drive => Some(x[2].exp()),
        },
        accel_limit: match kind {
            Kind::Steering => Some(x[2].exp()),
            Kind::Drive => None,
        },
    }
}

/// Nelder–Mead minimisation of `f` from `x0` with initial steps `step`, for `iters` iterations.
fn nelder_mead(f: &dyn Fn(&[f64]) -> f64, x0: &[f64], step: f64, iters: usize) -> (Vec<f64>, f64) {
    let n = x0.len();
    let mut simplex: Vec<(Vec<f64>, f64)> = (0..=n)
        .map(|i| {
            let mut x = x0.to_vec();
            if i > 0 {
                x[i - 1] += step;
            }
            let v = f(&x);
            (x, v)
        })
        .collect();
    for _ in 0..iters {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let centroid: Vec<f64> = (0..n)
            .map(|j| simplex[..n].iter().map(|(x, _)| x[j]).sum::<f64>() / n as f64)
            .collect();
        let at = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|j| centroid[j] + t * (simplex[n].0[j] - centroid[j]))
                .collect()
        };
        let xr = at(-1.0);
        let fr = f(&xr);
        if fr < simplex[0].1 {
            let xe = at(-2.0);
            let fe = f(&xe);
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let xc = at(0.5);
            let fc = f(&xc);
            if fc < simplex[n].1 {
                simplex[n] = (xc, fc);
            } else {
                let best = simplex[0].0.clone();
                for (x, v) in simplex.iter_mut().skip(1) {
                    *x = (0..n).map(|j| best[j] + 0.5 * (x[j] - best[j])).collect();
                    *v = f(x);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex.swap_remove(0)
}

/// The best parameters for `runs`: every dead time on the log's sample grid, each with
/// its own least-squares time constant and limits, then the limits the log does not show
/// dropped.
pub fn fit(kind: Kind, runs: &[&Run]) -> Params {
    let dt = grid_step(runs);
    let peak = runs
        .iter()
        .filter_map(|r| channel(r, kind).map(|c| (r, c)))
        .flat_map(|(r, c)| {
            (1..r.t_s.len()).map(move |k| {
                ((c.measured[k] - c.measured[k - 1]) / (r.t_s[k] - r.t_s[k - 1])).abs()
            })
        })
        .fold(1e-3, f64::max);
    let x0 = match kind {
        // The motor's acceleration starts as reaching that rate in 50 ms.
        Kind::Steering => vec![0.1_f64.ln(), (1.5 * peak).ln(), (30.0 * peak).ln()],
        Kind::Drive => vec![0.25_f64.ln(), (1.5 * peak).ln(), (1.5 * peak).ln()],
    };
    let search = |d: f64, iters: usize| {
        // The time constants a truck file takes: the drive's from 0.01 s.
        let tau_min = match kind {
            Kind::Steering => 1e-3,
            Kind::Drive => 0.01,
        };
        let f = |x: &[f64]| {
            if !x.iter().all(|v| v.is_finite()) || x[0].exp() < tau_min || x[0].exp() > 10.0 {
                return f64::INFINITY;
            }
            let e = sse(kind, &params(kind, d, x), runs);
            if e.is_nan() { f64::INFINITY } else { e }
        };
        nelder_mead(&f, &x0, 0.7, iters)
    };
    let steps = (MAX_DEAD_TIME_S / dt).round() as usize;
    let (mut best_d, mut best) = (0.0, search(0.0, 60));
    for k in 1..=steps {
        let d = k as f64 * dt;
        let r = search(d, 60);
        if r.1 < best.1 {
            (best_d, best) = (d, r);
        }
    }
    let refined = search(best_d, 200);
    let mut p = params(kind, best_d, &refined.0);
    drop_unseen_limits(kind, &mut p, refined.1, runs);
    p
}

/// Drops each limit whose removal changes the error by less than `LIMIT_SEEN`, and any
/// beyond what a truck file takes (20 rad/s, 50 m/s², 1000 rad/s²): the log cannot tell
/// those apart from no limit.
fn drop_unseen_limits(kind: Kind, p: &mut Params, err: f64, runs: &[&Run]) {
    let cap = match kind {
        Kind::Steering => 20.0,
        Kind::Drive => 50.0,
    };
    p.limit_up = p.limit_up.filter(|v| *v <= cap);
    p.limit_down = p.limit_down.filter(|v| *v <= cap);
    p.accel_limit = p.accel_limit.filter(|v| *v <= 1000.0);
    for which in [0, 1, 2] {
        let mut without = *p;
        match which {
            0 => without.limit_up = None,
            1 => without.limit_down = None,
            _ => without.accel_limit = None,
        }
        if without != *p && sse(kind, &without, runs) <= err * (1.0 + LIMIT_SEEN) + 1e-12 {
            *p = without;
        }
    }
}

/// The dead-time grid's spacing: the log's sample step, and no finer than 10 ms (what
/// the physics resolves), so the grid has at most 61 points.
pub fn grid_step(runs: &[&Run]) -> f64 {
    let (step, floor) = (median_step(runs), 1.0 / crate::rate::FIT_RATE_HZ);
    // A step a rounding short of the floor (epoch stamps in a bag) is the log's own: the
    // grid stays on its samples.
    if step >= floor * 0.999 { step } else { floor }
}

fn median_step(runs: &[&Run]) -> f64 {
    let mut steps: Vec<f64> = runs
        .iter()
        .flat_map(|r| r.t_s.windows(2).map(|w| w[1] - w[0]))
        .collect();
    steps.sort_by(f64::total_cmp);
    steps
        .get(steps.len() / 2)
        .copied()
        .unwrap_or(0.01)
        .max(1e-4)
}

/// The runs a fit is validated on (every fourth, or the last of two or three) and those
/// it is fitted on; one run is both.
pub fn split(n: usize) -> (Vec<usize>, Vec<usize>) {
    let held: Vec<usize> = match n {
        0 | 1 => vec![],
        2 | 3 => vec![n - 1],
        _ => (0..n).filter(|i| i % 4 == 3).collect(),
    };
    let train: Vec<usize> = (0..n).filter(|i| !held.contains(i)).collect();
    (train, held)
}

/// Fits `kind` on the log's training runs and validates it on the held-out ones.
pub fn identify_channel(kind: Kind, log: &ActuatorLog) -> Result<ChannelFit, IdentifyError> {
    let all: Vec<&Run> = log
        .runs
        .iter()
        .filter(|r| channel(r, kind).is_some())
        .collect();
    let (prepared, mut notes) = crate::rate::prepare(kind, &all);
    let with: Vec<&Run> = prepared.iter().collect();
    crate::check::enough(kind, &with)?;
    let (train, held) = split(with.len());
    let (fitted, cut) = crate::rate::within_budget(train.iter().map(|&i| with[i]).collect());
    notes.extend(cut);
    let fit_runs: Vec<&Run> = fitted.iter().collect();
    let p = fit(kind, &fit_runs);
    let dead_time_step_s = grid_step(&fit_runs);
    let (mut settings, mut refused) = in_truck_ranges(settings(kind, &p));
    if let Some(why) = lag_unresolved(&p, dead_time_step_s, command_period_s(&fit_runs, kind)) {
        let key = match kind {
            Kind::Steering => "steering.time_constant_s",
            Kind::Drive => "drive.time_constant_s",
        };
        settings.remove(key);
        refused.push((key.to_owned(), why));
    }
    notes.extend(refused.iter().map(|(k, why)| format!("{k}: {why}")));
    let check_runs: Vec<&Run> = if held.is_empty() {
        fit_runs.clone()
    } else {
        held.iter().map(|&i| with[i]).collect()
    };
    let (mut y, mut yh) = (Vec::new(), Vec::new());
    for r in &check_runs {
        let ch = channel(r, kind).expect("filtered");
        y.extend_from_slice(&ch.measured);
        yh.extend(simulate(kind, &p, &r.t_s, ch, 0, r.t_s.len()));
    }
    let first = check_runs[0];
    let ch = channel(first, kind).expect("filtered");
    Ok(ChannelFit {
        channel: match kind {
            Kind::Steering => "steering",
            Kind::Drive => "drive",
        }
        .to_owned(),
        settings,
        not_identified: unseen(kind, &p)
            .into_iter()
            .chain(refused.into_iter().map(|(k, _)| k))
            .collect(),
        dead_time_step_s,
        notes,
        fit_percent: fit_percent(&y, &yh),
        fit_runs: fit_runs.len(),
        held_out_runs: held.len(),
        samples: with.iter().map(|r| r.t_s.len()).sum(),
        rollout_rmse: HORIZONS_S
            .iter()
            .map(|&h| (h, rollout_rmse(kind, &p, &check_runs, h)))
            .collect(),
        trace: Trace {
            t_s: first.t_s.clone(),
            command: ch.cmd.clone(),
            measured: ch.measured.clone(),
            fitted: simulate(kind, &p, &first.t_s, ch, 0, first.t_s.len()),
        },
    })
}

/// Why the fitted lag cannot be told from dead time in this log, if it cannot: it is
/// shorter than two samples of the dead-time grid, or than the period the commands were
/// held for, and either blurs a lag into a delay.
fn lag_unresolved(p: &Params, grid_s: f64, period_s: Option<f64>) -> Option<String> {
    let (what, resolved_s) = match period_s {
        Some(t) if t > 2.0 * grid_s => ("the commands' period", t),
        _ => ("two samples of the log", 2.0 * grid_s),
    };
    (p.time_constant_s < resolved_s).then(|| {
        format!(
            "fitted {:.4} s, shorter than {what} ({resolved_s:.3} s): this log cannot tell \
             the lag from dead time (the dead time holds both); not identified",
            p.time_constant_s
        )
    })
}

/// The controller's period as the log shows it: the median time between changes of the
/// command, when most changes come within 0.25 s of the last (a controller's stream, not
/// a step test's held steps).
fn command_period_s(runs: &[&Run], kind: Kind) -> Option<f64> {
    let mut gaps: Vec<f64> = Vec::new();
    for r in runs {
        let Some(ch) = channel(r, kind) else { continue };
        let mut last: Option<f64> = None;
        for k in 1..ch.cmd.len() {
            if ch.cmd[k] != ch.cmd[k - 1] {
                if let Some(t0) = last {
                    gaps.push(r.t_s[k] - t0);
                }
                last = Some(r.t_s[k]);
            }
        }
    }
    let short: Vec<f64> = gaps.iter().copied().filter(|g| *g < 0.25).collect();
    if gaps.is_empty() || short.len() * 2 < gaps.len() {
        return None;
    }
    let mut short = short;
    short.sort_by(f64::total_cmp);
    Some(short[short.len() / 2])
}

/// RMS error at the end of open-loop rollouts of `h_s`, started every half second from
/// the measured state.
fn rollout_rmse(kind: Kind, p: &Params, runs: &[&Run], h_s: f64) -> Option<f64> {
    let (mut sum, mut n) = (0.0, 0usize);
    for r in runs {
        let ch = channel(r, kind).expect("filtered");
        let mut start = 0;
        while start < r.t_s.len() {
            let t0 = r.t_s[start];
            let Some(end) = r.t_s[start..].iter().position(|t| *t >= t0 + h_s - 1e-9) else {
                break;
            };
            let y = simulate(kind, p, &r.t_s, ch, start, end + 1);
            if let Some(last) = y.last() {
                sum += (last - ch.measured[start + end]).powi(2);
                n += 1;
            }
            start += r.t_s[start..]
                .iter()
                .position(|t| *t >= t0 + 0.5 - 1e-9)
                .unwrap_or(r.t_s.len());
        }
    }
    (n > 0).then(|| (sum / n as f64).sqrt())
}

/// The fitted values by the truck file's own names.
fn settings(kind: Kind, p: &Params) -> BTreeMap<String, f64> {
    let mut s = BTreeMap::new();
    match kind {
        Kind::Steering => {
            s.insert("steering.dead_time_s".into(), p.dead_time_s);
            s.insert("steering.time_constant_s".into(), p.time_constant_s);
            if let Some(r) = p.limit_up {
                s.insert("max_steer_rate_radps".into(), r);
            }
            if let Some(a) = p.accel_limit {
                s.insert("steering.accel_limit_radps2".into(), a);
            }
        }
        Kind::Drive => {
            s.insert("drive.dead_time_s".into(), p.dead_time_s);
            s.insert("drive.time_constant_s".into(), p.time_constant_s);
            if let Some(a) = p.limit_up {
                s.insert("drive.accel_limit_mps2".into(), a);
            }
            if let Some(b) = p.limit_down {
                s.insert("drive.brake_limit_mps2".into(), b);
            }
        }
    }
    s
}

/// The settings a truck file takes, and those it would refuse with the reason: a fitted
/// value out of a truck's range means the log does not show that setting.
fn in_truck_ranges(
    fitted: BTreeMap<String, f64>,
) -> (BTreeMap<String, f64>, Vec<(String, String)>) {
    let mut refused = Vec::new();
    let mut kept = BTreeMap::new();
    for (k, v) in fitted {
        let mut truck = forkbench_core::ForkliftSpec::default();
        let known = forkbench_core::run_settings::set(&mut truck, &k, v);
        match truck.validate() {
            Ok(()) if known => {
                kept.insert(k, v);
            }
            Ok(()) => refused.push((k, "not a truck file's setting".to_owned())),
            Err(e) => refused.push((
                k,
                format!("fitted {v:.4}, which a truck file refuses ({e}): not identified"),
            )),
        }
    }
    (kept, refused)
}

/// The limits the log never reached, by the truck file's names.
fn unseen(kind: Kind, p: &Params) -> Vec<String> {
    match kind {
        Kind::Steering => [
            (p.limit_up, "max_steer_rate_radps"),
            (p.accel_limit, "steering.accel_limit_radps2"),
        ]
        .iter()
        .filter(|(v, _)| v.is_none())
        .map(|(_, n)| (*n).to_owned())
        .collect(),
        Kind::Drive => [
            (p.limit_up, "drive.accel_limit_mps2"),
            (p.limit_down, "drive.brake_limit_mps2"),
        ]
        .iter()
        .filter(|(v, _)| v.is_none())
        .map(|(_, n)| (*n).to_owned())
        .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lag shorter than the commands' period or two samples is not written: the log
    /// cannot tell it from dead time.
    #[test]
    fn a_lag_the_log_cannot_resolve_is_not_identified() {
        let p = |tau: f64| Params {
            dead_time_s: 0.1,
            time_constant_s: tau,
            limit_up: None,
            limit_down: None,
            accel_limit: None,
        };
        assert!(lag_unresolved(&p(0.001), 0.01, None).is_some_and(|w| w.contains("two samples")));
        assert!(lag_unresolved(&p(0.03), 0.01, None).is_none());
        let why = lag_unresolved(&p(0.03), 0.01, Some(0.05)).expect("below the period");
        assert!(why.contains("the commands' period (0.050 s)"), "{why}");
        // A 50 ms controller's stream, and a step test's held steps.
        let t: Vec<f64> = (0..400).map(|k| k as f64 * 0.01).collect();
        let run = |cmd: Vec<f64>| Run {
            t_s: t.clone(),
            steer: Some(crate::log::Channel {
                measured: cmd.clone(),
                cmd,
            }),
            speed: None,
        };
        let stream = run((0..400).map(|k| (k / 5) as f64 * 0.01).collect());
        let period = command_period_s(&[&stream], Kind::Steering).expect("a stream");
        assert!((period - 0.05).abs() < 1e-9, "{period}");
        let steps = run((0..400).map(|k| (k / 100) as f64 * 0.1).collect());
        assert_eq!(command_period_s(&[&steps], Kind::Steering), None);
    }

    /// A fitted value a truck file would refuse (a rate of 0, an acceleration of
    /// 0.003 m/s²) is not written: it is named as not identified, with the reason.
    #[test]
    fn fitted_values_a_truck_refuses_are_not_written() {
        let fitted: BTreeMap<String, f64> = [
            ("drive.accel_limit_mps2", 0.003),
            ("drive.dead_time_s", 0.1),
            ("max_steer_rate_radps", 0.0),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect();
        let (kept, refused) = in_truck_ranges(fitted);
        assert_eq!(kept.keys().collect::<Vec<_>>(), ["drive.dead_time_s"]);
        let names: Vec<&str> = refused.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(names, ["drive.accel_limit_mps2", "max_steer_rate_radps"]);
        assert!(
            refused.iter().all(|(_, why)| why.contains("refuses")),
            "{refused:?}"
        );
    }
}
