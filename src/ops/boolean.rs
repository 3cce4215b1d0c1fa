//! Boolean operations — union, intersection, difference, symmetric difference and complement — by one
//! simultaneous depth-first traversal of the two input trees (Meagher §6, claim M2).
//!
//! Where both inputs are partial the traversal descends; where one is a leaf the result is that leaf, a copy
//! of the other subtree, or its complement, decided by the operation's truth table, so the cost is linear in
//! the input nodes actually reached (never in voxels). Children are computed before they are pushed, so a
//! node whose children come out all full or all empty collapses on the spot: the output is reduced.
//!
//! The operations are *regularized* in Meagher's sense without extra work: objects are sets of voxels, so
//! two objects touching along a face share no voxel and their intersection is empty.
//!
//! Two trees of different universe levels are an error ([`OpsError::LevelMismatch`]); trees of different
//! dimension `K` cannot be combined at all — `KTree<2>` and `KTree<3>` are different types.

use super::output::{collapse, leaf, Memory};
use super::OpsError;
use crate::tree::cursor::{try_walk_pair, PairNode, PairVisitor, Walk};
use crate::tree::sink::{copy_subtree, LevelSink};
use crate::tree::storage::TreeStorage;
use crate::tree::words::{self, NODES_PER_WORD};
use crate::tree::{KTree, NodeState};

/// A binary Boolean operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BoolOp {
    /// `A ∪ B`.
    Union,
    /// `A ∩ B`.
    Intersection,
    /// `A ∖ B`.
    Difference,
    /// `A △ B` (exclusive or).
    SymmetricDifference,
}

impl BoolOp {
    /// All four operations.
    pub const ALL: [BoolOp; 4] = [
        BoolOp::Union,
        BoolOp::Intersection,
        BoolOp::Difference,
        BoolOp::SymmetricDifference,
    ];

    /// The operation on one voxel: whether it is in the result given whether it is in `a` and in `b`.
    pub fn apply(self, a: bool, b: bool) -> bool {
        match self {
            BoolOp::Union => a || b,
            BoolOp::Intersection => a && b,
            BoolOp::Difference => a && !b,
            BoolOp::SymmetricDifference => a != b,
        }
    }

    /// The command-line name: `union`, `intersect`, `diff`, `xor`.
    pub fn name(self) -> &'static str {
        match self {
            BoolOp::Union => "union",
            BoolOp::Intersection => "intersect",
            BoolOp::Difference => "diff",
            BoolOp::SymmetricDifference => "xor",
        }
    }
}

/// What the result is over a region where one input is a leaf and the other is not: the operation's truth
/// table with one side fixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Outcome {
    /// The result is this leaf, whatever the other side holds.
    Leaf(NodeState),
    /// The result is the other side's subtree.
    Copy,
    /// The result is the complement of the other side's subtree.
    Invert,
}

impl Outcome {
    /// The result of `op` where one side is the leaf `fixed_full` (full or empty): `a`'s if `a_fixed`,
    /// else `b`'s.
    pub(crate) fn of(op: BoolOp, fixed_full: bool, a_fixed: bool) -> Self {
        let apply = |x: bool| {
            if a_fixed {
                op.apply(fixed_full, x)
            } else {
                op.apply(x, fixed_full)
            }
        };
        match (apply(false), apply(true)) {
            (r, s) if r == s => Outcome::Leaf(leaf(r)),
            (false, true) => Outcome::Copy,
            _ => Outcome::Invert,
        }
    }
}

/// The Boolean as a two-tree walk over any two storages, writing to any level sink: a pair is decided on
/// the spot where a leaf decides it (a leaf, a copy of the other subtree or its complement), else its
/// children are visited and the pair is decided when it is left, from its children's states. The first
/// error (a read of a subtree being copied, or a write) stops the walk and is kept.
struct Merge<'a, const K: usize, A, B, S, E> {
    a: &'a A,
    b: &'a B,
    op: BoolOp,
    out: S,
    /// `kids[d]`: the states decided so far for the children (at depth `d`) of the open pair above.
    kids: Vec<[NodeState; 16]>,
    error: Option<E>,
}

impl<const K: usize, A, B, S, E> Merge<'_, K, A, B, S, E>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
    S: LevelSink,
    E: From<A::Error> + From<S::Error>,
{
    /// Records the result `state` of the pair at `depth` with child code `code`.
    #[inline]
    fn decide(&mut self, depth: usize, code: usize, state: NodeState) {
        self.kids[depth][code] = state;
    }

    /// The result over a partial node of one side (`a`'s if `of_a`) where the other is the leaf
    /// `other_full`: a leaf, or the node's subtree copied (complemented if the table says so).
    #[inline]
    fn one_side(&mut self, of_a: bool, depth: usize, index: usize, other_full: bool) -> NodeState {
        let invert = match Outcome::of(self.op, other_full, !of_a) {
            Outcome::Leaf(s) => return s,
            Outcome::Copy => false,
            Outcome::Invert => true,
        };
        let copied = if of_a {
            copy_subtree::<K, _, _, E>(&mut self.out, self.a, depth, index, invert)
        } else {
            copy_subtree::<K, _, _, E>(&mut self.out, self.b, depth, index, invert)
        };
        if let Err(e) = copied {
            self.error.get_or_insert(e);
        }
        NodeState::Partial
    }
}

impl<const K: usize, A, B, S, E> PairVisitor<K> for Merge<'_, K, A, B, S, E>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
    S: LevelSink,
    E: From<A::Error> + From<S::Error>,
{
    const ORIGINS: bool = false;

    #[inline]
    fn visit(&mut self, pair: &PairNode<K>) -> Walk {
        if self.error.is_some() {
            return Walk::Stop;
        }
        let (depth, code) = (pair.cell.level as usize, pair.code);
        let state = match (pair.a.state, pair.b.state) {
            (NodeState::Partial, NodeState::Partial) => return Walk::Descend,
            (NodeState::Partial, lb) => {
                self.one_side(true, depth, pair.a.index, lb == NodeState::Full)
            }
            (la, NodeState::Partial) => {
                self.one_side(false, depth, pair.b.index, la == NodeState::Full)
            }
            (la, lb) => leaf(self.op.apply(la == NodeState::Full, lb == NodeState::Full)),
        };
        self.decide(depth, code, state);
        if self.error.is_some() {
            Walk::Stop
        } else {
            Walk::Skip
        }
    }

    #[inline]
    fn leave(&mut self, pair: &PairNode<K>) {
        let depth = pair.cell.level as usize;
        let kids = self.kids[depth + 1];
        let kids = &kids[..1 << K];
        let state = match collapse(kids) {
            Some(s) => s,
            None => {
                if let Err(e) = self.out.push_block(depth + 1, kids) {
                    self.error.get_or_insert(e.into());
                }
                NodeState::Partial
            }
        };
        self.decide(depth, pair.code, state);
    }
}

/// `a op b` written to `sink`, for trees of the same universe in any storages: the one Boolean behind
/// [`boolean`] (in memory) and `io::boolean_files` (mapped files, levels spilled to files). The output is
/// reduced. The levels are not compared: see [`boolean`].
///
/// ```
/// use ktree::{KTree, ops::{boolean, boolean_into, BoolOp}};
/// use ktree::tree::sink::MemorySink;
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
/// let sink = MemorySink::new(a.universe());
/// let x: KTree<1> = boolean_into::<1, _, _, _, std::convert::Infallible>(&a, &b, BoolOp::Difference, sink).unwrap();
/// assert_eq!(x, boolean(&a, &b, BoolOp::Difference).unwrap());
/// ```
///
/// # Errors
/// The first read error of `a` or `b`, or write error of `sink`.
pub fn boolean_into<const K: usize, A, B, S, E>(
    a: &A,
    b: &B,
    op: BoolOp,
    sink: S,
) -> Result<S::Output, E>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
    S: LevelSink,
    E: From<A::Error> + From<S::Error>,
{
    let depths = a.depth_count().max(b.depth_count());
    let mut m = Merge {
        a,
        b,
        op,
        out: sink,
        kids: vec![[NodeState::Empty; 16]; depths + 1],
        error: None,
    };
    let walked = try_walk_pair(a, b, &mut m);
    if let Some(e) = m.error {
        return Err(e);
    }
    walked?;
    let root = m.kids[0][0];
    Ok(m.out.finish(root)?)
}

/// The complement of `a` written to `sink`, from any storage: the root's subtree copied with full and
/// empty swapped. For a tree in memory, [`complement`] flips the words in place of a copy.
///
/// # Errors
/// The first read error of `a` or write error of `sink`.
pub fn complement_into<const K: usize, A, S, E>(a: &A, mut sink: S) -> Result<S::Output, E>
where
    A: TreeStorage<K>,
    S: LevelSink,
    E: From<A::Error> + From<S::Error>,
{
    let root = match a.root_state()? {
        NodeState::Partial => {
            copy_subtree::<K, _, _, E>(&mut sink, a, 0, 0, true)?;
            NodeState::Partial
        }
        NodeState::Full => NodeState::Empty,
        NodeState::Empty => NodeState::Full,
    };
    Ok(sink.finish(root)?)
}

/// Checks that two trees share a universe level.
pub(crate) fn same_level<const K: usize, A: TreeStorage<K>, B: TreeStorage<K>>(
    a: &A,
    b: &B,
) -> Result<(), OpsError> {
    if a.level() != b.level() {
        return Err(OpsError::LevelMismatch {
            left: a.level(),
            right: b.level(),
        });
    }
    Ok(())
}

/// Applies a binary Boolean operation to two trees of any storages (with one read error type: two trees
/// in memory, two mapped files, …). The output is reduced; the cost is linear in the input nodes.
///
/// ```
/// use ktree::{KTree, ops::{boolean, BoolOp}};
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
/// let u = boolean(&a, &b, BoolOp::Union).unwrap();
/// assert_eq!(u.to_dense().unwrap(), [true, true, true, false]);
/// let x = boolean(&a, &b, BoolOp::SymmetricDifference).unwrap();
/// assert_eq!(x.to_dense().unwrap(), [true, false, true, false]);
/// ```
///
/// # Errors
/// [`OpsError::LevelMismatch`] when the trees' levels differ; [`OpsError::Storage`] if a read fails.
pub fn boolean<const K: usize, A, B>(a: &A, b: &B, op: BoolOp) -> Result<KTree<K>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    same_level(a, b)?;
    boolean_into::<K, _, _, _, A::Error>(a, b, op, Memory::new(a.universe()))
        .map_err(OpsError::storage)
}

/// `A ∪ B`. See [`boolean`].
///
/// # Errors
/// As [`boolean`].
pub fn union<const K: usize, A, B>(a: &A, b: &B) -> Result<KTree<K>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    boolean(a, b, BoolOp::Union)
}

/// `A ∩ B`. See [`boolean`].
///
/// # Errors
/// As [`boolean`].
pub fn intersection<const K: usize, A, B>(a: &A, b: &B) -> Result<KTree<K>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    boolean(a, b, BoolOp::Intersection)
}

/// `A ∖ B`. See [`boolean`].
///
/// # Errors
/// As [`boolean`].
pub fn difference<const K: usize, A, B>(a: &A, b: &B) -> Result<KTree<K>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    boolean(a, b, BoolOp::Difference)
}

/// `A △ B`. See [`boolean`].
///
/// # Errors
/// As [`boolean`].
pub fn symmetric_difference<const K: usize, A, B>(a: &A, b: &B) -> Result<KTree<K>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    boolean(a, b, BoolOp::SymmetricDifference)
}

/// The complement `¬A` within the universe: full and empty leaves swap, the structure is unchanged (so the
/// result is reduced). Works on the packed words directly: 32 nodes per machine operation.
///
/// ```
/// use ktree::{KTree, ops::complement};
/// let a = KTree::<1>::from_dense(2, &[true, false, false, false]).unwrap();
/// assert_eq!(complement(&a).to_dense().unwrap(), [false, true, true, true]);
/// ```
pub fn complement<const K: usize>(a: &KTree<K>) -> KTree<K> {
    let levels = (0..a.depth_count())
        .map(|d| {
            let l = a.level_states(d);
            let n = l.len();
            // Whole words complemented; the last word only in its used slots.
            let words: Vec<u64> = l
                .words()
                .iter()
                .enumerate()
                .map(|(w, &word)| words::complement(word, n - NODES_PER_WORD * w))
                .collect();
            l.with_same_partials(words)
        })
        .collect();
    KTree::from_levels(a.universe(), levels)
}
