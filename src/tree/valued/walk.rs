//! Reading a valued tree: one storage trait for trees in memory and files read in place, walks and leaves.

use std::convert::Infallible;

use smallvec::SmallVec;

use super::{ValueNode, ValueState};
use crate::space::{Cell, Universe};
use crate::tree::cursor::Walk;
use crate::tree::error::StorageError;
use crate::tree::ktree::KTree;
use crate::tree::states::NodeState;
use crate::tree::storage::{infallible, TreeStorage};
use crate::value::Value;

/// A leaf met by a look-up: the log of its side and its value (`None`: empty).
pub type LeafValue<V> = (u32, Option<V>);

/// A valued tree stored in level order, read one block of siblings at a time, reads failing like those of
/// [`TreeStorage`]: a valued tree in memory ([`KTree`] with a value type,
/// [`Infallible`] reads) or a valued `.ktree` file read in place. A binary tree is one with `Value = ()`.
pub trait ValueStorage<const K: usize> {
    /// What a voxel holds.
    type Value: Value;
    /// Why a read failed ([`Infallible`] in memory).
    type Error: std::error::Error + Into<StorageError> + Send + Sync + 'static;

    /// The universe.
    fn universe(&self) -> Universe<K>;

    /// The number of stored levels.
    fn depth_count(&self) -> usize;

    /// The root's 2-bit code (`00`, `01`, `10` or `11`).
    ///
    /// # Errors
    /// The storage's read error.
    fn root_code(&self) -> Result<u32, Self::Error>;

    /// The 2-bit codes of the `2^K` siblings of level `depth` from `first` (a multiple of `2^K`), the first in
    /// the low bits.
    ///
    /// # Errors
    /// The storage's read error.
    fn codes(&self, depth: usize, first: usize) -> Result<u32, Self::Error>;

    /// The index in level `depth + 1` of the first child of node `index` of level `depth`, a node with
    /// children (partial or mixed).
    ///
    /// # Errors
    /// The storage's read error.
    fn children(&self, depth: usize, index: usize) -> Result<usize, Self::Error>;

    /// The value of the full node `index` of level `depth`.
    ///
    /// # Errors
    /// The storage's read error.
    fn value(&self, depth: usize, index: usize) -> Result<Self::Value, Self::Error>;

    /// The universe level `L`.
    fn level(&self) -> u32 {
        self.universe().level()
    }

    /// The state of a node of level `depth`, index `index`, whose code is `code`.
    ///
    /// # Errors
    /// The storage's read error.
    #[inline]
    fn decode(
        &self,
        depth: usize,
        index: usize,
        code: u32,
    ) -> Result<ValueState<Self::Value>, Self::Error> {
        Ok(match code & 3 {
            0 => ValueState::Empty,
            1 => ValueState::Full(self.value(depth, index)?),
            2 => ValueState::Partial,
            _ => ValueState::Mixed,
        })
    }

    /// The leaf holding voxel `point` — the log of its side and its value (`None`: empty) — or `None`
    /// outside the universe, on any storage ([`KTree::leaf_at`] in memory).
    ///
    /// ```
    /// use ktree::tree::valued::ValueStorage;
    /// let tree = ktree::KTree::<3, u8>::from_dense_values(1, &[Some(4); 8]).unwrap();
    /// assert_eq!(tree.try_leaf_at([1, 0, 1]), Ok(Some((1, Some(4)))));
    /// ```
    ///
    /// # Errors
    /// The storage's read error.
    fn try_leaf_at(&self, point: [u32; K]) -> Result<Option<LeafValue<Self::Value>>, Self::Error> {
        if self.universe().check_point(point).is_err() {
            return Ok(None);
        }
        let (mut depth, mut index) = (0usize, 0usize);
        let mut code = self.root_code()?;
        let mut log_side = self.level();
        while code >= 2 {
            log_side -= 1;
            let child = (0..K).fold(0, |c, a| c | ((point[a] >> log_side & 1) as usize) << a);
            index = self.children(depth, index)? + child;
            depth += 1;
            code = (self.codes(depth, index - child)? >> (2 * child)) & 3;
        }
        let value = if code == 1 {
            Some(self.value(depth, index)?)
        } else {
            None
        };
        Ok(Some((log_side, value)))
    }

    /// The root node.
    ///
    /// # Errors
    /// The storage's read error.
    fn root(&self) -> Result<ValueNode<K, Self::Value>, Self::Error> {
        Ok(ValueNode {
            index: 0,
            cell: self.universe().root(),
            state: self.decode(0, 0, self.root_code()?)?,
        })
    }
}

impl<const K: usize, V: Value> ValueStorage<K> for KTree<K, V> {
    type Value = V;
    type Error = Infallible;

    #[inline]
    fn universe(&self) -> Universe<K> {
        self.universe
    }

    #[inline]
    fn depth_count(&self) -> usize {
        self.levels.len()
    }

    #[inline]
    fn root_code(&self) -> Result<u32, Infallible> {
        Ok((self.levels[0].words()[0] & 3) as u32)
    }

    #[inline(always)]
    fn codes(&self, depth: usize, first: usize) -> Result<u32, Infallible> {
        Ok(self.levels[depth].block_codes(first, K))
    }

    #[inline(always)]
    fn children(&self, depth: usize, index: usize) -> Result<usize, Infallible> {
        Ok(self.levels[depth].partial_rank(index) << K)
    }

    #[inline]
    fn value(&self, depth: usize, index: usize) -> Result<V, Infallible> {
        if !V::STORED {
            return Ok(V::read_le(&[]));
        }
        let level = &self.values[depth];
        Ok(level.values[level.rank.rank(&self.levels[depth], index)])
    }
}

/// A binary tree read as a valued tree whose full voxels hold `()`: what lets one valued code path serve
/// binary trees in memory and mapped `.ktree` files alike.
///
/// ```
/// use ktree::tree::valued::{BinaryValues, ValueStorage};
/// use ktree::KTree;
/// let tree = KTree::<2>::from_dense(1, &[true, false, true, true]).unwrap();
/// let seen = BinaryValues(&tree);
/// assert_eq!(seen.value(1, 0), Ok(()));
/// assert_eq!(seen.codes(1, 0), Ok(0b01_01_00_01));
/// ```
#[derive(Debug, Clone, Copy)]
pub struct BinaryValues<'a, T>(pub &'a T);

impl<const K: usize, T: TreeStorage<K>> ValueStorage<K> for BinaryValues<'_, T> {
    type Value = ();
    type Error = T::Error;

    fn universe(&self) -> Universe<K> {
        self.0.universe()
    }

    fn depth_count(&self) -> usize {
        self.0.depth_count()
    }

    fn root_code(&self) -> Result<u32, T::Error> {
        Ok(self.0.root_state()? as u32)
    }

    #[inline(always)]
    fn codes(&self, depth: usize, first: usize) -> Result<u32, T::Error> {
        self.0.block_codes(depth, first)
    }

    #[inline(always)]
    fn children(&self, depth: usize, index: usize) -> Result<usize, T::Error> {
        self.0.first_child(depth, index)
    }

    #[inline]
    fn value(&self, _depth: usize, _index: usize) -> Result<(), T::Error> {
        Ok(())
    }
}

/// A walk of a valued tree: sees each node before its children.
pub trait ValueVisitor<const K: usize, V> {
    /// Sees a node; says whether to visit its children, skip them, or stop.
    fn visit(&mut self, node: &ValueNode<K, V>) -> Walk;

    /// Called after the children of a node have all been visited (not when they were skipped).
    #[inline]
    fn leave(&mut self, _node: &ValueNode<K, V>) {}
}

/// Walks a valued tree depth first from the root, children in code (Morton) order. `Ok(true)` if the
/// visitor stopped the walk.
///
/// # Errors
/// The storage's first read error.
pub fn try_walk_values<const K: usize, T: ValueStorage<K>, W: ValueVisitor<K, T::Value>>(
    tree: &T,
    visitor: &mut W,
) -> Result<bool, T::Error> {
    let mut stack: SmallVec<[(ValueNode<K, T::Value>, bool); 64]> = SmallVec::new();
    stack.push((tree.root()?, false));
    while let Some((node, leaving)) = stack.pop() {
        if leaving {
            visitor.leave(&node);
            continue;
        }
        match visitor.visit(&node) {
            Walk::Stop => return Ok(true),
            Walk::Skip => continue,
            Walk::Descend if !node.state.has_children() => continue,
            Walk::Descend => {}
        }
        let depth = node.cell.level as usize;
        let first = tree.children(depth, node.index)?;
        let codes = tree.codes(depth + 1, first)?;
        stack.push((node, true));
        for code in (0..1usize << K).rev() {
            let index = first + code;
            stack.push((
                ValueNode {
                    index,
                    cell: node.cell.child(code),
                    state: tree.decode(depth + 1, index, codes >> (2 * code))?,
                },
                false,
            ));
        }
    }
    Ok(false)
}

/// The leaves of a valued tree, in Morton order: each leaf's cell and value (`None` for an empty leaf),
/// or the storage's read error (after which the iterator ends).
#[derive(Debug, Clone)]
pub struct ValueLeaves<'a, const K: usize, T: ValueStorage<K>> {
    tree: &'a T,
    stack: Vec<ValueNode<K, T::Value>>,
    fresh: bool,
}

impl<'a, const K: usize, T: ValueStorage<K>> ValueLeaves<'a, K, T> {
    /// The leaves of `tree`.
    pub fn new(tree: &'a T) -> Self {
        Self {
            tree,
            stack: Vec::new(),
            fresh: true,
        }
    }
}

impl<const K: usize, T: ValueStorage<K>> Iterator for ValueLeaves<'_, K, T> {
    type Item = Result<(Cell<K>, Option<T::Value>), T::Error>;

    fn next(&mut self) -> Option<Self::Item> {
        if std::mem::take(&mut self.fresh) {
            match self.tree.root() {
                Ok(root) => self.stack.push(root),
                Err(e) => return Some(Err(e)),
            }
        }
        while let Some(node) = self.stack.pop() {
            match node.state {
                ValueState::Empty => return Some(Ok((node.cell, None))),
                ValueState::Full(v) => return Some(Ok((node.cell, Some(v)))),
                ValueState::Partial | ValueState::Mixed => {}
            }
            let depth = node.cell.level as usize;
            let read = self.tree.children(depth, node.index).and_then(|first| {
                let codes = self.tree.codes(depth + 1, first)?;
                for code in (0..1usize << K).rev() {
                    let index = first + code;
                    self.stack.push(ValueNode {
                        index,
                        cell: node.cell.child(code),
                        state: self.tree.decode(depth + 1, index, codes >> (2 * code))?,
                    });
                }
                Ok(())
            });
            if let Err(e) = read {
                self.stack.clear();
                return Some(Err(e));
            }
        }
        None
    }
}

/// A valued tree read as a tree without values of the same nodes — a mixed node (`11`) reads as a node
/// with children (`10`) — so every walk, picture and query of a [`TreeStorage`]
/// sees each full leaf of the valued tree as one full leaf: the leaves where one value holds. The tree it
/// shows is the valued tree's [shape](KTree::shape), not reduced where a mixed node stands.
///
/// ```
/// use ktree::tree::valued::LeavesOfValues;
/// use ktree::tree::cursor::TryLeaves;
/// use ktree::KTree;
/// let t = KTree::<1, u8>::from_dense_values(1, &[Some(1), Some(2)]).unwrap(); // a mixed root
/// let leaves: Vec<_> = TryLeaves::new(&LeavesOfValues(&t)).collect::<Result<_, _>>().unwrap();
/// assert_eq!(leaves.len(), 2); // the shape alone has one full leaf
/// ```
#[derive(Debug, Clone, Copy)]
pub struct LeavesOfValues<'a, const K: usize, V: Value>(pub &'a KTree<K, V>);

/// Each mixed code (`11`) of `codes` turned into `10`.
#[inline]
pub(crate) fn mixed_as_partial(codes: u32) -> u32 {
    let mixed = codes & (codes >> 1) & 0x5555_5555;
    codes & !mixed
}

impl<const K: usize, V: Value> TreeStorage<K> for LeavesOfValues<'_, K, V> {
    type Error = Infallible;

    fn universe(&self) -> Universe<K> {
        self.0.universe
    }

    fn depth_count(&self) -> usize {
        self.0.levels.len()
    }

    fn level_len(&self, depth: usize) -> usize {
        self.0.levels[depth].len()
    }

    fn counts_per_level(&self) -> Vec<crate::tree::LevelCounts> {
        self.0.counts_per_level()
    }

    fn root_state(&self) -> Result<NodeState, Infallible> {
        Ok(NodeState::from_bits(mixed_as_partial(infallible(
            self.0.root_code(),
        ))))
    }

    #[inline(always)]
    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, Infallible> {
        Ok(self.0.levels[depth].partial_rank(index))
    }

    #[inline(always)]
    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, Infallible> {
        Ok(mixed_as_partial(self.0.levels[depth].block_codes(first, K)))
    }
}
