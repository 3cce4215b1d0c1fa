//! Building a valued tree from valued runs ([`ValueRuns`]): from the root down, each cell holds the pieces
//! of the runs inside it; a cell is a leaf when no run enters it (empty) or when every column of the cell
//! is covered by one piece, all of one value (full of it); otherwise its pieces are cut among its `2^K`
//! children. Blocks of children that turn out alike are joined from the bottom up
//! ([`build_top_down`]), so the tree is minimal whatever the runs (touching runs of one value included).
//!
//! Cost: each run is cut once per level it crosses a cell boundary in, and each cell with children sorts
//! its pieces among its children — about `O(2^K · pieces)` per level.
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
use crate::tree::top_down::{build_top_down, Decision};
use crate::tree::TreeError;
use crate::value::Value;
use crate::KTree;

impl<const K: usize, V: Value> KTree<K, V> {
    /// The minimal valued tree of `runs`.
    pub fn from_value_runs(runs: &ValueRuns<K, V>) -> KTree<K, V> {
        let universe = runs.universe();
        let keys = ColumnKeys::<K>::new(universe.level());
        let out = build_top_down::<K, V, (Cell<K>, Vec<ValueRun<V>>), TreeError>(
            universe.level(),
            (universe.root(), runs.runs().to_vec()),
            |_, (cell, pieces)| Ok(decide(cell, pieces)),
            |(cell, pieces), code| Ok(cut(&keys, cell, pieces, code)),
        );
        out.expect("the runs' values were checked when the runs were made")
    }
}

/// The pieces of a cell's pieces inside its child `code`, clipped to the child's `z` range.
fn cut<const K: usize, V: Value>(
    keys: &ColumnKeys<K>,
    cell: &Cell<K>,
    pieces: &[ValueRun<V>],
    code: usize,
) -> (Cell<K>, Vec<ValueRun<V>>) {
    let child = cell.child(code);
    let half = child.side() as u32;
    let (z0, z1) = (child.origin[K - 1], child.origin[K - 1] + half);
    let inside = pieces
        .iter()
        .filter(|p| {
            p.z1 < z1
                && p.z2 > z0
                && (0..K - 1).all(|a| {
                    let x = keys.axis(p.column, a);
                    x >= child.origin[a] && x < child.origin[a] + half
                })
        })
        .map(|p| ValueRun {
            z1: p.z1.max(z0),
            z2: p.z2.min(z1),
            ..*p
        })
        .collect();
    (child, inside)
}

/// A cell's decision from the pieces of runs inside it (clipped to its `z` range).
fn decide<const K: usize, V: Value>(cell: &Cell<K>, pieces: &[ValueRun<V>]) -> Decision<V> {
    let Some(first) = pieces.first() else {
        return Decision::Leaf(None);
    };
    let side = cell.side();
    let columns = u128::from(side).pow(K as u32 - 1);
    let z0 = cell.origin[K - 1];
    let uniform = pieces.len() as u128 == columns
        && pieces.iter().all(|p| {
            u64::from(p.z1) == u64::from(z0)
                && u64::from(p.z2) == u64::from(z0) + side
                && p.value.same(first.value)
        });
    if uniform {
        Decision::Leaf(Some(first.value))
    } else {
        Decision::Split
    }
}
