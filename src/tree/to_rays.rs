//! A tree back to rays: the runs of its full voxels along the last axis, read from any storage
//! ([`rays_of`]; [`KTree::to_rays`] for a tree in memory).
//!
//! The runs are gathered slab by slab along the first axis (up to [`SLABS`] slabs): a walk that skips the
//! subtrees outside the slab lists each full leaf's column pieces, which are sorted by column and joined
//! into the slab's runs. The walk goes depth first in child order, so the pieces of one column already come
//! in order along it (two leaves over the same column part at an ancestor whose children differ only in
//! the last axis's bit): a stable radix sort by the column alone puts them in order. Only one slab's
//! pieces are held at a time, so the memory is that of the runs plus a slab's share of the pieces (a
//! column crosses a piece per full leaf above it, many more than it has runs).

use crate::rays::{ColumnKeys, RaySet, RunGatherer};
use crate::tree::cursor::{try_walk, Visitor, Walk};
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{KTree, NodeRef, NodeState};

/// At most this many slabs along the first axis.
const SLABS: u64 = 64;

/// The runs along the last axis of the full voxels of `tree` (in memory or a file read in place): the ray
/// set that stacks back to the tree. A run per column a full leaf crosses, joined: a tree whose full
/// leaves are large holds many more runs than nodes (the full universe of level `L` has `2^(L(K−1))`); the
/// number of runs is known beforehand from [`shape::run_count`](crate::shape::run_count).
///
/// ```
/// use ktree::{rays::ball_rays, stacking::paper::stack, tree::rays_of};
/// let rays = ball_rays::<3>(5, [16, 16, 16], 11).unwrap();
/// assert_eq!(rays_of(&stack(&rays)), Ok(rays));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn rays_of<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<RaySet<K>, T::Error> {
    let universe = tree.universe();
    let level = universe.level();
    let side = universe.side();
    // K = 1 has one column, the last axis itself: one slab.
    let width = if K == 1 { side } else { (side / SLABS).max(1) };
    let mut out = RunGatherer::<K>::new(level, width);
    let mut pieces = Vec::new();
    let mut start = 0;
    while start < side {
        let end = (start + width).min(side);
        pieces.clear();
        let mut slab = SlabPieces::<K> {
            slab: (start as u32, end as u32),
            keys: ColumnKeys::new(level),
            pieces: &mut pieces,
        };
        try_walk(tree, &mut slab)?;
        out.append(start, &mut pieces);
        start = end;
    }
    Ok(out.finish(universe))
}

impl<const K: usize> KTree<K> {
    /// The runs along the last axis of a tree's full voxels: the ray set that stacks back to the tree
    /// ([`rays_of`]).
    ///
    /// ```
    /// use ktree::{stacking::paper::stack, rays::ball_rays};
    /// let rays = ball_rays::<3>(5, [16, 16, 16], 11).unwrap();
    /// assert_eq!(stack(&rays).to_rays(), rays);
    /// ```
    pub fn to_rays(&self) -> RaySet<K> {
        infallible(rays_of(self))
    }
}

/// Lists, as `(column key, z1, z2)`, the column pieces of the full leaves within a slab `x0 ≤ x < x1` of
/// the first axis (the whole universe for K = 1).
struct SlabPieces<'a, const K: usize> {
    slab: (u32, u32),
    keys: ColumnKeys<K>,
    pieces: &'a mut Vec<(u64, u32, u32)>,
}

impl<const K: usize> Visitor<K> for SlabPieces<'_, K> {
    const LEAVES: bool = false;

    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        let cell = node.cell;
        let side = 1u32 << cell.log_side;
        let origin = cell.origin;
        let (x0, x1) = if K == 1 {
            (0, u32::MAX)
        } else {
            (
                origin[0].max(self.slab.0),
                (origin[0] + side).min(self.slab.1),
            )
        };
        if x0 >= x1 {
            return Walk::Skip;
        }
        if node.state != NodeState::Full {
            return Walk::Descend;
        }
        let (z1, z2) = (origin[K - 1], origin[K - 1] + side);
        // Every column of the cell within the slab: an odometer over the first K − 1 axes.
        let mut column = origin;
        if K > 1 {
            column[0] = x0;
        }
        loop {
            self.pieces.push((self.keys.pack(column), z1, z2));
            let mut axis = 0;
            while axis + 1 < K {
                column[axis] += 1;
                let end = if axis == 0 { x1 } else { origin[axis] + side };
                if column[axis] < end {
                    break;
                }
                column[axis] = if axis == 0 { x0 } else { origin[axis] };
                axis += 1;
            }
            if axis + 1 >= K {
                break;
            }
        }
        Walk::Skip
    }
}
