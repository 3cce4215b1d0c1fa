//! Face neighbours in the compact tree, without pointers. Veenstra & Ahuja thread each black leaf to its
//! six neighbours with spare child pointers (V3); the level-order tree has no pointers, so a neighbour is
//! found by descending from the root to the equal-sized cell across a face — `O(L)` rank lookups — and the
//! part of it that touches the face (or an edge) is read by descending only into the children that touch
//! it. Both are [`cursor`] walks that choose which children to visit. A [`Neighbours`] asks many such
//! questions about nearby cells, each descent starting from the deepest ancestor it shares with the last
//! one ([`PointCursor`]).
//!
//! ```
//! use ktree::display::neighbours::is_surrounded;
//! use ktree::KTree;
//! // A full 4 × 4 × 4 universe: the voxel (1, 1, 1) is surrounded, the universe's corner voxel is not.
//! let full = KTree::<3>::full(2).unwrap();
//! let u = full.universe();
//! assert!(is_surrounded(&full, &u.cell([1, 1, 1], 2).unwrap()));
//! assert!(!is_surrounded(&full, &u.cell([0, 0, 0], 2).unwrap()));
//! ```

use std::convert::Infallible;

use crate::space::Cell;
use crate::tree::cursor::{self, ChildOrder, Visitor, Walk};
use crate::tree::locate::PointCursor;
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{KTree, NodeRef, NodeState};

/// The node whose cell contains the aligned cell `region` and is either a leaf or `region` itself.
/// `region` must lie inside the tree's universe. (Any storage: [`Neighbours::locate`].)
pub fn locate<const K: usize, T: TreeStorage<K, Error = Infallible>>(
    tree: &T,
    region: &Cell<K>,
) -> NodeRef<K> {
    infallible(crate::tree::locate::locate(
        tree,
        infallible(tree.root()),
        region,
    ))
}

/// The cell of the same size as `cell` across its face on `axis` (`upper`: the face at `origin + side`),
/// `None` when that face is on the universe's boundary.
pub fn face_neighbour_cell<const K: usize>(
    cell: &Cell<K>,
    axis: usize,
    upper: bool,
    side_of_universe: u64,
) -> Option<Cell<K>> {
    shifted(cell, &[(axis, upper)], side_of_universe)
}

/// The cell of the same size as `cell` shifted by one side along each `(axis, upper)` given, `None`
/// outside the universe.
pub fn shifted<const K: usize>(
    cell: &Cell<K>,
    moves: &[(usize, bool)],
    side_of_universe: u64,
) -> Option<Cell<K>> {
    let s = cell.side();
    let mut out = *cell;
    for &(axis, upper) in moves {
        let o = u64::from(cell.origin[axis]);
        if upper {
            if o + s >= side_of_universe {
                return None;
            }
            out.origin[axis] = (o + s) as u32;
        } else {
            if o < s {
                return None;
            }
            out.origin[axis] = (o - s) as u32;
        }
    }
    Some(out)
}

/// Whether every voxel of `region` that touches its face on `axis` (`upper` side) is full: the face of the
/// region is wholly covered by the object. (Any storage: [`Neighbours::face_all_full`].)
pub fn face_all_full<const K: usize, T: TreeStorage<K, Error = Infallible>>(
    tree: &T,
    region: &Cell<K>,
    axis: usize,
    upper: bool,
) -> bool {
    infallible(Neighbours::new(tree).and_then(|mut n| n.face_all_full(region, axis, upper)))
}

/// Whether a full leaf is surrounded: each of its `2K` faces touches only full voxels across it (V5).
/// Faces on the universe's boundary are open. (Any storage: [`Neighbours::is_surrounded`].)
pub fn is_surrounded<const K: usize, T: TreeStorage<K, Error = Infallible>>(
    tree: &T,
    cell: &Cell<K>,
) -> bool {
    infallible(Neighbours::new(tree).and_then(|mut n| n.is_surrounded(cell)))
}

/// Questions about the cells near one another in a tree, on any storage, each descent starting from the
/// deepest ancestor shared with the previous question's cell. Every answer is the storage's read or its
/// error.
///
/// ```
/// use ktree::display::neighbours::Neighbours;
/// use ktree::KTree;
/// let full = KTree::<3>::full(2).unwrap();
/// let u = full.universe();
/// let mut n = Neighbours::new(&full).unwrap();
/// assert_eq!(n.is_surrounded(&u.cell([1, 1, 1], 2).unwrap()), Ok(true));
/// assert_eq!(n.is_surrounded(&u.cell([0, 0, 0], 2).unwrap()), Ok(false));
/// ```
#[derive(Debug, Clone)]
pub struct Neighbours<'t, const K: usize, T = KTree<K>> {
    tree: &'t T,
    locator: PointCursor<'t, K, T>,
}

impl<'t, const K: usize, T: TreeStorage<K>> Neighbours<'t, K, T> {
    /// Questions about `tree`.
    ///
    /// # Errors
    /// The storage's read error.
    pub fn new(tree: &'t T) -> Result<Self, T::Error> {
        Ok(Self {
            tree,
            locator: PointCursor::new(tree)?,
        })
    }

    /// As [`locate`].
    ///
    /// # Errors
    /// The storage's read error.
    pub fn locate(&mut self, region: &Cell<K>) -> Result<NodeRef<K>, T::Error> {
        self.locator.locate(region)
    }

    /// As [`face_all_full`].
    ///
    /// # Errors
    /// The storage's read error.
    pub fn face_all_full(
        &mut self,
        region: &Cell<K>,
        axis: usize,
        upper: bool,
    ) -> Result<bool, T::Error> {
        struct AllFull {
            face: ChildOrder,
            all_full: bool,
        }
        impl<const K: usize> Visitor<K> for AllFull {
            const LEAVES: bool = false;
            fn visit(&mut self, node: &NodeRef<K>) -> Walk {
                if node.state == NodeState::Empty {
                    self.all_full = false;
                    return Walk::Stop;
                }
                Walk::Descend
            }
            fn child_order(&self, _node: &NodeRef<K>) -> ChildOrder {
                self.face
            }
        }
        let mut query = AllFull {
            face: ChildOrder::half::<K>(axis, upper),
            all_full: true,
        };
        let node = self.locate(region)?;
        cursor::try_walk_from(self.tree, node, &mut query)?;
        Ok(query.all_full)
    }

    /// Calls `f` with each leaf (cell and state) of `region` that touches the region's face on `axis`
    /// (`upper` side), in Morton order; `region` itself when it lies in a leaf (then with the leaf's state).
    ///
    /// ```
    /// use ktree::display::neighbours::Neighbours;
    /// use ktree::{KTree, NodeState};
    /// // Voxels 0 and 3 of a 2 × 2 square: its upper face on axis 0 touches voxels 1 (empty) and 3 (full).
    /// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
    /// let mut seen = Vec::new();
    /// let mut near = Neighbours::new(&tree).unwrap();
    /// near.face_leaves(&tree.universe().root(), 0, true, |c, s| seen.push((c.origin(), s))).unwrap();
    /// assert_eq!(seen, [([1, 0], NodeState::Empty), ([1, 1], NodeState::Full)]);
    /// ```
    ///
    /// # Errors
    /// The storage's read error.
    pub fn face_leaves(
        &mut self,
        region: &Cell<K>,
        axis: usize,
        upper: bool,
        f: impl FnMut(&Cell<K>, NodeState),
    ) -> Result<(), T::Error> {
        struct FaceLeaves<F> {
            face: ChildOrder,
            f: F,
        }
        impl<const K: usize, F: FnMut(&Cell<K>, NodeState)> Visitor<K> for FaceLeaves<F> {
            const LEAVES: bool = false;
            fn visit(&mut self, node: &NodeRef<K>) -> Walk {
                if node.state != NodeState::Partial {
                    (self.f)(&node.cell, node.state);
                }
                Walk::Descend
            }
            fn child_order(&self, _node: &NodeRef<K>) -> ChildOrder {
                self.face
            }
        }
        let node = self.locate(region)?;
        if node.state != NodeState::Partial {
            let mut f = f;
            f(region, node.state);
            return Ok(());
        }
        let mut query = FaceLeaves {
            face: ChildOrder::half::<K>(axis, upper),
            f,
        };
        cursor::try_walk_from(self.tree, node, &mut query)?;
        Ok(())
    }

    /// As [`is_surrounded`].
    ///
    /// # Errors
    /// The storage's read error.
    pub fn is_surrounded(&mut self, cell: &Cell<K>) -> Result<bool, T::Error> {
        let side = self.tree.universe().side();
        for axis in 0..K {
            for upper in [false, true] {
                let Some(n) = face_neighbour_cell(cell, axis, upper, side) else {
                    return Ok(false);
                };
                if !self.face_all_full(&n, axis, !upper)? {
                    return Ok(false);
                }
            }
        }
        Ok(true)
    }
}

/// The occupancy of a 3-D region's edge line: the region is an aligned cube; the edge runs along `axis`
/// at the region's `side_b` face on axis `b` and `side_c` face on axis `c` (`true` = upper). Returns
/// `(start, end, full)` runs covering `[0, region side)` as offsets from the region's origin along `axis`,
/// in order, adjacent runs of equal state merged. A missing region (outside the universe) is empty.
/// (Any storage: [`Neighbours::edge_occupancy`].)
pub fn edge_occupancy<T: TreeStorage<3, Error = Infallible>>(
    tree: &T,
    region: Option<&Cell<3>>,
    side: u32,
    axis: usize,
    b: (usize, bool),
    c: (usize, bool),
) -> Vec<(u32, u32, bool)> {
    infallible(Neighbours::new(tree).and_then(|mut n| n.edge_occupancy(region, side, axis, b, c)))
}

impl<T: TreeStorage<3>> Neighbours<'_, 3, T> {
    /// As [`edge_occupancy`].
    ///
    /// # Errors
    /// The storage's read error.
    pub fn edge_occupancy(
        &mut self,
        region: Option<&Cell<3>>,
        side: u32,
        axis: usize,
        (b, side_b): (usize, bool),
        (c, side_c): (usize, bool),
    ) -> Result<Vec<(u32, u32, bool)>, T::Error> {
        let mut out: Vec<(u32, u32, bool)> = Vec::new();
        let Some(region) = region else {
            return Ok(vec![(0, side, false)]);
        };
        let tree = self.tree;
        let node = self.locate(region)?;
        let base = region.origin[axis];
        let mut push = |start: u32, end: u32, full: bool| match out.last_mut() {
            Some(last) if last.2 == full && last.1 == start => last.1 = end,
            _ => out.push((start, end, full)),
        };
        if node.state != NodeState::Partial {
            push(0, side, node.state == NodeState::Full);
            return Ok(out);
        }
        // Depth-first along the edge, lower half first.
        struct Edge<F> {
            along: ChildOrder,
            axis: usize,
            base: u32,
            push: F,
        }
        impl<F: FnMut(u32, u32, bool)> Visitor<3> for Edge<F> {
            const LEAVES: bool = false;
            fn visit(&mut self, n: &NodeRef<3>) -> Walk {
                if n.state != NodeState::Partial {
                    let start = n.cell.origin[self.axis] - self.base;
                    (self.push)(
                        start,
                        start + n.cell.side() as u32,
                        n.state == NodeState::Full,
                    );
                }
                Walk::Descend
            }
            fn child_order(&self, _n: &NodeRef<3>) -> ChildOrder {
                self.along
            }
        }
        let corner = (usize::from(side_b) << b) | (usize::from(side_c) << c);
        let mut query = Edge {
            along: ChildOrder::from_codes([corner, corner | 1 << axis]),
            axis,
            base,
            push,
        };
        cursor::try_walk_from(tree, node, &mut query)?;
        Ok(out)
    }
}
