//! The surface area: the number of `(K − 1)`-faces between a full voxel and an empty one.
use crate::KTree;

impl<const K: usize> KTree<K> {
    /// The number of `(K − 1)`-faces between a full voxel and an empty one, outside the universe counting
    /// as empty: the perimeter for `K = 2`, the count of boundary squares for `K = 3`.
    ///
    /// ```
    /// use ktree::KTree;
    /// assert_eq!(KTree::<2>::full(2).unwrap().surface_area(), 16);
    /// assert_eq!(KTree::<3>::full(1).unwrap().surface_area(), 24);
    /// ```
    ///
    /// # Performance
    /// `2K·N − 2·(adjacent pairs)`, the pairs counted on the runs: along the last axis from the run
    /// lengths, along each other axis by one merge of each column with its neighbour. `O(runs · K)`.
    pub fn surface_area(&self) -> u128 {
        let rays = self.to_rays();
        let keys = rays.column_keys();
        let runs = rays.runs();
        let n = rays.voxel_count();
        // Along the last axis: the voxels of a run minus one per run.
        let mut adjacent = n - runs.len() as u128;
        let side = rays.universe().side() as u32;
        for (key, range) in rays.column_groups() {
            let col = rays.column_of_key(key);
            for axis in 0..K - 1 {
                if col[axis] + 1 >= side {
                    continue;
                }
                let mut other = col;
                other[axis] += 1;
                let okey = rays.column_key(other);
                let lo = keys.partition_point(|&k| k < okey);
                let hi = keys.partition_point(|&k| k <= okey);
                let (mut p, mut q) = (range.start, lo);
                while p < range.end && q < hi {
                    let (a, b) = (runs[p], runs[q]);
                    let overlap = a.1.min(b.1).saturating_sub(a.0.max(b.0));
                    adjacent += u128::from(overlap);
                    if a.1 < b.1 {
                        p += 1;
                    } else {
                        q += 1;
                    }
                }
            }
        }
        2 * K as u128 * n - 2 * adjacent
    }
}
