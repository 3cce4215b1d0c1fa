//! With the `mpi` feature: the ranks of an MPI run build one tree together.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use mpi::collective::SystemOperation;
use mpi::topology::{Process, SimpleCommunicator};
use mpi::traits::*;
use rayon::prelude::*;

use super::{Ranks, STOPPED};
use crate::common::error::{CliError, CliResult};
use crate::common::output::{describe, TreeOutput};
use ktree::io::ktree::Notes;
use ktree::io::SpilledFiles;
use ktree::rays::RaySource;
use ktree::space::WorldFrame;
use ktree::stacking::{balanced_parts, OutOfCoreReport, SpilledPart, ValuePart, ValueSlabsReport};
use ktree::value::Value;

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

/// Set when the ranks agreed that the build failed and every rank cleaned up.
static SETTLED: AtomicBool = AtomicBool::new(false);

pub fn settled() -> bool {
    SETTLED.load(Ordering::SeqCst)
}

/// The largest message of the index and the level streams, in bytes.
const CHUNK_BYTES: u64 = 4 << 20;
/// The smallest, in bytes (when the budget is small).
const MIN_CHUNK_BYTES: u64 = 64 << 10;
/// The first word of a stream message: the chunk follows.
const CHUNK: u64 = 0;
/// The first word of a stream message: the sender failed, its stream ends.
const FAILED: u64 = 1;

/// Words per message: at most [`CHUNK_BYTES`], and a sixteenth of the budget shared by the buffers
/// rank 0 holds (one per other rank).
fn chunk_words(budget: u64, size: usize) -> usize {
    let bytes = (budget / 16 / size as u64).clamp(MIN_CHUNK_BYTES, CHUNK_BYTES);
    (bytes / 8) as usize
}

/// The ranks agree whether one failed: `Ok` if none did; else this rank's error, or [`STOPPED`].
fn agree<T>(w: &SimpleCommunicator, outcome: CliResult<T>) -> CliResult<T> {
    let failed = u64::from(outcome.is_err());
    let mut any = 0u64;
    w.all_reduce_into(&failed, &mut any, SystemOperation::sum());
    match outcome {
        Err(e) => Err(e),
        Ok(_) if any > 0 => Err(CliError::Failed(STOPPED.to_string())),
        ok => ok,
    }
}

/// Builds the tree of `source` into the `.ktree` (version 2) file `out` across the ranks of the run,
/// out of core in `budget` bytes per rank, on the worker threads of `tree` on each rank (MPI is called
/// from this thread only; the pool stacks): `Some(report)` on rank 0, `None` on the other ranks.
///
/// # Errors
/// The error naming the output if the build fails on this rank; [`STOPPED`] if it failed on another.
pub fn build_across_ranks<const K: usize, S>(
    tree: &TreeOutput<'_>,
    source: &S,
    out: &Path,
    budget: u64,
) -> CliResult<Option<OutOfCoreReport>>
where
    S: RaySource<K>,
    S::Error: std::error::Error + Send + Sync + 'static,
{
    let pool = crate::common::threads::thread_pool(tree.threads)?;
    let w = world();
    let outcome = run(&w, tree, source, out, &pool, budget);
    if outcome.is_err() {
        // Every rank has dropped its spill folder: none is stopped before it could.
        w.barrier();
        SETTLED.store(true, Ordering::SeqCst);
    }
    outcome
}

/// The phases of the build, each ending with an agreement (the spill folder is dropped on return).
fn run<const K: usize, S>(
    w: &SimpleCommunicator,
    tree: &TreeOutput<'_>,
    source: &S,
    out: &Path,
    pool: &rayon::ThreadPool,
    budget: u64,
) -> CliResult<Option<OutOfCoreReport>>
where
    S: RaySource<K>,
    S::Error: std::error::Error + Send + Sync + 'static,
{
    let Ranks { rank, size } = ranks();
    let chunk = chunk_words(budget, size);
    // The message buffers come out of the budget: rank 0 holds one per other rank.
    let held = 8 * chunk as u64 * if rank == 0 { size as u64 - 1 } else { 1 };
    let part_budget = budget.saturating_sub(held);
    let bar = crate::common::progress::progress_bar(tree.args.progress && rank == 0, "stacking");
    let progress = |p| crate::common::progress::report_progress(bar.as_ref(), p);
    let builder = tree.builder(source).progress(&progress);

    // 1. Partition: the slabs' costs, each rank measuring every P-th slab.
    let slabs = builder.slabs();
    let mut costs = vec![0u64; slabs.len()];
    let measured = pool
        .install(|| {
            slabs
                .par_iter()
                .enumerate()
                .filter(|(i, _)| i % size == rank)
                .map(|(i, &b0)| builder.slab_cost(b0).map(|c| (i, c)))
                .collect::<Result<Vec<_>, _>>()
        })
        .map_err(|e| CliError::in_file(out, e));
    let measured = agree(w, measured)?;
    for (i, c) in measured {
        costs[i] = c;
    }
    let mut all = vec![0u64; costs.len()];
    w.all_reduce_into(&costs[..], &mut all[..], SystemOperation::sum());
    let mine = balanced_parts(&all, size)[rank].clone();

    // 2. Stacking: this rank's slabs, spilled.
    let part = pool
        .install(|| builder.stack_part(&slabs[mine], out, part_budget))
        .map_err(|e| describe(out, e, held));
    let part = agree(w, part)?;

    // 3. Index, and 4. levels: the other ranks send, rank 0 writes.
    let written = gather_and_write(w, part, chunk, |part, receive| {
        let header = (builder.frame(), &ktree::io::Notes::new());
        let written =
            part.write_framed::<std::convert::Infallible>(out, header, receive, &progress);
        if let Some(bar) = &bar {
            bar.finish_and_clear();
        }
        written.map_err(|e| describe(out, e, held))
    })?;
    Ok(written)
}

/// The part of a build a rank stacked, as the ranks exchange it ([`SpilledPart`] without values,
/// [`ValuePart`] with).
trait RankPart {
    fn index_words(&self) -> Vec<u64>;
    fn add_part(&mut self, words: &[u64]) -> std::io::Result<u64>;
    fn stream_levels(
        &mut self,
        chunk_words: usize,
        send: &mut dyn FnMut(&[u64]) -> std::io::Result<()>,
    ) -> std::io::Result<u64>;
}

impl RankPart for SpilledPart<SpilledFiles> {
    fn index_words(&self) -> Vec<u64> {
        SpilledPart::index_words(self)
    }
    fn add_part(&mut self, words: &[u64]) -> std::io::Result<u64> {
        SpilledPart::add_part(self, words)
    }
    fn stream_levels(
        &mut self,
        chunk_words: usize,
        send: &mut dyn FnMut(&[u64]) -> std::io::Result<()>,
    ) -> std::io::Result<u64> {
        SpilledPart::stream_levels(self, chunk_words, send)
    }
}

impl<const K: usize, V: Value + Send + Sync> RankPart for ValuePart<K, V, SpilledFiles> {
    fn index_words(&self) -> Vec<u64> {
        ValuePart::index_words(self)
    }
    fn add_part(&mut self, words: &[u64]) -> std::io::Result<u64> {
        ValuePart::add_part(self, words)
    }
    fn stream_levels(
        &mut self,
        chunk_words: usize,
        send: &mut dyn FnMut(&[u64]) -> std::io::Result<()>,
    ) -> std::io::Result<u64> {
        ValuePart::stream_levels(self, chunk_words, send)
    }
}

/// Phases 3 and 4 of a build across ranks, once every rank stacked its `part`: the other ranks send rank 0
/// their indexes, then their levels in chunks of `chunk` words; rank 0 adds the indexes and writes the
/// tree with `write(part, receive)`, `receive(owner, words)` taking the next words of that rank's stream.
/// `Some(report)` on rank 0, `None` on the others.
fn gather_and_write<P: RankPart, R>(
    w: &SimpleCommunicator,
    mut part: P,
    chunk: usize,
    write: impl FnOnce(P, &mut dyn FnMut(usize, &mut [u64]) -> std::io::Result<()>) -> CliResult<R>,
) -> CliResult<Option<R>> {
    let Ranks { rank, size } = ranks();
    let root = w.process_at_rank(0);
    if rank != 0 {
        send_words(&root, &part.index_words(), chunk);
        agree(w, Ok(()))?;
        let mut message = Vec::with_capacity(chunk + 1);
        let streamed = part.stream_levels(chunk, &mut |words| {
            message.clear();
            message.push(CHUNK);
            message.extend_from_slice(words);
            root.send(&message[..]);
            Ok(())
        });
        if streamed.is_err() {
            root.send(&[FAILED][..]);
        }
        drop(part);
        agree(
            w,
            streamed.map_err(|e| CliError::about("sending the levels to rank 0".to_string(), e)),
        )?;
        root.gather_into(&crate::common::memory::peak_rss_bytes().unwrap_or(0));
        return Ok(None);
    }
    let mut moved = 0u64;
    let mut streams = Vec::with_capacity(size - 1);
    let mut added = Ok(());
    for r in 1..size {
        let from = w.process_at_rank(r as i32);
        let words = receive_words(&from);
        moved += 8 * words.len() as u64;
        match part.add_part(&words) {
            Ok(total) => streams.push(Stream::new(from, total)),
            Err(e) if added.is_ok() => added = Err(CliError::about(format!("rank {r}"), e)),
            Err(_) => {}
        }
    }
    agree(w, added)?;
    let written = write(part, &mut |owner, words| {
        streams[owner - 1].fill(owner, words)
    });
    // Take what is left of the streams, so that no rank waits on a send.
    for stream in &mut streams {
        stream.drain();
        moved += stream.received;
    }
    let report = agree(w, written)?;
    let mut peaks = vec![0u64; size];
    let own = crate::common::memory::peak_rss_bytes().unwrap_or(0);
    root.gather_into_root(&own, &mut peaks[..]);
    eprintln!(
        "ktree: {size} ranks; {moved} bytes sent to rank 0; peak memory per rank (MiB): {}",
        peaks
            .iter()
            .map(|p| format!("{:.1}", *p as f64 / (1u64 << 20) as f64))
            .collect::<Vec<_>>()
            .join(" ")
    );
    Ok(Some(report))
}

/// Builds a valued tree into the `.ktree` (version 3) file `out` (with `frame` and `notes`) across the
/// ranks of the run: the slabs `slabs` (those worth building: the others are empty) are cut into one
/// contiguous range a rank, and each rank builds and spills its own with `stack(range)` — a volume read
/// slab by slab reads only its own planes ([`ktree::stacking::ValueSlabs::stack_part_files`]), runs are
/// cut at its slabs ([`ktree::rays::ValueRuns::stack_part_files`]); rank 0 writes the file as
/// [`build_across_ranks`] does, byte for byte the single process's. `Some(report)` on rank 0, `None` on
/// the other ranks.
///
/// # Errors
/// The error of `stack` or of the files on this rank; [`STOPPED`] if another failed.
pub fn build_values_across_ranks<const K: usize, V: Value + Send + Sync>(
    slabs: std::ops::Range<u32>,
    out: &Path,
    frame: Option<&WorldFrame>,
    notes: &Notes,
    stack: impl FnOnce(std::ops::Range<u32>) -> CliResult<ValuePart<K, V, SpilledFiles>>,
) -> CliResult<Option<ValueSlabsReport>> {
    let w = world();
    let outcome = (|| {
        let Ranks { rank, size } = ranks();
        let chunk = (CHUNK_BYTES / 8) as usize;
        let n = u64::from(slabs.end - slabs.start);
        let cut = |r: usize| slabs.start + (n * r as u64 / size as u64) as u32;
        let part = agree(&w, stack(cut(rank)..cut(rank + 1)))?;
        gather_and_write(&w, part, chunk, |part, receive| {
            part.write::<std::convert::Infallible>(out, frame, notes, receive)
                .map_err(|e| describe(out, e, 0))
        })
    })();
    if outcome.is_err() {
        // Every rank has dropped its spill folder: none is stopped before it could.
        w.barrier();
        SETTLED.store(true, Ordering::SeqCst);
    }
    outcome
}

/// Sends `words` to `to`: their number, then chunks of at most `chunk` words.
fn send_words(to: &Process<'_>, words: &[u64], chunk: usize) {
    to.send(&(words.len() as u64));
    for piece in words.chunks(chunk) {
        to.send(piece);
    }
}

/// Receives what [`send_words`] sends.
fn receive_words(from: &Process<'_>) -> Vec<u64> {
    let (len, _) = from.receive::<u64>();
    let mut words = Vec::new();
    while (words.len() as u64) < len {
        let (piece, _) = from.receive_vec::<u64>();
        if words.is_empty() {
            words = piece;
        } else {
            words.extend_from_slice(&piece);
        }
    }
    words
}

/// The level stream of one other rank, as rank 0 takes it: the chunk being read.
struct Stream<'a> {
    from: Process<'a>,
    chunk: Vec<u64>,
    /// The next word of `chunk` to take.
    at: usize,
    /// Words the stream still brings.
    left: u64,
    /// The sender failed: its stream has ended.
    failed: bool,
    /// Bytes received.
    received: u64,
}

impl<'a> Stream<'a> {
    fn new(from: Process<'a>, words: u64) -> Self {
        Self {
            from,
            chunk: Vec::new(),
            at: 0,
            left: words,
            failed: false,
            received: 0,
        }
    }

    /// Receives the next message; `false` if the sender failed.
    fn next(&mut self) -> bool {
        let (message, _) = self.from.receive_vec::<u64>();
        self.received += 8 * message.len() as u64;
        if message.first() != Some(&CHUNK) {
            self.failed = true;
            return false;
        }
        self.left = self.left.saturating_sub(message.len() as u64 - 1);
        self.chunk = message;
        self.at = 1;
        true
    }

    /// Fills `words` with the next words of the stream of rank `owner`.
    fn fill(&mut self, owner: usize, mut words: &mut [u64]) -> std::io::Result<()> {
        while !words.is_empty() {
            if self.at == self.chunk.len() && (self.failed || self.left == 0 || !self.next()) {
                return Err(std::io::Error::other(format!(
                    "rank {owner} failed while sending its levels"
                )));
            }
            let take = words.len().min(self.chunk.len() - self.at);
            words[..take].copy_from_slice(&self.chunk[self.at..self.at + take]);
            self.at += take;
            words = &mut words[take..];
        }
        Ok(())
    }

    /// Receives (and drops) what is left of the stream.
    fn drain(&mut self) {
        self.chunk = Vec::new();
        self.at = 0;
        while self.left > 0 && !self.failed {
            self.next();
        }
    }
}
