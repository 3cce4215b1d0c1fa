//! One traversal for every query over the compact tree: a depth-first walk of one tree, or of two trees
//! side by side, driven by a [`Visitor`] that answers per node whether to descend, skip the subtree or stop
//! the whole walk, and that chooses which children to visit and in what order (code order, a view order,
//! the one child towards a point).
//!
//! Queries are small visitors, not new descents: the Booleans and interference tests are [`walk_pair`]
//! visitors; display orders are [`ChildOrder::xor`] orders; point location is the one descent of
//! [`locate`](super::locate). The nodes under a node are contiguous at every level, so a whole subtree is
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

use super::ktree::{KTree, NodeRef};
use super::states::NodeState;
use std::convert::Infallible;

use super::storage::infallible;
pub use super::storage::TreeStorage;
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
pub fn walk<const K: usize, T: TreeStorage<K, Error = Infallible>, V: Visitor<K>>(
    tree: &T,
    visitor: &mut V,
) -> bool {
    infallible(try_walk(tree, visitor))
}

/// Walks the subtree of `node` (a node of `tree`) depth first with `visitor`. Returns `true` if the
/// visitor stopped the walk. For a storage whose reads can fail, [`try_walk_from`].
///
/// # Panics
/// If `node` is a node of another tree (see [`NodeRef`]).
#[track_caller]
pub fn walk_from<const K: usize, T: TreeStorage<K, Error = Infallible>, V: Visitor<K>>(
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

impl<'a, const K: usize, T: TreeStorage<K, Error = Infallible>> Leaves<'a, K, T> {
    /// The leaves of `tree`.
    pub fn new(tree: &'a T) -> Self {
        Self(TryLeaves::new(tree))
    }
}

impl<const K: usize, T: TreeStorage<K, Error = Infallible>> Iterator for Leaves<'_, K, T> {
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
pub fn walk_pair<
    const K: usize,
    A: TreeStorage<K, Error = Infallible>,
    B: TreeStorage<K, Error = Infallible>,
    V: PairVisitor<K>,
>(
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
