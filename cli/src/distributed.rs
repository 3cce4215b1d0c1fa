//! Building across MPI ranks (cargo feature `mpi`; without it, one process does everything).
//!
//! Started as `mpirun -n P ktree rays|build|voxelize …`, every rank reads the same input (a ray file, a
//! mesh, a volume or a solid's description) and keeps only the columns of its slab: contiguous along axis 0
//! and balanced by their number of runs ([`ktree::stacking::balanced_slabs`]). Each rank stacks its slab
//! (on all its threads) and sends its tree, in the `.ktree` encoding, to rank 0, which joins the parts by
//! union ([`ktree::stacking::join_parts`]) as they arrive — in rank order, so rank 0 holds its own tree,
//! the tree joined so far and one received part — and writes the one output file, atomically. The result
//! is byte for byte the single-process file. A rank that fails stops the whole run (`MPI_Abort`) before
//! anything is written.

use ktree::{KTree, RaySet};

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

/// Builds the tree of `rays` across the ranks of the run: `Some(tree)` on rank 0 (and in a run of one
/// process), `None` on the other ranks, whose part has been sent to rank 0.
///
/// # Errors
/// A message if a part cannot be exchanged or joined.
pub fn stack<const K: usize>(
    rays: &RaySet<K>,
    threads: Option<usize>,
) -> Result<Option<KTree<K>>, String> {
    imp::stack(rays, threads)
}

/// Stacks rays in this process, cell by cell on `threads` worker threads (all cores when `None`).
fn stack_here<const K: usize>(
    rays: &RaySet<K>,
    threads: Option<usize>,
) -> Result<KTree<K>, String> {
    crate::build::with_threads(threads, || crate::build::stack_cells(rays))
}

/// This process's rank and the number of ranks (`0` of `1` without MPI).
pub fn ranks() -> Ranks {
    imp::ranks()
}

/// Reports a failed command: with several ranks, stops every rank of the run (nothing is written, as the
/// output is written by rank 0 only after every part arrived); otherwise prints the error.
pub fn report_failure(message: &str) {
    let r = ranks();
    if r.size > 1 {
        eprintln!("ktree: rank {} of {}: {message}", r.rank, r.size);
        imp::abort();
    }
    eprintln!("ktree: {message}");
}

/// Starts MPI for the life of the returned guard (a no-op without the `mpi` feature).
pub fn init() -> imp::Guard {
    imp::init()
}

#[cfg(not(feature = "mpi"))]
mod imp {
    use super::Ranks;
    use ktree::{KTree, RaySet};

    /// Nothing to hold without MPI.
    pub struct Guard;

    pub fn init() -> Guard {
        Guard
    }

    pub fn ranks() -> Ranks {
        Ranks { rank: 0, size: 1 }
    }

    pub fn abort() {}

    pub fn stack<const K: usize>(
        rays: &RaySet<K>,
        threads: Option<usize>,
    ) -> Result<Option<KTree<K>>, String> {
        super::stack_here(rays, threads).map(Some)
    }
}

#[cfg(feature = "mpi")]
mod imp {
    use mpi::topology::SimpleCommunicator;
    use mpi::traits::*;

    use super::Ranks;
    use ktree::io::{read_ktree, write_ktree};
    use ktree::stacking::{balanced_slabs, join_parts, slab_rays};
    use ktree::{KTree, RaySet};

    /// Keeps MPI initialised; finalises it when dropped.
    pub struct Guard {
        _universe: Option<mpi::environment::Universe>,
    }

    pub fn init() -> Guard {
        Guard {
            _universe: mpi::initialize(),
        }
    }

    fn world() -> SimpleCommunicator {
        SimpleCommunicator::world()
    }

    pub fn ranks() -> Ranks {
        let w = world();
        Ranks {
            rank: w.rank() as usize,
            size: w.size() as usize,
        }
    }

    pub fn abort() {
        world().abort(1);
    }

    /// Largest message sent at once (MPI counts are 32-bit).
    const CHUNK: usize = 1 << 30;

    pub fn stack<const K: usize>(
        rays: &RaySet<K>,
        threads: Option<usize>,
    ) -> Result<Option<KTree<K>>, String> {
        let Ranks { rank, size } = ranks();
        if size == 1 {
            return super::stack_here(rays, threads).map(Some);
        }
        let slabs = balanced_slabs(rays, size);
        let mine = super::stack_here(&slab_rays(rays, slabs[rank].clone()), threads)?;
        let w = world();
        let root = w.process_at_rank(0);
        if rank != 0 {
            let mut bytes = Vec::new();
            write_ktree(&mut bytes, &mine).map_err(|e| e.to_string())?;
            root.send(&(bytes.len() as u64));
            for chunk in bytes.chunks(CHUNK) {
                root.send(chunk);
            }
            root.send(&ktree_repro::peak_rss_bytes().unwrap_or(0));
            return Ok(None);
        }
        let mut moved = 0u64;
        let mut peaks = vec![0];
        let parts = (1..size).map(|r| {
            let from = w.process_at_rank(r as i32);
            let (len, _) = from.receive::<u64>();
            let mut bytes = Vec::with_capacity(len as usize);
            while (bytes.len() as u64) < len {
                let (chunk, _) = from.receive_vec::<u8>();
                bytes.extend_from_slice(&chunk);
            }
            moved += len;
            let (p, _) = from.receive::<u64>();
            peaks.push(p);
            read_ktree::<K>(&bytes, &format!("<part of rank {r}>")).map_err(|e| e.to_string())
        });
        let mut error = None;
        let joined = join_parts(
            mine,
            parts.map_while(|p| p.map_err(|e| error = Some(e)).ok()),
        );
        if let Some(e) = error {
            return Err(e);
        }
        let tree = joined.map_err(|e| e.to_string())?;
        peaks[0] = ktree_repro::peak_rss_bytes().unwrap_or(0);
        eprintln!(
            "ktree: {size} ranks; {moved} bytes sent to rank 0; peak memory per rank (MiB): {}",
            peaks
                .iter()
                .map(|p| format!("{:.1}", *p as f64 / (1u64 << 20) as f64))
                .collect::<Vec<_>>()
                .join(" ")
        );
        Ok(Some(tree))
    }
}
