//! The `.ktree` file, version 3: a valued tree ([`KTree`] with a [`Value`] type) — the level sections of
//! version 2 with the mixed code, a rank over full nodes and each level's values. A binary tree is still
//! written as version 2 (its files are unchanged); version 3 holds a tree with values.
//!
//! All integers are little-endian; every section starts at a multiple of 8 bytes.
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 6 | magic `KTREE\0` |
//! | 6 | 2 | format version, `u16` (= 3) |
//! | 8 | 1 | `K` (1…4) |
//! | 9 | 1 | `L` (0…[`crate::max_level`]`(K)`) |
//! | 10 | 1 | the value type, [`Dtype::code`] (1 `uint8`, 2 `uint16`, 3 `uint32`, 4 `int8`, 5 `float32`, 6 `rgb8`) |
//! | 11 | 1 | flags: bit 0 set when a world frame follows the header, bit 1 when notes follow it; the other bits 0 |
//! | 12 | 4 | reserved, 0 |
//! | 16 | 32 | only with flag bit 0: the world frame ([`WorldFrame`]): the voxel size, then the origin's x, y and z (`f64` each) |
//! | 16 or 48 | 8 + N, padded to 8 | only with flag bit 1: the notes ([`Notes`]): their length `N` (`u64`), then `N` bytes of `name=text` lines |
//! | after them | … | section 0 (the root level), then section `d` right after section `d − 1` |
//! | S | 32·D | directory: per level `d`, nodes `n_d`, full nodes `f_d`, nodes with children `c_d` (`u64` each), CRC-32 of section `d` (`u32`), reserved `u32` = 0 |
//! | S + 32·D | 8 | the file's length in bytes (`u64`) |
//! | S + 32·D + 8 | 4 | `D`, the number of levels (`u32`) |
//! | S + 32·D + 12 | 4 | CRC-32 of the header (bytes 0…15, the frame and the notes) and of everything from S up to here |
//!
//! Section `d` holds `W_d = ⌈n_d / 32⌉` words of 2-bit codes (node `i` in bits `2·(i mod 32)` of word
//! `i / 32`: `00` empty, `01` full, `10` partial, `11` mixed — every voxel valued, not all alike; unused bits
//! 0), then `R_d = ⌈W_d / 64⌉` samples of the nodes with children before words `64·b` and `R_d` samples of
//! the full nodes before them (so a reader through a map finds a node's children and its value with at
//! most 64 pop-counts), then the `f_d` values of the level's full nodes in level order, each
//! [`Dtype::bytes`] little-endian bytes, zero-padded to a multiple of 8. The section's CRC covers all of it.
//!
//! Reading checks everything version 2 checks, and: the value type is the one asked for, every value is
//! one a voxel may hold (no NaN), a mixed node has no empty or partial child, and the tree is minimal (no
//! node with children whose children are all empty or all full of one value).
//!
//! ```
//! use ktree::io::ktree::v3::{read_valued_ktree, write_valued_ktree};
//! use ktree::KTree;
//! let tree = KTree::<2, u16>::from_dense_values(1, &[Some(7), None, Some(9), Some(7)]).unwrap();
//! let mut bytes = Vec::new();
//! write_valued_ktree(&mut bytes, &tree).unwrap();
//! assert_eq!(read_valued_ktree::<2, u16>(&bytes, "mem").unwrap(), tree);
//! assert!(read_valued_ktree::<2, u8>(&bytes, "mem").is_err()); // another value type
//! ```

use std::io::Write;
use std::path::Path;

use super::notes::Notes;
use super::v2::layout::{
    header_extras, samples_of, u32_at, u64_at, words_of, HeaderExtras, ENTRY_BYTES, HEADER_BYTES,
    TAIL_BYTES,
};
use super::{KtreeFileError, KtreeFileErrorKind, MAGIC};
use crate::space::{max_level, Universe, WorldFrame, MAX_K};
use crate::tree::valued::ValueStorage;
use crate::tree::words::{children_mask, full_mask};
use crate::tree::{AnyTree, AnyValuedTree, Dtype, KTree, PackedStates, Value};

pub use super::v3_mapped::{MappedLeaves, MappedValuedTree};
pub use super::v3_writer::ValuedKtreeWriter;

/// The format version of valued files.
pub const VERSION: u16 = 3;

/// Words between two rank samples.
const WORDS_PER_SAMPLE: usize = 64;

fn padded(bytes: u64) -> Option<u64> {
    bytes.checked_add(7).map(|b| b / 8 * 8)
}

/// The bytes of a level's section: codes, both rank samples, values padded.
fn section_bytes(nodes: u64, full: u64, value_bytes: u64) -> Option<u64> {
    let words = words_of(nodes);
    let fixed = 8u64.checked_mul(words.checked_add(2 * samples_of(words))?)?;
    fixed.checked_add(padded(full.checked_mul(value_bytes)?)?)
}

/// Writes a valued tree as a version 3 `.ktree` file; a tree without values (`V = ()`) as version 2.
///
/// # Errors
/// Any I/O error.
pub fn write_valued_ktree<const K: usize, V: Value>(
    out: impl Write,
    tree: &KTree<K, V>,
) -> std::io::Result<()> {
    write_valued_ktree_framed(out, tree, None)
}

/// Writes a valued tree as a version 3 `.ktree` file with where its voxels are in the world (`frame`, kept
/// after the header; `None`: none). A tree without values is written as version 2, without a frame.
///
/// ```
/// use ktree::io::ktree::v3::{read_valued_ktree_framed, write_valued_ktree_framed};
/// use ktree::space::WorldFrame;
/// use ktree::KTree;
/// let tree = KTree::<3, f32>::from_dense_values(1, &[Some(0.5); 8]).unwrap();
/// let frame = WorldFrame { voxel_size: 0.05, origin: [-1.0, 2.0, 0.0] };
/// let mut bytes = Vec::new();
/// write_valued_ktree_framed(&mut bytes, &tree, Some(&frame)).unwrap();
/// assert_eq!(read_valued_ktree_framed::<3, f32>(&bytes, "mem").unwrap(), (tree, Some(frame)));
/// ```
///
/// # Errors
/// Any I/O error; [`std::io::ErrorKind::InvalidInput`] for a frame whose voxel size is not a positive
/// number or whose origin is not finite.
pub fn write_valued_ktree_framed<const K: usize, V: Value>(
    out: impl Write,
    tree: &KTree<K, V>,
    frame: Option<&WorldFrame>,
) -> std::io::Result<()> {
    write_valued_ktree_noted(out, tree, frame, &Notes::new())
}

/// Writes a valued tree as a version 3 `.ktree` file with its world frame (if any) and `notes` (kept
/// after the frame; none: no block, the file [`write_valued_ktree_framed`] writes). A tree without values
/// is written as version 2, without frame or notes. Example: [`super::notes`].
///
/// # Errors
/// As [`write_valued_ktree_framed`]; [`std::io::ErrorKind::InvalidInput`] for a note that cannot be kept
/// (an empty name, a name holding `=`, a line break).
pub fn write_valued_ktree_noted<const K: usize, V: Value>(
    out: impl Write,
    tree: &KTree<K, V>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> std::io::Result<()> {
    let Some(dtype) = V::DTYPE else {
        return super::write_ktree(out, &tree.shape());
    };
    let mut writer = ValuedKtreeWriter::new(out, K, tree.level(), dtype, frame, notes)?;
    let mut values = Vec::new();
    for depth in 0..tree.depth_count() {
        let states = tree.level_states(depth);
        writer.append_words(states.words(), states.len() as u64)?;
        writer.end_codes()?;
        values.clear();
        for index in 0..states.len() {
            if states.get(index) == crate::tree::NodeState::Full {
                let value = match tree.value(depth, index) {
                    Ok(v) => v,
                    Err(never) => match never {},
                };
                value.write_le(&mut values);
            }
        }
        writer.append_values(&values)?;
        writer.end_level()?;
    }
    writer.finish().map(drop)
}

/// Writes a valued tree's `.ktree` file with its world frame atomically ([`write_valued_ktree_framed`]).
///
/// # Errors
/// A [`FileOpError`](crate::fs::FileOpError) naming the path, its source the I/O error.
pub fn write_valued_ktree_file_framed<const K: usize, V: Value>(
    path: &Path,
    tree: &KTree<K, V>,
    frame: Option<&WorldFrame>,
) -> Result<(), crate::fs::FileOpError> {
    crate::fs::write_atomic_with(path, |w| write_valued_ktree_framed(w, tree, frame))
}

/// Writes a valued tree's `.ktree` file with its world frame and notes atomically
/// ([`write_valued_ktree_noted`]).
///
/// # Errors
/// A [`FileOpError`](crate::fs::FileOpError) naming the path, its source the I/O error.
pub fn write_valued_ktree_file_noted<const K: usize, V: Value>(
    path: &Path,
    tree: &KTree<K, V>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> Result<(), crate::fs::FileOpError> {
    crate::fs::write_atomic_with(path, |w| write_valued_ktree_noted(w, tree, frame, notes))
}

/// Writes a valued tree's `.ktree` file atomically (a temporary file, then renamed).
///
/// # Errors
/// A [`FileOpError`](crate::fs::FileOpError) naming the path, its source the I/O error.
pub fn write_valued_ktree_file<const K: usize, V: Value>(
    path: &Path,
    tree: &KTree<K, V>,
) -> Result<(), crate::fs::FileOpError> {
    crate::fs::write_atomic_with(path, |w| write_valued_ktree(w, tree))
}

/// The dimension, level and value type of a `.ktree` file's first 16 bytes (`None`: a binary tree, version
/// 1 or 2).
///
/// # Errors
/// [`KtreeFileErrorKind::BadMagic`], a short header, an unknown version or value type.
pub fn valued_header(
    head: &[u8],
    file: &str,
) -> Result<(usize, u32, Option<Dtype>), KtreeFileError> {
    let fail = |offset: u64, kind| KtreeFileError::at_byte(file.to_string(), offset, kind);
    if head.len() < 6 || &head[..6] != MAGIC {
        return Err(fail(0, KtreeFileErrorKind::BadMagic));
    }
    if head.len() < HEADER_BYTES {
        return Err(fail(
            head.len() as u64,
            KtreeFileErrorKind::Length {
                expected: HEADER_BYTES as u64,
                found: head.len() as u64,
            },
        ));
    }
    let version = u16::from_le_bytes([head[6], head[7]]);
    let k = head[8] as usize;
    let level = u32::from(head[9]);
    match version {
        1 | 2 => Ok((k, level, None)),
        VERSION => match Dtype::from_code(head[10]) {
            Some(d) => Ok((k, level, Some(d))),
            None => Err(fail(
                10,
                KtreeFileErrorKind::Header(format!("value type code {} is not 1 to 6", head[10])),
            )),
        },
        other => Err(fail(6, KtreeFileErrorKind::Version(other))),
    }
}

/// Reads a version 3 `.ktree` file's bytes holding a `K`-dimensional tree of values of type `V`. A file of
/// version 1 or 2 is read as a binary tree when `V` is `()`.
///
/// # Errors
/// [`KtreeFileError`] naming the byte offset of the first inconsistency; [`KtreeFileErrorKind::Dtype`] when
/// the file holds another value type, [`KtreeFileErrorKind::Dimension`] another `K`.
pub fn read_valued_ktree<const K: usize, V: Value>(
    bytes: &[u8],
    file: &str,
) -> Result<KTree<K, V>, KtreeFileError> {
    read_valued_ktree_framed(bytes, file).map(|(tree, _)| tree)
}

/// Reads a `.ktree` file's bytes as [`read_valued_ktree`] does, with the world frame the file keeps
/// (`None` when it keeps none; version 1 and 2 files keep none).
///
/// # Errors
/// As [`read_valued_ktree`]; a frame whose voxel size is not a positive number or whose origin is not
/// finite.
pub fn read_valued_ktree_framed<const K: usize, V: Value>(
    bytes: &[u8],
    file: &str,
) -> Result<(KTree<K, V>, Option<WorldFrame>), KtreeFileError> {
    read_valued_ktree_noted(bytes, file).map(|(tree, frame, _)| (tree, frame))
}

/// Reads a `.ktree` file's bytes as [`read_valued_ktree_framed`] does, with the notes the file keeps
/// (none for a file without them, and for version 1 and 2 files). Example: [`super::notes`].
///
/// # Errors
/// As [`read_valued_ktree_framed`]; notes that are not `name=text` lines of UTF-8, naming their byte.
pub fn read_valued_ktree_noted<const K: usize, V: Value>(
    bytes: &[u8],
    file: &str,
) -> Result<(KTree<K, V>, Option<WorldFrame>, Notes), KtreeFileError> {
    match check_valued::<K, V>(bytes, file, true)? {
        Checked::Binary(tree) => Ok((tree, None, Notes::new())),
        Checked::Valued {
            tree, frame, notes, ..
        } => Ok((
            tree.expect("the levels were kept: check_valued built the tree"),
            frame,
            notes,
        )),
    }
}

/// Where a level of a valued file lies, found and checked when the file was read.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ValuedLevel {
    /// The section's first byte.
    pub(crate) offset: usize,
    /// Its nodes, full nodes and nodes with children.
    pub(crate) nodes: u64,
    pub(crate) full: u64,
    pub(crate) children: u64,
    /// Words of codes, and rank samples of each kind.
    pub(crate) words: usize,
    pub(crate) samples: usize,
}

/// What [`check_valued`] found.
pub(crate) enum Checked<const K: usize, V: Value> {
    /// A version 1 or 2 file, read as a binary tree (`V` is `()`).
    Binary(KTree<K, V>),
    /// A version 3 file: its universe, its levels and, when asked for, the tree.
    Valued {
        universe: Universe<K>,
        levels: Vec<ValuedLevel>,
        tree: Option<KTree<K, V>>,
        frame: Option<WorldFrame>,
        notes: Notes,
    },
}

/// Checks a `.ktree` file's bytes holding a `K`-dimensional tree of `V` values — everything but, unless
/// `keep`, the tree's minimality and its mixed nodes' children (checked on the tree built when `keep`).
pub(crate) fn check_valued<const K: usize, V: Value>(
    bytes: &[u8],
    file: &str,
    keep: bool,
) -> Result<Checked<K, V>, KtreeFileError> {
    let fail = |offset: u64, kind| KtreeFileError::at_byte(file.to_string(), offset, kind);
    let (k, level, dtype) = valued_header(&bytes[..bytes.len().min(HEADER_BYTES)], file)?;
    if dtype != V::DTYPE {
        return Err(fail(
            10,
            KtreeFileErrorKind::Dtype {
                expected: V::DTYPE,
                found: dtype,
            },
        ));
    }
    let Some(dtype) = dtype else {
        let tree = super::read_ktree::<K>(bytes, file)?;
        // V is `()` here (the only type without a dtype): the binary tree is the valued tree of no values.
        return Ok(Checked::Binary(KTree::from_valued_levels(
            tree.universe,
            tree.levels,
            Vec::new(),
        )));
    };
    if !(1..=MAX_K).contains(&k) {
        return Err(fail(
            8,
            KtreeFileErrorKind::Header(format!("K = {k} is not 1 to {MAX_K}")),
        ));
    }
    if k != K {
        return Err(fail(
            8,
            KtreeFileErrorKind::Dimension {
                expected: K,
                found: k,
            },
        ));
    }
    if level > max_level(k) {
        return Err(fail(
            9,
            KtreeFileErrorKind::Header(format!("L = {level} exceeds {} for K = {k}", max_level(k))),
        ));
    }
    if bytes[12..HEADER_BYTES].iter().any(|&b| b != 0) {
        return Err(fail(
            12,
            KtreeFileErrorKind::Header("reserved bytes are not 0".into()),
        ));
    }
    let len = bytes.len() as u64;
    let too_short = |minimum: usize| {
        fail(
            len,
            KtreeFileErrorKind::Length {
                expected: minimum as u64,
                found: len,
            },
        )
    };
    if bytes.len() < HEADER_BYTES + ENTRY_BYTES + TAIL_BYTES {
        return Err(too_short(HEADER_BYTES + ENTRY_BYTES + TAIL_BYTES));
    }
    let extras = header_extras(file, bytes[..HEADER_BYTES].to_vec(), len, &mut |at, n| {
        Ok(bytes[at as usize..at as usize + n].to_vec())
    })?;
    let sections_at = extras.bytes.len();
    if bytes.len() < sections_at + ENTRY_BYTES + TAIL_BYTES {
        return Err(too_short(sections_at + ENTRY_BYTES + TAIL_BYTES));
    }
    let minimum = (sections_at + ENTRY_BYTES + TAIL_BYTES) as u64;
    let tail_at = bytes.len() - TAIL_BYTES;
    let recorded = u64_at(bytes, tail_at);
    if recorded != len {
        return Err(fail(
            len.min(recorded),
            KtreeFileErrorKind::Length {
                expected: recorded,
                found: len,
            },
        ));
    }
    let depth = u64::from(u32_at(bytes, tail_at + 8));
    let directory_bytes = depth * ENTRY_BYTES as u64;
    if depth == 0
        || depth > u64::from(level) + 1
        || directory_bytes + minimum - ENTRY_BYTES as u64 > len
    {
        return Err(fail(
            tail_at as u64 + 8,
            KtreeFileErrorKind::Header(format!(
                "{depth} levels recorded for a level-{level} universe in a {len}-byte file"
            )),
        ));
    }
    let directory_at = tail_at - directory_bytes as usize;
    let stored = u32_at(bytes, bytes.len() - 4);
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..sections_at]);
    hasher.update(&bytes[directory_at..bytes.len() - 4]);
    let computed = hasher.finalize();
    if stored != computed {
        return Err(fail(
            len - 4,
            KtreeFileErrorKind::Checksum { stored, computed },
        ));
    }
    let HeaderExtras { frame, notes, .. } = extras;
    let value_bytes = dtype.bytes();
    let mut levels = Vec::with_capacity(if keep { depth as usize } else { 0 });
    let mut values: Vec<Vec<V>> = Vec::with_capacity(if keep { depth as usize } else { 0 });
    let mut found = Vec::with_capacity(depth as usize);
    let mut offset = sections_at as u64;
    let mut above_children: Option<u64> = None;
    for d in 0..depth as usize {
        let entry_at = directory_at + d * ENTRY_BYTES;
        let e = &bytes[entry_at..entry_at + ENTRY_BYTES];
        let (nodes, full, children) = (u64_at(e, 0), u64_at(e, 8), u64_at(e, 16));
        let shape_error =
            |message: String| fail(entry_at as u64, KtreeFileErrorKind::Tree(message));
        if u32_at(e, 28) != 0 {
            return Err(shape_error(format!("reserved field of level {d} is not 0")));
        }
        let expected = match above_children {
            None => Some(1),
            Some(c) => c.checked_mul(1 << K),
        };
        if Some(nodes) != expected {
            return Err(shape_error(format!(
                "level {d} has {nodes} nodes, the level above calls for {expected:?}"
            )));
        }
        if !matches!(full.checked_add(children), Some(n) if n <= nodes) {
            return Err(shape_error(format!(
                "level {d}: more full nodes and nodes with children than nodes"
            )));
        }
        if d + 1 == depth as usize && children > 0 {
            return Err(shape_error(format!(
                "the last level ({d}) has {children} nodes with children below it"
            )));
        }
        let size = match section_bytes(nodes, full, value_bytes as u64) {
            Some(s) if offset + s <= directory_at as u64 => s,
            _ => {
                return Err(fail(
                    offset,
                    KtreeFileErrorKind::Tree(format!(
                        "the section of level {d} ({nodes} nodes, {full} values) runs past the directory at byte {directory_at}"
                    )),
                ))
            }
        };
        // Sizes are within the file from here on: allocating them is bounded by its length.
        let section = &bytes[offset as usize..(offset + size) as usize];
        let stored = u32_at(e, 24);
        let computed = crc32fast::hash(section);
        if stored != computed {
            return Err(fail(
                offset,
                KtreeFileErrorKind::SectionChecksum {
                    level: d,
                    stored,
                    computed,
                },
            ));
        }
        let words_n = words_of(nodes) as usize;
        let words: Vec<u64> = (0..words_n).map(|i| u64_at(section, 8 * i)).collect();
        let samples_n = samples_of(words_n as u64) as usize;
        let (mut c, mut f) = (0u64, 0u64);
        for (i, &w) in words.iter().enumerate() {
            if i % WORDS_PER_SAMPLE == 0 {
                let b = i / WORDS_PER_SAMPLE;
                let at = 8 * (words_n + b);
                if u64_at(section, at) != c || u64_at(section, at + 8 * samples_n) != f {
                    return Err(fail(
                        offset + at as u64,
                        KtreeFileErrorKind::Tree(format!("rank sample {b} of level {d} is wrong")),
                    ));
                }
            }
            c += u64::from(children_mask(w).count_ones());
            f += u64::from(full_mask(w).count_ones());
        }
        if c != children || f != full {
            return Err(fail(
                offset,
                KtreeFileErrorKind::Tree(format!(
                    "level {d} holds {f} full nodes and {c} with children, the directory says {full} and {children}"
                )),
            ));
        }
        found.push(ValuedLevel {
            offset: offset as usize,
            nodes,
            full,
            children,
            words: words_n,
            samples: samples_n,
        });
        let level_states = if keep {
            Some(
                PackedStates::from_valued_words(words, nodes as usize).map_err(|e| {
                    fail(offset, KtreeFileErrorKind::Tree(format!("level {d}: {e}")))
                })?,
            )
        } else {
            None
        };
        let values_at = 8 * (words_n + 2 * samples_n);
        let mut column = Vec::with_capacity(if keep { full as usize } else { 0 });
        for j in 0..full as usize {
            let at = values_at + j * value_bytes;
            let v = V::read_le(&section[at..at + value_bytes]);
            if let Err(e) = v.check() {
                return Err(fail(
                    offset + at as u64,
                    KtreeFileErrorKind::Tree(format!("level {d}: {e}")),
                ));
            }
            if keep {
                column.push(v);
            }
        }
        let end = values_at + full as usize * value_bytes;
        if section[end..].iter().any(|&b| b != 0) {
            return Err(fail(
                offset + end as u64,
                KtreeFileErrorKind::Tree(format!("padding of level {d} is not 0")),
            ));
        }
        levels.extend(level_states);
        values.push(column);
        above_children = Some(children);
        offset += size;
    }
    if offset != directory_at as u64 {
        return Err(fail(
            offset,
            KtreeFileErrorKind::Tree(format!(
                "the sections end at byte {offset} but the directory starts at {directory_at}"
            )),
        ));
    }
    let universe = Universe::<K>::new(level)
        .map_err(|e| fail(9, KtreeFileErrorKind::Header(e.to_string())))?;
    if !keep {
        return Ok(Checked::Valued {
            universe,
            levels: found,
            tree: None,
            frame,
            notes,
        });
    }
    let tree = KTree::from_valued_levels(universe, levels, values);
    tree.check()
        .map_err(|e| fail(HEADER_BYTES as u64, KtreeFileErrorKind::Tree(e.to_string())))?;
    Ok(Checked::Valued {
        universe,
        levels: found,
        tree: Some(tree),
        frame,
        notes,
    })
}

/// Reads a valued `.ktree` file from disk ([`read_valued_ktree`]).
///
/// # Errors
/// As [`read_valued_ktree`]; an unreadable file is [`KtreeFileErrorKind::Io`].
pub fn read_valued_ktree_file<const K: usize, V: Value>(
    path: &Path,
) -> Result<KTree<K, V>, KtreeFileError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path)
        .map_err(|e| KtreeFileError::at_byte(name.clone(), 0, KtreeFileErrorKind::Io(e.into())))?;
    read_valued_ktree(&bytes, &name)
}

/// A `.ktree` file's tree of whatever dimension and value type its header names: a tree without values
/// (versions 1 and 2) or a tree with values (version 3).
#[derive(Debug, Clone, PartialEq)]
pub enum AnyKtree {
    /// A tree without values.
    Binary(AnyTree),
    /// A tree with values.
    Valued(AnyValuedTree),
}

/// Reads a `.ktree` file's bytes of any version, dimension and value type.
///
/// ```
/// use ktree::io::ktree::v3::{read_any_ktree, read_any_ktree_noted, write_any_valued_ktree, AnyKtree};
/// use ktree::io::ktree::Notes;
/// use ktree::{AnyValuedTree, KTree};
/// let tree = AnyValuedTree::from(KTree::<1, i8>::from_dense_values(1, &[Some(-3), None]).unwrap());
/// let notes = Notes::from([("label.-3".to_string(), "wall".to_string())]);
/// let mut bytes = Vec::new();
/// write_any_valued_ktree(&mut bytes, &tree, &notes).unwrap();
/// assert_eq!(read_any_ktree(&bytes, "mem").unwrap(), AnyKtree::Valued(tree.clone()));
/// assert_eq!(read_any_ktree_noted(&bytes, "mem").unwrap(), (AnyKtree::Valued(tree), notes));
/// ```
///
/// # Errors
/// As [`read_valued_ktree`]; a dimension other than 1…4 is [`KtreeFileErrorKind::Dimension`].
pub fn read_any_ktree(bytes: &[u8], file: &str) -> Result<AnyKtree, KtreeFileError> {
    read_any_ktree_noted(bytes, file).map(|(tree, _)| tree)
}

/// [`read_any_ktree`] with the notes the file keeps ([`Notes`]).
///
/// # Errors
/// As [`read_any_ktree`].
pub fn read_any_ktree_noted(bytes: &[u8], file: &str) -> Result<(AnyKtree, Notes), KtreeFileError> {
    read_any_ktree_framed(bytes, file).map(|(tree, _, notes)| (tree, notes))
}

/// [`read_any_ktree`] with where the voxels are in the world, if the file says, and its notes.
///
/// # Errors
/// As [`read_any_ktree`].
pub fn read_any_ktree_framed(
    bytes: &[u8],
    file: &str,
) -> Result<(AnyKtree, Option<WorldFrame>, Notes), KtreeFileError> {
    let binary = |bytes, file| {
        super::read_ktree_framed(bytes, file)
            .map(|(tree, frame, notes)| (AnyKtree::Binary(tree), frame, notes))
    };
    if bytes.get(6..8) != Some(&VERSION.to_le_bytes()[..]) {
        return binary(bytes, file);
    }
    let (k, _, dtype) = valued_header(bytes, file)?;
    let Some(dtype) = dtype else {
        return binary(bytes, file);
    };
    crate::with_valued!(k, dtype, K, V => {
        read_valued_ktree_noted::<K, V>(bytes, file)
            .map(|(t, frame, notes)| (AnyKtree::Valued(AnyValuedTree::from(t)), frame, notes))
    }, else Err(KtreeFileError::at_byte(
        file.to_string(),
        8,
        KtreeFileErrorKind::Header(format!("K = {k} is not 1 to 4")),
    )))
}

/// Writes a tree with values of any dimension and value type as a version 3 `.ktree` file with `notes`
/// and no world frame ([`write_valued_ktree_noted`]).
///
/// # Errors
/// As [`write_valued_ktree_noted`].
pub fn write_any_valued_ktree(
    out: impl Write,
    tree: &AnyValuedTree,
    notes: &Notes,
) -> std::io::Result<()> {
    crate::with_valued!(tree, t => write_valued_ktree_noted(out, t, None, notes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::ktree::v3_writer::FRAME_BYTES;

    fn pattern<const K: usize, V: Value>() -> AnyValuedTree {
        let bytes = V::DTYPE.unwrap().bytes();
        let dense: Vec<Option<V>> = (0..1usize << (2 * K))
            .map(|i| (i % 3 != 0).then(|| V::read_le(&vec![(i % 4) as u8; bytes])))
            .collect();
        AnyValuedTree::from(KTree::<K, V>::from_dense_values(2, &dense).unwrap())
    }

    #[test]
    fn any_tree_of_every_dimension_and_value_type_reads_back() {
        for k in 1..=4 {
            for dtype in Dtype::ALL {
                let tree =
                    crate::with_valued!(k, dtype, K, V => pattern::<K, V>(), else unreachable!());
                let mut bytes = Vec::new();
                write_any_valued_ktree(&mut bytes, &tree, &Notes::new()).unwrap();
                assert_eq!(
                    read_any_ktree(&bytes, "mem").unwrap(),
                    AnyKtree::Valued(tree.clone())
                );
                // A tree without values reads as one.
                let mut binary = Vec::new();
                crate::with_dim!(&tree.shape(), AnyTree, t => super::super::write_ktree(&mut binary, t)).unwrap();
                assert_eq!(
                    read_any_ktree(&binary, "mem").unwrap(),
                    AnyKtree::Binary(tree.shape())
                );
                // A cut file is refused, not misread.
                let cut = &bytes[..bytes.len() - 5];
                assert!(read_any_ktree(cut, "mem").is_err());
            }
        }
    }

    #[test]
    fn a_world_frame_reads_back_and_a_damaged_one_is_refused() {
        let tree =
            KTree::<2, u16>::from_dense_values(1, &[Some(7), None, Some(9), Some(7)]).unwrap();
        let frame = WorldFrame {
            voxel_size: 0.25,
            origin: [-3.5, 1e6, 0.0],
        };
        let mut bytes = Vec::new();
        write_valued_ktree_framed(&mut bytes, &tree, Some(&frame)).unwrap();
        let mut plain = Vec::new();
        write_valued_ktree(&mut plain, &tree).unwrap();
        assert_eq!(bytes.len(), plain.len() + FRAME_BYTES);
        assert_eq!(
            read_valued_ktree_framed::<2, u16>(&bytes, "mem").unwrap(),
            (tree.clone(), Some(frame))
        );
        assert_eq!(read_valued_ktree::<2, u16>(&bytes, "mem").unwrap(), tree);
        assert_eq!(
            read_valued_ktree_framed::<2, u16>(&plain, "mem").unwrap(),
            (tree.clone(), None)
        );
        // A changed frame byte breaks the checksum; an unknown flag is refused by name.
        let mut damaged = bytes.clone();
        damaged[20] ^= 1;
        let e = read_valued_ktree::<2, u16>(&damaged, "mem").unwrap_err();
        assert!(matches!(e.kind, KtreeFileErrorKind::Checksum { .. }), "{e}");
        let mut flagged = bytes.clone();
        flagged[11] = 5;
        let e = read_valued_ktree::<2, u16>(&flagged, "mem")
            .unwrap_err()
            .to_string();
        assert!(e.contains("flags") && e.contains("byte 11"), "{e}");
        // A frame no voxel can have is not written.
        let bad = WorldFrame {
            voxel_size: 0.0,
            ..frame
        };
        assert!(write_valued_ktree_framed(&mut Vec::new(), &tree, Some(&bad)).is_err());
    }

    #[test]
    fn notes_read_back_after_the_frame_and_are_checked() {
        let tree =
            KTree::<2, u16>::from_dense_values(1, &[Some(7), None, Some(9), Some(7)]).unwrap();
        let frame = WorldFrame {
            voxel_size: 0.25,
            origin: [-3.5, 1e6, 0.0],
        };
        let notes = Notes::from([("steps".to_string(), "12".to_string())]);
        for frame in [None, Some(&frame)] {
            let mut bytes = Vec::new();
            write_valued_ktree_noted(&mut bytes, &tree, frame, &notes).unwrap();
            let mut without = Vec::new();
            write_valued_ktree_framed(&mut without, &tree, frame).unwrap();
            // The block: its length (8 bytes), "steps=12\n" (9), padded to 24.
            assert_eq!(bytes.len(), without.len() + 24);
            assert_eq!(
                read_valued_ktree_noted::<2, u16>(&bytes, "mem").unwrap(),
                (tree.clone(), frame.copied(), notes.clone())
            );
            assert_eq!(
                read_valued_ktree_framed::<2, u16>(&bytes, "mem").unwrap(),
                (tree.clone(), frame.copied())
            );
            // Without notes the file is the one written without them.
            let mut empty = Vec::new();
            write_valued_ktree_noted(&mut empty, &tree, frame, &Notes::new()).unwrap();
            assert_eq!(empty, without);
            // A changed note breaks the checksum; a length past the file is refused at the block.
            let at = HEADER_BYTES + if frame.is_some() { FRAME_BYTES } else { 0 };
            let mut damaged = bytes.clone();
            damaged[at + 10] ^= 1;
            let e = read_valued_ktree::<2, u16>(&damaged, "mem").unwrap_err();
            assert!(matches!(e.kind, KtreeFileErrorKind::Checksum { .. }), "{e}");
            let mut long = bytes.clone();
            long[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
            let e = read_valued_ktree::<2, u16>(&long, "mem")
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("notes") && e.contains(&format!("byte {at}")),
                "{e}"
            );
        }
        let bad = Notes::from([("a=b".to_string(), String::new())]);
        assert!(write_valued_ktree_noted(&mut Vec::new(), &tree, None, &bad).is_err());
        // Every byte changed, and every length cut: an answer, never a panic.
        let mut bytes = Vec::new();
        write_valued_ktree_noted(&mut bytes, &tree, Some(&frame), &notes).unwrap();
        for i in 0..bytes.len() {
            for b in [0, 0xff, bytes[i] ^ 0x80, 2] {
                let mut changed = bytes.clone();
                changed[i] = b;
                let _ = read_valued_ktree_noted::<2, u16>(&changed, "mem");
            }
            let _ = read_valued_ktree_noted::<2, u16>(&bytes[..i], "mem");
        }
    }
}
