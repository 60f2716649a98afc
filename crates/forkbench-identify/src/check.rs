//! What a log must show before a fit is worth making: enough samples and time, commands that move and a response that follows.

use crate::IdentifyError;
use crate::log::{Channel, Run};
use crate::model::{Kind, channel};

/// Fewest samples over a channel's runs.
const MIN_SAMPLES: usize = 100;
/// Shortest logged time over a channel's runs.
const MIN_DURATION_S: f64 = 2.0;

/// Refuses a channel whose log is too short or whose command never moves.
pub fn enough(kind: Kind, runs: &[&Run]) -> Result<(), IdentifyError> {
    let name = match kind {
        Kind::Steering => "steering",
        Kind::Drive => "drive",
    };
    let samples: usize = runs.iter().map(|r| r.t_s.len()).sum();
    let duration: f64 = runs
        .iter()
        .map(|r| r.t_s.last().copied().unwrap_or(0.0) - r.t_s.first().copied().unwrap_or(0.0))
        .sum();
    if samples < MIN_SAMPLES || duration < MIN_DURATION_S {
        return Err(IdentifyError::TooShort {
            channel: name,
            samples,
            duration_s: duration,
        });
    }
    let threshold = match kind {
        Kind::Steering => 0.01,
        Kind::Drive => 0.02,
    };
    let span = span_of(runs, kind, |c| &c.cmd);
    // NaN-safe: an empty or non-finite span is no excitation either.
    if span.is_nan() || span < threshold {
        return Err(IdentifyError::NoExcitation {
            channel: name,
            span: span.max(0.0),
            threshold,
        });
    }
    // A response that never moves (a wheel held at its stop, a sensor stuck) says nothing
    // of the dynamics: any dead time, lag and limit fit it.
    let moved = span_of(runs, kind, |c| &c.measured);
    if moved.is_nan() || moved < threshold {
        return Err(IdentifyError::NoResponse {
            channel: name,
            span: moved.max(0.0),
            threshold,
        });
    }
    Ok(())
}

/// How far `values` of the channel range over all runs.
fn span_of(runs: &[&Run], kind: Kind, values: impl Fn(&Channel) -> &Vec<f64>) -> f64 {
    let (lo, hi) = runs
        .iter()
        .filter_map(|r| channel(r, kind))
        .flat_map(|c| values(c).iter().copied())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    hi - lo
}
