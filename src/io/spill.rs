//! Spill files: the levels of a tree larger than memory, each level in its own temporary file of 2-bit
//! states packed 32 to a little-endian word.
//!
//! [`LevelFile`] is one such file: nodes appended at any offset (the words completed go to the file through
//! a [`BUFFER_BYTES`] buffer), or whole words at a word boundary, and read back once writing is over. Two
//! jobs spill through it:
//!
//! * the out-of-core builder's store of pieces ([`crate::io::SpilledFiles`]) appends each stacked cell's
//!   subtree, level by level, as whole words (a piece per cell), and reads the pieces back in Morton order
//!   when it writes the tree;
//! * [`SpillLevels`], the [`LevelSink`] of the streamed Booleans, appends nodes in depth-first order, so
//!   each file holds its level in level order, and streams the files into a `.ktree` when finished.
//!
//! Every error names the spill file (or the output) it happened to.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::{KtreeWriter, Notes};
use crate::fs::SpillError;
use crate::space::WorldFrame;
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

    /// Appends `nodes` states packed in the first words of `words` as whole words, starting at a word
    /// boundary (the states appended before are padded to a whole word first); the words after the
    /// states' (a valued piece's values) follow them.
    pub(crate) fn append_words(&mut self, words: &[u64], nodes: u64) -> Result<(), SpillError> {
        debug_assert!(words.len() as u64 >= nodes.div_ceil(NODES_PER_WORD as u64));
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

/// Gives the disk of a spill file back while its pieces are read, in any order: the bytes of each piece
/// read, widened to the whole blocks at its ends when every other piece in them was read before, are
/// freed by punching a hole over them (`fallocate` with `FALLOC_FL_PUNCH_HOLE`), so each block is freed
/// once the last piece in it is read. A build that spills as much as it writes then needs about the
/// output's size of disk, not twice it. Freed ranges that touch are joined and punched once they reach
/// [`PUNCH_BYTES`], so at most that much per run of pieces read in file order waits;
/// [`finish`](Self::finish) gives back the rest. (A hole for each piece made the file system the
/// bottleneck: punches cost about 100 µs each here, and the L = 15 sphere's ~5 × 10^5 of them took its
/// writing from 10 to 58 s.) Where holes cannot be punched (a system other than Linux, or a file system
/// without them) the file keeps its blocks until it is finished; nothing not yet read is ever punched.
pub(crate) struct PieceRelease<'a> {
    /// The word offset of each piece in the file, in file order (pieces may be empty).
    offsets: &'a [u64],
    /// The file's length in words (the end of the last piece).
    end: u64,
    /// One bit per piece: read.
    read: Vec<u64>,
    /// The file system's block size in bytes.
    block: u64,
    /// Freed ranges not yet punched (start → end), none touching another.
    waiting: BTreeMap<u64, u64>,
    /// The size a freed range is punched at.
    punch_bytes: u64,
    /// False once a hole could not be punched.
    punching: bool,
}

impl<'a> PieceRelease<'a> {
    /// The pieces at word offsets `offsets` of `file`, which is `end` words long.
    pub(crate) fn new(file: &File, offsets: &'a [u64], end: u64) -> Self {
        Self::with_block(offsets, end, block_size(file), PUNCH_BYTES)
    }

    fn with_block(offsets: &'a [u64], end: u64, block: u64, punch_bytes: u64) -> Self {
        Self {
            offsets,
            end,
            read: vec![0; offsets.len().div_ceil(64)],
            block: block.max(1),
            waiting: BTreeMap::new(),
            punch_bytes,
            punching: true,
        }
    }

    fn bytes(&self, piece: usize) -> std::ops::Range<u64> {
        let start = self.offsets[piece];
        let end = self.offsets.get(piece + 1).copied().unwrap_or(self.end);
        8 * start..8 * end
    }

    fn is_read(&self, piece: usize) -> bool {
        self.read[piece / 64] >> (piece % 64) & 1 == 1 || self.bytes(piece).is_empty()
    }

    /// Whether every one of `pieces` was read; false if there are more than [`NEIGHBOURS_LOOKED_AT`] (a
    /// block shared by that many pieces stays until its file is removed, so each piece read costs a bounded
    /// time whatever the order).
    fn all_read(&self, mut pieces: impl Iterator<Item = usize>) -> bool {
        pieces
            .by_ref()
            .take(NEIGHBOURS_LOOKED_AT)
            .all(|p| self.is_read(p))
            && pieces.next().is_none()
    }

    /// Marks `piece` read; returns the bytes that may now be freed: the piece, widened at each end to the
    /// block boundary when every other piece in that block is read (empty when none is whole).
    fn mark_read(&mut self, piece: usize) -> std::ops::Range<u64> {
        self.read[piece / 64] |= 1 << (piece % 64);
        let bytes = self.bytes(piece);
        if bytes.is_empty() {
            return 0..0;
        }
        let b = self.block;
        let first_block = bytes.start / b * b;
        let before_read = self.all_read(
            (0..piece)
                .rev()
                .take_while(|&p| self.bytes(p).end > first_block),
        );
        let start = if before_read {
            first_block
        } else {
            bytes.start.next_multiple_of(b)
        };
        let last_block = bytes.end.next_multiple_of(b);
        let after_read = self.all_read(
            (piece + 1..self.offsets.len()).take_while(|&p| self.bytes(p).start < last_block),
        );
        let end = if after_read {
            last_block
        } else {
            bytes.end / b * b
        };
        if start < end {
            start..end
        } else {
            0..0
        }
    }

    /// Marks `piece` of `file` read and frees what it can of it. Punching is an economy, not a part of the
    /// result: a hole that cannot be punched stops the punching of this file, with no error.
    pub(crate) fn release(&mut self, file: &File, piece: usize) {
        let range = self.mark_read(piece);
        if !self.punching {
            return;
        }
        if let Some(range) = self.join(range) {
            self.punching = punch_hole(file, range).is_ok();
        }
    }

    /// Joins the freed `range` to the waiting ones it touches; returns the joined range if it is to be
    /// punched now (it has [`PUNCH_BYTES`]), else keeps it waiting.
    fn join(&mut self, range: std::ops::Range<u64>) -> Option<std::ops::Range<u64>> {
        if range.is_empty() {
            return None;
        }
        let (mut start, mut end) = (range.start, range.end);
        if let Some((&before, &before_end)) = self.waiting.range(..start).next_back() {
            if before_end == start {
                self.waiting.remove(&before);
                start = before;
            }
        }
        if let Some(after_end) = self.waiting.remove(&end) {
            end = after_end;
        }
        if end - start >= self.punch_bytes {
            Some(start..end)
        } else {
            self.waiting.insert(start, end);
            None
        }
    }

    /// Ends reading `file` (every piece that will be read was): whatever it still holds is given back.
    pub(crate) fn finish(self, file: &File) {
        // An economy, like the holes: the file is removed with its folder in any case.
        let _ = file.set_len(0);
    }
}

/// The size at which [`PieceRelease`] punches a freed range.
const PUNCH_BYTES: u64 = 1 << 18;

/// The most pieces [`PieceRelease`] looks at on each side of a piece read.
const NEIGHBOURS_LOOKED_AT: usize = 64;

/// The block size of `file`'s file system (4096 where it cannot be read).
fn block_size(file: &File) -> u64 {
    #[cfg(unix)]
    if let Ok(meta) = file.metadata() {
        return std::os::unix::fs::MetadataExt::blksize(&meta);
    }
    let _ = file;
    4096
}

/// Frees the bytes `range` of `file` (they read as zeros after), keeping its size.
#[cfg(target_os = "linux")]
fn punch_hole(file: &File, range: std::ops::Range<u64>) -> std::io::Result<()> {
    use rustix::fs::{fallocate, FallocateFlags};
    fallocate(
        file,
        FallocateFlags::PUNCH_HOLE | FallocateFlags::KEEP_SIZE,
        range.start,
        range.end - range.start,
    )
    .map_err(std::io::Error::from)
}

#[cfg(not(target_os = "linux"))]
fn punch_hole(_file: &File, _range: std::ops::Range<u64>) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
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
    frame: Option<WorldFrame>,
    notes: Notes,
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
            frame: None,
            notes: Notes::new(),
        })
    }

    /// The output written with a world frame and notes.
    pub(crate) fn framed(self, frame: Option<WorldFrame>, notes: Notes) -> Self {
        Self {
            frame,
            notes,
            ..self
        }
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
            let buffered = BufWriter::with_capacity(BUFFER_BYTES, w);
            let mut writer =
                KtreeWriter::with_frame(buffered, k, level, self.frame.as_ref(), &self.notes)?;
            writer.push(root)?;
            writer.end_level()?;
            let mut words = vec![0u64; BUFFER_BYTES / 8];
            let mut bytes = vec![0u8; BUFFER_BYTES];
            let per_word = NODES_PER_WORD as u64;
            for (path, file, nodes) in readers {
                let with_path = |e: std::io::Error| {
                    std::io::Error::new(e.kind(), format!("spill file {}: {e}", path.display()))
                };
                // Read in chunks of `words.len()` words, each given back once read.
                let file_words = nodes.div_ceil(per_word);
                let chunks: Vec<u64> = (0..file_words).step_by(words.len()).collect();
                let mut release = PieceRelease::new(&file, &chunks, file_words);
                let mut reader = BufReader::new(&file);
                let mut left = nodes;
                let mut chunk = 0;
                while left > 0 {
                    let n = left.min(per_word * words.len() as u64);
                    let w = n.div_ceil(per_word) as usize;
                    reader.read_exact(&mut bytes[..8 * w]).map_err(with_path)?;
                    for (word, b) in words.iter_mut().zip(bytes.chunks_exact(8)).take(w) {
                        *word = u64::from_le_bytes(b.try_into().expect("8 bytes"));
                    }
                    writer.append_words(&words[..w], n)?;
                    release.release(&file, chunk);
                    chunk += 1;
                    left -= n;
                }
                release.finish(&file);
                writer.end_level()?;
            }
            counts = writer.counts_per_level();
            writer.finish()?.flush()
        })
        .map_err(|e| SpillError::Output {
            path: self.out.clone(),
            source: e.into_io(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Word offsets of pieces of `sizes` words, and the file's end.
    fn offsets(sizes: &[u64]) -> (Vec<u64>, u64) {
        let mut at = 0;
        let offsets = sizes
            .iter()
            .map(|&n| {
                at += n;
                at - n
            })
            .collect();
        (offsets, at)
    }

    /// The pieces with bytes in block `b` (of `block` bytes).
    fn pieces_in(sizes: &[u64], block: u64, b: u64) -> Vec<usize> {
        let (offsets, _) = offsets(sizes);
        (0..sizes.len())
            .filter(|&p| {
                let (start, end) = (8 * offsets[p], 8 * (offsets[p] + sizes[p]));
                start < end && start < (b + 1) * block && end > b * block
            })
            .collect()
    }

    proptest! {
        /// Read in any order, a block is given back exactly when every piece in it was read (a block of
        /// more pieces than are looked at may stay), never before.
        #[test]
        fn blocks_are_given_back_once_all_their_pieces_are_read(
            sizes in prop::collection::vec(prop_oneof![Just(0u64), 1u64..4, 1u64..40], 1..120),
            block in prop::sample::select(vec![8u64, 16, 64, 512]),
            punch_blocks in prop::sample::select(vec![1u64, 2, 5, 1000]),
            order in any::<prop::sample::Index>(),
            seed: u64,
        ) {
            let (offsets, end) = offsets(&sizes);
            let n = sizes.len();
            // A permutation of the pieces, from `seed`.
            let mut perm: Vec<usize> = (0..n).collect();
            let mut state = seed | 1;
            for i in (1..n).rev() {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                perm.swap(i, (state % (i as u64 + 1)) as usize);
            }
            perm.rotate_left(order.index(n));
            let blocks = (8 * end).div_ceil(block);
            let mut release = PieceRelease::with_block(&offsets, end, block, punch_blocks * block);
            // Blocks freed, and blocks punched: each freed block is punched once, or still waits.
            let mut freed = vec![false; blocks as usize];
            let mut punched = vec![false; blocks as usize];
            let mut released = vec![false; blocks as usize];
            let mut read = vec![false; n];
            for &p in &perm {
                read[p] = true;
                let range = release.mark_read(p);
                prop_assert!(range.start.is_multiple_of(block) && range.end.is_multiple_of(block));
                for b in range.start / block..range.end / block {
                    freed[b as usize] = true;
                }
                if let Some(hole) = release.join(range.clone()) {
                    prop_assert!(hole.end - hole.start >= punch_blocks * block, "a hole punched too small");
                    for b in hole.start / block..hole.end / block {
                        prop_assert!(freed[b as usize], "block {b} punched before it was freed");
                        prop_assert!(!punched[b as usize], "block {b} punched twice");
                        punched[b as usize] = true;
                    }
                }
                let mut waiting = vec![false; freed.len()];
                let mut last_end = None;
                for (&start, &end) in &release.waiting {
                    prop_assert!(end - start < punch_blocks * block, "a waiting range large enough to punch");
                    prop_assert!(last_end.is_none_or(|e| e < start), "waiting ranges that touch");
                    last_end = Some(end);
                    for b in start / block..end / block {
                        waiting[b as usize] = true;
                    }
                }
                for b in 0..freed.len() {
                    prop_assert_eq!(freed[b], punched[b] || waiting[b], "block {} lost or made up", b);
                }
                for b in range.start / block..range.end / block {
                    prop_assert!(b < blocks, "a block past the end");
                    prop_assert!(!released[b as usize], "block {b} given back twice");
                    released[b as usize] = true;
                }
                for b in 0..blocks {
                    let inside = pieces_in(&sizes, block, b);
                    let all_read = inside.iter().all(|&q| read[q]);
                    if released[b as usize] {
                        prop_assert!(all_read, "block {b} given back with a piece unread");
                    } else if inside.len() <= NEIGHBOURS_LOOKED_AT / 2 {
                        prop_assert!(!all_read, "block {b} kept though all its pieces were read");
                    }
                }
            }
        }
    }

    /// On a real file: once every piece is read back (in an order far from the file's), the file holds no
    /// block, and a piece not yet read keeps its bytes while those around it are punched.
    #[test]
    fn a_spill_file_read_back_holds_no_disk() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("level");
        let sizes: Vec<u64> = (0..400u64).map(|i| (i * 37) % 300).collect();
        let (offsets, end) = offsets(&sizes);
        let data: Vec<u8> = (0..8 * end).map(|i| (i % 251) as u8 + 1).collect();
        std::fs::write(&path, &data).unwrap();
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(&path)
            .unwrap();
        file.sync_all().unwrap();
        let held = |file: &File| std::os::unix::fs::MetadataExt::blocks(&file.metadata().unwrap());
        assert!(held(&file) > 0);
        // Each freed block punched at once (in a build, freed ranges wait to be joined).
        let mut release = PieceRelease::with_block(&offsets, end, block_size(&file), 1);
        // Every piece but piece 200, in a scattered order.
        for p in (0..400).map(|i| (i * 173) % 400).filter(|&p| p != 200) {
            release.release(&file, p);
        }
        let kept = 8 * offsets[200] as usize..8 * (offsets[200] + sizes[200]) as usize;
        let now = std::fs::read(&path).unwrap();
        assert_eq!(now.len(), data.len(), "the file keeps its size");
        assert_eq!(
            now[kept.clone()],
            data[kept],
            "an unread piece keeps its bytes"
        );
        release.release(&file, 200);
        if !release.punching {
            eprintln!("holes cannot be punched in this file system: only the bytes were checked");
        } else {
            assert_eq!(
                held(&file),
                0,
                "blocks still held after every piece was read"
            );
            assert!(std::fs::read(&path).unwrap().iter().all(|&b| b == 0));
        }
    }
}
