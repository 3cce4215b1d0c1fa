//! `KTree<K>`: a compact, pointer-free, navigable k-tree in level order.

use std::sync::atomic::{AtomicU64, Ordering};

use super::cursor::Leaves;
use super::states::{node_out_of_range, NodeState, PackedStates};
use super::valued::LevelValues;
use super::TreeError;
use crate::value::Value;

use crate::space::{Cell, DimCheck, SpaceError, Universe};

/// Node counts of one level (or of a whole tree): Meagher's complexity metric.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LevelCounts {
    /// The level (depth, 0 = root); for a whole-tree total, the universe level.
    pub level: u32,
    /// Full nodes.
    pub full: u64,
    /// Empty nodes.
    pub empty: u64,
    /// Partial nodes.
    pub partial: u64,
}

impl LevelCounts {
    /// The sum of per-level counts, labelled with the universe level `level`.
    pub fn total(level: u32, per_level: &[LevelCounts]) -> LevelCounts {
        per_level.iter().fold(
            LevelCounts {
                level,
                ..Default::default()
            },
            |t, c| LevelCounts {
                level,
                full: t.full + c.full,
                empty: t.empty + c.empty,
                partial: t.partial + c.partial,
            },
        )
    }

    /// All nodes.
    pub fn nodes(&self) -> u64 {
        self.full + self.empty + self.partial
    }
}

/// A k-tree over a `K`-dimensional universe of level `L`, stored in level order: level `d` is a packed array
/// of 2-bit node states ([`NodeState`]); the children of the `i`-th partial node of level `d` are the nodes
/// `2^K·i … 2^K·i + 2^K − 1` of level `d + 1`, in child-code order (see [`crate::space`]). Navigation needs
/// only a rank over partial nodes, kept per level: about 2.07 bits a node in all ([`KTree::heap_bytes`];
/// see [`PackedStates`]).
///
/// Trees built by this crate are *reduced* (no partial node has children all full or all empty) and so
/// minimal and canonical: two trees of the same object are equal node for node, and `==` compares objects.
///
/// ```
/// use ktree::{KTree, NodeState};
/// // A 4×4 quadtree universe with the lower-left 2×2 quadrant full.
/// let mut dense = vec![false; 16];
/// for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] { dense[x + 4 * y] = true; }
/// let tree = KTree::<2>::from_dense(2, &dense).unwrap();
/// assert_eq!(tree.root_state(), NodeState::Partial);
/// assert_eq!(tree.node_count(), 5);
/// assert!(tree.contains([1, 1]) && !tree.contains([2, 1]));
/// assert_eq!(tree.to_dense().unwrap(), dense);
/// ```
///
/// The Boolean operations of [`crate::ops`] are also operators on `&KTree`: `|` (union), `&`
/// (intersection), `-` (difference), `^` (symmetric difference) give a `Result`, as trees of universes of
/// different levels do not combine (an [`crate::ops::OpsError::LevelMismatch`], not a panic); `!` is the
/// complement.
///
/// ```
/// use ktree::KTree;
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
/// assert_eq!((&a | &b)?.to_dense()?, [true, true, true, false]);
/// assert_eq!((&a & &b)?.to_dense()?, [false, true, false, false]);
/// assert_eq!((&a - &b)?.to_dense()?, [true, false, false, false]);
/// assert_eq!((&a ^ &b)?.to_dense()?, [true, false, true, false]);
/// assert_eq!((!&a).to_dense()?, [false, false, true, true]);
/// assert!((&a | &KTree::<1>::full(3)?).is_err()); // another universe
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Values
/// `KTree<K, V>` with a [`Value`] type `V` other than `()` is a *valued* tree: every voxel is empty or
/// holds a value of type `V` (a label, a density, a colour), full nodes hold one value each and nodes whose
/// voxels all hold values, not all equal, have the code `11` (see [`crate::tree::valued`]). `KTree<K>` is
/// `KTree<K, ()>`: no value column, the same bits and speed.
#[derive(Debug, Clone)]
pub struct KTree<const K: usize, V: Value = ()> {
    pub(crate) universe: Universe<K>,
    pub(crate) levels: Vec<PackedStates>,
    /// The values of each level's full nodes, with their rank index; empty when `V` is `()`.
    pub(crate) values: Vec<LevelValues<V>>,
    /// Which tree this is, for its [`NodeRef`]s: not part of the object (`==` ignores it); a clone keeps it.
    pub(crate) id: TreeId,
}

impl<const K: usize, V: Value> PartialEq for KTree<K, V> {
    fn eq(&self, other: &Self) -> bool {
        self.universe == other.universe
            && self.levels == other.levels
            && self.values == other.values
    }
}

impl<const K: usize, V: Value> Eq for KTree<K, V> {}

impl<const K: usize, V: Value> std::hash::Hash for KTree<K, V> {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.universe.hash(state);
        self.levels.hash(state);
        for level in &self.values {
            level.hash(state);
        }
    }
}

/// The identity of a built tree: the trees of one process get distinct ones, so that a [`NodeRef`] knows
/// the tree it belongs to. `TreeId::NONE` marks nodes of a tree without one (a memory-mapped tree).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct TreeId(u64);

impl TreeId {
    /// No identity.
    pub(crate) const NONE: TreeId = TreeId(0);

    /// A new identity, distinct from every other one handed out in this process.
    pub(crate) fn fresh() -> Self {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        TreeId(NEXT.fetch_add(1, Ordering::Relaxed))
    }
}

/// A bintree (K = 1).
pub type Bintree = KTree<1>;
/// A quadtree (K = 2).
pub type Quadtree = KTree<2>;
/// An octree (K = 3).
pub type Octree = KTree<3>;
/// A 4-D (e.g. time-space) tree (K = 4).
pub type Tree4 = KTree<4>;

/// A node of a tree, as seen while navigating: its position in level order, its cell and its state.
///
/// A `NodeRef` comes from the tree it belongs to ([`KTree::root`], [`KTree::children`], the walks of
/// [`crate::tree::cursor`]) and is navigated in that tree (or a clone of it) only: given to another tree's
/// [`KTree::children`], [`cursor::child`](crate::tree::cursor::child),
/// [`cursor::walk_from`](crate::tree::cursor::walk_from) or the other functions of the cursor that take a
/// node, it makes them panic with a message saying so, rather than read another tree's nodes.
///
/// ```
/// use ktree::{KTree, NodeState};
/// let tree = KTree::<1>::from_dense(1, &[true, false]).unwrap();
/// let root = tree.root();
/// assert_eq!((root.index(), root.depth(), root.state()), (0, 0, NodeState::Partial));
/// let kids: Vec<_> = tree.children(&root).map(|c| (c.cell().origin(), c.state())).collect();
/// assert_eq!(kids, [([0], NodeState::Full), ([1], NodeState::Empty)]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct NodeRef<const K: usize> {
    /// Index of the node within its level.
    pub(crate) index: usize,
    /// The node's cell (its level is the node's depth).
    pub(crate) cell: Cell<K>,
    /// The node's state.
    pub(crate) state: NodeState,
    /// The tree the node belongs to.
    pub(crate) tree: TreeId,
}

impl<const K: usize> NodeRef<K> {
    /// The node's index within its level (level order).
    #[inline]
    pub fn index(&self) -> usize {
        self.index
    }

    /// The node's cell; its level is the node's depth.
    #[inline]
    pub fn cell(&self) -> Cell<K> {
        self.cell
    }

    /// The node's depth (0 for the root), the level of its cell.
    #[inline]
    pub fn depth(&self) -> usize {
        self.cell.level as usize
    }

    /// The node's state.
    #[inline]
    pub fn state(&self) -> NodeState {
        self.state
    }

    /// Panics unless the node belongs to the tree of identity `tree`: the one check behind every function
    /// that navigates from a given node.
    #[inline]
    #[track_caller]
    pub(crate) fn assert_of(&self, tree: TreeId) {
        if self.tree != tree {
            node_of_another_tree(self.cell.level, self.index);
        }
    }
}

#[cold]
#[inline(never)]
#[track_caller]
fn node_of_another_tree(depth: u32, index: usize) -> ! {
    panic!(
        "the node at depth {depth}, index {index} belongs to another tree: a NodeRef is navigated only in \
         the tree (or a clone of the tree) it came from"
    )
}

impl<const K: usize, V: Value> KTree<K, V> {
    /// The number of children of a node that has children, `2^K`.
    pub const FANOUT: usize = 1 << K;

    /// The tree's identity, carried by its [`NodeRef`]s.
    #[inline]
    pub(crate) fn id(&self) -> TreeId {
        self.id
    }

    /// The universe.
    pub fn universe(&self) -> Universe<K> {
        self.universe
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        self.universe.level()
    }

    /// The number of stored levels (the depth of the deepest node plus one).
    pub fn depth_count(&self) -> usize {
        self.levels.len()
    }

    /// The packed states of level `depth`.
    pub fn level_states(&self, depth: usize) -> &PackedStates {
        &self.levels[depth]
    }

    /// The total number of nodes.
    pub fn node_count(&self) -> u64 {
        self.levels.iter().map(|l| l.len() as u64).sum()
    }

    /// Bytes needed at Meagher's 2 bits a node.
    pub fn bytes_at_two_bits(&self) -> u64 {
        self.node_count().div_ceil(4)
    }

    /// Checks the tree's invariants: level 0 holds the root, level sizes match the partial counts above, no
    /// partial node at the universe level, the last level has no partial node, and the tree is reduced (no
    /// partial node whose children are all full or all empty); for a valued tree, also the rules of
    /// [`crate::tree::valued`] (mixed nodes, one value a full node, minimality). Cost: `O(nodes)`.
    ///
    /// # Errors
    /// The first broken invariant.
    pub fn check(&self) -> Result<(), TreeError> {
        if V::STORED {
            self.check_values()
        } else {
            check_levels::<K>(self.level(), &self.levels)
        }
    }

    /// Panics with a readable message unless [`KTree::check`] passes. Property tests call it after every
    /// operation.
    pub fn assert_well_formed(&self) {
        if let Err(e) = self.check() {
            panic!(
                "malformed KTree<{K}, {}> (level {}): {e}",
                std::any::type_name::<V>(),
                self.level()
            );
        }
    }

    /// Node counts per level, from the root (level 0) down to the deepest stored level (a valued tree's
    /// mixed nodes count as partial: they have children).
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.levels
            .iter()
            .enumerate()
            .map(|(depth, l)| {
                let partial = l.partial_count() as u64;
                let full = l.full_count() as u64;
                LevelCounts {
                    level: depth as u32,
                    full,
                    partial,
                    empty: l.len() as u64 - full - partial,
                }
            })
            .collect()
    }

    /// Total node counts over all levels (`level` holds the universe level).
    pub fn counts(&self) -> LevelCounts {
        LevelCounts::total(self.level(), &self.counts_per_level())
    }

    /// Bytes of memory held by the navigable tree: packed states and rank indexes (about 2.07 bits a node on
    /// large trees), plus the per-level bookkeeping; for a valued tree also the full nodes' rank index and
    /// values.
    pub fn heap_bytes(&self) -> usize {
        self.levels
            .iter()
            .map(PackedStates::heap_bytes)
            .sum::<usize>()
            + self.levels.capacity() * std::mem::size_of::<PackedStates>()
            + self
                .values
                .iter()
                .map(|l| l.rank.heap_bytes() + l.values.capacity() * std::mem::size_of::<V>())
                .sum::<usize>()
            + self.values.capacity() * std::mem::size_of::<LevelValues<V>>()
    }

    /// The number of voxels inside the object, from the full-node counts of each level (no walk: a
    /// pop-count of each level's words).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i < 9).collect::<Vec<_>>()).unwrap();
    /// assert_eq!(tree.voxel_count(), 9);
    /// assert_eq!(KTree::<3>::full(21).unwrap().voxel_count(), 1 << 63);
    /// ```
    pub fn voxel_count(&self) -> u128 {
        let level = self.level();
        self.levels
            .iter()
            .enumerate()
            .map(|(depth, l)| (l.full_count() as u128) << (K * (level as usize - depth)))
            .sum()
    }
}

impl<const K: usize> KTree<K> {
    /// The tree of the empty object (one empty root).
    ///
    /// # Errors
    /// [`SpaceError::LevelTooLarge`] for a level beyond [`crate::max_level`].
    pub fn empty(level: u32) -> Result<Self, SpaceError> {
        Self::uniform(level, NodeState::Empty)
    }

    /// The tree of the whole universe (one full root).
    ///
    /// # Errors
    /// As [`KTree::empty`].
    pub fn full(level: u32) -> Result<Self, SpaceError> {
        Self::uniform(level, NodeState::Full)
    }

    fn uniform(level: u32, state: NodeState) -> Result<Self, SpaceError> {
        let () = DimCheck::<K>::OK;
        let universe = Universe::new(level)?;
        let mut root = PackedStates::with_capacity(1);
        root.push(state);
        root.finish();
        Ok(Self::from_levels(universe, vec![root]))
    }

    /// The tree of the given levels (level 0 holds the root; see [`KTree`] for the layout), checked by
    /// [`KTree::check`].
    ///
    /// ```
    /// use ktree::{tree::PackedStates, KTree, NodeState};
    /// // A bintree of level 1: a partial root over a full and an empty voxel.
    /// let root = PackedStates::from_words(vec![0b10], 1).unwrap();
    /// let voxels = PackedStates::from_words(vec![0b00_01], 2).unwrap();
    /// let tree = KTree::<1>::from_level_states(1, vec![root.clone(), voxels]).unwrap();
    /// assert!(tree.contains([0]) && !tree.contains([1]));
    /// assert!(KTree::<1>::from_level_states(1, vec![root]).is_err()); // the root's children are missing
    /// ```
    ///
    /// # Errors
    /// [`TreeError::Space`] for a level beyond [`crate::max_level`], otherwise the first broken invariant.
    pub fn from_level_states(level: u32, levels: Vec<PackedStates>) -> Result<Self, TreeError> {
        let () = DimCheck::<K>::OK;
        let universe = Universe::new(level)?;
        check_levels::<K>(level, &levels)?;
        Ok(Self::from_levels(universe, levels))
    }

    /// Assembles a tree from its levels. The caller guarantees the structure (see [`KTree::check`]).
    pub(crate) fn from_levels(universe: Universe<K>, levels: Vec<PackedStates>) -> Self {
        Self {
            universe,
            levels,
            values: Vec::new(),
            id: TreeId::fresh(),
        }
    }

    /// The root's state.
    pub fn root_state(&self) -> NodeState {
        self.levels[0].get(0)
    }

    /// The state of node `index` at `depth`.
    ///
    /// # Panics
    /// If the tree has no level `depth` or the level no node `index` ([`KTree::depth_count`],
    /// [`PackedStates::len`]).
    #[track_caller]
    pub fn state(&self, depth: usize, index: usize) -> NodeState {
        self.levels[depth].get(index)
    }

    /// The level-order index of the first child of the partial node `index` at `depth`
    /// (its children are this index and the next `2^K − 1`, at `depth + 1`).
    ///
    /// # Panics
    /// If the node does not exist, as [`KTree::state`]; in debug builds also if it is not partial (a leaf
    /// has no children: the index returned is then that of the next partial node's first child).
    #[inline]
    #[track_caller]
    pub fn first_child(&self, depth: usize, index: usize) -> usize {
        let level = &self.levels[depth];
        debug_assert_eq!(level.get(index), NodeState::Partial);
        if index >= level.len() {
            node_out_of_range(index, level.len());
        }
        level.partial_rank(index) << K
    }

    /// The root node.
    pub fn root(&self) -> NodeRef<K> {
        NodeRef {
            index: 0,
            cell: self.universe.root(),
            state: self.root_state(),
            tree: self.id,
        }
    }

    /// The children of a partial node of this tree, in child-code order (empty for a leaf).
    ///
    /// # Panics
    /// If `node` is a node of another tree (see [`NodeRef`]).
    #[track_caller]
    pub fn children(&self, node: &NodeRef<K>) -> impl Iterator<Item = NodeRef<K>> + '_ {
        node.assert_of(self.id);
        let (first, count) = if node.state == NodeState::Partial {
            (
                self.first_child(node.cell.level as usize, node.index),
                Self::FANOUT,
            )
        } else {
            (0, 0)
        };
        let depth = node.cell.level as usize + 1;
        let cell = node.cell;
        let tree = self.id;
        (0..count).map(move |code| NodeRef {
            index: first + code,
            cell: cell.child(code),
            state: self.levels[depth].get(first + code),
            tree,
        })
    }

    /// Whether the voxel `point` is inside the object (point query, `O(L)`). Points outside the universe are
    /// outside the object.
    pub fn contains(&self, point: [u32; K]) -> bool {
        if self.universe.check_point(point).is_err() {
            return false;
        }
        let state = super::locate::PointCursor::new(self).and_then(|mut c| c.state(point));
        super::storage::infallible(state) == NodeState::Full
    }

    /// Visits every leaf (empty and full) in Morton (depth-first) order: [`KTree::leaves`] as a callback.
    pub fn for_each_leaf(&self, mut visit: impl FnMut(Cell<K>, NodeState)) {
        for (cell, state) in self.leaves() {
            visit(cell, state);
        }
    }

    /// All leaves with their states, in Morton (depth-first) order.
    ///
    /// ```
    /// use ktree::{KTree, NodeState};
    /// let tree = KTree::<1>::from_dense(2, &[true, true, false, true]).unwrap();
    /// let states: Vec<NodeState> = tree.leaves().map(|(_, s)| s).collect();
    /// assert_eq!(states, [NodeState::Full, NodeState::Empty, NodeState::Full]);
    /// ```
    pub fn leaves(&self) -> Leaves<'_, K> {
        Leaves::new(self)
    }

    /// The full leaves in Morton order: the linear tree (Gargantini) of the object.
    pub fn full_cells(&self) -> impl Iterator<Item = Cell<K>> + '_ {
        self.leaves()
            .filter_map(|(cell, state)| (state == NodeState::Full).then_some(cell))
    }
}

/// [`KTree::check`] on raw levels.
fn check_levels<const K: usize>(level: u32, levels: &[PackedStates]) -> Result<(), TreeError> {
    if levels.is_empty() || levels[0].len() != 1 {
        return Err(TreeError::Root {
            nodes: levels.first().map_or(0, PackedStates::len),
        });
    }
    if levels.len() > level as usize + 1 {
        return Err(TreeError::TooDeep {
            levels: levels.len(),
            level,
        });
    }
    for depth in 0..levels.len() {
        let partial = levels[depth].partial_count();
        let next = levels.get(depth + 1).map_or(0, PackedStates::len);
        if partial > 0 && depth == level as usize {
            return Err(TreeError::PartialVoxel { depth });
        }
        if partial.checked_shl(K as u32) != Some(next) || partial > usize::MAX >> K {
            return Err(TreeError::LevelSize {
                depth,
                partial,
                next,
            });
        }
    }
    for (depth, l) in levels.iter().enumerate().skip(1) {
        for block in 0..l.len() >> K {
            let first = l.get(block << K);
            if first != NodeState::Partial
                && (1..1usize << K).all(|c| l.get((block << K) + c) == first)
            {
                return Err(TreeError::NotReduced {
                    depth: depth - 1,
                    index: block,
                    state: first,
                });
            }
        }
    }
    Ok(())
}

/// The number of voxels of a `k`-dimensional object of universe level `level` whose full nodes per level
/// (from the root) are `per_level`: what [`KTree::voxel_count`] gives, for counts read from a file.
///
/// ```
/// use ktree::tree::voxels_of_levels;
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(2, &[true, true, false, true]).unwrap();
/// assert_eq!(voxels_of_levels(1, 2, &tree.counts_per_level()), 3);
/// ```
pub fn voxels_of_levels(k: usize, level: u32, per_level: &[LevelCounts]) -> u128 {
    per_level
        .iter()
        .enumerate()
        .map(|(depth, l)| u128::from(l.full) << (k * (level as usize).saturating_sub(depth)))
        .sum()
}

/// The bytes a navigable tree with these per-level counts holds in memory ([`KTree::heap_bytes`]), without
/// building it — e.g. for a tree read through a memory map.
///
/// ```
/// use ktree::{rays::ball_rays, stacking::paper::stack, tree::heap_bytes_for_levels};
/// let tree = stack(&ball_rays::<3>(6, [64, 64, 64], 50).unwrap());
/// assert_eq!(heap_bytes_for_levels(&tree.counts_per_level()), tree.heap_bytes());
/// ```
pub fn heap_bytes_for_levels(per_level: &[LevelCounts]) -> usize {
    per_level
        .iter()
        .map(|l| PackedStates::heap_bytes_for(l.nodes() as usize))
        .sum::<usize>()
        + per_level.len() * std::mem::size_of::<PackedStates>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tree::cursor::{child, walk_from, Visitor, Walk};
    use crate::tree::locate::{locate, PointCursor};

    /// Two bintrees of level 2 with the same shape at the top (a partial root whose first child is
    /// partial) and other voxels: a node of one is a valid position in the other.
    fn two_trees() -> (KTree<1>, KTree<1>) {
        let a = KTree::<1>::from_dense(2, &[true, false, true, true]).unwrap();
        let b = KTree::<1>::from_dense(2, &[false, true, false, false]).unwrap();
        (a, b)
    }

    fn first_child_of(tree: &KTree<1>) -> NodeRef<1> {
        let node = tree.children(&tree.root()).next().unwrap();
        assert_eq!(node.state(), NodeState::Partial);
        node
    }

    #[test]
    fn nodes_navigate_in_their_tree_and_its_clones() {
        let (a, _) = two_trees();
        let node = first_child_of(&a);
        let kids: Vec<_> = a.children(&node).map(|c| c.state()).collect();
        assert_eq!(kids, [NodeState::Full, NodeState::Empty]);
        let clone = a.clone();
        assert_eq!(clone.children(&node).count(), 2);
        assert_eq!(child(&clone, &node, 0).cell().origin, [0]);
    }

    #[test]
    #[should_panic(expected = "belongs to another tree")]
    fn children_refuse_a_node_of_another_tree() {
        let (a, b) = two_trees();
        let _ = b.children(&first_child_of(&a)).count();
    }

    #[test]
    #[should_panic(expected = "belongs to another tree")]
    fn children_refuse_a_node_past_the_end_of_another_tree() {
        let (a, _) = two_trees();
        let small = KTree::<1>::from_dense(2, &[true, true, false, true]).unwrap();
        let _ = small.children(&first_child_of(&a)).count();
    }

    #[test]
    #[should_panic(expected = "belongs to another tree")]
    fn child_refuses_a_node_of_another_tree() {
        let (a, b) = two_trees();
        let _ = child(&b, &first_child_of(&a), 1);
    }

    #[test]
    #[should_panic(expected = "belongs to another tree")]
    fn walk_from_refuses_a_node_of_another_tree() {
        struct All;
        impl Visitor<1> for All {
            fn visit(&mut self, _: &NodeRef<1>) -> Walk {
                Walk::Descend
            }
        }
        let (a, b) = two_trees();
        walk_from(&b, first_child_of(&a), &mut All);
    }

    #[test]
    #[should_panic(expected = "belongs to another tree")]
    fn locate_refuses_a_start_of_another_tree() {
        let (a, b) = two_trees();
        let voxel = b.universe().cell([1], 2).unwrap();
        let _ = locate(&b, first_child_of(&a), &voxel);
    }

    #[test]
    #[should_panic(expected = "belongs to another tree")]
    fn a_cursor_refuses_a_start_of_another_tree() {
        let (a, b) = two_trees();
        let _ = PointCursor::at(&b, first_child_of(&a));
    }

    #[test]
    #[should_panic(expected = "node 1 of a level of 1 nodes")]
    fn state_past_the_end_of_a_level_panics_rather_than_reading_padding() {
        let (a, _) = two_trees();
        let _ = a.state(0, 1);
    }

    #[test]
    #[should_panic(expected = "node 3 of a level of 2 nodes")]
    fn first_child_past_the_end_of_a_level_panics() {
        let (a, _) = two_trees();
        let _ = a.first_child(1, 3);
    }

    #[test]
    fn equal_objects_are_equal_trees_whatever_their_identity() {
        let (a, _) = two_trees();
        let again = KTree::<1>::from_dense(2, &[true, false, true, true]).unwrap();
        assert_ne!(a.id(), again.id());
        assert_eq!(a, again);
    }
}
