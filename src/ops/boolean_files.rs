//! Booleans of two `.ktree` version 2 files streamed to a third in bounded memory, for trees larger than
//! memory.
//!
//! # How it runs
//! The inputs are read through their memory maps ([`KtreeView`]) by one simultaneous depth-first walk, as
//! [`boolean`](super::boolean) walks two trees in memory: where one side is a leaf, the result under it is a
//! leaf, a copy of the other side's subtree or its complement (level ranges copied word by word), and two
//! partial nodes are walked child by child. The result is produced in *post-order*: a node's `2^K` child
//! states are appended to the output level below once all of them are known, so a node whose children all
//! turn out full (or empty) collapses before anything of it is written, and the blocks of every level come
//! out in level order (a node finishes after every node before it at its depth). Each output level is
//! appended to its own temporary *spill file*; at the end they are streamed, level by level, into the
//! `.ktree` through a [`KtreeWriter`], written to a temporary file and renamed over the target.
//!
//! Child positions in the inputs come from running counts of the children blocks met at each depth (the
//! depth-first walk meets the partial nodes of every level in level order), re-synchronised from the file's
//! rank samples after a skipped subtree.
//!
//! # Memory
//! What the process allocates is bounded by the depth of the trees, not their size: the walk's stack, one
//! [`BUFFER_BYTES`] buffer per output level and one for the output. The inputs' pages are read through the
//! memory maps, each level front to back; they are the kernel's page cache, dropped under memory pressure,
//! so inputs larger than memory work.
//!
//! ```
//! use ktree::{io, ops, KTree};
//! let dir = tempfile::tempdir().unwrap();
//! let (pa, pb, pc) = (dir.path().join("a.ktree"), dir.path().join("b.ktree"), dir.path().join("c.ktree"));
//! let a = KTree::<2>::from_dense(2, &[true; 16]).unwrap();
//! let b = KTree::<2>::from_dense(2, &(0..16).map(|i| i % 3 == 0).collect::<Vec<_>>()).unwrap();
//! io::write_ktree_v2_file(&pa, &a).unwrap();
//! io::write_ktree_v2_file(&pb, &b).unwrap();
//! ops::boolean_files(&pa, &pb, ops::BoolOp::Difference, &pc, None).unwrap();
//! assert_eq!(io::read_ktree_file(&pc).unwrap(), io::AnyTree::K2(ops::difference(&a, &b).unwrap()));
//! ```

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use super::BoolOp;
use crate::io::{KtreeFileError, KtreeView, KtreeWriter};
use crate::tree::words::{self, WordPacker};
use crate::tree::{LevelCounts, NodeState};

/// Nodes in a word, counted as the file's node counts are.
const NODES_PER_WORD: u64 = words::NODES_PER_WORD as u64;

/// Bytes of each I/O buffer (one per output level, one for the output).
pub const BUFFER_BYTES: usize = 1 << 16;

/// Why a streamed Boolean failed. The target file is untouched and the spill files are removed.
#[derive(Debug, thiserror::Error)]
pub enum BooleanFileError {
    /// An input cannot be opened or read (the error names it and the byte offset).
    #[error("{0}")]
    Input(#[from] KtreeFileError),
    /// The inputs do not have the same `K` and `L`.
    #[error("{a} is a K = {ka}, L = {la} tree but {b} is K = {kb}, L = {lb}: both must have the same dimension and level")]
    Mismatch {
        /// The first input.
        a: String,
        /// Its `K`.
        ka: usize,
        /// Its `L`.
        la: u32,
        /// The second input.
        b: String,
        /// Its `K`.
        kb: usize,
        /// Its `L`.
        lb: u32,
    },
    /// The folder for the spill files cannot be used.
    #[error("cannot create spill files in the temporary folder {}: {source}", path.display())]
    TempDir {
        /// The folder.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A spill file cannot be written or read back.
    #[error("spill file {}: {source}", path.display())]
    Spill {
        /// The spill file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The output cannot be written.
    #[error("cannot write {}: {source}", path.display())]
    Output {
        /// The output file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

/// What a streamed Boolean wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BooleanFileReport {
    /// The dimension `K`.
    pub k: usize,
    /// The universe level `L`.
    pub level: u32,
    /// The result's node counts per level (`level` = depth).
    pub counts_per_level: Vec<LevelCounts>,
    /// Bytes written to spill files.
    pub spilled_bytes: u64,
}

/// Writes `a op b` to the `.ktree` version 2 file `out`, reading the version 2 files `a` and `b` through
/// their memory maps, in bounded memory (see the module's notes). Spill files go to a hidden folder in
/// `temp_dir` (default: the output's folder), removed at the end. The bytes are those of
/// [`write_ktree_v2`](crate::io::write_ktree_v2) of [`boolean`](super::boolean) of the trees.
///
/// # Errors
/// [`BooleanFileError`]; the target is then untouched.
pub fn boolean_files(
    a: &Path,
    b: &Path,
    op: BoolOp,
    out: &Path,
    temp_dir: Option<&Path>,
) -> Result<BooleanFileReport, BooleanFileError> {
    let va = KtreeView::open(a)?;
    let vb = KtreeView::open(b)?;
    boolean_views(&va, Some(&vb), Some(op), out, temp_dir)
}

/// Writes the complement of the version 2 file `a` to `out`, level by level, in bounded memory (see
/// [`boolean_files`]).
///
/// # Errors
/// [`BooleanFileError`]; the target is then untouched.
pub fn complement_file(
    a: &Path,
    out: &Path,
    temp_dir: Option<&Path>,
) -> Result<BooleanFileReport, BooleanFileError> {
    let va = KtreeView::open(a)?;
    boolean_views(&va, None, None, out, temp_dir)
}

/// `a op b` of two views (or the complement of `a` when `b` and `op` are `None`) to `out`.
///
/// # Errors
/// As [`boolean_files`].
pub fn boolean_views(
    a: &KtreeView,
    b: Option<&KtreeView>,
    op: Option<BoolOp>,
    out: &Path,
    temp_dir: Option<&Path>,
) -> Result<BooleanFileReport, BooleanFileError> {
    if let Some(b) = b {
        if (a.k(), a.level()) != (b.k(), b.level()) {
            return Err(BooleanFileError::Mismatch {
                a: a.name().to_string(),
                ka: a.k(),
                la: a.level(),
                b: b.name().to_string(),
                kb: b.k(),
                lb: b.level(),
            });
        }
    }
    let depths = a.depth_count().max(b.map_or(0, KtreeView::depth_count));
    let folder = crate::fs::spill_folder(out, temp_dir)
        .map_err(|(path, source)| BooleanFileError::TempDir { path, source })?;
    let mut levels = OutputLevels::create(folder.path(), depths)?;
    let mut inputs = [Input::new(a, depths), Input::new(b.unwrap_or(a), depths)];
    let root = match (b, op) {
        (Some(_), Some(op)) => {
            let mut walk = Walk {
                inputs: &mut inputs,
                levels: &mut levels,
                op,
                k: a.k(),
            };
            walk.pair(0, 0, 0)?
        }
        _ => {
            let mut walk = Walk {
                inputs: &mut inputs,
                levels: &mut levels,
                op: BoolOp::Difference,
                k: a.k(),
            };
            walk.side(0, 0, 0, Polarity::Complement)?
        }
    };
    let report = levels.finish(root, a.k(), a.level(), out);
    drop(folder);
    report
}

/// One input and where the walk is in it.
struct Input<'a> {
    view: &'a KtreeView,
    /// Per depth `d`: the index of the next children block to meet at depth `d`.
    next: Vec<u64>,
    /// Bit `d` set: `next[d]` is out of date (a subtree above was skipped).
    stale: u64,
}

impl<'a> Input<'a> {
    fn new(view: &'a KtreeView, depths: usize) -> Self {
        Self {
            view,
            next: vec![0; depths + 1],
            stale: 0,
        }
    }

    fn state(&self, depth: usize, index: u64) -> Result<NodeState, KtreeFileError> {
        self.view.checked_state(depth, index)
    }

    /// The first child of the partial node `index` of level `depth`, met in depth-first order.
    fn first_child(&mut self, depth: usize, index: u64, k: usize) -> u64 {
        let below = depth + 1;
        if self.stale >> below & 1 == 1 {
            self.next[below] = self.view.partial_rank(depth, index) << k;
            self.stale &= !(1 << below);
        }
        let first = self.next[below];
        self.next[below] += 1 << k;
        first
    }

    /// The walk does not enter the subtree of a partial node of level `depth`.
    fn skip(&mut self, depth: usize) {
        self.stale |= u64::MAX << (depth + 1);
    }
}

/// How a subtree goes into the result.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Polarity {
    Same,
    Complement,
}

/// The result as a function of one side, the other side being a leaf.
enum Under {
    Leaf(NodeState),
    Subtree(Polarity),
}

impl Under {
    /// What `op` makes of `other` when this side is the leaf `full` (`leaf_is_a`: the leaf is `a`'s).
    fn of(op: BoolOp, full: bool, leaf_is_a: bool) -> Self {
        let f = |x: bool| {
            if leaf_is_a {
                op.apply(full, x)
            } else {
                op.apply(x, full)
            }
        };
        match (f(false), f(true)) {
            (false, false) => Under::Leaf(NodeState::Empty),
            (true, true) => Under::Leaf(NodeState::Full),
            (false, true) => Under::Subtree(Polarity::Same),
            (true, false) => Under::Subtree(Polarity::Complement),
        }
    }
}

/// The simultaneous walk.
struct Walk<'w, 'a> {
    inputs: &'w mut [Input<'a>; 2],
    levels: &'w mut OutputLevels,
    op: BoolOp,
    k: usize,
}

impl Walk<'_, '_> {
    /// The result at node `ia` of `a` and `ib` of `b`, both at `depth`; the levels below are appended.
    fn pair(&mut self, depth: usize, ia: u64, ib: u64) -> Result<NodeState, BooleanFileError> {
        let sa = self.inputs[0].state(depth, ia)?;
        let sb = self.inputs[1].state(depth, ib)?;
        match (sa, sb) {
            (NodeState::Partial, NodeState::Partial) => {}
            (NodeState::Partial, leaf) => {
                return self.one_side(
                    0,
                    depth,
                    ia,
                    Under::of(self.op, leaf == NodeState::Full, false),
                )
            }
            (leaf, NodeState::Partial) => {
                return self.one_side(
                    1,
                    depth,
                    ib,
                    Under::of(self.op, leaf == NodeState::Full, true),
                )
            }
            (x, y) => {
                let full = self.op.apply(x == NodeState::Full, y == NodeState::Full);
                return Ok(if full {
                    NodeState::Full
                } else {
                    NodeState::Empty
                });
            }
        }
        let ca = self.inputs[0].first_child(depth, ia, self.k);
        let cb = self.inputs[1].first_child(depth, ib, self.k);
        let mut children = [NodeState::Empty; 16];
        for (code, child) in children.iter_mut().enumerate().take(1 << self.k) {
            *child = self.pair(depth + 1, ca + code as u64, cb + code as u64)?;
        }
        self.close(depth, &children[..1 << self.k])
    }

    fn one_side(
        &mut self,
        side: usize,
        depth: usize,
        index: u64,
        under: Under,
    ) -> Result<NodeState, BooleanFileError> {
        match under {
            Under::Leaf(state) => {
                self.inputs[side].skip(depth);
                Ok(state)
            }
            Under::Subtree(copy) => self.side(side, depth, index, copy),
        }
    }

    /// The partial node `index` of side `side` at `depth`, copied (or complemented) into the result.
    fn side(
        &mut self,
        side: usize,
        depth: usize,
        index: u64,
        copy: Polarity,
    ) -> Result<NodeState, BooleanFileError> {
        let state = self.inputs[side].state(depth, index)?;
        if state != NodeState::Partial {
            return Ok(match (state, copy) {
                (s, Polarity::Same) => s,
                (NodeState::Full, Polarity::Complement) => NodeState::Empty,
                _ => NodeState::Full,
            });
        }
        let input = &mut self.inputs[side];
        let mut start = input.first_child(depth, index, self.k);
        let mut nodes = 1u64 << self.k;
        let mut d = depth + 1;
        while nodes > 0 {
            let partial = self
                .levels
                .append_range(input.view, d, start, nodes, copy)?;
            let end = start + nodes;
            input.next[d] = end;
            input.stale &= !(1 << d);
            if partial == 0 {
                break;
            }
            start = input.view.partial_rank(d, start) << self.k;
            nodes = partial << self.k;
            d += 1;
        }
        // The depths down to the subtree's last level are in step (the blocks after the subtree come
        // next); below it, positions are found again from the rank samples.
        input.stale |= u64::MAX << (d + 1);
        Ok(NodeState::Partial)
    }

    /// A partial-partial node whose children are known: collapses it, or appends the children below it.
    fn close(
        &mut self,
        depth: usize,
        children: &[NodeState],
    ) -> Result<NodeState, BooleanFileError> {
        if children.iter().all(|&c| c == NodeState::Full) {
            return Ok(NodeState::Full);
        }
        if children.iter().all(|&c| c == NodeState::Empty) {
            return Ok(NodeState::Empty);
        }
        let word = words::pack(children);
        self.levels.append(depth + 1, word, children.len() as u64)?;
        Ok(NodeState::Partial)
    }
}

/// The result's levels `1 …`, each appended to its spill file.
struct OutputLevels {
    levels: Vec<OutputLevel>,
}

struct OutputLevel {
    path: PathBuf,
    file: BufWriter<File>,
    nodes: u64,
    packer: WordPacker,
}

impl OutputLevels {
    fn create(folder: &Path, depths: usize) -> Result<Self, BooleanFileError> {
        let levels = (1..depths)
            .map(|d| {
                let path = folder.join(format!("level-{d}"));
                let file = File::create(&path).map_err(|source| BooleanFileError::Spill {
                    path: path.clone(),
                    source,
                })?;
                Ok(OutputLevel {
                    path,
                    file: BufWriter::with_capacity(BUFFER_BYTES, file),
                    nodes: 0,
                    packer: WordPacker::default(),
                })
            })
            .collect::<Result<_, BooleanFileError>>()?;
        Ok(Self { levels })
    }

    /// Appends `nodes` (≤ 32) nodes packed in `word` to level `depth`.
    fn append(&mut self, depth: usize, word: u64, nodes: u64) -> Result<(), BooleanFileError> {
        let level = &mut self.levels[depth - 1];
        level.nodes += nodes;
        if let Some(whole) = level.packer.push(word, nodes as usize) {
            level
                .file
                .write_all(&whole.to_le_bytes())
                .map_err(|source| BooleanFileError::Spill {
                    path: level.path.clone(),
                    source,
                })?;
        }
        Ok(())
    }

    /// Appends nodes `start … start + nodes` of `view`'s level `depth` (complemented if asked) to the same
    /// level of the result; returns how many of them are partial.
    fn append_range(
        &mut self,
        view: &KtreeView,
        depth: usize,
        start: u64,
        nodes: u64,
        copy: Polarity,
    ) -> Result<u64, BooleanFileError> {
        if start + nodes > view.level_nodes(depth) {
            return Err(view.changed(depth, start + nodes - 1).into());
        }
        let words = view.level_nodes(depth).div_ceil(NODES_PER_WORD);
        let mut at = start;
        let mut partial = 0;
        while at < start + nodes {
            let take = (start + nodes - at).min(NODES_PER_WORD);
            let word = words::read_codes(
                |j| view.level_word(depth, j as u64),
                words as usize,
                at as usize,
                take as usize,
            );
            partial += u64::from(words::partial_count(word));
            let word = match copy {
                Polarity::Same => word,
                // Full and empty swap; partial stays.
                Polarity::Complement => words::complement(word, take as usize),
            };
            self.append(depth, word, take)?;
            at += take;
        }
        Ok(partial)
    }

    /// Writes the result (root `root`) to `out`: the root level, then each spilled level.
    fn finish(
        self,
        root: NodeState,
        k: usize,
        level: u32,
        out: &Path,
    ) -> Result<BooleanFileReport, BooleanFileError> {
        let mut spilled_bytes = 0;
        let mut readers = Vec::new();
        for mut l in self.levels {
            if let Some(word) = l.packer.flush() {
                l.file.write_all(&word.to_le_bytes()).map_err(|source| {
                    BooleanFileError::Spill {
                        path: l.path.clone(),
                        source,
                    }
                })?;
            }
            let spill_err = |source| BooleanFileError::Spill {
                path: l.path.clone(),
                source,
            };
            let file = l.file.into_inner().map_err(|e| spill_err(e.into_error()))?;
            spilled_bytes += 8 * l.nodes.div_ceil(NODES_PER_WORD);
            drop(file);
            if l.nodes > 0 {
                readers.push((l.path, l.nodes));
            }
        }
        let mut counts = Vec::new();
        crate::io::write_atomic_with(out, |w| {
            let mut writer = KtreeWriter::new(BufWriter::with_capacity(BUFFER_BYTES, w), k, level)?;
            writer.push(root)?;
            writer.end_level()?;
            let mut words = vec![0u64; BUFFER_BYTES / 8];
            let mut bytes = vec![0u8; BUFFER_BYTES];
            for (path, nodes) in &readers {
                let with_path = |e: std::io::Error| {
                    std::io::Error::new(e.kind(), format!("spill file {}: {e}", path.display()))
                };
                let mut reader = BufReader::new(File::open(path).map_err(with_path)?);
                let mut left = *nodes;
                while left > 0 {
                    let n = left.min(NODES_PER_WORD * words.len() as u64);
                    let w = n.div_ceil(NODES_PER_WORD) as usize;
                    reader.read_exact(&mut bytes[..8 * w]).map_err(with_path)?;
                    for (word, b) in words.iter_mut().zip(bytes.chunks_exact(8)).take(w) {
                        *word = u64::from_le_bytes(b.try_into().expect("8 bytes"));
                    }
                    writer.append_words(&words[..w], n)?;
                    left -= n;
                }
                writer.end_level()?;
            }
            counts = writer.counts_per_level();
            writer.finish()?.flush()
        })
        .map_err(|source| BooleanFileError::Output {
            path: out.to_path_buf(),
            source,
        })?;
        Ok(BooleanFileReport {
            k,
            level,
            counts_per_level: counts,
            spilled_bytes,
        })
    }
}
