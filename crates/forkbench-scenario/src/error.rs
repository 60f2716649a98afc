//! Why a scenario or world file cannot be used, naming the file and field.

/// A scenario or world file that cannot be used, with the file and field named.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The reason is in the message, not chained as a source: `{:#}` would print it twice.
    #[error("{file}: {cause}")]
    Read { file: String, cause: std::io::Error },
    /// Syntax or type error; toml's message carries line and column.
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
    #[error("{file}: field `{field}`: {reason}")]
    Invalid {
        file: String,
        field: String,
        reason: String,
    },
    /// A scenario of several cases run without naming one (`--case`, or `case=`).
    #[error(
        "{file}: has {count} cases; name one (`--case` on the command line, `case=` in Python; cases: {known})"
    )]
    CaseNeeded {
        file: String,
        count: usize,
        known: String,
    },
    #[error("{file}: no case named {case:?} (cases: {known})")]
    UnknownCase {
        file: String,
        case: String,
        known: String,
    },
}
