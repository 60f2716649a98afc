//! One child process: spawned in its own process group, fed by a writer thread and read by a bounded reader, so one deadline covers the whole exchange and nothing it prints can grow without bound.

use std::collections::BTreeSet;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::process::CommandExt as _;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TryRecvError, sync_channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, killpg};
use nix::unistd::Pid;

/// Longest line read from a child: far above a 200 m path at 1 cm, and a bound on what a
/// runaway child can make forkbench hold.
pub const MAX_LINE_BYTES: u64 = 64 << 20;

/// Bytes of the child's stderr kept for error messages.
const STDERR_TAIL_BYTES: usize = 2000;

/// How often a wait for an answer looks whether the child has exited.
const POLL: Duration = Duration::from_millis(20);

/// Process groups started and not yet killed, for [`kill_all`].
static LIVE: Mutex<BTreeSet<i32>> = Mutex::new(BTreeSet::new());

/// Kills every process group this process started and has not killed yet, with every
/// descendant (in the group or not) and, where this process adopts orphans, every orphan:
/// call before exiting, so a child that ignores end of input, or its own children, do not
/// outlive it.
pub fn kill_all() {
    let groups = std::mem::take(&mut *LIVE.lock().unwrap_or_else(PoisonError::into_inner));
    for g in groups {
        crate::tree::kill_descendants(g);
        let _ = killpg(Pid::from_raw(g), Signal::SIGKILL);
    }
    crate::tree::kill_orphans();
}

/// Which environment variables a child gets.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub enum EnvPolicy {
    /// All of forkbench's own environment.
    #[default]
    Inherit,
    /// Only these variables (an allow-list), the rest cleared.
    Only(Vec<String>),
}

/// What to start.
#[derive(Debug, Clone, Copy)]
pub struct Spawn<'a> {
    /// Program and arguments.
    pub command: &'a [String],
    /// Working directory.
    pub dir: &'a Path,
    pub env: &'a EnvPolicy,
    /// What the child is, for messages ("planner").
    pub what: &'a str,
}

/// Why an exchange failed: the message (exit status and stderr included), and whether it
/// was the deadline (what the circuit breaker counts).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct ExchangeError {
    pub timed_out: bool,
    pub message: String,
}

impl ExchangeError {
    /// A failure other than the deadline.
    pub fn other(message: impl Into<String>) -> Self {
        Self {
            timed_out: false,
            message: message.into(),
        }
    }
}

/// A running child with its stdin written and its stdout read on threads.
#[derive(Debug)]
pub struct Process {
    child: Child,
    pgid: i32,
    what: String,
    to_child: Option<SyncSender<String>>,
    write_error: Arc<Mutex<Option<String>>>,
    lines: Receiver<Result<String, String>>,
    stderr: Arc<Mutex<Vec<u8>>>,
    /// Disconnects when the stderr reader has seen end of file.
    stderr_done: Receiver<()>,
}

impl Process {
    /// Starts the child in a process group of its own.
    pub fn start(s: Spawn) -> Result<Self, ExchangeError> {
        let (program, args) = s
            .command
            .split_first()
            .ok_or_else(|| ExchangeError::other("the command is empty"))?;
        let mut cmd = Command::new(program);
        cmd.args(args)
            .current_dir(s.dir)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .process_group(0);
        if let EnvPolicy::Only(keep) = s.env {
            cmd.env_clear();
            for k in keep {
                if let Some(v) = std::env::var_os(k) {
                    cmd.env(k, v);
                }
            }
        }
        let mut child = cmd.spawn().map_err(|e| {
            ExchangeError::other(format!(
                "could not start {program:?} in {}: {e}",
                s.dir.display()
            ))
        })?;
        let pgid = i32::try_from(child.id()).unwrap_or(i32::MAX);
        LIVE.lock()
            .unwrap_or_else(PoisonError::into_inner)
            .insert(pgid);
        let (Some(stdin), Some(stdout), Some(stderr)) =
            (child.stdin.take(), child.stdout.take(), child.stderr.take())
        else {
            let _ = killpg(Pid::from_raw(pgid), Signal::SIGKILL);
            let _ = child.wait();
            return Err(ExchangeError::other(format!(
                "the {}'s pipes could not be opened",
                s.what
            )));
        };
        let write_error = Arc::new(Mutex::new(None));
        let (stderr, stderr_done) = spawn_stderr_tail(stderr);
        Ok(Self {
            child,
            pgid,
            what: s.what.to_owned(),
            to_child: Some(spawn_writer(stdin, Arc::clone(&write_error))),
            write_error,
            lines: spawn_line_reader(stdout),
            stderr,
            stderr_done,
        })
    }

    /// Sends one line and waits for the answer line; `timeout` covers both, so a child
    /// that stopped reading cannot block the send.
    pub fn exchange(&mut self, line: &str, timeout: Duration) -> Result<String, ExchangeError> {
        let deadline = Instant::now() + timeout;
        let sent = self
            .to_child
            .as_ref()
            .map(|tx| tx.try_send(line.to_owned()));
        if !matches!(sent, Some(Ok(()))) {
            return Err(ExchangeError::other(
                self.died("it is not reading its input"),
            ));
        }
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left.min(POLL)) {
                Ok(Ok(l)) if l.trim().is_empty() => {}
                Ok(Ok(l)) => return Ok(l),
                Ok(Err(e)) => return Err(ExchangeError::other(self.died(&e))),
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(ExchangeError::other(
                        self.died(&format!("the {} closed its output", self.what)),
                    ));
                }
                Err(RecvTimeoutError::Timeout) => {
                    if let Ok(Some(_)) = self.child.try_wait() {
                        // It exited; an answer written just before may still be in the pipe.
                        if let Ok(Ok(l)) = self.lines.recv_timeout(Duration::from_millis(50)) {
                            return Ok(l);
                        }
                        let what = format!("the {} exited without answering", self.what);
                        return Err(ExchangeError::other(self.died(&what)));
                    }
                    if left.is_zero() {
                        return Err(ExchangeError {
                            timed_out: true,
                            message: self.timed_out(timeout),
                        });
                    }
                }
            }
        }
    }

    /// Whether it printed while nobody asked (a protocol violation that retires it). One
    /// look: a child that floods would refill the channel as fast as it is drained.
    pub fn has_idle_output(&mut self) -> bool {
        !matches!(self.lines.try_recv(), Err(TryRecvError::Empty))
    }

    fn timed_out(&mut self, timeout: Duration) -> String {
        self.kill();
        let mut msg = format!(
            "no answer within {:.3} s (timeout_s); the {} was stopped",
            timeout.as_secs_f64(),
            self.what
        );
        self.push_stderr(&mut msg);
        msg
    }

    /// A message for a child that went away: its exit status and the tail of stderr.
    fn died(&mut self, what: &str) -> String {
        // Give a crashing process a moment to be reaped so its status can be reported.
        let deadline = Instant::now() + Duration::from_millis(200);
        let status = loop {
            match self.child.try_wait() {
                Ok(Some(s)) => break Some(s),
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(5))
                }
                _ => break None,
            }
        };
        // Its children may hold the pipes open: kill the group, then let the stderr reader
        // drain what is left (bounded).
        self.kill();
        let _ = self.stderr_done.recv_timeout(Duration::from_millis(500));
        let mut msg = what.to_owned();
        if let Some(e) = self
            .write_error
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .as_ref()
        {
            msg.push_str(&format!(" (writing to it failed: {e})"));
        }
        if let Some(s) = status {
            msg.push_str(&format!(" (it exited: {s})"));
        }
        self.push_stderr(&mut msg);
        msg
    }

    fn push_stderr(&self, msg: &mut String) {
        let tail = self.stderr.lock().map(|b| b.clone()).unwrap_or_default();
        let tail = String::from_utf8_lossy(&tail);
        if !tail.trim().is_empty() {
            msg.push_str(&format!("; stderr: {}", tail.trim()));
        }
    }

    /// Kills the whole process group and reaps the child.
    fn kill(&mut self) {
        self.to_child = None;
        // Descendants first, while their parent links still lead here: one that called
        // setsid is outside the group.
        crate::tree::kill_descendants(self.pgid);
        let _ = killpg(Pid::from_raw(self.pgid), Signal::SIGKILL);
        let _ = self.child.wait();
        LIVE.lock()
            .unwrap_or_else(PoisonError::into_inner)
            .remove(&self.pgid);
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        self.kill();
    }
}

/// Writes each line (with its newline) on a thread of its own, so a child that stops
/// reading blocks that thread, not the caller.
fn spawn_writer(
    mut stdin: impl Write + Send + 'static,
    error: Arc<Mutex<Option<String>>>,
) -> SyncSender<String> {
    let (tx, rx) = sync_channel::<String>(1);
    std::thread::spawn(move || {
        for line in rx {
            let r = stdin
                .write_all(line.as_bytes())
                .and_then(|()| stdin.write_all(b"\n"))
                .and_then(|()| stdin.flush());
            if let Err(e) = r {
                *error.lock().unwrap_or_else(PoisonError::into_inner) = Some(e.to_string());
                return;
            }
        }
    });
    tx
}

/// Reads lines into a channel that holds one: a child that prints while nobody reads
/// fills its pipe and waits, instead of filling forkbench's memory.
fn spawn_line_reader(stdout: impl Read + Send + 'static) -> Receiver<Result<String, String>> {
    let (tx, rx) = sync_channel(1);
    std::thread::spawn(move || {
        let mut r = BufReader::new(stdout);
        loop {
            let mut line = String::new();
            let got = (&mut r).take(MAX_LINE_BYTES).read_line(&mut line);
            let item = match got {
                Ok(0) => return,
                Ok(_) if line.ends_with('\n') => Ok(line),
                Ok(n) if n as u64 >= MAX_LINE_BYTES => {
                    Err(format!("a line longer than {MAX_LINE_BYTES} bytes"))
                }
                Ok(n) => Err(format!(
                    "its output ended mid-line ({n} bytes without a newline)"
                )),
                Err(e) => Err(format!("reading its output failed: {e}")),
            };
            let last = item.is_err();
            if tx.send(item).is_err() || last {
                return;
            }
        }
    });
    rx
}

/// Keeps the last bytes of `stderr`; the receiver disconnects when the pipe reaches its end.
fn spawn_stderr_tail(stderr: impl Read + Send + 'static) -> (Arc<Mutex<Vec<u8>>>, Receiver<()>) {
    let tail = Arc::new(Mutex::new(Vec::new()));
    let keep = Arc::clone(&tail);
    let (done_tx, done_rx) = sync_channel::<()>(0);
    std::thread::spawn(move || {
        let _done = done_tx;
        let mut r = stderr;
        let mut buf = [0u8; 4096];
        while let Ok(n) = r.read(&mut buf) {
            if n == 0 {
                return;
            }
            if let Ok(mut t) = keep.lock() {
                t.extend_from_slice(&buf[..n]);
                let excess = t.len().saturating_sub(STDERR_TAIL_BYTES);
                t.drain(..excess);
            }
        }
    });
    (tail, done_rx)
}

/// At most 200 characters of a line, control characters escaped, for messages.
pub fn clip(line: &str) -> String {
    let t: String = line
        .trim_end()
        .chars()
        .flat_map(|c| {
            let esc: Vec<char> = if c.is_control() {
                c.escape_default().collect()
            } else {
                vec![c]
            };
            esc
        })
        .collect();
    if t.chars().count() > 200 {
        t.chars().take(200).collect::<String>() + " …"
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sh(script: &str) -> Process {
        let command = vec!["sh".to_owned(), "-c".to_owned(), script.to_owned()];
        Process::start(Spawn {
            command: &command,
            dir: Path::new("."),
            env: &EnvPolicy::Inherit,
            what: "child",
        })
        .expect("starts")
    }

    #[test]
    fn output_while_idle_is_seen_and_bounded() {
        // Answers, then floods its stdout forever.
        let mut p = sh("read l; echo answer; yes flood");
        let a = p
            .exchange("request", Duration::from_secs(5))
            .expect("answers");
        assert_eq!(a.trim(), "answer");
        std::thread::sleep(Duration::from_millis(200));
        assert!(p.has_idle_output());
        // A child that answers and then stays quiet has nothing waiting.
        let mut q = sh("read l; echo answer; sleep 1000");
        q.exchange("request", Duration::from_secs(5))
            .expect("answers");
        std::thread::sleep(Duration::from_millis(200));
        assert!(!q.has_idle_output());
    }

    #[test]
    fn a_child_that_stops_reading_times_out_and_is_killed() {
        let mut p = sh("sleep 1000");
        let big = "x".repeat(1 << 20);
        let t0 = Instant::now();
        let e = p
            .exchange(&big, Duration::from_millis(300))
            .expect_err("times out");
        assert!(e.timed_out, "{e}");
        assert!(t0.elapsed() < Duration::from_secs(3));
    }
}
