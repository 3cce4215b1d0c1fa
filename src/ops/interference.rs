//! Interference detection in any dimension (Meagher §3, claim M14): do two objects share a voxel, which
//! cells do, and — for space-time trees — the first time step at which they meet.
//!
//! A simultaneous traversal like the Booleans', stopping at the first full–full or full–partial pair.
//! Both trees are pre-sorted, so no search is needed: cost linear in the nodes reached, usually far fewer.
//! The trees are read through any storages with one read error type (two trees in memory, two mapped
//! files, …).

use super::boolean::{intersection, same_level};
use super::OpsError;
use crate::space::Cell;
use crate::tree::cursor::{try_walk_pair, ChildOrder, PairNode, PairVisitor, Walk};
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// Whether the objects share at least one voxel (regularized: touching along a face is not interference).
/// Stops at the first overlap found.
///
/// ```
/// use ktree::{KTree, ops::interferes};
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(2, &[false, false, true, false]).unwrap();
/// assert!(!interferes(&a, &b).unwrap()); // they touch, they do not overlap
/// ```
///
/// # Errors
/// [`OpsError::LevelMismatch`] when the trees' levels differ; [`OpsError::Storage`] if a read fails.
pub fn interferes<const K: usize, A, B>(a: &A, b: &B) -> Result<bool, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    same_level(a, b)?;
    let mut meet = Meet(false);
    try_walk_pair(a, b, &mut meet).map_err(OpsError::storage)?;
    Ok(meet.0)
}

/// The interference test as a two-tree walk: stops at the first pair of a full node and a non-empty one.
struct Meet(bool);

impl<const K: usize> PairVisitor<K> for Meet {
    const ORIGINS: bool = false;

    #[inline]
    fn visit(&mut self, pair: &PairNode<K>) -> Walk {
        match (pair.a.state, pair.b.state) {
            (NodeState::Empty, _) | (_, NodeState::Empty) => Walk::Skip,
            (NodeState::Partial, NodeState::Partial) => Walk::Descend,
            // Full against anything non-empty: a reduced partial node holds at least one full voxel.
            _ => {
                self.0 = true;
                Walk::Stop
            }
        }
    }
}

/// The cells where the objects overlap (the full leaves of `A ∩ B`), in Morton order.
///
/// # Errors
/// As [`interferes`].
pub fn overlap_cells<const K: usize, A, B>(a: &A, b: &B) -> Result<Vec<Cell<K>>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    Ok(intersection(a, b)?.full_cells().collect())
}

/// For trees whose axis `time_axis` is time (e.g. 4-D space-time trees `(x, y, z, t)`): the first time
/// step at which the two objects share a voxel, or `None` if they never do. Descends into the children
/// with the lower `time_axis` half first and stops at the first overlap, so it visits few nodes.
///
/// # Errors
/// As [`interferes`]; [`OpsError::BadAxis`] if `time_axis ≥ K`.
pub fn first_contact<const K: usize, A, B>(
    a: &A,
    b: &B,
    time_axis: usize,
) -> Result<Option<u32>, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    same_level(a, b)?;
    if time_axis >= K {
        return Err(OpsError::BadAxis {
            axis: time_axis,
            k: K,
        });
    }
    let mut query = Earliest {
        axis: time_axis,
        order: ChildOrder::lower_half_first::<K>(time_axis),
        best: None,
    };
    try_walk_pair(a, b, &mut query).map_err(OpsError::storage)?;
    Ok(query.best)
}

/// The first contact as a two-tree walk, lower time half first: a pair of full nodes is a contact at the
/// cell's first time step; pairs starting no earlier than the best contact so far are skipped.
struct Earliest {
    axis: usize,
    order: ChildOrder,
    best: Option<u32>,
}

impl<const K: usize> PairVisitor<K> for Earliest {
    fn visit(&mut self, pair: &PairNode<K>) -> Walk {
        let t0 = pair.cell.origin[self.axis];
        if self.best.is_some_and(|b| b <= t0) {
            return Walk::Skip;
        }
        match (pair.a.state, pair.b.state) {
            (NodeState::Empty, _) | (_, NodeState::Empty) => Walk::Skip,
            (NodeState::Full, NodeState::Full) => {
                self.best = Some(t0);
                Walk::Skip
            }
            _ => Walk::Descend,
        }
    }

    fn child_order(&self, _pair: &PairNode<K>) -> ChildOrder {
        self.order
    }
}

/// How two objects meet: whether they share a voxel, how much, when (along a time axis) and, apart,
/// how far (the keys of `ktree collide --json`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Collision {
    /// Whether the objects share a voxel.
    pub collide: bool,
    /// The leaves of their intersection.
    pub overlap_cells: usize,
    /// The voxels they share.
    pub overlap_voxels: u128,
    /// The first position along the time axis (if one was given) at which they overlap.
    pub first_contact: Option<u32>,
    /// The smallest distance between voxel centres of the two objects, in voxels: 0 when they overlap,
    /// `None` when one is empty.
    pub min_separation: Option<f64>,
}

/// How `a` and `b` meet ([`Collision`]); `time_axis`, if given, is the axis whose first overlapping
/// position is reported.
///
/// ```
/// use ktree::{ops::collision, KTree};
/// let a = KTree::<1>::from_dense(3, &[true, true, false, false, false, false, false, false]).unwrap();
/// let b = KTree::<1>::from_dense(3, &[false, false, false, false, false, true, false, false]).unwrap();
/// let c = collision(&a, &b, None).unwrap();
/// assert!(!c.collide);
/// assert_eq!(c.min_separation, Some(4.0));
/// assert_eq!(collision(&a, &a, Some(0)).unwrap().first_contact, Some(0));
/// ```
///
/// # Errors
/// As [`interferes`]; a time axis not below `K`.
pub fn collision<const K: usize, A, B>(
    a: &A,
    b: &B,
    time_axis: Option<usize>,
) -> Result<Collision, OpsError>
where
    A: TreeStorage<K>,
    B: TreeStorage<K, Error = A::Error>,
{
    let overlap = intersection(a, b)?;
    let collide = overlap.root_state() != NodeState::Empty;
    let first_contact = match time_axis {
        Some(axis) => first_contact(a, b, axis)?,
        None => None,
    };
    let min_separation = if collide {
        Some(0.0)
    } else {
        super::min_separation(a, b)?
    };
    Ok(Collision {
        collide,
        overlap_cells: overlap.full_cells().count(),
        overlap_voxels: overlap.voxel_count(),
        first_contact,
        min_separation,
    })
}
