//! Building across MPI ranks (cargo feature `mpi`; without it, every run is one process, and a build never
//! comes here).
//!
//! Started as `mpirun -n P ktree rays|build|voxelize … --out F.ktree`, every rank takes the one
//! build-and-write step ([`crate::common::output::TreeOutput::write`]), which in a run of several ranks
//! hands the build to [`build_across_ranks`]: every rank runs the out-of-core build of
//! [`ktree::stacking`] on its share of the slabs of cells, in `--max-memory` bytes of its own:
//!
//! 1. **Partition.** The slabs of cells (one cell wide along axis 0, [`ktree::stacking::Builder::slabs`]) are
//!    measured by their runs ([`ktree::stacking::Builder::slab_cost`]: rank `r` measures the slabs `r, r + P, …`, an
//!    all-reduce shares the costs) and cut into `P` contiguous ranges of about equal cost
//!    ([`ktree::stacking::balanced_parts`]).
//! 2. **Stacking.** Each rank stacks the cells of its slabs and spills their subtrees to files of its own
//!    ([`ktree::stacking::Builder::stack_part`]). A solid makes only the rays of the rank's slabs; a ray file, mesh
//!    or volume is read whole by every rank.
//! 3. **Index.** Every other rank sends rank 0 the index of its part (the states of its cells of depth `m`,
//!    and the Morton index and node counts per level of each cell it stacked — as much as the
//!    single-process build holds for those cells).
//! 4. **Writing.** Rank 0 writes the one file ([`ktree::stacking::SpilledPart::write`], atomically): the
//!    top levels from all the cells' states, then each level in global Morton order of the cells, taking
//!    each cell's piece from its owner — its own spill files, or the stream of chunks (at most 4 MiB) that
//!    every other rank sends in its own Morton order. Rank 0 takes from each stream in the order it was
//!    sent, so the blocking sends cannot deadlock; it holds at most one chunk per other rank, each other
//!    rank one chunk, and these buffers come out of the budget. The file is byte for byte the
//!    single-process file.
//!
//! A volume with values (`voxelize --labels`, `--window`) is built by [`build_values_across_ranks`]: each
//! rank reads only the planes of its own range of slabs ([`ktree::stacking::ValueSlabs::stack_part`]), and
//! phases 3 and 4 are the same with the roots of the slabs' cells as the index and each level's codes,
//! then values, as the streams ([`ktree::stacking::ValuePart`]).
//!
//! **Failure.** The ranks agree after each phase whether one failed (an all-reduce); then every rank drops
//! its spill folder, waits for the others to have dropped theirs, and fails: the failed rank prints its
//! error with its rank, nothing is written. A rank that fails while sending its levels ends its stream with
//! a failure mark, and rank 0, whose write then fails, takes the rest of the other streams before agreeing.
//! A failure outside the build (an input a rank cannot read) stops every rank with `MPI_Abort`.

/// The partition of the run: this process's rank and the number of ranks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ranks {
    /// This process's rank, 0 … size − 1.
    pub rank: usize,
    /// The number of ranks.
    pub size: usize,
}

impl Ranks {
    /// Whether this process writes the output and prints the summary.
    pub fn is_root(self) -> bool {
        self.rank == 0
    }
}

/// The error of the ranks that did not fail when another did (they print nothing: the failed rank does).
const STOPPED: &str = "stopped: another rank failed";

/// This process's rank and the number of ranks (`0` of `1` without MPI).
pub fn ranks() -> Ranks {
    imp::ranks()
}

/// Reports a failed command. With several ranks: a failure the ranks agreed on is printed by the rank
/// that failed (with its rank) and every rank ends on its own; any other failure is printed with the
/// rank and stops every rank of the run (`MPI_Abort`; nothing is written). In one process: prints it.
pub fn report_failure(message: &str) {
    let r = ranks();
    if r.size > 1 {
        if message != STOPPED {
            eprintln!("ktree: rank {} of {}: {message}", r.rank, r.size);
        }
        if !imp::settled() {
            imp::abort();
        }
        return;
    }
    eprintln!("ktree: {message}");
}

/// Starts MPI for the life of the returned guard (a no-op without the `mpi` feature).
pub fn init() -> imp::Guard {
    imp::init()
}

#[cfg(not(feature = "mpi"))]
#[path = "one_process.rs"]
mod imp;

#[cfg(feature = "mpi")]
#[path = "mpi.rs"]
mod imp;

#[cfg(feature = "mpi")]
pub use imp::{build_across_ranks, build_values_across_ranks};
