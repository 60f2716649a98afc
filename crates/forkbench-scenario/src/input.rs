//! Reading a scenario or world file: capped in bytes, regular files only, a parse error's message kept short.

use std::path::Path as FsPath;

use super::hints;
use crate::ScenarioError;

/// Largest scenario or world file read: far above any real one, and a bound on what a
/// wrong path (a device, a huge file) can make the loader read.
pub const MAX_INPUT_BYTES: u64 = 4 << 20;

/// Longest parse message passed on: toml quotes the offending input, which for a
/// pathological file can be most of it.
const MAX_MESSAGE_CHARS: usize = 2000;

/// The text of the file at `path`, within [`MAX_INPUT_BYTES`].
pub(crate) fn read(path: &FsPath) -> Result<String, ScenarioError> {
    // The one capped reader: regular files only, so a FIFO or a device is refused at once
    // instead of blocking or growing without end.
    forkbench_core::files::read_text(path, MAX_INPUT_BYTES).map_err(|e| match e {
        forkbench_core::files::FileError::Io { cause, .. } => ScenarioError::Read {
            file: path.display().to_string(),
            cause,
        },
        other => {
            let file = path.display().to_string();
            let message = other.to_string();
            let message = message
                .strip_prefix(&format!("{file}: "))
                .unwrap_or(&message)
                .to_owned();
            ScenarioError::Parse { file, message }
        }
    })
}

/// `text` of `file` as `T`; the error names the file and line, and a key that landed in
/// the wrong table.
pub(crate) fn parse<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
) -> Result<T, ScenarioError> {
    toml::from_str(text).map_err(|e| {
        let mut message = crate::text::compact_numbers(e.to_string().trim_end());
        let hint = hints::misplaced_key(
            text,
            &message,
            // An empty span is the document's: a top-level key is missing.
            e.span().filter(|s| !s.is_empty()).map(|s| s.start),
        );
        if message.chars().count() > MAX_MESSAGE_CHARS {
            message = message.chars().take(MAX_MESSAGE_CHARS).collect::<String>() + " …";
        }
        if let Some(hint) = hint {
            message = format!("{message}\n{hint}");
        }
        ScenarioError::Parse {
            file: file.to_owned(),
            message,
        }
    })
}
