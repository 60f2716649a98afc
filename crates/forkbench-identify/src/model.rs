//! The actuator models a fit simulates, as the physics applies them: a dead time, then the steering's first-order lag limited in rate and acceleration, or the drive's speed loop limited in acceleration and braking.

use crate::log::{Channel, Run};

/// Which actuator a channel is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Steering,
    Drive,
}

/// A model's parameters: a dead time, a time constant, and the limits (none: unlimited).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    pub dead_time_s: f64,
    pub time_constant_s: f64,
    /// Steering: the rate limit; drive: the acceleration limit.
    pub limit_up: Option<f64>,
    /// Drive: the braking limit (the steering has one rate limit, in `limit_up`).
    pub limit_down: Option<f64>,
    /// Steering: the acceleration limit of its motor (the drive has none: its
    /// acceleration limit is `limit_up`).
    pub accel_limit: Option<f64>,
}

/// The channel of `kind` in `run`.
pub fn channel(run: &Run, kind: Kind) -> Option<&Channel> {
    match kind {
        Kind::Steering => run.steer.as_ref(),
        Kind::Drive => run.speed.as_ref(),
    }
}

/// The model's response over `t_s` to `ch`'s commands, from its measured state at sample
/// `from` for `len` samples (an open-loop rollout: the model never sees the measurements
/// after its start). Before the log begins, the command is taken to be the measured state.
pub fn simulate(
    kind: Kind,
    p: &Params,
    t_s: &[f64],
    ch: &Channel,
    from: usize,
    len: usize,
) -> Vec<f64> {
    let end = (from + len).min(t_s.len());
    let mut out = Vec::with_capacity(end.saturating_sub(from));
    let Some(&x0) = ch.measured.get(from) else {
        return out;
    };
    let (mut x, mut rate) = (x0, 0.0);
    out.push(x);
    // The newest sample whose time is at or before t − d (zero-order hold on the commands).
    let mut j: Option<usize> = None;
    for k in from + 1..end {
        let target_t = t_s[k] - p.dead_time_s + 1e-9;
        while j.map_or(0, |j| j + 1) < t_s.len() && t_s[j.map_or(0, |j| j + 1)] <= target_t {
            j = Some(j.map_or(0, |j| j + 1));
        }
        let u = j.map_or(ch.measured[0], |j| ch.cmd[j]);
        let dt = t_s[k] - t_s[k - 1];
        (x, rate) = step(kind, p, (x, rate), u, dt);
        out.push(x);
    }
    out
}

/// One step of the model from state `x` moving at `rate` under the (delayed) command
/// `u`; the new state and rate.
fn step(kind: Kind, p: &Params, (x, rate): (f64, f64), u: f64, dt: f64) -> (f64, f64) {
    match kind {
        Kind::Steering => {
            let err = u - x;
            let mut delta = forkbench_core::actuators::lag_fraction(dt, p.time_constant_s) * err;
            if let Some(r) = p.limit_up {
                delta = delta.clamp(-r * dt, r * dt);
            }
            if let Some(acc) = p.accel_limit {
                // As the physics' motor: it slows in time to stop at the target and
                // changes its rate only so fast.
                let half_step = 0.5 * acc * dt;
                let stop = (2.0 * acc * err.abs() + half_step * half_step).sqrt() - half_step;
                let w = (delta / dt)
                    .clamp(-stop, stop)
                    .clamp(rate - acc * dt, rate + acc * dt);
                delta = w * dt;
            }
            (x + delta, delta / dt)
        }
        Kind::Drive => {
            // The physics' speed loop: an explicit step of v' = (u − v) / τ, limited.
            let mut a = (u - x) / p.time_constant_s.max(dt);
            let lim = if a * x < 0.0 {
                p.limit_down
            } else {
                p.limit_up
            };
            if let Some(l) = lim {
                a = a.clamp(-l, l);
            }
            (x + a * dt, a)
        }
    }
}

/// Fit %: 100 (1 − ‖y − ŷ‖ / ‖y − ȳ‖), as MATLAB's `compare` reports it.
pub fn fit_percent(measured: &[f64], predicted: &[f64]) -> f64 {
    let n = measured.len().min(predicted.len());
    if n == 0 {
        return 0.0;
    }
    let mean = measured[..n].iter().sum::<f64>() / n as f64;
    let err: f64 = (0..n).map(|i| (measured[i] - predicted[i]).powi(2)).sum();
    let spread: f64 = measured[..n].iter().map(|y| (y - mean).powi(2)).sum();
    if spread <= 0.0 {
        return 0.0;
    }
    100.0 * (1.0 - (err / spread).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_model_waits_out_the_dead_time_then_lags() {
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.01).collect();
        let ch = Channel {
            cmd: vec![0.2; 100],
            measured: vec![0.0; 100],
        };
        let p = Params {
            dead_time_s: 0.1,
            time_constant_s: 0.2,
            limit_up: None,
            limit_down: None,
            accel_limit: None,
        };
        let y = simulate(Kind::Steering, &p, &t, &ch, 0, 100);
        // Before t = d the command is the measured state before the log (0).
        assert_eq!(y[9], 0.0);
        assert!(y[10] > 0.0);
        let want = 0.2 * (1.0 - (-(0.99 - 0.09) / 0.2_f64).exp());
        assert!((y[99] - want).abs() < 1e-9, "{} vs {want}", y[99]);
    }
}
