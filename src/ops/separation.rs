//! Minimum separation between two objects: the smallest distance between a voxel centre of one and a voxel
//! centre of the other, by best-first branch and bound over pairs of nodes (a bonus of claim M14).
//!
//! A pair of nodes is bounded below by the gap between their cells; pairs are expanded in order of that
//! bound (the larger partial node is split), empty nodes are dropped, and the first pair of two full
//! leaves popped gives the answer exactly: for two full cells the closest voxel centres are as far apart
//! as the cells' voxel index ranges. Integer arithmetic (squared distances).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::boolean::same_level;
use super::OpsError;
use crate::space::Cell;
use crate::tree::{KTree, NodeState};

/// Squared distance between the nearest voxel centres of two cells.
fn gap2<const K: usize>(a: &Cell<K>, b: &Cell<K>) -> u128 {
    let mut d = 0u128;
    for i in 0..K {
        let (a0, a1) = (
            u64::from(a.origin[i]),
            u64::from(a.origin[i]) + a.side() - 1,
        );
        let (b0, b1) = (
            u64::from(b.origin[i]),
            u64::from(b.origin[i]) + b.side() - 1,
        );
        let g = b0.saturating_sub(a1).max(a0.saturating_sub(b1));
        d += u128::from(g) * u128::from(g);
    }
    d
}

/// The smallest Euclidean distance between voxel centres of `a` and of `b` (0 when they share a voxel, 1
/// when they touch along a face), or `None` if either object is empty.
///
/// ```
/// use ktree::{KTree, ops::min_separation};
/// let a = KTree::<1>::from_dense(3, &[true, false, false, false, false, false, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(3, &[false, false, false, false, false, true, true, false]).unwrap();
/// assert_eq!(min_separation(&a, &b).unwrap(), Some(5.0));
/// ```
///
/// # Errors
/// [`OpsError::LevelMismatch`] when the levels differ.
pub fn min_separation<const K: usize>(a: &KTree<K>, b: &KTree<K>) -> Result<Option<f64>, OpsError> {
    same_level(a, b)?;
    // A pair: (depth, index, cell) of a node of a, of b; the heap pops the smallest bound first.
    type Side<const K: usize> = (usize, usize, Cell<K>);
    let node = |tree: &KTree<K>, s: Side<K>| tree.node_at(s.1, s.2);
    let root = a.universe().root();
    // The heap orders small entries (bound, shallowness, place in `pairs`); the pairs stay put. Among
    // equal bounds the deepest pair comes first: it is the nearest to a pair of full leaves.
    let mut pairs: Vec<(Side<K>, Side<K>)> = vec![((0, 0, root), (0, 0, root))];
    let mut heap: BinaryHeap<Reverse<(u128, usize, usize)>> = BinaryHeap::new();
    heap.push(Reverse((0, usize::MAX, 0)));
    while let Some(Reverse((bound, _, at))) = heap.pop() {
        let (sa, sb) = pairs[at];
        let (na, nb) = (node(a, sa), node(b, sb));
        if na.state == NodeState::Empty || nb.state == NodeState::Empty {
            continue;
        }
        if na.state == NodeState::Full && nb.state == NodeState::Full {
            return Ok(Some((bound as f64).sqrt()));
        }
        // Split the partial node with the larger cell (a if tied and partial).
        let split_a = na.state == NodeState::Partial
            && (nb.state != NodeState::Partial || na.cell.log_side >= nb.cell.log_side);
        let (tree, split) = if split_a { (a, &na) } else { (b, &nb) };
        for child in tree.children(split) {
            if child.state == NodeState::Empty {
                continue;
            }
            let side = (child.cell.level as usize, child.index, child.cell);
            let (ca, cb) = if split_a { (side, sb) } else { (sa, side) };
            let shallowness = usize::MAX - (ca.0 + cb.0);
            heap.push(Reverse((gap2(&ca.2, &cb.2), shallowness, pairs.len())));
            pairs.push((ca, cb));
        }
    }
    Ok(None)
}
