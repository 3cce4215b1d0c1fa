//! The `.ktree` file, version 2: one word-aligned, checksummed section per tree level, written as a stream
//! and read by memory-mapping.
//!
//! All integers are little-endian; every section starts at a multiple of 8 bytes.
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 6 | magic `KTREE\0` |
//! | 6 | 2 | format version, `u16` (= 2) |
//! | 8 | 1 | `K` (1…4) |
//! | 9 | 1 | `L` (0…[`crate::max_level`]`(K)`) |
//! | 10 | 1 | reserved, 0 (version 3's value type) |
//! | 11 | 1 | flags: bit 0 set when a world frame follows the header, bit 1 when notes follow it; the other bits 0 |
//! | 12 | 4 | reserved, 0 |
//! | 16 | 32 | only with flag bit 0: the world frame ([`WorldFrame`]): the voxel size, then the origin's x, y and z (`f64` each) |
//! | 16 or 48 | 8 + N, padded to 8 | only with flag bit 1: the notes ([`Notes`]): their length `N` (`u64`), then `N` bytes of `name=text` lines |
//! | H (16 without either) | 8·(W₀ + R₀) | section 0 (the root level) |
//! | … | 8·(W_d + R_d) | section `d`, right after section `d − 1` |
//! | S | 32·D | directory: per level `d`, nodes `n_d`, full nodes, partial nodes (`u64` each), CRC-32 of section `d` (`u32`), reserved `u32` = 0 |
//! | S + 32·D | 8 | the file's length in bytes (`u64`) |
//! | S + 32·D + 8 | 4 | `D`, the number of levels (`u32`) |
//! | S + 32·D + 12 | 4 | CRC-32 of the header (bytes 0…H − 1: with the frame and the notes) and of everything from S up to here |
//!
//! Section `d` holds `W_d = ⌈n_d / 32⌉` words of node states — node `i` of the level in bits `2·(i mod 32)`
//! of word `i / 32`, `00` empty, `01` full, `10` partial, unused bits 0 (the in-memory layout of
//! [`PackedStates`]) — followed by `R_d = ⌈W_d / 64⌉` rank samples: sample `b` is the number of partial
//! nodes in words `0 … 64·b − 1`. With them the first child of a node (`2^K` × the partial nodes before
//! it) is found from the map by at most 64 word pop-counts, without an index in memory. The section's CRC
//! covers its words and samples.
//!
//! A file without frame or notes (flags 0) is byte for byte what the format wrote before they existed;
//! a reader older than them refuses a file with either (its byte 11 is not 0).
//!
//! The directory is at the end so that the file can be written in one pass, level after level, by a
//! builder that never holds the whole tree ([`KtreeWriter`]). A reader finds it from the last 16 bytes.
//!
//! # Checks
//! Opening a file ([`KtreeView::open`], [`read_ktree_any`](crate::io::read_ktree_any)) checks, before
//! allocating or mapping anything proportional to the sizes it reads: the magic, version, K, L and reserved
//! bytes; that the length recorded at the end is the file's length (a truncated or padded file fails here,
//! with the offset); the directory's checksum; that the sections exactly fill the space between header and
//! directory; and the tree's shape (one root, `n_{d+1} = 2^K · partial_d`, no partial node at the last
//! level). Then every section is scanned in bounded windows: its checksum (a mismatch names the level and
//! the section's byte offset), the unused code `11`, zero padding, the rank samples, the full and partial
//! counts of the directory, and that the tree is reduced (no `2^K` siblings all full or all empty).

use super::super::notes::{self, Notes};
use super::super::v3_writer::{check_frame, FRAME_BYTES};
use super::super::{KtreeFileError, KtreeFileErrorKind, MAGIC};
use crate::space::{max_level, WorldFrame, MAX_K};
use crate::tree::LevelCounts;

/// The format version of this layout.
pub const VERSION: u16 = 2;

pub(crate) const HEADER_BYTES: usize = 16;
pub(crate) const ENTRY_BYTES: usize = 32;
pub(crate) const TAIL_BYTES: usize = 16;
/// Nodes in a word.
pub(crate) const NODES_PER_WORD: u64 = 32;
/// Words between two rank samples.
pub(crate) const WORDS_PER_SAMPLE: u64 = 64;
/// Bytes scanned at a time when a file's sections are checked through the map.
pub(crate) const WINDOW_BYTES: usize = 1 << 20;
pub(crate) use crate::tree::words::{full_mask, partial_mask, LOW_BITS};

/// The mask of the low `nodes` 2-bit slots of a word, for node counts of a file.
#[inline]
pub(crate) fn slots_mask(nodes: u64) -> u64 {
    crate::tree::words::slots_mask(nodes.min(NODES_PER_WORD) as usize)
}

pub(crate) fn words_of(nodes: u64) -> u64 {
    nodes.div_ceil(NODES_PER_WORD)
}

pub(crate) fn samples_of(words: u64) -> u64 {
    words.div_ceil(WORDS_PER_SAMPLE)
}

pub(crate) fn invalid(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, message)
}

pub(crate) fn header_bytes(k: usize, level: u32) -> [u8; HEADER_BYTES] {
    let mut h = [0u8; HEADER_BYTES];
    h[..6].copy_from_slice(MAGIC);
    h[6..8].copy_from_slice(&VERSION.to_le_bytes());
    h[8] = k as u8;
    h[9] = level as u8;
    h
}

/// The header of a file with where its voxels are in the world (`frame`) and `notes`: the 16 bytes of
/// [`header_bytes`] with the flags set, then the frame and the notes' block, if any — the same in
/// versions 2 and 3.
///
/// # Errors
/// `InvalidInput` for a frame whose voxel size is not a positive number or whose origin is not finite,
/// or a note that cannot be kept.
pub(crate) fn header_block(
    mut header: [u8; HEADER_BYTES],
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> std::io::Result<Vec<u8>> {
    if let Some(f) = frame {
        check_frame(f).map_err(invalid)?;
    }
    let notes_block = notes::encode(notes).map_err(invalid)?;
    header[11] = u8::from(frame.is_some()) | u8::from(!notes_block.is_empty()) << 1;
    let mut block = Vec::with_capacity(HEADER_BYTES + FRAME_BYTES + notes_block.len());
    block.extend_from_slice(&header);
    if let Some(f) = frame {
        for x in [f.voxel_size, f.origin[0], f.origin[1], f.origin[2]] {
            block.extend_from_slice(&x.to_le_bytes());
        }
    }
    block.extend_from_slice(&notes_block);
    Ok(block)
}

/// One level's directory entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Section {
    /// Byte offset of the section's first word.
    pub(crate) offset: u64,
    pub(crate) nodes: u64,
    pub(crate) full: u64,
    pub(crate) partial: u64,
    pub(crate) crc: u32,
}

impl Section {
    pub(crate) fn words(&self) -> u64 {
        words_of(self.nodes)
    }

    pub(crate) fn samples_offset(&self) -> u64 {
        self.offset + 8 * self.words()
    }

    pub(crate) fn bytes(&self) -> u64 {
        8 * (self.words() + samples_of(self.words()))
    }
}

/// The end of a file whose level sections (`sections`, `partial` counting the nodes with children) end at
/// byte `written`: the directory, the file's length, the number of levels and the CRC of `header` and of
/// all of it — the same in versions 2 and 3.
///
/// # Errors
/// `InvalidInput` if there is no level or the last one has nodes with children.
pub(crate) fn directory_tail(
    sections: &[Section],
    written: u64,
    header: &[u8],
) -> std::io::Result<Vec<u8>> {
    match sections.last() {
        None => return Err(invalid("no level was written".into())),
        Some(last) if last.partial > 0 => {
            return Err(invalid(format!(
                "the last level ({}) has {} nodes with children, but no level below",
                sections.len() - 1,
                last.partial
            )))
        }
        Some(_) => {}
    }
    let mut tail = Vec::with_capacity(sections.len() * ENTRY_BYTES + TAIL_BYTES);
    for s in sections {
        for v in [s.nodes, s.full, s.partial] {
            tail.extend_from_slice(&v.to_le_bytes());
        }
        tail.extend_from_slice(&s.crc.to_le_bytes());
        tail.extend_from_slice(&0u32.to_le_bytes());
    }
    let len = written + tail.len() as u64 + TAIL_BYTES as u64;
    tail.extend_from_slice(&len.to_le_bytes());
    tail.extend_from_slice(&(sections.len() as u32).to_le_bytes());
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(header);
    hasher.update(&tail);
    tail.extend_from_slice(&hasher.finalize().to_le_bytes());
    Ok(tail)
}

/// The shape of a version 2 file: its header and directory, checked.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    pub(crate) k: usize,
    pub(crate) level: u32,
    pub(crate) sections: Vec<Section>,
    /// Where the voxels are in the world, if the file says.
    pub(crate) frame: Option<WorldFrame>,
    pub(crate) notes: Notes,
}

pub(crate) fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
}

pub(crate) fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
}

/// What follows a version 2 or 3 header when its flags (byte 11) say so.
pub(crate) struct HeaderExtras {
    pub(crate) frame: Option<WorldFrame>,
    pub(crate) notes: Notes,
    /// The header's 16 bytes, then the frame's and the notes' block, as in the file: what its checksum
    /// covers before the directory. The level sections start right after them.
    pub(crate) bytes: Vec<u8>,
}

/// Reads and checks the world frame and the notes that follow `head` (a header's 16 bytes) in a file of
/// `len` bytes (at least a header, a directory entry and the tail), as the header's flags say, each
/// measured before it is read; `read(offset, n)` returns the file's `n` bytes from `offset`.
pub(crate) fn header_extras(
    file: &str,
    head: Vec<u8>,
    len: u64,
    read: &mut impl FnMut(u64, usize) -> Result<Vec<u8>, KtreeFileError>,
) -> Result<HeaderExtras, KtreeFileError> {
    let fail = |offset: u64, kind| KtreeFileError::at_byte(file.to_string(), offset, kind);
    let header_error =
        |offset: u64, message: String| fail(offset, KtreeFileErrorKind::Header(message));
    let flags = head[11];
    if flags > 3 {
        return Err(header_error(
            11,
            format!("flags {flags:#04x}: only bits 0 and 1 are known"),
        ));
    }
    // Room for at least one directory entry and the tail after what follows the header.
    let after = (ENTRY_BYTES + TAIL_BYTES) as u64;
    let mut bytes = head;
    let mut frame = None;
    if flags & 1 == 1 {
        let minimum = (HEADER_BYTES + FRAME_BYTES) as u64 + after;
        if len < minimum {
            return Err(fail(
                len,
                KtreeFileErrorKind::Length {
                    expected: minimum,
                    found: len,
                },
            ));
        }
        let block = read(HEADER_BYTES as u64, FRAME_BYTES)?;
        let at = |i: usize| f64::from_bits(u64_at(&block, 8 * i));
        let f = WorldFrame {
            voxel_size: at(0),
            origin: [at(1), at(2), at(3)],
        };
        check_frame(&f).map_err(|e| header_error(HEADER_BYTES as u64, e))?;
        frame = Some(f);
        bytes.extend_from_slice(&block);
    }
    let mut notes = Notes::new();
    if flags & 2 == 2 {
        let notes_at = bytes.len() as u64;
        let room = (len - notes_at).saturating_sub(after) as usize;
        let runs_past = || header_error(notes_at, "the notes' length runs past the file".into());
        if room < 8 {
            return Err(runs_past());
        }
        let length = read(notes_at, 8)?;
        let size = notes::block_bytes(&length, room).ok_or_else(runs_past)?;
        let block = read(notes_at, size)?;
        notes =
            notes::decode(&block).map_err(|(at, why)| header_error(notes_at + at as u64, why))?;
        bytes.extend_from_slice(&block);
    }
    Ok(HeaderExtras {
        frame,
        notes,
        bytes,
    })
}

impl Layout {
    /// Reads and checks the header (with the frame and the notes) and the directory. `len` is the
    /// file's length and `read(offset, n)` returns its `n` bytes from `offset` (`offset + n ≤ len`).
    pub(crate) fn parse(
        file: &str,
        len: u64,
        mut read: impl FnMut(u64, usize) -> Result<Vec<u8>, KtreeFileError>,
    ) -> Result<Self, KtreeFileError> {
        let fail = |offset: u64, kind| KtreeFileError::at_byte(file.to_string(), offset, kind);
        let header_error =
            |offset: u64, message: String| fail(offset, KtreeFileErrorKind::Header(message));
        let head = read(0, len.min(HEADER_BYTES as u64) as usize)?;
        if head.len() < 6 || &head[..6] != MAGIC {
            return Err(fail(0, KtreeFileErrorKind::BadMagic));
        }
        let minimum = (HEADER_BYTES + ENTRY_BYTES + TAIL_BYTES) as u64;
        if len < minimum || head.len() < HEADER_BYTES {
            return Err(fail(
                len,
                KtreeFileErrorKind::Length {
                    expected: minimum,
                    found: len,
                },
            ));
        }
        let version = u16::from_le_bytes([head[6], head[7]]);
        if version != VERSION {
            return Err(fail(6, KtreeFileErrorKind::Version(version)));
        }
        let k = head[8] as usize;
        if !(1..=MAX_K).contains(&k) {
            return Err(header_error(8, format!("K = {k} is not 1 to {MAX_K}")));
        }
        let level = u32::from(head[9]);
        if level > max_level(k) {
            return Err(header_error(
                9,
                format!("L = {level} exceeds {} for K = {k}", max_level(k)),
            ));
        }
        if head[10] != 0 || head[12..HEADER_BYTES].iter().any(|&b| b != 0) {
            return Err(header_error(10, "reserved bytes are not 0".into()));
        }
        let extras = header_extras(file, head, len, &mut read)?;
        let sections_at = extras.bytes.len() as u64;
        let minimum = sections_at + (ENTRY_BYTES + TAIL_BYTES) as u64;
        let tail_at = len - TAIL_BYTES as u64;
        let end = read(tail_at, TAIL_BYTES)?;
        let recorded = u64_at(&end, 0);
        if recorded != len {
            return Err(fail(
                len.min(recorded),
                KtreeFileErrorKind::Length {
                    expected: recorded,
                    found: len,
                },
            ));
        }
        let depth = u32_at(&end, 8) as u64;
        let directory_bytes = depth * ENTRY_BYTES as u64;
        if depth == 0
            || depth > u64::from(level) + 1
            || directory_bytes + minimum - ENTRY_BYTES as u64 > len
        {
            return Err(header_error(
                tail_at + 8,
                format!(
                    "{depth} levels recorded for a level-{level} universe in a {len}-byte file"
                ),
            ));
        }
        let directory_at = tail_at - directory_bytes;
        let directory = read(directory_at, directory_bytes as usize + TAIL_BYTES)?;
        let stored = u32_at(&directory, directory.len() - 4);
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&extras.bytes);
        hasher.update(&directory[..directory.len() - 4]);
        let computed = hasher.finalize();
        if stored != computed {
            return Err(fail(
                len - 4,
                KtreeFileErrorKind::Checksum { stored, computed },
            ));
        }
        let mut sections = Vec::with_capacity(depth as usize);
        let mut offset = sections_at;
        for d in 0..depth as usize {
            let e = &directory[d * ENTRY_BYTES..(d + 1) * ENTRY_BYTES];
            let entry_at = directory_at + (d * ENTRY_BYTES) as u64;
            let section = Section {
                offset,
                nodes: u64_at(e, 0),
                full: u64_at(e, 8),
                partial: u64_at(e, 16),
                crc: u32_at(e, 24),
            };
            let shape_error = |message: String| fail(entry_at, KtreeFileErrorKind::Tree(message));
            if u32_at(e, 28) != 0 {
                return Err(shape_error(format!("reserved field of level {d} is not 0")));
            }
            let expected = match sections.last() {
                None => Some(1),
                Some(above) => {
                    let above: &Section = above;
                    above.partial.checked_mul(1 << k)
                }
            };
            if Some(section.nodes) != expected {
                return Err(shape_error(format!(
                    "level {d} has {} nodes, the level above calls for {expected:?}",
                    section.nodes
                )));
            }
            if !matches!(section.full.checked_add(section.partial), Some(n) if n <= section.nodes) {
                return Err(shape_error(format!(
                    "level {d}: more full and partial nodes than nodes"
                )));
            }
            if d + 1 == depth as usize && section.partial > 0 {
                return Err(shape_error(format!(
                    "the last level ({d}) has {} partial nodes without children",
                    section.partial
                )));
            }
            // Nodes are below 2^64 / 2^K·…: the section's byte size cannot overflow past the file's length
            // check below because every level is at most 2^K times the one above and the file is finite.
            offset = match offset.checked_add(section.bytes()) {
                Some(o) if o <= directory_at => o,
                _ => {
                    return Err(fail(
                        directory_at,
                        KtreeFileErrorKind::Length {
                            expected: directory_at,
                            found: len,
                        },
                    ))
                }
            };
            sections.push(section);
        }
        if offset != directory_at {
            return Err(fail(
                offset,
                KtreeFileErrorKind::Tree(format!(
                    "the sections end at byte {offset} but the directory starts at {directory_at}"
                )),
            ));
        }
        Ok(Self {
            k,
            level,
            sections,
            frame: extras.frame,
            notes: extras.notes,
        })
    }

    pub(crate) fn counts_per_level(&self) -> Vec<LevelCounts> {
        counts_of(&self.sections)
    }
}

pub(crate) fn layout_of_bytes(bytes: &[u8], file: &str) -> Result<Layout, KtreeFileError> {
    let len = bytes.len() as u64;
    Layout::parse(file, len, |offset, n| {
        Ok(bytes[offset as usize..offset as usize + n].to_vec())
    })
}

/// The node counts of directory entries, one per level from the root (`level` = depth).
pub(crate) fn counts_of(sections: &[Section]) -> Vec<LevelCounts> {
    sections
        .iter()
        .enumerate()
        .map(|(d, s)| LevelCounts {
            level: d as u32,
            full: s.full,
            empty: s.nodes - s.full - s.partial,
            partial: s.partial,
        })
        .collect()
}
