//! Errors of the shape operations.
use thiserror::Error;

/// Errors of the shape operations.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ShapeError {
    /// The radius is negative, NaN or infinite: give a finite number ≥ 0.
    #[error("radius {0} is not a finite number >= 0")]
    BadRadius(f64),
    /// The element's slice across the columns has too many offsets for the radius asked for: use a
    /// smaller radius (each offset is one pass over the runs).
    #[error("a radius of {radius} needs {offsets} column offsets (at most {limit}); use a smaller radius")]
    RadiusTooLarge {
        /// The radius asked for.
        radius: f64,
        /// The number of column offsets of its element.
        offsets: u128,
        /// The largest number allowed.
        limit: u128,
    },
    /// A closing's radius reaches more than four universe sides past the universe: its unbounded
    /// dilation would cover too many columns. Use a radius of at most `4 · side`.
    #[error("a closing by radius {radius} reaches past 4 × the universe's side {side}; use a smaller radius")]
    ClosingTooWide {
        /// The radius asked for.
        radius: f64,
        /// The universe's side.
        side: u64,
    },
    /// A band's width is negative, NaN or infinite: give a finite number ≥ 0.
    #[error("band width {0} is not a finite number >= 0")]
    BadWidth(f64),
    /// A point of a distance query lies outside the universe: give voxels in `0..side` on every axis.
    #[error("point {point:?} is outside the universe (side {side})")]
    PointOutside {
        /// The point.
        point: Vec<u32>,
        /// The universe's side.
        side: u64,
    },
    /// A window leaves the universe or holds more than 2^31 voxels: give `origin + shape ≤ side` on every
    /// axis and a smaller window.
    #[error("window at {origin:?} of shape {shape:?} leaves the universe (side {side}) or holds more than 2^31 voxels")]
    Window {
        /// The window's first voxel.
        origin: Vec<u32>,
        /// Its extent along each axis.
        shape: Vec<usize>,
        /// The universe's side.
        side: u64,
    },
    /// The connectivity is not in `1..=K`.
    #[error("connectivity {connectivity} is not in 1..={k}")]
    Connectivity {
        /// The connectivity asked for.
        connectivity: usize,
        /// The dimension.
        k: usize,
    },
    /// Reading the input tree failed (a file read in place was changed after it was opened).
    #[error(transparent)]
    Storage(#[from] crate::tree::StorageError),
    /// The Euler number is defined for connectivity 1 and `K` only (scikit-image: 4 or 8 in 2-D, 6 or 26 in 3-D).
    #[error("the Euler number in {k}-D is defined for connectivity 1 or {k}, not {connectivity}")]
    EulerConnectivity {
        /// The connectivity asked for.
        connectivity: usize,
        /// The dimension.
        k: usize,
    },
}

/// Checks a connectivity against `1..=K`.
pub(crate) fn check_connectivity<const K: usize>(connectivity: usize) -> Result<(), ShapeError> {
    if (1..=K).contains(&connectivity) {
        Ok(())
    } else {
        Err(ShapeError::Connectivity { connectivity, k: K })
    }
}
