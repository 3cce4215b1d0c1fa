//! Errors of the bindings, made without the interpreter lock and turned into Python exceptions after.

use ktree::fs::error_chain;
use std::io::ErrorKind;
use std::path::Path;

use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyIsADirectoryError, PyNotADirectoryError, PyOSError,
    PyPermissionError, PyValueError,
};
use pyo3::PyErr;

/// What went wrong, as the library says it: bad input or parameters (`ValueError`) or a file that cannot be
/// read or written (`OSError`, or the subclass its kind names, with `filename` set).
#[derive(Debug)]
pub(crate) enum Failure {
    /// Bad input: `ValueError`.
    Value(String),
    /// A file system failure: `OSError` or a subclass.
    Os {
        /// What failed, as `std::io` says it.
        kind: ErrorKind,
        /// The system's error number, where there is one (`errno`).
        errno: i32,
        /// The message (`strerror`): the library's whole message, naming the file.
        message: String,
        /// The file (`filename`).
        filename: String,
    },
}

impl Failure {
    /// The failure of an error or a message: an `OSError` (or subclass) if a [`std::io::Error`] is among
    /// the error's causes, else a `ValueError`; the message is the error with its causes (`A: B: C`).
    pub(crate) fn value(e: impl Into<Box<dyn std::error::Error + Send + Sync + 'static>>) -> Self {
        let e = e.into();
        let path = e
            .downcast_ref::<ktree::fs::FileOpError>()
            .map(|f| f.path().to_path_buf())
            .unwrap_or_default();
        Self::of_error(e.as_ref(), &path)
    }

    /// An `OSError` (or subclass) for `path` if an `std::io::Error` is `e` or among its causes (the one the
    /// system gave, with its errno, where there is one), else a `ValueError`; the message is `e` with its
    /// causes.
    pub(crate) fn of_error(e: &(dyn std::error::Error + 'static), path: &Path) -> Self {
        let mut io: Option<&std::io::Error> = None;
        let mut cause = Some(e);
        while let Some(c) = cause {
            if let Some(found) = c.downcast_ref::<std::io::Error>() {
                if io.is_none() || found.raw_os_error().is_some() {
                    io = Some(found);
                }
            }
            cause = c.source();
        }
        match io {
            Some(io) => Self::Os {
                kind: io.kind(),
                errno: io.raw_os_error().unwrap_or(0),
                message: error_chain(e),
                filename: path.display().to_string(),
            },
            None => Self::Value(error_chain(e)),
        }
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> Self {
        match f {
            Failure::Value(m) => PyValueError::new_err(m),
            Failure::Os {
                kind,
                errno,
                message,
                filename,
            } => {
                let args = (errno, message, filename);
                match kind {
                    ErrorKind::NotFound => PyFileNotFoundError::new_err(args),
                    ErrorKind::PermissionDenied => PyPermissionError::new_err(args),
                    ErrorKind::AlreadyExists => PyFileExistsError::new_err(args),
                    ErrorKind::IsADirectory => PyIsADirectoryError::new_err(args),
                    ErrorKind::NotADirectory => PyNotADirectoryError::new_err(args),
                    _ => PyOSError::new_err(args),
                }
            }
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
        match &e {
            ktree::solid::SolidError::Io { path, .. } => Self::of_error(&e, &path.clone()),
            _ => Self::value(e),
        }
    }
}
