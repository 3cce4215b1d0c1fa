//! Values at points, in a batch, on any valued storage (a tree in memory or a valued file read in place).
//!
//! A large batch first tabulates the tree over the box its points span (`box_table`, 2^15 cells: each an
//! empty or full leaf, or the node to descend from), so that a point's answer is one look-up in the table
//! and a descent of the few levels below it (10^6 points spread over OctoMap's real scan at 0.1 m answered
//! in 0.037 s, against 0.114 s from a table of the universe's top levels). The table is kept small enough
//! to stay in the processor's cache: with 2^18 cells (2 MB for K = 3) its random look-ups missed, and 10^7
//! points took 1.2 times as long. The descents run sixteen side by side, a level of each in turn: their
//! reads do not wait on one another, so the processor overlaps their cache misses, where a lone descent
//! waits for each level's read before the next (sorting the points into Morton order instead, so that
//! neighbours share reads, cost more than it saved on random points). The points are answered in chunks on
//! all threads.

use rayon::prelude::*;

use super::box_table::{BoxTable, TABLE_FROM};
use crate::tree::cursor::Walk;
use crate::tree::valued::{try_walk_values, ValueNode, ValueState, ValueStorage, ValueVisitor};

/// Cells of the table of a batch's box, as a power of two.
const TOP_CELLS_LOG2: u32 = 15;

/// Points a task answers.
const CHUNK: usize = 1 << 14;

/// Descents run side by side.
const LANES: usize = 16;

/// A cell of the table: a leaf's value (`Leaf(None)`: empty) or the node of the table's depth to descend
/// from (its index in its level).
#[derive(Clone, Copy)]
enum Top<V> {
    Leaf(Option<V>),
    Node(u32),
}

impl<V> Top<V> {
    /// The entry of node `index` in state `state`.
    fn of(state: ValueState<V>, index: usize) -> Self {
        match state {
            ValueState::Empty => Top::Leaf(None),
            ValueState::Full(v) => Top::Leaf(Some(v)),
            ValueState::Partial | ValueState::Mixed => Top::Node(index as u32),
        }
    }
}

/// The value of every voxel of `points` (`None` where empty or outside the universe), in order.
///
/// ```
/// use ktree::query::values_at;
/// use ktree::KTree;
/// let t = KTree::<2, u8>::from_dense_values(1, &[Some(4), None, Some(4), Some(9)]).unwrap();
/// assert_eq!(values_at(&t, &[[0, 0], [1, 0], [1, 1], [5, 5]]), Ok(vec![Some(4), None, Some(9), None]));
/// ```
///
/// # Errors
/// The storage's first read error.
pub fn values_at<const K: usize, T>(
    tree: &T,
    points: &[[u32; K]],
) -> Result<Vec<Option<T::Value>>, T::Error>
where
    T: ValueStorage<K> + Sync,
    T::Error: Send,
{
    let mut out = vec![None; points.len()];
    values_at_into(tree, points, &mut out)?;
    Ok(out)
}

/// [`values_at`] written into `out` (one entry a point), so that a caller answering batch after batch
/// keeps one buffer (a fresh one of 10^7 entries costs its pages' first writes, about a tenth of the
/// answers' time).
///
/// ```
/// use ktree::query::values_at_into;
/// use ktree::KTree;
/// let t = KTree::<1, u8>::from_dense_values(1, &[Some(4), None]).unwrap();
/// let mut out = [Some(0); 3];
/// values_at_into(&t, &[[1], [0], [2]], &mut out).unwrap();
/// assert_eq!(out, [None, Some(4), None]);
/// ```
///
/// # Errors
/// The storage's first read error (`out` then partly written).
///
/// # Panics
/// If `out` and `points` differ in length.
pub fn values_at_into<const K: usize, T>(
    tree: &T,
    points: &[[u32; K]],
    out: &mut [Option<T::Value>],
) -> Result<(), T::Error>
where
    T: ValueStorage<K> + Sync,
    T::Error: Send,
{
    assert_eq!(
        points.len(),
        out.len(),
        "values_at_into: one entry of the output a point"
    );
    let level = tree.level();
    let table = TopTable::new(tree, points)?;
    points
        .par_chunks(CHUNK)
        .zip(out.par_chunks_mut(CHUNK))
        .try_for_each(|(points, out)| {
            let mut lanes = Lanes::new(tree);
            for (i, &point) in points.iter().enumerate() {
                // Outside the universe (a coordinate with a bit at or above the level): empty.
                if point.iter().fold(0, |or, &c| or | c) >> level != 0 {
                    out[i] = None;
                    continue;
                }
                match table.cell(point) {
                    (Top::Leaf(v), _) => out[i] = v,
                    (Top::Node(index), depth) => lanes.push(
                        Lane {
                            point,
                            depth: depth as usize,
                            index: index as usize,
                            slot: i as u32,
                        },
                        out,
                    )?,
                }
            }
            lanes.descend(out)
        })
}

/// A descent under way: the point, the node of level `depth` holding it (one with children) and where
/// its answer goes.
#[derive(Clone, Copy)]
struct Lane<const K: usize> {
    point: [u32; K],
    depth: usize,
    index: usize,
    slot: u32,
}

/// Up to [`LANES`] descents under way in `tree`.
struct Lanes<'a, const K: usize, T> {
    tree: &'a T,
    lanes: [Lane<K>; LANES],
    len: usize,
}

impl<'a, const K: usize, T: ValueStorage<K>> Lanes<'a, K, T> {
    fn new(tree: &'a T) -> Self {
        let idle = Lane {
            point: [0; K],
            depth: 0,
            index: 0,
            slot: 0,
        };
        Self {
            tree,
            lanes: [idle; LANES],
            len: 0,
        }
    }

    /// Adds a descent; with [`LANES`] under way, runs them all to their leaves first.
    #[inline]
    fn push(&mut self, lane: Lane<K>, out: &mut [Option<T::Value>]) -> Result<(), T::Error> {
        if self.len == LANES {
            self.descend(out)?;
        }
        self.lanes[self.len] = lane;
        self.len += 1;
        Ok(())
    }

    /// Runs every descent to its leaf and writes the leaf's value (`None`: empty) to its slot of `out`.
    fn descend(&mut self, out: &mut [Option<T::Value>]) -> Result<(), T::Error> {
        let level = self.tree.level() as usize;
        let mut codes = [0u32; LANES];
        // The full leaves met: their values are read together at the end, side by side too.
        let mut full = [(0usize, 0usize, 0u32); LANES];
        let mut fulls = 0;
        while self.len > 0 {
            // One level of every descent, with no branch on what is read.
            for (lane, code) in self.lanes[..self.len].iter_mut().zip(&mut codes) {
                let log_side = (level - lane.depth - 1) as u32;
                let child = (0..K).fold(0, |c, a| {
                    c | ((lane.point[a] >> log_side & 1) as usize) << a
                });
                let first = self.tree.children(lane.depth, lane.index)?;
                lane.depth += 1;
                lane.index = first + child;
                *code = (self.tree.codes(lane.depth, first)? >> (2 * child)) & 3;
            }
            // The descents at a leaf answer; the others go on.
            let mut kept = 0;
            for (j, &code) in codes[..self.len].iter().enumerate() {
                let lane = self.lanes[j];
                match code {
                    0 => out[lane.slot as usize] = None,
                    1 => {
                        full[fulls] = (lane.depth, lane.index, lane.slot);
                        fulls += 1;
                    }
                    _ => {
                        self.lanes[kept] = lane;
                        kept += 1;
                    }
                }
            }
            self.len = kept;
        }
        for &(depth, index, slot) in &full[..fulls] {
            out[slot as usize] = Some(self.tree.value(depth, index)?);
        }
        Ok(())
    }
}

/// The table of a batch's box ([`BoxTable`]) with the root's entry, for the points outside the box.
struct TopTable<const K: usize, V> {
    cells: BoxTable<K, Top<V>>,
    root: Top<V>,
}

impl<const K: usize, V: Copy> TopTable<K, V> {
    /// The table for `points`: the root alone for a batch smaller than [`TABLE_FROM`] points.
    fn new<T: ValueStorage<K, Value = V>>(tree: &T, points: &[[u32; K]]) -> Result<Self, T::Error> {
        let level = tree.level();
        let empty = Top::Leaf(None);
        let mut cells = if points.len() < TABLE_FROM {
            BoxTable::root(level, empty)
        } else {
            BoxTable::spanning(level, points, |p| Some(*p), TOP_CELLS_LOG2, empty)
        };
        struct Fill<'a, const K: usize, V>(&'a mut BoxTable<K, Top<V>>);
        impl<const K: usize, V: Copy> ValueVisitor<K, V> for Fill<'_, K, V> {
            fn visit(&mut self, node: &ValueNode<K, V>) -> Walk {
                let entry = Top::of(node.state, node.index);
                if matches!(entry, Top::Node(_)) && node.cell.level < self.0.depth {
                    return if self.0.overlaps(&node.cell) {
                        Walk::Descend
                    } else {
                        Walk::Skip
                    };
                }
                self.0.set(&node.cell, entry);
                Walk::Skip
            }
        }
        try_walk_values(tree, &mut Fill(&mut cells))?;
        let root = Top::of(tree.root()?.state, 0);
        Ok(Self { cells, root })
    }

    /// The entry of the cell holding `point` (a voxel of the universe) and the depth of its node; the
    /// root's for a point outside the box.
    #[inline]
    fn cell(&self, point: [u32; K]) -> (Top<V>, u32) {
        match self.cells.get(point) {
            Some(entry) => (entry, self.cells.depth),
            None => (self.root, 0),
        }
    }
}

/// The first voxel holding a value that each ray meets, with its value (`None`: the ray meets none), on
/// all threads, in the order given: the rays are cast on the tree's shape ([`crate::KTree::shape`], made once for
/// the batch) as [`cast_rays`](super::cast_rays) casts them, and each hit voxel's value is read.
///
/// ```
/// use ktree::query::{first_values, RayCast};
/// use ktree::KTree;
/// // A bintree row: empty, 3, 3, 8.
/// let t = KTree::<1, u8>::from_dense_values(2, &[None, Some(3), Some(3), Some(8)]).unwrap();
/// let rays = [RayCast::new([0.5], [1.0], f64::INFINITY).unwrap(), RayCast::new([3.9], [-1.0], 0.5).unwrap()];
/// let hits = first_values(&t, &rays);
/// assert_eq!(hits[0].map(|(h, v)| (h.voxel, v)), Some(([1], 3)));
/// assert_eq!(hits[1].map(|(h, v)| (h.voxel, v)), Some(([3], 8)));
/// ```
pub fn first_values<const K: usize, V: crate::value::Value>(
    tree: &crate::KTree<K, V>,
    rays: &[super::RayCast<K>],
) -> Vec<Option<(super::RayHit<K>, V)>> {
    let shape = tree.shape();
    let hits = crate::tree::storage::infallible(super::cast_rays(&shape, rays));
    hits.into_iter()
        .map(|hit| {
            hit.map(|h| {
                let value = tree
                    .value_at(h.voxel)
                    .expect("a voxel of the shape holds a value");
                (h, value)
            })
        })
        .collect()
}
