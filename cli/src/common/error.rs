//! Why a command failed: the one error type every subcommand returns.

use std::fmt;

/// Why a command failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CliError {
    /// Standard output was closed by its reader (`ktree stats A | head` takes what it wants and goes): the
    /// command ends quietly and successfully.
    OutputClosed,
    /// Anything else, as the one line written to standard error.
    Failed(String),
}

/// What a subcommand returns.
pub type CliResult<T = ()> = Result<T, CliError>;

impl CliError {
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
        }
    }
}

impl std::error::Error for CliError {}

/// A failed read of a tree (a file read in place that changed after it was opened), as a command's
/// error: what the generic code over any storage maps its reads' errors with.
pub fn read_error(e: impl Into<ktree::tree::StorageError>) -> CliError {
    CliError::Failed(e.into().to_string())
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
        assert_eq!(CliError::from_output(closed), CliError::OutputClosed);
        let full = std::io::Error::other("disk full");
        let CliError::Failed(message) = CliError::from_output(full) else {
            panic!("a full disk is a failure");
        };
        assert!(message.contains("disk full"), "{message}");
    }
}
