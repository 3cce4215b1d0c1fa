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
    /// Points of a cloud lie outside the universe of the level asked for (and were not to be cropped): how
    /// many, and the first of them. A larger level or voxel size, another origin, or cropping fixes it.
    #[error("{count} points lie outside the universe of level {level} (side {} voxels); the first is point {first} {point:?} in voxel {voxel:?}", side(.level))]
    PointsOutside {
        /// How many points.
        count: u64,
        /// The level of the universe.
        level: u32,
        /// The index of the first point outside.
        first: usize,
        /// That point.
        point: [f64; 3],
        /// Its voxel, `floor((point − origin) / voxel size)`.
        voxel: [f64; 3],
    },
    /// A point of a cloud lies below the origin given, along an axis, and no level was given (whose
    /// universe could crop it). Another origin, or a level and cropping, fixes it.
    #[error("point {index} {point:?} lies below the origin {origin:?} along axis {axis}")]
    PointBelowOrigin {
        /// The index of the point.
        index: usize,
        /// The point.
        point: [f64; 3],
        /// The origin.
        origin: [f64; 3],
        /// The axis (0, 1, 2).
        axis: usize,
    },
    /// A file could not be read.
    #[error("cannot read {}", path.display())]
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

/// The side of a universe of level `level`, in voxels.
fn side(level: &u32) -> u64 {
    2u64.saturating_pow(*level)
}
