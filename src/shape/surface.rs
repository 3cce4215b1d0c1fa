//! The surface area: the number of `(K − 1)`-faces between a full voxel and an empty one, counted on the
//! tree's nodes, never on its voxels or runs, so that it scales to the whole universe.
//!
//! # Method
//! Along each axis `a`, every full voxel has two faces, less two for each pair of full voxels adjacent
//! along `a`: `faces_a = 2N − 2·pairs_a`. `N` is known from the node counts per level. A pair lies inside
//! one full leaf (a leaf of side `s` holds `s^(K−1)·(s − 1)` of them along each axis: from the counts, no
//! walk) or across the face shared by two sibling cells whose codes differ in bit `a`, where it is counted
//! by descending both cells together along that face only: two full cells share a whole face, a full cell
//! and a partial one the full voxels of the partial one's face, two partial cells their children across
//! the face. Every node lies on the faces of at most `2K` such descents, so the cost is `O(K · nodes)`:
//! a full leaf of side `2^19` costs one step, not `2^38`. The siblings are read level by level, block
//! after block, so a tree read in place from a file is read in order.

use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{KTree, NodeState};

/// The number of faces between a full voxel and an empty one across each axis (the faces perpendicular
/// to it), outside the universe counting as empty; their sum is [`surface_area`].
///
/// ```
/// use ktree::{shape::faces_per_axis, KTree};
/// // A 2 × 1 domino in 2-D: 2 faces across axis 0, 4 across axis 1.
/// let tree = KTree::<2>::from_dense(1, &[true, true, false, false]).unwrap();
/// assert_eq!(faces_per_axis(&tree), Ok([2, 4]));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn faces_per_axis<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<[u128; K], T::Error> {
    let level = tree.level();
    let per_level = tree.counts_per_level();
    let voxels = tree.voxel_count();
    // The pairs inside the full leaves, the same along every axis.
    let inside: u128 = per_level
        .iter()
        .enumerate()
        .map(|(depth, counts)| {
            let log_side = level - depth as u32;
            let s = 1u128 << log_side;
            (u128::from(counts.full) * (s - 1)) << (log_side as usize * (K - 1))
        })
        .sum();
    let mut across = [0u128; K];
    let fanout = 1usize << K;
    for depth in 1..tree.depth_count() {
        let log_side = level - depth as u32;
        for first in (0..tree.level_len(depth)).step_by(fanout) {
            let codes = tree.block_codes(depth, first)?;
            let state = |code: usize| NodeState::from_bits(codes >> (2 * code));
            for (axis, pairs) in across.iter_mut().enumerate() {
                for low in (0..fanout).filter(|c| c >> axis & 1 == 0) {
                    let high = low | 1 << axis;
                    *pairs += pairs_across(
                        tree,
                        depth,
                        (first + low, state(low)),
                        (first + high, state(high)),
                        axis,
                        log_side,
                    )?;
                }
            }
        }
    }
    Ok(across.map(|pairs| 2 * voxels - 2 * (inside + pairs)))
}

/// The pairs of full voxels adjacent along `axis` across the face between two nodes of level `depth` and
/// side `2^log_side`: `low` below `high` on `axis`, the face between them. Each is `(index, state)`.
fn pairs_across<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    depth: usize,
    low: (usize, NodeState),
    high: (usize, NodeState),
    axis: usize,
    log_side: u32,
) -> Result<u128, T::Error> {
    use NodeState::{Empty, Full, Partial};
    Ok(match (low.1, high.1) {
        (Empty, _) | (_, Empty) => 0,
        (Full, Full) => 1u128 << (log_side as usize * (K - 1)),
        // The full voxels of the partial node's face towards the full one.
        (Full, Partial) => full_on_face(tree, depth, high.0, axis, false, log_side)?,
        (Partial, Full) => full_on_face(tree, depth, low.0, axis, true, log_side)?,
        (Partial, Partial) => {
            let (first_low, first_high) = (
                tree.first_child(depth, low.0)?,
                tree.first_child(depth, high.0)?,
            );
            let codes_low = tree.block_codes(depth + 1, first_low)?;
            let codes_high = tree.block_codes(depth + 1, first_high)?;
            let mut pairs = 0;
            // The children of `low` on its upper side against those of `high` on its lower side.
            for code in (0..1usize << K).filter(|c| c >> axis & 1 == 0) {
                let up = code | 1 << axis;
                pairs += pairs_across(
                    tree,
                    depth + 1,
                    (first_low + up, NodeState::from_bits(codes_low >> (2 * up))),
                    (
                        first_high + code,
                        NodeState::from_bits(codes_high >> (2 * code)),
                    ),
                    axis,
                    log_side - 1,
                )?;
            }
            pairs
        }
    })
}

/// The full voxels on the face of the partial node `index` of level `depth` (side `2^log_side`) at its
/// upper (`upper`) or lower end of `axis`.
fn full_on_face<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    depth: usize,
    index: usize,
    axis: usize,
    upper: bool,
    log_side: u32,
) -> Result<u128, T::Error> {
    let first = tree.first_child(depth, index)?;
    let codes = tree.block_codes(depth + 1, first)?;
    let mut full = 0;
    for code in (0..1usize << K).filter(|c| (c >> axis & 1 == 1) == upper) {
        full += match NodeState::from_bits(codes >> (2 * code)) {
            NodeState::Empty => 0,
            NodeState::Full => 1u128 << ((log_side - 1) as usize * (K - 1)),
            NodeState::Partial => {
                full_on_face(tree, depth + 1, first + code, axis, upper, log_side - 1)?
            }
        };
    }
    Ok(full)
}

/// The number of `(K − 1)`-faces between a full voxel and an empty one, outside the universe counting as
/// empty: the perimeter for `K = 2`, the count of boundary squares for `K = 3`. Counted on the tree's nodes
/// (full leaves from the counts per level, pairs across sibling faces by descending both sides of the face
/// only): `O(K · nodes)`, whatever the size of the leaves.
///
/// ```
/// use ktree::{shape::surface_area, KTree};
/// assert_eq!(surface_area(&KTree::<3>::full(21).unwrap()), Ok(6 << 42));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn surface_area<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<u128, T::Error> {
    Ok(faces_per_axis(tree)?.iter().sum())
}

/// The number of runs along the last axis of the tree's full voxels — of [`rays_of`](crate::tree::rays_of)
/// — without making them: half the faces across the last axis (each run has one where it starts and one
/// where it ends).
///
/// ```
/// use ktree::{shape::run_count, KTree};
/// assert_eq!(run_count(&KTree::<3>::full(21).unwrap()), Ok(1 << 42));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn run_count<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<u128, T::Error> {
    Ok(faces_per_axis(tree)?[K - 1] / 2)
}

impl<const K: usize> KTree<K> {
    /// The number of `(K − 1)`-faces between a full voxel and an empty one, outside the universe counting
    /// as empty: the perimeter for `K = 2`, the count of boundary squares for `K = 3` ([`surface_area`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// assert_eq!(KTree::<2>::full(2).unwrap().surface_area(), 16);
    /// assert_eq!(KTree::<3>::full(1).unwrap().surface_area(), 24);
    /// ```
    ///
    /// # Performance
    /// `O(K · nodes)`, on the nodes alone (see [`crate::shape`]'s surface notes).
    pub fn surface_area(&self) -> u128 {
        infallible(surface_area(self))
    }
}
