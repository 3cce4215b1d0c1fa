//! Where in an input a problem was found, and the one error type of every file format: a [`Location`] (the
//! file and a byte offset or a line) with the format's own kind of problem.

use std::fmt;
use std::path::{Path, PathBuf};

/// A place in an input: a byte offset (binary formats), a 1-based line (text formats), or the whole file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Place {
    /// The problem is about the whole input (it cannot be opened, say).
    Whole,
    /// The byte offset where the problem was found.
    Byte(u64),
    /// The 1-based line where the problem was found.
    Line(usize),
}

/// Where in an input a problem was found: the file (or a name for the input) and the place in it.
///
/// ```
/// use ktree::io::{Location, Place};
/// assert_eq!(Location::new("a.ktree", Place::Byte(24)).to_string(), "a.ktree: byte 24");
/// assert_eq!(Location::new("a.rays", Place::Line(3)).to_string(), "a.rays:3");
/// assert_eq!(Location::new("a.rays", Place::Whole).to_string(), "a.rays");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Location {
    /// The file, or a name for the input.
    pub file: PathBuf,
    /// The place in it.
    pub place: Place,
}

impl Location {
    /// A place in a file.
    pub fn new(file: impl Into<PathBuf>, place: Place) -> Self {
        Self {
            file: file.into(),
            place,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.place {
            Place::Whole => write!(f, "{}", self.file.display()),
            Place::Byte(offset) => write!(f, "{}: byte {offset}", self.file.display()),
            Place::Line(line) => write!(f, "{}:{line}", self.file.display()),
        }
    }
}

/// A format's kind of problem: a message, and the I/O failure behind it if there is one.
pub trait ProblemKind: fmt::Display + fmt::Debug {
    /// The I/O failure this problem is, if it is one (it becomes the error's
    /// [`source`](std::error::Error::source)).
    fn io_cause(&self) -> Option<&std::io::Error>;
}

/// An error in an input file: where it was found, and what was wrong (a format's own kind).
///
/// ```
/// use ktree::io::{read_rays, Place};
/// let e = read_rays("2 3\n1 5 4\n".as_bytes(), "bad.rays").unwrap_err();
/// assert_eq!(e.location.place, Place::Line(2));
/// assert_eq!(e.line(), Some(2));
/// assert!(e.to_string().starts_with("bad.rays:2: "));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileError<Kind> {
    /// Where.
    pub location: Location,
    /// What was wrong.
    pub kind: Kind,
}

impl<Kind> FileError<Kind> {
    /// A problem at a byte offset of `file`.
    pub fn at_byte(file: impl Into<PathBuf>, offset: u64, kind: Kind) -> Self {
        Self {
            location: Location::new(file, Place::Byte(offset)),
            kind,
        }
    }

    /// A problem on a 1-based line of `file` (line 0: the whole file).
    pub fn at_line(file: impl Into<PathBuf>, line: usize, kind: Kind) -> Self {
        let place = if line == 0 {
            Place::Whole
        } else {
            Place::Line(line)
        };
        Self {
            location: Location::new(file, place),
            kind,
        }
    }

    /// The file (or the name of the input).
    pub fn file(&self) -> &Path {
        &self.location.file
    }

    /// The byte offset, for a problem found at one.
    pub fn offset(&self) -> Option<u64> {
        match self.location.place {
            Place::Byte(offset) => Some(offset),
            _ => None,
        }
    }

    /// The 1-based line, for a problem found on one.
    pub fn line(&self) -> Option<usize> {
        match self.location.place {
            Place::Line(line) => Some(line),
            _ => None,
        }
    }
}

impl<Kind: fmt::Display> fmt::Display for FileError<Kind> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location, self.kind)
    }
}

impl<Kind: ProblemKind> std::error::Error for FileError<Kind> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.kind.io_cause().map(|e| e as _)
    }
}
