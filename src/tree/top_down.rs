//! Builds a minimal valued tree from the top down: a function says, for each cell, its value (or that it
//! is empty) or that it splits, and carries a context of its own (the input nodes the cell lies in) from
//! each cell to its children. The cells are decided level by level, so the nodes come in level order;
//! then, from the deepest level up, each block of `2^K` children that [`combine`] makes a leaf (all
//! empty, or all full of one value) is removed and its parent becomes that leaf. The result is minimal
//! whatever the function decides, as long as a cell it splits has children (it is not a voxel).
//!
//! Every operation on valued trees that makes a tree (selecting, masking, overlaying, combining, mapping)
//! is this builder with a deciding function over its inputs' nodes ([`InputNode`]).
//!
//! ```
//! use ktree::tree::top_down::{build_top_down, Decision};
//! use ktree::KTree;
//! // The voxels of a bintree of level 3 whose coordinate is below 5, valued by their half.
//! let tree = build_top_down::<1, u8, (), ktree::tree::TreeError>(
//!     3,
//!     (),
//!     |cell, ()| {
//!         let (lo, hi) = (cell.origin()[0], cell.origin()[0] + cell.side() as u32);
//!         Ok(if lo >= 5 {
//!             Decision::Leaf(None)
//!         } else if hi <= 4 {
//!             Decision::Leaf(Some(0))
//!         } else if cell.side() == 1 {
//!             Decision::Leaf(Some(1))
//!         } else {
//!             Decision::Split
//!         })
//!     },
//!     |(), _| Ok(()),
//! )
//! .unwrap();
//! tree.assert_well_formed();
//! let dense: Vec<Option<u8>> = (0..8).map(|x| (x < 5).then_some((x >= 4) as u8)).collect();
//! assert_eq!(tree, KTree::from_dense_values(3, &dense).unwrap());
//! ```

use super::ktree::KTree;
use super::states::PackedStates;
use super::valued::{combine, ValueState, ValueStorage, ValuedLevel};
use super::TreeError;
use crate::space::{Cell, Universe};
use crate::value::Value;

/// What a cell of the tree being built is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Decision<V> {
    /// A leaf: empty (`None`) or every voxel holding the value.
    Leaf(Option<V>),
    /// The cell splits into its `2^K` children (each decided in turn).
    Split,
}

/// Builds the minimal tree of level `level` that `decide` describes from the root down; `child(context,
/// code)` gives the context of a split cell's child `code` (Morton order) from the cell's.
///
/// # Errors
/// The first error of `decide` or `child` ([`TreeError`] through `From`); [`TreeError::Value`] for a NaN
/// decided as a value; [`TreeError::PartialVoxel`] if a voxel is split; a level beyond the largest.
pub fn build_top_down<const K: usize, V: Value, C: Clone, E: From<TreeError>>(
    level: u32,
    root: C,
    mut decide: impl FnMut(&Cell<K>, &C) -> Result<Decision<V>, E>,
    mut child: impl FnMut(&C, usize) -> Result<C, E>,
) -> Result<KTree<K, V>, E> {
    let universe = Universe::<K>::new(level).map_err(TreeError::from)?;
    // Level by level: each level's states (Partial stands for "split, to be settled") in level order.
    let mut levels: Vec<Vec<ValueState<V>>> = Vec::new();
    let mut frontier = vec![(universe.root(), root)];
    while !frontier.is_empty() {
        let depth = levels.len();
        let mut states = Vec::with_capacity(frontier.len());
        let mut next = Vec::new();
        for (cell, context) in &frontier {
            match decide(cell, context)? {
                Decision::Leaf(None) => states.push(ValueState::Empty),
                Decision::Leaf(Some(v)) => {
                    v.check().map_err(TreeError::from)?;
                    states.push(ValueState::Full(v));
                }
                Decision::Split => {
                    if cell.side() == 1 {
                        return Err(TreeError::PartialVoxel { depth }.into());
                    }
                    states.push(ValueState::Partial);
                    for code in 0..1usize << K {
                        next.push((cell.child(code), child(context, code)?));
                    }
                }
            }
        }
        levels.push(states);
        frontier = next;
    }
    Ok(settle(universe, levels))
}

/// Settles the split nodes from the deepest level up (a block of children that combines into a leaf
/// replaces its parent and leaves its level) and packs the levels.
fn settle<const K: usize, V: Value>(
    universe: Universe<K>,
    mut levels: Vec<Vec<ValueState<V>>>,
) -> KTree<K, V> {
    let n = 1usize << K;
    for depth in (0..levels.len().saturating_sub(1)).rev() {
        let (upper, lower) = levels.split_at_mut(depth + 1);
        let (parents, children) = (&mut upper[depth], &mut lower[0]);
        let mut kept = 0usize;
        let mut block = 0usize;
        for parent in parents.iter_mut() {
            if !parent.has_children() {
                continue;
            }
            let kids = &children[block * n..(block + 1) * n];
            let combined = combine(kids);
            block += 1;
            *parent = combined;
            if combined.has_children() {
                children.copy_within((block - 1) * n..block * n, kept * n);
                kept += 1;
            }
        }
        children.truncate(kept * n);
    }
    pack(universe, levels)
}

/// Packs settled levels of states (level order, a node with children followed by its `2^K` children in
/// the level below) into a tree; trailing empty levels are dropped.
pub(crate) fn pack<const K: usize, V: Value>(
    universe: Universe<K>,
    levels: Vec<Vec<ValueState<V>>>,
) -> KTree<K, V> {
    pack_chunks(
        universe,
        levels
            .into_iter()
            .map(|l| vec![ValuedLevel::from_states(&l)])
            .collect(),
    )
}

/// [`pack`] of levels each kept as consecutive chunks; the levels packed on the rayon pool.
fn pack_chunks<const K: usize, V: Value>(
    universe: Universe<K>,
    mut levels: Vec<Vec<ValuedLevel<V>>>,
) -> KTree<K, V> {
    use rayon::prelude::*;
    while levels.len() > 1
        && levels
            .last()
            .is_some_and(|l| l.iter().all(ValuedLevel::is_empty))
    {
        levels.pop();
    }
    let (packed, values): (Vec<PackedStates>, Vec<Vec<V>>) =
        levels.into_par_iter().map(pack_level).unzip();
    KTree::from_valued_levels(universe, packed, values)
}

/// One level, kept as chunks, packed: its 2-bit codes with their rank index and the values of its full
/// nodes (the chunks' codes joined by shifted word copies; one chunk is moved, not copied).
fn pack_level<V: Value>(chunks: Vec<ValuedLevel<V>>) -> PackedLevel<V> {
    let mut chunks = chunks.into_iter();
    let mut level = chunks.next().unwrap_or_default();
    for chunk in chunks {
        level.append(chunk);
    }
    level.into_packed()
}

/// A level packed: its 2-bit codes and the values of its full nodes.
pub(crate) type PackedLevel<V> = (PackedStates, Vec<V>);

/// A subtree built apart (on a thread of its own, say): its root's state and each level below it in
/// level order (2-bit codes and the full nodes' values, [`ValuedLevel`]), each level as the chunks it
/// was made of — joined to its siblings' without copying, copied once when the whole tree is packed
/// ([`Subtree::into_tree`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Subtree<V> {
    root: ValueState<V>,
    /// Level `d` holds the nodes `d + 1` levels below the root, in chunks.
    below: Vec<Vec<ValuedLevel<V>>>,
}

impl<V: Value> Subtree<V> {
    /// The subtree of root `root` and the levels `below` it (level order, the first one the root's
    /// children, if it has any).
    pub(crate) fn new(root: ValueState<V>, below: Vec<ValuedLevel<V>>) -> Self {
        let below = below
            .into_iter()
            .take_while(|l| !l.is_empty())
            .map(|l| vec![l])
            .collect();
        Self { root, below }
    }

    /// [`Subtree::new`] of levels each made of chunks (the level their concatenation).
    pub(crate) fn from_chunks(root: ValueState<V>, below: Vec<Vec<ValuedLevel<V>>>) -> Self {
        let below = below
            .into_iter()
            .take_while(|l| l.iter().any(|chunk| !chunk.is_empty()))
            .collect();
        Self { root, below }
    }

    /// A leaf.
    pub(crate) fn leaf(root: ValueState<V>) -> Self {
        Self {
            root,
            below: Vec::new(),
        }
    }

    /// The subtree of a cell from those of its `2^K` children, in code order: a leaf if they are alike
    /// ([`combine`]), else the children, then each level of their subtrees one after the other.
    pub(crate) fn join(kids: Vec<Self>) -> Self {
        let states: Vec<ValueState<V>> = kids.iter().map(|k| k.root).collect();
        let root = combine(&states);
        if !root.has_children() {
            return Self::leaf(root);
        }
        let mut below = vec![vec![ValuedLevel::from_states(&states)]];
        for kid in kids {
            for (d, chunks) in kid.below.into_iter().enumerate() {
                if below.len() <= d + 1 {
                    below.push(Vec::new());
                }
                below[d + 1].extend(chunks);
            }
        }
        Self { root, below }
    }

    /// The root's state.
    pub(crate) fn root(&self) -> ValueState<V> {
        self.root
    }

    /// The levels below the root, each packed as its codes and its full nodes' values, taken out: the
    /// subtree is left its root alone.
    pub(crate) fn take_levels_below(&mut self) -> Vec<PackedLevel<V>> {
        std::mem::take(&mut self.below)
            .into_iter()
            .map(pack_level)
            .collect()
    }

    /// The levels from the root down, each packed as its codes and its full nodes' values.
    pub(crate) fn into_packed_levels(self) -> Vec<PackedLevel<V>> {
        std::iter::once(vec![ValuedLevel::from_states(&[self.root])])
            .chain(self.below)
            .map(pack_level)
            .collect()
    }

    /// The tree of `universe` this subtree is the whole of (its root the universe's root).
    pub(crate) fn into_tree<const K: usize>(self, universe: Universe<K>) -> KTree<K, V> {
        let mut levels = Vec::with_capacity(universe.level() as usize + 1);
        levels.push(vec![ValuedLevel::from_states(&[self.root])]);
        levels.extend(self.below);
        pack_chunks(universe, levels)
    }
}

/// A node of an input tree as a cell of the output descends: the node the cell lies in (a leaf covers all
/// the cells below it) and its state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputNode<V> {
    depth: usize,
    index: usize,
    /// The node's state (a leaf's for every cell inside it).
    pub state: ValueState<V>,
}

impl<V: Value> InputNode<V> {
    /// The root of a valued tree.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn root<const K: usize, T: ValueStorage<K, Value = V>>(tree: &T) -> Result<Self, T::Error> {
        Ok(Self {
            depth: 0,
            index: 0,
            state: tree.root()?.state,
        })
    }

    /// The node of child `code` of the cell this node stands for.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn child<const K: usize, T: ValueStorage<K, Value = V>>(
        &self,
        tree: &T,
        code: usize,
    ) -> Result<Self, T::Error> {
        if !self.state.has_children() {
            return Ok(*self);
        }
        let first = tree.children(self.depth, self.index)?;
        let codes = tree.codes(self.depth + 1, first)?;
        let index = first + code;
        Ok(Self {
            depth: self.depth + 1,
            index,
            state: tree.decode(self.depth + 1, index, codes >> (2 * code))?,
        })
    }
}
