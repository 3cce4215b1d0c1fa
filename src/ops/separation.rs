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
    let root = a.universe().root();
    // Heap entries: (bound, (depth, index, cell) of a, of b), smallest bound first.
    type Side<const K: usize> = (usize, usize, Cell<K>);
    let mut heap: BinaryHeap<Reverse<(u128, Side<K>, Side<K>)>> = BinaryHeap::new();
    heap.push(Reverse((0, (0, 0, root), (0, 0, root))));
    while let Some(Reverse((bound, sa, sb))) = heap.pop() {
        let (state_a, state_b) = (a.state(sa.0, sa.1), b.state(sb.0, sb.1));
        if state_a == NodeState::Empty || state_b == NodeState::Empty {
            continue;
        }
        if state_a == NodeState::Full && state_b == NodeState::Full {
            return Ok(Some((bound as f64).sqrt()));
        }
        // Split the partial node with the larger cell (a if tied and partial).
        let split_a = state_a == NodeState::Partial
            && (state_b != NodeState::Partial || sa.2.log_side >= sb.2.log_side);
        let (tree, side) = if split_a { (a, sa) } else { (b, sb) };
        let first = tree.first_child(side.0, side.1);
        for c in 0..1usize << K {
            let child = (side.0 + 1, first + c, side.2.child(c));
            if tree.state(child.0, child.1) == NodeState::Empty {
                continue;
            }
            let (na, nb) = if split_a { (child, sb) } else { (sa, child) };
            heap.push(Reverse((gap2(&na.2, &nb.2), na, nb)));
        }
    }
    Ok(None)
}
