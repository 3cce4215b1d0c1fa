//! Why a build failed.

use super::budget::bytes_text;

/// Why a build failed. A build to a file leaves the target untouched and removes its spill files.
#[derive(Debug, thiserror::Error)]
pub enum BuildError<E> {
    /// The source could not produce its rays.
    #[error("{0}")]
    Source(E),
    /// The worker threads asked for ([`Builder::threads`](crate::stacking::Builder::threads)) could not
    /// be started.
    #[error("cannot start worker threads: {0}")]
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
    /// A temporary file or the output could not be written.
    #[error(transparent)]
    Files(#[from] crate::fs::SpillError),
}
