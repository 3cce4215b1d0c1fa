//! The nearest full voxel to a voxel and its distance ([`nearest`], [`distance`], from anywhere:
//! [`nearest_signed`]; many on all threads: [`nearest_many`], [`nearest_many_signed`]), Euclidean
//! between voxel centres as scipy's `distance_transform_edt` measures it.
//!
//! Exact branch and bound: a cell's lower bound is the integer squared distance from the query voxel to
//! the nearest voxel of the cell, so no rounding decides anything; a full leaf's bound is attained by its
//! voxel nearest the query. Children are visited near half first; a subtree whose bound cannot beat the
//! best found is skipped.
//!
//! Ties: among equally near full voxels, the one with the smallest Morton key
//! ([`crate::space::morton_encode`]) is returned.

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use crate::space::morton_encode;
use crate::tree::cursor::{try_walk, ChildOrder, Visitor, Walk};
use crate::tree::storage::TreeStorage;
use crate::tree::{NodeRef, NodeState};

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

struct Search<const K: usize> {
    point: [i64; K],
    /// The best so far: squared distance, voxel, its Morton key.
    best: Option<(u128, [u32; K], u64)>,
}

impl<const K: usize> Visitor<K> for Search<K> {
    const LEAVES: bool = false;

    #[inline]
    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        if node.state() == NodeState::Empty {
            return Walk::Skip;
        }
        let cell = node.cell();
        let side = cell.side();
        // The voxel of the cell nearest the point, and its squared distance: the cell's lower bound.
        let mut near = [0u32; K];
        let mut bound = 0u128;
        for a in 0..K {
            let (lo, p) = (i64::from(cell.origin[a]), self.point[a]);
            let c = p.clamp(lo, lo + side as i64 - 1);
            near[a] = c as u32;
            // Exact for coordinates within ±2^61; saturating beyond.
            let gap = u128::from(c.abs_diff(p));
            bound = bound.saturating_add(gap.saturating_mul(gap));
        }
        if let Some((best, _, key)) = self.best {
            if bound > best || (bound == best && cell.morton() >= key) {
                return Walk::Skip;
            }
        }
        if node.state() == NodeState::Partial {
            return Walk::Descend;
        }
        // A full leaf: its nearest voxel is unique; it beats the best (checked above, its key being at
        // least the cell's).
        let key = morton_encode(near);
        match self.best {
            Some((best, _, k)) if (bound, key) >= (best, k) => Walk::Skip,
            _ => {
                self.best = Some((bound, near, key));
                if bound == 0 {
                    Walk::Stop
                } else {
                    Walk::Skip
                }
            }
        }
    }

    #[inline]
    fn child_order(&self, node: &NodeRef<K>) -> ChildOrder {
        let cell = node.cell();
        let half = cell.side() / 2;
        let mask = (0..K).fold(0, |m, a| {
            m | usize::from(self.point[a] >= i64::from(cell.origin[a]) + half as i64) << a
        });
        ChildOrder::xor::<K>(mask)
    }
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
    let mut search = Search { point, best: None };
    try_walk(tree, &mut search)?;
    Ok(search
        .best
        .map(|(squared, voxel, _)| Nearest { voxel, squared }))
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
