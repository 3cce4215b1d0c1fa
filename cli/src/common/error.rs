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
}

/// What a subcommand returns.
pub type CliResult<T = ()> = Result<T, CliError>;

impl CliError {
    /// A library error as a command's error, its causes kept.
    pub fn caused(e: impl Error + Send + Sync + 'static) -> Self {
        Self::Caused(Box::new(e))
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
        }
    }
}

pub use ktree::fs::error_chain as chain;

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
}
