//! Runs gathered from pieces: the pieces of runs that a walk of a tree (or a block-by-block computation)
//! finds, slab by slab along the first axis, sorted into a [`RaySet`] and joined where they touch.

use super::RaySet;
use crate::radix;
use crate::space::Universe;

/// Runs gathered slab by slab along the first axis (slabs of a power-of-two width, appended in order):
/// each slab's pieces `(column key, z1, z2)` come with every column's pieces in order along it, so one
/// stable radix sort by the column alone orders them, and the pieces of a column that touch are joined.
///
/// Only one slab's pieces are held at a time: the memory is that of the runs plus a slab's share of the
/// pieces.
pub(crate) struct RunGatherer<const K: usize> {
    /// A column key less its slab's first key is below `2^key_bits`.
    key_bits: u32,
    /// Bits of the column key below the first axis.
    inner_bits: u32,
    columns: Vec<u64>,
    runs: Vec<(u32, u32)>,
    scratch: Vec<(u64, u32, u32)>,
}

impl<const K: usize> RunGatherer<K> {
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

    /// Appends the pieces of the slab starting at `start` on the first axis (after every earlier slab's),
    /// sorting `pieces` on the way.
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
