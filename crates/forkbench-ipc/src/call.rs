//! One request and its answer on this thread's pooled process for an external component: started with a hello when none waits, counted by a circuit breaker, returned to the pool only when the answer kept to the protocol.

use std::path::Path;

use crate::breaker::Breaker;
use crate::command::CommandConfig;
use crate::hello::start_with_hello;
use crate::pool::{put_back, take_pooled};
use crate::process::{ExchangeError, Spawn, clip};

/// Who is called: where the command runs, the protocol it speaks, what it is called in
/// messages, and the breaker that counts its timeouts.
#[derive(Debug, Clone, Copy)]
pub struct Callee<'a> {
    pub dir: &'a Path,
    pub protocol: &'static str,
    pub version: u64,
    /// "planner", "detector".
    pub what: &'a str,
    pub breaker: &'a Breaker,
}

impl CommandConfig {
    /// [`CommandConfig::call`] with JSON both ways: `message` builds the request for the
    /// request id, and the answer is parsed as `T`, whose `id_of` is the id it answers.
    pub fn call_json<M: serde::Serialize, T: serde::de::DeserializeOwned>(
        &self,
        callee: Callee<'_>,
        message: impl FnOnce(u64) -> M,
        id_of: impl FnOnce(&T) -> u64,
    ) -> Result<T, ExchangeError> {
        let request = |id| {
            serde_json::to_string(&message(id)).map_err(|e| ExchangeError::other(e.to_string()))
        };
        let read = |answer: &str| {
            let msg: T = serde_json::from_str(answer).map_err(|e| {
                ExchangeError::other(format!("invalid answer ({e}): {:?}", clip(answer)))
            })?;
            Ok((id_of(&msg), msg))
        };
        self.call(callee, request, read)
    }

    /// Sends the line `request` writes for the request id, and reads the answer with
    /// `read`, which returns the id it answered and the value. Err: why, for that trial.
    pub fn call<T>(
        &self,
        callee: Callee<'_>,
        request: impl FnOnce(u64) -> Result<String, ExchangeError>,
        read: impl FnOnce(&str) -> Result<(u64, T), ExchangeError>,
    ) -> Result<T, ExchangeError> {
        let key = self.breaker_key(callee.dir);
        callee.breaker.check(&key)?;
        let r = self.exchange(callee, request, read);
        callee
            .breaker
            .record(&key, r.as_ref().is_err_and(|e| e.timed_out));
        r
    }

    fn exchange<T>(
        &self,
        callee: Callee<'_>,
        request: impl FnOnce(u64) -> Result<String, ExchangeError>,
        read: impl FnOnce(&str) -> Result<(u64, T), ExchangeError>,
    ) -> Result<T, ExchangeError> {
        let pool = self.pool_key(callee.protocol, callee.dir);
        let (mut proc, id) = match take_pooled(&pool) {
            Some(p) => p,
            None => {
                let spawn = Spawn {
                    command: &self.command,
                    dir: callee.dir,
                    env: &self.env(),
                    what: callee.what,
                };
                let p = start_with_hello(spawn, callee.protocol, callee.version, self.timeout())?;
                (p, 0)
            }
        };
        let answer = proc.exchange(&request(id)?, self.timeout())?;
        let (got, value) = read(&answer)?;
        if got != id {
            return Err(ExchangeError::other(format!(
                "answered request {got}, expected {id}"
            )));
        }
        put_back(pool, proc, id + 1);
        Ok(value)
    }
}
