//! A valued tree written level by level with its cells' subtrees spilled: the box of a [`ValueSlabs`] is
//! read slab by slab as [`KTree::from_value_slabs`](crate::KTree::from_value_slabs) reads it, each cell of
//! depth `m` built apart, and the levels below a cell with children go to a [`PieceStore`] at once — the
//! cell keeps only its root. Once every slab is read, the top levels (down to the cells) are written to a
//! [`ValuedLevelSink`], then each level below them, its pieces read back in the Morton order of their
//! cells: its codes first, then its full nodes' values, as a `.ktree` version 3 section lies. Memory held:
//! one slab, its cells' subtrees until they are spilled, the top levels (at most `2^(K·m)` cells, about 16
//! million) and an index of two counts a spilled cell and level.
//!
//! A piece of level `j` of a cell is its `⌈n / 32⌉` words of codes (as
//! [`PackedStates::words`](crate::tree::PackedStates::words)) followed by the `f` values of its full nodes,
//! little-endian ([`Value::write_le`]), zero-padded to whole words. The build is that of one part of
//! [`ValueSlabs::stack_part`]: every slab in it.

use std::ops::Range;

use super::out_of_core::{BuildError, PieceStore};
use super::value_slabs::ValueSlabs;
use crate::rays::RayError;
use crate::tree::LevelCounts;
use crate::value::Value;

/// The output of a valued build written level by level, from the root down, each level as its section of
/// a `.ktree` version 3 file lies: its codes (in one or more runs of consecutive nodes, packed as in
/// [`PackedStates::words`](crate::tree::PackedStates::words)), [`end_codes`](Self::end_codes), the values of its full nodes in level order
/// as little-endian bytes, [`end_level`](Self::end_level). `io` implements it with the version 3 writer
/// (`ValuedKtreeWriter`).
pub trait ValuedLevelSink {
    /// Why the output could not be written.
    type Error;
    /// What the finished output is.
    type Output;

    /// Appends `nodes` nodes packed in `words` (at least `⌈nodes / 32⌉` words) to the current level's
    /// codes.
    ///
    /// # Errors
    /// The output's error.
    fn append_words(&mut self, words: &[u64], nodes: u64) -> Result<(), Self::Error>;

    /// Closes the current level's codes: its values come next.
    ///
    /// # Errors
    /// The output's error.
    fn end_codes(&mut self) -> Result<(), Self::Error>;

    /// Appends values of the current level's full nodes (whole values, little-endian).
    ///
    /// # Errors
    /// The output's error.
    fn append_values(&mut self, bytes: &[u8]) -> Result<(), Self::Error>;

    /// Closes the current level: the next append starts the level below.
    ///
    /// # Errors
    /// The output's error.
    fn end_level(&mut self) -> Result<(), Self::Error>;

    /// The node counts of the levels closed so far (`level` = depth).
    fn counts_per_level(&self) -> Vec<LevelCounts>;

    /// Ends the output (every level was closed).
    ///
    /// # Errors
    /// The output's error.
    fn finish(self) -> Result<Self::Output, Self::Error>;
}

/// What a valued build written level by level did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValueSlabsReport {
    /// The tree's node counts per level (`level` = depth).
    pub counts_per_level: Vec<LevelCounts>,
    /// The size of the file written, in bytes (0 from [`ValueSlabs::build_into`], whose output is not
    /// necessarily a file).
    pub file_bytes: u64,
    /// The depth `m` of the cells built apart.
    pub cell_depth: u32,
    /// Cells of depth `m` with children, their subtrees spilled.
    pub subtrees: u64,
    /// Bytes written to the [`PieceStore`].
    pub spilled_bytes: u64,
}

impl<const K: usize, V: Value + Send + Sync> ValueSlabs<K, V> {
    /// Builds the tree of the box `read` gives (as [`KTree::from_value_slabs`](crate::KTree::from_value_slabs)
    /// does) into `sink`, level by level from the root down, the subtrees of its cells of depth `m`
    /// spilled to `store` as they are built. Memory held: one slab, its cells' subtrees until they are
    /// spilled, the top levels down to the cells (at most about 16 million) and two counts a spilled cell
    /// and level. The levels `sink` receives are those of the tree `from_value_slabs` makes.
    ///
    /// ```
    /// use ktree::io::ktree::v3::read_valued_ktree;
    /// use ktree::io::ktree::{Notes, v3::ValuedKtreeWriter};
    /// use ktree::stacking::ValueSlabs;
    /// use ktree::KTree;
    /// // A 6 × 5 box of labels at (1, 2) in a quadtree of level 3, read two rows at a time.
    /// let label = |x: u32, y: u32| ((x / 2 + y) % 3) as u8;
    /// let read = |rows: std::ops::Range<u32>, out: &mut Vec<u8>| {
    ///     out.extend(rows.flat_map(|y| (1..7).map(move |x| label(x, y))));
    ///     Ok::<_, ktree::rays::RayError>(())
    /// };
    /// let slabs = ValueSlabs { level: 3, region: [1..7, 2..7], background: 0u8, slab_bytes: 12 };
    /// let tree = KTree::<2, u8>::from_value_slabs(3, [1..7, 2..7], 0, 12, read).unwrap();
    /// # // The store and the output of PieceStore's example, with values.
    /// # use ktree::stacking::{LevelPieces, PieceStore, StoredPieces};
    /// # #[derive(Default)]
    /// # struct InMemory(Vec<Vec<u64>>);
    /// # impl PieceStore for InMemory {
    /// #     type Error = std::io::Error;
    /// #     type Stored = InMemory;
    /// #     fn append(&mut self, depth: usize, words: &[u64], _nodes: u64) -> std::io::Result<()> {
    /// #         if self.0.len() < depth { self.0.resize(depth, Vec::new()); }
    /// #         self.0[depth - 1].extend_from_slice(words);
    /// #         Ok(())
    /// #     }
    /// #     fn finish(self) -> std::io::Result<InMemory> { Ok(self) }
    /// # }
    /// # struct Level<'a> { words: Vec<u64>, offsets: &'a [u64] }
    /// # impl StoredPieces for InMemory {
    /// #     type Error = std::io::Error;
    /// #     type Level<'a> = Level<'a>;
    /// #     fn level<'a>(&'a mut self, depth: usize, offsets: &'a [u64], _words: u64) -> Level<'a> {
    /// #         let words = self.0.get_mut(depth - 1).map(std::mem::take).unwrap_or_default();
    /// #         Level { words, offsets }
    /// #     }
    /// # }
    /// # impl LevelPieces for Level<'_> {
    /// #     type Error = std::io::Error;
    /// #     fn read(&mut self, piece: usize, at: u64, out: &mut [u64]) -> std::io::Result<()> {
    /// #         let start = (self.offsets[piece] + at) as usize;
    /// #         out.copy_from_slice(&self.words[start..start + out.len()]);
    /// #         Ok(())
    /// #     }
    /// #     fn finish(self) {}
    /// # }
    /// let writer = ValuedKtreeWriter::new(Vec::new(), 2, 3, ktree::value::Dtype::U8, None, &Notes::new())?;
    /// let (bytes, report) = slabs.build_into(read, InMemory::default(), writer).unwrap();
    /// assert_eq!(read_valued_ktree::<2, u8>(&bytes, "mem").unwrap(), tree);
    /// assert_eq!(report.counts_per_level, tree.counts_per_level());
    /// # Ok::<(), std::io::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`BuildError::Source`]: the first error of `read`, or what `from_value_slabs` refuses (a level
    /// beyond the largest, a box reaching outside the universe, a NaN, a slab of the wrong length);
    /// [`BuildError::Files`]: the store's or the output's error.
    pub fn build_into<E, P, O>(
        &self,
        read: impl FnMut(Range<u32>, &mut Vec<V>) -> Result<(), E>,
        store: P,
        sink: O,
    ) -> Result<(O::Output, ValueSlabsReport), BuildError<E, P::Error>>
    where
        E: From<RayError>,
        P: PieceStore,
        O: ValuedLevelSink<Error = P::Error>,
    {
        let slabs = 0..self.slab_count();
        self.stack_part(slabs, read, store)?
            .write_into(sink, |_, _: &mut [u64]| {
                unreachable!("a build in one part receives nothing")
            })
    }
}
