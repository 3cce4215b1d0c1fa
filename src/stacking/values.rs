//! Building a valued tree from valued runs ([`ValueRuns`]), depth first: a cell is a leaf when no run
//! enters it (empty) or when every column of the cell is covered by one piece of a run, all of one value
//! (full of it); otherwise its pieces are distributed among its `2^K` children (a piece crossing the
//! middle of the last axis is cut in two) and each child is built in turn. A block of children that turns
//! out alike (all empty, or all full of one value) is taken back and its parent becomes that leaf, so the
//! tree is minimal whatever the runs (touching runs of one value included) — Akman & Franklin's
//! combination of aligned equal blocks, generalised to values.
//!
//! The nodes of a level are met in the order of a depth-first walk, which is the level order; so the
//! subtrees of the cells of one depth, built apart on several threads, join level by level in Morton order. Cost: each
//! piece is placed once per level it lives in (a counting sort among the children, no allocation past one
//! buffer a level) — `O(pieces · L)`.
//!
//! ```
//! use ktree::rays::ValueRuns;
//! use ktree::{KTree, Ray};
//! let runs = ValueRuns::<1, u8>::from_runs(2, [(Ray::new([0], 2), 4), (Ray::new([2], 3), 4), (Ray::new([3], 4), 9)]).unwrap();
//! let tree = KTree::from_value_runs(&runs);
//! assert_eq!(tree, KTree::from_dense_values(2, &[Some(4), Some(4), Some(4), Some(9)]).unwrap());
//! ```

use rayon::prelude::*;

use crate::rays::source::default_split_depth;
use crate::rays::{ColumnKeys, ValueRun, ValueRuns};
use crate::space::Cell;
use crate::tree::top_down::Subtree;
use crate::tree::valued::{combine, ValueState, ValuedLevel};
use crate::value::Value;
use crate::KTree;

impl<const K: usize, V: Value> KTree<K, V> {
    /// The minimal valued tree of `runs`, on the threads of the current rayon pool: with more than one,
    /// the subtrees of cells of about 2^18 voxels built apart ([`default_split_depth`], see
    /// [`KTree::from_value_runs_split`]); with one, in a single depth-first pass (joining the subtrees'
    /// levels costs about a tenth more there).
    pub fn from_value_runs(runs: &ValueRuns<K, V>) -> KTree<K, V> {
        let split = if rayon::current_num_threads() > 1 {
            default_split_depth(K, runs.universe().level())
        } else {
            0
        };
        Self::from_value_runs_split(runs, split)
    }

    /// [`KTree::from_value_runs`] on the threads of the current rayon pool: the subtrees of the cells of
    /// depth `split` (clamped to the level) are built apart, each from the pieces of runs inside it, and
    /// their levels joined in Morton order (the subtrees of consecutive cells follow one another in every
    /// level); the cells above are settled from their children as the one-thread build settles them.
    /// Equal, node for node, to [`KTree::from_value_runs`], whatever the split and the threads.
    ///
    /// ```
    /// use ktree::rays::ValueRuns;
    /// use ktree::KTree;
    /// let dense: Vec<Option<u8>> = (0..64u32).map(|i| (i % 5 != 0).then_some((i / 16) as u8)).collect();
    /// let runs = ValueRuns::<2, u8>::from_dense_background(3, &dense.iter().map(|v| v.unwrap_or(9)).collect::<Vec<_>>(), 9).unwrap();
    /// assert_eq!(KTree::from_value_runs_split(&runs, 2), KTree::from_value_runs(&runs));
    /// ```
    pub fn from_value_runs_split(runs: &ValueRuns<K, V>, split: u32) -> KTree<K, V> {
        let universe = runs.universe();
        let keys = ColumnKeys::<K>::new(universe.level());
        subtree(&keys, universe.root(), runs.runs(), split).into_tree(universe)
    }
}

/// The subtree of `cell` from the pieces inside it: its root's state and the states of each level below
/// it (in level order), built apart on the rayon pool down to the cells of depth `split`.
pub(super) fn subtree<const K: usize, V: Value>(
    keys: &ColumnKeys<K>,
    cell: Cell<K>,
    pieces: &[ValueRun<V>],
    split: u32,
) -> Subtree<V> {
    if let Some(leaf) = leaf_of(cell, pieces) {
        return Subtree::leaf(leaf);
    }
    let depths = cell.log_side() as usize + 1;
    if cell.level() >= split {
        let mut builder = DepthFirst {
            keys,
            levels: vec![ValuedLevel::new(); depths],
            scratch: vec![Vec::new(); depths + 1],
        };
        let root = builder.node(cell, pieces, 0);
        let mut levels = builder.levels;
        levels.remove(0);
        return Subtree::new(root, levels);
    }
    let mut buffer = Vec::new();
    let start = distribute(keys, cell, pieces, &mut buffer);
    let kids: Vec<Subtree<V>> = (0..1usize << K)
        .into_par_iter()
        .map(|code| {
            subtree(
                keys,
                cell.child(code),
                &buffer[start[code]..start[code + 1]],
                split,
            )
        })
        .collect();
    Subtree::join(kids)
}

/// The leaf `cell` is when no piece enters it (empty) or one piece of one value covers each of its
/// columns whole (full); `None` when it has children.
fn leaf_of<const K: usize, V: Value>(
    cell: Cell<K>,
    pieces: &[ValueRun<V>],
) -> Option<ValueState<V>> {
    let Some(first) = pieces.first() else {
        return Some(ValueState::Empty);
    };
    let side = cell.side();
    let z0 = cell.origin()[K - 1];
    let columns = u128::from(side).pow(K as u32 - 1);
    let full = pieces.len() as u128 == columns
        && pieces.iter().all(|p| {
            p.z1 == z0 && u64::from(p.z2) == u64::from(z0) + side && p.value.same(first.value)
        });
    full.then_some(ValueState::Full(first.value))
}

/// The pieces of a cell that is not a leaf (so not a voxel) distributed among its `2^K` children into
/// `buffer` (a piece crossing the middle of the last axis is cut in two): child `code`'s pieces are
/// `buffer[start[code]..start[code + 1]]`, `start` returned.
fn distribute<const K: usize, V: Value>(
    keys: &ColumnKeys<K>,
    cell: Cell<K>,
    pieces: &[ValueRun<V>],
    buffer: &mut Vec<ValueRun<V>>,
) -> [usize; 17] {
    let half_log = cell.log_side() - 1;
    let mid = cell.origin()[K - 1] + (1u32 << half_log);
    let z_bit = 1usize << (K - 1);
    let code_of = |p: &ValueRun<V>| {
        (0..K - 1).fold(0usize, |code, a| {
            code | (((keys.axis(p.column, a) >> half_log) & 1) as usize) << a
        })
    };
    let n = 1usize << K;
    let mut start = [0usize; 17];
    for p in pieces {
        let c = code_of(p);
        if p.z1 < mid {
            start[c + 1] += 1;
        }
        if p.z2 > mid {
            start[(c | z_bit) + 1] += 1;
        }
    }
    for c in 0..n {
        start[c + 1] += start[c];
    }
    buffer.clear();
    if let Some(first) = pieces.first() {
        buffer.resize(start[n], *first);
    }
    let mut at = start;
    for p in pieces {
        let c = code_of(p);
        if p.z1 < mid {
            buffer[at[c]] = ValueRun {
                z2: p.z2.min(mid),
                ..*p
            };
            at[c] += 1;
        }
        if p.z2 > mid {
            buffer[at[c | z_bit]] = ValueRun {
                z1: p.z1.max(mid),
                ..*p
            };
            at[c | z_bit] += 1;
        }
    }
    start
}

/// The state of a depth-first build: the settled nodes of each level so far, and one buffer a level for
/// the pieces of the children of the cell being built there.
struct DepthFirst<'a, const K: usize, V> {
    keys: &'a ColumnKeys<K>,
    levels: Vec<ValuedLevel<V>>,
    scratch: Vec<Vec<ValueRun<V>>>,
}

impl<const K: usize, V: Value> DepthFirst<'_, K, V> {
    /// Builds the subtree of `cell` (at `depth`) from the pieces inside it (clipped to its `z` range);
    /// returns the cell's state, its children (if any) pushed onto the level below.
    fn node(&mut self, cell: Cell<K>, pieces: &[ValueRun<V>], depth: usize) -> ValueState<V> {
        if let Some(leaf) = leaf_of(cell, pieces) {
            return leaf;
        }
        let mut buffer = std::mem::take(&mut self.scratch[depth + 1]);
        let start = distribute(self.keys, cell, pieces, &mut buffer);
        let n = 1usize << K;
        let mut kids = [ValueState::Empty; 16];
        for (code, kid) in kids.iter_mut().enumerate().take(n) {
            *kid = self.node(
                cell.child(code),
                &buffer[start[code]..start[code + 1]],
                depth + 1,
            );
        }
        self.scratch[depth + 1] = buffer;
        let state = combine(&kids[..n]);
        if state.has_children() {
            self.levels[depth + 1].extend_from_slice(&kids[..n]);
        }
        state
    }
}
