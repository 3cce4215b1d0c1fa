//! The error of point cloud and mesh files ([`GeometryFileError`]), and the fault the parsers return before
//! the file's name is attached to it.

use std::path::Path;

use thiserror::Error;

use super::location::{FileError, Place, ProblemKind};
use crate::fs::IoCause;

/// What was wrong with a point cloud or mesh file.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum GeometryFileErrorKind {
    /// The extension names none of the formats read (`what`: "point cloud" or "mesh"; `known`: the
    /// extensions that are).
    #[error("unknown {what} format '.{extension}' (known: {known})")]
    UnknownFormat {
        /// What was to be read.
        what: &'static str,
        /// The extension given.
        extension: String,
        /// The extensions known.
        known: String,
    },
    /// The content is malformed, contradicts itself, or declares more than the file holds.
    #[error("{0}")]
    Malformed(String),
    /// The file could not be read.
    #[error("cannot read")]
    Io(IoCause),
}

impl ProblemKind for GeometryFileErrorKind {
    fn io_cause(&self) -> Option<&std::io::Error> {
        match self {
            Self::Io(cause) => Some(cause.error()),
            _ => None,
        }
    }
}

/// An error reading a point cloud or a mesh file, with the file and the line (text) or byte offset
/// (binary) where it was found.
///
/// ```
/// use ktree::io::{read_cloud_bytes, Place};
/// let e = read_cloud_bytes(b"1 2 3\n4 five 6\n", "xyz", "c.xyz".as_ref()).unwrap_err();
/// assert_eq!(e.location.place, Place::Line(2));
/// assert_eq!(e.to_string(), "c.xyz:2: 'five' is not a number");
/// ```
pub type GeometryFileError = FileError<GeometryFileErrorKind>;

/// A problem found by a parser, with where it was found; [`Fault::in_file`] names the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Fault {
    pub(crate) place: Place,
    pub(crate) message: String,
}

impl Fault {
    /// A problem on a 1-based line.
    pub(crate) fn line(line: usize, message: impl Into<String>) -> Self {
        Self {
            place: Place::Line(line),
            message: message.into(),
        }
    }

    /// A problem at a byte offset.
    pub(crate) fn byte(offset: usize, message: impl Into<String>) -> Self {
        Self {
            place: Place::Byte(offset as u64),
            message: message.into(),
        }
    }

    /// A problem of the whole input.
    pub(crate) fn whole(message: impl Into<String>) -> Self {
        Self {
            place: Place::Whole,
            message: message.into(),
        }
    }

    /// The error of `file`.
    pub(crate) fn in_file(self, file: &Path) -> GeometryFileError {
        GeometryFileError {
            location: super::Location::new(file.display().to_string(), self.place),
            kind: GeometryFileErrorKind::Malformed(self.message),
        }
    }
}

/// The error of a file that cannot be read.
pub(crate) fn io_error(file: &Path, e: std::io::Error) -> GeometryFileError {
    GeometryFileError::at_line(
        file.display().to_string(),
        0,
        GeometryFileErrorKind::Io(e.into()),
    )
}

/// The lower-case extension of a path (empty without one).
pub(crate) fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}
