//! Where a tree being produced goes, level by level: the one output trait of the operations.
//!
//! An operation that decides each node after its children (the Booleans) appends a node's block of
//! children to the level below once they are all known, and copies whole subtrees of an input level by
//! level (a subtree is a contiguous range at every level). Appended in depth-first order, each level comes
//! out in level order. [`LevelSink`] is that output: [`MemorySink`] builds a [`KTree`]; a sink that spills
//! each level to its own file writes trees larger than memory.
//!
//! ```
//! use ktree::tree::sink::{LevelSink, MemorySink};
//! use ktree::{KTree, NodeState, Universe};
//! // A root whose two children are full and empty.
//! let mut sink = MemorySink::<1>::new(Universe::new(1).unwrap());
//! sink.push_block(1, &[NodeState::Full, NodeState::Empty]).unwrap();
//! let tree = sink.finish(NodeState::Partial).unwrap();
//! assert_eq!(tree, KTree::<1>::from_dense(1, &[true, false]).unwrap());
//! ```

use std::convert::Infallible;

use super::assemble::LevelWriter;
use super::ktree::KTree;
use super::states::NodeState;
use super::storage::TreeStorage;
use super::words;
use crate::space::Universe;

/// The output of an operation, level by level: nodes are appended to the levels below the root in
/// depth-first order, the root's state is given at the end.
pub trait LevelSink {
    /// Why an append failed ([`Infallible`] in memory).
    type Error;
    /// What the finished output is.
    type Output;

    /// Appends the `n ≤ 32` states packed in the low bits of `word` (two bits each, higher bits clear)
    /// to level `depth ≥ 1`.
    ///
    /// # Errors
    /// The sink's write error.
    fn append(&mut self, depth: usize, word: u64, n: usize) -> Result<(), Self::Error>;

    /// Ends the output with the root's state `root` (levels appended below a leaf root are dropped).
    ///
    /// # Errors
    /// The sink's write error.
    fn finish(self, root: NodeState) -> Result<Self::Output, Self::Error>;

    /// Appends a block of sibling states (at most 32) to level `depth`.
    ///
    /// # Errors
    /// The sink's write error.
    #[inline]
    fn push_block(&mut self, depth: usize, kids: &[NodeState]) -> Result<(), Self::Error> {
        let word = kids
            .iter()
            .enumerate()
            .fold(0u64, |w, (i, &s)| w | (s as u64) << (2 * i));
        self.append(depth, word, kids.len())
    }
}

/// Appends the descendants of the partial node `index` of level `depth` of `tree` to `sink` (the node's
/// level written as `depth` too), full and empty leaves swapped if `invert`: per level one range of
/// `tree`, read and appended 32 nodes at a time, and one rank lookup.
///
/// # Errors
/// The first read error of `tree` or write error of `sink`.
pub fn copy_subtree<const K: usize, T, S, E>(
    sink: &mut S,
    tree: &T,
    depth: usize,
    index: usize,
    invert: bool,
) -> Result<(), E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    copy_subtree_to::<K, T, S, E>(sink, tree, depth, index, depth, invert)
}

/// [`copy_subtree`] with the node's level written as `to_depth` (its descendants one level below it and
/// so on): a subtree moved up or down the tree, as zooming and growing do.
///
/// ```
/// use ktree::tree::sink::{copy_subtree_to, LevelSink, MemorySink};
/// use ktree::{KTree, NodeState};
/// // The upper half of a bintree, made the whole of a universe one level smaller.
/// let tree = KTree::<1>::from_dense(3, &[true, false, false, false, true, false, true, true]).unwrap();
/// let mut sink = MemorySink::<1>::new(ktree::Universe::new(2).unwrap());
/// copy_subtree_to::<1, _, _, std::convert::Infallible>(&mut sink, &tree, 1, 1, 0, false).unwrap();
/// let half = sink.finish(NodeState::Partial).unwrap();
/// assert_eq!(half.to_dense().unwrap(), [true, false, true, true]);
/// ```
///
/// # Errors
/// The first read error of `tree` or write error of `sink`.
pub fn copy_subtree_to<const K: usize, T, S, E>(
    sink: &mut S,
    tree: &T,
    depth: usize,
    index: usize,
    to_depth: usize,
    invert: bool,
) -> Result<(), E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    let mut start = tree.first_child(depth, index)?;
    let mut nodes = 1usize << K;
    let mut d = depth + 1;
    loop {
        let mut partials = 0usize;
        let mut first_partial = None;
        let mut at = start;
        while at < start + nodes {
            let take = (start + nodes - at).min(32);
            let word = tree.slots(d, at, take)?;
            let partial = words::partial_mask(word);
            if first_partial.is_none() && partial != 0 {
                first_partial = Some(at + partial.trailing_zeros() as usize / 2);
            }
            partials += partial.count_ones() as usize;
            let word = if invert {
                // Full and empty swap (the low bit of every non-partial slot flips); partial stays.
                words::complement(word, take)
            } else {
                word
            };
            sink.append(d - depth + to_depth, word, take)?;
            at += take;
        }
        let Some(first_partial) = first_partial else {
            return Ok(());
        };
        // The children of the range's partial nodes are contiguous below, from the first one's children.
        start = tree.first_child(d, first_partial)?;
        nodes = partials << K;
        d += 1;
    }
}

/// A [`LevelSink`] in memory that produces a [`KTree`].
#[derive(Debug, Clone)]
pub struct MemorySink<const K: usize> {
    universe: Universe<K>,
    levels: LevelWriter,
}

impl<const K: usize> MemorySink<K> {
    /// An empty output for a tree of `universe`.
    pub fn new(universe: Universe<K>) -> Self {
        Self {
            universe,
            levels: LevelWriter::new(),
        }
    }
}

impl<const K: usize> LevelSink for MemorySink<K> {
    type Error = Infallible;
    type Output = KTree<K>;

    #[inline]
    fn append(&mut self, depth: usize, word: u64, n: usize) -> Result<(), Infallible> {
        self.levels.append_word(depth, word, n);
        Ok(())
    }

    fn finish(self, root: NodeState) -> Result<KTree<K>, Infallible> {
        Ok(self.levels.finish_with_root(self.universe, root))
    }
}
