//! Valued trees: every voxel empty or holding a value of one type `V` ([`Value`]), in one minimal tree.
//!
//! # Layout
//! The levels are those of a binary tree, two bits a node, in level order, with one more code:
//! * `00` empty: no voxel holds a value;
//! * `01` full: every voxel holds the same value, stored in the level's value column;
//! * `10` partial: some voxels are empty, some hold values — `2^K` children;
//! * `11` mixed: every voxel holds a value, not all the same one — `2^K` children.
//!
//! The children of the `i`-th node with children (`10` or `11`) of a level are nodes `2^K·i …` of the level
//! below, found by the same rank as a binary tree's; the value of the `j`-th full node of a level is the
//! `j`-th of its value column, found by a rank over its full nodes. A binary tree is the case without values
//! (`V = ()`): no `11` code, no value column, the same bits and speed. About 2.13 bits a node plus the
//! value's bits a full node ([`KTree::heap_bytes`]).
//!
//! The tree is *minimal*: a node is a leaf exactly when all its voxels are empty, or all hold one equal
//! value, so two trees of the same voxels and values are equal node for node.
//!
//! # The shape
//! [`KTree::shape`] is the binary tree of the voxels that hold a value (a mixed node is a full leaf of it):
//! every Boolean, query, shape operation, picture and export of the crate applies to it as to any tree.
//!
//! ```
//! use ktree::KTree;
//! // Four voxels of a bintree: label 3, 3, empty, 7.
//! let tree = KTree::<1, u8>::from_dense_values(2, &[Some(3), Some(3), None, Some(7)]).unwrap();
//! tree.assert_well_formed();
//! assert_eq!(tree.value_at([1]), Some(3));
//! assert_eq!(tree.value_at([2]), None);
//! assert_eq!(tree.node_count(), 5); // the root, [3 3] as one full node, the partial [_ 7] and its two voxels
//! assert_eq!(tree.to_dense_values().unwrap(), [Some(3), Some(3), None, Some(7)]);
//! assert_eq!(tree.shape(), KTree::<1>::from_dense(2, &[true, true, false, true]).unwrap());
//! ```
//!
//! # Modules
//! [`walk`]: reading a valued tree — the storage trait over trees in memory and files read in place, its
//! depth-first walk and its leaves, and the tree read as its shape's leaves ([`LeavesOfValues`]);
//! [`ValueAssembler`]: a valued tree collected from a depth-first traversal; [`ValueCursor`]: point
//! location that remembers its last path; the dense reference builder; a level as it is written
//! (`ValuedLevel`).

mod assemble;
mod cursor;
mod dense;
mod level;
pub mod walk;

pub use assemble::ValueAssembler;
pub use cursor::ValueCursor;
pub(crate) use dense::for_each_voxel;
pub(crate) use level::ValuedLevel;
pub(crate) use walk::mixed_as_partial;
pub use walk::{
    try_walk_values, BinaryValues, LeafValue, LeavesOfValues, ValueLeaves, ValueStorage,
    ValueVisitor,
};

use super::ktree::{KTree, TreeId};
use super::sink::{LevelSink, MemorySink};
use super::states::{FullRank, NodeState, PackedStates};
use super::storage::infallible;
use super::words::{children_mask, full_mask, unused_mask, LOW_BITS};
use super::TreeError;
use crate::space::{Cell, SpaceError, Universe, DENSE_LIMIT};
use crate::value::{Value, ValueError};

/// The values of a level's full nodes, in level order, and the rank over the level's full nodes that finds
/// a node's value.
#[derive(Debug, Clone, Default)]
pub(crate) struct LevelValues<V> {
    pub(crate) values: Vec<V>,
    pub(crate) rank: FullRank,
}

impl<V: Value> PartialEq for LevelValues<V> {
    fn eq(&self, other: &Self) -> bool {
        self.values.len() == other.values.len()
            && self
                .values
                .iter()
                .zip(&other.values)
                .all(|(a, b)| a.same(*b))
    }
}

impl<V: Value> std::hash::Hash for LevelValues<V> {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        for v in &self.values {
            v.key().hash(state);
        }
    }
}

/// A node of a valued tree as it is stored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ValueState<V> {
    /// No voxel holds a value (code `00`).
    Empty,
    /// Every voxel holds this value (code `01`).
    Full(V),
    /// Some voxels are empty, some hold values (code `10`): the node has children.
    Partial,
    /// Every voxel holds a value, not all the same one (code `11`): the node has children.
    Mixed,
}

impl<V> ValueState<V> {
    /// Whether the node has children.
    #[inline]
    pub fn has_children(&self) -> bool {
        matches!(self, ValueState::Partial | ValueState::Mixed)
    }

    /// The node as a node of the tree's shape ([`KTree::shape`]): a mixed node is full.
    #[inline]
    pub fn shape(&self) -> NodeState {
        match self {
            ValueState::Empty => NodeState::Empty,
            ValueState::Full(_) | ValueState::Mixed => NodeState::Full,
            ValueState::Partial => NodeState::Partial,
        }
    }
}

/// A node met by a walk of a valued tree: its index in its level, its cell and its state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValueNode<const K: usize, V> {
    /// The node's index within its level.
    pub index: usize,
    /// The node's cell (its level is the node's depth).
    pub cell: Cell<K>,
    /// The node's state, with the value of a full node.
    pub state: ValueState<V>,
}
impl<const K: usize, V: Value> KTree<K, V> {
    /// Assembles a tree from its levels and their full nodes' values. The caller guarantees the structure
    /// (see [`KTree::check`]).
    pub(crate) fn from_valued_levels(
        universe: Universe<K>,
        levels: Vec<PackedStates>,
        values: Vec<Vec<V>>,
    ) -> Self {
        let values = if V::STORED {
            levels
                .iter()
                .zip(values)
                .map(|(level, mut values)| {
                    // Built by pushing: the slack of growth is given back.
                    values.shrink_to_fit();
                    LevelValues {
                        rank: FullRank::new(level),
                        values,
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        Self {
            universe,
            levels,
            values,
            id: TreeId::fresh(),
        }
    }

    /// The tree of a dense array of voxels (axis 0 fastest, see [`Universe::dense_index`]), each empty
    /// (`None`) or holding a value; minimal.
    ///
    /// # Errors
    /// [`TreeError::Space`] for a level beyond [`crate::max_level`], a universe beyond
    /// [`DENSE_LIMIT`](crate::space::DENSE_LIMIT) or an array of another length than `U^K`;
    /// [`TreeError::Value`] for a value no voxel may hold (a NaN).
    pub fn from_dense_values(level: u32, dense: &[Option<V>]) -> Result<Self, TreeError> {
        dense::reference_pyramid::<K, V>(level, dense)
    }

    /// The value of voxel `point`: `None` where it is empty or outside the universe.
    pub fn value_at(&self, point: [u32; K]) -> Option<V> {
        self.leaf_at(point).and_then(|(_, v)| v)
    }

    /// The leaf holding voxel `point` — the log of its side and its value (`None`: empty) — or `None`
    /// outside the universe. Every voxel of the leaf's cell (`point` with its lowest `log_side` bits
    /// cleared on each axis) has that value, so a walk through neighbouring voxels looks again only
    /// once it leaves the cell.
    ///
    /// ```
    /// use ktree::KTree;
    /// // A quadtree of level 2: the first quadrant holds 3, voxel (2, 0) holds 5.
    /// let tree = KTree::<2, u8>::from_dense_values(2, &[
    ///     Some(3), Some(3), Some(5), None,
    ///     Some(3), Some(3), None, None,
    ///     None, None, None, None,
    ///     None, None, None, None,
    /// ]).unwrap();
    /// assert_eq!(tree.leaf_at([1, 1]), Some((1, Some(3))));
    /// assert_eq!(tree.leaf_at([2, 0]), Some((0, Some(5))));
    /// assert_eq!(tree.leaf_at([3, 3]), Some((1, None)));
    /// assert_eq!(tree.leaf_at([4, 0]), None);
    /// ```
    pub fn leaf_at(&self, point: [u32; K]) -> Option<(u32, Option<V>)> {
        infallible(self.try_leaf_at(point))
    }

    /// The leaves with their values (`None`: empty), in Morton order.
    pub fn value_leaves(&self) -> impl Iterator<Item = (Cell<K>, Option<V>)> + '_ {
        ValueLeaves::new(self).map(infallible)
    }

    /// The dense array of the voxels' values (axis 0 fastest, see [`Universe::dense_index`]).
    ///
    /// # Errors
    /// [`SpaceError::TooLargeForDense`] if the universe exceeds [`DENSE_LIMIT`].
    pub fn to_dense_values(&self) -> Result<Vec<Option<V>>, SpaceError> {
        let len = self.universe.dense_len(DENSE_LIMIT)?;
        let mut dense = vec![None; len];
        for (cell, value) in self.value_leaves() {
            if value.is_some() {
                for_each_voxel(&self.universe, &cell, |i| dense[i] = value);
            }
        }
        Ok(dense)
    }

    /// The binary tree of the voxels that hold a value: a mixed node is a full leaf of it. Every operation
    /// of the crate on binary trees applies to it. `O(nodes)`.
    pub fn shape(&self) -> KTree<K> {
        let mut sink = MemorySink::<K>::new(self.universe);
        // Depth first, children in code order: the partial nodes of each depth come in level order, and
        // so do the blocks of their children appended to the level below.
        let mut stack: Vec<(usize, usize)> = Vec::new();
        let root = infallible(self.root_code());
        if root == 2 {
            stack.push((0, 0));
        }
        while let Some((depth, index)) = stack.pop() {
            let first = infallible(self.children(depth, index));
            let codes = u64::from(self.levels[depth + 1].block_codes(first, K));
            // A mixed child is a full leaf of the shape: `11` becomes `01`.
            let shape = codes & !(unused_mask(codes) << 1);
            infallible(sink.append(depth + 1, shape, 1 << K));
            for code in (0..1usize << K).rev() {
                if codes >> (2 * code) & 3 == 2 {
                    stack.push((depth + 1, first + code));
                }
            }
        }
        let root = match root {
            0 => NodeState::Empty,
            2 => NodeState::Partial,
            _ => NodeState::Full,
        };
        infallible(sink.finish(root))
    }

    /// The invariants of a valued tree ([`KTree::check`]): level sizes, the codes (a mixed node only where `V` carries values,
    /// under a mixed node neither empty nor partial nodes), minimality (no node with children whose
    /// children are all empty, or all full of one value; a partial node's children not all holding values),
    /// one value per full node and no NaN.
    ///
    pub(crate) fn check_values(&self) -> Result<(), TreeError> {
        let level = self.level();
        if self.levels.is_empty() || self.levels[0].len() != 1 {
            return Err(TreeError::Root {
                nodes: self.levels.first().map_or(0, PackedStates::len),
            });
        }
        if self.levels.len() > level as usize + 1 {
            return Err(TreeError::TooDeep {
                levels: self.levels.len(),
                level,
            });
        }
        if V::STORED && self.values.len() != self.levels.len() {
            return Err(TreeError::ValueCount {
                depth: self.values.len().min(self.levels.len()),
                full: 0,
                values: 0,
            });
        }
        for (depth, states) in self.levels.iter().enumerate() {
            let words = states.words();
            if !V::STORED && words.iter().any(|&w| unused_mask(w) != 0) {
                let w = words.iter().position(|&w| unused_mask(w) != 0).unwrap_or(0);
                return Err(TreeError::UnusedCode {
                    node: w * 32 + unused_mask(words[w]).trailing_zeros() as usize / 2,
                });
            }
            let with_children: usize = words
                .iter()
                .map(|&w| children_mask(w).count_ones() as usize)
                .sum();
            let next = self.levels.get(depth + 1).map_or(0, PackedStates::len);
            if next != with_children << K {
                return Err(TreeError::LevelSize {
                    depth,
                    partial: with_children,
                    next,
                });
            }
            if with_children > 0 && depth as u32 == level {
                return Err(TreeError::PartialVoxel { depth });
            }
            if V::STORED {
                let full: usize = words
                    .iter()
                    .map(|&w| full_mask(w).count_ones() as usize)
                    .sum();
                let values = &self.values[depth].values;
                if values.len() != full {
                    return Err(TreeError::ValueCount {
                        depth,
                        full,
                        values: values.len(),
                    });
                }
                if let Some(e) = values.iter().find_map(|v| v.check().err()) {
                    return Err(TreeError::Value(e));
                }
            }
        }
        // Each node with children against its children.
        for depth in 0..self.levels.len().saturating_sub(1) {
            let states = &self.levels[depth];
            for index in 0..states.len() {
                let code = (states.words()[index / 32] >> (2 * (index % 32))) & 3;
                if code < 2 {
                    continue;
                }
                let first = infallible(self.children(depth, index));
                let codes = u64::from(self.levels[depth + 1].block_codes(first, K));
                let n = 1usize << K;
                let mask = if n == 32 {
                    u64::MAX
                } else {
                    (1u64 << (2 * n)) - 1
                };
                let low = LOW_BITS & mask;
                let empty_or_partial = !codes & low; // the low bit clear: 00 or 10
                let all_empty = codes & mask == 0;
                let all_full = full_mask(codes) & low == low;
                let valued = empty_or_partial == 0; // every child 01 or 11
                let bad = if all_empty {
                    true
                } else if all_full {
                    // All full: minimal only if the values differ (a mixed node).
                    !V::STORED || {
                        let v0 = infallible(self.value(depth + 1, first));
                        (1..n).all(|c| infallible(self.value(depth + 1, first + c)).same(v0))
                    }
                } else {
                    // A partial node must have an empty or partial child; a mixed one must not.
                    (code == 2) == valued
                };
                if bad || (code == 3 && !valued) {
                    return Err(TreeError::NotMinimal { depth, index });
                }
            }
        }
        Ok(())
    }
}

/// The state of a node from its children's: the one rule of minimality.
///
/// ```
/// use ktree::tree::valued::{combine, ValueState};
/// use ValueState::*;
/// assert_eq!(combine(&[Full(2u8), Full(2)]), Full(2));
/// assert_eq!(combine(&[Full(2u8), Full(3)]), Mixed);
/// assert_eq!(combine(&[Full(2u8), Mixed]), Mixed);
/// assert_eq!(combine(&[Empty, Full(3u8)]), Partial);
/// assert_eq!(combine::<u8>(&[Empty, Empty]), Empty);
/// ```
pub fn combine<V: Value>(kids: &[ValueState<V>]) -> ValueState<V> {
    let first = kids[0];
    match first {
        ValueState::Empty if kids.iter().all(|k| matches!(k, ValueState::Empty)) => {
            ValueState::Empty
        }
        ValueState::Full(v)
            if kids
                .iter()
                .all(|k| matches!(k, ValueState::Full(w) if w.same(v))) =>
        {
            ValueState::Full(v)
        }
        _ if kids
            .iter()
            .all(|k| matches!(k, ValueState::Full(_) | ValueState::Mixed)) =>
        {
            ValueState::Mixed
        }
        _ => ValueState::Partial,
    }
}

/// A value no voxel may hold, as the trees' error.
impl From<ValueError> for TreeError {
    fn from(e: ValueError) -> Self {
        TreeError::Value(e)
    }
}
