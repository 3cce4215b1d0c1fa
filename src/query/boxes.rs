//! Boxes and windows: the bounding box of the full voxels ([`bounding_box`]), the number of full voxels
//! inside a box ([`count`]) and the object cut to a box ([`crop`]). A box is `(lo, hi)`, `hi` exclusive
//! on every axis, clipped to the universe; a box with `hi ≤ lo` on some axis holds no voxel.

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::space::Cell;
use crate::tree::cursor::{try_walk, Visitor, Walk};
use crate::tree::sink::{LevelSink, MemorySink};
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{KTree, NodeRef, NodeState};

/// A box of voxels `(lo, hi)`, `hi` exclusive on every axis.
pub type VoxelBox<const K: usize> = ([u32; K], [u32; K]);

/// How a cell lies against a box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Overlap {
    /// No voxel of the cell is in the box.
    Outside,
    /// Every voxel of the cell is in the box.
    Inside,
    /// Some are, some are not.
    Straddles,
}

/// The voxels of `cell` in the box `[lo, hi)`, per axis `(from, to)`, `to` exclusive.
fn meet<const K: usize>(cell: &Cell<K>, lo: &[u64; K], hi: &[u64; K]) -> [(u64, u64); K] {
    std::array::from_fn(|a| {
        let o = u64::from(cell.origin[a]);
        (o.max(lo[a]), (o + cell.side()).min(hi[a]))
    })
}

fn overlap<const K: usize>(cell: &Cell<K>, lo: &[u64; K], hi: &[u64; K]) -> Overlap {
    let m = meet(cell, lo, hi);
    if m.iter().any(|&(f, t)| t <= f) {
        Overlap::Outside
    } else if m.iter().all(|&(f, t)| t - f == cell.side()) {
        Overlap::Inside
    } else {
        Overlap::Straddles
    }
}

fn widen<const K: usize>(p: [u32; K]) -> [u64; K] {
    p.map(u64::from)
}

/// The bounding box of the full voxels, `(lo, hi)` with `hi` exclusive, or `None` for an empty object.
/// A walk that skips every subtree that cannot move a side of the box found so far.
///
/// ```
/// use ktree::query::bounding_box;
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(3, &[false, true, true, false, true, false, false, false]).unwrap();
/// assert_eq!(bounding_box(&tree), Ok(Some(([1], [5]))));
/// assert_eq!(bounding_box(&KTree::<2>::empty(4).unwrap()), Ok(None));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn bounding_box<const K: usize, T: TreeStorage<K>>(
    tree: &T,
) -> Result<Option<VoxelBox<K>>, T::Error> {
    struct Bounds<const K: usize> {
        lo: [u64; K],
        hi: [u64; K],
        any: bool,
    }
    impl<const K: usize> Visitor<K> for Bounds<K> {
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            let cell = node.cell();
            let o = widen(cell.origin);
            let s = cell.side();
            // Nothing in the cell can lower a `lo` or raise a `hi`.
            if self.any && (0..K).all(|a| o[a] >= self.lo[a] && o[a] + s <= self.hi[a]) {
                return Walk::Skip;
            }
            match node.state() {
                NodeState::Empty => Walk::Skip,
                NodeState::Partial => Walk::Descend,
                NodeState::Full => {
                    for a in 0..K {
                        if !self.any || o[a] < self.lo[a] {
                            self.lo[a] = o[a];
                        }
                        if !self.any || o[a] + s > self.hi[a] {
                            self.hi[a] = o[a] + s;
                        }
                    }
                    self.any = true;
                    Walk::Skip
                }
            }
        }
    }
    let mut b = Bounds {
        lo: [0; K],
        hi: [0; K],
        any: false,
    };
    try_walk(tree, &mut b)?;
    // Every side is at most U ≤ 2^31.
    Ok(b.any
        .then(|| (b.lo.map(|v| v as u32), b.hi.map(|v| v as u32))))
}

/// The number of full voxels inside the box `[lo, hi)`: one walk that descends only into the partial
/// nodes whose cells straddle the box's faces.
///
/// ```
/// use ktree::query::count;
/// use ktree::KTree;
/// let tree = KTree::<2>::full(3).unwrap();
/// assert_eq!(count(&tree, [1, 2], [4, 100]), Ok(18)); // clipped to the universe: 3 × 6
/// assert_eq!(count(&tree, [4, 2], [4, 8]), Ok(0));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn count<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    lo: [u32; K],
    hi: [u32; K],
) -> Result<u128, T::Error> {
    struct Count<const K: usize> {
        lo: [u64; K],
        hi: [u64; K],
        n: u128,
    }
    impl<const K: usize> Visitor<K> for Count<K> {
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            let cell = node.cell();
            match (node.state(), overlap(&cell, &self.lo, &self.hi)) {
                (NodeState::Empty, _) | (_, Overlap::Outside) => Walk::Skip,
                (NodeState::Partial, _) => Walk::Descend,
                (NodeState::Full, _) => {
                    self.n += meet(&cell, &self.lo, &self.hi)
                        .iter()
                        .map(|&(f, t)| u128::from(t - f))
                        .product::<u128>();
                    Walk::Skip
                }
            }
        }
    }
    let mut c = Count {
        lo: widen(lo),
        hi: widen(hi),
        n: 0,
    };
    try_walk(tree, &mut c)?;
    Ok(c.n)
}

/// The object cut to the box `[lo, hi)`: the tree of its voxels inside the box, reduced, in the same
/// universe. Copies the subtrees inside the box and descends only into the cells that straddle its faces.
///
/// ```
/// use ktree::query::crop;
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(2, &[true, true, false, true]).unwrap();
/// assert_eq!(crop(&tree, [1], [4]), Ok(KTree::from_dense(2, &[false, true, false, true]).unwrap()));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn crop<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    lo: [u32; K],
    hi: [u32; K],
) -> Result<KTree<K>, T::Error> {
    let (lo, hi) = (widen(lo), widen(hi));
    let mut sink = MemorySink::<K>::new(tree.universe());
    let root = crop_node(
        tree,
        &mut sink,
        tree.universe().root(),
        0,
        tree.root_state()?,
        &lo,
        &hi,
    )?;
    Ok(infallible(sink.finish(root)))
}

/// The state of the cropped node at `cell` whose node in `tree` is `(index, state)` (a full or empty
/// leaf above `cell` stands for every cell below it), after appending its descendants to `sink`.
fn crop_node<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    sink: &mut MemorySink<K>,
    cell: Cell<K>,
    index: usize,
    state: NodeState,
    lo: &[u64; K],
    hi: &[u64; K],
) -> Result<NodeState, T::Error> {
    let place = overlap(&cell, lo, hi);
    if state == NodeState::Empty || place == Overlap::Outside {
        return Ok(NodeState::Empty);
    }
    if state == NodeState::Full && place == Overlap::Inside {
        return Ok(NodeState::Full);
    }
    // A partial node, or a full leaf straddling the box: decide the children, then the node.
    let depth = cell.level as usize;
    let (first, codes) = if state == NodeState::Partial {
        let first = tree.first_child(depth, index)?;
        (first, tree.block_codes(depth + 1, first)?)
    } else {
        (0, 0)
    };
    let mut kids = [NodeState::Empty; 16];
    for (code, kid) in kids.iter_mut().enumerate().take(1 << K) {
        let (i, s) = if state == NodeState::Partial {
            (first + code, NodeState::from_bits(codes >> (2 * code)))
        } else {
            (0, NodeState::Full)
        };
        *kid = crop_node(tree, sink, cell.child(code), i, s, lo, hi)?;
    }
    let kids = &kids[..1 << K];
    if kids.iter().all(|&k| k == NodeState::Empty) {
        return Ok(NodeState::Empty);
    }
    if kids.iter().all(|&k| k == NodeState::Full) {
        return Ok(NodeState::Full);
    }
    infallible(sink.push_block(depth + 1, kids));
    Ok(NodeState::Partial)
}
