//! Runs with signed coordinates, not clipped to a universe: the working form of the morphology, so that an
//! intermediate result (a dilation before an erosion) may reach past the universe's faces.
//!
//! A column (the first `K − 1` coordinates) is kept as one packed key: each coordinate biased by half its
//! field, in a field of `64 / (K − 1)` bits, the first coordinate highest, so that keys sort as the
//! columns do lexicographically and a column offset moves every key by one constant. The fields hold
//! every coordinate the morphology reaches: the universe's side plus twice the largest radius a closing
//! accepts (four sides), that is below `2^(L + 4)` — at most 2^25 for K = 3 (fields of 32 bits) and 2^20
//! for K = 4 (21 bits; `L ≤ 16`).
use crate::rays::RaySet;
use crate::space::Universe;

/// Bits of each column coordinate's field in a packed key.
const fn field_bits(k: usize) -> u32 {
    if k <= 1 {
        0
    } else {
        64 / (k as u32 - 1)
    }
}

/// Packs the first `K − 1` coordinates of `col` (see the module's docs).
fn pack<const K: usize>(col: &[i64]) -> u64 {
    let w = field_bits(K);
    col[..K - 1].iter().fold(0u128, |key, &x| {
        let field = (x as i128 + (1i128 << (w - 1))) as u128 & ((1u128 << w) - 1);
        (key << w) | field
    }) as u64
}

/// Coordinate `axis` (`< K − 1`) of a packed key.
fn unpack_axis<const K: usize>(key: u64, axis: usize) -> i64 {
    let w = field_bits(K);
    let shift = w * (K as u32 - 2 - axis as u32);
    let field = (u128::from(key) >> shift) & ((1u128 << w) - 1);
    (field as i128 - (1i128 << (w - 1))) as i64
}

/// Sorted columns (packed keys, see the module's docs), each with sorted, disjoint, non-touching half-open
/// runs `[z1, z2)`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Runs<const K: usize> {
    cols: Vec<u64>,
    runs: Vec<(i64, i64)>,
}

impl<const K: usize> Runs<K> {
    pub(crate) fn from_rays(set: &RaySet<K>) -> Self {
        let level = set.level();
        let cols = set
            .column_keys()
            .iter()
            .map(|&k| pack::<K>(&RaySet::<K>::column_of_key_at(level, k).map(i64::from)))
            .collect();
        let runs = set
            .runs()
            .iter()
            .map(|&(a, b)| (i64::from(a), i64::from(b)))
            .collect();
        Self { cols, runs }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Removes every run, keeping the buffers.
    pub(crate) fn clear(&mut self) {
        self.cols.clear();
        self.runs.clear();
    }

    /// The runs clipped to the universe, as a ray set.
    pub(crate) fn to_rays(&self, universe: Universe<K>) -> RaySet<K> {
        let level = universe.level();
        let side = universe.side() as i64;
        let mut columns = Vec::new();
        let mut runs = Vec::new();
        'runs: for (&c, &(z1, z2)) in self.cols.iter().zip(&self.runs) {
            let (z1, z2) = (z1.max(0), z2.min(side));
            if z1 >= z2 {
                continue;
            }
            let mut key = 0u64;
            for axis in 0..K - 1 {
                let x = unpack_axis::<K>(c, axis);
                if x < 0 || x >= side {
                    continue 'runs;
                }
                key = (key << level) | x as u64;
            }
            columns.push(key);
            runs.push((z1 as u32, z2 as u32));
        }
        RaySet::from_sorted_parts(universe, columns, runs, None)
    }

    /// The runs moved by the column offset `by` and grown by `grow` at both ends (shrunk if negative), read
    /// on the fly by [`Runs::combine_into`]; a column offset keeps the columns' order.
    pub(crate) fn moved(&self, by: [i64; K], grow: i64) -> Moved<'_, K> {
        // Packing is linear while no field overflows: the offset's key less the origin's.
        Moved {
            runs: self,
            by: pack::<K>(&by).wrapping_sub(pack::<K>(&[0; K])),
            grow,
        }
    }

    /// Appends a run at the end, merging it with the last run of the same column if they overlap or touch.
    fn push(&mut self, col: u64, z1: i64, z2: i64) {
        if let (Some(last_col), Some(last)) = (self.cols.last(), self.runs.last_mut()) {
            if *last_col == col && z1 <= last.1 {
                last.1 = last.1.max(z2);
                return;
            }
        }
        self.cols.push(col);
        self.runs.push((z1, z2));
    }

    /// Sets `out` to the union of the runs moved and grown by every `(offset, grow)` of `element`, in one
    /// merge pass over all the moved copies at once (for a few offsets: each output column looks at every
    /// copy's next column).
    pub(crate) fn union_of_moved_into(&self, element: &[([i64; K], i64)], out: &mut Self) {
        out.clear();
        let mut gathered = Vec::new();
        let copies: Vec<Moved<'_, K>> = element.iter().map(|&(c, h)| self.moved(c, h)).collect();
        let mut at = vec![0usize; copies.len()];
        loop {
            let mut col = None::<u64>;
            for (copy, &i) in copies.iter().zip(&at) {
                if let Some(&c) = self.cols.get(i) {
                    let c = copy.column(c);
                    col = Some(col.map_or(c, |m| m.min(c)));
                }
            }
            let Some(col) = col else {
                return;
            };
            gathered.clear();
            for (copy, i) in copies.iter().zip(at.iter_mut()) {
                while *i < self.cols.len() && copy.column(self.cols[*i]) == col {
                    let (z1, z2) = self.runs[*i];
                    gathered.push((z1 - copy.grow, z2 + copy.grow));
                    *i += 1;
                }
            }
            gathered.sort_unstable_by_key(|r| r.0);
            for &(z1, z2) in gathered.iter() {
                if z1 < z2 {
                    out.push(col, z1, z2);
                }
            }
        }
    }

    /// Sets `out` to the intersection of the runs moved and shrunk by every `(offset, shrink)` of
    /// `element` (emptied runs dropped), in one pass: the columns of the first copy, each looked up in the
    /// other copies by cursors that only move forward, their runs intersected there.
    pub(crate) fn intersection_of_moved_into(&self, element: &[([i64; K], i64)], out: &mut Self) {
        out.clear();
        let Some((&(c0, h0), rest)) = element.split_first() else {
            return;
        };
        let first = self.moved(c0, -h0);
        let others: Vec<Moved<'_, K>> = rest.iter().map(|&(c, h)| self.moved(c, -h)).collect();
        let mut at = vec![0usize; others.len()];
        let (mut acc, mut next) = (Vec::new(), Vec::new());
        let mut i = 0;
        'columns: while i < self.cols.len() {
            let col = first.column(self.cols[i]);
            let mut end = i;
            acc.clear();
            while end < self.cols.len() && self.cols[end] == self.cols[i] {
                let (z1, z2) = self.runs[end];
                if z1 - first.grow < z2 + first.grow {
                    acc.push((z1 - first.grow, z2 + first.grow));
                }
                end += 1;
            }
            i = end;
            for (copy, j) in others.iter().zip(at.iter_mut()) {
                while *j < self.cols.len() && copy.column(self.cols[*j]) < col {
                    *j += 1;
                }
                let (mut p, mut q) = (0, *j);
                next.clear();
                while p < acc.len() && q < self.cols.len() && copy.column(self.cols[q]) == col {
                    let (z1, z2) = self.runs[q];
                    let b = (z1 - copy.grow, z2 + copy.grow);
                    let (lo, hi) = (acc[p].0.max(b.0), acc[p].1.min(b.1));
                    if lo < hi {
                        next.push((lo, hi));
                    }
                    if acc[p].1 < b.1 {
                        p += 1;
                    } else {
                        q += 1;
                    }
                }
                std::mem::swap(&mut acc, &mut next);
                if acc.is_empty() {
                    continue 'columns;
                }
            }
            for &(z1, z2) in &acc {
                out.cols.push(col);
                out.runs.push((z1, z2));
            }
        }
    }

    /// Sets `out` to the union (`union = true`) or intersection of `self` and `other`, in one merge pass.
    /// `out`'s buffers are reused, so a chain of combinations allocates only while the runs grow.
    pub(crate) fn combine_into(&self, other: Moved<'_, K>, union: bool, out: &mut Self) {
        out.clear();
        let (a_cols, b_cols) = (&self.cols, &other.runs.cols);
        let (mut i, mut j) = (0, 0);
        while i < a_cols.len() || j < b_cols.len() {
            let ci = a_cols.get(i).copied();
            let cj = b_cols.get(j).map(|&c| other.column(c));
            let col = match (ci, cj) {
                (Some(a), Some(b)) => a.min(b),
                (Some(a), None) => a,
                (None, Some(b)) => b,
                (None, None) => unreachable!(),
            };
            let mut i_end = i;
            while i_end < a_cols.len() && a_cols[i_end] == col {
                i_end += 1;
            }
            let mut j_end = j;
            while j_end < b_cols.len() && other.column(b_cols[j_end]) == col {
                j_end += 1;
            }
            let a = &self.runs[i..i_end];
            let b = &other.runs.runs[j..j_end];
            let grown = |&(z1, z2): &(i64, i64)| (z1 - other.grow, z2 + other.grow);
            if union {
                // Merge by z1 (growing keeps the order); `push` joins overlaps.
                let (mut p, mut q) = (0, 0);
                while p < a.len() || q < b.len() {
                    let take_a = q >= b.len() || (p < a.len() && a[p].0 <= grown(&b[q]).0);
                    let r = if take_a { a[p] } else { grown(&b[q]) };
                    if take_a {
                        p += 1;
                    } else {
                        q += 1;
                    }
                    if r.0 < r.1 {
                        out.push(col, r.0, r.1);
                    }
                }
            } else {
                // Shrinking keeps both ends' order; an emptied run meets nothing.
                let (mut p, mut q) = (0, 0);
                while p < a.len() && q < b.len() {
                    let bq = grown(&b[q]);
                    let (lo, hi) = (a[p].0.max(bq.0), a[p].1.min(bq.1));
                    if lo < hi {
                        out.cols.push(col);
                        out.runs.push((lo, hi));
                    }
                    if a[p].1 < bq.1 {
                        p += 1;
                    } else {
                        q += 1;
                    }
                }
            }
            i = i_end;
            j = j_end;
        }
    }
}

/// A run set moved by a column offset and grown at both ends: see [`Runs::moved`].
#[derive(Clone, Copy)]
pub(crate) struct Moved<'a, const K: usize> {
    runs: &'a Runs<K>,
    /// The packed offset, added to a key (wrapping) to move it.
    by: u64,
    grow: i64,
}

impl<const K: usize> Moved<'_, K> {
    /// Column `col` of the runs, moved.
    fn column(&self, col: u64) -> u64 {
        col.wrapping_add(self.by)
    }

    /// Sets `out` to the moved runs (emptied runs dropped).
    pub(crate) fn copy_into(self, out: &mut Runs<K>) {
        out.clear();
        for (&col, &(z1, z2)) in self.runs.cols.iter().zip(&self.runs.runs) {
            let (z1, z2) = (z1 - self.grow, z2 + self.grow);
            if z1 < z2 {
                out.push(self.column(col), z1, z2);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Keys round-trip, sort as their columns and move by a constant over the whole reach of the
    /// morphology (nine sides either way) at the largest level.
    fn keys_hold_the_reach<const K: usize>() {
        let reach = 9 * (1i64 << crate::max_level(K));
        let values = [-reach, -reach / 2 - 3, -1, 0, 1, 5, reach / 3, reach];
        let cols: Vec<[i64; K]> = (0..values.len().pow(K as u32 - 1))
            .map(|mut i| {
                let mut col = [0i64; K];
                for x in col[..K - 1].iter_mut().rev() {
                    *x = values[i % values.len()];
                    i /= values.len();
                }
                col
            })
            .collect();
        let origin = pack::<K>(&[0; K]);
        for a in &cols {
            let key = pack::<K>(a);
            for (axis, &x) in a[..K - 1].iter().enumerate() {
                assert_eq!(unpack_axis::<K>(key, axis), x);
            }
            for b in &cols {
                assert_eq!(key.cmp(&pack::<K>(b)), a.cmp(b), "{a:?} against {b:?}");
                let sum: [i64; K] = std::array::from_fn(|i| a[i] + b[i]);
                if sum.iter().all(|x| x.abs() <= reach) {
                    let by = pack::<K>(b).wrapping_sub(origin);
                    assert_eq!(
                        key.wrapping_add(by),
                        pack::<K>(&sum),
                        "{a:?} moved by {b:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn keys_hold_the_reach_k2_to_k4() {
        keys_hold_the_reach::<2>();
        keys_hold_the_reach::<3>();
        keys_hold_the_reach::<4>();
    }
}
