//! Building a tree in parts that run apart (other processes, other machines) and joining them.
//!
//! The columns are cut into contiguous slabs along axis 0, balanced by their number of runs (runs follow
//! the object's boundary, and so does the size of the tree a slab makes); each part stacks the rays of its
//! slab alone, and the parts' trees are joined by union. The parts cover disjoint sets of columns, so the
//! union is the object itself, and as every tree ktree builds is the minimal reduced tree of its voxels, the
//! joined tree is node for node the tree of the whole ray set — whatever the number of parts.
//!
//! ```
//! use ktree::stacking::{balanced_slabs, join_parts, slab_rays, stack};
//! use ktree::rays::ball_rays;
//! let rays = ball_rays::<3>(5, [32, 32, 32], 22).unwrap();
//! let slabs = balanced_slabs(&rays, 3);
//! assert_eq!(slabs.len(), 3);
//! let mut parts = slabs.iter().map(|x| stack(&slab_rays(&rays, x.clone())));
//! let first = parts.next().unwrap();
//! assert_eq!(join_parts(first, parts).unwrap(), stack(&rays));
//! ```

use std::ops::Range;

use crate::ops::{union, OpsError};
use crate::rays::RaySet;
use crate::tree::KTree;

/// Cuts the columns of `rays` into `parts` contiguous slabs along axis 0 (half-open ranges of the axis-0
/// coordinate, in increasing order, covering `0..U` together) holding about equal numbers of runs. Some
/// slabs are empty ranges when there are fewer occupied axis-0 coordinates than parts. For `K = 1` there
/// is one column: the first part gets it whole and the others get empty ranges at the end.
pub fn balanced_slabs<const K: usize>(rays: &RaySet<K>, parts: usize) -> Vec<Range<u32>> {
    let parts = parts.max(1);
    let side = u32::try_from(rays.universe().side()).unwrap_or(u32::MAX);
    if K == 1 {
        let mut slabs = vec![side..side; parts];
        slabs[0] = 0..side;
        return slabs;
    }
    let keys = rays.column_keys();
    let shift = (K - 2) as u32 * rays.level();
    let x_of = |i: usize| (keys[i] >> shift) as u32;
    let mut bounds = Vec::with_capacity(parts + 1);
    bounds.push(0u32);
    for p in 1..parts {
        // The slab boundary at the axis-0 coordinate of the run that starts this part's share.
        let at = keys.len() * p / parts;
        let x = if at < keys.len() { x_of(at) } else { side };
        let last = *bounds.last().unwrap_or(&0);
        bounds.push(x.max(last));
    }
    bounds.push(side);
    bounds.windows(2).map(|w| w[0]..w[1]).collect()
}

/// The rays of the columns whose axis-0 coordinate lies in `x`, in the same universe (for `K = 1`, every
/// ray unless `x` is empty).
pub fn slab_rays<const K: usize>(rays: &RaySet<K>, x: Range<u32>) -> RaySet<K> {
    let range = if x.is_empty() {
        0..0
    } else {
        rays.slab_range(x)
    };
    RaySet::from_sorted_parts(
        rays.universe(),
        rays.column_keys()[range.clone()].to_vec(),
        rays.runs()[range].to_vec(),
        None,
    )
}

/// Joins the trees of parts that cover disjoint columns of one universe (as [`slab_rays`] makes them) into
/// the tree of the whole: their union, taken part after part (only the joined tree and one part are held).
///
/// # Errors
/// [`OpsError`] if the parts are not all of one level.
pub fn join_parts<const K: usize>(
    first: KTree<K>,
    others: impl IntoIterator<Item = KTree<K>>,
) -> Result<KTree<K>, OpsError> {
    others
        .into_iter()
        .try_fold(first, |acc, part| union(&acc, &part))
}
