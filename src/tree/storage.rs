//! Where a tree's levels are read from: the one storage trait every walk, query and operation runs over.
//!
//! A tree is stored in level order, two bits a node, and the walks of [`cursor`](super::cursor) only ever
//! ask a storage for the state codes of a block of siblings and for the first child of a partial node.
//! [`TreeStorage`] is that question with a fallible answer, so that the same walks run on a tree in memory
//! ([`KTree`], whose reads cannot fail: its error is [`Infallible`], and the compiler removes the checks)
//! and on a file read in place (`io::MappedTree`), whose every read is checked and fails with an error
//! naming the file and the byte offset when the file no longer is what it was.
//!
//! ```
//! use ktree::tree::storage::TreeStorage;
//! use ktree::{KTree, NodeState};
//! let tree = KTree::<1>::from_dense(2, &[true, true, false, true]).unwrap();
//! // The root is partial; its children are nodes 0 and 1 of level 1.
//! assert_eq!(TreeStorage::root_state(&tree), Ok(NodeState::Partial));
//! assert_eq!(TreeStorage::first_child(&tree, 0, 0), Ok(0));
//! assert_eq!(tree.block_states(1, 0), Ok([NodeState::Full, NodeState::Partial].to_vec()));
//! ```

use std::convert::Infallible;

use super::error::StorageError;
use super::ktree::TreeId;
use super::ktree::{KTree, LevelCounts, NodeRef};
use super::states::NodeState;
use super::words::slots_mask;
use crate::space::Universe;

/// The `n ≤ 32` states from node `first`, gathered from the blocks of `2^K` siblings that cover them
/// (`block(at)` reads the block starting at node `at`): the default of [`TreeStorage::slots`].
fn slots_from_blocks<const K: usize, E>(
    first: usize,
    n: usize,
    mut block: impl FnMut(usize) -> Result<u32, E>,
) -> Result<u64, E> {
    let fanout = 1usize << K;
    let mut word = 0u64;
    let mut at = first - first % fanout;
    while at < first + n {
        let codes = u64::from(block(at)?);
        let shift = 2 * (at as i64 - first as i64);
        word |= if shift >= 0 {
            codes << shift
        } else {
            codes >> -shift
        };
        at += fanout;
    }
    Ok(word & slots_mask(n))
}

/// A `K`-dimensional tree stored in level order, read one block of siblings at a time: the one
/// primitive every walk, query, operation, picture and export of the crate reads trees through.
/// Reads may fail (a file changed underneath): every read returns `Result<_, Self::Error>`.
///
/// Implementors give the reads below; the rest is provided. Implemented by [`KTree`] (with
/// [`Infallible`] errors, at no cost) and by `io::MappedTree`, a `.ktree` file read in place. The
/// questions asked of a tree (points, boxes, rays, nearest voxels) are provided on top of it by
/// `query::Query`.
pub trait TreeStorage<const K: usize> {
    /// Why a read failed ([`Infallible`] for a tree in memory); it converts into a [`StorageError`],
    /// which the operations with errors of their own keep as a variant.
    type Error: std::error::Error + Into<StorageError> + Send + Sync + 'static;

    /// The universe.
    fn universe(&self) -> Universe<K>;

    /// The number of stored levels.
    fn depth_count(&self) -> usize;

    /// The number of nodes of level `depth` (0 below the last stored level).
    fn level_len(&self, depth: usize) -> usize;

    /// Node counts per level, from the root down (the tree's shape, known without a walk).
    fn counts_per_level(&self) -> Vec<LevelCounts>;

    /// The root's state.
    ///
    /// # Errors
    /// The storage's read error.
    fn root_state(&self) -> Result<NodeState, Self::Error>;

    /// The number of partial nodes of level `depth` before node `index` (`index ≤` the level's length).
    ///
    /// # Errors
    /// The storage's read error, for instance when `index` is past the level.
    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, Self::Error>;

    /// The states of the `2^K` siblings of level `depth` from `first` (a multiple of `2^K`), two bits each,
    /// the first in the low bits.
    ///
    /// # Errors
    /// The storage's read error, for instance when the block is not in the level.
    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, Self::Error>;

    /// The index (in level `depth + 1`) of the first child of the partial node `index` of level `depth`:
    /// `2^K` times its rank among the level's partial nodes.
    ///
    /// # Errors
    /// The storage's read error, for instance when `index` is not a partial node of the level.
    #[inline(always)]
    fn first_child(&self, depth: usize, index: usize) -> Result<usize, Self::Error> {
        Ok(self.partial_rank(depth, index)? << K)
    }

    /// The states of the `n ≤ 32` nodes of level `depth ≥ 1` from `first`, two bits each, the first in the
    /// low bits (higher bits clear): what bulk copies of a subtree read. The default reads the blocks of
    /// siblings the range covers.
    ///
    /// # Errors
    /// The storage's read error, for instance when the range is not in the level.
    fn slots(&self, depth: usize, first: usize, n: usize) -> Result<u64, Self::Error> {
        slots_from_blocks::<K, _>(first, n, |at| self.block_codes(depth, at))
    }

    /// The state of node `index` of level `depth`.
    ///
    /// # Errors
    /// The storage's read error, for instance when the node is not in the level.
    #[inline]
    fn state(&self, depth: usize, index: usize) -> Result<NodeState, Self::Error> {
        if depth == 0 {
            return self.root_state();
        }
        Ok(NodeState::from_bits(self.slots(depth, index, 1)? as u32))
    }

    /// The universe level `L`.
    #[inline]
    fn level(&self) -> u32 {
        self.universe().level()
    }

    /// The total node counts (`level` holds the universe level), as [`KTree::counts`].
    fn counts(&self) -> LevelCounts {
        LevelCounts::total(self.level(), &self.counts_per_level())
    }

    /// The total number of nodes.
    fn node_count(&self) -> u64 {
        self.counts().nodes()
    }

    /// The number of voxels inside the object, from the counts per level (no walk).
    fn voxel_count(&self) -> u128 {
        super::voxels_of_levels(K, self.level(), &self.counts_per_level())
    }

    /// The root node.
    ///
    /// # Errors
    /// The storage's read error.
    #[inline]
    fn root(&self) -> Result<NodeRef<K>, Self::Error> {
        Ok(NodeRef {
            index: 0,
            cell: self.universe().root(),
            state: self.root_state()?,
            tree: TreeId::NONE,
        })
    }

    /// The states of the block of siblings of level `depth` from `first`, in code order.
    ///
    /// # Errors
    /// The storage's read error.
    fn block_states(&self, depth: usize, first: usize) -> Result<Vec<NodeState>, Self::Error> {
        let codes = self.block_codes(depth, first)?;
        Ok((0..1usize << K)
            .map(|c| NodeState::from_bits(codes >> (2 * c)))
            .collect())
    }
}

impl<const K: usize> TreeStorage<K> for KTree<K> {
    type Error = Infallible;

    #[inline]
    fn universe(&self) -> Universe<K> {
        KTree::universe(self)
    }

    #[inline]
    fn depth_count(&self) -> usize {
        KTree::depth_count(self)
    }

    #[inline]
    fn level_len(&self, depth: usize) -> usize {
        if depth < self.depth_count() {
            self.level_states(depth).len()
        } else {
            0
        }
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        KTree::counts_per_level(self)
    }

    fn counts(&self) -> LevelCounts {
        KTree::counts(self)
    }

    fn voxel_count(&self) -> u128 {
        KTree::voxel_count(self)
    }

    #[inline]
    fn root_state(&self) -> Result<NodeState, Infallible> {
        Ok(KTree::root_state(self))
    }

    #[inline]
    fn root(&self) -> Result<NodeRef<K>, Infallible> {
        Ok(KTree::root(self))
    }

    #[inline(always)]
    fn state(&self, depth: usize, index: usize) -> Result<NodeState, Infallible> {
        Ok(KTree::state(self, depth, index))
    }

    #[inline(always)]
    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, Infallible> {
        Ok(self.level_states(depth).partial_rank(index))
    }

    #[inline(always)]
    fn first_child(&self, depth: usize, index: usize) -> Result<usize, Infallible> {
        Ok(KTree::first_child(self, depth, index))
    }

    #[inline(always)]
    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, Infallible> {
        Ok(self.level_states(depth).block_codes(first, K))
    }

    #[inline(always)]
    fn slots(&self, depth: usize, first: usize, n: usize) -> Result<u64, Infallible> {
        let words = self.level_states(depth).words();
        let (w, s) = (first / 32, 2 * (first % 32));
        let mut chunk = words[w] >> s;
        if s > 0 && w + 1 < words.len() {
            chunk |= words[w + 1] << (64 - s);
        }
        Ok(chunk & slots_mask(n))
    }
}

/// The value of a read that cannot fail: what the infallible conveniences of [`KTree`] return from the
/// generic walks and queries.
///
/// ```
/// use ktree::tree::storage::{infallible, TreeStorage};
/// use ktree::{KTree, NodeState};
/// let tree = KTree::<1>::full(2).unwrap();
/// assert_eq!(infallible(TreeStorage::root_state(&tree)), NodeState::Full);
/// ```
#[inline(always)]
pub fn infallible<T>(result: Result<T, Infallible>) -> T {
    match result {
        Ok(value) => value,
        Err(never) => match never {},
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tree::sink::{copy_subtree, LevelSink, MemorySink};

    /// A tree in memory read only through the required reads: the provided `slots` and `first_child`
    /// are under test.
    struct BlocksOnly<'a, const K: usize>(&'a KTree<K>);

    impl<const K: usize> TreeStorage<K> for BlocksOnly<'_, K> {
        type Error = Infallible;
        fn universe(&self) -> Universe<K> {
            self.0.universe()
        }
        fn depth_count(&self) -> usize {
            self.0.depth_count()
        }
        fn level_len(&self, depth: usize) -> usize {
            TreeStorage::level_len(self.0, depth)
        }
        fn counts_per_level(&self) -> Vec<LevelCounts> {
            self.0.counts_per_level()
        }
        fn root_state(&self) -> Result<NodeState, Infallible> {
            Ok(self.0.root_state())
        }
        fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, Infallible> {
            TreeStorage::partial_rank(self.0, depth, index)
        }
        fn block_codes(&self, depth: usize, first: usize) -> Result<u32, Infallible> {
            TreeStorage::block_codes(self.0, depth, first)
        }
    }

    fn tree<const K: usize>(level: u32, seed: u64) -> KTree<K> {
        let n = 1usize << (K as u32 * level);
        let dense: Vec<bool> = (0..n as u64)
            .map(|i| (i.wrapping_mul(seed) ^ (i >> 3)) % 7 < 3)
            .collect();
        KTree::from_dense(level, &dense).unwrap()
    }

    fn slots_and_copies_agree<const K: usize>(level: u32) {
        for seed in [3, 11, 12345] {
            let t = tree::<K>(level, seed);
            let b = BlocksOnly(&t);
            // Below the root every level is whole blocks of siblings.
            for depth in 1..t.depth_count() {
                let len = t.level_states(depth).len();
                for first in 0..len {
                    assert_eq!(
                        TreeStorage::state(&b, depth, first),
                        Ok(t.state(depth, first))
                    );
                    for n in 1..=32.min(len - first) {
                        assert_eq!(
                            TreeStorage::slots(&b, depth, first, n),
                            TreeStorage::slots(&t, depth, first, n),
                            "K = {K}, depth {depth}, {first} + {n}"
                        );
                    }
                }
            }
            if t.root_state() == NodeState::Partial {
                for invert in [false, true] {
                    let mut sink = MemorySink::new(t.universe());
                    infallible(copy_subtree::<K, _, _, Infallible>(
                        &mut sink, &b, 0, 0, invert,
                    ));
                    let copy = infallible(sink.finish(NodeState::Partial));
                    let expect = if invert {
                        crate::ops::complement(&t)
                    } else {
                        t.clone()
                    };
                    assert_eq!(copy, expect, "K = {K}, invert {invert}");
                }
            }
        }
    }

    #[test]
    fn provided_slots_and_subtree_copies_read_what_the_words_hold() {
        slots_and_copies_agree::<1>(7);
        slots_and_copies_agree::<2>(4);
        slots_and_copies_agree::<3>(3);
        slots_and_copies_agree::<4>(2);
    }
}
