//! Point queries: one voxel ([`contains`]), many at once ([`contains_many`], from anywhere:
//! [`contains_many_signed`]; most answered from a table of the tree's top levels, the rest ordered by
//! Morton key and answered on all threads, each thread walking its share of the tree once), and a cursor
//! that remembers its last path for coherent queries ([`PointCursor`], the one point descent of
//! [`locate`](crate::tree::locate)).

use rayon::prelude::*;

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

/// log₂ of the most cells of [`TopStates`]: a byte each, 256 KiB, held in the second-level cache.
const TOP_CELLS_LOG2: u32 = 18;

/// Batches of at least this many points first build a [`TopStates`] table (its cost, a walk of the top
/// levels and a fill of its cells, is then a small share of the batch).
const TOP_FROM: usize = 1 << 16;

/// The state of every cell of one depth `d` of the tree (`d` levels of `K` bits: at most
/// 2^[`TOP_CELLS_LOG2`] cells), indexed by Morton key, as OpenVDB keeps its top levels in a root table: a
/// point in an empty or full cell of depth ≤ `d` is answered by one read, and only a point in a partial
/// cell of depth `d` walks the tree below.
struct TopStates {
    /// A point's Morton key shifted right by this gives its cell.
    shift: u32,
    states: Vec<u8>,
}

impl TopStates {
    fn new<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<Self, T::Error> {
        let level = tree.level();
        let depth = (TOP_CELLS_LOG2 / K as u32).min(level);
        let shift = K as u32 * (level - depth);
        let mut fill = Fill {
            depth,
            shift,
            states: vec![NodeState::Empty as u8; 1 << (K as u32 * depth)],
        };
        try_walk(tree, &mut fill)?;
        Ok(Self {
            shift,
            states: fill.states,
        })
    }

    /// The state of the cell holding the point of Morton key `key`: [`NodeState::Partial`] where the
    /// tree must be walked below.
    #[inline]
    fn state(&self, key: u64) -> NodeState {
        NodeState::from_bits(u32::from(self.states[(key >> self.shift) as usize]))
    }
}

/// Writes each node of a [`TopStates`] walk that is a leaf above its depth, or at its depth, over its cells.
struct Fill {
    depth: u32,
    shift: u32,
    states: Vec<u8>,
}

impl<const K: usize> Visitor<K> for Fill {
    const LEAVES: bool = false;
    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        if node.state == NodeState::Partial && node.cell.level < self.depth {
            return Walk::Descend;
        }
        // A node's cells are a contiguous range in Morton order.
        let first = (morton_encode(node.cell.origin) >> self.shift) as usize;
        let count = 1usize << (K as u32 * (self.depth - node.cell.level));
        self.states[first..first + count].fill(node.state as u8);
        Walk::Skip
    }
}

/// Whether each voxel of `points` is inside the object, in the order given. A batch of 65 536 points or
/// more first reads the tree's top levels into a table of at most 2^18 cells, which answers every point
/// in an empty or full cell down to that depth by one read. The other points are cut into runs of 16 384
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
    let top = if points.len() >= TOP_FROM {
        Some(TopStates::new(tree)?)
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
            let key = morton_encode(v);
            match top.as_ref().map_or(NodeState::Partial, |t| t.state(key)) {
                NodeState::Partial => order.push((key, i as u32)),
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
