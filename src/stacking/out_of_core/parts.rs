//! A build in parts: some slabs stacked and spilled by each part ([`stack_part`]), the parts' indexes
//! gathered by one of them, which writes the tree ([`SpilledPart::write_into`]) — as the ranks of a
//! distributed run do, and as a build in one process does with one part of every slab.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use super::budget::{Budget, RUN_BYTES};
use super::error::BuildError;
use super::pieces::{ChunkedSend, LevelPieces, PieceStore, StoredPieces};
use super::progress::{Progress, Stage};
use super::sink::LevelOrderSink;
use super::spill::{level_offsets, spill_piece, SubtreeIndex};
use super::{OutOfCore, OutOfCoreReport, StoreBuildError};
use crate::rays::RaySource;
use crate::stacking::cells::{CellBlock, CellStates};
use crate::stacking::partition::{slab_pieces, Piece};
use crate::tree::NodeState;

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

/// The slabs of cells of depth `depth` (clamped to `L`) an out-of-core build stacks, numbered along axis 0
/// in increasing order: those of [`RaySource::occupied_slabs`] (the one slab `0` for `K = 1`).
pub(crate) fn build_slabs<const K: usize, S: RaySource<K>>(source: &S, depth: u32) -> Vec<u32> {
    if K == 1 {
        vec![0]
    } else {
        source.occupied_slabs(depth.min(source.universe().level()))
    }
}

/// The estimated cost of stacking slab `b0` of the cells of depth `depth`: the bytes accounted for its runs
/// ([`RUN_BYTES`] each), which the size of the subtrees it makes follows. The runs are made and dropped.
///
/// # Errors
/// The source's error.
pub(crate) fn slab_cost<const K: usize, S: RaySource<K>>(
    source: &S,
    depth: u32,
    b0: u32,
) -> Result<u64, S::Error> {
    let level = source.universe().level();
    let side = 1u32 << (level - depth.min(level));
    let slab = source.slab(b0 * side..(b0 + 1) * side)?;
    Ok(slab.runs.len() as u64 * RUN_BYTES)
}

/// Cuts a sequence of slabs with their costs into `parts` contiguous ranges (of positions in `costs`, in
/// order, covering it) of about equal total cost; some ranges are empty when there are fewer slabs than
/// parts.
///
/// ```
/// use ktree::stacking::balanced_parts;
/// assert_eq!(balanced_parts(&[5, 1, 1, 1, 1, 1], 2), vec![0..1, 1..6]);
/// assert_eq!(balanced_parts(&[1], 3), vec![0..1, 1..1, 1..1]);
/// ```
pub fn balanced_parts(costs: &[u64], parts: usize) -> Vec<std::ops::Range<usize>> {
    let parts = parts.max(1);
    let total: u128 = costs.iter().map(|&c| u128::from(c.max(1))).sum();
    let mut bounds = vec![0usize];
    let mut at = 0usize;
    let mut sum = 0u128;
    for p in 1..parts {
        // The part ends after the last slab whose middle lies within its share of the total (rounded up:
        // ties go to the earlier part).
        let share = (total * p as u128).div_ceil(parts as u128);
        while at < costs.len() && 2 * sum + u128::from(costs[at].max(1)) <= 2 * share {
            sum += u128::from(costs[at].max(1));
            at += 1;
        }
        bounds.push(at);
    }
    bounds.push(costs.len());
    bounds.windows(2).map(|w| w[0]..w[1]).collect()
}

/// The stacking phase of an out-of-core build run on some of its slabs (for a process that builds a
/// share of the tree): the cells of `slabs` (numbers from [`build_slabs`], increasing) are stacked, on the
/// threads of the current rayon pool, and their subtrees spilled to `store` (levels `1 … L − m`). The
/// part's index travels to the part that writes ([`SpilledPart::index_words`], [`SpilledPart::add_part`])
/// and its levels follow ([`SpilledPart::stream_levels`]); a build of one part writes at once
/// ([`SpilledPart::write_into`]).
///
/// # Errors
/// [`BuildError`]: the source's first error (in slab order), a budget too small for this part (at once
/// when what is known before any slab is stacked does not fit), the store's error.
pub(crate) fn stack_part<const K: usize, S, P>(
    source: &S,
    slabs: &[u32],
    mut store: P,
    options: &OutOfCore,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<SpilledPart<P::Stored>, StoreBuildError<S::Error, P>>
where
    S: RaySource<K>,
    P: PieceStore,
{
    let universe = source.universe();
    let level = universe.level();
    let m = options.depth.min(level);
    let t = level - m;
    let mut budget = Budget {
        max: options.max_memory,
        t: u64::from(t),
        peak: 0,
    };
    let mut cells = CellStates::new(K as u32, m);
    let mut index = SubtreeIndex::default();
    let mut spilled_words = 0u64;
    // What is held before any slab is stacked (the buffers): a budget below it fails before any work.
    let before = budget.fixed(cells.bytes(), 0);
    if before > budget.max {
        return Err(BuildError::BudgetTooSmall {
            budget: budget.max,
            needed: before,
        });
    }
    let threads = rayon::current_num_threads().max(1);
    let total = slabs.len() as u64;
    let mut done = 0u64;
    progress(Progress {
        stage: Stage::Stacking,
        done,
        total,
    });
    let mut queue: VecDeque<u32> = slabs.iter().copied().collect();
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
                    .map_err(BuildError::Source)?;
                let cost = slab.runs.len() as u64 * RUN_BYTES;
                if fixed.saturating_add(cost) > budget.max {
                    return Ok(SlabOutcome::TooBig { cost });
                }
                let before = in_flight.fetch_add(cost, Ordering::SeqCst);
                if fixed.saturating_add(before).saturating_add(cost) > budget.max {
                    in_flight.fetch_sub(cost, Ordering::SeqCst);
                    return Ok(SlabOutcome::SetAside);
                }
                let pieces = slab_pieces::<K>(&slab, level, m, b0, options.cells);
                Ok(SlabOutcome::Stacked { cost, pieces })
            })
            .collect::<Vec<Result<SlabOutcome<K>, BuildError<S::Error, P::Error>>>>();
        let (mut set_aside, mut too_big, mut round_cost) = (Vec::new(), false, 0u64);
        for (&b0, outcome) in round.iter().zip(outcomes) {
            match outcome? {
                SlabOutcome::Stacked { cost, mut pieces } => {
                    largest = largest.max(cost);
                    round_cost += cost;
                    done += 1;
                    // Spilled in Morton order, the order they are read back in: each slab's part of a
                    // spill file is then read front to back, and its disk given back as it goes.
                    pieces.sort_unstable_by_key(|&(morton, _)| morton);
                    for (morton, piece) in pieces {
                        spilled_words += spill_piece(
                            &mut store, t as usize, &mut cells, &mut index, morton, piece,
                        )?;
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
            // Fail at once, naming what is known to be needed: what is held plus the largest slab.
            return Err(BuildError::BudgetTooSmall {
                budget: budget.max,
                needed: fixed + largest,
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
        return Err(BuildError::BudgetTooSmall {
            budget: budget.max,
            needed: end + largest,
        });
    }
    budget.peak = budget.peak.max(end);
    Ok(SpilledPart {
        k: K as u32,
        level,
        m,
        cells,
        own: index,
        others: Vec::new(),
        pieces: store.finish()?,
        budget,
        largest,
        spilled_bytes: 8 * spilled_words,
    })
}

/// The cells of some slabs stacked and their subtrees spilled to the stored pieces `P`
/// ([`Builder::stack_part`](crate::stacking::Builder::stack_part) to spill files,
/// [`Builder::stack_part_into`](crate::stacking::Builder::stack_part_into) to any [`PieceStore`]), and the
/// index of the parts other processes stacked ([`add_part`](Self::add_part)): all that is needed to write
/// the tree ([`write`](Self::write) to a file, [`write_into`](Self::write_into) to any
/// [`LevelOrderSink`]), with the levels of the other parts received as streams. The pieces (the spill
/// folder) are dropped with the part.
pub struct SpilledPart<P> {
    k: u32,
    level: u32,
    m: u32,
    /// The states of the non-empty cells of depth `m`, of this part and the parts added.
    cells: CellStates,
    /// The cells stacked here.
    own: SubtreeIndex,
    /// The cells stacked by the parts added, owner `1, 2, …` in the order added.
    others: Vec<SubtreeIndex>,
    /// The subtrees' levels `1 … t` of the cells stacked here, for reading back.
    pieces: P,
    budget: Budget,
    largest: u64,
    /// Bytes written to spill files by this part and the parts added.
    spilled_bytes: u64,
}

/// The words of an index header: magic, K, L, m, 0 (reserved), cell words, subtrees, spilled bytes.
const INDEX_HEADER: usize = 8;
/// The most parts a tree is written from.
pub const MAX_PARTS: usize = 1 << 16;
/// The first word of a part's index.
const INDEX_MAGIC: u64 = u64::from_le_bytes(*b"ktpart02");

impl<P: StoredPieces> SpilledPart<P> {
    /// The dimension `K` of the tree.
    pub(crate) fn k(&self) -> usize {
        self.k as usize
    }

    /// The level `L` of the tree's universe.
    pub(crate) fn level(&self) -> u32 {
        self.level
    }

    /// Levels of a subtree below its root.
    fn t(&self) -> usize {
        (self.level - self.m) as usize
    }

    /// The cells of depth `m` stacked by this part.
    pub fn subtrees(&self) -> u64 {
        self.own.mortons.len() as u64
    }

    /// The index of this part for the process that writes the tree ([`add_part`](Self::add_part)): the
    /// blocks of its full cells of depth `m` (first cell and depth), and for each cell it stacked its
    /// Morton index and node count per subtree level — a few words per stacked cell, nothing of the subtrees themselves.
    pub fn index_words(&self) -> Vec<u64> {
        let cell_words: Vec<u64> = self
            .cells
            .held()
            .flat_map(|b| [b.first, u64::from(b.depth)])
            .collect();
        let mut words = vec![
            INDEX_MAGIC,
            u64::from(self.k),
            u64::from(self.level),
            u64::from(self.m),
            0,
            cell_words.len() as u64,
            self.own.mortons.len() as u64,
            self.spilled_bytes,
        ];
        words.extend(cell_words);
        words.extend(&self.own.mortons);
        words.extend(&self.own.counts);
        words
    }

    /// Adds the index of a part stacked elsewhere ([`index_words`](Self::index_words) of a part of the
    /// same build, over other slabs), as owner `1, 2, …` in the order added; returns the number of words
    /// its [`stream_levels`](Self::stream_levels) sends.
    ///
    /// # Errors
    /// [`std::io::ErrorKind::InvalidData`] if `words` is not the index of a part of this build.
    pub fn add_part(&mut self, words: &[u64]) -> std::io::Result<u64> {
        let bad = |what: &str| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("the index of part {}: {what}", self.others.len() + 1),
            )
        };
        if self.others.len() + 1 >= MAX_PARTS {
            return Err(bad("too many parts"));
        }
        if words.len() < INDEX_HEADER || words[0] != INDEX_MAGIC {
            return Err(bad("not a part index"));
        }
        if words[1..5]
            != [
                u64::from(self.k),
                u64::from(self.level),
                u64::from(self.m),
                0,
            ]
        {
            return Err(bad("another K, level, split depth or cell layout"));
        }
        if !words[5].is_multiple_of(2) {
            return Err(bad("an odd number of cell words"));
        }
        let t = self.t();
        let (cell_words, n) = (words[5], words[6]);
        let expected =
            (n as u128) * (t as u128 + 1) + u128::from(cell_words) + INDEX_HEADER as u128;
        if expected != words.len() as u128 {
            return Err(bad("its length does not match its header"));
        }
        let cell_words = cell_words as usize;
        let n = n as usize;
        let body = &words[INDEX_HEADER..];
        let (cell_part, rest) = body.split_at(cell_words);
        let (mortons, counts) = rest.split_at(n);
        let k = u64::from(self.k);
        let mut stream = 0u64;
        for (s, &morton) in mortons.iter().enumerate() {
            if u128::from(morton) >> (k * u64::from(self.m)) != 0 {
                return Err(bad("a cell outside the universe"));
            }
            for (j, &nodes) in counts[s * t..(s + 1) * t].iter().enumerate() {
                if u128::from(nodes) > 1u128 << (k * (j as u64 + 1)).min(127) {
                    return Err(bad("more nodes than a subtree level holds"));
                }
                stream += nodes.div_ceil(32);
            }
        }
        let m = self.m;
        let mut blocks = Vec::with_capacity(cell_words / 2);
        for pair in cell_part.chunks_exact(2) {
            let (first, depth) = (pair[0], pair[1]);
            if depth > u64::from(m)
                || u128::from(first) >> (k * u64::from(m)) != 0
                || first % (1u64 << (k * (u64::from(m) - depth))) != 0
            {
                return Err(bad("a block of cells out of place"));
            }
            blocks.push(CellBlock {
                first,
                depth: depth as u32,
                state: NodeState::Full,
            });
        }
        self.cells
            .add_blocks(blocks)
            .map_err(|_| bad("a cell of two parts"))?;
        self.spilled_bytes += words[7];
        self.others.push(SubtreeIndex {
            mortons: mortons.to_vec(),
            counts: counts.to_vec(),
        });
        Ok(stream)
    }

    /// Sends this part's subtree levels to the process that writes the tree: for each level `1 … t`, the
    /// pieces of the cells it stacked in Morton order (each piece `⌈nodes / 32⌉` words), concatenated and
    /// cut into chunks of at most `chunk_words` words handed to `send` in order; returns the words sent.
    /// The writer takes them in the same order ([`write_into`](Self::write_into)).
    ///
    /// # Errors
    /// A piece that cannot be read back (naming its spill file), or the error of `send`.
    pub fn stream_levels(
        &mut self,
        chunk_words: usize,
        send: &mut dyn FnMut(&[u64]) -> std::io::Result<()>,
    ) -> std::io::Result<u64>
    where
        P::Error: Into<std::io::Error>,
    {
        let t = self.t();
        let n = self.own.mortons.len();
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_unstable_by_key(|&s| self.own.mortons[s]);
        let mut stream = ChunkedSend::new(chunk_words, send);
        let mut offsets = vec![0u64; n];
        for j in 0..t {
            let at = level_offsets(&self.own, t, j, &mut offsets);
            let mut level = self.pieces.level(j + 1, &offsets, at);
            for &s in &order {
                let count = self.own.counts[s * t + j].div_ceil(32);
                stream.push_from(count, |at, out| level.read(s, at, out).map_err(Into::into))?;
            }
            level.finish();
        }
        stream.finish()
    }

    /// The writing phase: writes the tree to `output`, level after level — the top levels from the cells'
    /// states, then each level below as the pieces of the stacked cells in Morton order, each from its
    /// owner: this part's pieces, or `receive(owner, words)`, which fills `words` with the next words of
    /// that owner's [`stream_levels`](Self::stream_levels). Returns the finished output and the report
    /// (its `file_bytes` 0: the output's size is the output's own; [`write`](Self::write) gives the
    /// file's).
    ///
    /// # Errors
    /// [`BuildError::BudgetTooSmall`] if the index of all parts does not fit in the budget;
    /// [`BuildError::PartsOverlap`]; the error of a piece read back, of `output` or of `receive`. The
    /// pieces are dropped in any case.
    pub fn write_into<E, O, R>(
        self,
        mut output: O,
        mut receive: R,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<(O::Output, OutOfCoreReport), BuildError<E, P::Error>>
    where
        O: LevelOrderSink<Error = P::Error>,
        R: FnMut(usize, &mut [u64]) -> Result<(), P::Error>,
    {
        let SpilledPart {
            k: _,
            level,
            m,
            cells,
            own,
            others,
            mut pieces,
            mut budget,
            largest,
            spilled_bytes,
        } = self;
        let t = (level - m) as usize;
        let parts: Vec<&SubtreeIndex> = std::iter::once(&own).chain(&others).collect();
        let subtrees: usize = parts.iter().map(|p| p.mortons.len()).sum();
        let end = budget.fixed(cells.bytes(), subtrees);
        if end > budget.max {
            return Err(BuildError::BudgetTooSmall {
                budget: budget.max,
                needed: end + largest,
            });
        }
        budget.peak = budget.peak.max(end);
        // The stacked cells of every part in Morton order, as (owner, position in its index).
        // (Packed in one word: the owner in the top 16 bits, at most `MAX_PARTS`.)
        let mut order: Vec<u64> = Vec::with_capacity(subtrees);
        for (owner, part) in parts.iter().enumerate() {
            order.extend((0..part.mortons.len() as u64).map(|s| (owner as u64) << 48 | s));
        }
        let unpack = |o: u64| ((o >> 48) as usize, (o & ((1 << 48) - 1)) as usize);
        order.sort_unstable_by_key(|&o| {
            let (owner, s) = unpack(o);
            parts[owner].mortons[s]
        });
        let partial: Vec<u64> = order
            .iter()
            .map(|&o| {
                let (owner, s) = unpack(o);
                parts[owner].mortons[s]
            })
            .collect();
        let top = cells
            .into_top_levels(&partial)
            .map_err(|_| BuildError::PartsOverlap)?;
        drop(partial);
        let deepest = (1..=t)
            .rev()
            .find(|&j| {
                parts
                    .iter()
                    .any(|p| (0..p.mortons.len()).any(|s| p.counts[s * t + j - 1] > 0))
            })
            .unwrap_or(0);
        let total = (top.len() + deepest) as u64;
        let mut done = 0;
        for states in &top {
            output.append_states(states)?;
            output.end_level()?;
            done += 1;
            progress(Progress {
                stage: Stage::Writing,
                done,
                total,
            });
        }
        drop(top);
        let mut offsets = vec![0u64; own.mortons.len()];
        let mut words: Vec<u64> = Vec::new();
        for j in 0..deepest {
            let at = level_offsets(&own, t, j, &mut offsets);
            let mut level = pieces.level(j + 1, &offsets, at);
            for &o in &order {
                let (owner, s) = unpack(o);
                let nodes = parts[owner].counts[s * t + j];
                if nodes == 0 {
                    continue;
                }
                words.clear();
                words.resize(nodes.div_ceil(32) as usize, 0);
                if owner == 0 {
                    level.read(s, 0, &mut words)?;
                } else {
                    receive(owner, &mut words)?;
                }
                output.append_words(&words, nodes)?;
            }
            level.finish();
            output.end_level()?;
            done += 1;
            progress(Progress {
                stage: Stage::Writing,
                done,
                total,
            });
        }
        let counts_per_level = output.counts_per_level();
        let output = output.finish()?;
        Ok((
            output,
            OutOfCoreReport {
                counts_per_level,
                file_bytes: 0,
                subtrees: subtrees as u64,
                spilled_bytes,
                peak_accounted_bytes: budget.peak,
            },
        ))
    }
}
