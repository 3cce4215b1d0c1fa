//! Rays as integer arrays: one row per run, the column's `K − 1` coordinates, then `z1` and `z2` (the run
//! covers `z1 ≤ z < z2` along the last axis), as in the ray text format.

use ktree::shape::run_count;
use ktree::tree::rays_of;
use ktree::tree::storage::infallible;
use ktree::{KTree, Ray, RaySet};
use numpy::ndarray::Array2;

use crate::failure::Failure;

/// Most runs a tree is turned into (counted before anything is allocated).
const MAX_RUNS: u128 = 1 << 27;

/// The ray set of an `(n, K + 1)` array's rows (`flat`: row after row) in a universe of level `level`.
pub(crate) fn rays_of_rows<const K: usize>(flat: &[i64], level: u32) -> Result<RaySet<K>, Failure> {
    let mut rays = Vec::with_capacity(flat.len() / (K + 1));
    for (i, row) in flat.chunks_exact(K + 1).enumerate() {
        let mut v = [0u32; K];
        let mut z2 = 0u32;
        for (j, &x) in row.iter().enumerate() {
            let x = u32::try_from(x).map_err(|_| {
                Failure::Value(format!(
                    "ray {i}: {x} in column {j} is not a coordinate (0 to 2^32 - 1)"
                ))
            })?;
            match v.get_mut(j) {
                Some(c) => *c = x,
                None => z2 = x,
            }
        }
        rays.push(Ray::new(v, z2));
    }
    Ok(RaySet::from_rays(level, rays)?)
}

/// The `(n, K + 1)` array of a ray set's runs, in the set's order.
pub(crate) fn array_of_rays<const K: usize>(rays: &RaySet<K>) -> Array2<i64> {
    let mut out = Array2::zeros((rays.len(), K + 1));
    for (mut row, ray) in out.outer_iter_mut().zip(rays.iter()) {
        for (j, &c) in ray.start.iter().enumerate() {
            row[j] = i64::from(c);
        }
        row[K] = i64::from(ray.z2);
    }
    out
}

/// The runs of a tree's voxels along the last axis (the library's [`rays_of`]), counted first
/// ([`run_count`]): at most [`MAX_RUNS`] of them.
///
/// # Errors
/// A `ValueError` when the tree has more than [`MAX_RUNS`] runs.
pub(crate) fn tree_rays<const K: usize>(tree: &KTree<K>) -> Result<RaySet<K>, Failure> {
    let runs = infallible(run_count(tree));
    if runs > MAX_RUNS {
        return Err(Failure::Value(format!(
            "the tree has {runs} runs, more than the {MAX_RUNS} this conversion allows"
        )));
    }
    Ok(infallible(rays_of(tree)))
}
