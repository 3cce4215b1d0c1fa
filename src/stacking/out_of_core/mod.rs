//! Out-of-core stacking: a tree written level after level in bounded memory, its subtrees spilled as
//! they are stacked to a [`PieceStore`] and the tree written to a [`LevelOrderSink`] (the notes on how it
//! runs, in parts, its memory and its temporary files are in the [`stacking`](super) module's
//! documentation). The builder knows only these traits: `io` implements them with spill files and the
//! `.ktree` writer.

mod budget;
mod error;
mod parts;
mod pieces;
mod progress;
mod sink;
mod spill;

pub(crate) use budget::BUFFER_BYTES;
pub use error::BuildError;
pub use parts::{balanced_parts, SpilledPart, MAX_PARTS};
pub(crate) use parts::{build_slabs, slab_cost, stack_part};

pub(crate) use pieces::ChunkedSend;
pub use pieces::{LevelPieces, PieceStore, StoredPieces};
pub use progress::{Progress, Stage};
pub use sink::LevelOrderSink;

use super::CellStacking;
use crate::tree::LevelCounts;

/// The error of a build out of core (the source's error `E`) into the store `P`.
pub(crate) type StoreBuildError<E, P> = BuildError<E, <P as PieceStore>::Error>;

/// How an out-of-core build runs (set through [`Builder`](super::Builder)).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct OutOfCore {
    /// The depth `m` of the cells stacked apart (clamped to `L`).
    pub(crate) depth: u32,
    /// The memory budget in bytes (see the module's notes on how it is accounted).
    pub(crate) max_memory: u64,
    /// How each cell of depth `m` is stacked.
    pub(crate) cells: CellStacking,
}

/// What an out-of-core build wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutOfCoreReport {
    /// The tree's node counts per level (`level` = depth).
    pub counts_per_level: Vec<LevelCounts>,
    /// The size of the file written, in bytes (0 from [`SpilledPart::write_into`] and
    /// [`Builder::build_into`](super::Builder::build_into), whose output is not necessarily a file).
    pub file_bytes: u64,
    /// Cells of depth `m` stacked (and spilled).
    pub subtrees: u64,
    /// Bytes written to spill files (to the [`PieceStore`]).
    pub spilled_bytes: u64,
    /// The most memory accounted at once, in bytes.
    pub peak_accounted_bytes: u64,
}
