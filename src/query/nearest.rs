//! The nearest full voxel to a voxel and its distance ([`nearest`], [`distance`], from anywhere:
//! [`nearest_signed`]; many on all threads: [`nearest_many`], [`nearest_many_signed`]), Euclidean
//! between voxel centres as scipy's `distance_transform_edt` measures it.
//!
//! Exact best-first branch and bound: a cell's lower bound is the integer squared distance from the query
//! voxel to the nearest voxel of the cell, so no rounding decides anything; a full leaf's bound is
//! attained by its voxel nearest the query. Cells wait in a queue ordered by bound; the search ends when
//! the best voxel found is no farther than every cell still waiting, so only cells nearer than the answer
//! are opened.
//!
//! Ties: among equally near full voxels, the one with the smallest Morton key
//! ([`crate::space::morton_encode`]) is returned.

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use std::collections::BinaryHeap;

use crate::space::{morton_encode, Cell};
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// A nearest full voxel and its squared distance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Nearest<const K: usize> {
    /// The voxel.
    pub voxel: [u32; K],
    /// The squared Euclidean distance between the query's centre and the voxel's, in voxel units.
    pub squared: u128,
}

impl<const K: usize> Nearest<K> {
    /// The Euclidean distance (`√squared`, rounded once).
    pub fn distance(&self) -> f64 {
        (self.squared as f64).sqrt()
    }
}

/// A cell waiting in the search: its lower bound and the Morton key of its origin (the smallest key of
/// its voxels) order the queue.
#[derive(Debug, Clone, Copy)]
struct Waiting<const K: usize> {
    bound: u128,
    key: u64,
    cell: Cell<K>,
    index: usize,
    state: NodeState,
}

impl<const K: usize> PartialEq for Waiting<K> {
    fn eq(&self, other: &Self) -> bool {
        (self.bound, self.key) == (other.bound, other.key)
    }
}

impl<const K: usize> Eq for Waiting<K> {}

impl<const K: usize> PartialOrd for Waiting<K> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl<const K: usize> Ord for Waiting<K> {
    /// Reversed: the max-heap pops the smallest bound (then the smallest key) first.
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        (other.bound, other.key).cmp(&(self.bound, self.key))
    }
}

/// The voxel of `cell` nearest `point` and its squared distance (exact for coordinates within ±2^61;
/// saturating beyond).
#[inline]
fn nearest_in<const K: usize>(cell: &Cell<K>, point: &[i64; K]) -> ([u32; K], u128) {
    let side = cell.side() as i64;
    let mut near = [0u32; K];
    let mut bound = 0u128;
    for a in 0..K {
        let lo = i64::from(cell.origin[a]);
        let c = point[a].clamp(lo, lo + side - 1);
        near[a] = c as u32;
        let gap = u128::from(c.abs_diff(point[a]));
        bound = bound.saturating_add(gap.saturating_mul(gap));
    }
    (near, bound)
}

/// A nearest full voxel to voxel `point` (which may lie outside the universe) and its squared distance;
/// `None` for an empty object. Ties: the smallest Morton key (see the [module docs](self)).
///
/// ```
/// use ktree::query::nearest;
/// use ktree::KTree;
/// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i == 15).collect::<Vec<_>>()).unwrap();
/// let n = nearest(&tree, [0, 1]).unwrap().unwrap();
/// assert_eq!((n.voxel, n.squared), ([3, 3], 13));
/// assert_eq!(nearest(&KTree::<2>::empty(2).unwrap(), [0, 0]), Ok(None));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn nearest<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    point: [u32; K],
) -> Result<Option<Nearest<K>>, T::Error> {
    nearest_signed(tree, point.map(i64::from))
}

/// [`nearest`] from a voxel anywhere, negative coordinates included (as numpy users give them). Exact for
/// coordinates within `±2^61`; beyond, squared distances saturate at `u128::MAX`.
///
/// ```
/// use ktree::query::nearest_signed;
/// use ktree::KTree;
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, false]).unwrap();
/// assert_eq!(nearest_signed(&tree, [-3, 0]).unwrap().unwrap().squared, 9);
/// ```
///
/// # Errors
/// The storage's read error.
pub fn nearest_signed<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    point: [i64; K],
) -> Result<Option<Nearest<K>>, T::Error> {
    let root = tree.root_state()?;
    if root == NodeState::Empty {
        return Ok(None);
    }
    let cell = tree.universe().root();
    let mut queue = BinaryHeap::new();
    queue.push(Waiting {
        bound: nearest_in(&cell, &point).1,
        key: cell.morton(),
        cell,
        index: 0,
        state: root,
    });
    // The best so far: squared distance, Morton key, voxel.
    let mut best: Option<(u128, u64, [u32; K])> = None;
    let beats = |best: &Option<(u128, u64, [u32; K])>, bound: u128, key: u64| match best {
        None => true,
        Some((d, k, _)) => (bound, key) < (*d, *k),
    };
    while let Some(w) = queue.pop() {
        // Every cell still waiting has a bound (and key) at least this one's: none holds a better voxel.
        if !beats(&best, w.bound, w.key) {
            break;
        }
        if w.state == NodeState::Full {
            let (near, d) = nearest_in(&w.cell, &point);
            let key = morton_encode(near);
            if beats(&best, d, key) {
                best = Some((d, key, near));
            }
            continue;
        }
        let depth = w.cell.level as usize;
        let first = tree.first_child(depth, w.index)?;
        let codes = tree.block_codes(depth + 1, first)?;
        for code in 0..1usize << K {
            let state = NodeState::from_bits(codes >> (2 * code));
            if state == NodeState::Empty {
                continue;
            }
            let cell = w.cell.child(code);
            let (bound, key) = (nearest_in(&cell, &point).1, cell.morton());
            if beats(&best, bound, key) {
                queue.push(Waiting {
                    bound,
                    key,
                    cell,
                    index: first + code,
                    state,
                });
            }
        }
    }
    Ok(best.map(|(squared, _, voxel)| Nearest { voxel, squared }))
}

/// The distance from voxel `point` to the nearest full voxel: `0` inside the object, infinite for an
/// empty object.
///
/// ```
/// use ktree::query::distance;
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(2, &[true, false, false, false]).unwrap();
/// assert_eq!(distance(&tree, [3]), Ok(3.0));
/// assert_eq!(distance(&tree, [0]), Ok(0.0));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn distance<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    point: [u32; K],
) -> Result<f64, T::Error> {
    Ok(nearest(tree, point)?.map_or(f64::INFINITY, |n| n.distance()))
}

/// [`nearest_signed`] for each point, on all threads, in the order given.
///
/// # Errors
/// The storage's first read error.
pub fn nearest_many_signed<const K: usize, T>(
    tree: &T,
    points: &[[i64; K]],
) -> Result<Vec<Option<Nearest<K>>>, T::Error>
where
    T: TreeStorage<K> + Sync,
    T::Error: Send,
{
    points
        .par_iter()
        .with_min_len(256)
        .map(|&p| nearest_signed(tree, p))
        .collect()
}

/// [`nearest`] for each point, on all threads, in the order given.
///
/// # Errors
/// The storage's first read error.
pub fn nearest_many<const K: usize, T>(
    tree: &T,
    points: &[[u32; K]],
) -> Result<Vec<Option<Nearest<K>>>, T::Error>
where
    T: TreeStorage<K> + Sync,
    T::Error: Send,
{
    points
        .par_iter()
        .with_min_len(256)
        .map(|&p| nearest(tree, p))
        .collect()
}
