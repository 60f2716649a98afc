//! One external planner process: spawn, handshake, a request/response with a deadline, kill.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path as FsPath, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::protocol::{Hello, PROTOCOL, VERSION};

/// Longest line read from a planner: far above a 200 m path at 1 cm, and a bound on what
/// a runaway planner can make forkbench hold.
pub const MAX_LINE_BYTES: u64 = 64 << 20;

/// Bytes of the planner's stderr kept for error messages.
const STDERR_TAIL_BYTES: usize = 2000;

/// A running planner with its stdout read on a thread, so reads can time out.
#[derive(Debug)]
pub struct Process {
    child: Child,
    stdin: ChildStdin,
    lines: Receiver<std::io::Result<String>>,
    stderr: Arc<Mutex<Vec<u8>>>,
    /// Disconnects when the stderr reader has seen end of file.
    stderr_done: Receiver<()>,
}

impl Process {
    /// Starts `command` in `dir` and exchanges hellos within `timeout`.
    pub fn start(command: &[String], dir: &FsPath, timeout: Duration) -> Result<Self, String> {
        let (program, args) = command
            .split_first()
            .ok_or_else(|| "the command is empty".to_owned())?;
        let mut child = Command::new(program)
            .args(args)
            .current_dir(dir)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("could not start {program:?} in {}: {e}", dir.display()))?;
        let (Some(stdin), Some(stdout), Some(stderr)) =
            (child.stdin.take(), child.stdout.take(), child.stderr.take())
        else {
            let _ = child.kill();
            return Err("the planner's pipes could not be opened".into());
        };
        let (stderr, stderr_done) = spawn_stderr_tail(stderr);
        let mut p = Self {
            child,
            stdin,
            lines: spawn_line_reader(stdout),
            stderr,
            stderr_done,
        };
        p.handshake(timeout)?;
        Ok(p)
    }

    fn handshake(&mut self, timeout: Duration) -> Result<(), String> {
        let hello = serde_json::to_string(&Hello::ours()).map_err(|e| e.to_string())?;
        let line = self.exchange(&hello, timeout)?;
        let theirs: Hello = serde_json::from_str(&line)
            .map_err(|e| format!("invalid hello {:?}: {e}", clip(&line)))?;
        if theirs.kind != "hello" || theirs.protocol != PROTOCOL {
            return Err(format!(
                "the first line must be a {PROTOCOL} hello, got {:?}",
                clip(&line)
            ));
        }
        if theirs.version != VERSION {
            return Err(format!(
                "the planner speaks protocol version {}, forkbench speaks {VERSION}",
                theirs.version
            ));
        }
        Ok(())
    }

    /// Sends one line and waits at most `timeout` for the answer line.
    pub fn exchange(&mut self, line: &str, timeout: Duration) -> Result<String, String> {
        let sent = writeln!(self.stdin, "{line}").and_then(|()| self.stdin.flush());
        if let Err(e) = sent {
            return Err(self.died(&format!("could not write to the planner ({e})")));
        }
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            return match self.lines.recv_timeout(left) {
                Ok(Ok(l)) if l.trim().is_empty() => continue,
                Ok(Ok(l)) => Ok(l),
                Ok(Err(e)) => Err(self.died(&format!("reading its output failed: {e}"))),
                Err(RecvTimeoutError::Timeout) => Err(format!(
                    "no answer within {:.3} s (timeout_s); the planner was stopped",
                    timeout.as_secs_f64()
                )),
                Err(RecvTimeoutError::Disconnected) => {
                    Err(self.died("the planner closed its output"))
                }
            };
        }
    }

    /// A message for a planner that went away: its exit status and the tail of stderr.
    fn died(&mut self, what: &str) -> String {
        // Give a crashing process a moment to be reaped so its status can be reported.
        let deadline = Instant::now() + Duration::from_millis(200);
        let status = loop {
            match self.child.try_wait() {
                Ok(Some(s)) => break Some(s),
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(5));
                }
                _ => break None,
            }
        };
        // The stderr reader may still be draining the pipe: wait for its end of file (bounded,
        // since a grandchild could hold the pipe open) so the message carries the whole tail.
        let _ = self.stderr_done.recv_timeout(Duration::from_millis(500));
        let mut msg = what.to_owned();
        if let Some(s) = status {
            msg.push_str(&format!(" (it exited: {s})"));
        }
        let tail = self.stderr.lock().map(|b| b.clone()).unwrap_or_default();
        let tail = String::from_utf8_lossy(&tail);
        if !tail.trim().is_empty() {
            msg.push_str(&format!("; stderr: {}", tail.trim()));
        }
        msg
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn spawn_line_reader(stdout: impl Read + Send + 'static) -> Receiver<std::io::Result<String>> {
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        let mut r = BufReader::new(stdout);
        loop {
            let mut line = String::new();
            let got = (&mut r).take(MAX_LINE_BYTES).read_line(&mut line);
            let stop = match &got {
                Ok(0) => true,
                Ok(_) if !line.ends_with('\n') && line.len() as u64 >= MAX_LINE_BYTES => {
                    let _ = tx.send(Err(std::io::Error::other(format!(
                        "a line longer than {MAX_LINE_BYTES} bytes"
                    ))));
                    true
                }
                Ok(_) => tx.send(Ok(line)).is_err(),
                Err(_) => true,
            };
            if let Err(e) = got {
                let _ = tx.send(Err(e));
            }
            if stop {
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
    let (done_tx, done_rx) = channel::<()>();
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

/// At most 200 characters of a line, for messages.
pub fn clip(line: &str) -> String {
    let t = line.trim_end();
    if t.chars().count() > 200 {
        t.chars().take(200).collect::<String>() + " …"
    } else {
        t.to_owned()
    }
}

/// Where a planner defined in `file` runs: that file's directory.
pub fn dir_of(file: &FsPath) -> PathBuf {
    file.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), FsPath::to_path_buf)
}
