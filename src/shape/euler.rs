//! The Euler number of the full voxels, as scikit-image's `measure.euler_number(image, connectivity)`.
//!
//! Connectivity 1 (4 in 2-D, 6 in 3-D) counts the cubical complex whose `j`-cells are the blocks of `2^j`
//! full voxels forming a unit `j`-cube; connectivity `K` (8 in 2-D, 26 in 3-D) counts the closed voxels
//! (a grid cell is there when a full voxel touches it). Both are sums over the `2^K` windows around the
//! grid's vertices of a value looked up from the window's pattern (each cell shared by the windows that
//! see it); a window's pattern only changes along the last axis where a run of one of its `2^(K−1)`
//! columns starts or ends, so each stretch of windows is counted at once: `O(runs · 2^(K−1))` windows
//! patterns, never one per voxel.
use super::error::check_connectivity;
use super::input::runs;
use super::ShapeError;
use crate::tree::storage::TreeStorage;
use crate::KTree;

/// [`table`] for each `K` and both complexes, made once.
fn cached_table<const K: usize>(closed: bool) -> &'static [i64] {
    use std::sync::OnceLock;
    static TABLES: [OnceLock<Vec<i64>>; 2 * (crate::MAX_K + 1)] =
        [const { OnceLock::new() }; 2 * (crate::MAX_K + 1)];
    TABLES[2 * K + usize::from(closed)].get_or_init(|| table::<K>(closed))
}

/// `2^K ×` the Euler contribution of each window pattern (bit `Σ b_i 2^i` for the voxel at `v − 1 + b`).
fn table<const K: usize>(closed: bool) -> Vec<i64> {
    let corners = 1usize << K;
    let mut out = vec![0i64; 1 << corners];
    for (pattern, value) in out.iter_mut().enumerate() {
        // Faces of the window cube: free axes `s`, fixed values `f` on the others.
        for s in 0..corners {
            let dim = s.count_ones() as i64;
            for f in 0..corners {
                if f & s != 0 {
                    continue;
                }
                let members = (0..corners).filter(|&b| b & !s == f);
                if closed {
                    // The grid cell of dimension K − dim, seen by 2^(K − dim) windows.
                    if members.clone().any(|b| pattern >> b & 1 == 1) {
                        let j = K as i64 - dim;
                        let sign = if j % 2 == 0 { 1 } else { -1 };
                        *value += sign * (1i64 << (K as i64 - j));
                    }
                } else if members.clone().all(|b| pattern >> b & 1 == 1) {
                    // A block of 2^dim voxels, seen by 2^(K − dim) windows.
                    let sign = if dim % 2 == 0 { 1 } else { -1 };
                    *value += sign * (1i64 << dim);
                }
            }
        }
    }
    out
}

/// The Euler number of the full voxels of `tree` (in memory or a file read in place): objects minus
/// tunnels plus cavities, as scikit-image's `measure.euler_number(image, connectivity)`: connectivity 1
/// or `K` (4 or 8 neighbours in 2-D, 6 or 26 in 3-D), the outside of the universe empty. Defined here for
/// every `K` the same way.
///
/// ```
/// use ktree::{shape::euler_number, KTree, Ray, RaySet};
/// // A 3 × 3 ring: one object, one hole.
/// let rays = RaySet::<2>::from_rays(2, [Ray::new([0, 0], 3), Ray::new([1, 0], 1), Ray::new([1, 2], 3), Ray::new([2, 0], 3)]).unwrap();
/// let ring = KTree::from_rays(&rays);
/// assert_eq!(euler_number(&ring, 1).unwrap(), 0);
/// assert_eq!(euler_number(&ring, 2).unwrap(), 0);
/// ```
///
/// # Performance
/// `O(runs · 2^(K−1))` window patterns over the tree's runs ([`rays_of`](crate::tree::rays_of)), which
/// are held in memory.
///
/// # Errors
/// [`ShapeError::Connectivity`] outside `1..=K`, [`ShapeError::EulerConnectivity`] for a connectivity
/// strictly between 1 and `K` (scikit-image defines none), [`ShapeError::Storage`] for a read error.
pub fn euler_number<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    connectivity: usize,
) -> Result<i64, ShapeError> {
    check_connectivity::<K>(connectivity)?;
    if connectivity != 1 && connectivity != K {
        return Err(ShapeError::EulerConnectivity { connectivity, k: K });
    }
    let rays = runs(tree)?;
    let table = cached_table::<K>(connectivity == K);
    let keys = rays.column_keys();
    let runs = rays.runs();
    let side = rays.universe().side() as i64;
    let columns = 1usize << (K - 1);
    let mut total: i128 = 0;
    let mut column_runs: Vec<&[(u32, u32)]> = Vec::with_capacity(columns);
    let mut breaks: Vec<i64> = Vec::new();
    // Adds the windows at the grid vertices of one corner (first K − 1 coordinates of the vertex v).
    let mut count = |v: [i64; K]| {
        column_runs.clear();
        breaks.clear();
        for b in 0..columns {
            let mut col = [0u32; K];
            let mut inside = true;
            for axis in 0..K - 1 {
                let x = v[axis] - 1 + (b >> axis & 1) as i64;
                inside &= (0..side).contains(&x);
                col[axis] = x.max(0) as u32;
            }
            let slice: &[(u32, u32)] = if inside {
                let key = rays.keys().pack(col);
                let lo = keys.partition_point(|&k| k < key);
                let hi = keys.partition_point(|&k| k <= key);
                &runs[lo..hi]
            } else {
                &[]
            };
            for &(z1, z2) in slice {
                let (z1, z2) = (i64::from(z1), i64::from(z2));
                breaks.extend([z1, z1 + 1, z2, z2 + 1]);
            }
            column_runs.push(slice);
        }
        breaks.sort_unstable();
        breaks.dedup();
        let full = |runs: &[(u32, u32)], z: i64| {
            let i = runs.partition_point(|&(_, z2)| i64::from(z2) <= z);
            i < runs.len() && i64::from(runs[i].0) <= z
        };
        for w in breaks.windows(2) {
            let z = w[0]; // the grid vertex's last coordinate; voxels z − 1 and z
            let mut pattern = 0usize;
            for (b, r) in column_runs.iter().enumerate() {
                if full(r, z - 1) {
                    pattern |= 1 << b;
                }
                if full(r, z) {
                    pattern |= 1 << (b | columns);
                }
            }
            total += i128::from(table[pattern]) * i128::from(w[1] - w[0]);
        }
    };
    // The window corners next to a non-empty column, row by row along the first axis: the corners of
    // row x come from the columns of rows x − 1 and x, so two rows' corners are held at a time.
    let mut flush = |row: &mut Vec<[i64; K]>| {
        row.sort_unstable();
        row.dedup();
        for &v in row.iter() {
            count(v);
        }
        row.clear();
    };
    let (mut row, mut current, mut next) = (None, Vec::new(), Vec::new());
    for (key, _) in rays.column_groups() {
        let col = rays.keys().unpack(key).map(i64::from);
        let x = col[0];
        match row {
            Some(r) if r == x => {}
            Some(r) if r + 1 == x => {
                flush(&mut current);
                std::mem::swap(&mut current, &mut next);
            }
            _ => {
                flush(&mut current);
                flush(&mut next);
            }
        }
        row = Some(x);
        for b in 0..columns {
            let mut v = col;
            for (axis, x) in v[..K - 1].iter_mut().enumerate() {
                *x += (b >> axis & 1) as i64;
            }
            // For K ≥ 2, bit 0 of b moves the corner to the next row (for K = 1, b is 0).
            if b & 1 == 1 {
                next.push(v);
            } else {
                current.push(v);
            }
        }
    }
    flush(&mut current);
    flush(&mut next);
    Ok((total >> K) as i64)
}

impl<const K: usize> KTree<K> {
    /// The Euler number of the full voxels (objects minus tunnels plus cavities), as scikit-image's
    /// `measure.euler_number(image, connectivity)`: connectivity 1 or `K` ([`euler_number`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let ring = KTree::<2>::from_dense(2, &[true, true, true, false, true, false, true, false, true, true, true, false, false, false, false, false]).unwrap();
    /// assert_eq!(ring.euler_number(1).unwrap(), 0);
    /// ```
    ///
    /// # Errors
    /// As [`euler_number`].
    pub fn euler_number(&self, connectivity: usize) -> Result<i64, ShapeError> {
        euler_number(self, connectivity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_voxel_window_values() {
        // A single voxel is seen by 2^K windows, each contributing 1 (× 2^K / 2^K).
        assert_eq!(table::<2>(false)[1], 1);
        assert_eq!(table::<2>(true)[1], 1);
        assert_eq!(table::<3>(true)[1], 1);
        assert_eq!(table::<3>(false)[0], 0);
        assert_eq!(table::<3>(true)[0], 0);
    }
}
