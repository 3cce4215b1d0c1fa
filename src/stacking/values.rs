//! Building a valued tree from valued runs ([`ValueRuns`]), depth first: a cell is a leaf when no run
//! enters it (empty) or when every column of the cell is covered by one piece of a run, all of one value
//! (full of it); otherwise its pieces are distributed among its `2^K` children (a piece crossing the
//! middle of the last axis is cut in two) and each child is built in turn. A block of children that turns
//! out alike (all empty, or all full of one value) is taken back and its parent becomes that leaf, so the
//! tree is minimal whatever the runs (touching runs of one value included) — Akman & Franklin's
//! combination of aligned equal blocks, generalised to values.
//!
//! The nodes of a level are met in the order of a depth-first walk, which is the level order. Cost: each
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

use crate::rays::{ColumnKeys, ValueRun, ValueRuns};
use crate::space::Cell;
use crate::tree::top_down::pack;
use crate::tree::valued::{combine, ValueState};
use crate::value::Value;
use crate::KTree;

impl<const K: usize, V: Value> KTree<K, V> {
    /// The minimal valued tree of `runs`.
    pub fn from_value_runs(runs: &ValueRuns<K, V>) -> KTree<K, V> {
        let universe = runs.universe();
        let depths = universe.level() as usize + 1;
        let mut builder = DepthFirst {
            keys: ColumnKeys::<K>::new(universe.level()),
            levels: vec![Vec::new(); depths],
            scratch: vec![Vec::new(); depths + 1],
        };
        let root = builder.node(universe.root(), runs.runs(), 0);
        builder.levels[0].push(root);
        pack(universe, builder.levels)
    }
}

/// The state of a depth-first build: the settled states of each level so far, and one buffer a level for
/// the pieces of the children of the cell being built there.
struct DepthFirst<const K: usize, V> {
    keys: ColumnKeys<K>,
    levels: Vec<Vec<ValueState<V>>>,
    scratch: Vec<Vec<ValueRun<V>>>,
}

impl<const K: usize, V: Value> DepthFirst<K, V> {
    /// Builds the subtree of `cell` (at `depth`) from the pieces inside it (clipped to its `z` range);
    /// returns the cell's state, its children (if any) pushed onto the level below.
    fn node(&mut self, cell: Cell<K>, pieces: &[ValueRun<V>], depth: usize) -> ValueState<V> {
        let Some(first) = pieces.first() else {
            return ValueState::Empty;
        };
        let side = cell.side();
        let z0 = cell.origin()[K - 1];
        let columns = u128::from(side).pow(K as u32 - 1);
        if pieces.len() as u128 == columns
            && pieces.iter().all(|p| {
                p.z1 == z0 && u64::from(p.z2) == u64::from(z0) + side && p.value.same(first.value)
            })
        {
            return ValueState::Full(first.value);
        }
        // Not a leaf, so not a voxel (a voxel's one piece covers it): distribute among the children.
        let half_log = cell.log_side() - 1;
        let mid = z0 + (1u32 << half_log);
        let z_bit = 1usize << (K - 1);
        let code_of = |p: &ValueRun<V>| {
            (0..K - 1).fold(0usize, |code, a| {
                code | (((self.keys.axis(p.column, a) >> half_log) & 1) as usize) << a
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
        let mut buffer = std::mem::take(&mut self.scratch[depth + 1]);
        buffer.clear();
        buffer.resize(start[n], *first);
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
