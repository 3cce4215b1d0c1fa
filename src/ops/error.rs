//! The error type of the operations.

use thiserror::Error;

/// What can go wrong in an operation on k-trees. Every variant says how to fix the input.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum OpsError {
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
    /// A matrix has the wrong number of entries, is not affine (last row not `0 … 0 1`), has a
    /// non-finite entry, or is singular.
    #[error("bad matrix: {reason}")]
    BadMatrix {
        /// What is wrong with it.
        reason: String,
    },
    /// A scale factor is zero or negative, or an axis permutation is not a permutation.
    #[error("bad parameter: {reason}")]
    BadParameter {
        /// What is wrong with it.
        reason: String,
    },
}
