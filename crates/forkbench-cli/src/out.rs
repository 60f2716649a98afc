//! What the binary prints to standard output: text made visible (no raw control characters) and JSON lines, a closed pipe not an error.

use anyhow::Context as _;

/// Writes command output; a closed pipe (`forkbench … | head`) ends output quietly.
pub(crate) fn emit(text: &str) -> anyhow::Result<()> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    // Names come from users' files and child processes: no control character reaches
    // the terminal raw.
    let text = forkbench_trial::text::visible(text);
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other.context("writing to stdout"),
    }
}

/// Writes `value` as one JSON line to stdout, serialised as it is written (no copy of the
/// whole text in memory); a closed pipe is not an error.
pub(crate) fn emit_json_line<T: serde::Serialize>(value: &T) -> anyhow::Result<()> {
    use std::io::Write as _;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let written = serde_json::to_writer(&mut out, value)
        .map_err(std::io::Error::from)
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush());
    match written {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other.context("writing to stdout"),
    }
}
