//! Without the `mpi` feature: every run is one process, rank 0 of 1.

use super::Ranks;
use crate::common::memory::BuildArgs;
use ktree::rays::RaySource;
use ktree::stacking::OutOfCoreReport;
use std::path::Path;

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

/// One process builds everything.
pub fn build_to_file<const K: usize, S>(
    source: &S,
    out: &Path,
    pool: &rayon::ThreadPool,
    args: &BuildArgs,
    budget: u64,
) -> Result<Option<OutOfCoreReport>, String>
where
    S: RaySource<K>,
    S::Error: std::fmt::Display,
{
    pool.install(|| crate::common::memory::build_to_file(source, out, args, budget))
        .map(Some)
}
