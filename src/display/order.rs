//! Traversal order for a view (Meagher's M7, Veenstra & Ahuja's V2): children are visited in an order fixed
//! by the viewer's octant, so that a node that can occlude another is visited first (front to back) or last
//! (back to front). No searching or sorting.
//!
//! For a parallel view along `dir`, the *near* child on axis `i` is the lower half when `dir[i] > 0` (the
//! viewer sits at −∞ on that axis) and the upper half otherwise. Visiting the children `near ^ 0, near ^ 1,
//! …, near ^ (2^K − 1)` is front to back: a ray only moves away from the viewer on every axis, so it can
//! pass from child `near ^ a` into child `near ^ b` only if the bits of `a` are a subset of the bits of `b`,
//! hence `a < b`. For a perspective view the near child is chosen per node from the eye's side of the node's
//! centre on each axis; the same argument holds inside each node.
//!
//! ```
//! use ktree::display::{walk_ordered, Order, Viewer, Walk};
//! use ktree::KTree;
//! // Two voxels along x; looking along −x (from the +x side), the one at x = 1 comes first front to back.
//! let mut dense = vec![false; 8];
//! dense[0] = true;
//! dense[1] = true;
//! let tree = KTree::<3>::from_dense(1, &dense).unwrap();
//! let mut seen = Vec::new();
//! walk_ordered(&tree, Viewer::Direction([-1.0, 0.0, 0.0]), Order::FrontToBack, |n| {
//!     if n.state() == ktree::NodeState::Full {
//!         seen.push(n.cell().origin()[0]);
//!     }
//!     Walk::Descend
//! });
//! assert_eq!(seen, [1, 0]);
//! ```

use std::convert::Infallible;

use crate::space::Cell;
use crate::tree::cursor::{self, ChildOrder, Visitor};
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{NodeRef, NodeState};

/// Which way a traversal goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// Occluders before what they occlude (painting never overwrites).
    FrontToBack,
    /// Occluded before occluders (the painter's algorithm: later cells overwrite earlier ones).
    BackToFront,
}

/// Where the viewer is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Viewer<const K: usize> {
    /// A parallel (orthographic) view looking along this direction (from the viewer into the scene), in
    /// voxel coordinates.
    Direction([f64; K]),
    /// A perspective view from this eye point, in voxel coordinates.
    Eye([f64; K]),
}

pub use crate::tree::cursor::Walk;

/// The near child code for a parallel view along `dir`: bit `i` set when the viewer is on the upper side of
/// axis `i` (`dir[i] < 0`).
///
/// ```
/// use ktree::display::near_child;
/// assert_eq!(near_child([1.0, -1.0, -0.5]), 0b110);
/// ```
pub fn near_child<const K: usize>(dir: [f64; K]) -> usize {
    dir.iter()
        .enumerate()
        .fold(0, |code, (i, &d)| code | (usize::from(d < 0.0) << i))
}

/// The near child of `cell` for a perspective eye: bit `i` set when the eye is at or above the cell's centre
/// on axis `i`.
pub fn near_child_from_eye<const K: usize>(cell: &Cell<K>, eye: [f64; K]) -> usize {
    let half = cell.side() as f64 / 2.0;
    cell.origin
        .iter()
        .zip(eye.iter())
        .enumerate()
        .fold(0, |code, (i, (&o, &e))| {
            code | (usize::from(e >= f64::from(o) + half) << i)
        })
}

/// The `j`-th child code to visit (`j = 0 … 2^K − 1`) given the near child and the order.
#[inline]
pub fn child_at<const K: usize>(near: usize, j: usize, order: Order) -> usize {
    match order {
        Order::FrontToBack => near ^ j,
        Order::BackToFront => near ^ ((1 << K) - 1 - j),
    }
}

/// Visits the nodes of `tree` in pre-order with children in view order; `visit` sees every node (partial
/// nodes before their children) and may skip a subtree or stop. A [`cursor`] walk with a view order, for a
/// storage whose reads cannot fail; any storage: [`try_walk_ordered`].
///
/// ```
/// use ktree::display::{walk_ordered, Order, Viewer, Walk};
/// use ktree::{rays::ball_rays, stacking::paper::stack};
/// let tree = stack(&ball_rays::<3>(4, [16, 16, 16], 14).unwrap());
/// let mut full = 0;
/// walk_ordered(&tree, Viewer::Direction([1.0, 0.5, -0.2]), Order::FrontToBack, |n| {
///     full += usize::from(n.state() == ktree::NodeState::Full);
///     Walk::Descend
/// });
/// assert_eq!(full, tree.full_cells().count());
/// ```
pub fn walk_ordered<const K: usize, T: TreeStorage<K, Error = Infallible>>(
    tree: &T,
    viewer: Viewer<K>,
    order: Order,
    visit: impl FnMut(&NodeRef<K>) -> Walk,
) {
    infallible(try_walk_ordered(tree, viewer, order, visit));
}

/// [`walk_ordered`] over any storage: the walk ends at the first read that fails.
///
/// # Errors
/// The storage's read error.
pub fn try_walk_ordered<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    viewer: Viewer<K>,
    order: Order,
    visit: impl FnMut(&NodeRef<K>) -> Walk,
) -> Result<(), T::Error> {
    cursor::try_walk(tree, &mut ViewOrder::new(viewer, order, visit))?;
    Ok(())
}

/// A visitor in view order: wraps a per-node function and visits children front to back or back to front.
pub(crate) struct ViewOrder<const K: usize, F> {
    /// For a parallel view, the order of every node's children.
    fixed: Option<ChildOrder>,
    eye: [f64; K],
    /// `0` front to back, `2^K − 1` back to front (xored onto the near child).
    flip: usize,
    visit: F,
}

impl<const K: usize, F> ViewOrder<K, F> {
    /// Visits with `visit` in the order `order` for `viewer`.
    pub(crate) fn new(viewer: Viewer<K>, order: Order, visit: F) -> Self {
        let flip = match order {
            Order::FrontToBack => 0,
            Order::BackToFront => (1 << K) - 1,
        };
        let (fixed, eye) = match viewer {
            Viewer::Direction(d) => (Some(ChildOrder::xor::<K>(near_child(d) ^ flip)), [0.0; K]),
            Viewer::Eye(e) => (None, e),
        };
        Self {
            fixed,
            eye,
            flip,
            visit,
        }
    }
}

impl<const K: usize, F: FnMut(&NodeRef<K>) -> Walk> Visitor<K> for ViewOrder<K, F> {
    const LEAVES: bool = false;

    #[inline]
    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        (self.visit)(node)
    }

    #[inline]
    fn child_order(&self, node: &NodeRef<K>) -> ChildOrder {
        match self.fixed {
            Some(order) => order,
            None => ChildOrder::xor::<K>(near_child_from_eye(&node.cell, self.eye) ^ self.flip),
        }
    }
}

/// The full leaves of `tree` in view order (a storage whose reads cannot fail; any storage:
/// [`try_ordered_full_cells`]).
pub fn ordered_full_cells<const K: usize, T: TreeStorage<K, Error = Infallible>>(
    tree: &T,
    viewer: Viewer<K>,
    order: Order,
) -> Vec<Cell<K>> {
    infallible(try_ordered_full_cells(tree, viewer, order))
}

/// [`ordered_full_cells`] over any storage.
///
/// # Errors
/// The storage's read error.
pub fn try_ordered_full_cells<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    viewer: Viewer<K>,
    order: Order,
) -> Result<Vec<Cell<K>>, T::Error> {
    let mut out = Vec::new();
    try_walk_ordered(tree, viewer, order, |n| {
        if n.state == NodeState::Full {
            out.push(n.cell);
        }
        Walk::Descend
    })?;
    Ok(out)
}
