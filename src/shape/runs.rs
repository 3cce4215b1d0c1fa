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

    /// The runs moved by the column offset `c` and grown by `grow` at both ends (shrunk if negative); a
    /// column offset keeps the columns' order.
    pub(crate) fn shifted(&self, c: [i64; K], grow: i64) -> Self {
        let mut out = Self::default();
        for (col, &(z1, z2)) in self.cols.iter().zip(&self.runs) {
            let (z1, z2) = (z1 - grow, z2 + grow);
            if z1 >= z2 {
                continue;
            }
            let mut col2 = *col;
            for (x, d) in col2[..K - 1].iter_mut().zip(&c[..K - 1]) {
                *x += d;
            }
            out.push(col2, z1, z2);
        }
        out
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

    /// The union (`union = true`) or intersection of two run sets, in one merge pass.
    pub(crate) fn combine(&self, other: &Self, union: bool) -> Self {
        let mut out = Self::default();
        let (mut i, mut j) = (0, 0);
        while i < self.runs.len() || j < other.runs.len() {
            let ci = self.cols.get(i);
            let cj = other.cols.get(j);
            let col = match (ci, cj) {
                (Some(a), Some(b)) => *a.min(b),
                (Some(a), None) => *a,
                (None, Some(b)) => *b,
                (None, None) => unreachable!(),
            };
            let i_end = i + self.cols[i..].iter().take_while(|c| **c == col).count();
            let j_end = j + other.cols[j..].iter().take_while(|c| **c == col).count();
            let (a, b) = (&self.runs[i..i_end], &other.runs[j..j_end]);
            if union {
                // Merge by z1; `push` joins overlaps.
                let (mut p, mut q) = (0, 0);
                while p < a.len() || q < b.len() {
                    let take_a = q >= b.len() || (p < a.len() && a[p].0 <= b[q].0);
                    let r = if take_a { a[p] } else { b[q] };
                    if take_a {
                        p += 1;
                    } else {
                        q += 1;
                    }
                    out.push(col, r.0, r.1);
                }
            } else {
                let (mut p, mut q) = (0, 0);
                while p < a.len() && q < b.len() {
                    let (lo, hi) = (a[p].0.max(b[q].0), a[p].1.min(b[q].1));
                    if lo < hi {
                        out.cols.push(col);
                        out.runs.push((lo, hi));
                    }
                    if a[p].1 < b[q].1 {
                        p += 1;
                    } else {
                        q += 1;
                    }
                }
            }
            i = i_end;
            j = j_end;
        }
        out
    }
}
