//! The geometric transforms of a tree in memory under one name each, with or without values: what code
//! that chooses between the exact integer operations and one overlay pass (the CLI's `transform`, the
//! Python module's methods) calls, written once for binary and valued trees. A binary tree takes the
//! binary operations (streamed, the fastest); a valued one their valued forms, each voxel keeping its
//! value.
//!
//! ```
//! use ktree::ops::{AxisMap, Geometry};
//! use ktree::KTree;
//! /// A quarter turn then a move by one voxel along y, whatever the tree holds.
//! fn turn_and_move<T: Geometry<2>>(tree: &T) -> T {
//!     tree.rotated(&AxisMap::quarter_turn(0, 1).unwrap()).translated([0, 1])
//! }
//! let labels = KTree::<2, u8>::from_dense_values(1, &[Some(4), None, None, None]).unwrap();
//! assert_eq!(turn_and_move(&labels).to_dense_values().unwrap(), [None, None, None, Some(4)]);
//! let shape = labels.shape();
//! assert_eq!(turn_and_move(&shape), turn_and_move(&labels).shape());
//! ```

use super::{
    rotate_axes, rotate_values, scale, scale_values, transform, transform_projective,
    transform_projective_values, transform_values, translate, Affine, AxisMap, OpsError,
    Projective,
};
use crate::tree::storage::infallible;
use crate::value::Rgb;
use crate::KTree;

/// A tree in memory that can be scaled, rotated, moved and mapped, returning a tree of its own kind.
pub trait Geometry<const K: usize>: Sized {
    /// Scaled by `num / den` about the universe's origin corner ([`scale`]).
    ///
    /// # Errors
    /// [`OpsError::BadScale`] unless both are positive and at most 2^20.
    fn scaled(&self, num: u32, den: u32) -> Result<Self, OpsError>;

    /// Rotated or reflected by an element of the hyperoctahedral group ([`rotate_axes`]).
    fn rotated(&self, map: &AxisMap<K>) -> Self;

    /// Moved by `t` whole voxels; voxels leaving the universe are lost ([`translate`]).
    fn translated(&self, t: [i64; K]) -> Self;

    /// Mapped by an affine map in one overlay pass ([`transform`]).
    ///
    /// # Errors
    /// [`OpsError::Singular`] for a singular map.
    fn affine(&self, m: &Affine<K>) -> Result<Self, OpsError>;

    /// Mapped by a projective map in one overlay pass ([`transform_projective`]).
    ///
    /// # Errors
    /// As [`transform_projective`].
    fn projective(&self, m: &Projective<K>) -> Result<Self, OpsError>;
}

impl<const K: usize> Geometry<K> for KTree<K> {
    fn scaled(&self, num: u32, den: u32) -> Result<Self, OpsError> {
        scale(self, num, den)
    }

    fn rotated(&self, map: &AxisMap<K>) -> Self {
        infallible(rotate_axes(self, map))
    }

    fn translated(&self, t: [i64; K]) -> Self {
        infallible(translate(self, t))
    }

    fn affine(&self, m: &Affine<K>) -> Result<Self, OpsError> {
        transform(self, m)
    }

    fn projective(&self, m: &Projective<K>) -> Result<Self, OpsError> {
        transform_projective(self, m)
    }
}

/// The valued forms, for each value type (a binary tree is `KTree<K, ()>`, above).
macro_rules! valued_geometry {
    ($($v:ty),*) => {$(
        impl<const K: usize> Geometry<K> for KTree<K, $v> {
            fn scaled(&self, num: u32, den: u32) -> Result<Self, OpsError> {
                scale_values(self, num, den)
            }

            fn rotated(&self, map: &AxisMap<K>) -> Self {
                infallible(rotate_values(self, map))
            }

            fn translated(&self, t: [i64; K]) -> Self {
                self.translate_values(t)
            }

            fn affine(&self, m: &Affine<K>) -> Result<Self, OpsError> {
                transform_values(self, m)
            }

            fn projective(&self, m: &Projective<K>) -> Result<Self, OpsError> {
                transform_projective_values(self, m)
            }
        }
    )*};
}

valued_geometry!(u8, u16, u32, i8, f32, Rgb);
