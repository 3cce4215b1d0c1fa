//! A `K`-tree seen in `K − 1` dimensions: the **slice** at one position along an axis, and the
//! **projection** along an axis over a range of positions (the union of the slices in the range) — an
//! octree's floor plan between two heights, a 4-D history's 3-D map at one time or over a span of times.
//! The remaining axes keep their order. Its inverse, the **extrusion**, stretches a `K − 1`-tree over a
//! range of positions along a new axis (a 3-D region held over a span of times).
//!
//! One walk of the tree skips every subtree outside the range; the full leaves inside it, their cells
//! with the axis dropped, are nested or disjoint (they are cells of one grid), so the union is the
//! outermost of them, joined into maximal cells.
//!
//! ```
//! use ktree::ops::{project, slice};
//! use ktree::KTree;
//! // A 4 × 4 quadtree: an L of voxels.
//! let tree = KTree::<2>::from_dense(2, &[
//!     true, false, false, false, //  y = 0
//!     true, false, false, false, //  y = 1
//!     true, true, true, false,   //  y = 2
//!     false, false, false, false,
//! ]).unwrap();
//! // Along y (axis 1): which x are full in rows 0..=1, and in any row.
//! let rows: KTree<1> = project(&tree, 1, 0..2).unwrap();
//! assert_eq!(rows.to_dense().unwrap(), [true, false, false, false]);
//! let all: KTree<1> = project(&tree, 1, 0..4).unwrap();
//! assert_eq!(all.to_dense().unwrap(), [true, true, true, false]);
//! // The slice at x = 0 (axis 0): the column of y.
//! let column: KTree<1> = slice(&tree, 0, 0).unwrap();
//! assert_eq!(column.to_dense().unwrap(), [true, true, true, false]);
//! // That column held at x = 1..=2: an extrusion along a new axis 0.
//! let held: KTree<2> = ktree::ops::extrude(&column, 0, 1..3).unwrap();
//! assert_eq!(slice::<2, 1, _>(&held, 0, 2).unwrap(), column);
//! assert_eq!(slice::<2, 1, _>(&held, 0, 0).unwrap().voxel_count(), 0);
//! ```

use std::ops::Range;

use super::values::Failure;
use super::OpsError;
use crate::space::{Cell, Universe};
use crate::tree::cursor::{try_walk, Visitor, Walk};
use crate::tree::storage::TreeStorage;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::{BinaryValues, ValueState, ValueStorage};
use crate::tree::{DimensionMismatch, KTree, NodeRef, NodeState};

/// The `J = K − 1`-dimensional tree of the voxels of `tree` at `position` along `axis`.
///
/// # Errors
/// [`OpsError::BadAxis`] for an axis not below `K`; [`OpsError::SliceOutside`] for a position outside
/// the universe; [`OpsError::DimensionMismatch`] unless `J + 1 = K`; [`OpsError::Storage`] for a failed
/// read.
pub fn slice<const K: usize, const J: usize, T: TreeStorage<K>>(
    tree: &T,
    axis: usize,
    position: u32,
) -> Result<KTree<J>, OpsError> {
    check_inside(axis, position, tree.universe())?;
    project(tree, axis, position..position + 1)
}

/// The `J = K − 1`-dimensional valued tree of the voxels of a valued `tree` at `position` along `axis`,
/// each with its value: a label volume's section, a 4-D history's state at one step.
///
/// ```
/// use ktree::ops::slice_values;
/// use ktree::KTree;
/// // A 2 × 2 quadtree of labels: 1 2 in row y = 0, 3 and empty in row y = 1.
/// let tree = KTree::<2, u8>::from_dense_values(1, &[Some(1), Some(2), Some(3), None]).unwrap();
/// let row: KTree<1, u8> = slice_values(&tree, 1, 1).unwrap();
/// assert_eq!(row.to_dense_values().unwrap(), [Some(3), None]);
/// let column: KTree<1, u8> = slice_values(&tree, 0, 0).unwrap();
/// assert_eq!(column.to_dense_values().unwrap(), [Some(1), Some(3)]);
/// ```
///
/// # Errors
/// As [`slice()`].
pub fn slice_values<const K: usize, const J: usize, T: ValueStorage<K>>(
    tree: &T,
    axis: usize,
    position: u32,
) -> Result<KTree<J, T::Value>, OpsError> {
    let level = tree.level();
    check_inside(axis, position, tree.universe())?;
    down::<K, J>(axis, level)?;
    // A J-cell of side 2^s stands on the K-node of the same side whose cell holds it at `position`; its
    // child `code` stands on the K-child whose bit along `axis` is the position's bit s − 1.
    let low_bits = (1usize << axis) - 1;
    let root = InputNode::root(tree).map_err(OpsError::storage)?;
    let built = build_top_down::<J, T::Value, _, Failure<T::Error>>(
        level,
        (root, level),
        |_: &Cell<J>, (node, _): &(InputNode<T::Value>, u32)| {
            Ok(match node.state {
                ValueState::Empty => Decision::Leaf(None),
                ValueState::Full(v) => Decision::Leaf(Some(v)),
                ValueState::Partial | ValueState::Mixed => Decision::Split,
            })
        },
        |(node, log_side), code| {
            let bit = ((position >> (log_side - 1)) & 1) as usize;
            let upper = (code & low_bits) | (bit << axis) | ((code >> axis) << (axis + 1));
            let child = node.child(tree, upper).map_err(Failure::Read)?;
            Ok((child, log_side - 1))
        },
    );
    // Its level was checked and the input's values are its own: only a read can fail.
    built.map_err(|e| OpsError::storage(e.into_read()))
}

/// The `J = K − 1`-dimensional tree of the positions (the other axes' coordinates) where `tree` has a
/// full voxel at some coordinate of `range` along `axis`: the union of the slices in the range (clipped to
/// the universe; an empty range gives an empty tree).
///
/// # Errors
/// [`OpsError::BadAxis`] for an axis not below `K`; [`OpsError::DimensionMismatch`] unless `J + 1 = K`;
/// [`OpsError::Storage`] for a failed read.
pub fn project<const K: usize, const J: usize, T: TreeStorage<K>>(
    tree: &T,
    axis: usize,
    range: Range<u32>,
) -> Result<KTree<J>, OpsError> {
    let universe = down::<K, J>(axis, tree.level())?;
    struct Range1<const K: usize> {
        axis: usize,
        lo: u64,
        hi: u64,
        cells: Vec<Cell<K>>,
    }
    impl<const K: usize> Visitor<K> for Range1<K> {
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            let o = u64::from(node.cell.origin[self.axis]);
            if o >= self.hi || o + node.cell.side() <= self.lo || node.state == NodeState::Empty {
                return Walk::Skip;
            }
            if node.state == NodeState::Full {
                self.cells.push(node.cell);
                return Walk::Skip;
            }
            Walk::Descend
        }
    }
    let mut walk = Range1 {
        axis,
        lo: u64::from(range.start),
        hi: u64::from(range.end),
        cells: Vec::new(),
    };
    if range.start < range.end {
        try_walk(tree, &mut walk).map_err(|e| OpsError::Storage(e.into()))?;
    }
    let mut cells: Vec<Cell<J>> = walk
        .cells
        .iter()
        .map(|c| Cell {
            origin: std::array::from_fn(|i| c.origin[if i < axis { i } else { i + 1 }]),
            level: c.level,
            log_side: c.log_side,
        })
        .collect();
    // Nested or disjoint: sorted by Morton key, larger first where two start alike, each cell inside the
    // last one kept is dropped.
    cells.sort_unstable_by_key(|c| (c.morton(), c.level));
    let mut outer: Vec<Cell<J>> = Vec::with_capacity(cells.len());
    let mut end = 0u128;
    for c in cells {
        let key = u128::from(c.morton());
        if !outer.is_empty() && key < end {
            continue;
        }
        end = key + c.volume();
        outer.push(c);
    }
    Ok(KTree::from_sorted_cells(universe, &maximal(outer)))
}

/// The universe of level `level` in `J` dimensions, for a `K`-tree seen along `axis`.
///
/// # Errors
/// [`OpsError::DimensionMismatch`] unless `J + 1 = K`; [`OpsError::BadAxis`] for an axis not below `K`;
/// [`OpsError::LevelTooLarge`] for a level `J` dimensions cannot have.
fn down<const K: usize, const J: usize>(axis: usize, level: u32) -> Result<Universe<J>, OpsError> {
    if J + 1 != K {
        return Err(OpsError::DimensionMismatch(DimensionMismatch {
            expected: K - 1,
            found: J,
        }));
    }
    if axis >= K {
        return Err(OpsError::BadAxis { axis, k: K });
    }
    Universe::<J>::new(level).map_err(|_| OpsError::LevelTooLarge {
        k: J,
        level,
        max: crate::max_level(J),
    })
}

/// [`OpsError::SliceOutside`] for a `position` along `axis` (when below `K`) outside `universe`.
fn check_inside<const K: usize>(
    axis: usize,
    position: u32,
    universe: Universe<K>,
) -> Result<(), OpsError> {
    let side = universe.side();
    if axis < K && u64::from(position) >= side {
        return Err(OpsError::SliceOutside {
            axis,
            position,
            side,
        });
    }
    Ok(())
}

/// The `K = J + 1`-dimensional tree of the voxels whose coordinate along `axis` lies in `range` (clipped
/// to the universe) and whose other coordinates, in order, are a full voxel of `tree`: `tree` held over
/// the range. Its projection over the range gives `tree` back (for a range that is not empty).
///
/// # Errors
/// [`OpsError::BadAxis`] for an axis not below `K`; [`OpsError::DimensionMismatch`] unless `J + 1 = K`;
/// [`OpsError::LevelTooLarge`] for a level `K` dimensions cannot have; [`OpsError::Storage`] for a failed
/// read.
pub fn extrude<const J: usize, const K: usize, T: TreeStorage<J>>(
    tree: &T,
    axis: usize,
    range: Range<u32>,
) -> Result<KTree<K>, OpsError> {
    if J + 1 != K {
        return Err(OpsError::DimensionMismatch(DimensionMismatch {
            expected: J + 1,
            found: K,
        }));
    }
    if axis >= K {
        return Err(OpsError::BadAxis { axis, k: K });
    }
    let level = tree.level();
    Universe::<K>::new(level).map_err(|_| OpsError::LevelTooLarge {
        k: K,
        level,
        max: crate::max_level(K),
    })?;
    let (lo, hi) = (u64::from(range.start), u64::from(range.end));
    // The child of a K-cell without its bit along `axis` is the child of the J-cell it stands on.
    let low_bits = (1usize << axis) - 1;
    let built = build_top_down::<K, (), _, Failure<T::Error>>(
        level,
        InputNode::root(&BinaryValues(tree)).map_err(OpsError::storage)?,
        |cell: &Cell<K>, node: &InputNode<()>| {
            let o = u64::from(cell.origin[axis]);
            let end = o + cell.side();
            if o >= hi || end <= lo {
                return Ok(Decision::Leaf(None));
            }
            Ok(match node.state {
                ValueState::Empty => Decision::Leaf(None),
                ValueState::Full(()) if lo <= o && end <= hi => Decision::Leaf(Some(())),
                _ => Decision::Split,
            })
        },
        |node, code| {
            let lower = (code & low_bits) | ((code >> (axis + 1)) << axis);
            node.child(&BinaryValues(tree), lower)
                .map_err(Failure::Read)
        },
    );
    // Its level was checked, it splits no voxel and holds no value: only a read can fail.
    built.map_err(|e| OpsError::storage(e.into_read()))
}

/// Joins every complete block of `2^J` sibling cells into their parent, repeatedly. `cells` must be
/// disjoint and sorted by Morton key.
fn maximal<const J: usize>(cells: Vec<Cell<J>>) -> Vec<Cell<J>> {
    let n = 1usize << J;
    let mut out: Vec<Cell<J>> = Vec::with_capacity(cells.len());
    for cell in cells {
        out.push(cell);
        while out.len() >= n {
            let first = out[out.len() - n];
            if first.level == 0 {
                break;
            }
            let parent_side = first.side() * 2;
            let block = &out[out.len() - n..];
            let complete = first
                .origin
                .iter()
                .all(|&c| u64::from(c) % parent_side == 0)
                && block.iter().enumerate().all(|(i, c)| {
                    c.level == first.level
                        && u128::from(c.morton())
                            == u128::from(first.morton()) + i as u128 * first.volume()
                });
            if !complete {
                break;
            }
            out.truncate(out.len() - n);
            out.push(Cell {
                origin: first.origin,
                level: first.level - 1,
                log_side: first.log_side + 1,
            });
        }
    }
    out
}
