//! Output of the operations: every operation that makes a tree writes it through a
//! [`LevelSink`](crate::tree::sink::LevelSink), node blocks appended level by level in depth-first order
//! (children in child-code order), which is level order for free; [`Memory`] is the sink of the forms that
//! return a [`KTree`].
//!
//! Every operation here computes a node's children *before* appending them, so a node whose children all
//! come out as the same leaf collapses into that leaf without anything to undo: the output is reduced by
//! construction, in one pass, with a buffer of at most `2^K` states per level of recursion.

use std::marker::PhantomData;

use crate::space::Universe;
use crate::tree::sink::{copy_subtree, LevelSink, MemorySink};
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{KTree, NodeState};

/// The state of a node whose children are `kids`: a leaf if they are all the same leaf, else partial
/// (in which case the caller appends them).
#[inline]
pub(crate) fn collapse(kids: &[NodeState]) -> Option<NodeState> {
    let first = kids[0];
    if first != NodeState::Partial && kids.iter().all(|&k| k == first) {
        Some(first)
    } else {
        None
    }
}

/// The leaf state of a boolean.
#[inline]
pub(crate) fn leaf(full: bool) -> NodeState {
    if full {
        NodeState::Full
    } else {
        NodeState::Empty
    }
}

/// A [`MemorySink`] whose write errors (there are none) have the type `E` of the input's read errors, so
/// that an operation over any storage returns a tree in memory with the storage's error alone.
pub(crate) struct Memory<const K: usize, E> {
    sink: MemorySink<K>,
    error: PhantomData<fn() -> E>,
}

impl<const K: usize, E> Memory<K, E> {
    /// An empty output for a tree of `universe`.
    pub(crate) fn new(universe: Universe<K>) -> Self {
        Self {
            sink: MemorySink::new(universe),
            error: PhantomData,
        }
    }
}

impl<const K: usize, E> LevelSink for Memory<K, E> {
    type Error = E;
    type Output = KTree<K>;

    #[inline(always)]
    fn append(&mut self, depth: usize, word: u64, n: usize) -> Result<(), E> {
        infallible(self.sink.append(depth, word, n));
        Ok(())
    }

    #[inline]
    fn finish(self, root: NodeState) -> Result<KTree<K>, E> {
        Ok(infallible(self.sink.finish(root)))
    }
}

/// The whole of `tree` written to `sink` (the result of an operation that changes nothing): the root's
/// subtree copied level range by level range.
///
/// # Errors
/// The first read error of `tree` or write error of `sink`.
pub(crate) fn copy_into<const K: usize, T, S, E>(tree: &T, mut sink: S) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    let root = tree.root_state()?;
    if root == NodeState::Partial {
        copy_subtree::<K, _, _, E>(&mut sink, tree, 0, 0, false)?;
    }
    Ok(sink.finish(root)?)
}
