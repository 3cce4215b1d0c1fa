//! Values at points, in a batch, on any valued storage (a tree in memory or a valued file read in place).
//!
//! A large batch first tabulates the tree's top levels (about 2^15 cells: each an empty or full leaf, or
//! the node to descend from), so that a point's answer is one look-up in the table and a descent of the
//! few levels below it. The table is kept small enough to stay in the processor's cache: with 2^18 cells
//! (2 MB for K = 3) its random look-ups missed, and 10^7 points took 1.2 times as long. The descents run sixteen side by side, a level of each in turn: their reads do
//! not wait on one another, so the processor overlaps their cache misses, where a lone descent waits for
//! each level's read before the next (sorting the points into Morton order instead, so that neighbours
//! share reads, cost more than it saved on random points). The points are answered in chunks on all
//! threads.

use rayon::prelude::*;

use crate::space::morton_encode;
use crate::tree::cursor::Walk;
use crate::tree::valued::{try_walk_values, ValueNode, ValueState, ValueStorage, ValueVisitor};

/// Cells of the table of top levels, as a power of two.
const TOP_CELLS_LOG2: u32 = 15;

/// Batches from this many points are answered through the table.
const TOP_FROM: usize = 1 << 16;

/// Points a task answers.
const CHUNK: usize = 1 << 14;

/// Descents run side by side.
const LANES: usize = 16;

/// A cell of the table: a leaf's value (`Leaf(None)`: empty) or the node of the table's depth to descend
/// from (below `2^(K · depth) ≤ 2^TOP_CELLS_LOG2`).
#[derive(Clone, Copy)]
enum Top<V> {
    Leaf(Option<V>),
    Node(u32),
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
    let level = tree.level();
    let depth = if points.len() >= TOP_FROM {
        (TOP_CELLS_LOG2 / K as u32).min(level)
    } else {
        0
    };
    let table = top_table(tree, depth)?;
    let below = level - depth;
    let mut out = vec![None; points.len()];
    points
        .par_chunks(CHUNK)
        .zip(out.par_chunks_mut(CHUNK))
        .try_for_each(|(points, out)| {
            let mut lanes = Lanes::new(tree);
            for (i, &point) in points.iter().enumerate() {
                // Outside the universe (a coordinate with a bit at or above the level): empty.
                if point.iter().fold(0, |or, &c| or | c) >> level != 0 {
                    continue;
                }
                match table[morton_encode(point.map(|c| c >> below)) as usize] {
                    Top::Leaf(v) => out[i] = v,
                    Top::Node(index) => lanes.push(
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
        })?;
    Ok(out)
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

/// The table of the cells of level `depth`, in Morton order.
fn top_table<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    depth: u32,
) -> Result<Vec<Top<T::Value>>, T::Error> {
    struct Fill<V> {
        depth: u32,
        shift: u32,
        cells: Vec<Top<V>>,
    }
    impl<const K: usize, V: Copy> ValueVisitor<K, V> for Fill<V> {
        fn visit(&mut self, node: &ValueNode<K, V>) -> Walk {
            let entry = match node.state {
                ValueState::Empty => Top::Leaf(None),
                ValueState::Full(v) => Top::Leaf(Some(v)),
                ValueState::Partial | ValueState::Mixed if node.cell.level < self.depth => {
                    return Walk::Descend
                }
                ValueState::Partial | ValueState::Mixed => Top::Node(node.index as u32),
            };
            // A node's cells are a contiguous range in Morton order.
            let first = (morton_encode(node.cell.origin) >> self.shift) as usize;
            let count = 1usize << (K as u32 * (self.depth - node.cell.level));
            self.cells[first..first + count].fill(entry);
            Walk::Skip
        }
    }
    let mut fill = Fill {
        depth,
        shift: K as u32 * (tree.level() - depth),
        cells: vec![Top::Leaf(None); 1 << (K as u32 * depth)],
    };
    try_walk_values(tree, &mut fill)?;
    Ok(fill.cells)
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
