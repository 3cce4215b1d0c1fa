//! Point queries: one voxel ([`contains`]), many at once ([`contains_many`], from anywhere:
//! [`contains_many_signed`]; most answered from a table of the cells of the points' box, the rest ordered by
//! Morton key and answered on all threads, each thread walking its share of the tree once), and a cursor
//! that remembers its last path for coherent queries ([`PointCursor`], the one point descent of
//! [`locate`](crate::tree::locate)).

use rayon::prelude::*;

use super::box_table::{BoxTable, TABLE_FROM};
use crate::radix::sort_by_key;
use crate::space::morton_encode;
use crate::tree::cursor::{try_walk, Visitor, Walk};
pub use crate::tree::locate::PointCursor;
use crate::tree::storage::TreeStorage;
use crate::tree::{NodeRef, NodeState};

/// Whether voxel `point` is inside the object stored in `tree` (outside the universe: `false`).
///
/// # Errors
/// The storage's read error.
pub fn contains<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    point: [u32; K],
) -> Result<bool, T::Error> {
    PointCursor::new(tree)?.contains(point)
}

/// The points of one run of a batch, ordered by Morton key and answered by one [`PointCursor`].
const RUN: usize = 1 << 14;

/// log₂ of the most cells of a batch's table: a byte each, 256 KiB, held in the second-level cache.
const TOP_CELLS_LOG2: u32 = 18;

/// The state of every cell of a batch's box ([`BoxTable`]), as OpenVDB keeps its top levels in a root
/// table: a point in an empty or full cell is answered by one read, and only a point in a partial cell (or
/// outside the box) walks the tree.
fn top_states<const K: usize, T: TreeStorage<K>, P>(
    tree: &T,
    points: &[P],
    voxel: impl Fn(&P) -> Option<[u32; K]>,
) -> Result<BoxTable<K, NodeState>, T::Error> {
    struct Fill<'a, const K: usize>(&'a mut BoxTable<K, NodeState>);
    impl<const K: usize> Visitor<K> for Fill<'_, K> {
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            if node.state == NodeState::Partial && node.cell.level < self.0.depth {
                return if self.0.overlaps(&node.cell) {
                    Walk::Descend
                } else {
                    Walk::Skip
                };
            }
            self.0.set(&node.cell, node.state);
            Walk::Skip
        }
    }
    let mut table = BoxTable::spanning(
        tree.level(),
        points,
        voxel,
        TOP_CELLS_LOG2,
        NodeState::Empty,
    );
    try_walk(tree, &mut Fill(&mut table))?;
    Ok(table)
}

/// Whether each voxel of `points` is inside the object, in the order given. A batch of 65 536 points or
/// more first reads the tree's nodes over the box of its points into a table of at most 2^18 cells,
/// which answers every point in an empty or full cell by one read. The other points are cut into runs of 16 384
/// answered on all threads; within a run they are ordered by Morton key and answered by one
/// [`PointCursor`], so that each run walks the tree once, in order, in cache. Points outside the universe
/// are `false`.
///
/// ```
/// use ktree::query::contains_many;
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(2, &[true, false, false, true]).unwrap();
/// assert_eq!(contains_many(&tree, &[[3], [1], [0], [7]]), Ok(vec![true, false, true, false]));
/// ```
///
/// # Errors
/// The storage's first read error.
pub fn contains_many<const K: usize, T>(
    tree: &T,
    points: &[[u32; K]],
) -> Result<Vec<bool>, T::Error>
where
    T: TreeStorage<K> + Sync,
{
    contains_many_by(tree, points, |p| Some(*p))
}

/// [`contains_many`] of points anywhere (negative coordinates too: outside), read as they are given
/// (a caller's `i64` array is not converted first).
///
/// ```
/// use ktree::query::contains_many_signed;
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(2, &[true, false, false, true]).unwrap();
/// assert_eq!(contains_many_signed(&tree, &[[3], [-1], [0], [1 << 40]]), Ok(vec![true, false, true, false]));
/// ```
///
/// # Errors
/// The storage's first read error.
pub fn contains_many_signed<const K: usize, T>(
    tree: &T,
    points: &[[i64; K]],
) -> Result<Vec<bool>, T::Error>
where
    T: TreeStorage<K> + Sync,
{
    contains_many_by(tree, points, |p| {
        let mut voxel = [0u32; K];
        for (v, &c) in voxel.iter_mut().zip(p) {
            *v = u32::try_from(c).ok()?;
        }
        Some(voxel)
    })
}

/// [`contains_many`] of points of any type, `voxel` giving each one's voxel (`None`: not a voxel of any
/// universe, outside).
fn contains_many_by<const K: usize, T, P>(
    tree: &T,
    points: &[P],
    voxel: impl Fn(&P) -> Option<[u32; K]> + Sync,
) -> Result<Vec<bool>, T::Error>
where
    T: TreeStorage<K> + Sync,
    P: Sync,
{
    let top = if points.len() >= TABLE_FROM {
        Some(top_states(tree, points, &voxel)?)
    } else {
        None
    };
    let side = 1u64 << tree.level();
    let inside = |p: &P| voxel(p).filter(|v| v.iter().all(|&c| u64::from(c) < side));
    let mut out = vec![false; points.len()];
    let answer = |(points, out): (&[P], &mut [bool])| -> Result<(), T::Error> {
        let mut order: Vec<(u64, u32)> = Vec::with_capacity(points.len());
        for (i, p) in points.iter().enumerate() {
            let Some(v) = inside(p) else {
                continue;
            };
            // In a partial cell or outside the box: walked. (A leaf's answer is written without a
            // branch on which leaf: inside and outside alternate at random.)
            match top
                .as_ref()
                .and_then(|t| t.get(v))
                .unwrap_or(NodeState::Partial)
            {
                NodeState::Partial => order.push((morton_encode(v), i as u32)),
                state => out[i] = state == NodeState::Full,
            }
        }
        sort_by_key(&mut order, K as u32 * tree.level(), &mut Vec::new(), |p| {
            p.0
        });
        let mut cursor = PointCursor::new(tree)?;
        for (_, i) in order {
            if let Some(v) = inside(&points[i as usize]) {
                out[i as usize] = cursor.contains(v)?;
            }
        }
        Ok(())
    };
    points
        .par_chunks(RUN)
        .zip(out.par_chunks_mut(RUN))
        .try_for_each(answer)?;
    Ok(out)
}
