//! Runs with signed coordinates, not clipped to a universe: the working form of the morphology, so that an
//! intermediate result (a dilation before an erosion) may reach past the universe's faces.
//!
//! A column (the first `K − 1` coordinates) is kept as one signed key ([`SignedColumnKeys`]), which sorts
//! as the columns do and moves by one constant for a column offset. Its fields hold every coordinate the
//! morphology reaches: the universe's side plus twice the largest radius a closing accepts (four sides),
//! that is below `2^(L + 4)` — at most 2^25 for K = 3 (fields of 32 bits) and 2^20 for K = 4 (21 bits;
//! `L ≤ 16`).
use crate::rays::{join_columns, merge_runs, RaySet, SignedColumnKeys, TruthTable};
use crate::space::Universe;

/// The signed column keys of the morphology.
type Keys<const K: usize> = SignedColumnKeys<K>;

/// The line of the runs (they are never complemented, so its ends are never reached).
const LINE: std::ops::Range<i64> = i64::MIN..i64::MAX;

/// Sorted columns (packed keys, see the module's docs), each with sorted, disjoint, non-touching half-open
/// runs `[z1, z2)`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Runs<const K: usize> {
    cols: Vec<u64>,
    runs: Vec<(i64, i64)>,
}

impl<const K: usize> Runs<K> {
    pub(crate) fn from_rays(set: &RaySet<K>) -> Self {
        let keys = set.keys();
        let cols = set
            .column_keys()
            .iter()
            .map(|&k| Keys::<K>::of_unsigned(keys, k))
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
        let keys = crate::rays::ColumnKeys::<K>::new(universe.level());
        let side = universe.side() as i64;
        let mut columns = Vec::new();
        let mut runs = Vec::new();
        for (&c, &(z1, z2)) in self.cols.iter().zip(&self.runs) {
            let (z1, z2) = (z1.max(0), z2.min(side));
            if z1 >= z2 {
                continue;
            }
            if let Some(key) = Keys::<K>::to_unsigned(keys, c) {
                columns.push(key);
                runs.push((z1 as u32, z2 as u32));
            }
        }
        RaySet::from_sorted_parts(universe, columns, runs, None)
    }

    /// The runs moved by the column offset `by` and grown by `grow` at both ends (shrunk if negative), read
    /// on the fly by [`Runs::combine_into`]; a column offset keeps the columns' order.
    pub(crate) fn moved(&self, by: [i64; K], grow: i64) -> Moved<'_, K> {
        Moved {
            runs: self,
            by: Keys::<K>::offset(by),
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
                let mut end = *j;
                while end < self.cols.len() && copy.column(self.cols[end]) == col {
                    end += 1;
                }
                next.clear();
                merge_runs(
                    acc.iter().copied(),
                    copy.runs_of(*j..end),
                    TruthTable::INTERSECTION,
                    LINE,
                    |z1, z2, _, _| next.push((z1, z2)),
                );
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

    /// Sets `out` to the union (`union = true`) or intersection of `self` and `other`, in one merge pass
    /// ([`merge_runs`] column by column). `out`'s buffers are reused, so a chain of combinations allocates
    /// only while the runs grow.
    pub(crate) fn combine_into(&self, other: Moved<'_, K>, union: bool, out: &mut Self) {
        out.clear();
        let table = if union {
            TruthTable::UNION
        } else {
            TruthTable::INTERSECTION
        };
        for (col, ra, rb) in join_columns(&self.cols, &other.runs.cols, other.by) {
            if !union && (ra.is_empty() || rb.is_empty()) {
                continue;
            }
            // Growing may make a column's runs overlap, which a union takes; shrinking may empty some
            // (dropped).
            merge_runs(
                self.runs[ra].iter().copied(),
                other.runs_of(rb),
                table,
                LINE,
                |z1, z2, _, _| {
                    out.cols.push(col);
                    out.runs.push((z1, z2));
                },
            );
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

    /// The runs `range` (of one column), grown (shrunk ones that vanish dropped).
    fn runs_of(
        &self,
        range: std::ops::Range<usize>,
    ) -> impl Iterator<Item = (i64, i64)> + Clone + '_ {
        let grow = self.grow;
        self.runs.runs[range]
            .iter()
            .map(move |&(z1, z2)| (z1 - grow, z2 + grow))
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
        for a in &cols {
            let key = Keys::<K>::pack(*a);
            for (axis, &x) in a[..K - 1].iter().enumerate() {
                assert_eq!(Keys::<K>::axis(key, axis), x);
            }
            assert_eq!(Keys::<K>::unpack(key), *a);
            for b in &cols {
                assert_eq!(
                    key.cmp(&Keys::<K>::pack(*b)),
                    a.cmp(b),
                    "{a:?} against {b:?}"
                );
                let sum: [i64; K] = std::array::from_fn(|i| a[i] + b[i]);
                if sum.iter().all(|x| x.abs() <= reach) {
                    assert_eq!(
                        key.wrapping_add(Keys::<K>::offset(*b)),
                        Keys::<K>::pack(sum),
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
