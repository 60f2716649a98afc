//! Child processes speaking newline-delimited text (external planners and detectors): each in its own process group, one deadline over writing a request and reading the answer, bounded output, the group killed when done, exit status and stderr in every failure, and a circuit breaker for commands that keep timing out.

mod breaker;
mod call;
mod command;
mod hello;
mod pool;
mod process;
mod tree;

pub use breaker::{BREAKER_THRESHOLD, Breaker};
pub use call::Callee;
pub use command::{CommandConfig, MAX_TIMEOUT_S};
pub use pool::release_pooled;
pub use process::{EnvPolicy, ExchangeError, MAX_LINE_BYTES, Process, Spawn, clip, kill_all};
pub use tree::adopt_orphans;
