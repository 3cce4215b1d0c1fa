//! Values at points, in a batch, on any valued storage (a tree in memory or a valued file read in place).
//!
//! A large batch first tabulates the tree's top levels (about 2^18 cells: each an empty or full leaf, or
//! the node to descend from), so that a point's answer is one look-up in the table and a descent of the
//! few levels below it; the points are answered in chunks on all threads, each chunk in Morton order.

use rayon::prelude::*;

use crate::radix::sort_by_key;
use crate::space::morton_encode;
use crate::tree::cursor::Walk;
use crate::tree::valued::{try_walk_values, ValueNode, ValueState, ValueStorage, ValueVisitor};

/// Cells of the table of top levels, as a power of two.
const TOP_CELLS_LOG2: u32 = 18;

/// Batches from this many points are answered through the table.
const TOP_FROM: usize = 1 << 16;

/// Points a task answers.
const CHUNK: usize = 1 << 14;

/// A cell of the table: a leaf's value (`Leaf(None)`: empty) or the node of the table's depth to descend
/// from.
#[derive(Clone, Copy)]
enum Top<V> {
    Leaf(Option<V>),
    Node(usize),
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
    let side = 1u64 << level;
    let depth = if points.len() >= TOP_FROM {
        (TOP_CELLS_LOG2 / K as u32).min(level)
    } else {
        0
    };
    let table = top_table(tree, depth)?;
    let shift = K as u32 * (level - depth);
    let mut out = vec![None; points.len()];
    points
        .par_chunks(CHUNK)
        .zip(out.par_chunks_mut(CHUNK))
        .try_for_each(|(points, out)| {
            // In Morton order, so that neighbouring points read neighbouring cells of the table and
            // parts of the levels.
            let mut order: Vec<(u64, u32)> = Vec::with_capacity(points.len());
            for (i, p) in points.iter().enumerate() {
                if p.iter().all(|&c| u64::from(c) < side) {
                    order.push((morton_encode(*p), i as u32));
                }
            }
            sort_by_key(&mut order, K as u32 * level, &mut Vec::new(), |p| p.0);
            for (key, i) in order {
                out[i as usize] = match table[(key >> shift) as usize] {
                    Top::Leaf(v) => v,
                    Top::Node(index) => descend(tree, points[i as usize], depth as usize, index)?,
                };
            }
            Ok(())
        })?;
    Ok(out)
}

/// The value at `point` found from node `index` of level `depth`, a node with children whose cell holds
/// the point.
#[inline]
fn descend<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    point: [u32; K],
    mut depth: usize,
    mut index: usize,
) -> Result<Option<T::Value>, T::Error> {
    let level = tree.level() as usize;
    loop {
        let log_side = (level - depth - 1) as u32;
        let code = (0..K).fold(0, |c, a| c | ((point[a] >> log_side & 1) as usize) << a);
        let first = tree.children(depth, index)?;
        depth += 1;
        index = first + code;
        let codes = tree.codes(depth, first)?;
        match tree.decode(depth, index, codes >> (2 * code))? {
            ValueState::Empty => return Ok(None),
            ValueState::Full(v) => return Ok(Some(v)),
            ValueState::Partial | ValueState::Mixed => {}
        }
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
                ValueState::Partial | ValueState::Mixed => Top::Node(node.index),
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
