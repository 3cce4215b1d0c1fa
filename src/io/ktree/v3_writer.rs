//! [`ValuedKtreeWriter`]: a version 3 file written level by level, in one pass, without holding the tree.

use std::io::Write;

use super::level_stream::LevelStream;
use super::notes::Notes;
use super::v2::layout::{header_block, invalid, HEADER_BYTES};
use super::MAGIC;
use crate::space::WorldFrame;
use crate::stacking::ValuedLevelSink;
use crate::tree::{Dtype, LevelCounts};

/// The bytes of a world frame after the header: the voxel size and three origin coordinates.
pub(super) const FRAME_BYTES: usize = 32;

/// Writes a `.ktree` version 3 file (a valued tree, see [`v3`](super::v3)) level by level, from the root
/// down, without holding the tree.
///
/// A level is given in two parts, as its section lies in the file: first its 2-bit codes, in one or more
/// pieces ([`append_words`](Self::append_words), each a run of consecutive nodes packed as in
/// [`PackedStates::words`](crate::tree::PackedStates::words), shifted to follow the nodes before it), then
/// [`end_codes`](Self::end_codes), then the values of its full nodes in level order, as little-endian bytes,
/// in one or more pieces ([`append_values`](Self::append_values)), then [`end_level`](Self::end_level).
/// [`finish`](Self::finish) writes the directory. Memory held: one partial word, two rank samples per
/// 2048 nodes of the current level and a buffer of 64 KiB.
///
/// The writer checks the tree's shape as it goes (a root level of one node, each level `2^K` times the
/// nodes with children of the level above, as many values as full nodes, no node with children at the
/// last level) and returns [`std::io::ErrorKind::InvalidInput`] when it is broken; whether the values
/// are ones a voxel may hold and the tree is minimal is checked when the file is read.
///
/// ```
/// use ktree::io::ktree::v3::{read_valued_ktree, ValuedKtreeWriter};
/// use ktree::io::ktree::Notes;
/// use ktree::value::Dtype;
/// use ktree::KTree;
/// let tree = KTree::<2, u16>::from_dense_values(1, &[Some(7), None, Some(9), Some(7)]).unwrap();
/// let mut bytes = Vec::new();
/// let mut w = ValuedKtreeWriter::new(&mut bytes, 2, 1, Dtype::U16, None, &Notes::new()).unwrap();
/// w.append_words(&[0b10], 1).unwrap(); // the root: partial
/// w.end_codes().unwrap();
/// w.end_level().unwrap();
/// // The four children (full, empty, full, full) in two pieces, then their values in two pieces.
/// w.append_words(&[0b0001], 2).unwrap();
/// w.append_words(&[0b0101], 2).unwrap();
/// w.end_codes().unwrap();
/// w.append_values(&[7, 0, 9, 0]).unwrap();
/// w.append_values(&[7, 0]).unwrap();
/// w.end_level().unwrap();
/// w.finish().unwrap();
/// assert_eq!(read_valued_ktree::<2, u16>(&bytes, "mem").unwrap(), tree);
/// ```
#[derive(Debug)]
pub struct ValuedKtreeWriter<W: Write> {
    stream: LevelStream<W>,
    /// The bytes of a value.
    value_bytes: u64,
    /// Bytes of values of the current level written.
    level_value_bytes: u64,
}

impl<W: Write> ValuedKtreeWriter<W> {
    /// Starts a file for a `K = k` tree of values of type `dtype` in a level-`level` universe, with where
    /// its voxels are in the world (`frame`) and `notes` (none: no notes block), writing the header.
    ///
    /// # Errors
    /// `InvalidInput` for `k` or `level` out of range, a frame whose voxel size is not a positive number
    /// or whose origin is not finite, a note that cannot be kept; any I/O error.
    pub fn new(
        out: W,
        k: usize,
        level: u32,
        dtype: Dtype,
        frame: Option<&WorldFrame>,
        notes: &Notes,
    ) -> std::io::Result<Self> {
        let mut first = [0u8; HEADER_BYTES];
        first[..6].copy_from_slice(MAGIC);
        first[6..8].copy_from_slice(&super::v3::VERSION.to_le_bytes());
        first[8..11].copy_from_slice(&[k as u8, level as u8, dtype.code()]);
        let header = header_block(first, frame, notes)?;
        Ok(Self {
            stream: LevelStream::new(out, k, level, header, true)?,
            value_bytes: dtype.bytes() as u64,
            level_value_bytes: 0,
        })
    }

    /// Appends `nodes` nodes packed in `words` (the first node in the low bits of `words[0]`) to the codes
    /// of the current level, shifted to follow the nodes already appended.
    ///
    /// # Errors
    /// `InvalidInput` if `words` holds fewer than `nodes` nodes or the level's codes were ended; any I/O
    /// error.
    pub fn append_words(&mut self, words: &[u64], nodes: u64) -> std::io::Result<()> {
        self.stream.append_codes(words, nodes)
    }

    /// Closes the codes of the current level and writes its rank samples: its full nodes' values come
    /// next.
    ///
    /// # Errors
    /// `InvalidInput` if the level's codes were ended already, the root level is not one node, or the
    /// level's size is not `2^K` times the nodes with children of the level above, or the tree would be
    /// deeper than the universe; any I/O error.
    pub fn end_codes(&mut self) -> std::io::Result<()> {
        self.stream.end_codes()
    }

    /// Appends values of the current level's full nodes, in level order: `bytes` holds whole values, each
    /// its type's bytes, little-endian (as [`Value::write_le`](crate::value::Value::write_le) writes them).
    ///
    /// # Errors
    /// `InvalidInput` before [`end_codes`](Self::end_codes), for a length that is not a whole number of
    /// values, or for more values than the level's full nodes; any I/O error.
    pub fn append_values(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let depth = self.stream.depth();
        if !self.stream.codes_ended() {
            return Err(invalid(format!(
                "values of level {depth} appended before its codes ended"
            )));
        }
        let len = bytes.len() as u64;
        if !len.is_multiple_of(self.value_bytes) {
            return Err(invalid(format!(
                "{len} bytes are not whole values of {} bytes",
                self.value_bytes
            )));
        }
        let total = self.level_value_bytes + len;
        if total > self.stream.full() * self.value_bytes {
            return Err(invalid(format!(
                "level {depth} has {} full nodes, and more values were given",
                self.stream.full()
            )));
        }
        self.level_value_bytes = total;
        self.stream.put(bytes)
    }

    /// Closes the current level (the next append starts the level below).
    ///
    /// # Errors
    /// `InvalidInput` if the level's codes were not ended or it has fewer values than full nodes; any I/O
    /// error.
    pub fn end_level(&mut self) -> std::io::Result<()> {
        let full = self.stream.full();
        if !self.stream.codes_ended() || self.level_value_bytes != full * self.value_bytes {
            return Err(invalid(format!(
                "level {} ended with {} of its {full} values",
                self.stream.depth(),
                self.level_value_bytes / self.value_bytes,
            )));
        }
        let padding = self.level_value_bytes.next_multiple_of(8) - self.level_value_bytes;
        self.stream.put(&[0; 8][..padding as usize])?;
        self.level_value_bytes = 0;
        self.stream.end_level()
    }

    /// The node counts of the levels closed so far (`level` = depth), as the file's directory will hold
    /// them.
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.stream.counts_per_level()
    }

    /// Writes the directory and returns the output.
    ///
    /// # Errors
    /// `InvalidInput` if no level was written, a level was left open, or the last level has nodes with
    /// children; any I/O error.
    pub fn finish(self) -> std::io::Result<W> {
        if !self.stream.level_is_empty() {
            return Err(invalid(format!(
                "level {} was not ended",
                self.stream.depth()
            )));
        }
        self.stream.finish()
    }
}

impl<W: Write> ValuedLevelSink for ValuedKtreeWriter<W> {
    type Error = std::io::Error;
    type Output = W;

    fn append_words(&mut self, words: &[u64], nodes: u64) -> std::io::Result<()> {
        ValuedKtreeWriter::append_words(self, words, nodes)
    }

    fn end_codes(&mut self) -> std::io::Result<()> {
        ValuedKtreeWriter::end_codes(self)
    }

    fn append_values(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        ValuedKtreeWriter::append_values(self, bytes)
    }

    fn end_level(&mut self) -> std::io::Result<()> {
        ValuedKtreeWriter::end_level(self)
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        ValuedKtreeWriter::counts_per_level(self)
    }

    fn finish(self) -> std::io::Result<W> {
        ValuedKtreeWriter::finish(self)
    }
}

/// Why a world frame cannot be kept: a voxel size that is not a positive number, an origin not finite.
pub(super) fn check_frame(f: &WorldFrame) -> Result<(), String> {
    if !(f.voxel_size.is_finite() && f.voxel_size > 0.0) {
        return Err(format!(
            "a frame's voxel size {} is not a positive number",
            f.voxel_size
        ));
    }
    if f.origin.iter().any(|c| !c.is_finite()) {
        return Err(format!("a frame's origin {:?} is not finite", f.origin));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::ktree::v3::{read_valued_ktree, write_valued_ktree_noted};
    use crate::tree::valued::ValueStorage;
    use crate::tree::words::{codes_at, NODES_PER_WORD};
    use crate::tree::NodeState;
    use crate::value::Value;
    use crate::KTree;
    use proptest::prelude::*;

    /// A level's codes cut into pieces at `cuts` (node offsets), each piece's words starting at its
    /// first node.
    fn pieces(words: &[u64], nodes: usize, cuts: &[usize]) -> Vec<(Vec<u64>, u64)> {
        let mut bounds: Vec<usize> = cuts.iter().map(|c| c % (nodes + 1)).collect();
        bounds.extend([0, nodes]);
        bounds.sort_unstable();
        bounds
            .windows(2)
            .map(|w| {
                let (start, len) = (w[0], w[1] - w[0]);
                let piece = (0..len.div_ceil(NODES_PER_WORD))
                    .map(|i| {
                        let from = start + i * NODES_PER_WORD;
                        codes_at(words, from, (len - i * NODES_PER_WORD).min(NODES_PER_WORD))
                    })
                    .collect();
                (piece, len as u64)
            })
            .collect()
    }

    /// The file of `tree` written in pieces cut at `cuts`, codes and values alike.
    fn written_in_pieces<V: Value>(tree: &KTree<3, V>, cuts: &[usize], notes: &Notes) -> Vec<u8> {
        let dtype = V::DTYPE.expect("a stored value");
        let frame = WorldFrame {
            voxel_size: 0.25,
            origin: [1.0, -2.0, 3.5],
        };
        let mut w = ValuedKtreeWriter::new(Vec::new(), 3, tree.level(), dtype, Some(&frame), notes)
            .unwrap();
        for depth in 0..tree.depth_count() {
            let states = tree.level_states(depth);
            for (piece, nodes) in pieces(states.words(), states.len(), cuts) {
                w.append_words(&piece, nodes).unwrap();
            }
            w.end_codes().unwrap();
            let mut values = Vec::new();
            for i in 0..states.len() {
                if states.get(i) == NodeState::Full {
                    tree.value(depth, i).unwrap().write_le(&mut values);
                }
            }
            let whole_values: Vec<usize> = cuts.iter().map(|c| c * dtype.bytes()).collect();
            let mut at = 0;
            let mut ends: Vec<usize> = whole_values
                .iter()
                .map(|c| c % (values.len() + 1))
                .collect();
            ends.push(values.len());
            ends.sort_unstable();
            for end in ends {
                let end = end / dtype.bytes() * dtype.bytes();
                if end > at {
                    w.append_values(&values[at..end]).unwrap();
                    at = end;
                }
            }
            w.end_level().unwrap();
        }
        assert_eq!(w.counts_per_level(), tree.counts_per_level());
        w.finish().unwrap()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn pieces_write_the_file_of_the_whole_tree(
            labels in proptest::collection::vec(0u16..4, 512),
            cuts in proptest::collection::vec(0usize..600, 0..6),
        ) {
            let dense: Vec<Option<u16>> =
                labels.iter().map(|&l| (l > 0).then_some(l / 2)).collect();
            let tree = KTree::<3, u16>::from_dense_values(3, &dense).unwrap();
            let notes = Notes::from([("source".to_string(), "pieces".to_string())]);
            let frame = WorldFrame { voxel_size: 0.25, origin: [1.0, -2.0, 3.5] };
            let mut whole = Vec::new();
            write_valued_ktree_noted(&mut whole, &tree, Some(&frame), &notes).unwrap();
            let pieces = written_in_pieces(&tree, &cuts, &notes);
            prop_assert_eq!(&pieces, &whole);
            prop_assert_eq!(read_valued_ktree::<3, u16>(&pieces, "mem").unwrap(), tree);
        }
    }

    #[test]
    fn a_broken_shape_is_refused() {
        let new =
            || ValuedKtreeWriter::new(Vec::new(), 2, 2, Dtype::U8, None, &Notes::new()).unwrap();
        // A root level of two nodes.
        let mut w = new();
        w.append_words(&[0b0101], 2).unwrap();
        assert!(w.end_codes().is_err());
        // Values before the codes end; codes after the values begin; a value too many; one too few.
        let mut w = new();
        w.append_words(&[0b01], 1).unwrap();
        assert!(w.append_values(&[3]).is_err());
        w.end_codes().unwrap();
        assert!(w.append_words(&[0b01], 1).is_err());
        assert!(w.append_values(&[3, 4]).is_err());
        assert!(w.end_level().is_err());
        w.append_values(&[3]).unwrap();
        w.end_level().unwrap();
        assert_eq!(w.finish().unwrap().len() % 8, 0);
        // A partial root without children.
        let mut w = new();
        w.append_words(&[0b10], 1).unwrap();
        w.end_codes().unwrap();
        w.end_level().unwrap();
        assert!(w.finish().is_err());
        // Four children where a partial root calls for them, but one of them mixed at the last level.
        let mut w =
            ValuedKtreeWriter::new(Vec::new(), 2, 1, Dtype::U8, None, &Notes::new()).unwrap();
        w.append_words(&[0b10], 1).unwrap();
        w.end_codes().unwrap();
        w.end_level().unwrap();
        assert!(w.append_words(&[0b01], 1).is_ok());
        assert!(w.end_codes().is_err());
        // A level left open.
        let mut w = new();
        w.append_words(&[0b00], 1).unwrap();
        assert!(w.finish().is_err());
    }
}
