//! Boolean operators on trees in memory: `&a | &b`, `&a & &b`, `&a - &b`, `&a ^ &b` and `!&a`, the
//! operations of [`crate::ops`] under their usual symbols.
//!
//! Two trees combine only when their universes have the same level, so the binary operators give a
//! `Result` (an [`OpsError::LevelMismatch`] otherwise) rather than panic.
//!
//! ```
//! use ktree::KTree;
//! let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
//! let b = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
//! assert_eq!((&a & &b).unwrap().to_dense().unwrap(), [false, true, false, false]);
//! assert_eq!((!&a).to_dense().unwrap(), [false, false, true, true]);
//! assert!((&a | &KTree::<1>::full(3).unwrap()).is_err());
//! ```

use std::ops::{BitAnd, BitOr, BitXor, Not, Sub};

use super::{self as ops, OpsError};
use crate::tree::KTree;

impl<const K: usize> BitOr for &KTree<K> {
    type Output = Result<KTree<K>, OpsError>;

    /// The union, [`ops::union`].
    fn bitor(self, other: Self) -> Self::Output {
        ops::union(self, other)
    }
}

impl<const K: usize> BitAnd for &KTree<K> {
    type Output = Result<KTree<K>, OpsError>;

    /// The intersection, [`ops::intersection`].
    fn bitand(self, other: Self) -> Self::Output {
        ops::intersection(self, other)
    }
}

impl<const K: usize> Sub for &KTree<K> {
    type Output = Result<KTree<K>, OpsError>;

    /// The difference, [`ops::difference`].
    fn sub(self, other: Self) -> Self::Output {
        ops::difference(self, other)
    }
}

impl<const K: usize> BitXor for &KTree<K> {
    type Output = Result<KTree<K>, OpsError>;

    /// The symmetric difference, [`ops::symmetric_difference`].
    fn bitxor(self, other: Self) -> Self::Output {
        ops::symmetric_difference(self, other)
    }
}

impl<const K: usize> Not for &KTree<K> {
    type Output = KTree<K>;

    /// The complement within the universe, [`ops::complement`].
    fn not(self) -> KTree<K> {
        ops::complement(self)
    }
}
