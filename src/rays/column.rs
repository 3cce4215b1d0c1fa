//! Column keys: the `K − 1` coordinates of a column (a line along the last axis) packed into one `u64`, so
//! that a list of runs keeps one key per run and sorts by column with integer comparisons.
//!
//! [`ColumnKeys`] packs the columns of a universe of level `L`: `L` bits a coordinate, axis 0 most
//! significant, `(key << L) | c` axis after axis. [`SignedColumnKeys`] is its twin for columns that may lie
//! outside the universe on either side (the working space of the morphology): a wider field a coordinate,
//! biased by half the field. Both sort as the columns do lexicographically (axis 0 first), which every
//! sort and merge of runs relies on.
//!
//! ```
//! use ktree::rays::{ColumnKeys, SignedColumnKeys};
//! let keys = ColumnKeys::<3>::new(4);
//! let key = keys.pack([5, 9, 0]);
//! assert_eq!(key, 5 << 4 | 9);
//! assert_eq!(keys.unpack(key), [5, 9, 0]);
//! assert_eq!(keys.axis(key, 1), 9);
//! assert!(keys.pack([5, 10, 0]) > key && keys.pack([6, 0, 0]) > keys.pack([5, 15, 0]));
//! assert_eq!(keys.moved(key, [-5, 6, 0]), Some(keys.pack([0, 15, 0])));
//! assert_eq!(keys.moved(key, [0, 7, 0]), None); // y = 16 leaves the universe
//!
//! let signed = SignedColumnKeys::<3>::pack([-3, 7, 0]);
//! assert_eq!(SignedColumnKeys::<3>::unpack(signed), [-3, 7, 0]);
//! assert!(SignedColumnKeys::<3>::pack([-2, -100, 0]) > signed);
//! // Moving every key by one column offset is one wrapping addition.
//! let by = SignedColumnKeys::<3>::offset([10, -10, 0]);
//! assert_eq!(signed.wrapping_add(by), SignedColumnKeys::<3>::pack([7, -3, 0]));
//! ```

use std::ops::Range;

/// How the `K − 1` column coordinates of a voxel pack into one key in a universe of level `L`: `L` bits a
/// coordinate, axis 0 most significant (the last coordinate, along the runs, is not part of the key).
/// Keys compare as the columns do lexicographically; the keys of the columns whose axis-0 coordinate lies
/// in `x0..x1` are the range [`ColumnKeys::slab`]. For `K = 1` there is one column, key 0.
///
/// The key of a [`RaySet`](super::RaySet)'s runs, of the builder's slabs and of every list of runs the
/// crate gathers from a tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ColumnKeys<const K: usize> {
    level: u32,
}

impl<const K: usize> ColumnKeys<K> {
    /// The keys of a universe of level `level` (at most [`max_level`](crate::max_level)`(K)`, so that the
    /// `K − 1` fields fit 64 bits).
    #[inline]
    pub const fn new(level: u32) -> Self {
        Self { level }
    }

    /// The universe level `L`: the bits of each field.
    #[inline]
    pub const fn level(self) -> u32 {
        self.level
    }

    /// The shift of axis `axis`'s field (`axis < K − 1`).
    #[inline]
    fn shift(self, axis: usize) -> u32 {
        (K - 2 - axis) as u32 * self.level
    }

    /// The key of the column through `point` (its last coordinate is ignored). Each coordinate must be
    /// below the universe's side.
    #[inline]
    pub fn pack(self, point: [u32; K]) -> u64 {
        point[..K - 1]
            .iter()
            .fold(0u64, |key, &c| (key << self.level) | u64::from(c))
    }

    /// The column of `key`, with its last coordinate 0: the inverse of [`ColumnKeys::pack`].
    #[inline]
    pub fn unpack(self, key: u64) -> [u32; K] {
        let mut point = [0u32; K];
        for (axis, c) in point[..K - 1].iter_mut().enumerate() {
            *c = self.axis(key, axis);
        }
        point
    }

    /// Coordinate `axis` (`< K − 1`) of the column of `key`.
    #[inline]
    pub fn axis(self, key: u64, axis: usize) -> u32 {
        let mask = (1u64 << self.level) - 1;
        ((key >> self.shift(axis)) & mask) as u32
    }

    /// The keys of the columns whose axis-0 coordinate lies in `x` (for `K = 1`, the one column's key when
    /// `x` holds 0): a range, as keys sort by axis 0 first. The runs of a sorted list in that slab are the
    /// ones whose keys fall in it.
    #[inline]
    pub fn slab(self, x: Range<u32>) -> Range<u64> {
        if K == 1 {
            return u64::from(x.start > 0)..u64::from(x.end > 0);
        }
        let shift = self.shift(0);
        u64::from(x.start) << shift..u64::from(x.end) << shift
    }

    /// The key of the column `key` moved by `by` (its last coordinate ignored), or `None` when the moved
    /// column leaves the universe.
    #[inline]
    pub fn moved(self, key: u64, by: [i64; K]) -> Option<u64> {
        let side = 1i64 << self.level;
        let mut out = 0u64;
        for (axis, &d) in by[..K - 1].iter().enumerate() {
            let c = i64::from(self.axis(key, axis)).checked_add(d)?;
            if !(0..side).contains(&c) {
                return None;
            }
            out = (out << self.level) | c as u64;
        }
        Some(out)
    }
}

/// The twin of [`ColumnKeys`] for columns with signed coordinates, not bounded by a universe: each of the
/// `K − 1` coordinates biased by half its field, in a field of `64 / (K − 1)` bits (32 for `K = 3`, 21 for
/// `K = 4`), axis 0 most significant. Keys sort as the columns do lexicographically, and while no field
/// overflows, packing is linear: a column moved by `by` has the key moved by [`SignedColumnKeys::offset`]
/// (a wrapping addition), which keeps the keys' order.
///
/// The fields hold every coordinate below `2^(field − 1)` in size: for the morphology, whose intermediate
/// results reach past the universe by a few sides, that is every coordinate up to `2^(L + 4)` at the
/// largest level `L` of each `K`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SignedColumnKeys<const K: usize>;

impl<const K: usize> SignedColumnKeys<K> {
    /// Bits of each field.
    const BITS: u32 = if K <= 1 { 0 } else { 64 / (K as u32 - 1) };

    /// The key of the column through `point` (its last coordinate is ignored).
    #[inline]
    pub fn pack(point: [i64; K]) -> u64 {
        let w = Self::BITS;
        point[..K - 1].iter().fold(0u128, |key, &x| {
            let field = (x as i128 + (1i128 << (w - 1))) as u128 & ((1u128 << w) - 1);
            (key << w) | field
        }) as u64
    }

    /// Coordinate `axis` (`< K − 1`) of the column of `key`.
    #[inline]
    pub fn axis(key: u64, axis: usize) -> i64 {
        let w = Self::BITS;
        let shift = w * (K as u32 - 2 - axis as u32);
        let field = (u128::from(key) >> shift) & ((1u128 << w) - 1);
        (field as i128 - (1i128 << (w - 1))) as i64
    }

    /// The column of `key`, with its last coordinate 0: the inverse of [`SignedColumnKeys::pack`].
    #[inline]
    pub fn unpack(key: u64) -> [i64; K] {
        let mut point = [0i64; K];
        for (axis, c) in point[..K - 1].iter_mut().enumerate() {
            *c = Self::axis(key, axis);
        }
        point
    }

    /// What moving a column by `by` adds (wrapping) to its key: the key of `by` less the origin's.
    #[inline]
    pub fn offset(by: [i64; K]) -> u64 {
        Self::pack(by).wrapping_sub(Self::pack([0; K]))
    }

    /// The signed key of the column `key` of `keys`' universe.
    #[inline]
    pub fn of_unsigned(keys: ColumnKeys<K>, key: u64) -> u64 {
        Self::pack(keys.unpack(key).map(i64::from))
    }

    /// The key in `keys`' universe of the column of the signed `key`, or `None` outside the universe.
    #[inline]
    pub fn to_unsigned(keys: ColumnKeys<K>, key: u64) -> Option<u64> {
        let side = 1i64 << keys.level();
        let mut out = 0u64;
        for axis in 0..K - 1 {
            let x = Self::axis(key, axis);
            if !(0..side).contains(&x) {
                return None;
            }
            out = (out << keys.level()) | x as u64;
        }
        Some(out)
    }
}

/// The columns of two lists of runs side by side: for each column key of either list, in order, the key
/// and the index ranges of its runs in each (empty where a list has none). The second list's keys are
/// read moved by `moved_by` (added wrapping, as a [`SignedColumnKeys::offset`]; 0 leaves them as they
/// are), which must keep them sorted. Both key lists are sorted (non-decreasing), a key per run.
///
/// ```
/// use ktree::rays::join_columns;
/// let joined: Vec<_> = join_columns(&[1, 1, 4], &[0, 4, 4], 0).collect();
/// assert_eq!(joined, [(0, 0..0, 0..1), (1, 0..2, 1..1), (4, 2..3, 1..3)]);
/// ```
pub fn join_columns<'a>(first: &'a [u64], second: &'a [u64], moved_by: u64) -> ColumnJoin<'a> {
    ColumnJoin {
        first,
        second,
        moved_by,
        at: (0, 0),
    }
}

/// The iterator of [`join_columns`].
#[derive(Debug, Clone)]
pub struct ColumnJoin<'a> {
    first: &'a [u64],
    second: &'a [u64],
    moved_by: u64,
    at: (usize, usize),
}

impl Iterator for ColumnJoin<'_> {
    type Item = (u64, Range<usize>, Range<usize>);

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        let (i, j) = self.at;
        let by = self.moved_by;
        let a = self.first.get(i).copied();
        let b = self.second.get(j).map(|&k| k.wrapping_add(by));
        let key = match (a, b) {
            (None, None) => return None,
            (Some(x), None) => x,
            (None, Some(y)) => y,
            (Some(x), Some(y)) => x.min(y),
        };
        let mut i_end = i;
        while i_end < self.first.len() && self.first[i_end] == key {
            i_end += 1;
        }
        let mut j_end = j;
        while j_end < self.second.len() && self.second[j_end].wrapping_add(by) == key {
            j_end += 1;
        }
        self.at = (i_end, j_end);
        Some((key, i..i_end, j..j_end))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn k1_has_one_column() {
        let keys = ColumnKeys::<1>::new(31);
        assert_eq!(keys.pack([77]), 0);
        assert_eq!(keys.unpack(0), [0]);
        assert_eq!(keys.moved(0, [5]), Some(0));
        assert_eq!(keys.slab(0..1), 0..1);
        assert_eq!(SignedColumnKeys::<1>::pack([-4]), 0);
        assert_eq!(SignedColumnKeys::<1>::to_unsigned(keys, 0), Some(0));
    }

    #[test]
    fn slabs_hold_their_columns_keys() {
        let keys = ColumnKeys::<3>::new(3);
        let range = keys.slab(2..5);
        for x in 0..8 {
            for y in 0..8 {
                let key = keys.pack([x, y, 0]);
                assert_eq!(range.contains(&key), (2..5).contains(&x), "{x} {y}");
            }
        }
    }
}
