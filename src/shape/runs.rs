//! Runs with signed coordinates, not clipped to a universe: the working form of the morphology, so that an
//! intermediate result (a dilation before an erosion) may reach past the universe's faces.
use crate::rays::RaySet;
use crate::space::Universe;

/// Sorted columns (lexicographic, the first `K − 1` coordinates; the last is 0), each with sorted,
/// disjoint, non-touching half-open runs `[z1, z2)`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Runs<const K: usize> {
    pub(crate) cols: Vec<[i64; K]>,
    pub(crate) runs: Vec<(i64, i64)>,
}

impl<const K: usize> Runs<K> {
    pub(crate) fn from_rays(set: &RaySet<K>) -> Self {
        let level = set.level();
        let cols = set
            .column_keys()
            .iter()
            .map(|&k| RaySet::<K>::column_of_key_at(level, k).map(i64::from))
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
        for (c, &(z1, z2)) in self.cols.iter().zip(&self.runs) {
            if c[..K - 1].iter().any(|&x| x < 0 || x >= side) {
                continue;
            }
            let (z1, z2) = (z1.max(0), z2.min(side));
            if z1 >= z2 {
                continue;
            }
            let key = c[..K - 1]
                .iter()
                .fold(0u64, |key, &x| (key << level) | x as u64);
            columns.push(key);
            runs.push((z1 as u32, z2 as u32));
        }
        RaySet::from_sorted_parts(universe, columns, runs, None)
    }

    /// The runs moved by the column offset `by` and grown by `grow` at both ends (shrunk if negative), read
    /// on the fly by [`Runs::combine_into`]; a column offset keeps the columns' order.
    pub(crate) fn moved(&self, by: [i64; K], grow: i64) -> Moved<'_, K> {
        Moved {
            runs: self,
            by,
            grow,
        }
    }

    /// Appends a run at the end, merging it with the last run of the same column if they overlap or touch.
    fn push(&mut self, col: [i64; K], z1: i64, z2: i64) {
        if let (Some(last_col), Some(last)) = (self.cols.last(), self.runs.last_mut()) {
            if *last_col == col && z1 <= last.1 {
                last.1 = last.1.max(z2);
                return;
            }
        }
        self.cols.push(col);
        self.runs.push((z1, z2));
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
    by: [i64; K],
    grow: i64,
}

impl<const K: usize> Moved<'_, K> {
    /// Column `col` of the runs, moved.
    fn column(&self, mut col: [i64; K]) -> [i64; K] {
        for (x, d) in col[..K - 1].iter_mut().zip(&self.by[..K - 1]) {
            *x += d;
        }
        col
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
