//! The error type of the operations.

use thiserror::Error;

use crate::tree::StorageError;

/// What can go wrong in an operation on k-trees. Every variant but [`OpsError::Storage`] says how to fix
/// the input.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum OpsError {
    /// A read of an input tree failed: a tree read in place from a file found the file changed (the error
    /// names the file and the byte offset). Trees in memory never fail.
    #[error(transparent)]
    Storage(#[from] StorageError),
    /// Two trees of different dimensions were combined.
    #[error("{0}: both trees must have the same dimension")]
    DimensionMismatch(crate::tree::DimensionMismatch),
    /// Two trees of different universe levels were combined. Re-level one of them first (for example with
    /// [`crate::ops::grow`], which adds root levels, or [`crate::ops::zoom`], which removes them).
    #[error("the trees have different universe levels ({left} and {right}); re-level one with grow/zoom first")]
    LevelMismatch {
        /// Level of the first tree.
        left: u32,
        /// Level of the second tree.
        right: u32,
    },
    /// The result would exceed the largest level for this dimension.
    #[error("level {level} is too large for K = {k}: the largest is {max}")]
    LevelTooLarge {
        /// The dimension.
        k: usize,
        /// The level asked for.
        level: u32,
        /// The largest level allowed.
        max: u32,
    },
    /// A child path names a child code `≥ 2^K` or is longer than the tree's level.
    #[error("bad child path {path:?} for K = {k} and level {level}: codes must be < {fanout} and the path at most {level} long")]
    BadPath {
        /// The path given.
        path: Vec<usize>,
        /// The dimension.
        k: usize,
        /// The tree's level.
        level: u32,
        /// `2^K`.
        fanout: usize,
    },
    /// A matrix has the wrong number of entries: a map in `K` dimensions is a `(K+1)×(K+1)` homogeneous
    /// matrix, given row by row.
    #[error("{given} matrix entries given, a {n}×{n} homogeneous matrix needs {}", n * n)]
    MatrixSize {
        /// Entries given.
        given: usize,
        /// `K + 1`.
        n: usize,
    },
    /// A matrix entry is infinite or NaN.
    #[error("a matrix entry is not a finite number")]
    NonFiniteEntry,
    /// An affine map's last row is not `0 … 0 1`; use a projective map for such a matrix.
    #[error("the last row must be 0 … 0 1 (an affine map), got {last_row:?}")]
    NotAffine {
        /// The last row given.
        last_row: Vec<f64>,
    },
    /// The matrix is singular: it would flatten the object. Give an invertible map.
    #[error("the matrix is singular (it flattens the object)")]
    Singular,
    /// The inverse of the map has entries or a translation too large for the fixed-point form; use fewer
    /// fractional bits or the floating-point transform.
    #[error("the inverse map's entries are too large for fixed point")]
    FixedPointOverflow,
    /// A projective map whose denominator changes sign or vanishes over the universe: it would send part
    /// of the universe to infinity. Move the viewer out of the universe.
    #[error("the map sends part of the universe to infinity (its denominator changes sign)")]
    ToInfinity,
    /// A slice's position is outside the universe.
    #[error("position {position} along axis {axis} is outside the universe (0 to {side} − 1)")]
    SliceOutside {
        /// The axis.
        axis: usize,
        /// The position given.
        position: u32,
        /// The universe's side.
        side: u64,
    },
    /// An axis is not below the dimension `K`.
    #[error("axis {axis} is not below K = {k}")]
    BadAxis {
        /// The axis given.
        axis: usize,
        /// The dimension.
        k: usize,
    },
    /// A rotation or quarter turn needs two different axes below `K`.
    #[error("a rotation needs two different axes below K = {k}, got {from} and {to}")]
    BadAxisPair {
        /// The axis turned from.
        from: usize,
        /// The axis turned to.
        to: usize,
        /// The dimension.
        k: usize,
    },
    /// An axis map's permutation is not a permutation of `0 … K−1`.
    #[error("{perm:?} is not a permutation of the axes 0..{}", perm.len())]
    NotAPermutation {
        /// The permutation given.
        perm: Vec<usize>,
    },
    /// A scale factor's numerator or denominator is outside `1 ..= 2^20`.
    #[error("scale factor {num}/{den}: both must be between 1 and 2^20")]
    BadScale {
        /// The numerator.
        num: u32,
        /// The denominator.
        den: u32,
    },
    /// The fixed-point form needs 8 to 48 fractional bits.
    #[error("fixed point needs 8 to 48 fractional bits, got {bits}")]
    BadFractionBits {
        /// The bits asked for.
        bits: u32,
    },
    /// More than 65 536 placements were asked for: use fewer steps per axis.
    #[error("{per_axis}^{k} placements is too many (at most 2^16)")]
    TooManyPlacements {
        /// Placements per axis.
        per_axis: u64,
        /// The dimension.
        k: usize,
    },
    /// A viewer distance is not positive and finite.
    #[error("the viewer distance must be positive and finite, got {distance}")]
    BadDistance {
        /// The distance given.
        distance: f64,
    },
    /// An operation made a value no voxel may hold (a sum of floats `inf + -inf` is a NaN).
    #[error("the result would hold a value the tree cannot")]
    Value(#[from] crate::value::ValueError),
}

impl OpsError {
    /// A storage's read error as an operation's error (for `map_err`).
    pub fn storage(error: impl Into<StorageError>) -> Self {
        Self::Storage(error.into())
    }
}
