//! The nearest full voxel to a voxel and its distance ([`nearest`], [`distance`], from anywhere:
//! [`nearest_signed`]; many on all threads: [`nearest_many`], [`nearest_many_signed`]), Euclidean
//! between voxel centres as scipy's `distance_transform_edt` measures it.
//!
//! Exact depth-first branch and bound: a cell's lower bound is the integer squared distance from the query
//! voxel to the nearest voxel of the cell, so no rounding decides anything; a full leaf's bound is
//! attained by its voxel nearest the query. A node's non-empty children are visited nearest first, and a
//! cell is opened only while its bound could still beat the best voxel found, so the search ends with the
//! exact answer once every cell that could hold a nearer voxel has been ruled out. The batch forms order
//! their points by Morton key and start each search from the previous point's answer (a full voxel, so
//! its distance is an exact upper bound): the cells farther than it are never opened.
//!
//! Ties: among equally near full voxels, the one with the smallest Morton key
//! ([`crate::space::morton_encode`]) is returned.

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use crate::radix::sort_by_key;
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
    Ok(search(tree, point, None, &mut Vec::new())?
        .map(|(squared, _, voxel)| Nearest { voxel, squared }))
}

/// The best candidate so far: squared distance, Morton key, voxel.
type Best<const K: usize> = (u128, u64, [u32; K]);

/// A cell to open: its bound, the cell, its node index and state.
type Frame<const K: usize> = (u128, Cell<K>, usize, NodeState);

/// Whether a cell with lower bound `bound` may hold a voxel that beats `best` (nearer, or as near with a
/// smaller key: the cell's keys are at least its origin's).
#[inline]
fn may_beat<const K: usize>(best: &Option<Best<K>>, bound: u128, cell: &Cell<K>) -> bool {
    match best {
        None => true,
        Some((d, k, _)) => bound < *d || (bound == *d && cell.morton() < *k),
    }
}

/// The exact nearest full voxel to `point`: depth-first, children nearest first, starting from `seed` (a
/// full voxel, whose distance bounds the answer) if given. `stack` is scratch space, reused by batches.
fn search<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    point: [i64; K],
    seed: Option<[u32; K]>,
    stack: &mut Vec<Frame<K>>,
) -> Result<Option<Best<K>>, T::Error> {
    let root = tree.root_state()?;
    if root == NodeState::Empty {
        return Ok(None);
    }
    let mut best: Option<Best<K>> = seed.map(|v| {
        let d = (0..K).fold(0u128, |d, a| {
            let gap = u128::from(i64::from(v[a]).abs_diff(point[a]));
            d.saturating_add(gap.saturating_mul(gap))
        });
        (d, morton_encode(v), v)
    });
    let cell = tree.universe().root();
    stack.clear();
    stack.push((nearest_in(&cell, &point).1, cell, 0, root));
    // The children of one node, to be pushed farthest first (popped nearest first).
    let mut children: Vec<Frame<K>> = Vec::with_capacity(1 << K);
    while let Some((bound, cell, index, state)) = stack.pop() {
        if !may_beat(&best, bound, &cell) {
            continue;
        }
        if state == NodeState::Full {
            let (near, d) = nearest_in(&cell, &point);
            let key = morton_encode(near);
            if best.is_none_or(|(bd, bk, _)| (d, key) < (bd, bk)) {
                best = Some((d, key, near));
            }
            continue;
        }
        let depth = cell.level as usize;
        let first = tree.first_child(depth, index)?;
        let codes = tree.block_codes(depth + 1, first)?;
        children.clear();
        for code in 0..1usize << K {
            let state = NodeState::from_bits(codes >> (2 * code));
            if state == NodeState::Empty {
                continue;
            }
            let child = cell.child(code);
            let bound = nearest_in(&child, &point).1;
            if may_beat(&best, bound, &child) {
                children.push((bound, child, first + code, state));
            }
        }
        // Farthest first onto the stack, so the nearest is opened first (the order only matters for
        // speed: every cell that may beat the best is opened whatever the order).
        children.sort_unstable_by_key(|c| std::cmp::Reverse(c.0));
        stack.extend_from_slice(&children);
    }
    Ok(best)
}

/// The fewest points of one run of a batch, searched one after the other on one thread.
const RUN: usize = 1 << 12;

/// Answers `points` on all threads: the whole batch ordered by Morton key (of the voxel nearest each point
/// in the universe), cut into runs, each run's points searched in order, each from the previous answer.
fn search_many<const K: usize, T>(
    tree: &T,
    points: &[[i64; K]],
) -> Result<Vec<Option<Nearest<K>>>, T::Error>
where
    T: TreeStorage<K> + Sync,
{
    let top = tree.universe().side() as i64 - 1;
    let mut order: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (morton_encode(p.map(|c| c.clamp(0, top) as u32)), i as u32))
        .collect();
    sort_by_key(&mut order, K as u32 * tree.level(), &mut Vec::new(), |p| {
        p.0
    });
    // A few runs a thread, so that uneven runs even out.
    let run = RUN.max(points.len() / (4 * rayon::current_num_threads()) + 1);
    let found: Vec<Vec<Option<Best<K>>>> = order
        .par_chunks(run)
        .map(|run| {
            let mut stack = Vec::new();
            let mut seed = None;
            run.iter()
                .map(|&(_, i)| {
                    let found = search(tree, points[i as usize], seed, &mut stack)?;
                    seed = found.map(|(_, _, v)| v).or(seed);
                    Ok(found)
                })
                .collect()
        })
        .collect::<Result<_, T::Error>>()?;
    let mut out = vec![None; points.len()];
    for (&(_, i), found) in order.iter().zip(found.into_iter().flatten()) {
        out[i as usize] = found.map(|(squared, _, voxel)| Nearest { voxel, squared });
    }
    Ok(out)
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

/// [`nearest_signed`] for each point, on all threads, in the order given (the points searched in Morton
/// order, each search from the previous answer).
///
/// # Errors
/// The storage's first read error.
pub fn nearest_many_signed<const K: usize, T>(
    tree: &T,
    points: &[[i64; K]],
) -> Result<Vec<Option<Nearest<K>>>, T::Error>
where
    T: TreeStorage<K> + Sync,
{
    search_many(tree, points)
}

/// [`nearest`] for each point, on all threads, in the order given (as [`nearest_many_signed`]).
///
/// # Errors
/// The storage's first read error.
pub fn nearest_many<const K: usize, T>(
    tree: &T,
    points: &[[u32; K]],
) -> Result<Vec<Option<Nearest<K>>>, T::Error>
where
    T: TreeStorage<K> + Sync,
{
    let points: Vec<[i64; K]> = points.iter().map(|p| p.map(i64::from)).collect();
    search_many(tree, &points)
}
