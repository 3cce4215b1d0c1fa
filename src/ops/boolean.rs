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

use super::emit::{collapse, leaf, LevelWriter};
use super::OpsError;
use crate::tree::cursor::{walk_pair, PairNode, PairVisitor, Walk};
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

/// What the result is over a region where one input is the leaf `fixed` and the other is `x`.
#[derive(Clone, Copy)]
enum Outcome {
    Leaf(NodeState),
    Copy,
    Invert,
}

/// The Boolean as a two-tree walk: a pair is decided on the spot where a leaf decides it (a leaf, a copy
/// of the other subtree or its complement), else its children are visited and the pair is decided when
/// it is left, from its children's states.
struct Merge<'a, const K: usize> {
    a: &'a KTree<K>,
    b: &'a KTree<K>,
    op: BoolOp,
    out: LevelWriter,
    /// `kids[d]`: the states decided so far for the children (at depth `d`) of the open pair above.
    kids: Vec<[NodeState; 16]>,
}

impl<const K: usize> Merge<'_, K> {
    /// Result over a region where input `a` is the leaf `la` (`a_fixed`) or `b` is (`!a_fixed`).
    fn outcome(&self, fixed_full: bool, a_fixed: bool) -> Outcome {
        let (r0, r1) = if a_fixed {
            (
                self.op.apply(fixed_full, false),
                self.op.apply(fixed_full, true),
            )
        } else {
            (
                self.op.apply(false, fixed_full),
                self.op.apply(true, fixed_full),
            )
        };
        match (r0, r1) {
            (r, s) if r == s => Outcome::Leaf(leaf(r)),
            (false, true) => Outcome::Copy,
            _ => Outcome::Invert,
        }
    }

    /// Records the result `state` of the pair at `depth` with child code `code`.
    #[inline]
    fn decide(&mut self, depth: usize, code: usize, state: NodeState) {
        self.kids[depth][code] = state;
    }
}

impl<const K: usize> PairVisitor<K> for Merge<'_, K> {
    const ORIGINS: bool = false;

    #[inline]
    fn visit(&mut self, pair: &PairNode<K>) -> Walk {
        let (depth, code) = (pair.cell.level as usize, pair.code);
        let state = match (pair.a.state, pair.b.state) {
            (NodeState::Partial, NodeState::Partial) => return Walk::Descend,
            (NodeState::Partial, lb) => {
                let invert = match self.outcome(lb == NodeState::Full, false) {
                    Outcome::Leaf(s) => {
                        self.decide(depth, code, s);
                        return Walk::Skip;
                    }
                    outcome => matches!(outcome, Outcome::Invert),
                };
                self.out
                    .copy_subtree(self.a, depth, pair.a.index, depth, invert)
            }
            (la, NodeState::Partial) => {
                let invert = match self.outcome(la == NodeState::Full, true) {
                    Outcome::Leaf(s) => {
                        self.decide(depth, code, s);
                        return Walk::Skip;
                    }
                    outcome => matches!(outcome, Outcome::Invert),
                };
                self.out
                    .copy_subtree(self.b, depth, pair.b.index, depth, invert)
            }
            (la, lb) => leaf(self.op.apply(la == NodeState::Full, lb == NodeState::Full)),
        };
        self.decide(depth, code, state);
        Walk::Skip
    }

    #[inline]
    fn leave(&mut self, pair: &PairNode<K>) {
        let depth = pair.cell.level as usize;
        let kids = self.kids[depth + 1];
        let kids = &kids[..1 << K];
        let state = match collapse(kids) {
            Some(s) => s,
            None => {
                self.out.push_block(depth + 1, kids);
                NodeState::Partial
            }
        };
        self.decide(depth, pair.code, state);
    }
}

/// Checks that two trees share a universe level.
pub(crate) fn same_level<const K: usize>(a: &KTree<K>, b: &KTree<K>) -> Result<(), OpsError> {
    if a.level() != b.level() {
        return Err(OpsError::LevelMismatch {
            left: a.level(),
            right: b.level(),
        });
    }
    Ok(())
}

/// Applies a binary Boolean operation. The output is reduced; the cost is linear in the input nodes.
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
/// [`OpsError::LevelMismatch`] when the trees' levels differ.
pub fn boolean<const K: usize>(
    a: &KTree<K>,
    b: &KTree<K>,
    op: BoolOp,
) -> Result<KTree<K>, OpsError> {
    same_level(a, b)?;
    let depths = a.depth_count().max(b.depth_count());
    let mut m = Merge {
        a,
        b,
        op,
        out: LevelWriter::new(),
        kids: vec![[NodeState::Empty; 16]; depths + 1],
    };
    walk_pair(a, b, &mut m);
    let root = m.kids[0][0];
    Ok(m.out.finish_with_root(a.universe(), root))
}

/// `A ∪ B`. See [`boolean`].
///
/// # Errors
/// [`OpsError::LevelMismatch`].
pub fn union<const K: usize>(a: &KTree<K>, b: &KTree<K>) -> Result<KTree<K>, OpsError> {
    boolean(a, b, BoolOp::Union)
}

/// `A ∩ B`. See [`boolean`].
///
/// # Errors
/// [`OpsError::LevelMismatch`].
pub fn intersection<const K: usize>(a: &KTree<K>, b: &KTree<K>) -> Result<KTree<K>, OpsError> {
    boolean(a, b, BoolOp::Intersection)
}

/// `A ∖ B`. See [`boolean`].
///
/// # Errors
/// [`OpsError::LevelMismatch`].
pub fn difference<const K: usize>(a: &KTree<K>, b: &KTree<K>) -> Result<KTree<K>, OpsError> {
    boolean(a, b, BoolOp::Difference)
}

/// `A △ B`. See [`boolean`].
///
/// # Errors
/// [`OpsError::LevelMismatch`].
pub fn symmetric_difference<const K: usize>(
    a: &KTree<K>,
    b: &KTree<K>,
) -> Result<KTree<K>, OpsError> {
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
