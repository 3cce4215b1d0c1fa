//! Out-of-core stacking: a tree written straight to a `.ktree` version 2 file in bounded memory, its
//! subtrees spilled to temporary files as they are stacked (the notes on how it runs, in parts, its
//! memory and its temporary files are in the [`stacking`](super) module's documentation).

mod budget;
mod error;
mod parts;
mod progress;
mod spill;

pub use error::BuildError;
pub use parts::{balanced_parts, SpilledPart, MAX_PARTS};
pub(crate) use parts::{build_slabs, slab_cost, stack_part};
pub use progress::{Progress, Stage};

use std::fmt::Display;
use std::path::{Path, PathBuf};

use super::CellStacking;
use crate::rays::RaySource;
use crate::tree::LevelCounts;

/// How an out-of-core build runs (set through [`Builder`](super::Builder)).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct OutOfCore {
    /// The depth `m` of the cells stacked apart (clamped to `L`).
    pub(crate) depth: u32,
    /// The memory budget in bytes (see the module's notes on how it is accounted).
    pub(crate) max_memory: u64,
    /// The folder of the spill files; `None`: the output's folder.
    pub(crate) temp_dir: Option<PathBuf>,
    /// How each cell of depth `m` is stacked.
    pub(crate) cells: CellStacking,
}

/// What an out-of-core build wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutOfCoreReport {
    /// The tree's node counts per level (`level` = depth).
    pub counts_per_level: Vec<LevelCounts>,
    /// The size of the file written, in bytes.
    pub file_bytes: u64,
    /// Cells of depth `m` stacked (and spilled).
    pub subtrees: u64,
    /// Bytes written to spill files.
    pub spilled_bytes: u64,
    /// The most memory accounted at once, in bytes.
    pub peak_accounted_bytes: u64,
}

/// Builds the tree of `source` from its cells of depth `options.depth` and writes it to `out` as a
/// `.ktree` version 2 file, in the memory budget `options.max_memory`, on the threads of the current rayon
/// pool; `progress` is called (on the calling thread) as slabs are stacked and levels written. The file
/// is byte for byte the one [`write_ktree_file`](crate::io::write_ktree_file) writes for the tree
/// built in memory. It is [`stack_part`] of every slab of [`build_slabs`] followed by
/// [`SpilledPart::write`].
///
/// # Errors
/// [`BuildError`]: the source's first error (in slab order), a budget too small, a temporary folder
/// or output that cannot be written (a full disk included). The target is then untouched and no
/// temporary file remains.
pub(crate) fn stack_to_file<const K: usize, S>(
    source: &S,
    out: &Path,
    options: &OutOfCore,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<OutOfCoreReport, BuildError<S::Error>>
where
    S: RaySource<K>,
    S::Error: Display,
{
    let slabs = build_slabs(source, options.depth);
    let part = stack_part(source, &slabs, out, options, progress)?;
    part.write(
        out,
        &mut |_, _| Err(std::io::Error::other("no other part")),
        progress,
    )
}
