//! A table over the cells of one level of a tree, those that the box of a batch of points overlaps: the
//! first step of a batch point query. A point in a cell that is a leaf is answered by one read; only a
//! point in a cell with children descends, from the cell's node.
//!
//! The cells are the smallest aligned cells of which the box needs no more than a given number (sized to
//! stay in the processor's cache). Points gathered in a small part of a large universe (a map's scan in
//! OctoMap's universe of 2^16 voxels a side) thus start a few levels above the voxels; points spread over
//! the universe start from its top levels. The box is that of an evenly spaced sample of the points (at
//! most 2^16), not of every point: a pass over a batch of 10^7 points cost a third of the answers' time. A
//! point outside the box is not in the table ([`BoxTable::get`] gives `None`) and is answered from the root.
//!
//! ```text
//! level 0 ─ root
//!   …         (a walk of the nodes that overlap the box, down to the table's level)
//! level d ─ │cell│cell│cell│…   one entry a cell of the box, axis 0 fastest
//!   …         (a descent from the cell's node, for a point whose cell has children)
//! ```

use crate::space::Cell;

/// Batches of at least this many points first build a table of their box (its cost, a walk of the nodes
/// above its cells and a fill of its cells, is then a small share of the batch).
pub(crate) const TABLE_FROM: usize = 1 << 16;

/// The points sampled to find a batch's box, at most.
const SAMPLE_LOG2: u32 = 16;

/// Entries of type `E` for the cells of level `depth` that a box overlaps.
pub(crate) struct BoxTable<const K: usize, E> {
    /// The cells' depth in the tree.
    pub(crate) depth: u32,
    /// log2 of a cell's side: `level − depth`.
    log_side: u32,
    /// The box's first and last cell along each axis (in cells).
    first: [u32; K],
    last: [u32; K],
    /// The box's cells along each axis.
    sides: [u32; K],
    /// The entries between neighbouring cells along each axis.
    strides: [usize; K],
    cells: Vec<E>,
}

impl<const K: usize, E: Copy> BoxTable<K, E> {
    /// The table of the box of a sample of `points` (their voxels, from `voxel`; `None` or a voxel
    /// outside the universe of `level` ignored), of at most `2^cells_log2` cells, each `entry` until set.
    pub(crate) fn spanning<P>(
        level: u32,
        points: &[P],
        voxel: impl Fn(&P) -> Option<[u32; K]>,
        cells_log2: u32,
        entry: E,
    ) -> Self {
        let (mut lo, mut hi) = ([u32::MAX; K], [0u32; K]);
        let step = (points.len() >> SAMPLE_LOG2).max(1);
        for v in points.iter().step_by(step).filter_map(voxel) {
            if v.iter().all(|&c| u64::from(c) >> level == 0) {
                for a in 0..K {
                    lo[a] = lo[a].min(v[a]);
                    hi[a] = hi[a].max(v[a]);
                }
            }
        }
        if lo[0] > hi[0] {
            return Self::root(level, entry);
        }
        let cells_for = |log_side: u32| -> u64 {
            (0..K)
                .map(|a| u64::from((hi[a] >> log_side) - (lo[a] >> log_side)) + 1)
                .product()
        };
        let log_side = (0..=level)
            .find(|&s| cells_for(s) <= 1 << cells_log2)
            .unwrap_or(level);
        Self::of_box(level, log_side, lo, hi, entry)
    }

    /// The table of one cell, the root.
    pub(crate) fn root(level: u32, entry: E) -> Self {
        Self::of_box(level, level, [0; K], [0; K], entry)
    }

    /// The table of the cells of side `2^log_side` from the one holding voxel `lo` to the one holding `hi`.
    fn of_box(level: u32, log_side: u32, lo: [u32; K], hi: [u32; K], entry: E) -> Self {
        let first = lo.map(|c| c >> log_side);
        let last = hi.map(|c| c >> log_side);
        let sides: [u32; K] = std::array::from_fn(|a| last[a] - first[a] + 1);
        let mut strides = [0; K];
        let mut count = 1;
        for a in 0..K {
            strides[a] = count;
            count *= sides[a] as usize;
        }
        Self {
            depth: level - log_side,
            log_side,
            first,
            last,
            sides,
            strides,
            cells: vec![entry; count],
        }
    }

    /// Sets the cells of the box that `cell` (a node's cell, no deeper than the table's level) overlaps to
    /// `entry`. Returns `false`, setting nothing, when it overlaps none (a walk then skips the node).
    pub(crate) fn set(&mut self, cell: &Cell<K>, entry: E) -> bool {
        let Some((from, to)) = self.overlap(cell) else {
            return false;
        };
        let mut at = from;
        loop {
            let start = self.index_of(at);
            let run = (to[0] - from[0]) as usize + 1;
            self.cells[start..start + run].fill(entry);
            // The next row: axes 1.. counted like an odometer.
            let mut a = 1;
            loop {
                if a == K {
                    return true;
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

    /// Whether `cell` (no deeper than the table's level) overlaps the box.
    pub(crate) fn overlaps(&self, cell: &Cell<K>) -> bool {
        self.overlap(cell).is_some()
    }

    /// The first and last cells of the box that `cell` overlaps (in cells), if any.
    fn overlap(&self, cell: &Cell<K>) -> Option<([u32; K], [u32; K])> {
        let cells = 1u64 << (cell.log_side - self.log_side);
        let (mut from, mut to) = ([0u32; K], [0u32; K]);
        for a in 0..K {
            let start = u64::from(cell.origin[a] >> self.log_side);
            let end = start + cells - 1;
            if end < u64::from(self.first[a]) || start > u64::from(self.last[a]) {
                return None;
            }
            from[a] = (start as u32).max(self.first[a]);
            to[a] = end.min(u64::from(self.last[a])) as u32;
        }
        Some((from, to))
    }

    /// The entry of the cell `at` (in cells, inside the box).
    #[inline]
    fn index_of(&self, at: [u32; K]) -> usize {
        (0..K)
            .map(|a| (at[a] - self.first[a]) as usize * self.strides[a])
            .sum()
    }

    /// The entry of the cell holding voxel `point` (of the universe), `None` outside the box.
    #[inline]
    pub(crate) fn get(&self, point: [u32; K]) -> Option<E> {
        let mut index = 0;
        let mut inside = true;
        for (a, &c) in point.iter().enumerate() {
            let at = (c >> self.log_side).wrapping_sub(self.first[a]);
            inside &= at < self.sides[a];
            index += at as usize * self.strides[a];
        }
        inside.then(|| self.cells[index])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::{contains, contains_many, contains_many_signed, values_at, values_at_into};
    use crate::space::Universe;
    use crate::testing::Lcg;
    use crate::KTree;
    use proptest::prelude::*;

    /// Every voxel of `universe` in dense order, empty (`None`) or a number 0…2, in blocks of 4 and of 2
    /// voxels a side, so that a tree of them has leaves of all sizes.
    fn blocks_of_values<const K: usize>(universe: Universe<K>, seed: u64) -> Vec<Option<u8>> {
        (0..universe.voxels() as usize)
            .map(|i| {
                let p = universe.dense_point(i);
                let block = p
                    .iter()
                    .fold(seed, |h, &c| h.wrapping_mul(31) ^ u64::from(c >> 2));
                let fine = p
                    .iter()
                    .fold(seed, |h, &c| h.wrapping_mul(17) ^ u64::from(c >> 1));
                (block % 3 != 0).then_some((fine.wrapping_mul(0x9E37_79B9) >> 7) as u8 % 3)
            })
            .collect()
    }

    /// Twice as many points as are sampled for a table's box, inside the box with corners `corners`
    /// (taken modulo `side`) of a universe of `side` voxels, except at the places 7, 9 and 501 of each
    /// thousand: outside the universe, outside it below 0 (as signed points), and anywhere in it — the
    /// places are odd, so none of them is in the sample.
    fn points_in_a_box<const K: usize>(
        lcg: &mut Lcg,
        side: u32,
        corners: [[u32; K]; 2],
    ) -> Vec<[i64; K]> {
        let [c, d] = corners.map(|corner| corner.map(|v| v % side));
        let lo: [u32; K] = std::array::from_fn(|a| c[a].min(d[a]));
        let hi: [u32; K] = std::array::from_fn(|a| c[a].max(d[a]));
        (0..(2usize << SAMPLE_LOG2) + 1000)
            .map(|i| match i % 1000 {
                7 => [i64::from(side) + (i as i64 % 3); K],
                9 => std::array::from_fn(|a| if a == i % K { -1 } else { 0 }),
                501 => std::array::from_fn(|_| lcg.below(u64::from(side)) as i64),
                _ => std::array::from_fn(|a| {
                    i64::from(lo[a]) + lcg.below(u64::from(hi[a] - lo[a] + 1)) as i64
                }),
            })
            .collect()
    }

    /// A large batch of points inside a box, and some elsewhere, is answered as the tree answers each
    /// point, whatever the box's size and place (the table's cells are then of any size, from a voxel to
    /// the root): its values ([`values_at`], into a buffer too) and, by the tree's shape, whether each is
    /// inside ([`contains_many`], [`contains_many_signed`]).
    fn batch_in_a_box_is_point_by_point<const K: usize>(
        level: u32,
        corners: [[u32; K]; 2],
        seed: u64,
    ) -> Result<(), TestCaseError> {
        let u = Universe::<K>::new(level).unwrap();
        let tree = KTree::<K, u8>::from_dense_values(level, &blocks_of_values(u, seed)).unwrap();
        let signed = points_in_a_box(&mut Lcg(seed), u.side() as u32, corners);
        let points: Vec<[u32; K]> = signed
            .iter()
            .map(|p| p.map(|c| u32::try_from(c).unwrap_or(u32::MAX)))
            .collect();
        let got = values_at(&tree, &points).unwrap();
        for (g, p) in got.iter().zip(&points) {
            prop_assert_eq!(*g, tree.value_at(*p), "at {:?}", p);
        }
        // Into a buffer holding other values: every entry written.
        let mut buffer = vec![Some(7); points.len()];
        values_at_into(&tree, &points, &mut buffer).unwrap();
        prop_assert_eq!(buffer, got);
        let shape = tree.shape();
        let inside: Vec<bool> = points
            .iter()
            .map(|&p| contains(&shape, p).unwrap())
            .collect();
        prop_assert_eq!(contains_many(&shape, &points).unwrap(), inside.clone());
        prop_assert_eq!(contains_many_signed(&shape, &signed).unwrap(), inside);
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

    #[test]
    fn the_cells_are_the_smallest_of_which_the_box_needs_no_more_than_asked() {
        let u = Universe::<2>::new(10).unwrap();
        // A box of 100 × 20 voxels: 2^10 cells allowed gives cells of 2 voxels a side.
        let points = [[300u32, 500], [399, 519]];
        let table = BoxTable::spanning(10, &points, |p| Some(*p), 10, 0u8);
        assert_eq!((table.log_side, table.depth), (1, 9));
        assert_eq!(table.cells.len(), 50 * 10);
        // Every cell a node of depth 9 overlaps, and none other.
        let mut table = table;
        assert!(table.set(&u.cell([300, 500], 9).unwrap(), 1));
        assert_eq!(table.get([301, 501]), Some(1));
        assert_eq!(table.get([302, 501]), Some(0));
        assert!(!table.set(&u.cell([298, 500], 9).unwrap(), 2));
        assert!(!table.overlaps(&u.cell([512, 0], 1).unwrap()));
        // A node of depth 1 (512 voxels a side) covers the box's cells it holds.
        assert!(table.set(&u.cell([0, 512], 1).unwrap(), 3));
        assert_eq!(table.get([399, 519]), Some(3));
        assert_eq!(table.get([399, 511]), Some(0));
        // Outside the box: not in the table.
        assert_eq!(table.get([298, 500]), None);
        assert_eq!(table.get([400, 500]), None);
        assert_eq!(table.get([350, 520]), None);
    }

    #[test]
    fn no_point_inside_the_universe_gives_the_root_alone() {
        let table = BoxTable::<3, u8>::spanning(4, &[[16u32, 0, 0]], |p| Some(*p), 15, 0);
        assert_eq!((table.depth, table.cells.len()), (0, 1));
        assert_eq!(table.get([15, 15, 15]), Some(0));
        let table = BoxTable::<1, u8>::spanning(4, &[None, None], |p: &Option<[u32; 1]>| *p, 15, 0);
        assert_eq!(table.depth, 0);
    }
}
