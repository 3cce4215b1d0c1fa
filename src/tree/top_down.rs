//! Builds a minimal valued tree from the top down: a function says, for each cell, its value (or that it
//! is empty) or that it splits, and carries a context of its own (the input nodes the cell lies in) from
//! each cell to its children. The cells are decided depth first; a split cell's `2^K` children, once
//! built, become a leaf if [`combine`] makes one of them (all empty, or all full of one value), else are
//! appended to their level — so each level comes in level order, written as 2-bit codes and values as it
//! comes, and the memory held besides the tree is one context a level. The result is minimal whatever the
//! function decides, as long as a cell it splits has children (it is not a voxel).
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
pub fn build_top_down<const K: usize, V: Value, C, E: From<TreeError>>(
    level: u32,
    root: C,
    mut decide: impl FnMut(&Cell<K>, &C) -> Result<Decision<V>, E>,
    mut child: impl FnMut(&C, usize) -> Result<C, E>,
) -> Result<KTree<K, V>, E> {
    let universe = Universe::<K>::new(level).map_err(TreeError::from)?;
    let mut build = TopDown {
        levels: vec![ValuedLevel::new(); level as usize + 1],
        decide: &mut decide,
        child: &mut child,
    };
    let state = build.node(universe.root(), &root, 0)?;
    let mut levels = build.levels;
    levels[0].push(state);
    Ok(pack_chunks(
        universe,
        levels.into_iter().map(|level| vec![level]).collect(),
    ))
}

/// A build from the top down under way: the settled nodes of each level so far (a node's children are
/// appended to their level when the node is settled, so each level comes in level order), and the
/// functions that decide a cell and make a child's context.
struct TopDown<V, D, H> {
    levels: Vec<ValuedLevel<V>>,
    decide: D,
    child: H,
}

impl<V: Value, D, H> TopDown<V, D, H> {
    /// The state of `cell` (at `depth`, of context `context`) once its children, if it splits, are built
    /// and settled: a leaf if they combine into one, else their states appended to the level below.
    fn node<const K: usize, C, E>(
        &mut self,
        cell: Cell<K>,
        context: &C,
        depth: usize,
    ) -> Result<ValueState<V>, E>
    where
        D: FnMut(&Cell<K>, &C) -> Result<Decision<V>, E>,
        H: FnMut(&C, usize) -> Result<C, E>,
        E: From<TreeError>,
    {
        match (self.decide)(&cell, context)? {
            Decision::Leaf(None) => Ok(ValueState::Empty),
            Decision::Leaf(Some(v)) => {
                v.check().map_err(TreeError::from)?;
                Ok(ValueState::Full(v))
            }
            Decision::Split => {
                if cell.side() == 1 {
                    return Err(TreeError::PartialVoxel { depth }.into());
                }
                let n = 1usize << K;
                let mut kids = [ValueState::Empty; 16];
                for (code, kid) in kids.iter_mut().enumerate().take(n) {
                    let context = (self.child)(context, code)?;
                    *kid = self.node(cell.child(code), &context, depth + 1)?;
                }
                let state = combine(&kids[..n]);
                if state.has_children() {
                    self.levels[depth + 1].extend_from_slice(&kids[..n]);
                }
                Ok(state)
            }
        }
    }
}

/// Packs levels, each kept as consecutive chunks, into a tree (trailing empty levels dropped); the levels
/// packed on the rayon pool.
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
/// nodes (the chunks' codes joined by shifted word copies into room made once; the first chunk is moved,
/// not copied).
fn pack_level<V: Value>(chunks: Vec<ValuedLevel<V>>) -> PackedLevel<V> {
    let nodes: usize = chunks.iter().map(ValuedLevel::len).sum();
    let values: usize = chunks.iter().map(|c| c.values().len()).sum();
    let mut chunks = chunks.into_iter();
    let mut level = chunks.next().unwrap_or_default();
    level.reserve(nodes - level.len(), values - level.values().len());
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
/// the cells below it), its state, and where its children start (found once, when the node is reached,
/// not once for each child).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputNode<V> {
    depth: usize,
    /// The node's first child's index at `depth + 1`, when it has children.
    first: usize,
    /// The node's state (a leaf's for every cell inside it).
    pub state: ValueState<V>,
}

impl<V: Value> InputNode<V> {
    /// The node at `depth`, `index` of `tree`, of state `state`.
    fn at<const K: usize, T: ValueStorage<K, Value = V>>(
        tree: &T,
        depth: usize,
        index: usize,
        state: ValueState<V>,
    ) -> Result<Self, T::Error> {
        let first = if state.has_children() {
            tree.children(depth, index)?
        } else {
            0
        };
        Ok(Self {
            depth,
            first,
            state,
        })
    }

    /// The root of a valued tree.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn root<const K: usize, T: ValueStorage<K, Value = V>>(tree: &T) -> Result<Self, T::Error> {
        Self::at(tree, 0, 0, tree.root()?.state)
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
        let depth = self.depth + 1;
        let codes = tree.codes(depth, self.first)?;
        let index = self.first + code;
        let state = tree.decode(depth, index, codes >> (2 * code))?;
        Self::at(tree, depth, index, state)
    }
}
