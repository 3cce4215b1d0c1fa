//! The error type of the solids module.

use std::path::PathBuf;

use crate::rays::RayError;
use crate::space::SpaceError;
use thiserror::Error;

/// Errors when turning a solid (quadric, mesh, volume) into rays.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SolidError {
    /// The universe level is not allowed.
    #[error(transparent)]
    Space(#[from] SpaceError),
    /// The generated rays were rejected (a bug if it ever happens: generators clip to the universe).
    #[error(transparent)]
    Rays(#[from] RayError),
    /// A number could not be read.
    #[error("cannot read '{text}' as a number: {why}")]
    BadNumber {
        /// The text.
        text: String,
        /// Why.
        why: &'static str,
    },
    /// A matrix or parameter list has the wrong shape or value.
    #[error("{0}")]
    BadParameter(String),
    /// Integer coefficients too large for exact evaluation at this level.
    #[error(
        "coefficients too large for exact evaluation at level {level} (largest |entry| {largest})"
    )]
    TooLarge {
        /// The level asked for.
        level: u32,
        /// The largest matrix entry.
        largest: i128,
    },
    /// The result would hold more runs than [`crate::solid::MAX_RAYS`].
    #[error("the solid has more than {limit} rays at level {level}: use a smaller level")]
    TooManyRays {
        /// The level asked for.
        level: u32,
        /// The limit.
        limit: usize,
    },
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A file could not be parsed.
    #[error("{path}: {what}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the line or byte where known.
        what: String,
    },
}
