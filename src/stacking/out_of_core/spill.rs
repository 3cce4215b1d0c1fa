//! The spill files of an out-of-core build: the levels below the cells of depth `m`, one file per level,
//! written as the cells are stacked and read back, piece by piece, when the tree is written.

use crate::fs::SpillError;
use crate::io::spill::{LevelFile, PieceRelease};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use super::error::BuildError;
use crate::stacking::cells::CellStates;
use crate::stacking::partition::Piece;
use crate::tree::NodeState;

/// The spill files: one per subtree level `1 … t`, each cell's piece of a level in whole words.
pub(super) struct Spill {
    pub(super) dir: tempfile::TempDir,
    pub(super) files: Vec<LevelFile>,
}

impl Spill {
    /// Words written to all the files.
    pub(super) fn words(&self) -> u64 {
        self.files.iter().map(LevelFile::words).sum()
    }
}

/// The stacked cells, in the order they were spilled: Morton index and node count per subtree level
/// `1 … t` (0 beyond the subtree's depth).
#[derive(Default)]
pub(super) struct SubtreeIndex {
    pub(super) mortons: Vec<u64>,
    pub(super) counts: Vec<u64>,
}

/// Sets `offsets[s]` to the word offset of cell `s`'s piece in spill file `j + 1` (pieces are in the order
/// the cells were spilled); returns the file's length in words.
pub(super) fn level_offsets(index: &SubtreeIndex, t: usize, j: usize, offsets: &mut [u64]) -> u64 {
    let mut at = 0u64;
    for (s, offset) in offsets.iter_mut().enumerate() {
        *offset = at;
        at += index.counts[s * t + j].div_ceil(32);
    }
    at
}

/// Reads pieces of one spill file back, one read per piece (pieces are taken out of the order they were
/// spilled in, so a buffer ahead would mostly be wasted), and gives the disk of each piece back once it is
/// read ([`PieceRelease`]); errors name the file.
pub(super) struct SpillReader<'a> {
    path: &'a Path,
    file: &'a mut File,
    /// The word the file is at (`u64::MAX`: unknown).
    at: u64,
    /// The file's length in words.
    len: u64,
    /// The pieces of the file (their word offsets), and which were read.
    pieces: PieceRelease<'a>,
    bytes: Vec<u8>,
}

impl<'a> SpillReader<'a> {
    /// The reader of `file`, `len` words long, of pieces at word offsets `offsets` (in file order).
    pub(super) fn new(path: &'a Path, file: &'a mut File, offsets: &'a [u64], len: u64) -> Self {
        let pieces = PieceRelease::new(file, offsets, len);
        Self {
            path,
            file,
            at: u64::MAX,
            len,
            pieces,
            bytes: Vec::new(),
        }
    }

    fn error(&self, e: std::io::Error) -> std::io::Error {
        std::io::Error::new(e.kind(), format!("spill file {}: {e}", self.path.display()))
    }

    /// Moves to word `word` (no system call when the file is already there).
    pub(super) fn seek(&mut self, word: u64) -> std::io::Result<()> {
        if word != self.at {
            self.at = u64::MAX;
            self.file
                .seek(SeekFrom::Start(8 * word))
                .map_err(|e| self.error(e))?;
            self.at = word;
        }
        Ok(())
    }

    /// Appends the next `count` words to `words`.
    pub(super) fn read_into(&mut self, count: usize, words: &mut Vec<u64>) -> std::io::Result<()> {
        if self.at.saturating_add(count as u64) > self.len {
            return Err(self.error(std::io::Error::new(
                std::io::ErrorKind::UnexpectedEof,
                "shorter than its index",
            )));
        }
        self.bytes.resize(8 * count, 0);
        if let Err(e) = self.file.read_exact(&mut self.bytes) {
            self.at = u64::MAX;
            return Err(self.error(e));
        }
        words.extend(
            self.bytes
                .chunks_exact(8)
                .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes"))),
        );
        self.at += count as u64;
        Ok(())
    }

    /// Marks piece `s` read (all its words): its disk is given back.
    pub(super) fn release(&mut self, s: usize) {
        self.pieces.release(self.file, s);
    }

    /// Ends reading the file: what is left of it is given back (it is not read again).
    pub(super) fn finish(self) {
        self.pieces.finish(self.file);
    }
}

/// Creates the spill folder and its `t` files.
pub(super) fn open_spill<E>(
    out: &Path,
    temp_dir: Option<&Path>,
    t: usize,
) -> Result<Spill, BuildError<E>> {
    let dir = crate::fs::spill_folder(out, temp_dir)
        .map_err(|(path, source)| BuildError::Files(SpillError::TempDir { path, source }))?;
    let files = (1..=t)
        .map(|j| LevelFile::create(dir.path().join(format!("level-{j}"))))
        .collect::<Result<_, _>>()?;
    Ok(Spill { dir, files })
}

/// Records a non-empty cell of depth `m`, spilling the levels below its root if it is partial.
pub(super) fn spill_piece<const K: usize, E>(
    spill: &mut Spill,
    cells: &mut CellStates,
    index: &mut SubtreeIndex,
    morton: u64,
    piece: Piece<K>,
) -> Result<(), BuildError<E>> {
    let tree = match piece {
        Piece::Full => {
            cells.set_full(morton);
            return Ok(());
        }
        Piece::Tree(tree) => tree,
    };
    match tree.root_state() {
        NodeState::Empty => return Ok(()),
        NodeState::Full => {
            cells.set_full(morton);
            return Ok(());
        }
        NodeState::Partial => {}
    }
    index.mortons.push(morton);
    for (j, file) in (1..).zip(spill.files.iter_mut()) {
        let nodes = if j < tree.depth_count() {
            let states = tree.level_states(j);
            let nodes = states.len() as u64;
            file.append_words(&states.words()[..states.len().div_ceil(32)], nodes)?;
            nodes
        } else {
            0
        };
        index.counts.push(nodes);
    }
    Ok(())
}
