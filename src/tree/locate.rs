//! Point location: the one descent from a node towards a voxel or an aligned cell, on any storage.
//!
//! [`PointCursor`] remembers its last path from the root, so that a point near the previous one (a
//! neighbour, the next voxel in Morton order) is found from their deepest common ancestor instead of from
//! the root, and a point in a sibling of the last leaf reads nothing from the tree. Every point query of
//! the crate (batch `contains`, line drawings' neighbour tests, resampling, zooms) goes through it;
//! [`locate`] is the descent for one cell from a given node.
//!
//! ```
//! use ktree::tree::locate::{locate, PointCursor};
//! use ktree::{KTree, NodeState};
//! let tree = KTree::<2>::from_dense(3, &(0..64).map(|i| i % 5 == 0).collect::<Vec<_>>()).unwrap();
//! let mut cursor = PointCursor::new(&tree).unwrap();
//! for p in [[3, 4], [3, 5], [7, 0], [0, 0], [9, 9]] {
//!     assert_eq!(cursor.contains(p).unwrap(), tree.contains(p));
//! }
//! // The node holding the 2 × 2 cell at (4, 4): a leaf above it or the cell's own node.
//! let cell = tree.universe().cell([4, 4], 2).unwrap();
//! let node = cursor.locate(&cell).unwrap();
//! assert_eq!(node, locate(&tree, tree.root(), &cell).unwrap());
//! assert!(node.depth() <= 2 && node.cell().origin() == [4, 4]);
//! ```

use super::ktree::{NodeRef, TreeId};
use super::states::NodeState;
use super::storage::TreeStorage;
use crate::space::Cell;

/// The depth of the deepest node a path can hold (the largest universe level) plus one.
const PATH: usize = 33;

/// Point location that remembers its last path from the root (see the module's notes). Works on any
/// storage; gives what a descent from the root gives.
#[derive(Debug, Clone)]
pub struct PointCursor<'a, const K: usize, T> {
    tree: &'a T,
    level: u32,
    /// `(index, state)` of the node at each depth of the last path.
    path: [(usize, NodeState); PATH],
    /// For each partial node of the last path but the deepest: its first child and its children's codes,
    /// so that a point in a sibling of the last leaf reads nothing from the tree.
    children: [(usize, u32); PATH],
    /// Nodes on the last path (at least the first).
    len: usize,
    /// The depth of the first node of the path: 0 (the root) unless the cursor was started at a node.
    top: usize,
    /// The origin of the last point or cell located.
    last: [u32; K],
    /// The tree the nodes handed out belong to.
    id: TreeId,
}

impl<'a, const K: usize, T: TreeStorage<K>> PointCursor<'a, K, T> {
    /// A cursor over `tree`, its path at the root.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn new(tree: &'a T) -> Result<Self, T::Error> {
        Self::at(tree, tree.root()?)
    }

    /// A cursor whose path starts at `start`, a node of `tree`: it locates the points and cells inside
    /// `start`'s cell (others are located as if `start`'s cell were the universe).
    ///
    /// # Errors
    /// The storage's read error.
    ///
    /// # Panics
    /// If `start` is a node of another tree (see [`NodeRef`]).
    #[track_caller]
    pub fn at(tree: &'a T, start: NodeRef<K>) -> Result<Self, T::Error> {
        start.assert_of(tree.root()?.tree);
        let mut path = [(0, NodeState::Empty); PATH];
        let top = start.cell.level as usize;
        path[top] = (start.index, start.state);
        Ok(Self {
            tree,
            level: tree.level(),
            path,
            children: [(0, 0); PATH],
            len: top + 1,
            top,
            last: start.cell.origin,
            id: start.tree,
        })
    }

    /// The one descent: from the deepest node the last path shares with `origin`'s, down towards
    /// `origin` until a leaf or depth `target` (a depth `≥` the cursor's start). Returns the node's depth,
    /// index and state.
    #[inline(always)]
    fn descend(
        &mut self,
        origin: [u32; K],
        target: usize,
    ) -> Result<(usize, usize, NodeState), T::Error> {
        // The ancestors of the last point down to depth `common` are this one's: the highest bit in which
        // any coordinate differs from the last point's is the depth where the paths part.
        let changed = (0..K).fold(0u32, |or, a| or | (self.last[a] ^ origin[a]));
        let differ = 32 - changed.leading_zeros();
        let common = (self.level.saturating_sub(differ) as usize).max(self.top);
        let mut depth = common.min(self.len - 1).min(target);
        let (mut index, mut state) = self.path[depth];
        // A partial node above the last path's end was descended last time: its children are known.
        let mut known = depth + 1 < self.len;
        // Only this prefix is sure to be the last point's path should a read below fail.
        self.len = depth + 1;
        while state == NodeState::Partial && depth < target {
            let bit = self.level - 1 - depth as u32;
            let code = (0..K).fold(0usize, |c, a| c | ((origin[a] >> bit & 1) as usize) << a);
            let (first, codes) = if known {
                self.children[depth]
            } else {
                let first = self.tree.first_child(depth, index)?;
                let read = (first, self.tree.block_codes(depth + 1, first)?);
                self.children[depth] = read;
                read
            };
            known = false;
            index = first + code;
            state = NodeState::from_bits(codes >> (2 * code));
            depth += 1;
            self.path[depth] = (index, state);
        }
        self.len = depth + 1;
        self.last = origin;
        Ok((depth, index, state))
    }

    /// The state of the leaf holding voxel `point`; [`NodeState::Empty`] outside the universe.
    ///
    /// # Errors
    /// The storage's read error.
    #[inline]
    pub fn state(&mut self, point: [u32; K]) -> Result<NodeState, T::Error> {
        // Outside the universe: a coordinate with a bit at or above the level.
        let all = point.iter().fold(0u64, |or, &c| or | u64::from(c));
        if all >> self.level != 0 {
            return Ok(NodeState::Empty);
        }
        Ok(self.descend(point, self.level as usize)?.2)
    }

    /// Whether voxel `point` is inside the object (outside the universe: `false`).
    ///
    /// # Errors
    /// The storage's read error.
    #[inline]
    pub fn contains(&mut self, point: [u32; K]) -> Result<bool, T::Error> {
        Ok(self.state(point)? == NodeState::Full)
    }

    /// The node whose cell contains the aligned cell `target` (of the tree's universe) and is either a
    /// leaf or `target` itself.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn locate(&mut self, target: &Cell<K>) -> Result<NodeRef<K>, T::Error> {
        let (depth, index, state) = self.descend(target.origin, target.level as usize)?;
        let log_side = self.level - depth as u32;
        let low = ((1u64 << log_side) - 1) as u32;
        Ok(NodeRef {
            index,
            cell: Cell {
                origin: target.origin.map(|o| o & !low),
                level: depth as u32,
                log_side,
            },
            state,
            tree: self.id,
        })
    }
}

/// The node of `tree` whose cell contains the aligned cell `target` and is either a leaf or `target`
/// itself, found by descending from `start` (a node whose cell contains `target`; usually the root) one
/// child at a time, towards `target`: `O(levels descended)` rank lookups. For many targets near one
/// another, a [`PointCursor`] reads less.
///
/// ```
/// use ktree::tree::locate::locate;
/// use ktree::{KTree, NodeState};
/// let tree = KTree::<1>::from_dense(2, &[false, true, true, true]).unwrap();
/// let voxel = tree.universe().cell([3], 2).unwrap();
/// let node = locate(&tree, tree.root(), &voxel).unwrap();
/// assert_eq!((node.state(), node.cell().side()), (NodeState::Full, 2));
/// ```
///
/// # Errors
/// The storage's read error.
///
/// # Panics
/// If `start` is a node of another tree (see [`NodeRef`]).
#[track_caller]
pub fn locate<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    start: NodeRef<K>,
    target: &Cell<K>,
) -> Result<NodeRef<K>, T::Error> {
    debug_assert!(start.cell.level <= target.level);
    PointCursor::at(tree, start)?.locate(target)
}
