//! Maximal rows of a run: the leaves of the 1-D reduced tree (bintree) of one column.

/// An aligned row along the ray axis: `2^log_len` voxels starting at `z`, with `z` a multiple of the length.
/// At universe level `L` a row of length `2^s` is a node at tree level `L − s`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Row {
    /// First voxel along the ray axis.
    pub z: u32,
    /// log2 of the length.
    pub log_len: u32,
}

impl Row {
    /// The length in voxels.
    pub fn len(&self) -> u64 {
        1u64 << self.log_len
    }

    /// Rows are never empty; provided for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// One past the last voxel.
    pub fn end(&self) -> u64 {
        u64::from(self.z) + self.len()
    }
}

/// The maximal rows of the half-open run `[z1, z2)`, in increasing `z`: each row is the longest aligned
/// row that starts where the previous one ended and stays inside the run. No two of them can be put together
/// into a longer aligned row, so they are the full leaves of the run's reduced bintree.
///
/// A run has at most `2·log2(z2 − z1)` maximal rows: lengths first grow, then shrink.
///
/// # Example (Akman & Franklin, Fig. 3)
/// ```
/// use ktree::rays::maximal_rows;
/// let rows: Vec<(u32, u64)> = maximal_rows(17, 93).map(|r| (r.z, r.len())).collect();
/// assert_eq!(rows, [(17, 1), (18, 2), (20, 4), (24, 8), (32, 32), (64, 16), (80, 8), (88, 4), (92, 1)]);
/// ```
pub fn maximal_rows(z1: u32, z2: u32) -> MaximalRows {
    MaximalRows {
        z: u64::from(z1),
        end: u64::from(z2),
    }
}

/// Iterator returned by [`maximal_rows`].
#[derive(Debug, Clone)]
pub struct MaximalRows {
    z: u64,
    end: u64,
}

impl Iterator for MaximalRows {
    type Item = Row;

    #[inline]
    fn next(&mut self) -> Option<Row> {
        if self.z >= self.end {
            return None;
        }
        // Longest length allowed by alignment (trailing zeros of z) and by what is left of the run.
        let by_alignment = if self.z == 0 {
            u32::MAX
        } else {
            self.z.trailing_zeros()
        };
        let by_room = 63 - (self.end - self.z).leading_zeros();
        let log_len = by_alignment.min(by_room);
        let row = Row {
            z: self.z as u32,
            log_len,
        };
        self.z += 1u64 << log_len;
        Some(row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fig3_ray_splits_into_the_papers_nine_rows() {
        // AF1: the ray (x=1, y=1, z1=17, z2=93) covers 17..=92.
        let mut rows: Vec<(u32, u64)> = maximal_rows(17, 93).map(|r| (r.z, r.len())).collect();
        rows.sort();
        let paper = [
            (17, 1),
            (18, 2),
            (20, 4),
            (24, 8),
            (32, 32),
            (64, 16),
            (80, 8),
            (88, 4),
            (92, 1),
        ];
        assert_eq!(rows, paper);
        let covered: u64 = rows.iter().map(|r| r.1).sum();
        assert_eq!(covered, 93 - 17);
    }

    #[test]
    fn rows_tile_the_run_and_are_maximal() {
        for z1 in 0..70u32 {
            for z2 in z1 + 1..=72 {
                let rows: Vec<Row> = maximal_rows(z1, z2).collect();
                let mut z = u64::from(z1);
                for r in &rows {
                    assert_eq!(u64::from(r.z), z);
                    assert_eq!(u64::from(r.z) % r.len(), 0, "aligned");
                    z = r.end();
                }
                assert_eq!(z, u64::from(z2));
                // Maximal: no two neighbours form an aligned row of twice the length.
                for w in rows.windows(2) {
                    let merged =
                        w[0].log_len == w[1].log_len && u64::from(w[0].z) % (2 * w[0].len()) == 0;
                    assert!(!merged, "rows {w:?} of [{z1},{z2}) could be merged");
                }
            }
        }
    }

    #[test]
    fn whole_universe_is_one_row() {
        let rows: Vec<Row> = maximal_rows(0, 1 << 31).collect();
        assert_eq!(rows, [Row { z: 0, log_len: 31 }]);
    }
}
