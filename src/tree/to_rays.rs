//! A tree back to rays: the runs of its full voxels along the last axis.
//!
//! The runs are gathered slab by slab along the first axis (up to [`SLABS`] slabs): a walk that skips the
//! subtrees outside the slab lists each full leaf's column pieces, which are sorted by column and joined
//! into the slab's runs. The walk goes depth first in child order, so the pieces of one column already come
//! in order along it (two leaves over the same column part at an ancestor whose children differ only in
//! the last axis's bit): a stable radix sort by the column alone puts them in order. Only one slab's pieces are held at a time, so the memory is that of the runs plus a slab's
//! share of the pieces (a column crosses a piece per full leaf above it, many more than it has runs).

use crate::radix;
use crate::rays::RaySet;
use crate::space::Universe;
use crate::tree::cursor::{walk, Visitor, Walk};
use crate::tree::{KTree, NodeRef, NodeState};

/// At most this many slabs along the first axis.
const SLABS: u64 = 64;

impl<const K: usize> KTree<K> {
    /// The runs along the last axis of a tree's full voxels: the ray set that stacks back to the tree.
    ///
    /// ```
    /// use ktree::{stacking::paper::stack, rays::ball_rays};
    /// let rays = ball_rays::<3>(5, [16, 16, 16], 11).unwrap();
    /// assert_eq!(stack(&rays).to_rays(), rays);
    /// ```
    pub fn to_rays(&self) -> RaySet<K> {
        let universe = self.universe();
        let level = universe.level();
        let side = universe.side();
        // K = 1 has one column, the last axis itself: one slab.
        let width = if K == 1 { side } else { (side / SLABS).max(1) };
        let mut out = SlabRuns::<K>::new(level, width);
        let mut pieces = Vec::new();
        let mut start = 0;
        while start < side {
            let end = (start + width).min(side);
            pieces.clear();
            let mut slab = SlabPieces::<K> {
                slab: (start as u32, end as u32),
                level,
                pieces: &mut pieces,
            };
            walk(self, &mut slab);
            out.append(start, &mut pieces);
            start = end;
        }
        out.finish(universe)
    }
}

/// Runs gathered slab by slab along the first axis (slabs of a power-of-two width, in order): each slab's
/// pieces `(column key, z1, z2)` come with every column's pieces in order along it, so one stable radix
/// sort by the column alone orders them, and touching pieces of a column are joined.
pub(crate) struct SlabRuns<const K: usize> {
    /// A column key less its slab's first key is below `2^key_bits`.
    key_bits: u32,
    /// Bits of the column key below the first axis.
    inner_bits: u32,
    columns: Vec<u64>,
    runs: Vec<(u32, u32)>,
    scratch: Vec<(u64, u32, u32)>,
}

impl<const K: usize> SlabRuns<K> {
    /// For a universe of level `level`, slabs `width` (a power of two) wide.
    pub(crate) fn new(level: u32, width: u64) -> Self {
        let inner_bits = level * (K.max(2) as u32 - 2);
        let key_bits = if K == 1 {
            0
        } else {
            width.trailing_zeros() + inner_bits
        };
        Self {
            key_bits,
            inner_bits,
            columns: Vec::new(),
            runs: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// Appends the pieces of the slab starting at `start` on the first axis (after every earlier slab's).
    pub(crate) fn append(&mut self, start: u64, pieces: &mut Vec<(u64, u32, u32)>) {
        let base = if K == 1 { 0 } else { start << self.inner_bits };
        radix::sort_by_key(pieces, self.key_bits, &mut self.scratch, |p| p.0 - base);
        for &(column, z1, z2) in pieces.iter() {
            if let (Some(&last_column), Some(last)) = (self.columns.last(), self.runs.last_mut()) {
                if last_column == column {
                    debug_assert!(z1 >= last.1, "pieces of a column in order");
                    if z1 == last.1 {
                        last.1 = z2;
                        continue;
                    }
                }
            }
            self.columns.push(column);
            self.runs.push((z1, z2));
        }
    }

    /// The runs gathered, as a ray set of `universe`.
    pub(crate) fn finish(self, universe: Universe<K>) -> RaySet<K> {
        RaySet::from_sorted_parts(universe, self.columns, self.runs, None)
    }
}

/// Lists, as `(column key, z1, z2)`, the column pieces of the full leaves within a slab `x0 ≤ x < x1` of
/// the first axis (the whole universe for K = 1).
struct SlabPieces<'a, const K: usize> {
    slab: (u32, u32),
    level: u32,
    pieces: &'a mut Vec<(u64, u32, u32)>,
}

impl<const K: usize> Visitor<K> for SlabPieces<'_, K> {
    const LEAVES: bool = false;

    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        let cell = node.cell;
        let side = 1u32 << cell.log_side;
        let origin = cell.origin;
        let (x0, x1) = if K == 1 {
            (0, u32::MAX)
        } else {
            (
                origin[0].max(self.slab.0),
                (origin[0] + side).min(self.slab.1),
            )
        };
        if x0 >= x1 {
            return Walk::Skip;
        }
        if node.state != NodeState::Full {
            return Walk::Descend;
        }
        let (z1, z2) = (origin[K - 1], origin[K - 1] + side);
        // Every column of the cell within the slab: an odometer over the first K − 1 axes.
        let mut column = origin;
        if K > 1 {
            column[0] = x0;
        }
        loop {
            let key = column[..K - 1]
                .iter()
                .fold(0u64, |key, &c| (key << self.level) | u64::from(c));
            self.pieces.push((key, z1, z2));
            let mut axis = 0;
            while axis + 1 < K {
                column[axis] += 1;
                let end = if axis == 0 { x1 } else { origin[axis] + side };
                if column[axis] < end {
                    break;
                }
                column[axis] = if axis == 0 { x0 } else { origin[axis] };
                axis += 1;
            }
            if axis + 1 >= K {
                break;
            }
        }
        Walk::Skip
    }
}
