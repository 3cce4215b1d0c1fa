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
//! little-endian ([`Value::write_le`]), zero-padded to whole words.

use std::ops::Range;

use rayon::prelude::*;

use super::out_of_core::{BuildError, LevelPieces, PieceStore, StoredPieces};
use super::value_slabs::{spread_across, ValueSlabs};
use crate::rays::RayError;
use crate::tree::top_down::PackedLevel;
use crate::tree::LevelCounts;
use crate::value::Value;

/// Words read back at once: a multiple of 3, so that as many bytes of values are whole values of 1, 2, 3
/// or 4 bytes.
const CHUNK_WORDS: usize = 3 << 13;

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

/// Why reading the slabs stopped: the source's error or the store's.
enum Stop<E, F> {
    Source(E),
    Store(F),
}

impl<E: From<RayError>, F> From<RayError> for Stop<E, F> {
    fn from(e: RayError) -> Self {
        Stop::Source(E::from(e))
    }
}

impl<E, F> From<Stop<E, F>> for BuildError<E, F> {
    fn from(stop: Stop<E, F>) -> Self {
        match stop {
            Stop::Source(e) => BuildError::Source(e),
            Stop::Store(f) => BuildError::Files(f),
        }
    }
}

/// The spilled cells, in the order they were spilled: each one's Morton index among the cells of depth
/// `m`, and per level `1 … t` below it its node count and full node count (0 beyond its depth).
struct SpillIndex {
    t: usize,
    mortons: Vec<u64>,
    counts: Vec<[u64; 2]>,
}

impl SpillIndex {
    /// The words of cell `s`'s piece of level `j`: codes, then values of `value_bytes` bytes each.
    fn piece_words(&self, s: usize, j: usize, value_bytes: u64) -> (u64, u64) {
        let [nodes, full] = self.counts[s * self.t + j - 1];
        (nodes.div_ceil(32), (full * value_bytes).div_ceil(8))
    }
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
        mut read: impl FnMut(Range<u32>, &mut Vec<V>) -> Result<(), E>,
        mut store: P,
        mut sink: O,
    ) -> Result<(O::Output, ValueSlabsReport), BuildError<E, P::Error>>
    where
        E: From<RayError>,
        P: PieceStore,
        O: ValuedLevelSink<Error = P::Error>,
    {
        let m = self.cell_depth();
        let t = (self.level - m) as usize;
        let value_bytes = V::DTYPE.map_or(0, |d| d.bytes()) as u64;
        let mut index = SpillIndex {
            t,
            mortons: Vec::new(),
            counts: Vec::new(),
        };
        let mut spilled_words = 0u64;
        let mut piece = Vec::new();
        let top = self.stack::<Stop<E, P::Error>>(
            |rows, out| read(rows, out).map_err(Stop::Source),
            |b, cells| {
                let levels: Vec<Option<Vec<PackedLevel<V>>>> = cells
                    .par_iter_mut()
                    .map(|cell| cell.root().has_children().then(|| cell.take_levels_below()))
                    .collect();
                for (i, levels) in levels.into_iter().enumerate() {
                    let Some(levels) = levels else { continue };
                    index
                        .mortons
                        .push(spread_across::<K>(i as u64) | spread_last::<K>(b));
                    for j in 1..=t {
                        let Some((codes, values)) = levels.get(j - 1) else {
                            index.counts.push([0, 0]);
                            continue;
                        };
                        piece.clear();
                        piece.extend_from_slice(codes.words());
                        piece.extend(value_words(values));
                        store
                            .append(j, &piece, codes.len() as u64)
                            .map_err(Stop::Store)?;
                        spilled_words += piece.len() as u64;
                        index.counts.push([codes.len() as u64, values.len() as u64]);
                    }
                }
                Ok(())
            },
        )?;
        let mut stored = store.finish()?;
        for (codes, values) in top.into_packed_levels() {
            sink.append_words(codes.words(), codes.len() as u64)?;
            sink.end_codes()?;
            sink.append_values(&value_bytes_of(&values))?;
            sink.end_level()?;
        }
        let mut order: Vec<usize> = (0..index.mortons.len()).collect();
        order.sort_unstable_by_key(|&s| index.mortons[s]);
        let mut offsets = vec![0u64; order.len()];
        let mut words = vec![0u64; CHUNK_WORDS];
        let mut bytes = Vec::with_capacity(8 * CHUNK_WORDS);
        for j in 1..=t {
            if order.iter().all(|&s| index.counts[s * t + j - 1][0] == 0) {
                break;
            }
            let mut at = 0;
            for (s, offset) in offsets.iter_mut().enumerate() {
                *offset = at;
                let (codes, values) = index.piece_words(s, j, value_bytes);
                at += codes + values;
            }
            let mut level = stored.level(j, &offsets, at);
            for &s in &order {
                let mut nodes = index.counts[s * t + j - 1][0];
                let mut from = 0;
                while nodes > 0 {
                    let take = nodes.min(32 * CHUNK_WORDS as u64);
                    let chunk = &mut words[..take.div_ceil(32) as usize];
                    level.read(s, from, chunk)?;
                    sink.append_words(chunk, take)?;
                    from += chunk.len() as u64;
                    nodes -= take;
                }
            }
            sink.end_codes()?;
            for &s in &order {
                let (mut from, mut left) = index.piece_words(s, j, value_bytes);
                let mut value_left = index.counts[s * t + j - 1][1] * value_bytes;
                while left > 0 {
                    let chunk = &mut words[..left.min(CHUNK_WORDS as u64) as usize];
                    level.read(s, from, chunk)?;
                    bytes.clear();
                    bytes.extend(chunk.iter().flat_map(|w| w.to_le_bytes()));
                    bytes.truncate(value_left.min(bytes.len() as u64) as usize);
                    sink.append_values(&bytes)?;
                    value_left -= bytes.len() as u64;
                    from += chunk.len() as u64;
                    left -= chunk.len() as u64;
                }
            }
            sink.end_level()?;
            level.finish();
        }
        let counts_per_level = sink.counts_per_level();
        let output = sink.finish()?;
        Ok((
            output,
            ValueSlabsReport {
                counts_per_level,
                file_bytes: 0,
                cell_depth: m,
                subtrees: index.mortons.len() as u64,
                spilled_bytes: 8 * spilled_words,
            },
        ))
    }
}

/// The Morton key, among cells of `K` dimensions, of the cell whose last coordinate is `b` and whose other
/// coordinates are 0.
fn spread_last<const K: usize>(b: u32) -> u64 {
    (0..32)
        .filter(|bit| b >> bit & 1 == 1)
        .map(|bit| 1u64 << (bit * K + K - 1))
        .sum()
}

/// Values as their little-endian bytes, one after the other.
fn value_bytes_of<V: Value>(values: &[V]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(std::mem::size_of_val(values));
    for &v in values {
        v.write_le(&mut bytes);
    }
    bytes
}

/// Values as their little-endian bytes, zero-padded to whole words.
fn value_words<V: Value>(values: &[V]) -> impl Iterator<Item = u64> {
    let bytes = value_bytes_of(values);
    let words: Vec<u64> = bytes
        .chunks(8)
        .map(|c| {
            let mut word = [0u8; 8];
            word[..c.len()].copy_from_slice(c);
            u64::from_le_bytes(word)
        })
        .collect();
    words.into_iter()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::morton_encode;

    #[test]
    fn the_last_coordinate_spreads_to_the_last_axis() {
        assert_eq!(spread_last::<3>(0b101), morton_encode::<3>([0, 0, 0b101]));
        assert_eq!(spread_last::<1>(0b1101), 0b1101);
        assert_eq!(
            spread_across::<4>(0b1011) | spread_last::<4>(0b10),
            morton_encode::<4>([0b11, 0b1, 0, 0b10])
        );
    }
}
