//! Point queries: one voxel ([`contains`]), many at once ([`contains_many`]: ordered by Morton key and
//! answered on all threads, each thread walking its share of the tree once), and a cursor that remembers
//! its last path for coherent queries ([`PointCursor`]).

use rayon::prelude::*;

use crate::radix::sort_by_key;
use crate::space::morton_encode;
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// The depth of the deepest node a path can hold (the largest universe level) plus one.
const PATH: usize = 33;

/// Point location that remembers its last path from the root: a point near the previous one (a
/// neighbour, the next voxel in Morton order) is found from their deepest common ancestor instead of
/// from the root. Works on any storage.
///
/// ```
/// use ktree::query::PointCursor;
/// use ktree::KTree;
/// let tree = KTree::<2>::from_dense(3, &(0..64).map(|i| i % 5 == 0).collect::<Vec<_>>()).unwrap();
/// let mut cursor = PointCursor::new(&tree).unwrap();
/// for p in [[3, 4], [3, 5], [7, 0], [0, 0], [9, 9]] {
///     assert_eq!(cursor.contains(p).unwrap(), tree.contains(p));
/// }
/// ```
#[derive(Debug, Clone)]
pub struct PointCursor<'a, const K: usize, T> {
    tree: &'a T,
    level: u32,
    /// `(index, state)` of the node at each depth of the last path.
    path: [(usize, NodeState); PATH],
    /// For each partial node of the last path but the deepest: its first child and its children's codes,
    /// so that a point in a sibling of the last leaf reads nothing from the tree.
    children: [(usize, u32); PATH],
    /// Nodes on the last path (at least the root).
    len: usize,
    /// The last point located.
    last: [u32; K],
}

impl<'a, const K: usize, T: TreeStorage<K>> PointCursor<'a, K, T> {
    /// A cursor over `tree`, its path at the root.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn new(tree: &'a T) -> Result<Self, T::Error> {
        let mut path = [(0, NodeState::Empty); PATH];
        path[0] = (0, tree.root_state()?);
        Ok(Self {
            tree,
            level: tree.level(),
            path,
            children: [(0, 0); PATH],
            len: 1,
            last: [0; K],
        })
    }

    /// The state of the leaf holding voxel `point`; [`NodeState::Empty`] outside the universe.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn state(&mut self, point: [u32; K]) -> Result<NodeState, T::Error> {
        // Outside the universe: a coordinate with a bit at or above the level.
        let all = point.iter().fold(0u64, |or, &c| or | u64::from(c));
        if all >> self.level != 0 {
            return Ok(NodeState::Empty);
        }
        // The ancestors of the last point down to depth `common` are the point's: the highest bit in which
        // any coordinate differs from the last point's is the depth where the paths part.
        let changed = (0..K).fold(0u32, |or, a| or | (self.last[a] ^ point[a]));
        let differ = 32 - changed.leading_zeros();
        let common = self.level.saturating_sub(differ) as usize;
        let mut depth = common.min(self.len - 1);
        let (mut index, mut state) = self.path[depth];
        // A partial node above the last path's end was descended last time: its children are known.
        let mut known = depth + 1 < self.len;
        // Only this prefix is sure to be the last point's path should a read below fail.
        self.len = depth + 1;
        while state == NodeState::Partial {
            let bit = self.level - 1 - depth as u32;
            let code = (0..K).fold(0usize, |c, a| c | ((point[a] >> bit & 1) as usize) << a);
            let (first, codes) = if known {
                self.children[depth]
            } else {
                let first = self.tree.first_child(depth, index)?;
                let read = (first, self.tree.block_codes(depth + 1, first)?);
                self.children[depth] = read;
                read
            };
            known = false;
            index = first + code;
            state = NodeState::from_bits(codes >> (2 * code));
            depth += 1;
            self.path[depth] = (index, state);
        }
        self.len = depth + 1;
        self.last = point;
        Ok(state)
    }

    /// Whether voxel `point` is inside the object (outside the universe: `false`).
    ///
    /// # Errors
    /// The storage's read error.
    pub fn contains(&mut self, point: [u32; K]) -> Result<bool, T::Error> {
        Ok(self.state(point)? == NodeState::Full)
    }
}

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

/// Whether each voxel of `points` is inside the object, in the order given. The points are cut into runs
/// of 16 384 answered on all threads; within a run they are ordered by Morton key and answered by one
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
    T::Error: Send,
{
    let side = 1u64 << tree.level();
    let mut out = vec![false; points.len()];
    let answer = |(points, out): (&[[u32; K]], &mut [bool])| -> Result<(), T::Error> {
        let mut order: Vec<(u64, u32)> = points
            .iter()
            .enumerate()
            .filter(|(_, p)| p.iter().all(|&c| u64::from(c) < side))
            .map(|(i, p)| (morton_encode(*p), i as u32))
            .collect();
        sort_by_key(&mut order, K as u32 * tree.level(), &mut Vec::new(), |p| {
            p.0
        });
        let mut cursor = PointCursor::new(tree)?;
        for (_, i) in order {
            out[i as usize] = cursor.contains(points[i as usize])?;
        }
        Ok(())
    };
    points
        .par_chunks(RUN)
        .zip(out.par_chunks_mut(RUN))
        .try_for_each(answer)?;
    Ok(out)
}
