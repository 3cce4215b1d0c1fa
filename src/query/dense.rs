//! Dense windows: the voxels of a box as a dense array of booleans ([`dense_window`], into a buffer of
//! the caller's: [`dense_window_into`]), the box anywhere (its voxels outside the universe are outside
//! the object), in either memory order ([`DenseOrder`]): numpy's Fortran order and `KTree::to_dense`'s
//! (axis 0 fastest) or C order (the last axis fastest).
//!
//! One walk that skips the subtrees outside the box; each full leaf fills its part of the box row by row
//! along the fastest axis, so the cost is that of the box's memory plus the nodes that meet the box.
//!
//! ```
//! use ktree::query::{dense_window, DenseOrder};
//! use ktree::KTree;
//! let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i == 5 || i == 6).collect::<Vec<_>>()).unwrap();
//! // Voxels (1, 1) and (2, 1); the window [0, 3) × [1, 2) in both orders (one row: the same).
//! let row = dense_window(&tree, [0, 1], [3, 2], DenseOrder::FirstAxisFastest).unwrap();
//! assert_eq!(row, [false, true, true]);
//! // A window past the universe's corner: outside is empty.
//! let corner = dense_window(&tree, [-1, -1], [1, 1], DenseOrder::LastAxisFastest).unwrap();
//! assert_eq!(corner, [false; 4]);
//! ```

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use thiserror::Error;

use crate::space::{SpaceError, DENSE_LIMIT};
use crate::tree::cursor::{try_walk, Visitor, Walk};
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{KTree, NodeRef, NodeState, StorageError};

/// The memory order of a dense window's voxels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DenseOrder {
    /// Axis 0 fastest: the index of voxel `p` of a box of extents `n` is `p0 + n0 · (p1 + n1 · …)` (numpy's
    /// Fortran order of an array indexed `[x0, …, x(K−1)]`; [`KTree::to_dense`]'s order).
    FirstAxisFastest,
    /// The last axis fastest (numpy's C order of an array indexed `[x0, …, x(K−1)]`).
    LastAxisFastest,
}

/// Why a dense window was not made.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DenseError {
    /// The box holds more than [`DENSE_LIMIT`] voxels: ask for a smaller box.
    #[error("a window of {voxels} voxels is more than the {limit} a dense array may hold")]
    TooLarge {
        /// The voxels of the box.
        voxels: u128,
        /// The most a dense window holds.
        limit: u128,
    },
    /// Reading the tree failed (a file read in place was changed after it was opened).
    #[error(transparent)]
    Storage(#[from] StorageError),
}

/// The voxels of the box `[lo, hi)` (any coordinates: the voxels outside the universe are outside the
/// object; a box with `hi ≤ lo` on an axis holds none) as a dense array in `order`: `true` on the full
/// voxels.
///
/// # Errors
/// [`DenseError::TooLarge`] past [`DENSE_LIMIT`] voxels (checked before allocating);
/// [`DenseError::Storage`] for the storage's read error.
pub fn dense_window<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    lo: [i64; K],
    hi: [i64; K],
    order: DenseOrder,
) -> Result<Vec<bool>, DenseError> {
    let voxels = window_voxels(lo, hi);
    if voxels > DENSE_LIMIT {
        return Err(DenseError::TooLarge {
            voxels,
            limit: DENSE_LIMIT,
        });
    }
    let mut data = vec![false; voxels as usize];
    dense_window_into(tree, lo, hi, order, &mut data, true).map_err(|e| e.into())?;
    Ok(data)
}

/// The number of voxels of the box `[lo, hi)` (0 when `hi ≤ lo` on an axis).
pub fn window_voxels<const K: usize>(lo: [i64; K], hi: [i64; K]) -> u128 {
    (0..K)
        .map(|a| u128::from(hi[a].saturating_sub(lo[a]).max(0) as u64))
        .fold(1u128, u128::saturating_mul)
}

/// Writes the box `[lo, hi)` of `tree` into `data` (its [`window_voxels`], in `order`): `full` on the full
/// voxels, `!full` on every other (empty or outside the universe). [`dense_window`] with `full = true`;
/// with `full = false`, the mask of the empty voxels.
///
/// # Errors
/// The storage's read error.
///
/// # Panics
/// If `data` does not hold exactly the box's voxels.
pub fn dense_window_into<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    lo: [i64; K],
    hi: [i64; K],
    order: DenseOrder,
    data: &mut [bool],
    full: bool,
) -> Result<(), T::Error> {
    assert_eq!(
        data.len() as u128,
        window_voxels(lo, hi),
        "a dense window's buffer holds the box's voxels"
    );
    data.fill(!full);
    if data.is_empty() {
        return Ok(());
    }
    let dims: [i64; K] = std::array::from_fn(|a| hi[a] - lo[a]);
    // The other axes from the faster to the slower.
    let rest: Vec<usize> = match order {
        DenseOrder::FirstAxisFastest => (1..K).collect(),
        DenseOrder::LastAxisFastest => (0..K - 1).rev().collect(),
    };
    let mut fill = Fill {
        lo,
        hi,
        strides: strides(&dims, order),
        fastest: match order {
            DenseOrder::FirstAxisFastest => 0,
            DenseOrder::LastAxisFastest => K - 1,
        },
        rest,
        data,
        value: full,
    };
    try_walk(tree, &mut fill)?;
    Ok(())
}

/// The strides of a box of extents `dims` in `order`.
fn strides<const K: usize>(dims: &[i64; K], order: DenseOrder) -> [usize; K] {
    let mut s = [1usize; K];
    match order {
        DenseOrder::FirstAxisFastest => {
            for a in 1..K {
                s[a] = s[a - 1] * dims[a - 1] as usize;
            }
        }
        DenseOrder::LastAxisFastest => {
            for a in (0..K - 1).rev() {
                s[a] = s[a + 1] * dims[a + 1] as usize;
            }
        }
    }
    s
}

/// Sets the full cells' voxels inside the box.
struct Fill<'a, const K: usize> {
    lo: [i64; K],
    hi: [i64; K],
    strides: [usize; K],
    fastest: usize,
    rest: Vec<usize>,
    data: &'a mut [bool],
    value: bool,
}

impl<const K: usize> Visitor<K> for Fill<'_, K> {
    const LEAVES: bool = false;

    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        if node.state() == NodeState::Empty {
            return Walk::Skip;
        }
        let cell = node.cell();
        let side = cell.side() as i64;
        // The cell's part of the box, relative to the box's corner.
        let mut from = [0i64; K];
        let mut to = [0i64; K];
        for a in 0..K {
            let o = i64::from(cell.origin[a]);
            from[a] = o.max(self.lo[a]) - self.lo[a];
            to[a] = (o + side).min(self.hi[a]) - self.lo[a];
            if to[a] <= from[a] {
                return Walk::Skip;
            }
        }
        if node.state() == NodeState::Partial {
            return Walk::Descend;
        }
        // Row by row along the fastest axis: an odometer over the others.
        let f = self.fastest;
        let len = (to[f] - from[f]) as usize;
        let mut at = from;
        loop {
            let start: usize = (0..K).map(|a| at[a] as usize * self.strides[a]).sum();
            self.data[start..start + len].fill(self.value);
            let mut stepped = false;
            for &a in &self.rest {
                at[a] += 1;
                if at[a] < to[a] {
                    stepped = true;
                    break;
                }
                at[a] = from[a];
            }
            if !stepped {
                return Walk::Skip;
            }
        }
    }
}

impl<const K: usize> KTree<K> {
    /// The object as a dense boolean array of the whole universe, axis 0 fastest (see
    /// [`Universe::dense_index`](crate::Universe::dense_index); [`dense_window`] of the universe).
    ///
    /// ```
    /// use ktree::KTree;
    /// let dense = [false, true, true, true];
    /// assert_eq!(KTree::<2>::from_dense(1, &dense).unwrap().to_dense().unwrap(), dense);
    /// ```
    ///
    /// # Errors
    /// [`SpaceError::TooLargeForDense`] if the universe exceeds [`DENSE_LIMIT`] voxels.
    pub fn to_dense(&self) -> Result<Vec<bool>, SpaceError> {
        let len = self.universe().dense_len(DENSE_LIMIT)?;
        let mut dense = vec![false; len];
        let side = self.universe().side() as i64;
        infallible(dense_window_into(
            self,
            [0; K],
            [side; K],
            DenseOrder::FirstAxisFastest,
            &mut dense,
            true,
        ));
        Ok(dense)
    }
}
