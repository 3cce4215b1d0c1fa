//! A tree's statistics: its dimension, level, node counts, size, voxels and bounding box, from the
//! storage's counts per level and one bounding-box walk, on any storage.

use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{heap_bytes_for_levels, AnyTree, LevelCounts};

/// The statistics of a tree: its dimension, level, node counts, size, voxels and bounding box. With the
/// `serde` feature these are the keys of `ktree stats --json`.
///
/// ```
/// use ktree::{AnyTree, KTree};
/// let tree = AnyTree::from(KTree::<2>::from_dense(1, &[true, false, false, false]).unwrap());
/// let s = tree.stats(None);
/// assert_eq!((s.k, s.level, s.nodes, s.full, s.partial), (2, 1, 5, 1, 1));
/// assert_eq!(s.per_level.len(), 2);
/// assert_eq!((s.voxels, s.bounding_box), (1, Some([vec![0, 0], vec![1, 1]])));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TreeStats {
    /// The dimension `K`.
    pub k: usize,
    /// The universe level `L`.
    pub level: u32,
    /// Runs of the ray set the tree was stacked from, where there was one.
    pub rays: Option<u64>,
    /// Full nodes.
    pub full: u64,
    /// Empty nodes.
    pub empty: u64,
    /// Partial nodes.
    pub partial: u64,
    /// All nodes.
    pub nodes: u64,
    /// Bytes at 2 bits a node.
    pub bytes_at_2_bits: u64,
    /// Heap bytes of the navigable tree in memory (states and rank index, [`crate::KTree::heap_bytes`]);
    /// for a tree read in place, what it would take loaded.
    pub memory_bytes: u64,
    /// The voxels inside the object.
    pub voxels: u128,
    /// The box `[lo, hi)` of the full voxels (`hi` excluded, as [`super::bounding_box`] gives it),
    /// `None` when the object is empty.
    pub bounding_box: Option<[Vec<u32>; 2]>,
    /// Node counts per level, the root's first.
    pub per_level: Vec<LevelCounts>,
}

/// The statistics of `tree`, with `rays` the number of runs it was stacked from (if it was): counts from
/// the storage (no walk), the bounding box from one walk that descends only where a face of the box may
/// lie.
///
/// # Errors
/// The storage's read error.
pub fn stats<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    rays: Option<u64>,
) -> Result<TreeStats, T::Error> {
    let per_level = tree.counts_per_level();
    let c = LevelCounts::total(tree.level(), &per_level);
    Ok(TreeStats {
        k: K,
        level: tree.level(),
        rays,
        full: c.full,
        empty: c.empty,
        partial: c.partial,
        nodes: c.nodes(),
        bytes_at_2_bits: c.nodes().div_ceil(4),
        memory_bytes: heap_bytes_for_levels(&per_level) as u64,
        voxels: crate::tree::voxels_of_levels(K, tree.level(), &per_level),
        bounding_box: super::bounding_box(tree)?.map(|(lo, hi)| [lo.to_vec(), hi.to_vec()]),
        per_level,
    })
}

impl AnyTree {
    /// The statistics ([`stats`]), with `rays` the number of runs the tree was stacked from (if it was).
    pub fn stats(&self, rays: Option<u64>) -> TreeStats {
        crate::with_dim!(self, AnyTree, t => infallible(stats(t, rays)))
    }
}
