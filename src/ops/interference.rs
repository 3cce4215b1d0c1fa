//! Interference detection in any dimension (Meagher §3, claim M14): do two objects share a voxel, which
//! cells do, and — for space-time trees — the first time step at which they meet.
//!
//! A simultaneous traversal like the Booleans', stopping at the first full–full or full–partial pair.
//! Both trees are pre-sorted, so no search is needed: cost linear in the nodes reached, usually far fewer.

use super::boolean::{intersection, same_level};
use super::OpsError;
use crate::space::Cell;
use crate::tree::{KTree, NodeState};

/// Whether the objects share at least one voxel (regularized: touching along a face is not interference).
/// Stops at the first overlap found.
///
/// ```
/// use ktree::{KTree, ops::interferes};
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(2, &[false, false, true, false]).unwrap();
/// assert!(!interferes(&a, &b).unwrap()); // they touch, they do not overlap
/// ```
///
/// # Errors
/// [`OpsError::LevelMismatch`] when the trees' levels differ.
pub fn interferes<const K: usize>(a: &KTree<K>, b: &KTree<K>) -> Result<bool, OpsError> {
    same_level(a, b)?;
    Ok(meet(a, b, 0, 0, 0))
}

fn meet<const K: usize>(a: &KTree<K>, b: &KTree<K>, depth: usize, ia: usize, ib: usize) -> bool {
    match (a.state(depth, ia), b.state(depth, ib)) {
        (NodeState::Empty, _) | (_, NodeState::Empty) => false,
        (NodeState::Partial, NodeState::Partial) => {
            let (fa, fb) = (a.first_child(depth, ia), b.first_child(depth, ib));
            (0..1usize << K).any(|c| meet(a, b, depth + 1, fa + c, fb + c))
        }
        // Full against anything non-empty: a reduced partial node holds at least one full voxel.
        _ => true,
    }
}

/// The cells where the objects overlap (the full leaves of `A ∩ B`), in Morton order.
///
/// # Errors
/// [`OpsError::LevelMismatch`].
pub fn overlap_cells<const K: usize>(a: &KTree<K>, b: &KTree<K>) -> Result<Vec<Cell<K>>, OpsError> {
    Ok(intersection(a, b)?.full_cells().collect())
}

/// For trees whose axis `time_axis` is time (e.g. 4-D space-time trees `(x, y, z, t)`): the first time
/// step at which the two objects share a voxel, or `None` if they never do. Descends into the children
/// with the lower `time_axis` half first and stops at the first overlap, so it visits few nodes.
///
/// # Errors
/// [`OpsError::LevelMismatch`]; [`OpsError::BadParameter`] if `time_axis ≥ K`.
pub fn first_contact<const K: usize>(
    a: &KTree<K>,
    b: &KTree<K>,
    time_axis: usize,
) -> Result<Option<u32>, OpsError> {
    same_level(a, b)?;
    if time_axis >= K {
        return Err(OpsError::BadParameter {
            reason: format!("time axis {time_axis} is not below K = {K}"),
        });
    }
    let mut best = None;
    earliest(a, b, (0, 0), 0, a.universe().root(), time_axis, &mut best);
    Ok(best)
}

fn earliest<const K: usize>(
    a: &KTree<K>,
    b: &KTree<K>,
    (ia, ib): (usize, usize),
    depth: usize,
    cell: Cell<K>,
    axis: usize,
    best: &mut Option<u32>,
) {
    let t0 = cell.origin[axis];
    if best.is_some_and(|b| b <= t0) {
        return;
    }
    match (a.state(depth, ia), b.state(depth, ib)) {
        (NodeState::Empty, _) | (_, NodeState::Empty) => {}
        (NodeState::Full, NodeState::Full) => *best = Some(t0),
        (sa, sb) => {
            // Lower time half first.
            let mut codes: Vec<usize> = (0..1usize << K).collect();
            codes.sort_by_key(|&c| c >> axis & 1);
            for c in codes {
                let ca = if sa == NodeState::Partial {
                    a.first_child(depth, ia) + c
                } else {
                    usize::MAX
                };
                let cb = if sb == NodeState::Partial {
                    b.first_child(depth, ib) + c
                } else {
                    usize::MAX
                };
                earliest_mixed(
                    a,
                    b,
                    (ca, sa),
                    (cb, sb),
                    depth + 1,
                    cell.child(c),
                    axis,
                    best,
                );
            }
        }
    }
}

/// Like [`earliest`] where either side may be a full leaf standing in for all its descendants.
#[allow(clippy::too_many_arguments)]
fn earliest_mixed<const K: usize>(
    a: &KTree<K>,
    b: &KTree<K>,
    (ia, sa): (usize, NodeState),
    (ib, sb): (usize, NodeState),
    depth: usize,
    cell: Cell<K>,
    axis: usize,
    best: &mut Option<u32>,
) {
    if sa == NodeState::Partial && sb == NodeState::Partial {
        return earliest(a, b, (ia, ib), depth, cell, axis, best);
    }
    // One side is a full leaf above this depth: the first time the other side is non-empty in `cell`.
    let (tree, index) = if sa == NodeState::Partial {
        (a, ia)
    } else {
        (b, ib)
    };
    if let Some(t) = first_time(tree, depth, index, cell, axis, *best) {
        *best = Some(best.map_or(t, |b| b.min(t)));
    }
}

/// The smallest time coordinate of a full voxel in the subtree (`None` if none before `bound`).
fn first_time<const K: usize>(
    tree: &KTree<K>,
    depth: usize,
    index: usize,
    cell: Cell<K>,
    axis: usize,
    bound: Option<u32>,
) -> Option<u32> {
    let t0 = cell.origin[axis];
    if bound.is_some_and(|b| b <= t0) {
        return None;
    }
    match tree.state(depth, index) {
        NodeState::Empty => None,
        NodeState::Full => Some(t0),
        NodeState::Partial => {
            let first = tree.first_child(depth, index);
            let mut best = bound;
            let mut found = None;
            let mut codes: Vec<usize> = (0..1usize << K).collect();
            codes.sort_by_key(|&c| c >> axis & 1);
            for c in codes {
                if let Some(t) = first_time(tree, depth + 1, first + c, cell.child(c), axis, best) {
                    best = Some(best.map_or(t, |b| b.min(t)));
                    found = Some(found.map_or(t, |f: u32| f.min(t)));
                }
            }
            found
        }
    }
}
