//! Spill files: the levels of a tree larger than memory, each level in its own temporary file of 2-bit
//! states packed 32 to a little-endian word.
//!
//! [`LevelFile`] is one such file: nodes appended at any offset (the words completed go to the file through
//! a [`BUFFER_BYTES`] buffer), or whole words at a word boundary, and read back once writing is over. Two
//! jobs spill through it:
//!
//! * the out-of-core builder appends each stacked cell's subtree, level by level, as whole words (a piece
//!   per cell), and reads the pieces back in Morton order when it writes the tree;
//! * [`SpillLevels`], the [`LevelSink`] of the streamed Booleans, appends nodes in depth-first order, so
//!   each file holds its level in level order, and streams the files into a `.ktree` when finished.
//!
//! Every error names the spill file (or the output) it happened to.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::KtreeWriter;
use crate::fs::SpillError;
use crate::tree::sink::LevelSink;
use crate::tree::words::{WordPacker, NODES_PER_WORD};
use crate::tree::{LevelCounts, NodeState};

/// Bytes of the buffer of each spill file while it is written, and of the output's.
pub(crate) const BUFFER_BYTES: usize = 1 << 16;

/// One level of a tree (or the pieces of one level) spilled to a file.
pub(crate) struct LevelFile {
    path: PathBuf,
    file: BufWriter<File>,
    packer: WordPacker,
    nodes: u64,
    words: u64,
}

impl LevelFile {
    /// Creates the file `path` (which must not exist), for writing and reading back.
    pub(crate) fn create(path: PathBuf) -> Result<Self, SpillError> {
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&path);
        match file {
            Ok(file) => Ok(Self {
                path,
                file: BufWriter::with_capacity(BUFFER_BYTES, file),
                packer: WordPacker::default(),
                nodes: 0,
                words: 0,
            }),
            Err(source) => Err(SpillError::Spill { path, source }),
        }
    }

    fn error(&self, source: std::io::Error) -> SpillError {
        SpillError::Spill {
            path: self.path.clone(),
            source,
        }
    }

    fn write_word(&mut self, word: u64) -> Result<(), SpillError> {
        self.words += 1;
        self.file
            .write_all(&word.to_le_bytes())
            .map_err(|e| self.error(e))
    }

    /// Appends the `n ≤ 32` states packed in the low bits of `word` (higher bits clear).
    #[inline]
    pub(crate) fn append(&mut self, word: u64, n: usize) -> Result<(), SpillError> {
        self.nodes += n as u64;
        match self.packer.push(word, n) {
            Some(whole) => self.write_word(whole),
            None => Ok(()),
        }
    }

    /// Appends `nodes` states packed in `words` as whole words, starting at a word boundary (the states
    /// appended before are padded to a whole word first).
    pub(crate) fn append_words(&mut self, words: &[u64], nodes: u64) -> Result<(), SpillError> {
        debug_assert_eq!(words.len() as u64, nodes.div_ceil(NODES_PER_WORD as u64));
        if let Some(last) = self.packer.flush() {
            self.write_word(last)?;
        }
        for &w in words {
            self.write_word(w)?;
        }
        self.nodes += nodes;
        Ok(())
    }

    /// The states appended so far.
    pub(crate) fn nodes(&self) -> u64 {
        self.nodes
    }

    /// The words written so far (the states still waiting for their word not counted).
    pub(crate) fn words(&self) -> u64 {
        self.words
    }

    /// Ends writing: the last word padded and written, everything flushed. Returns the file's path and
    /// the file, to be read back.
    pub(crate) fn finish(mut self) -> Result<(PathBuf, File), SpillError> {
        if let Some(last) = self.packer.flush() {
            self.write_word(last)?;
        }
        let Self { path, file, .. } = self;
        match file.into_inner() {
            Ok(file) => Ok((path, file)),
            Err(e) => Err(SpillError::Spill {
                path,
                source: e.into_error(),
            }),
        }
    }
}

/// What [`SpillLevels`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct SpilledTree {
    /// The tree's node counts per level (`level` = depth).
    pub(crate) counts_per_level: Vec<LevelCounts>,
    /// Bytes written to the spill files.
    pub(crate) spilled_bytes: u64,
}

/// A [`LevelSink`] that appends each level `1 …` of a tree to its own spill file and, when finished,
/// streams them into a `.ktree` version 2 file (written to a temporary file and renamed over the target):
/// trees larger than memory, written in bounded memory.
pub(crate) struct SpillLevels {
    levels: Vec<LevelFile>,
    k: usize,
    level: u32,
    out: PathBuf,
}

impl SpillLevels {
    /// Spill files for the levels `1 … depths − 1` of a `K = k`, `L = level` tree in `folder`, to be
    /// written to `out`.
    pub(crate) fn create(
        folder: &Path,
        depths: usize,
        k: usize,
        level: u32,
        out: &Path,
    ) -> Result<Self, SpillError> {
        let levels = (1..depths)
            .map(|d| LevelFile::create(folder.join(format!("level-{d}"))))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            levels,
            k,
            level,
            out: out.to_path_buf(),
        })
    }

    /// Writes the tree (root `root`) to the output: the root level, then each spilled level.
    fn write(self, root: NodeState) -> Result<SpilledTree, SpillError> {
        let (k, level) = (self.k, self.level);
        let mut spilled_bytes = 0;
        let mut readers = Vec::new();
        for file in self.levels {
            let nodes = file.nodes();
            let (path, mut file) = file.finish()?;
            spilled_bytes += 8 * nodes.div_ceil(NODES_PER_WORD as u64);
            if nodes > 0 {
                file.seek(SeekFrom::Start(0))
                    .map_err(|source| SpillError::Spill {
                        path: path.clone(),
                        source,
                    })?;
                readers.push((path, file, nodes));
            }
        }
        let mut counts = Vec::new();
        crate::fs::write_atomic_with(&self.out, |w| {
            let mut writer = KtreeWriter::new(BufWriter::with_capacity(BUFFER_BYTES, w), k, level)?;
            writer.push(root)?;
            writer.end_level()?;
            let mut words = vec![0u64; BUFFER_BYTES / 8];
            let mut bytes = vec![0u8; BUFFER_BYTES];
            for (path, file, nodes) in readers {
                let with_path = |e: std::io::Error| {
                    std::io::Error::new(e.kind(), format!("spill file {}: {e}", path.display()))
                };
                let mut reader = BufReader::new(file);
                let mut left = nodes;
                let per_word = NODES_PER_WORD as u64;
                while left > 0 {
                    let n = left.min(per_word * words.len() as u64);
                    let w = n.div_ceil(per_word) as usize;
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
        .map_err(|source| SpillError::Output {
            path: self.out.clone(),
            source,
        })?;
        Ok(SpilledTree {
            counts_per_level: counts,
            spilled_bytes,
        })
    }
}

impl LevelSink for SpillLevels {
    type Error = SpillError;
    type Output = SpilledTree;

    #[inline]
    fn append(&mut self, depth: usize, word: u64, n: usize) -> Result<(), SpillError> {
        self.levels[depth - 1].append(word, n)
    }

    fn finish(self, root: NodeState) -> Result<SpilledTree, SpillError> {
        self.write(root)
    }
}
