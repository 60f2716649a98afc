//! The circuit breaker: after a command times out several times in a row, its remaining requests fail at once instead of each waiting out its deadline.

use std::collections::HashMap;
use std::sync::{Mutex, PoisonError};

/// Consecutive timeouts of one command that open its breaker.
pub const BREAKER_THRESHOLD: u32 = 3;

/// Consecutive timeouts per command, shared by every worker thread of this process.
#[derive(Debug, Default)]
pub struct Breaker {
    timeouts: Mutex<HashMap<String, u32>>,
}

impl Breaker {
    /// Refuses a request of `command` when its breaker is open, saying why.
    pub fn check(&self, command: &str) -> Result<(), crate::ExchangeError> {
        let map = self.timeouts.lock().unwrap_or_else(PoisonError::into_inner);
        match map.get(command) {
            Some(&n) if n >= BREAKER_THRESHOLD => Err(crate::ExchangeError::other(format!(
                "not started: {command} timed out {n} times in a row, so its remaining \
                 requests fail at once (circuit breaker)"
            ))),
            _ => Ok(()),
        }
    }

    /// Counts a request's end: a timeout adds one, anything else closes the count.
    pub fn record(&self, command: &str, timed_out: bool) {
        let mut map = self.timeouts.lock().unwrap_or_else(PoisonError::into_inner);
        if timed_out {
            *map.entry(command.to_owned()).or_default() += 1;
        } else if map.get(command).is_some_and(|&n| n < BREAKER_THRESHOLD) {
            map.remove(command);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opens_after_consecutive_timeouts_only() {
        let b = Breaker::default();
        b.record("p", true);
        b.record("p", true);
        b.record("p", false);
        b.record("p", true);
        assert!(b.check("p").is_ok());
        b.record("p", true);
        b.record("p", true);
        let e = b.check("p").expect_err("open");
        assert!(e.message.contains("timed out 3 times in a row"), "{e}");
        assert!(b.check("q").is_ok());
    }
}
