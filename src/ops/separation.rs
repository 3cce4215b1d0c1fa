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
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

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
/// [`OpsError::LevelMismatch`] when the levels differ; [`OpsError::Storage`] if a read fails.
pub fn min_separation<const K: usize, A, B>(a: &A, b: &B) -> Result<Option<f64>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    same_level(a, b)?;
    min_separation_of(a, b).map_err(OpsError::storage)
}

/// One side of a pair of nodes: a node's index in its level, its cell (whose level is the node's depth)
/// and its state.
type Side<const K: usize> = (usize, Cell<K>, NodeState);

/// [`min_separation`] of two trees of one level.
fn min_separation_of<const K: usize, A, B>(a: &A, b: &B) -> Result<Option<f64>, A::Error>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    let root = a.universe().root();
    // The heap orders small entries (bound, shallowness, place in `pairs`); the pairs stay put. Among
    // equal bounds the deepest pair comes first: it is the nearest to a pair of full leaves.
    let mut pairs: Vec<(Side<K>, Side<K>)> =
        vec![((0, root, a.root_state()?), (0, root, b.root_state()?))];
    let mut heap: BinaryHeap<Reverse<(u128, usize, usize)>> = BinaryHeap::new();
    heap.push(Reverse((0, usize::MAX, 0)));
    while let Some(Reverse((bound, _, at))) = heap.pop() {
        let (na, nb) = pairs[at];
        if na.2 == NodeState::Empty || nb.2 == NodeState::Empty {
            continue;
        }
        if na.2 == NodeState::Full && nb.2 == NodeState::Full {
            return Ok(Some((bound as f64).sqrt()));
        }
        // Split the partial node with the larger cell (a if tied and partial).
        let split_a = na.2 == NodeState::Partial
            && (nb.2 != NodeState::Partial || na.1.log_side >= nb.1.log_side);
        let split = if split_a { na } else { nb };
        let depth = split.1.level as usize;
        let (first, codes) = if split_a {
            let first = a.first_child(depth, split.0)?;
            (first, a.block_codes(depth + 1, first)?)
        } else {
            let first = b.first_child(depth, split.0)?;
            (first, b.block_codes(depth + 1, first)?)
        };
        for code in 0..1usize << K {
            let state = NodeState::from_bits(codes >> (2 * code));
            if state == NodeState::Empty {
                continue;
            }
            let child = (first + code, split.1.child(code), state);
            let (ca, cb) = if split_a { (child, nb) } else { (na, child) };
            let shallowness = usize::MAX - (ca.1.level as usize + cb.1.level as usize);
            heap.push(Reverse((gap2(&ca.1, &cb.1), shallowness, pairs.len())));
            pairs.push((ca, cb));
        }
    }
    Ok(None)
}
