//! [`KtreeWriter`]: a version 2 file written level by level, in one pass, without holding the tree.

use std::io::Write;

use super::layout::*;
use crate::io::ktree::level_stream::LevelStream;
use crate::io::ktree::notes::Notes;
use crate::space::{max_level, WorldFrame, MAX_K};
use crate::tree::{KTree, LevelCounts, NodeState, PackedStates};

/// Writes a `.ktree` version 2 file level by level, from the root down, without holding the tree.
///
/// A level is given as one or more *pieces*, each a run of consecutive nodes packed two bits a node in
/// `u64` words exactly as in [`PackedStates::words`] (node `j` of the piece in bits `2·(j mod 32)` of word
/// `j / 32`; bits beyond the piece's node count are ignored). A piece may end in the middle of a word: the
/// next piece is shifted to continue right after it, so the subtrees of consecutive cells, built apart, can
/// be appended one after the other at every level. [`KtreeWriter::end_level`] closes a level (the next
/// append starts the next one); [`KtreeWriter::finish`] writes the directory. Memory held: one partial word
/// and one rank sample per 2048 nodes of the current level.
///
/// The writer checks the tree's shape as it goes (a root level of one node, each level `2^K` times the
/// partial nodes of the level above, no code `11`, no partial node at the last level) and returns
/// [`std::io::ErrorKind::InvalidInput`] when it is broken; whether the tree is reduced is checked when the
/// file is read.
///
/// ```
/// use ktree::{io, KTree, NodeState};
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
/// let mut bytes = Vec::new();
/// let mut w = io::KtreeWriter::new(&mut bytes, 2, 1).unwrap();
/// w.push(NodeState::Partial).unwrap();
/// w.end_level().unwrap();
/// // The four children in two pieces: [full, empty] then [empty, full] (one word each).
/// w.append_words(&[0b0001], 2).unwrap();
/// w.append_words(&[0b0100], 2).unwrap();
/// w.finish().unwrap();
/// assert_eq!(io::read_ktree::<2>(&bytes, "mem").unwrap(), tree);
/// ```
#[derive(Debug)]
pub struct KtreeWriter<W: Write> {
    stream: LevelStream<W>,
}

impl<W: Write> KtreeWriter<W> {
    /// Starts a file for a `K = k` tree in a level-`level` universe, writing the header.
    ///
    /// # Errors
    /// `InvalidInput` for `k` or `level` out of range; any I/O error.
    pub fn new(out: W, k: usize, level: u32) -> std::io::Result<Self> {
        Self::with_frame(out, k, level, None, &Notes::new())
    }

    /// [`new`](Self::new) for a file that keeps where its voxels are in the world (`frame`) and `notes`
    /// (without either, the file is the one [`new`](Self::new) writes).
    ///
    /// # Errors
    /// As [`new`](Self::new), and `InvalidInput` for a frame whose voxel size is not a positive number
    /// or whose origin is not finite, or a note that cannot be kept.
    pub fn with_frame(
        out: W,
        k: usize,
        level: u32,
        frame: Option<&WorldFrame>,
        notes: &Notes,
    ) -> std::io::Result<Self> {
        let header = if (1..=MAX_K).contains(&k) && level <= max_level(k) {
            header_block(header_bytes(k, level), frame, notes)?
        } else {
            Vec::new()
        };
        Ok(Self {
            stream: LevelStream::new(out, k, level, header, false)?,
        })
    }

    /// Appends one node to the current level.
    ///
    /// # Errors
    /// Any I/O error.
    pub fn push(&mut self, state: NodeState) -> std::io::Result<()> {
        self.append_words(&[state as u64], 1)
    }

    /// Appends a whole [`PackedStates`] (for instance a level of a tree, or of a subtree) to the current
    /// level.
    ///
    /// # Errors
    /// Any I/O error.
    pub fn append_states(&mut self, states: &PackedStates) -> std::io::Result<()> {
        self.append_words(states.words(), states.len() as u64)
    }

    /// Appends `nodes` nodes packed in `words` (the first node in the low bits of `words[0]`) to the current
    /// level, shifted to follow the nodes already appended.
    ///
    /// # Errors
    /// `InvalidInput` if `words` holds fewer than `nodes` nodes or a node has the unused code `11`; any I/O
    /// error.
    pub fn append_words(&mut self, words: &[u64], nodes: u64) -> std::io::Result<()> {
        let mut remaining = nodes;
        for &word in words.iter().take(words_of(nodes) as usize) {
            let take = remaining.min(NODES_PER_WORD);
            let word = word & slots_mask(take);
            if (word >> 1) & word & LOW_BITS != 0 {
                return Err(invalid(format!(
                    "a node of level {} has the unused code 11",
                    self.stream.depth()
                )));
            }
            remaining -= take;
        }
        self.stream.append_codes(words, nodes)
    }

    /// Closes the current level: the next append starts the level below.
    ///
    /// # Errors
    /// `InvalidInput` if the level is empty, the root level is not one node, the level's size is not `2^K`
    /// times the partial nodes of the level above, or the tree would be deeper than the universe; any I/O
    /// error.
    pub fn end_level(&mut self) -> std::io::Result<()> {
        self.stream.end_codes()?;
        self.stream.end_level()
    }

    /// The node counts of the levels closed so far (`level` = depth), as the file's directory will hold them.
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.stream.counts_per_level()
    }

    /// Closes the last level if nodes were appended to it, writes the directory, and returns the output.
    ///
    /// # Errors
    /// `InvalidInput` if no level was written or the last level has partial nodes; any I/O error.
    pub fn finish(mut self) -> std::io::Result<W> {
        if !self.stream.level_is_empty() {
            self.end_level()?;
        }
        self.stream.finish()
    }
}

/// Writes a tree as a version 2 file, level by level, with `frame` and `notes`
/// ([`write_ktree`](crate::io::write_ktree) and [`write_ktree_framed`](crate::io::write_ktree_framed) call it).
pub(crate) fn write_levels<const K: usize>(
    out: impl Write,
    tree: &KTree<K>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> std::io::Result<()> {
    let mut w = KtreeWriter::with_frame(out, K, tree.level(), frame, notes)?;
    for d in 0..tree.depth_count() {
        w.append_states(tree.level_states(d))?;
        w.end_level()?;
    }
    w.finish().map(drop)
}
