//! Errors of the bindings, made without the interpreter lock and turned into Python exceptions after.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::PyErr;

/// What went wrong, as the library says it: bad input or parameters (`ValueError`) or a file that cannot be
/// read or written (`OSError`).
#[derive(Debug)]
pub(crate) enum Failure {
    /// Bad input: `ValueError`.
    Value(String),
    /// A file system failure: `OSError`.
    Os(String),
}

impl Failure {
    /// A `ValueError` with the error's message.
    pub(crate) fn value(e: impl std::fmt::Display) -> Self {
        Self::Value(e.to_string())
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> Self {
        match f {
            Failure::Value(m) => PyValueError::new_err(m),
            Failure::Os(m) => PyOSError::new_err(m),
        }
    }
}

/// `From` for the library's errors that are always bad input.
macro_rules! value_errors {
    ($($t:ty),*) => {
        $(impl From<$t> for Failure {
            fn from(e: $t) -> Self {
                Self::value(e)
            }
        })*
    };
}

value_errors!(
    ktree::space::SpaceError,
    ktree::rays::RayError,
    ktree::ops::OpsError,
    ktree::display::DisplayError
);

impl From<ktree::solid::SolidError> for Failure {
    fn from(e: ktree::solid::SolidError) -> Self {
        match e {
            ktree::solid::SolidError::Io { .. } => Self::Os(e.to_string()),
            other => Self::value(other),
        }
    }
}
