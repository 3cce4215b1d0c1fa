//! The `.ktree` file: a tree in level order at Meagher's 2 bits a node (`00` empty, `01` full, `10` partial),
//! checksummed. Two versions exist and both are read everywhere ([`read_ktree`], [`read_ktree_any`],
//! [`read_ktree_file`]); only the current one, [`VERSION`] = 2, is written ([`write_ktree`]):
//!
//! * [`v2`]: one word-aligned section per level with rank samples, written as a stream ([`KtreeWriter`]) and
//!   read in place through a memory map ([`KtreeView`], [`MappedTree`]), for trees larger than memory;
//! * [`v1`]: one body for the whole tree, read into memory; written only by [`v1::write_ktree_v1`];
//! * [`streamed`]: Booleans of version 2 files written to a third in bounded memory ([`boolean_files`]).
//!
//! ```
//! use ktree::{io, KTree};
//! let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
//! let mut bytes = Vec::new();
//! io::write_ktree(&mut bytes, &tree).unwrap();
//! assert_eq!(u16::from_le_bytes([bytes[6], bytes[7]]), io::VERSION);
//! assert_eq!(io::read_ktree::<2>(&bytes, "mem").unwrap(), tree);
//! bytes[20] ^= 1; // corrupt a byte
//! assert!(io::read_ktree::<2>(&bytes, "mem").is_err());
//! ```

use std::fs::File;
use std::io::Write;
use std::path::Path;

use thiserror::Error;

use crate::space::WorldFrame;
use crate::tree::{AnyTree, KTree};

mod history_file;
mod level_stream;
mod map_file;
pub mod notes;
pub mod streamed;
pub mod v1;
pub mod v2;
pub mod v3;
mod v3_mapped;
mod v3_writer;

pub use history_file::{read_history_ktree, write_history_ktree_file, STEPS_NOTE};
pub use map_file::{read_map_ktree, write_map_ktree_file, MappedMap};
pub use notes::Notes;
pub use streamed::{
    boolean_files, boolean_header, boolean_views, complement_file, BooleanFileError,
    BooleanFileReport, ViewOperation,
};
pub use v2::{AnyMappedTree, KtreeView, KtreeWriter, MappedTree};

/// The format version [`write_ktree`] writes.
pub const VERSION: u16 = v2::VERSION;

/// The magic bytes at the start of a `.ktree` file.
pub const MAGIC: &[u8; 6] = b"KTREE\0";

/// What was wrong with a `.ktree` file.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum KtreeFileErrorKind {
    /// Not a `.ktree` file.
    #[error("not a .ktree file (bad magic)")]
    BadMagic,
    /// Written by a newer version of ktree.
    #[error("format version {0} is not supported (this ktree reads versions 1, 2 and 3)")]
    Version(u16),
    /// `K` or `L` out of range.
    #[error("bad header: {0}")]
    Header(String),
    /// The file ends early or has extra bytes.
    #[error("file is {found} bytes but the header describes {expected}: truncated or padded")]
    Length {
        /// Bytes the header implies.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// The checksum does not match: the file is corrupted.
    #[error(
        "checksum mismatch (stored {stored:08x}, computed {computed:08x}): the file is corrupted"
    )]
    Checksum {
        /// Stored CRC.
        stored: u32,
        /// Computed CRC.
        computed: u32,
    },
    /// The checksum of one level's section (version 2) does not match: the file is corrupted.
    #[error("checksum mismatch in the section of level {level} (stored {stored:08x}, computed {computed:08x}): the file is corrupted")]
    SectionChecksum {
        /// The tree level whose section is corrupted.
        level: usize,
        /// Stored CRC.
        stored: u32,
        /// Computed CRC.
        computed: u32,
    },
    /// The node states are inconsistent.
    #[error("bad tree: {0}")]
    Tree(String),
    /// The tree has another dimension than the caller asked for.
    #[error("the file holds a K = {found} tree, K = {expected} was expected")]
    Dimension {
        /// K asked for.
        expected: usize,
        /// K in the file.
        found: usize,
    },
    /// The file holds values of another type than the reader asked for (`None`: no values, a binary tree).
    #[error("the file holds {}, {} was expected", dtype_name(*found), dtype_name(*expected))]
    Dtype {
        /// The value type asked for.
        expected: Option<crate::tree::Dtype>,
        /// The value type in the file.
        found: Option<crate::tree::Dtype>,
    },
    /// The file could not be read.
    #[error("cannot read")]
    Io(crate::fs::IoCause),
}

fn dtype_name(d: Option<crate::tree::Dtype>) -> String {
    d.map_or("a tree without values".into(), |d| {
        format!("values of type {d}")
    })
}

/// An error reading a `.ktree` file, with the file and the byte offset.
pub type KtreeFileError = crate::io::FileError<KtreeFileErrorKind>;

impl crate::io::ProblemKind for KtreeFileErrorKind {
    fn io_cause(&self) -> Option<&std::io::Error> {
        match self {
            Self::Io(cause) => Some(cause.error()),
            _ => None,
        }
    }
}

/// Writes a tree as a `.ktree` file of the current version ([`VERSION`]).
///
/// # Errors
/// Any I/O error.
pub fn write_ktree<const K: usize>(out: impl Write, tree: &KTree<K>) -> std::io::Result<()> {
    v2::write_levels(out, tree, None, &Notes::new())
}

/// [`write_ktree`] of a file that keeps where the tree's voxels are in the world (`frame`) and `notes`;
/// read back by [`read_ktree_framed`] and [`KtreeView::frame`] and [`KtreeView::notes`]. Without
/// either, the file is the one [`write_ktree`] writes.
///
/// ```
/// use ktree::io::{read_ktree_framed, write_ktree_framed, Notes};
/// use ktree::space::WorldFrame;
/// use ktree::{AnyTree, KTree};
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
/// let frame = WorldFrame { voxel_size: 0.05, origin: [1.0, -2.0, 0.0] };
/// let notes = Notes::from([("source".to_string(), "select 3".to_string())]);
/// let mut bytes = Vec::new();
/// write_ktree_framed(&mut bytes, &tree, Some(&frame), &notes).unwrap();
/// let (back, kept, kept_notes) = read_ktree_framed(&bytes, "mem").unwrap();
/// assert_eq!((back, kept, kept_notes), (AnyTree::K2(tree), Some(frame), notes));
/// ```
///
/// # Errors
/// Any I/O error; `InvalidInput` for a frame whose voxel size is not a positive number or whose origin
/// is not finite, or a note that cannot be kept.
pub fn write_ktree_framed<const K: usize>(
    out: impl Write,
    tree: &KTree<K>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> std::io::Result<()> {
    v2::write_levels(out, tree, frame, notes)
}

/// [`write_ktree_framed`] to a file, atomically (temporary file, then rename).
///
/// # Errors
/// A [`FileOpError`](crate::fs::FileOpError) naming the path, its source the I/O error.
pub fn write_ktree_file_framed<const K: usize>(
    path: &Path,
    tree: &KTree<K>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> Result<(), crate::fs::FileOpError> {
    crate::fs::write_atomic_with(path, |w| write_ktree_framed(w, tree, frame, notes))
}

/// Writes a `.ktree` file of the current version atomically (temporary file, then rename).
///
/// # Errors
/// A [`FileOpError`](crate::fs::FileOpError) naming the path, its source the I/O error.
pub fn write_ktree_file<const K: usize>(
    path: &Path,
    tree: &KTree<K>,
) -> Result<(), crate::fs::FileOpError> {
    crate::fs::write_atomic_with(path, |w| write_ktree(w, tree))
}

/// Reads a `.ktree` file's bytes (either version), expecting dimension `K`.
///
/// # Errors
/// [`KtreeFileError`] for any inconsistency, or [`KtreeFileErrorKind::Dimension`] if the file's `K` differs.
pub fn read_ktree<const K: usize>(bytes: &[u8], file: &str) -> Result<KTree<K>, KtreeFileError> {
    let any = read_ktree_any(bytes, file)?;
    let found = any.k();
    any.into_dim::<K>().map_err(|_| {
        KtreeFileError::at_byte(
            file.to_string(),
            8,
            KtreeFileErrorKind::Dimension { expected: K, found },
        )
    })
}

/// Reads a `.ktree` file from disk (either version), of whatever dimension it holds.
///
/// # Errors
/// As [`read_ktree_any`]; an unreadable file is [`KtreeFileErrorKind::Io`].
pub fn read_ktree_file(path: &Path) -> Result<AnyTree, KtreeFileError> {
    read_ktree_file_framed(path).map(|(tree, _, _)| tree)
}

/// [`read_ktree_file`] with where the voxels are in the world and the notes, if the file keeps them
/// ([`read_ktree_framed`]).
///
/// # Errors
/// As [`read_ktree_file`].
pub fn read_ktree_file_framed(
    path: &Path,
) -> Result<(AnyTree, Option<WorldFrame>, Notes), KtreeFileError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path)
        .map_err(|e| KtreeFileError::at_byte(name.clone(), 0, KtreeFileErrorKind::Io(e.into())))?;
    read_ktree_framed(&bytes, &name)
}

/// Reads a `.ktree` file's bytes (version 1 or 2), of whatever dimension they hold.
///
/// # Errors
/// [`KtreeFileError`] naming the byte offset of the first inconsistency.
pub fn read_ktree_any(bytes: &[u8], file: &str) -> Result<AnyTree, KtreeFileError> {
    read_ktree_framed(bytes, file).map(|(tree, _, _)| tree)
}

/// [`read_ktree_any`] with where the voxels are in the world and the notes, if the file keeps them
/// ([`write_ktree_framed`]; a version 1 file keeps neither).
///
/// # Errors
/// As [`read_ktree_any`].
pub fn read_ktree_framed(
    bytes: &[u8],
    file: &str,
) -> Result<(AnyTree, Option<WorldFrame>, Notes), KtreeFileError> {
    let fail = |offset: u64, kind| KtreeFileError::at_byte(file.to_string(), offset, kind);
    if bytes.len() < 6 || &bytes[..6] != MAGIC {
        return Err(fail(0, KtreeFileErrorKind::BadMagic));
    }
    if bytes.len() < 8 {
        return Err(fail(
            bytes.len() as u64,
            KtreeFileErrorKind::Length {
                expected: 16,
                found: bytes.len() as u64,
            },
        ));
    }
    match u16::from_le_bytes([bytes[6], bytes[7]]) {
        v1::VERSION => v1::read_v1_any(bytes, file).map(|tree| (tree, None, Notes::new())),
        v2::VERSION => v2::read_v2_framed(bytes, file),
        v3::VERSION => Err(fail(
            10,
            KtreeFileErrorKind::Dtype {
                expected: None,
                found: bytes
                    .get(10)
                    .and_then(|&c| crate::tree::Dtype::from_code(c)),
            },
        )),
        other => Err(fail(6, KtreeFileErrorKind::Version(other))),
    }
}

/// The format version of a `.ktree` file (1 or 2), from its first 8 bytes.
///
/// # Errors
/// [`KtreeFileErrorKind::BadMagic`] for another file; [`KtreeFileErrorKind::Io`] if it cannot be read.
pub fn ktree_file_version(path: &Path) -> Result<u16, KtreeFileError> {
    let name = path.display().to_string();
    let head = File::open(path)
        .and_then(|f| {
            let len = f.metadata()?.len().min(8) as usize;
            v2::read_at(&f, 0, len)
        })
        .map_err(|e| KtreeFileError::at_byte(name.clone(), 0, KtreeFileErrorKind::Io(e.into())))?;
    if head.len() < 8 || &head[..6] != MAGIC {
        return Err(KtreeFileError::at_byte(
            name,
            0,
            KtreeFileErrorKind::BadMagic,
        ));
    }
    Ok(u16::from_le_bytes([head[6], head[7]]))
}
