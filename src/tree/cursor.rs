//! One traversal for every query over the compact tree: a depth-first walk of one tree, or of two trees
//! side by side, driven by a [`Visitor`] that answers per node whether to descend, skip the subtree or stop
//! the whole walk, and that chooses which children to visit and in what order (code order, a view order,
//! the one child towards a point).
//!
//! Queries are small visitors, not new descents: point location ([`locate`]) takes the walk's one step
//! ([`child`]) towards a point; the Booleans and interference tests are [`walk_pair`] visitors; display orders are
//! [`ChildOrder::xor`] orders. The nodes under a node are contiguous at every level, so a whole subtree is
//! also a list of index ranges ([`subtree_ranges`]), which the level writer copies in bulk.
//!
//! ```
//! use ktree::tree::cursor::{walk, Visitor, Walk};
//! use ktree::tree::NodeRef;
//! use ktree::{KTree, NodeState};
//! // The side of the first full leaf of side ≥ 2, in Morton order; the walk stops there.
//! struct FirstBig(Option<u64>);
//! impl Visitor<1> for FirstBig {
//!     fn visit(&mut self, node: &NodeRef<1>) -> Walk {
//!         if node.state() == NodeState::Full && node.cell().side() >= 2 {
//!             self.0 = Some(node.cell().side());
//!             return Walk::Stop;
//!         }
//!         Walk::Descend
//!     }
//! }
//! let tree = KTree::<1>::from_dense(3, &[true, false, false, false, true, true, true, true]).unwrap();
//! let mut v = FirstBig(None);
//! assert!(walk(&tree, &mut v)); // stopped early
//! assert_eq!(v.0, Some(4));
//! ```

use smallvec::SmallVec;

use super::ktree::{KTree, NodeRef, TreeId};
use super::states::NodeState;
use super::storage::infallible;
pub use super::storage::{LevelOrder, TreeStorage};
use crate::space::Cell;

/// What a visitor wants after seeing a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Walk {
    /// Visit the node's children (if it has any).
    Descend,
    /// Skip the node's subtree and go on with the next node.
    Skip,
    /// End the whole walk now.
    Stop,
}

/// The children of a node to visit, in order: up to `2^K` child codes.
///
/// ```
/// use ktree::tree::cursor::ChildOrder;
/// let codes = |o: ChildOrder| o.codes().collect::<Vec<_>>();
/// assert_eq!(codes(ChildOrder::xor::<2>(0b10)), [2, 3, 0, 1]);
/// assert_eq!(codes(ChildOrder::lower_half_first::<2>(0)), [0, 2, 1, 3]);
/// assert_eq!(codes(ChildOrder::half::<2>(0, true)), [1, 3]);
/// assert_eq!(codes(ChildOrder::one(5)), [5]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChildOrder {
    /// Bits `4j .. 4j + 4` hold the `j`-th code: read without a branch.
    codes: u64,
    len: u8,
}

/// Code `j` is `j`.
const IDENTITY: u64 = 0xFEDC_BA98_7654_3210;
/// Every code is 1.
const ONES: u64 = 0x1111_1111_1111_1111;

impl ChildOrder {
    /// All children in child-code (Morton) order.
    #[inline]
    pub fn morton<const K: usize>() -> Self {
        Self::xor::<K>(0)
    }

    /// All children, the `j`-th being `mask ^ j`: a view order (front to back with `mask` the near
    /// child, back to front with `mask` the far child).
    #[inline]
    pub fn xor<const K: usize>(mask: usize) -> Self {
        Self {
            codes: IDENTITY ^ ((mask as u64 & 0xF) * ONES),
            len: 1 << K,
        }
    }

    /// Only child `code`.
    #[inline]
    pub fn one(code: usize) -> Self {
        Self {
            codes: code as u64 & 0xF,
            len: 1,
        }
    }

    /// The given child codes, in the order given (at most 16, each below `2^K`).
    pub fn from_codes(list: impl IntoIterator<Item = usize>) -> Self {
        let mut codes = 0u64;
        let mut len = 0u8;
        for c in list.into_iter().take(16) {
            codes |= (c as u64 & 0xF) << (4 * len);
            len += 1;
        }
        Self { codes, len }
    }

    /// All children, those in the lower half on `axis` first, each half in code order.
    pub fn lower_half_first<const K: usize>(axis: usize) -> Self {
        let lower = (0..1usize << K).filter(|c| c >> axis & 1 == 0);
        let upper = (0..1usize << K).filter(|c| c >> axis & 1 == 1);
        Self::from_codes(lower.chain(upper))
    }

    /// The children in the lower (`upper == false`) or upper half on `axis`, in code order.
    pub fn half<const K: usize>(axis: usize, upper: bool) -> Self {
        Self::from_codes((0..1usize << K).filter(|c| (c >> axis & 1 == 1) == upper))
    }

    /// The number of children visited.
    #[inline]
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// Whether no child is visited.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `j`-th child code to visit (`j < len`).
    #[inline]
    pub fn code(&self, j: usize) -> usize {
        (self.codes >> (4 * j) & 0xF) as usize
    }

    /// The child codes, in visiting order.
    pub fn codes(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.len()).map(|j| self.code(j))
    }
}

/// A query over one tree: sees each node before its children.
pub trait Visitor<const K: usize> {
    /// Whether the walk tracks cell origins. A visitor that never reads `cell.origin` sets this to
    /// `false`; its nodes then carry the right level and size but their parent's origin.
    const ORIGINS: bool = true;

    /// Whether the walk calls [`Visitor::leave`]. A visitor that does not override it may set this to
    /// `false` and save the walk the bookkeeping.
    const LEAVES: bool = true;

    /// Sees a node; says whether to visit its children, skip them, or stop.
    fn visit(&mut self, node: &NodeRef<K>) -> Walk;

    /// Called after the children of a partial node have all been visited (not when they were skipped,
    /// nor after a stop).
    #[inline]
    fn leave(&mut self, _node: &NodeRef<K>) {}

    /// Which children of a partial node to visit, in order (all, in code order, unless overridden).
    #[inline]
    fn child_order(&self, _node: &NodeRef<K>) -> ChildOrder {
        ChildOrder::morton::<K>()
    }
}

/// The cell of child `code`, with or without its origin (see [`Visitor::ORIGINS`]).
#[inline(always)]
fn step<const K: usize>(cell: &Cell<K>, code: usize, origins: bool) -> Cell<K> {
    if origins {
        cell.child(code)
    } else {
        Cell {
            origin: cell.origin,
            level: cell.level + 1,
            log_side: cell.log_side - 1,
        }
    }
}

/// The child `code` of the partial node `node` whose first child is `first`.
#[inline(always)]
fn child_ref<const K: usize>(
    tree: &KTree<K>,
    node: &NodeRef<K>,
    first: usize,
    code: usize,
    origins: bool,
) -> NodeRef<K> {
    NodeRef {
        index: first + code,
        cell: step(&node.cell, code, origins),
        state: tree.state(node.cell.level as usize + 1, first + code),
        tree: node.tree,
    }
}

/// Walks `tree` depth first from the root with `visitor`. Returns `true` if the visitor stopped the walk.
/// For a storage whose reads can fail, [`try_walk`].
pub fn walk<const K: usize, T: LevelOrder<K>, V: Visitor<K>>(tree: &T, visitor: &mut V) -> bool {
    infallible(try_walk(tree, visitor))
}

/// Walks the subtree of `node` (a node of `tree`) depth first with `visitor`. Returns `true` if the
/// visitor stopped the walk. For a storage whose reads can fail, [`try_walk_from`].
///
/// # Panics
/// If `node` is a node of another tree (see [`NodeRef`]).
#[track_caller]
pub fn walk_from<const K: usize, T: LevelOrder<K>, V: Visitor<K>>(
    tree: &T,
    node: NodeRef<K>,
    v: &mut V,
) -> bool {
    infallible(try_walk_from(tree, node, v))
}

/// [`walk`] over any storage: `Ok(true)` if the visitor stopped the walk, the storage's error if a read
/// failed (the walk then ends).
///
/// # Errors
/// The storage's read error.
pub fn try_walk<const K: usize, T: TreeStorage<K>, V: Visitor<K>>(
    tree: &T,
    visitor: &mut V,
) -> Result<bool, T::Error> {
    try_walk_from(tree, tree.root()?, visitor)
}

/// [`walk_from`] over any storage.
///
/// # Errors
/// The storage's read error.
pub fn try_walk_from<const K: usize, T: TreeStorage<K>, V: Visitor<K>>(
    tree: &T,
    node: NodeRef<K>,
    v: &mut V,
) -> Result<bool, T::Error> {
    node.assert_of(tree.root()?.tree);
    // Depth first with an explicit stack: a node to visit, or a partial node to leave once the entries
    // above it (its children's) are done.
    // Inline up to 64 entries: the narrow walks (a face, an edge, a point) run without allocating.
    let mut stack: SmallVec<[(NodeRef<K>, bool); 64]> = SmallVec::new();
    stack.push((node, false));
    while let Some((node, leaving)) = stack.pop() {
        if leaving {
            v.leave(&node);
            continue;
        }
        match v.visit(&node) {
            Walk::Stop => return Ok(true),
            Walk::Skip => continue,
            Walk::Descend if node.state != NodeState::Partial => continue,
            Walk::Descend => {}
        }
        let depth = node.cell.level as usize;
        let first = tree.first_child(depth, node.index)?;
        let codes = tree.block_codes(depth + 1, first)?;
        let order = v.child_order(&node);
        if V::LEAVES {
            stack.push((node, true));
        }
        // Pushed last to first: the first child in order is on top.
        for j in (0..order.len()).rev() {
            let code = order.code(j);
            stack.push((
                NodeRef {
                    index: first + code,
                    cell: step(&node.cell, code, V::ORIGINS),
                    state: NodeState::from_bits(codes >> (2 * code)),
                    tree: node.tree,
                },
                false,
            ));
        }
    }
    Ok(false)
}

/// The leaves of a tree (empty and full) with their cells, in Morton (depth-first) order, read from any
/// storage: each item is a leaf or the storage's read error (after which the iterator ends). For a tree
/// in memory, [`Leaves`] gives the leaves themselves.
///
/// Needs no rank lookup: a depth-first walk meets the partial nodes of each depth in index order, so
/// their children blocks follow one another.
#[derive(Debug, Clone)]
pub struct TryLeaves<'a, const K: usize, T> {
    tree: &'a T,
    /// Nodes still to visit (cell, index in its level, state), the next on top.
    stack: Vec<(Cell<K>, usize, NodeState)>,
    /// Per depth, the first child of the next partial node met at the depth above.
    next_first: Vec<usize>,
    /// The root still to read (nothing is read before the first `next`).
    fresh: bool,
}

impl<'a, const K: usize, T: TreeStorage<K>> TryLeaves<'a, K, T> {
    /// The leaves of `tree`.
    pub fn new(tree: &'a T) -> Self {
        Self {
            tree,
            stack: Vec::new(),
            next_first: vec![0; tree.depth_count() + 1],
            fresh: true,
        }
    }
}

impl<const K: usize, T: TreeStorage<K>> Iterator for TryLeaves<'_, K, T> {
    type Item = Result<(Cell<K>, NodeState), T::Error>;

    fn next(&mut self) -> Option<Self::Item> {
        if std::mem::take(&mut self.fresh) {
            match self.tree.root_state() {
                Ok(state) => self.stack.push((self.tree.universe().root(), 0, state)),
                Err(e) => return Some(Err(e)),
            }
        }
        while let Some((cell, _, state)) = self.stack.pop() {
            if state != NodeState::Partial {
                return Some(Ok((cell, state)));
            }
            let below = cell.level as usize + 1;
            let first = self.next_first[below];
            self.next_first[below] += 1 << K;
            let codes = match self.tree.block_codes(below, first) {
                Ok(codes) => codes,
                Err(e) => {
                    self.stack.clear();
                    return Some(Err(e));
                }
            };
            for code in (0..1usize << K).rev() {
                let child = NodeState::from_bits(codes >> (2 * code));
                self.stack.push((cell.child(code), first + code, child));
            }
        }
        None
    }
}

/// The leaves of a tree whose reads cannot fail, in Morton order: [`TryLeaves`] without the `Result`.
///
/// ```
/// use ktree::tree::cursor::Leaves;
/// use ktree::{KTree, NodeState};
/// let tree = KTree::<1>::from_dense(2, &[true, true, false, true]).unwrap();
/// let states: Vec<NodeState> = Leaves::new(&tree).map(|(_, s)| s).collect();
/// assert_eq!(states, [NodeState::Full, NodeState::Empty, NodeState::Full]);
/// ```
#[derive(Debug, Clone)]
pub struct Leaves<'a, const K: usize, T = KTree<K>>(TryLeaves<'a, K, T>);

impl<'a, const K: usize, T: LevelOrder<K>> Leaves<'a, K, T> {
    /// The leaves of `tree`.
    pub fn new(tree: &'a T) -> Self {
        Self(TryLeaves::new(tree))
    }
}

impl<const K: usize, T: LevelOrder<K>> Iterator for Leaves<'_, K, T> {
    type Item = (Cell<K>, NodeState);

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        self.0.next().map(infallible)
    }
}

/// Where one tree stands in a two-tree walk: its node at the walk's cell, or the leaf above the cell that
/// stands for every cell below it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Side {
    /// The node's index within its level (for a leaf above the cell, within the leaf's level).
    pub index: usize,
    /// The node's state.
    pub state: NodeState,
}

/// A cell of a simultaneous walk of two trees, with the node of each tree that covers it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PairNode<const K: usize> {
    /// The cell (see [`PairVisitor::ORIGINS`] for its origin); its level is the depth of the nodes that
    /// are at the cell.
    pub cell: Cell<K>,
    /// The cell's child code within its parent (0 for the root).
    pub code: usize,
    /// The first tree's node.
    pub a: Side,
    /// The second tree's node.
    pub b: Side,
}

/// A query over two trees of the same universe, walked side by side: sees each cell where at least one
/// tree is partial before its children. Where one tree is a leaf and the other partial, the walk goes on
/// with the leaf standing for every cell below it.
pub trait PairVisitor<const K: usize> {
    /// As [`Visitor::ORIGINS`].
    const ORIGINS: bool = true;

    /// Sees a pair of nodes; says whether to visit the children, skip them, or stop.
    fn visit(&mut self, pair: &PairNode<K>) -> Walk;

    /// Called after the children of a pair have all been visited.
    #[inline]
    fn leave(&mut self, _pair: &PairNode<K>) {}

    /// Which children to visit, in order.
    #[inline]
    fn child_order(&self, _pair: &PairNode<K>) -> ChildOrder {
        ChildOrder::morton::<K>()
    }
}

/// Walks two trees (of the same universe level) side by side from their roots. Returns `true` if the
/// visitor stopped the walk.
///
/// ```
/// use ktree::tree::cursor::{walk_pair, PairNode, PairVisitor, Walk};
/// use ktree::{KTree, NodeState};
/// // Do two objects share a voxel?
/// struct Meet(bool);
/// impl PairVisitor<1> for Meet {
///     fn visit(&mut self, p: &PairNode<1>) -> Walk {
///         match (p.a.state, p.b.state) {
///             (NodeState::Empty, _) | (_, NodeState::Empty) => Walk::Skip,
///             (NodeState::Partial, NodeState::Partial) => Walk::Descend,
///             _ => { self.0 = true; Walk::Stop }
///         }
///     }
/// }
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
/// let mut m = Meet(false);
/// walk_pair(&a, &b, &mut m);
/// assert!(m.0);
/// ```
pub fn walk_pair<const K: usize, A: LevelOrder<K>, B: LevelOrder<K>, V: PairVisitor<K>>(
    a: &A,
    b: &B,
    visitor: &mut V,
) -> bool {
    infallible(try_walk_pair(a, b, visitor))
}

/// [`walk_pair`] over any two storages with the same read error: `Ok(true)` if the visitor stopped the
/// walk.
///
/// # Errors
/// The first read error of either storage (the walk then ends).
pub fn try_walk_pair<const K: usize, A, B, V>(
    a: &A,
    b: &B,
    visitor: &mut V,
) -> Result<bool, A::Error>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
    V: PairVisitor<K>,
{
    debug_assert_eq!(a.level(), b.level());
    let root = PairNode {
        cell: a.universe().root(),
        code: 0,
        a: Side {
            index: 0,
            state: a.root_state()?,
        },
        b: Side {
            index: 0,
            state: b.root_state()?,
        },
    };
    visit_pair(a, b, &root, visitor)
}

/// The side of child `code`: the real child of a partial node (whose children's codes are `codes`, the
/// first at index `first`), or the same leaf standing in.
#[inline(always)]
fn child_side(side: &Side, first: usize, codes: u32, code: usize) -> Side {
    if side.state == NodeState::Partial {
        Side {
            index: first + code,
            state: NodeState::from_bits(codes >> (2 * code)),
        }
    } else {
        *side
    }
}

/// The first child of `side` and its children's codes (zeros for a leaf).
#[inline(always)]
fn children_of<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    side: &Side,
    depth: usize,
) -> Result<(usize, u32), T::Error> {
    if side.state == NodeState::Partial {
        let first = tree.first_child(depth, side.index)?;
        Ok((first, tree.block_codes(depth + 1, first)?))
    } else {
        Ok((0, 0))
    }
}

/// Visits `pair`; descends into its children if asked to and either side is partial. `true` when stopped.
#[inline(always)]
fn visit_pair<const K: usize, A, B, V>(
    a: &A,
    b: &B,
    pair: &PairNode<K>,
    v: &mut V,
) -> Result<bool, A::Error>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
    V: PairVisitor<K>,
{
    match v.visit(pair) {
        Walk::Stop => Ok(true),
        Walk::Skip => Ok(false),
        Walk::Descend
            if pair.a.state == NodeState::Partial || pair.b.state == NodeState::Partial =>
        {
            descend_pair(a, b, pair, v)
        }
        Walk::Descend => Ok(false),
    }
}

/// Visits the children of `pair` (already visited; at least one side partial), then leaves it. `true`
/// when stopped.
fn descend_pair<const K: usize, A, B, V>(
    a: &A,
    b: &B,
    pair: &PairNode<K>,
    v: &mut V,
) -> Result<bool, A::Error>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
    V: PairVisitor<K>,
{
    let depth = pair.cell.level as usize;
    let (fa, codes_a) = children_of(a, &pair.a, depth)?;
    let (fb, codes_b) = children_of(b, &pair.b, depth)?;
    let order = v.child_order(pair);
    for j in 0..order.len() {
        let code = order.code(j);
        let child = PairNode {
            cell: step(&pair.cell, code, V::ORIGINS),
            code,
            a: child_side(&pair.a, fa, codes_a, code),
            b: child_side(&pair.b, fb, codes_b, code),
        };
        if visit_pair(a, b, &child, v)? {
            return Ok(true);
        }
    }
    v.leave(pair);
    Ok(false)
}

/// The child `code` of the partial node `node` of `tree`: one step of navigation, the one every walk
/// takes.
///
/// ```
/// use ktree::tree::cursor::child;
/// use ktree::{KTree, NodeState};
/// let tree = KTree::<1>::from_dense(1, &[false, true]).unwrap();
/// assert_eq!(child(&tree, &tree.root(), 1).state(), NodeState::Full);
/// ```
///
/// # Panics
/// If `node` is a node of another tree (see [`NodeRef`]), is not partial, or `code ≥ 2^K`.
#[inline]
#[track_caller]
pub fn child<const K: usize>(tree: &KTree<K>, node: &NodeRef<K>, code: usize) -> NodeRef<K> {
    node.assert_of(tree.id());
    assert!(
        node.state == NodeState::Partial && code < KTree::<K>::FANOUT,
        "child {code} of a {:?} node of a K = {K} tree",
        node.state
    );
    let first = tree.first_child(node.cell.level as usize, node.index);
    child_ref(tree, node, first, code, true)
}

/// The node of `tree` whose cell contains the aligned cell `target` and is either a leaf or `target`
/// itself, found by descending from `start` (a node whose cell contains `target`; usually
/// [`KTree::root`]) one child at a time, towards `target`. `O(levels descended)` rank lookups.
///
/// ```
/// use ktree::tree::cursor::locate;
/// use ktree::{KTree, NodeState};
/// let tree = KTree::<1>::from_dense(2, &[false, true, true, true]).unwrap();
/// let voxel = tree.universe().cell([3], 2).unwrap();
/// let node = locate(&tree, tree.root(), &voxel);
/// assert_eq!((node.state(), node.cell().side()), (NodeState::Full, 2));
/// ```
///
/// # Panics
/// If `start` is a node of another tree (see [`NodeRef`]).
#[inline]
#[track_caller]
pub fn locate<const K: usize>(tree: &KTree<K>, start: NodeRef<K>, target: &Cell<K>) -> NodeRef<K> {
    start.assert_of(tree.id());
    descend(tree, start, target, |_| {})
}

/// [`locate`], calling `on_step` with each node stepped to.
#[inline(always)]
fn descend<const K: usize>(
    tree: &KTree<K>,
    start: NodeRef<K>,
    target: &Cell<K>,
    mut on_step: impl FnMut(&NodeRef<K>),
) -> NodeRef<K> {
    debug_assert!(start.cell.level <= target.level);
    let bit_top = tree.level().saturating_sub(1);
    let mut node = start;
    while node.state == NodeState::Partial && node.cell.level < target.level {
        let bit = bit_top - node.cell.level;
        let mut code = 0usize;
        for (axis, &c) in target.origin.iter().enumerate() {
            code |= ((c >> bit & 1) as usize) << axis;
        }
        let first = tree.first_child(node.cell.level as usize, node.index);
        node = child_ref(tree, &node, first, code, false);
        on_step(&node);
    }
    // The steps did not track origins: the node's cell is the target's ancestor at its level.
    let low = ((1u64 << node.cell.log_side) - 1) as u32;
    node.cell.origin = target.origin.map(|o| o & !low);
    node
}

/// Point location that remembers its last path from the root: a target near the previous one (a
/// neighbour of the same leaf, the next leaf in Morton order) is found from their deepest common ancestor
/// instead of from the root. Gives what [`locate`] from the root gives.
///
/// ```
/// use ktree::tree::cursor::{locate, Locator};
/// use ktree::KTree;
/// let tree = KTree::<2>::from_dense(3, &(0..64).map(|i| i % 5 == 0).collect::<Vec<_>>()).unwrap();
/// let mut locator = Locator::new(&tree);
/// for (x, y) in [(3, 4), (3, 5), (7, 0), (0, 0)] {
///     let voxel = tree.universe().cell([x, y], 3).unwrap();
///     assert_eq!(locator.locate(&tree, &voxel), locate(&tree, tree.root(), &voxel));
/// }
/// ```
#[derive(Debug, Clone)]
pub struct Locator<const K: usize> {
    /// `(index, state)` of the node at each depth of the last path.
    path: [(usize, NodeState); 33],
    /// Nodes on the last path.
    len: usize,
    /// The origin of the last target.
    last: [u32; K],
    /// The tree the path is in.
    tree: TreeId,
}

impl<const K: usize> Locator<K> {
    /// A locator for `tree`, its path at the root.
    pub fn new(tree: &KTree<K>) -> Self {
        let mut path = [(0, NodeState::Empty); 33];
        path[0] = (0, tree.root_state());
        Self {
            path,
            len: 1,
            last: [0; K],
            tree: tree.id(),
        }
    }

    /// As [`locate`] from the root of `tree` (the tree the locator was made for).
    ///
    /// # Panics
    /// If `tree` is not the tree (or a clone of the tree) the locator was made for.
    #[track_caller]
    pub fn locate(&mut self, tree: &KTree<K>, target: &Cell<K>) -> NodeRef<K> {
        assert!(
            self.tree == tree.id(),
            "a Locator is used only with the tree (or a clone of the tree) it was made for"
        );
        let top = tree.level();
        // The depth down to which the last target's ancestors are the target's.
        let differ = (0..K)
            .map(|a| 32 - (self.last[a] ^ target.origin[a]).leading_zeros())
            .max()
            .unwrap_or(0);
        let common = top.saturating_sub(differ) as usize;
        let depth = common.min(self.len - 1).min(target.level as usize);
        let (index, state) = self.path[depth];
        let start = NodeRef {
            index,
            cell: Cell {
                origin: target.origin,
                level: depth as u32,
                log_side: top - depth as u32,
            },
            state,
            tree: self.tree,
        };
        let path = &mut self.path;
        let node = descend(tree, start, target, |n| {
            path[n.cell.level as usize] = (n.index, n.state)
        });
        self.len = node.cell.level as usize + 1;
        self.last = target.origin;
        node
    }
}

/// The state of the voxel `point` (inside `start`'s cell): [`locate`] for one voxel when only its state is
/// wanted, descending from `start` without tracking cells.
///
/// ```
/// use ktree::tree::cursor::voxel_state;
/// use ktree::{KTree, NodeState};
/// let tree = KTree::<1>::from_dense(2, &[false, true, true, true]).unwrap();
/// assert_eq!(voxel_state(&tree, &tree.root(), [0]), NodeState::Empty);
/// assert_eq!(voxel_state(&tree, &tree.root(), [3]), NodeState::Full);
/// ```
///
/// # Panics
/// If `start` is a node of another tree (see [`NodeRef`]).
#[inline(always)]
#[track_caller]
pub fn voxel_state<const K: usize>(
    tree: &KTree<K>,
    start: &NodeRef<K>,
    point: [u32; K],
) -> NodeState {
    start.assert_of(tree.id());
    let (mut depth, mut index) = (start.cell.level as usize, start.index);
    let (mut state, mut log_side) = (start.state, start.cell.log_side);
    while state == NodeState::Partial {
        log_side -= 1;
        let code = (0..K).fold(0, |code, a| {
            code | ((point[a] >> log_side & 1) as usize) << a
        });
        index = tree.first_child(depth, index) + code;
        depth += 1;
        state = tree.state(depth, index);
    }
    state
}

/// The ranges of node indices, level by level from `depth + 1` down, that hold the descendants of the
/// node `index` at `depth`: `(depth, start..end)` pairs, contiguous because children blocks follow the
/// order of their parents. Empty for a leaf.
///
/// ```
/// use ktree::tree::cursor::subtree_ranges;
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(2, &[true, false, true, true]).unwrap();
/// assert_eq!(subtree_ranges(&tree, 0, 0).collect::<Vec<_>>(), [(1, 0..2), (2, 0..2)]);
/// assert_eq!(subtree_ranges(&tree, 1, 1).count(), 0); // a full leaf
/// ```
pub fn subtree_ranges<const K: usize>(
    tree: &KTree<K>,
    depth: usize,
    index: usize,
) -> impl Iterator<Item = (usize, std::ops::Range<usize>)> + '_ {
    let mut range = index..index + 1;
    let mut d = depth;
    std::iter::from_fn(move || {
        if d + 1 >= tree.depth_count() || range.is_empty() {
            return None;
        }
        let states = tree.level_states(d);
        let next = (states.partial_rank(range.start) << K)..(states.partial_rank(range.end) << K);
        d += 1;
        range = next.clone();
        (!next.is_empty()).then_some((d, next))
    })
}
