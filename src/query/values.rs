//! Values at points, in a batch, on any valued storage (a tree in memory or a valued file read in place).
//!
//! A large batch first tabulates the tree over the box its points span (about 2^15 cells: each an empty
//! or full leaf, or the node to descend from), so that a point's answer is one look-up in the table and a
//! descent of the few levels below it. The table's cells are the smallest aligned cells of which the box
//! needs no more than that: points gathered in a small part of a large universe (a map's scan in
//! OctoMap's universe of 2^16 voxels a side) descend from a few levels above the voxels, not from the
//! universe's top levels (10^6 points spread over OctoMap's real scan at 0.1 m answered in 0.037 s,
//! against 0.114 s from a table of the universe's top levels). The table is kept small enough to stay in
//! the processor's cache: with 2^18 cells (2 MB for K = 3) its random look-ups missed, and 10^7 points
//! took 1.2 times as long. The descents run sixteen side by side, a level of each in turn: their reads do
//! not wait on one another, so the processor overlaps their cache misses, where a lone descent waits for
//! each level's read before the next (sorting the points into Morton order instead, so that neighbours
//! share reads, cost more than it saved on random points). The points are answered in chunks on all
//! threads.

use rayon::prelude::*;

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
/// from (its index in its level).
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

/// The cells of level `depth` that a batch's box of points overlaps, each an entry of `cells`, axis 0
/// varying fastest.
struct TopTable<const K: usize, V> {
    depth: u32,
    /// log2 of a cell's side: `level − depth`.
    log_side: u32,
    /// The box's first cell along each axis (in cells).
    first: [u32; K],
    /// The box's cells along each axis.
    sides: [u32; K],
    /// The entries between neighbouring cells along each axis.
    strides: [usize; K],
    cells: Vec<Top<V>>,
    /// The root's entry (a node of depth 0), for points outside the box.
    root: Top<V>,
}

impl<const K: usize, V: Copy> TopTable<K, V> {
    /// The table for `points` (those outside the universe ignored): a single cell, the root, for a batch
    /// smaller than [`TOP_FROM`] points.
    fn new<T: ValueStorage<K, Value = V>>(tree: &T, points: &[[u32; K]]) -> Result<Self, T::Error> {
        let level = tree.level();
        // The box of a sample of the points (at most 2^16 of them, evenly spaced): a pass over all of
        // them would read the whole batch once more. A point outside it descends from the root.
        let (mut lo, mut hi) = ([u32::MAX; K], [0u32; K]);
        for point in points.iter().step_by((points.len() >> 16).max(1)) {
            if point.iter().fold(0, |or, &c| or | c) >> level == 0 {
                for a in 0..K {
                    lo[a] = lo[a].min(point[a]);
                    hi[a] = hi[a].max(point[a]);
                }
            }
        }
        let small = lo[0] > hi[0] || points.len() < TOP_FROM;
        if small {
            (lo, hi) = ([0; K], [0; K]);
        }
        // The smallest cells of which the box needs at most 2^TOP_CELLS_LOG2.
        let cells_for = |log_side: u32| -> u64 {
            (0..K)
                .map(|a| u64::from((hi[a] >> log_side) - (lo[a] >> log_side)) + 1)
                .product()
        };
        let log_side = if small {
            level
        } else {
            (0..=level)
                .find(|&s| cells_for(s) <= 1 << TOP_CELLS_LOG2)
                .unwrap_or(level)
        };
        let first = lo.map(|c| c >> log_side);
        let sides: [u32; K] = std::array::from_fn(|a| (hi[a] >> log_side) - first[a] + 1);
        let mut strides = [0; K];
        let mut count = 1;
        for a in 0..K {
            strides[a] = count;
            count *= sides[a] as usize;
        }
        let root = match tree.root()?.state {
            ValueState::Empty => Top::Leaf(None),
            ValueState::Full(v) => Top::Leaf(Some(v)),
            ValueState::Partial | ValueState::Mixed => Top::Node(0),
        };
        let mut table = Self {
            depth: level - log_side,
            log_side,
            first,
            sides,
            strides,
            cells: vec![Top::Leaf(None); count],
            root,
        };
        let last = hi.map(|c| c >> log_side);
        table.fill(tree, last)?;
        Ok(table)
    }

    /// Writes every cell's entry, walking the nodes that overlap the box (cells `first ..= last`).
    fn fill<T: ValueStorage<K, Value = V>>(
        &mut self,
        tree: &T,
        last: [u32; K],
    ) -> Result<(), T::Error> {
        struct Fill<'a, const K: usize, V> {
            table: &'a mut TopTable<K, V>,
            last: [u32; K],
        }
        impl<const K: usize, V: Copy> ValueVisitor<K, V> for Fill<'_, K, V> {
            fn visit(&mut self, node: &ValueNode<K, V>) -> Walk {
                let table = &mut *self.table;
                // The node's cells of the table's level (it is no deeper), clipped to the box.
                let cells = 1u64 << (node.cell.log_side - table.log_side);
                let (mut from, mut to) = ([0u32; K], [0u32; K]);
                for a in 0..K {
                    let start = u64::from(node.cell.origin[a] >> table.log_side);
                    let end = start + cells - 1;
                    if end < u64::from(table.first[a]) || start > u64::from(self.last[a]) {
                        return Walk::Skip;
                    }
                    from[a] = (start as u32).max(table.first[a]);
                    to[a] = (end.min(u64::from(self.last[a]))) as u32;
                }
                let entry = match node.state {
                    ValueState::Empty => Top::Leaf(None),
                    ValueState::Full(v) => Top::Leaf(Some(v)),
                    ValueState::Partial | ValueState::Mixed if node.cell.level < table.depth => {
                        return Walk::Descend
                    }
                    ValueState::Partial | ValueState::Mixed => Top::Node(node.index as u32),
                };
                table.fill_range(from, to, entry);
                Walk::Skip
            }
        }
        try_walk_values(tree, &mut Fill { table: self, last })?;
        Ok(())
    }

    /// Sets the cells `from ..= to` (in cells, inside the box) to `entry`.
    fn fill_range(&mut self, from: [u32; K], to: [u32; K], entry: Top<V>) {
        let mut at = from;
        loop {
            let start = self.index_of(at);
            let run = (to[0] - from[0]) as usize + 1;
            self.cells[start..start + run].fill(entry);
            // The next row: axes 1.. counted like an odometer.
            let mut a = 1;
            loop {
                if a == K {
                    return;
                }
                if at[a] < to[a] {
                    at[a] += 1;
                    break;
                }
                at[a] = from[a];
                a += 1;
            }
        }
    }

    /// The entry of the cell `at` (in cells, inside the box).
    #[inline]
    fn index_of(&self, at: [u32; K]) -> usize {
        (0..K)
            .map(|a| (at[a] - self.first[a]) as usize * self.strides[a])
            .sum()
    }

    /// The entry of the cell holding `point` (a voxel of the universe) and the depth of its node; the
    /// root's for a point outside the box.
    #[inline]
    fn cell(&self, point: [u32; K]) -> (Top<V>, u32) {
        let mut index = 0;
        let mut inside = true;
        for (a, &c) in point.iter().enumerate() {
            let at = (c >> self.log_side).wrapping_sub(self.first[a]);
            inside &= at < self.sides[a];
            index += at as usize * self.strides[a];
        }
        if inside {
            (self.cells[index], self.depth)
        } else {
            (self.root, 0)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::Universe;
    use crate::KTree;
    use proptest::prelude::*;

    /// A large batch of points inside the box `lo ..= hi` (and a few outside the universe) is answered as
    /// the tree answers each point, whatever the box's size and place (the table's cells are then of any
    /// size, from a voxel to the root).
    fn batch_in_a_box_is_point_by_point<const K: usize>(
        level: u32,
        corners: [[u32; K]; 2],
        seed: u64,
    ) -> Result<(), TestCaseError> {
        let u = Universe::<K>::new(level).unwrap();
        let mut lcg = crate::testing::Lcg(seed);
        // Values in blocks of 2 and 4 voxels a side, some empty, so that the tree has leaves of all sizes.
        let dense: Vec<Option<u8>> = (0..u.voxels() as usize)
            .map(|i| {
                let p = u.dense_point(i);
                let block = p
                    .iter()
                    .fold(seed, |h, &c| h.wrapping_mul(31) ^ u64::from(c >> 2));
                let fine = p
                    .iter()
                    .fold(seed, |h, &c| h.wrapping_mul(17) ^ u64::from(c >> 1));
                (block % 3 != 0).then_some((fine.wrapping_mul(0x9E37_79B9) >> 7) as u8 % 3)
            })
            .collect();
        let tree = KTree::<K, u8>::from_dense_values(level, &dense).unwrap();
        let side = u.side() as u32;
        let [c, d] = corners.map(|corner| corner.map(|v| v % side));
        let lo: [u32; K] = std::array::from_fn(|a| c[a].min(d[a]));
        let hi: [u32; K] = std::array::from_fn(|a| c[a].max(d[a]));
        // Twice the sampled count, so that the points at odd places (some anywhere in the universe) are
        // not in the sample the table's box is made from.
        let points: Vec<[u32; K]> = (0..2 * TOP_FROM + 1000)
            .map(|i| {
                if i % 1000 == 7 {
                    return [side + (i as u32 % 3); K];
                }
                if i % 1000 == 501 {
                    return std::array::from_fn(|_| lcg.below(u64::from(side)) as u32);
                }
                std::array::from_fn(|a: usize| {
                    lo[a] + lcg.below(u64::from(hi[a] - lo[a] + 1)) as u32
                })
            })
            .collect();
        let got = values_at(&tree, &points).unwrap();
        for (g, p) in got.iter().zip(&points) {
            prop_assert_eq!(*g, tree.value_at(*p), "at {:?}", p);
        }
        // Into a buffer holding other values: every entry written.
        let mut buffer = vec![Some(7); points.len()];
        values_at_into(&tree, &points, &mut buffer).unwrap();
        prop_assert_eq!(buffer, got);
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        #[test]
        fn batch_in_a_box_is_point_by_point_k1(a in any::<[u32; 1]>(), b in any::<[u32; 1]>(), seed in any::<u64>()) {
            batch_in_a_box_is_point_by_point::<1>(20, [a, b], seed)?;
        }

        #[test]
        fn batch_in_a_box_is_point_by_point_k2(a in any::<[u32; 2]>(), b in any::<[u32; 2]>(), seed in any::<u64>()) {
            batch_in_a_box_is_point_by_point::<2>(9, [a, b], seed)?;
        }

        #[test]
        fn batch_in_a_box_is_point_by_point_k3(a in any::<[u32; 3]>(), b in any::<[u32; 3]>(), seed in any::<u64>()) {
            batch_in_a_box_is_point_by_point::<3>(6, [a, b], seed)?;
        }

        #[test]
        fn batch_in_a_box_is_point_by_point_k4(a in any::<[u32; 4]>(), b in any::<[u32; 4]>(), seed in any::<u64>()) {
            batch_in_a_box_is_point_by_point::<4>(4, [a, b], seed)?;
        }
    }
}
