//! A `.ktree` version 2 file read as a tree in place: the walks of [`cursor`](crate::tree::cursor) (and so
//! rendering) run on its memory map, for trees larger than memory.

use super::KtreeView;
use crate::io::KtreeFileError;
use crate::space::Universe;
use crate::tree::cursor::LevelOrder;
use crate::tree::NodeState;

/// A `K`-dimensional tree read through a [`KtreeView`]: what the walks need, with each first child found
/// from the file's rank samples (at most 64 word pop-counts) instead of an index in memory.
///
/// ```
/// use ktree::tree::cursor::LevelOrder;
/// use ktree::{io, KTree};
/// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i % 3 == 0).collect::<Vec<_>>()).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// io::write_ktree_v2_file(&path, &tree).unwrap();
/// let view = io::KtreeView::open(&path).unwrap();
/// let mapped = io::MappedTree::<2>::new(&view).unwrap();
/// let mut leaves = Vec::new();
/// mapped.for_each_leaf(|cell, state| leaves.push((cell, state)));
/// assert_eq!(leaves, tree.leaves().collect::<Vec<_>>());
/// ```
#[derive(Debug, Clone, Copy)]
pub struct MappedTree<'a, const K: usize> {
    view: &'a KtreeView,
    universe: Universe<K>,
}

impl<'a, const K: usize> MappedTree<'a, K> {
    /// The tree of `view`.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`](crate::io::KtreeFileErrorKind::Dimension) if the file's `K` is not `K`.
    pub fn new(view: &'a KtreeView) -> Result<Self, KtreeFileError> {
        Ok(Self {
            view,
            universe: view.universe::<K>()?,
        })
    }
}

impl<const K: usize> LevelOrder<K> for MappedTree<'_, K> {
    fn universe(&self) -> Universe<K> {
        self.universe
    }

    fn depth_count(&self) -> usize {
        self.view.depth_count()
    }

    fn root_state(&self) -> NodeState {
        self.view.state(0, 0).unwrap_or(NodeState::Empty)
    }

    fn first_child(&self, depth: usize, index: usize) -> usize {
        (self.view.partial_rank(depth, index as u64) << K) as usize
    }

    fn block_codes(&self, depth: usize, first: usize) -> u32 {
        // `2^K` divides 32: the block lies in one word.
        let first = first as u64;
        let word = self.view.level_word(depth, first / 32) >> (2 * (first % 32));
        (word & ((1u64 << (2 << K)) - 1)) as u32
    }
}
