//! Why a command failed: the one error type every subcommand returns, printed with its causes in one line
//! (`ktree: cannot write out.ktree: No space left on device`).

use std::error::Error;
use std::fmt;

/// Why a command failed.
#[derive(Debug)]
pub enum CliError {
    /// Standard output was closed by its reader (`ktree stats A | head` takes what it wants and goes): the
    /// command ends quietly and successfully.
    OutputClosed,
    /// A message of the command's own, the one line written to standard error.
    Failed(String),
    /// An error of the library, kept whole: written with its causes after it ([`chain`]).
    Caused(Box<dyn Error + Send + Sync>),
    /// An error of the library about something its message does not name (a file, an option), kept
    /// whole: written after what it is about, with its causes (`in.obj: …: cause`).
    About(String, Box<dyn Error + Send + Sync>),
}

/// What a subcommand returns.
pub type CliResult<T = ()> = Result<T, CliError>;

impl CliError {
    /// A library error as a command's error, its causes kept.
    pub fn caused(e: impl Error + Send + Sync + 'static) -> Self {
        Self::Caused(Box::new(e))
    }

    /// A library error about `what` (a file's path, an option), its causes kept: written `what: error:
    /// causes`, or as [`caused`](Self::caused) when its message already names `what` (said once).
    pub fn about(what: impl fmt::Display, e: impl Error + Send + Sync + 'static) -> Self {
        let what = what.to_string();
        if names(&chain(&e), &what) {
            Self::caused(e)
        } else {
            Self::About(what, Box::new(e))
        }
    }

    /// A library error about the file `path` ([`about`](Self::about)).
    pub fn in_file(path: &std::path::Path, e: impl Error + Send + Sync + 'static) -> Self {
        Self::about(path.display(), e)
    }

    /// The error said about `what` (the file a command's step read): `what: error`, unless its message
    /// names `what` already.
    pub fn within(self, what: impl fmt::Display) -> Self {
        let what = what.to_string();
        if names(&self.to_string(), &what) {
            return self;
        }
        match self {
            Self::OutputClosed => Self::OutputClosed,
            Self::Failed(message) => Self::Failed(format!("{what}: {message}")),
            Self::Caused(e) => Self::About(what, e),
            Self::About(inner, e) => Self::About(format!("{what}: {inner}"), e),
        }
    }

    /// What a failed write to standard output is reported as: a closed pipe ends the command quietly.
    pub fn from_output(e: std::io::Error) -> Self {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            Self::OutputClosed
        } else {
            Self::Failed(format!("cannot write to standard output: {e}"))
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::OutputClosed => f.write_str("standard output closed"),
            Self::Failed(message) => f.write_str(message),
            Self::Caused(e) => f.write_str(&chain(e.as_ref())),
            Self::About(what, e) => write!(f, "{what}: {}", chain(e.as_ref())),
        }
    }
}

pub use ktree::fs::error_chain as chain;

/// Whether `message` names `what` (a path, an option) as a word of its own: not inside a longer name
/// (`a.ktree` is not named by `data.ktree`). An empty `what` is named by any message.
fn names(message: &str, what: &str) -> bool {
    let apart = |c: Option<char>| c.is_none_or(|c| c.is_whitespace() || "'\"`()[],;:".contains(c));
    what.is_empty()
        || message.match_indices(what).any(|(at, _)| {
            apart(message[..at].chars().next_back())
                && apart(message[at + what.len()..].chars().next())
        })
}

/// A failed read of the file `path`, as a command's error: `cannot read PATH: cause`.
pub fn cannot_read(path: &std::path::Path, e: std::io::Error) -> CliError {
    CliError::caused(ktree::fs::FileOpError::new(
        ktree::fs::FileOp::Read,
        path,
        e,
    ))
}

/// A failed read of a tree (a file read in place that changed after it was opened), as a command's
/// error: what the generic code over any storage maps its reads' errors with.
pub fn read_error(e: impl Into<ktree::tree::StorageError>) -> CliError {
    CliError::caused(e.into())
}

impl From<String> for CliError {
    fn from(message: String) -> Self {
        Self::Failed(message)
    }
}

impl From<&str> for CliError {
    fn from(message: &str) -> Self {
        Self::Failed(message.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_broken_pipe_is_a_quiet_end_and_other_write_errors_fail() {
        let closed = std::io::Error::from(std::io::ErrorKind::BrokenPipe);
        assert!(matches!(
            CliError::from_output(closed),
            CliError::OutputClosed
        ));
        let full = std::io::Error::other("disk full");
        let CliError::Failed(message) = CliError::from_output(full) else {
            panic!("a full disk is a failure");
        };
        assert!(message.contains("disk full"), "{message}");
    }

    #[test]
    fn a_chain_is_one_line_with_every_cause_once() {
        let io = std::io::Error::from_raw_os_error(20);
        let e = ktree::fs::FileOpError::new(
            ktree::fs::FileOp::Write,
            std::path::Path::new("plain/out.ktree"),
            io,
        );
        let text = CliError::caused(e).to_string();
        assert!(text.starts_with("cannot write plain/out.ktree: "), "{text}");
        assert_eq!(text.matches("plain/out.ktree").count(), 1, "{text}");
        assert!(text.to_lowercase().contains("not a directory"), "{text}");
        assert!(!text.contains('\n'));
    }

    #[test]
    fn what_an_error_is_about_is_said_once() {
        let gone = || std::io::Error::from(std::io::ErrorKind::NotFound);
        let text = cannot_read(std::path::Path::new("in/gone.ktree"), gone()).to_string();
        assert!(text.starts_with("cannot read in/gone.ktree: "), "{text}");
        // The file named by the error is not named again before it.
        let named = ktree::fs::FileOpError::new(
            ktree::fs::FileOp::Read,
            std::path::Path::new("in/gone.ktree"),
            gone(),
        );
        let text = CliError::about("in/gone.ktree", named).to_string();
        assert_eq!(text.matches("in/gone.ktree").count(), 1, "{text}");
        // An error that does not name it is said after it, its causes kept.
        let text = CliError::about("--voxel-size", gone()).to_string();
        assert!(text.starts_with("--voxel-size: "), "{text}");
        let text = CliError::in_file(std::path::Path::new("a.ktree"), gone())
            .within("a.ktree")
            .within("b.ktree")
            .to_string();
        assert!(text.starts_with("b.ktree: a.ktree: "), "{text}");
        assert_eq!(text.matches("a.ktree").count(), 1, "{text}");
        assert!(names("cannot read 'x': gone", "x") && names("x: gone", "x"));
        assert!(!names("cannot read xy.ktree: gone", "x") && !names("index 2x", "x"));
        let text = CliError::about("x", gone()).to_string();
        assert!(text.starts_with("x: "), "{text}");
        let text = CliError::from("a.ktree: too large")
            .within("a.ktree")
            .to_string();
        assert_eq!(text, "a.ktree: too large");
    }
}
