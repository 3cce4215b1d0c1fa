//! The operations on trees whose dimension is known only at run time ([`AnyTree`]): two trees of
//! different dimensions are an error ([`OpsError::DimensionMismatch`]), not a panic.
//!
//! ```
//! use ktree::{ops::{BoolOp, OpsError}, AnyTree, KTree};
//! let a = AnyTree::from(KTree::<2>::full(2).unwrap());
//! let b = AnyTree::from(KTree::<2>::empty(2).unwrap());
//! assert_eq!(a.boolean(&b, BoolOp::Difference).unwrap(), a);
//! assert_eq!(b.complement(), a);
//! let c = AnyTree::from(KTree::<3>::full(2).unwrap());
//! assert!(matches!(a.boolean(&c, BoolOp::Union), Err(OpsError::DimensionMismatch { .. })));
//! ```

use super::{boolean, collision, complement, interferes, BoolOp, Collision, OpsError};
use crate::tree::{AnyTree, DimensionMismatch};

/// Runs `$body` with `$x`, `$y` the typed trees of two [`AnyTree`]s of one dimension, or returns the
/// dimension mismatch.
macro_rules! pair {
    ($a:expr, $b:expr, ($x:ident, $y:ident) => $body:expr) => {
        match ($a, $b) {
            (AnyTree::K1($x), AnyTree::K1($y)) => $body,
            (AnyTree::K2($x), AnyTree::K2($y)) => $body,
            (AnyTree::K3($x), AnyTree::K3($y)) => $body,
            (AnyTree::K4($x), AnyTree::K4($y)) => $body,
            (x, y) => Err(OpsError::DimensionMismatch(DimensionMismatch {
                expected: x.k(),
                found: y.k(),
            })),
        }
    };
}

impl AnyTree {
    /// `self op other` ([`boolean`]).
    ///
    /// # Errors
    /// [`OpsError::DimensionMismatch`], [`OpsError::LevelMismatch`].
    pub fn boolean(&self, other: &AnyTree, op: BoolOp) -> Result<AnyTree, OpsError> {
        pair!(self, other, (x, y) => boolean(x, y, op).map(AnyTree::from))
    }

    /// The complement ([`complement`]).
    pub fn complement(&self) -> AnyTree {
        crate::with_dim!(self, AnyTree, t => AnyTree::from(complement(t)))
    }

    /// Whether the objects share a voxel ([`interferes`]).
    ///
    /// # Errors
    /// [`OpsError::DimensionMismatch`], [`OpsError::LevelMismatch`].
    pub fn interferes(&self, other: &AnyTree) -> Result<bool, OpsError> {
        pair!(self, other, (x, y) => interferes(x, y))
    }

    /// How the objects meet ([`collision`]).
    ///
    /// # Errors
    /// [`OpsError::DimensionMismatch`], and as [`collision`].
    pub fn collision(
        &self,
        other: &AnyTree,
        time_axis: Option<usize>,
    ) -> Result<Collision, OpsError> {
        pair!(self, other, (x, y) => collision(x, y, time_axis))
    }
}
