//! Splitting a [`RaySet`] by cell: the rays of an aligned cell are its columns' runs clipped to the cell's
//! range along the last axis, in the cell's own universe.

use std::ops::Range;

use super::{ColumnKeys, RaySet};
use crate::space::{Cell, Universe};

impl<const K: usize> RaySet<K> {
    /// The rays of one aligned cell, in the cell's own universe (level `L − cell.level`, coordinates
    /// relative to the cell's origin): the runs of the cell's columns clipped to its range along the last
    /// axis. Stacking them gives the subtree of the cell.
    ///
    /// ```
    /// use ktree::{Ray, RaySet, Universe};
    /// let rays = RaySet::<2>::from_rays(3, [Ray::new([5, 1], 7), Ray::new([1, 2], 3)]).unwrap();
    /// let cell = Universe::<2>::new(3).unwrap().cell([4, 4], 1).unwrap();
    /// let inner = rays.cell_rays(cell);
    /// assert_eq!(inner.level(), 2);
    /// assert_eq!(inner.iter().collect::<Vec<_>>(), [Ray::new([1, 0], 3)]);
    /// ```
    pub fn cell_rays(&self, cell: Cell<K>) -> RaySet<K> {
        let local = Universe::<K>::new(cell.log_side).expect("a cell's level is a valid level");
        let side = cell.side() as u32;
        let (z_lo, z_hi) = (cell.origin[K - 1], cell.origin[K - 1] + side);
        let slab = if K == 1 {
            0..self.len()
        } else {
            self.slab_range(cell.origin[0]..cell.origin[0] + side)
        };
        let (keys, local_keys) = (self.keys(), ColumnKeys::<K>::new(cell.log_side));
        let mut columns = Vec::new();
        let mut runs = Vec::new();
        for i in slab {
            let key = self.column_keys()[i];
            let (z1, z2) = self.runs()[i];
            if z2 <= z_lo || z1 >= z_hi {
                continue;
            }
            let column = keys.unpack(key);
            if (0..K - 1).all(|a| column[a].wrapping_sub(cell.origin[a]) < side) {
                let local = std::array::from_fn(|a| column[a].wrapping_sub(cell.origin[a]));
                columns.push(local_keys.pack(local));
                runs.push((z1.max(z_lo) - z_lo, z2.min(z_hi) - z_lo));
            }
        }
        RaySet::from_sorted_parts(local, columns, runs, None)
    }

    /// The index range of the runs whose column's axis-0 coordinate lies in `x` (for `K ≥ 2`; for `K = 1`
    /// every run, as there is one column).
    pub fn slab_range(&self, x: Range<u32>) -> Range<usize> {
        if K == 1 {
            return 0..self.len();
        }
        let range = self.keys().slab(x);
        let keys = self.column_keys();
        keys.partition_point(|&k| k < range.start)..keys.partition_point(|&k| k < range.end)
    }
}

#[cfg(test)]
mod tests {
    use crate::{Ray, RaySet, Universe};

    #[test]
    fn cell_rays_of_the_root_are_the_set() {
        let rays =
            RaySet::<3>::from_rays(3, [Ray::new([1, 2, 3], 8), Ray::new([7, 0, 0], 1)]).unwrap();
        let root = Universe::<3>::new(3).unwrap().root();
        assert_eq!(rays.cell_rays(root), rays);
    }

    #[test]
    fn runs_are_clipped_to_the_cell() {
        let rays = RaySet::<1>::from_rays(3, [Ray::new([1], 7)]).unwrap();
        let u = Universe::<1>::new(3).unwrap();
        let upper = rays.cell_rays(u.cell([4], 1).unwrap());
        assert_eq!(upper.runs(), [(0, 3)]);
        let lower = rays.cell_rays(u.cell([0], 1).unwrap());
        assert_eq!(lower.runs(), [(1, 4)]);
    }
}
