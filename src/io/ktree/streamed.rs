//! Booleans of two `.ktree` version 2 files streamed to a third in bounded memory, for trees larger than
//! memory: the files' side of [`ops::boolean_into`](crate::ops::boolean_into) (the algorithm, over any
//! storages and any sink), which this module runs on mapped inputs into spilled levels.
//!
//! # How it runs
//! The inputs are read through their memory maps ([`KtreeView`]) as [`MappedTree`]s, whose every read is
//! checked, by the Boolean that [`ops::boolean`](crate::ops::boolean) runs on trees in memory — the same pair walk,
//! merge and truth table: where one side is a leaf, the result under it is a leaf, a copy of the other
//! side's subtree or its complement (level ranges copied word by word), and two partial nodes are walked
//! child by child. The result is produced in *post-order*: a node's `2^K` child states are appended to the
//! output level below once all of them are known, so a node whose children all turn out full (or empty)
//! collapses before anything of it is written, and the blocks of every level come out in level order (a
//! node finishes after every node before it at its depth). The output is a level sink that appends each
//! level to its own temporary *spill file* (`io::spill::SpillLevels`); at the end they are streamed, level by level,
//! into the `.ktree` through a [`KtreeWriter`](crate::io::KtreeWriter), written to a temporary file and renamed over the target.
//!
//! Child positions in the inputs come from the file's rank samples (at most 64 word pop-counts each).
//!
//! # Memory
//! What the process allocates is bounded by the depth of the trees, not their size: the walk's stack, one
//! 64 KiB buffer per output level and one for the output. The inputs' pages are read through the
//! memory maps, each level front to back; they are the kernel's page cache, dropped under memory pressure,
//! so inputs larger than memory work.
//!
//! ```
//! use ktree::{io, ops, KTree};
//! let dir = tempfile::tempdir().unwrap();
//! let (pa, pb, pc) = (dir.path().join("a.ktree"), dir.path().join("b.ktree"), dir.path().join("c.ktree"));
//! let a = KTree::<2>::from_dense(2, &[true; 16]).unwrap();
//! let b = KTree::<2>::from_dense(2, &(0..16).map(|i| i % 3 == 0).collect::<Vec<_>>()).unwrap();
//! io::write_ktree_file(&pa, &a).unwrap();
//! io::write_ktree_file(&pb, &b).unwrap();
//! io::boolean_files(&pa, &pb, ops::BoolOp::Difference, &pc, None).unwrap();
//! assert_eq!(io::read_ktree_file(&pc).unwrap(), ktree::AnyTree::K2(ops::difference(&a, &b).unwrap()));
//! ```

use std::path::Path;

use super::{KtreeFileError, KtreeView, MappedTree, Notes};
use crate::fs::SpillError;
use crate::io::spill::{SpillLevels, SpilledTree};
use crate::ops::{boolean_into, complement_into, BoolOp};
use crate::space::WorldFrame;
use crate::tree::LevelCounts;

/// Why a streamed Boolean failed. The target file is untouched and the spill files are removed.
#[derive(Debug, thiserror::Error)]
pub enum BooleanFileError {
    /// An input cannot be opened or read (the error names it and the byte offset).
    #[error(transparent)]
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
    /// The inputs keep different world frames: their voxels are not the same places.
    #[error(
        "{a} keeps the world frame {fa:?} but {b} keeps {fb:?}: a Boolean needs trees on one grid"
    )]
    Frames {
        /// The first input.
        a: String,
        /// Its frame.
        fa: WorldFrame,
        /// The second input.
        b: String,
        /// Its frame.
        fb: WorldFrame,
    },
    /// A temporary file or the output could not be written.
    #[error(transparent)]
    Files(#[from] SpillError),
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

/// The operation of a streamed Boolean: a binary operation with its second operand, or the complement of
/// the first.
#[derive(Debug, Clone, Copy)]
pub enum ViewOperation<'a> {
    /// `a op b`.
    Binary(BoolOp, &'a KtreeView),
    /// `¬a`.
    Complement,
}

/// Writes `a op b` to the `.ktree` version 2 file `out`, reading the version 2 files `a` and `b` through
/// their memory maps, in bounded memory (see the module's notes). Spill files go to a hidden folder in
/// `temp_dir` (default: the output's folder), removed at the end. The bytes are those of
/// [`write_ktree_framed`](crate::io::write_ktree_framed) of [`ops::boolean`](crate::ops::boolean) of
/// the trees, with the world frame they keep ([`WorldFrame::shared`]) and the first one's notes (else
/// the second's).
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
    boolean_views(&va, ViewOperation::Binary(op, &vb), out, temp_dir)
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
    boolean_views(&va, ViewOperation::Complement, out, temp_dir)
}

/// `operation` applied to the view `a` (and the second operand it names), written to `out`.
///
/// ```
/// use ktree::{io, ops, KTree};
/// let dir = tempfile::tempdir().unwrap();
/// let (pa, pc) = (dir.path().join("a.ktree"), dir.path().join("c.ktree"));
/// let a = KTree::<1>::from_dense(2, &[true, false, false, true]).unwrap();
/// io::write_ktree_file(&pa, &a).unwrap();
/// let view = io::KtreeView::open(&pa).unwrap();
/// io::boolean_views(&view, io::ViewOperation::Complement, &pc, None).unwrap();
/// assert_eq!(io::read_ktree_file(&pc).unwrap(), ktree::AnyTree::K1(ops::complement(&a)));
/// ```
///
/// # Errors
/// As [`boolean_files`].
pub fn boolean_views(
    a: &KtreeView,
    operation: ViewOperation<'_>,
    out: &Path,
    temp_dir: Option<&Path>,
) -> Result<BooleanFileReport, BooleanFileError> {
    let (frame, notes) = match operation {
        ViewOperation::Binary(_, b) => {
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
            boolean_header(
                (a.name(), a.frame(), a.notes()),
                (b.name(), b.frame(), b.notes()),
            )?
        }
        ViewOperation::Complement => (a.frame(), a.notes().clone()),
    };
    let output = Output {
        path: out,
        frame,
        notes: &notes,
        temp_dir,
    };
    match a.k() {
        1 => boolean_views_k::<1>(a, operation, output),
        2 => boolean_views_k::<2>(a, operation, output),
        3 => boolean_views_k::<3>(a, operation, output),
        // Any other `K` is refused by `MappedTree::new`.
        _ => boolean_views_k::<4>(a, operation, output),
    }
}

/// The world frame and notes of a Boolean of two trees, each given as its name (for the error), frame and
/// notes: the frame they share ([`WorldFrame::shared`]) and the first one's notes, else the second's — what
/// [`boolean_files`] writes, and what a Boolean in memory should keep.
///
/// ```
/// use ktree::io::{boolean_header, Notes};
/// use ktree::space::WorldFrame;
/// let f = WorldFrame { voxel_size: 0.5, origin: [0.0; 3] };
/// let named = Notes::from([("source".to_string(), "b".to_string())]);
/// let (frame, notes) = boolean_header(("a", None, &Notes::new()), ("b", Some(f), &named)).unwrap();
/// assert_eq!((frame, notes), (Some(f), named));
/// ```
///
/// # Errors
/// [`BooleanFileError::Frames`] when both keep a frame and they differ.
pub fn boolean_header(
    (a, fa, na): (&str, Option<WorldFrame>, &Notes),
    (b, fb, nb): (&str, Option<WorldFrame>, &Notes),
) -> Result<(Option<WorldFrame>, Notes), BooleanFileError> {
    let frame = WorldFrame::shared(fa, fb).map_err(|[fa, fb]| BooleanFileError::Frames {
        a: a.to_string(),
        fa,
        b: b.to_string(),
        fb,
    })?;
    let notes = if na.is_empty() { nb } else { na };
    Ok((frame, notes.clone()))
}

/// Where a streamed Boolean writes, and the world frame and notes its file keeps.
struct Output<'a> {
    path: &'a Path,
    frame: Option<WorldFrame>,
    notes: &'a Notes,
    temp_dir: Option<&'a Path>,
}

/// [`boolean_views`] for files of dimension `K`.
fn boolean_views_k<const K: usize>(
    a: &KtreeView,
    operation: ViewOperation<'_>,
    output: Output<'_>,
) -> Result<BooleanFileReport, BooleanFileError> {
    let Output {
        path: out,
        frame,
        notes,
        temp_dir,
    } = output;
    let sa = MappedTree::<K>::new(a)?;
    let sb = match operation {
        ViewOperation::Binary(_, b) => Some(MappedTree::<K>::new(b)?),
        ViewOperation::Complement => None,
    };
    let depths = a
        .depth_count()
        .max(sb.as_ref().map_or(0, |b| b.view().depth_count()));
    let folder = crate::fs::spill_folder(out, temp_dir)
        .map_err(|(path, source)| BooleanFileError::Files(SpillError::TempDir { path, source }))?;
    let sink =
        SpillLevels::create(folder.path(), depths, K, a.level(), out)?.framed(frame, notes.clone());
    let written: Result<SpilledTree, BooleanFileError> = match (operation, sb) {
        (ViewOperation::Binary(op, _), Some(sb)) => boolean_into(&sa, &sb, op, sink),
        _ => complement_into(&sa, sink),
    };
    drop(folder);
    let written = written?;
    Ok(BooleanFileReport {
        k: K,
        level: a.level(),
        counts_per_level: written.counts_per_level,
        spilled_bytes: written.spilled_bytes,
    })
}
