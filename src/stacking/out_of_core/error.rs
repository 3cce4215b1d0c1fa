//! Why a build failed.

use super::budget::bytes_text;

/// Why a build failed: `E` is the source's error, `F` the error of the [`PieceStore`](super::PieceStore)
/// and output of a build out of core (by default that of the spill files and `.ktree` file of
/// [`Builder::to_file`](crate::stacking::Builder::to_file)). A build to a file leaves the target untouched
/// and removes its spill files.
#[derive(Debug, thiserror::Error)]
pub enum BuildError<E, F = crate::fs::SpillError> {
    /// The source could not produce its rays.
    #[error("the source could not make its rays")]
    Source(#[source] E),
    /// The worker threads asked for ([`Builder::threads`](crate::stacking::Builder::threads)) could not
    /// be started.
    #[error("cannot start worker threads")]
    Threads(#[source] rayon::ThreadPoolBuildError),
    /// Not even one slab of cells (or the index of the stacked cells, or the I/O buffers) fits in the
    /// budget.
    #[error(
        "a memory budget of {} is too small for this build: it needs a budget of at least {}",
        bytes_text(*budget),
        bytes_text(*needed)
    )]
    BudgetTooSmall {
        /// The budget given, in bytes.
        budget: u64,
        /// The least budget known to be needed, in bytes: what the build held when it failed plus its
        /// largest slab so far (a budget with which the whole build runs when the index at the end is
        /// what did not fit).
        needed: u64,
    },
    /// The parts of a build written together overlap: a cell of depth `m` was stacked by two of them, or
    /// stacked by one and full in another (an index added with
    /// [`SpilledPart::add_part`](crate::stacking::SpilledPart::add_part) that is not of another part
    /// of the same build).
    #[error(
        "the indexes of the parts overlap: a cell of depth m was stacked twice or is also full"
    )]
    PartsOverlap,
    /// The subtrees could not be stored or read back, or the output could not be written (for a file: a
    /// temporary folder or file, or the output, a full disk included).
    #[error(transparent)]
    Files(#[from] F),
}
