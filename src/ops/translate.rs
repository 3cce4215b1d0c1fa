//! Translation by an integer vector with Meagher's overlays (§6 "Translation", claim M3), and by a vector
//! given at a finer level.
//!
//! Each target obel is decided from the source obels of its own level that cover it — at most `2^K` of
//! them, Meagher's overlay — refined level by level where they are partial; parts moved outside the
//! universe are cut off (the "void"). Integer-only: additions, comparisons and shifts.

use super::overlay::{resample, Preimage};
use crate::tree::KTree;

/// The preimage of an integer translation by `t`: target voxel `q` comes from source voxel `q − t`.
struct Shift<const K: usize> {
    t: [i64; K],
}

impl<const K: usize> Preimage<K> for Shift<K> {
    fn voxel(&self, q: [u32; K]) -> [i64; K] {
        std::array::from_fn(|i| i64::from(q[i]) - self.t[i])
    }

    fn cell_box(&self, origin: [u32; K], side: u64) -> [(i64, i64); K] {
        std::array::from_fn(|i| {
            let lo = i64::from(origin[i]) - self.t[i];
            (lo, lo + side as i64 - 1)
        })
    }
}

/// Translates the object by `t` voxels (any integer vector, negative allowed); voxels moved out of the
/// universe are lost. The output is reduced.
///
/// ```
/// use ktree::{KTree, ops::translate};
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// assert_eq!(translate(&a, [1]).to_dense().unwrap(), [false, true, true, false]);
/// assert_eq!(translate(&a, [-1]).to_dense().unwrap(), [true, false, false, false]);
/// ```
pub fn translate<const K: usize>(tree: &KTree<K>, t: [i64; K]) -> KTree<K> {
    let side = tree.universe().side() as i64;
    if t.iter().all(|&v| v == 0) {
        return tree.clone();
    }
    if t.iter().any(|&v| v.abs() >= side) {
        return KTree::empty(tree.level()).expect("the tree's own level is valid");
    }
    resample(tree, &Shift { t })
}

/// The whole-voxel shift used for an offset of `t / 2^sub_level` voxels: the target voxel whose centre,
/// moved back by the offset, lands in a source voxel takes that voxel's state, which is a shift by
/// `t / 2^sub_level` rounded to the nearest integer with halves rounded *down* (towards −∞).
///
/// ```
/// use ktree::ops::fine_shift;
/// assert_eq!(fine_shift(5, 2), 1);   // 1.25 → 1
/// assert_eq!(fine_shift(6, 2), 1);   // 1.5  → 1 (half down)
/// assert_eq!(fine_shift(7, 2), 2);   // 1.75 → 2
/// assert_eq!(fine_shift(-6, 2), -2); // −1.5 → −2 (half down)
/// ```
pub fn fine_shift(t: i64, sub_level: u32) -> i64 {
    // Source voxel of target q: floor(q + ½ − t/2^s) = q + floor((2^s − 2t) / 2^(s+1)).
    let s = 1i64 << sub_level;
    -(s - 2 * t).div_euclid(2 * s)
}

/// Translates by a vector given at a finer level: `t[i] / 2^sub_level` voxels on axis `i`, applied as the
/// whole-voxel shift of [`fine_shift`] (a voxel grid can only move by whole voxels; the rounding rule is
/// that of sampling each target voxel at its centre).
pub fn translate_fine<const K: usize>(tree: &KTree<K>, t: [i64; K], sub_level: u32) -> KTree<K> {
    translate(tree, t.map(|v| fine_shift(v, sub_level)))
}
