//! The out-of-core builder's files: the subtrees of the stacked cells wait in spill files, one per level
//! below the cells, in a hidden spill folder ([`SpilledFiles`], the builder's
//! [`PieceStore`](crate::stacking::PieceStore)), each piece's disk given back once it is read
//! ([`PieceRelease`]); the tree goes to a `.ktree` version 2 file through a [`KtreeWriter`] (the builder's
//! [`LevelOrderSink`]), written to a temporary file renamed over the target ([`AtomicFile`]). With them
//! the builder writes files: [`Builder::to_file`], [`Builder::stack_part`] and [`SpilledPart::write`].

use std::fmt::Display;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use super::ktree::v3::ValuedKtreeWriter;
use super::ktree::Notes;
use super::spill::{LevelFile, PieceRelease, BUFFER_BYTES};
use super::KtreeWriter;
use crate::fs::{AtomicFile, SpillError};
use crate::rays::{RayError, RaySource, ValueRuns};
use crate::space::WorldFrame;
use crate::stacking::{
    BuildError, Builder, LevelOrderSink, LevelPieces, OutOfCoreReport, PieceStore, Progress,
    SpilledPart, StoredPieces,
};
use crate::stacking::{ValuePart, ValueSlabs, ValueSlabsReport, ValuedLevelSink};
use crate::tree::LevelCounts;
use crate::value::Value;
use std::convert::Infallible;

// The builder accounts for the buffers of the spill files and of the output at this size.
const _: () = assert!(BUFFER_BYTES as u64 == crate::stacking::BUFFER_BYTES);

impl<const K: usize, S: RaySource<K>> Builder<'_, K, S> {
    /// Builds the tree straight into `out` as a `.ktree` version 2 file (atomically: a temporary file
    /// renamed over it), holding at most about `max_memory` bytes: the subtrees of the cells are spilled
    /// to temporary files as they are stacked (see [`stacking`](crate::stacking)'s notes on memory and
    /// temporary files). The file is byte for byte what [`write_ktree_file`](crate::io::write_ktree_file)
    /// writes for the tree [`build`](Self::build) makes (with a [`world_frame`](Self::world_frame),
    /// what [`write_ktree_file_framed`](crate::io::write_ktree_file_framed) writes). It is [`build_into`](Self::build_into) with
    /// spill files and the `.ktree` writer: [`stack_part`](Self::stack_part) of every slab, then
    /// [`SpilledPart::write`].
    ///
    /// # Errors
    /// [`BuildError`]: the source's first error, a budget too small (at once when what is known before
    /// any slab is stacked does not fit), threads that cannot be started, a temporary folder or output
    /// that cannot be written (a full disk included). The target is then untouched and no temporary file
    /// remains.
    pub fn to_file(
        &self,
        out: &Path,
        max_memory: u64,
    ) -> Result<OutOfCoreReport, BuildError<S::Error>>
    where
        S::Error: Display,
    {
        let part = self.stack_part(&self.slabs(), out, max_memory)?;
        part.write_framed(
            out,
            (self.frame(), &Notes::new()),
            &mut |_, _| Err(std::io::Error::other("no other part")),
            self.progress_callback(),
        )
    }

    /// Stacks the cells of some slabs (from [`slabs`](Self::slabs), increasing) and spills their subtrees
    /// next to `out` (or in the [`temp_dir`](Self::temp_dir)), in a budget of `max_memory` bytes for this
    /// part alone; nothing is written to `out`. One part gathers the others' indexes and writes the file
    /// ([`SpilledPart::add_part`], [`SpilledPart::write`]): the file is that of
    /// [`to_file`](Self::to_file) for any cut into parts. It is
    /// [`stack_part_into`](Self::stack_part_into) spill files.
    ///
    /// # Errors
    /// As [`to_file`](Self::to_file).
    pub fn stack_part(
        &self,
        slabs: &[u32],
        out: &Path,
        max_memory: u64,
    ) -> Result<SpilledPart<SpilledFiles>, BuildError<S::Error>>
    where
        S::Error: Display,
    {
        let store = SpillFiles::create(out, self.spill_dir(), self.subtree_levels())?;
        self.stack_part_into(slabs, store, max_memory)
    }
}

impl SpilledPart<SpilledFiles> {
    /// The writing phase into a file: writes the tree to `out` as a `.ktree` version 2 file, atomically —
    /// [`write_into`](Self::write_into) a [`KtreeWriter`] over a temporary file renamed over `out` at the
    /// end, `receive(owner, words)` filling `words` with the next words of that owner's
    /// [`stream_levels`](Self::stream_levels).
    ///
    /// # Errors
    /// [`BuildError::BudgetTooSmall`] if the index of all parts does not fit in the budget; the output
    /// or a spill file that cannot be written or read (an error of `receive` included, as an error of the
    /// output). The target is then untouched; the spill folder is removed in any case.
    pub fn write<E>(
        self,
        out: &Path,
        receive: &mut dyn FnMut(usize, &mut [u64]) -> std::io::Result<()>,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<OutOfCoreReport, BuildError<E>> {
        self.write_framed(out, (None, &Notes::new()), receive, progress)
    }

    /// [`write`](Self::write) with a world frame and notes in the file's header (see
    /// [`io::write_ktree_framed`](crate::io::write_ktree_framed)).
    ///
    /// # Errors
    /// As [`write`](Self::write).
    pub fn write_framed<E>(
        self,
        out: &Path,
        (frame, notes): (Option<&WorldFrame>, &Notes),
        receive: &mut dyn FnMut(usize, &mut [u64]) -> std::io::Result<()>,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<OutOfCoreReport, BuildError<E>> {
        let file = AtomicFile::create(out).map_err(|e| output_error(out, e))?;
        let writer = KtreeWriter::with_frame(file, self.k(), self.level(), frame, notes)
            .map_err(|e| output_error(out, e))?;
        let receive = |owner: usize, words: &mut [u64]| {
            receive(owner, words).map_err(|e| output_error(out, e))
        };
        let output = OutputFile { writer, path: out };
        let (file_bytes, report) = self.write_into(output, receive, progress)?;
        Ok(OutOfCoreReport {
            file_bytes,
            ..report
        })
    }
}

/// Renames the finished temporary file over `path`; returns the file's size.
fn commit(file: AtomicFile, path: &Path) -> Result<u64, SpillError> {
    file.commit().map_err(|e| output_error(path, e))?;
    let metadata = std::fs::metadata(path).map_err(|e| output_error(path, e))?;
    Ok(metadata.len())
}

/// The error of a valued file `path` asked of a tree without values.
fn no_values(path: &Path) -> SpillError {
    output_error(
        path,
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "a tree without values is not written as a valued file",
        ),
    )
}

/// The error of the output `path`.
fn output_error(path: &Path, source: std::io::Error) -> SpillError {
    SpillError::Output {
        path: path.to_path_buf(),
        source,
    }
}

/// The spill files of a build's subtrees while they are written: one per level `1 … t` below the cells,
/// each piece appended in whole words, in a spill folder removed when they are dropped.
pub(crate) struct SpillFiles {
    files: Vec<LevelFile>,
    dir: tempfile::TempDir,
}

impl SpillFiles {
    /// Creates the spill folder of a build writing `out` (in `temp_dir`, by default `out`'s folder) and
    /// its files of levels `1 … levels`.
    pub(crate) fn create(
        out: &Path,
        temp_dir: Option<&Path>,
        levels: usize,
    ) -> Result<Self, SpillError> {
        let dir = crate::fs::spill_folder(out, temp_dir)
            .map_err(|(path, source)| SpillError::TempDir { path, source })?;
        let files = (1..=levels)
            .map(|j| LevelFile::create(dir.path().join(format!("level-{j}"))))
            .collect::<Result<_, _>>()?;
        Ok(Self { files, dir })
    }
}

impl PieceStore for SpillFiles {
    type Error = SpillError;
    type Stored = SpilledFiles;

    fn append(&mut self, depth: usize, words: &[u64], nodes: u64) -> Result<(), SpillError> {
        self.files[depth - 1].append_words(words, nodes)
    }

    fn finish(self) -> Result<SpilledFiles, SpillError> {
        let files = self
            .files
            .into_iter()
            .map(LevelFile::finish)
            .collect::<Result<_, _>>()?;
        Ok(SpilledFiles {
            files,
            _dir: self.dir,
        })
    }
}

/// The spill files of the subtrees of a part stacked out of core ([`Builder::stack_part`]), one per level
/// below the cells, read back when the part is written; the spill folder is removed when they are
/// dropped.
pub struct SpilledFiles {
    /// The files of levels `1 … t` (closed before their folder is removed).
    files: Vec<(PathBuf, File)>,
    _dir: tempfile::TempDir,
}

impl StoredPieces for SpilledFiles {
    type Error = SpillError;
    type Level<'a> = SpilledLevel<'a>;

    fn level<'a>(&'a mut self, depth: usize, offsets: &'a [u64], words: u64) -> SpilledLevel<'a> {
        let (path, file) = &mut self.files[depth - 1];
        let pieces = PieceRelease::new(file, offsets, words);
        SpilledLevel {
            path,
            file,
            offsets,
            at: u64::MAX,
            len: words,
            pieces,
            bytes: Vec::new(),
        }
    }
}

/// One spill file read back piece by piece, one read per piece (pieces are taken out of the order they
/// were spilled in, so a buffer ahead would mostly be wasted), the disk of each piece given back once it
/// is read (holes punched, see [`stacking`](crate::stacking)'s notes on disk); errors name the file.
pub struct SpilledLevel<'a> {
    path: &'a Path,
    file: &'a mut File,
    /// The word offset of each piece, in file order.
    offsets: &'a [u64],
    /// The word the file is at (`u64::MAX`: unknown).
    at: u64,
    /// The file's length in words.
    len: u64,
    /// Which pieces were read, and the disk given back.
    pieces: PieceRelease<'a>,
    bytes: Vec<u8>,
}

impl SpilledLevel<'_> {
    fn error(&self, source: std::io::Error) -> SpillError {
        SpillError::Spill {
            path: self.path.to_path_buf(),
            source,
        }
    }

    /// The words of piece `piece` in the file.
    fn words(&self, piece: usize) -> std::ops::Range<u64> {
        let end = self.offsets.get(piece + 1).copied().unwrap_or(self.len);
        self.offsets[piece]..end
    }
}

impl LevelPieces for SpilledLevel<'_> {
    type Error = SpillError;

    fn read(&mut self, piece: usize, at: u64, out: &mut [u64]) -> Result<(), SpillError> {
        let words = self.words(piece);
        let (start, end) = (words.start + at, words.start + at + out.len() as u64);
        if end > words.end.min(self.len) {
            return Err(self.error(std::io::Error::new(
                std::io::ErrorKind::UnexpectedEof,
                "shorter than its index",
            )));
        }
        if start != self.at {
            self.at = u64::MAX;
            if let Err(e) = self.file.seek(SeekFrom::Start(8 * start)) {
                return Err(self.error(e));
            }
            self.at = start;
        }
        self.bytes.resize(8 * out.len(), 0);
        if let Err(e) = self.file.read_exact(&mut self.bytes) {
            self.at = u64::MAX;
            return Err(self.error(e));
        }
        for (word, bytes) in out.iter_mut().zip(self.bytes.chunks_exact(8)) {
            *word = u64::from_le_bytes(bytes.try_into().expect("8 bytes"));
        }
        self.at = end;
        if end == words.end {
            self.pieces.release(self.file, piece);
        }
        Ok(())
    }

    fn finish(self) {
        self.pieces.finish(self.file);
    }
}

/// A `.ktree` file being written by a build: its writer (version 2 or 3) over the temporary file of `path`,
/// renamed over it when finished. Its output is the file's size.
struct OutputFile<'a, W> {
    writer: W,
    path: &'a Path,
}

impl<W> OutputFile<'_, W> {
    /// `write` of the writer, its error one of the output.
    fn with<T>(
        &mut self,
        write: impl FnOnce(&mut W) -> std::io::Result<T>,
    ) -> Result<T, SpillError> {
        write(&mut self.writer).map_err(|e| output_error(self.path, e))
    }
}

impl LevelOrderSink for OutputFile<'_, KtreeWriter<AtomicFile>> {
    type Error = SpillError;
    type Output = u64;

    fn append_words(&mut self, words: &[u64], nodes: u64) -> Result<(), SpillError> {
        self.with(|w| w.append_words(words, nodes))
    }

    fn end_level(&mut self) -> Result<(), SpillError> {
        self.with(KtreeWriter::end_level)
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.writer.counts_per_level()
    }

    fn finish(self) -> Result<u64, SpillError> {
        let file = self
            .writer
            .finish()
            .map_err(|e| output_error(self.path, e))?;
        commit(file, self.path)
    }
}

impl ValuedLevelSink for OutputFile<'_, ValuedKtreeWriter<AtomicFile>> {
    type Error = SpillError;
    type Output = u64;

    fn append_words(&mut self, words: &[u64], nodes: u64) -> Result<(), SpillError> {
        self.with(|w| w.append_words(words, nodes))
    }

    fn end_codes(&mut self) -> Result<(), SpillError> {
        self.with(ValuedKtreeWriter::end_codes)
    }

    fn append_values(&mut self, bytes: &[u8]) -> Result<(), SpillError> {
        self.with(|w| w.append_values(bytes))
    }

    fn end_level(&mut self) -> Result<(), SpillError> {
        self.with(ValuedKtreeWriter::end_level)
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.writer.counts_per_level()
    }

    fn finish(self) -> Result<u64, SpillError> {
        let file = self
            .writer
            .finish()
            .map_err(|e| output_error(self.path, e))?;
        commit(file, self.path)
    }
}

impl<const K: usize, V: Value + Send + Sync> ValueSlabs<K, V> {
    /// Builds the tree of the box `read` gives straight into `out` as a `.ktree` version 3 file with its
    /// world frame (if any) and `notes`, atomically (a temporary file renamed over it), the subtrees of its
    /// cells spilled to temporary files next to `out` (or in `temp_dir`) as they are built: the tree is
    /// never held whole ([`build_into`](Self::build_into) with spill files and the version 3 writer). The
    /// file is byte for byte what [`write_valued_ktree_noted`](crate::io::ktree::v3::write_valued_ktree_noted)
    /// writes for the tree [`KTree::from_value_slabs`](crate::KTree::from_value_slabs) makes.
    ///
    /// ```
    /// use ktree::io::ktree::v3::read_valued_ktree_file;
    /// use ktree::io::ktree::Notes;
    /// use ktree::stacking::ValueSlabs;
    /// use ktree::KTree;
    /// // An 8 × 8 × 8 cube of labels (a label a plane of 2, 1 the background) in a universe of side 16.
    /// let read = |planes: std::ops::Range<u32>, out: &mut Vec<u16>| {
    ///     out.extend(planes.flat_map(|z| std::iter::repeat_n(z as u16 / 2, 64)));
    ///     Ok::<_, ktree::rays::RayError>(())
    /// };
    /// let slabs = ValueSlabs { level: 4, region: [4..12, 4..12, 4..12], background: 1, slab_bytes: 256 };
    /// let dir = tempfile::tempdir().unwrap();
    /// let out = dir.path().join("labels.ktree");
    /// let report = slabs.write_file(&out, None, None, &Notes::new(), read).unwrap();
    /// let tree = KTree::<3, u16>::from_value_slabs(4, [4..12, 4..12, 4..12], 1, 256, read).unwrap();
    /// assert_eq!(read_valued_ktree_file::<3, u16>(&out).unwrap(), tree);
    /// assert_eq!(report.counts_per_level, tree.counts_per_level());
    /// ```
    ///
    /// # Errors
    /// As [`build_into`](Self::build_into): the source's errors; a temporary folder or output that cannot
    /// be written (a full disk included), a frame or notes that cannot be kept, a value type without
    /// values (`()`). The target is then untouched and no temporary file remains.
    pub fn write_file<E: From<RayError>>(
        &self,
        out: &Path,
        temp_dir: Option<&Path>,
        frame: Option<&WorldFrame>,
        notes: &Notes,
        read: impl FnMut(std::ops::Range<u32>, &mut Vec<V>) -> Result<(), E>,
    ) -> Result<ValueSlabsReport, BuildError<E>> {
        if V::DTYPE.is_none() {
            return Err(no_values(out).into());
        }
        self.stack_part_files(0..self.slab_count(), out, temp_dir, read)?
            .write(out, frame, notes, &mut |_, _| {
                unreachable!("a build in one part receives nothing")
            })
    }

    /// Builds the part of the tree in the slabs `slabs` ([`stack_part`](Self::stack_part)), its cells'
    /// subtrees spilled to temporary files next to `out` (or in `temp_dir`) — one part of a build across
    /// processes, each reading its own slabs; the part that writes `out` adds the others' indexes and
    /// writes it ([`ValuePart::write`]).
    ///
    /// # Errors
    /// As [`stack_part`](Self::stack_part); a spill folder or file that cannot be written.
    pub fn stack_part_files<E: From<RayError>>(
        &self,
        slabs: std::ops::Range<u32>,
        out: &Path,
        temp_dir: Option<&Path>,
        read: impl FnMut(std::ops::Range<u32>, &mut Vec<V>) -> Result<(), E>,
    ) -> Result<ValuePart<K, V, SpilledFiles>, BuildError<E>> {
        let t = (self.level - self.cell_depth()) as usize;
        let store = SpillFiles::create(out, temp_dir, t)?;
        self.stack_part(slabs, read, store)
    }
}

impl<const K: usize, V: Value + Send + Sync> ValueRuns<K, V> {
    /// Builds the tree of the runs straight into `out` as a `.ktree` version 3 file with its world frame
    /// (if any) and `notes`, atomically, its cells of depth `cell_depth` built slab by slab and their
    /// subtrees spilled to temporary files next to `out` (or in `temp_dir`): the tree is never held whole
    /// ([`build_into`](Self::build_into) with spill files and the version 3 writer). The file is byte for
    /// byte what [`write_valued_ktree_noted`](crate::io::ktree::v3::write_valued_ktree_noted) writes for
    /// [`KTree::from_value_runs`](crate::KTree::from_value_runs).
    ///
    /// ```
    /// use ktree::io::ktree::v3::read_valued_ktree_file;
    /// use ktree::io::ktree::Notes;
    /// use ktree::rays::ValueRuns;
    /// use ktree::{KTree, Ray};
    /// let runs = ValueRuns::<2, u8>::from_runs(3, [(Ray::new([1, 0], 7), 4), (Ray::new([2, 3], 8), 9)]).unwrap();
    /// let dir = tempfile::tempdir().unwrap();
    /// let out = dir.path().join("runs.ktree");
    /// let report = runs.write_file(&out, None, None, &Notes::new(), 2).unwrap();
    /// assert_eq!(read_valued_ktree_file::<2, u8>(&out).unwrap(), KTree::from_value_runs(&runs));
    /// assert_eq!(report.cell_depth, 2);
    /// ```
    ///
    /// # Errors
    /// A temporary folder or output that cannot be written (a full disk included), a frame or notes
    /// that cannot be kept, a value type without values (`()`). The target is then untouched and no
    /// temporary file remains.
    pub fn write_file(
        &self,
        out: &Path,
        temp_dir: Option<&Path>,
        frame: Option<&WorldFrame>,
        notes: &Notes,
        cell_depth: u32,
    ) -> Result<ValueSlabsReport, BuildError<Infallible>> {
        if V::DTYPE.is_none() {
            return Err(no_values(out).into());
        }
        self.stack_part_files(cell_depth, 0..u32::MAX, out, temp_dir)?
            .write(out, frame, notes, &mut |_, _| {
                unreachable!("a build in one part receives nothing")
            })
    }

    /// [`stack_part`](Self::stack_part) with the cells' subtrees spilled to temporary files next to `out`
    /// (or in `temp_dir`): one part of a build across processes ([`ValuePart::write`]).
    ///
    /// # Errors
    /// A spill folder or file that cannot be written.
    pub fn stack_part_files(
        &self,
        cell_depth: u32,
        slabs: std::ops::Range<u32>,
        out: &Path,
        temp_dir: Option<&Path>,
    ) -> Result<ValuePart<K, V, SpilledFiles>, BuildError<Infallible>> {
        let level = self.universe().level();
        let m = self.clamped_cell_depth(cell_depth);
        let store = SpillFiles::create(out, temp_dir, (level - m) as usize)?;
        self.stack_part(m, slabs, store)
    }
}

impl<const K: usize, V: Value + Send + Sync> ValuePart<K, V, SpilledFiles> {
    /// The writing phase into a file: writes the tree to `out` as a `.ktree` version 3 file with its world
    /// frame (if any) and `notes`, atomically — [`write_into`](Self::write_into) the version 3 writer over
    /// a temporary file renamed over `out` at the end, `receive(owner, words)` filling `words` with the
    /// next words of that owner's [`stream_levels`](Self::stream_levels). The file is byte for byte
    /// [`ValueSlabs::write_file`]'s.
    ///
    /// # Errors
    /// [`BuildError::PartsOverlap`]; the output or a spill file that cannot be written or read (an error
    /// of `receive` included, as an error of the output); a value type without values. The target is
    /// then untouched; the spill folder is removed in any case.
    pub fn write<E>(
        self,
        out: &Path,
        frame: Option<&WorldFrame>,
        notes: &Notes,
        receive: &mut dyn FnMut(usize, &mut [u64]) -> std::io::Result<()>,
    ) -> Result<ValueSlabsReport, BuildError<E>> {
        let dtype = V::DTYPE.ok_or_else(|| no_values(out))?;
        let level = self.level();
        let file = AtomicFile::create(out).map_err(|e| output_error(out, e))?;
        let writer = ValuedKtreeWriter::new(file, K, level, dtype, frame, notes)
            .map_err(|e| output_error(out, e))?;
        let sink = OutputFile { writer, path: out };
        let mut receive = |owner: usize, words: &mut [u64]| {
            receive(owner, words).map_err(|e| output_error(out, e))
        };
        let (file_bytes, report) = self.write_into(sink, &mut receive)?;
        Ok(ValueSlabsReport {
            file_bytes,
            ..report
        })
    }
}
