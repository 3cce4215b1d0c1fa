//! Where an out-of-core build writes its tree: level after level, from the root down ([`LevelOrderSink`]).

use crate::tree::{LevelCounts, PackedStates};

/// The output of an out-of-core build, written level after level from the root down: each level as one
/// or more runs of consecutive nodes, packed two bits a node in `u64` words as in
/// [`PackedStates::words`] (a run may end in the middle of a word: the next continues right after it),
/// closed by [`end_level`](Self::end_level). Unlike a [`LevelSink`](crate::tree::sink::LevelSink), which
/// takes the levels interleaved in depth-first order, a level is complete before the next begins, so the
/// output can be streamed to a file as it comes. `io` implements it with the `.ktree` writer
/// ([`KtreeWriter`](crate::io::KtreeWriter)); the example of [`PieceStore`](super::PieceStore) counts
/// nodes.
pub trait LevelOrderSink {
    /// Why the output could not be written.
    type Error;
    /// What the finished output is.
    type Output;

    /// Appends `nodes` nodes packed in `words` (at least `⌈nodes / 32⌉` words; bits beyond the nodes are
    /// ignored) to the current level.
    ///
    /// # Errors
    /// The output's error.
    fn append_words(&mut self, words: &[u64], nodes: u64) -> Result<(), Self::Error>;

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

    /// Appends a whole level, or a part of one, to the current level.
    ///
    /// # Errors
    /// The output's error.
    fn append_states(&mut self, states: &PackedStates) -> Result<(), Self::Error> {
        self.append_words(states.words(), states.len() as u64)
    }
}
