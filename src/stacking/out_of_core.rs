//! Out-of-core stacking: a tree written straight to a `.ktree` version 2 file in bounded memory, its
//! subtrees spilled to temporary files as they are stacked.
//!
//! # How it runs
//! The cells of depth `m` are stacked slab by slab exactly as in [`stack_source`](super::stack_source),
//! but no finished subtree is kept: the levels `1, 2, …` of each partial cell's subtree are appended to
//! one temporary *spill file* per level (word-aligned, in the order the slabs finish), and only a small
//! index (the cell's Morton index and its node count per level) and the states of the cells of depth `m`
//! (see *Memory*) stay in memory. At the end the file is written level by level through a [`KtreeWriter`]: the
//! top levels `0 … m` (from the cells' states; a uniform top collapses), then each level `m + j` as the
//! concatenation, in Morton order of the cells, of the subtrees' levels `j` read back from spill file `j`
//! (the writer shifts each piece into place). The file goes to a temporary file renamed over the target
//! ([`write_atomic_with`]), so the bytes are exactly those of the tree built in memory and written by
//! [`write_ktree_v2`](crate::io::write_ktree_v2), for any number of threads.
//!
//! # Memory
//! The budget ([`OutOfCore::max_memory`]) is kept by accounting, not by measuring the process:
//! [`RUN_BYTES`] bytes per run of each slab being stacked (its copies and the subtrees made from it, until
//! they are spilled), the states of the cells of depth `m` (2 bits a cell, all of them, up to `2^28` cells;
//! above, [`CELL_BYTES`] per non-empty cell), [`SUBTREE_BYTES`] plus 8 per level for
//! each stacked cell, and the I/O buffers ([`BUFFER_BYTES`] per spill file and two more). The first slab
//! runs alone; then rounds of up to as many slabs as the rayon pool has threads run at once, as many as
//! the largest slab seen so far allows in what is left of the budget; a slab whose rays turn out not to fit
//! beside those already admitted is set aside (its rays dropped) for the next round. Only these rays, made
//! before their size is known, are held beyond the accounted figure. If a slab does not fit even alone, the
//! slabs not yet stacked are only measured (their rays made and their cells classified, nothing stacked)
//! and [`OutOfCoreError::BudgetTooSmall`] names the budget the build needs: what it holds at its end plus
//! its largest slab (with it, every slab fits whatever the order slabs finish in).
//!
//! # Temporary files
//! The spill files live in a hidden folder `.NAME.XXXXXX.PID.ktree-spill` in [`OutOfCore::temp_dir`] (by
//! default the output's folder), removed when the build ends, whether it succeeds or fails; a process
//! killed mid-build leaves it behind, and the next build of the same output removes the folders of
//! processes that no longer run.
//!
//! ```
//! use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
//! use ktree::stacking::{stack_source, stack_to_file, OutOfCore};
//! let ball = Solid::Quadric(Quadric::<3>::ball([Rational::int(16); 3], Rational::int(11), Frame::Voxel).unwrap());
//! let source = SolidSource::new(&ball, 5, Sample::Centre).unwrap();
//! let dir = tempfile::tempdir().unwrap();
//! let out = dir.path().join("ball.ktree");
//! let report = stack_to_file(&source, &out, &OutOfCore::new(2, 1 << 30), &|_| {}).unwrap();
//! let tree = stack_source(&source, 2).unwrap();
//! assert_eq!(ktree::io::read_ktree_file(&out).unwrap(), ktree::io::AnyTree::K3(tree.clone()));
//! assert_eq!(report.counts_per_level, tree.counts_per_level());
//! ```

use std::collections::VecDeque;
use std::fmt::Display;
use std::fs::File;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use super::partition::{slab_pieces, top_levels, top_levels_dense, Piece, RaySource};

/// The suffix of spill folders: `.NAME.XXXXXX.PID.ktree-spill`.
const SPILL_SUFFIX: &str = ".ktree-spill";
use crate::io::{write_atomic_with, KtreeWriter};
use crate::tree::{LevelCounts, NodeState, PackedStates};

/// Bytes accounted for each run of a slab being stacked: the runs and their copies while they are cut
/// into cells, and the subtrees made from them until they are spilled.
pub const RUN_BYTES: u64 = 64;
/// Bytes accounted for each non-empty cell of depth `m` when they are listed (more than `2^28` cells): its
/// Morton index and state, and its share of the top levels made from them at the end. Up to `2^28` cells
/// are kept densely instead, at 2 bits each, accounted three times over (the pyramid and the top levels).
pub const CELL_BYTES: u64 = 24;
/// The cells of depth `m` are kept densely, two bits each, when there are at most `2^DENSE_BITS` of them
/// (64 MiB); above, as a sorted list of the non-empty ones.
const DENSE_BITS: u32 = 28;

/// Bytes accounted for each stacked cell, besides 8 per level of its subtree (its place in the index and
/// in the order the levels are written in).
pub const SUBTREE_BYTES: u64 = 24;
/// Bytes of each I/O buffer (one per spill file, one for the output, one for reading back).
pub const BUFFER_BYTES: u64 = 1 << 16;

/// How an out-of-core build runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutOfCore {
    /// The depth `m` of the cells stacked apart (clamped to `L`).
    pub depth: u32,
    /// The memory budget in bytes (see the module's notes on how it is accounted).
    pub max_memory: u64,
    /// The folder of the spill files; `None`: the output's folder.
    pub temp_dir: Option<PathBuf>,
}

impl OutOfCore {
    /// Cells of depth `depth`, a budget of `max_memory` bytes, spill files next to the output.
    pub fn new(depth: u32, max_memory: u64) -> Self {
        Self {
            depth,
            max_memory,
            temp_dir: None,
        }
    }
}

/// What an out-of-core build is doing, for progress reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Stacking slabs of cells (`done` of `total` slabs).
    Stacking,
    /// Writing the output file (`done` of `total` levels).
    Writing,
}

/// A progress report: `done` of `total` steps of a stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// The stage.
    pub stage: Stage,
    /// Steps done.
    pub done: u64,
    /// Steps in the stage.
    pub total: u64,
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

/// Why an out-of-core build failed. The target file is untouched and the spill files are removed.
#[derive(Debug, thiserror::Error)]
pub enum OutOfCoreError<E> {
    /// The source could not produce its rays.
    #[error("{0}")]
    Source(E),
    /// Not even one slab of cells (or the index of the stacked cells) fits in the budget.
    #[error(
        "a memory budget of {} is too small for this build: it needs a budget of at least {}",
        bytes_text(*budget),
        bytes_text(*needed)
    )]
    BudgetTooSmall {
        /// The budget given, in bytes.
        budget: u64,
        /// A budget with which the build runs, in bytes: what it holds at its end plus its largest slab.
        needed: u64,
    },
    /// The folder for the spill files cannot be used.
    #[error("cannot create spill files in the temporary folder {}: {source}", path.display())]
    TempDir {
        /// The folder.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A spill file cannot be written.
    #[error("cannot write the spill file {}: {source}", path.display())]
    Spill {
        /// The spill file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The output cannot be written (the message names it).
    #[error("{source}")]
    Output {
        /// The output file.
        path: PathBuf,
        /// The error, naming the output or the spill file read back.
        source: std::io::Error,
    },
}

/// A byte count with its size in MiB or GiB, for messages.
fn bytes_text(bytes: u64) -> String {
    const MIB: f64 = 1024.0 * 1024.0;
    let b = bytes as f64;
    if b >= 1024.0 * MIB {
        format!("{bytes} bytes ({:.2} GiB)", b / (1024.0 * MIB))
    } else {
        format!("{bytes} bytes ({:.1} MiB)", b / MIB)
    }
}

/// The spill files: one per subtree level `1 … t`.
struct Spill {
    dir: tempfile::TempDir,
    files: Vec<BufWriter<File>>,
    /// Words written to each file.
    words: Vec<u64>,
}

impl Spill {
    fn path(&self, j: usize) -> PathBuf {
        self.dir.path().join(format!("level-{j}"))
    }
}

/// The stacked cells, in the order they were spilled: Morton index and node count per subtree level
/// `1 … t` (0 beyond the subtree's depth).
#[derive(Default)]
struct SubtreeIndex {
    mortons: Vec<u64>,
    counts: Vec<u64>,
}

/// The states of the non-empty cells of depth `m`.
enum CellStates {
    /// All `2^(K·m)` cells, two bits each in Morton order (`00` for the empty ones).
    Dense(Vec<u64>),
    /// The non-empty cells as (Morton index, state).
    Sparse(Vec<(u64, NodeState)>),
}

impl CellStates {
    fn new(k: u32, m: u32) -> Self {
        if k * m <= DENSE_BITS {
            Self::Dense(vec![0; (1usize << (k * m)).div_ceil(32)])
        } else {
            Self::Sparse(Vec::new())
        }
    }

    fn set(&mut self, index: u64, state: NodeState) {
        match self {
            Self::Dense(words) => {
                words[(index / 32) as usize] |= (state as u64) << (2 * (index % 32))
            }
            Self::Sparse(cells) => cells.push((index, state)),
        }
    }

    /// The bytes accounted for the cells once `more` further non-empty cells are added.
    fn bytes_with(&self, more: usize) -> u64 {
        match self {
            Self::Dense(words) => 3 * 8 * words.len() as u64,
            Self::Sparse(cells) => (cells.len() + more) as u64 * CELL_BYTES,
        }
    }

    fn bytes(&self) -> u64 {
        self.bytes_with(0)
    }

    /// The top levels `0 … m` of the tree.
    fn into_top_levels(self, k: u32, m: u32) -> Vec<PackedStates> {
        match self {
            Self::Dense(words) => {
                let base = PackedStates::from_words(words, 1usize << (k * m))
                    .expect("cells hold the codes of node states");
                top_levels_dense(k, m, base)
            }
            Self::Sparse(mut cells) => {
                cells.sort_unstable();
                top_levels(k, m, cells)
            }
        }
    }
}

/// The memory accounting of a build.
struct Budget {
    max: u64,
    /// Levels of a subtree below its root.
    t: u64,
    peak: u64,
}

impl Budget {
    /// The memory held between slabs: cells, index, buffers.
    fn fixed(&self, cell_bytes: u64, subtrees: usize) -> u64 {
        cell_bytes
            + subtrees as u64 * (SUBTREE_BYTES + 8 * (self.t + 1))
            + (self.t + 2) * BUFFER_BYTES
    }
}

/// What came of one slab in a round of slabs run at once.
enum SlabOutcome<const K: usize> {
    Stacked {
        cost: u64,
        pieces: Vec<(u64, Piece<K>)>,
    },
    /// The slab does not fit beside the slabs running at once: it runs in a later round.
    SetAside,
    /// The slab does not fit in the budget even alone: nothing was stacked.
    TooBig { cost: u64 },
}

/// Builds the tree of `source` from its cells of depth `options.depth` and writes it to `out` as a
/// `.ktree` version 2 file, in the memory budget `options.max_memory`, on the threads of the current rayon
/// pool; `progress` is called (on the calling thread) as slabs are stacked and levels written. The file
/// is byte for byte the one [`write_ktree_v2_file`](crate::io::write_ktree_v2_file) writes for the tree
/// [`stack_source`](super::stack_source) builds.
///
/// # Errors
/// [`OutOfCoreError`]: the source's first error (in slab order), a budget too small, a temporary folder
/// or output that cannot be written (a full disk included). The target is then untouched and no
/// temporary file remains.
pub fn stack_to_file<const K: usize, S>(
    source: &S,
    out: &Path,
    options: &OutOfCore,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<OutOfCoreReport, OutOfCoreError<S::Error>>
where
    S: RaySource<K>,
    S::Error: Display,
{
    let universe = source.universe();
    let level = universe.level();
    let m = options.depth.min(level);
    let t = level - m;
    let slabs = if K == 1 {
        vec![0]
    } else {
        source.occupied_slabs(m)
    };
    let mut spill = open_spill(out, options.temp_dir.as_deref(), t as usize)?;
    let mut budget = Budget {
        max: options.max_memory,
        t: u64::from(t),
        peak: 0,
    };
    let mut cells = CellStates::new(K as u32, m);
    let mut index = SubtreeIndex::default();
    let threads = rayon::current_num_threads().max(1);
    let total = slabs.len() as u64;
    let mut done = 0u64;
    progress(Progress {
        stage: Stage::Stacking,
        done,
        total,
    });
    let mut queue: VecDeque<u32> = slabs.into();
    // The largest slab cost seen; the first slab runs alone to learn it.
    let mut largest = 0u64;
    let mut window = 1;
    while !queue.is_empty() {
        let round: Vec<u32> = queue.drain(..window.min(queue.len())).collect();
        let fixed = budget.fixed(cells.bytes(), index.mortons.len());
        let in_flight = AtomicU64::new(0);
        let outcomes = round
            .par_iter()
            .map(|&b0| {
                let side = 1u32 << t;
                let slab = source
                    .slab(b0 * side..(b0 + 1) * side)
                    .map_err(OutOfCoreError::Source)?;
                let cost = slab.runs.len() as u64 * RUN_BYTES;
                if fixed.saturating_add(cost) > budget.max {
                    return Ok(SlabOutcome::TooBig { cost });
                }
                let before = in_flight.fetch_add(cost, Ordering::SeqCst);
                if fixed.saturating_add(before).saturating_add(cost) > budget.max {
                    in_flight.fetch_sub(cost, Ordering::SeqCst);
                    return Ok(SlabOutcome::SetAside);
                }
                let pieces = slab_pieces::<K>(&slab, level, m, b0, true);
                Ok(SlabOutcome::Stacked { cost, pieces })
            })
            .collect::<Vec<Result<SlabOutcome<K>, OutOfCoreError<S::Error>>>>();
        let (mut set_aside, mut too_big, mut round_cost) = (Vec::new(), false, 0u64);
        for (&b0, outcome) in round.iter().zip(outcomes) {
            match outcome? {
                SlabOutcome::Stacked { cost, pieces } => {
                    largest = largest.max(cost);
                    round_cost += cost;
                    done += 1;
                    for (morton, piece) in pieces {
                        spill_piece(&mut spill, &mut cells, &mut index, morton, piece)?;
                    }
                }
                SlabOutcome::SetAside => set_aside.push(b0),
                SlabOutcome::TooBig { cost } => {
                    largest = largest.max(cost);
                    too_big = true;
                    set_aside.push(b0);
                }
            }
        }
        budget.peak = budget.peak.max(fixed + round_cost);
        if too_big {
            set_aside.extend(queue);
            let needed = survey::<K, S>(
                source,
                &budget,
                m,
                &set_aside,
                &cells,
                index.mortons.len(),
                largest,
            )?;
            return Err(OutOfCoreError::BudgetTooSmall {
                budget: budget.max,
                needed,
            });
        }
        for &b0 in set_aside.iter().rev() {
            queue.push_front(b0);
        }
        progress(Progress {
            stage: Stage::Stacking,
            done,
            total,
        });
        let free = budget
            .max
            .saturating_sub(budget.fixed(cells.bytes(), index.mortons.len()));
        window = (free / largest.max(1)).clamp(1, threads as u64) as usize;
    }
    let end = budget.fixed(cells.bytes(), index.mortons.len());
    if end > budget.max {
        return Err(OutOfCoreError::BudgetTooSmall {
            budget: budget.max,
            needed: end + largest,
        });
    }
    budget.peak = budget.peak.max(end);
    let spilled_bytes = 8 * spill.words.iter().sum::<u64>();
    let subtrees = index.mortons.len() as u64;
    let counts_per_level =
        write_levels::<K, S::Error>(out, level, m, cells, &index, spill, progress)?;
    let file_bytes = std::fs::metadata(out)
        .map_err(|source| OutOfCoreError::Output {
            path: out.to_path_buf(),
            source,
        })?
        .len();
    Ok(OutOfCoreReport {
        counts_per_level,
        file_bytes,
        subtrees,
        spilled_bytes,
        peak_accounted_bytes: budget.peak,
    })
}

/// Creates the spill folder and its `t` files.
fn open_spill<E>(
    out: &Path,
    temp_dir: Option<&Path>,
    t: usize,
) -> Result<Spill, OutOfCoreError<E>> {
    let dir = match temp_dir {
        Some(d) => d.to_path_buf(),
        None => match out.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        },
    };
    let temp_err = |source| OutOfCoreError::TempDir {
        path: dir.clone(),
        source,
    };
    if temp_dir.is_none() {
        std::fs::create_dir_all(&dir).map_err(temp_err)?;
    }
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    crate::io::remove_stale(&dir, &name, SPILL_SUFFIX);
    let folder = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(&format!(".{}{SPILL_SUFFIX}", std::process::id()))
        .tempdir_in(&dir)
        .map_err(temp_err)?;
    let mut spill = Spill {
        dir: folder,
        files: Vec::with_capacity(t),
        words: vec![0; t],
    };
    for j in 1..=t {
        let path = spill.path(j);
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&path)
            .map_err(|source| OutOfCoreError::Spill { path, source })?;
        spill
            .files
            .push(BufWriter::with_capacity(BUFFER_BYTES as usize, file));
    }
    Ok(spill)
}

/// Records a non-empty cell of depth `m`, spilling the levels below its root if it is partial.
fn spill_piece<const K: usize, E>(
    spill: &mut Spill,
    cells: &mut CellStates,
    index: &mut SubtreeIndex,
    morton: u64,
    piece: Piece<K>,
) -> Result<(), OutOfCoreError<E>> {
    let tree = match piece {
        Piece::Full => {
            cells.set(morton, NodeState::Full);
            return Ok(());
        }
        Piece::Tree(tree) => tree,
        Piece::Unstacked => unreachable!("stacked slabs have no unstacked cells"),
    };
    match tree.root_state() {
        NodeState::Empty => return Ok(()),
        NodeState::Full => {
            cells.set(morton, NodeState::Full);
            return Ok(());
        }
        NodeState::Partial => cells.set(morton, NodeState::Partial),
    }
    index.mortons.push(morton);
    for j in 1..=spill.files.len() {
        let nodes = if j < tree.depth_count() {
            let states = tree.level_states(j);
            let words = &states.words()[..states.len().div_ceil(32)];
            let file = &mut spill.files[j - 1];
            for w in words {
                file.write_all(&w.to_le_bytes())
                    .map_err(|source| OutOfCoreError::Spill {
                        path: spill.dir.path().join(format!("level-{j}")),
                        source,
                    })?;
            }
            spill.words[j - 1] += words.len() as u64;
            states.len() as u64
        } else {
            0
        };
        index.counts.push(nodes);
    }
    Ok(())
}

/// Measures the slabs not stacked (their rays made and cells classified, nothing stacked) and returns
/// the budget with which any slab fits at any point of the build: what the build holds at its end (every
/// mixed cell counted as stacked) plus the largest slab.
fn survey<const K: usize, S>(
    source: &S,
    budget: &Budget,
    m: u32,
    rest: &[u32],
    cells: &CellStates,
    mut subtrees: usize,
    mut largest: u64,
) -> Result<u64, OutOfCoreError<S::Error>>
where
    S: RaySource<K>,
{
    let level = source.universe().level();
    let side = 1u32 << (level - m);
    let mut more = 0;
    for &b0 in rest {
        let slab = source
            .slab(b0 * side..(b0 + 1) * side)
            .map_err(OutOfCoreError::Source)?;
        largest = largest.max(slab.runs.len() as u64 * RUN_BYTES);
        for (_, piece) in slab_pieces::<K>(&slab, level, m, b0, false) {
            more += 1;
            if matches!(piece, Piece::Unstacked) {
                subtrees += 1;
            }
        }
    }
    Ok(budget.fixed(cells.bytes_with(more), subtrees) + largest)
}

/// Writes the output: the top levels from the cells' states, then each level below as the subtrees'
/// levels read back from the spill files in Morton order.
fn write_levels<const K: usize, E>(
    out: &Path,
    level: u32,
    m: u32,
    cells: CellStates,
    index: &SubtreeIndex,
    spill: Spill,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<LevelCounts>, OutOfCoreError<E>> {
    let Spill {
        dir,
        files,
        words: _,
    } = spill;
    let t = files.len();
    let mut readers = Vec::with_capacity(t);
    for (j, file) in files.into_iter().enumerate() {
        let path = dir.path().join(format!("level-{}", j + 1));
        let file = file.into_inner().map_err(|e| OutOfCoreError::Spill {
            path: path.clone(),
            source: e.into_error(),
        })?;
        readers.push((path, file));
    }
    let top = cells.into_top_levels(K as u32, m);
    let n = index.mortons.len();
    // The stacked cells in Morton order, and the deepest subtree level.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by_key(|&s| index.mortons[s]);
    let deepest = (1..=t)
        .rev()
        .find(|&j| (0..n).any(|s| index.counts[s * t + j - 1] > 0))
        .unwrap_or(0);
    let total = (top.len() + deepest) as u64;
    let mut counts = Vec::new();
    write_atomic_with(out, |w| {
        let mut writer = KtreeWriter::new(w, K, level)?;
        let mut done = 0;
        for states in &top {
            writer.append_states(states)?;
            writer.end_level()?;
            done += 1;
            progress(Progress {
                stage: Stage::Writing,
                done,
                total,
            });
        }
        drop(top);
        let mut offsets = vec![0u64; n];
        let mut buffer: Vec<u8> = Vec::new();
        let mut words: Vec<u64> = Vec::new();
        for (j, (path, file)) in readers.iter_mut().enumerate().take(deepest) {
            let with_path = |e: std::io::Error| {
                std::io::Error::new(e.kind(), format!("spill file {}: {e}", path.display()))
            };
            let mut at = 0u64;
            for (s, offset) in offsets.iter_mut().enumerate() {
                *offset = at;
                at += index.counts[s * t + j].div_ceil(32);
            }
            for &s in &order {
                let nodes = index.counts[s * t + j];
                if nodes == 0 {
                    continue;
                }
                let count = nodes.div_ceil(32) as usize;
                buffer.resize(8 * count, 0);
                file.seek(SeekFrom::Start(8 * offsets[s]))
                    .map_err(with_path)?;
                file.read_exact(&mut buffer).map_err(with_path)?;
                words.clear();
                words.extend(
                    buffer
                        .chunks_exact(8)
                        .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes"))),
                );
                writer.append_words(&words, nodes)?;
            }
            writer.end_level()?;
            done += 1;
            progress(Progress {
                stage: Stage::Writing,
                done,
                total,
            });
        }
        counts = writer.counts_per_level();
        writer.finish().map(drop)
    })
    .map_err(|source| OutOfCoreError::Output {
        path: out.to_path_buf(),
        source,
    })?;
    drop(readers);
    drop(dir);
    Ok(counts)
}
