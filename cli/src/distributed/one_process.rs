//! Without the `mpi` feature: every run is one process, rank 0 of 1.

use super::Ranks;

/// Nothing to hold without MPI.
pub struct Guard;

pub fn init() -> Guard {
    Guard
}

pub fn ranks() -> Ranks {
    Ranks { rank: 0, size: 1 }
}

pub fn abort() {}

pub fn settled() -> bool {
    true
}
