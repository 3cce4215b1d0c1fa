//! A valued tree from leaves given in Morton order: cubes (their first voxel's Morton key and the log of
//! their side) each holding a value, disjoint — the leaves of an OctoMap file as it lists them, depth
//! first.

use crate::space::Cell;
use crate::tree::top_down::{build_top_down, Decision};
use crate::tree::TreeError;
use crate::value::Value;
use crate::KTree;

/// A leaf: the Morton key of its first voxel, the log of its side and its value.
pub type Leaf<V> = (u64, u32, V);

/// The minimal tree of level `level` of `leaves`, sorted by key and disjoint (each aligned to its side).
///
/// # Errors
/// [`TreeError::Value`] for a value no voxel may hold (a NaN); [`TreeError::PartialVoxel`] if two leaves
/// overlap or one is not aligned.
///
/// ```
/// use ktree::map::tree_from_leaves;
/// // A quadtree of level 2: the first quadrant (4 voxels) holds 1.5, voxel 4 (x = 2, y = 0) holds 2.
/// let tree = tree_from_leaves::<2, f32>(2, &[(0, 1, 1.5), (4, 0, 2.0)]).unwrap();
/// assert_eq!(tree.value_at([1, 1]), Some(1.5));
/// assert_eq!(tree.value_at([2, 0]), Some(2.0));
/// assert_eq!(tree.value_at([3, 0]), None);
/// ```
pub fn tree_from_leaves<const K: usize, V: Value>(
    level: u32,
    leaves: &[Leaf<V>],
) -> Result<KTree<K, V>, TreeError> {
    build_top_down::<K, V, _, TreeError>(
        level,
        (0..leaves.len(), 0u64, level),
        |_: &Cell<K>, (range, base, log_side)| {
            Ok(match &leaves[range.clone()] {
                [] => Decision::Leaf(None),
                [(key, side, v)] if key == base && side == log_side => Decision::Leaf(Some(*v)),
                _ => Decision::Split,
            })
        },
        |(range, base, log_side), code| {
            let span = 1u64 << (K as u32 * (log_side - 1));
            let start = base + code as u64 * span;
            let here = &leaves[range.clone()];
            let lo = range.start + here.partition_point(|l| l.0 < start);
            let hi = match start.checked_add(span) {
                Some(end) => range.start + here.partition_point(|l| l.0 < end),
                None => range.end,
            };
            Ok((lo..hi, start, log_side - 1))
        },
    )
}
