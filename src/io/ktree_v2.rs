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
//! | 10 | 6 | reserved, 0 |
//! | 16 | 8·(W₀ + R₀) | section 0 (the root level) |
//! | … | 8·(W_d + R_d) | section `d`, right after section `d − 1` |
//! | S | 32·D | directory: per level `d`, nodes `n_d`, full nodes, partial nodes (`u64` each), CRC-32 of section `d` (`u32`), reserved `u32` = 0 |
//! | S + 32·D | 8 | the file's length in bytes (`u64`) |
//! | S + 32·D + 8 | 4 | `D`, the number of levels (`u32`) |
//! | S + 32·D + 12 | 4 | CRC-32 of the header (bytes 0…15) and of everything from S up to here |
//!
//! Section `d` holds `W_d = ⌈n_d / 32⌉` words of node states — node `i` of the level in bits `2·(i mod 32)`
//! of word `i / 32`, `00` empty, `01` full, `10` partial, unused bits 0 (the in-memory layout of
//! [`PackedStates`]) — followed by `R_d = ⌈W_d / 64⌉` rank samples: sample `b` is the number of partial
//! nodes in words `0 … 64·b − 1`. With them the first child of a node (`2^K` × the partial nodes before
//! it) is found from the map by at most 64 word pop-counts, without an index in memory. The section's CRC
//! covers its words and samples.
//!
//! The directory is at the end so that the file can be written in one pass, level after level, by a
//! builder that never holds the whole tree ([`KtreeWriter`]). A reader finds it from the last 16 bytes.
//!
//! # Checks
//! Opening a file ([`KtreeView::open`], [`read_ktree_any`](super::read_ktree_any)) checks, before
//! allocating or mapping anything proportional to the sizes it reads: the magic, version, K, L and reserved
//! bytes; that the length recorded at the end is the file's length (a truncated or padded file fails here,
//! with the offset); the directory's checksum; that the sections exactly fill the space between header and
//! directory; and the tree's shape (one root, `n_{d+1} = 2^K · partial_d`, no partial node at the last
//! level). Then every section is scanned in bounded windows: its checksum (a mismatch names the level and
//! the section's byte offset), the unused code `11`, zero padding, the rank samples, the full and partial
//! counts of the directory, and that the tree is reduced (no `2^K` siblings all full or all empty).

use std::fs::File;
use std::io::Write;
use std::path::Path;

use super::any::AnyTree;
use super::ktree_file::{KtreeFileError, KtreeFileErrorKind, MAGIC};
use super::mmap::FileMap;
use crate::space::{max_level, Cell, Universe, MAX_K};
use crate::tree::{KTree, LevelCounts, NodeState, PackedStates};

/// The format version of this layout.
pub const VERSION: u16 = 2;

const HEADER_BYTES: usize = 16;
const ENTRY_BYTES: usize = 32;
const TAIL_BYTES: usize = 16;
/// Nodes in a word.
pub(crate) const NODES_PER_WORD: u64 = 32;
/// Words between two rank samples.
const WORDS_PER_SAMPLE: u64 = 64;
/// Bytes scanned at a time when a file's sections are checked through the map.
const WINDOW_BYTES: usize = 1 << 20;
pub(crate) const LOW_BITS: u64 = 0x5555_5555_5555_5555;

#[inline]
fn partial_mask(word: u64) -> u64 {
    (word >> 1) & !word & LOW_BITS
}

#[inline]
fn full_mask(word: u64) -> u64 {
    word & !(word >> 1) & LOW_BITS
}

/// The mask of the low `nodes` 2-bit slots of a word (`nodes ≤ 32`).
#[inline]
pub(crate) fn slots_mask(nodes: u64) -> u64 {
    if nodes >= NODES_PER_WORD {
        u64::MAX
    } else {
        (1u64 << (2 * nodes)) - 1
    }
}

fn words_of(nodes: u64) -> u64 {
    nodes.div_ceil(NODES_PER_WORD)
}

fn samples_of(words: u64) -> u64 {
    words.div_ceil(WORDS_PER_SAMPLE)
}

fn invalid(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, message)
}

fn header_bytes(k: usize, level: u32) -> [u8; HEADER_BYTES] {
    let mut h = [0u8; HEADER_BYTES];
    h[..6].copy_from_slice(MAGIC);
    h[6..8].copy_from_slice(&VERSION.to_le_bytes());
    h[8] = k as u8;
    h[9] = level as u8;
    h
}

/// One level's directory entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Section {
    /// Byte offset of the section's first word.
    offset: u64,
    nodes: u64,
    full: u64,
    partial: u64,
    crc: u32,
}

impl Section {
    fn words(&self) -> u64 {
        words_of(self.nodes)
    }

    fn samples_offset(&self) -> u64 {
        self.offset + 8 * self.words()
    }

    fn bytes(&self) -> u64 {
        8 * (self.words() + samples_of(self.words()))
    }
}

/// Writes a `.ktree` version 2 file level by level, from the root down, without holding the tree.
///
/// A level is given as one or more *pieces*, each a run of consecutive nodes packed two bits a node in
/// `u64` words exactly as in [`PackedStates::words`] (node `j` of the piece in bits `2·(j mod 32)` of word
/// `j / 32`; bits beyond the piece's node count are ignored). A piece may end in the middle of a word: the
/// next piece is shifted to continue right after it, so the subtrees of consecutive cells, built apart, can
/// be appended one after the other at every level. [`KtreeWriter::end_level`] closes a level (the next
/// append starts the next one); [`KtreeWriter::finish`] writes the directory. Memory held: one partial word
/// and one rank sample per 2048 nodes of the current level.
///
/// The writer checks the tree's shape as it goes (a root level of one node, each level `2^K` times the
/// partial nodes of the level above, no code `11`, no partial node at the last level) and returns
/// [`std::io::ErrorKind::InvalidInput`] when it is broken; whether the tree is reduced is checked when the
/// file is read.
///
/// ```
/// use ktree::{io, KTree, NodeState};
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
/// let mut bytes = Vec::new();
/// let mut w = io::KtreeWriter::new(&mut bytes, 2, 1).unwrap();
/// w.push(NodeState::Partial).unwrap();
/// w.end_level().unwrap();
/// // The four children in two pieces: [full, empty] then [empty, full] (one word each).
/// w.append_words(&[0b0001], 2).unwrap();
/// w.append_words(&[0b0100], 2).unwrap();
/// w.finish().unwrap();
/// assert_eq!(io::read_ktree::<2>(&bytes, "mem").unwrap(), tree);
/// ```
#[derive(Debug)]
pub struct KtreeWriter<W: Write> {
    out: W,
    k: usize,
    level: u32,
    /// Bytes written so far.
    written: u64,
    finished: Vec<Section>,
    current: LevelWriter,
    buffer: Vec<u8>,
}

/// Nodes appended two bits each at any position, handed out as whole words: the shifted append of
/// [`KtreeWriter`] and of the streamed Booleans' output levels.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct WordPacker {
    /// Nodes not yet forming a whole word, in the low bits.
    pending: u64,
    pending_nodes: u64,
}

impl WordPacker {
    /// Appends the `take ≤ 32` nodes of `word` (low bits first); returns the word they complete, if any.
    #[inline]
    pub(crate) fn push(&mut self, word: u64, take: u64) -> Option<u64> {
        let word = word & slots_mask(take);
        let p = self.pending_nodes;
        let joined = self.pending | word.checked_shl(2 * p as u32).unwrap_or(0);
        if p + take >= NODES_PER_WORD {
            // `p > 0` here unless the word is whole, so the shift below is less than 64.
            self.pending = if p == 0 {
                0
            } else {
                word >> (2 * (NODES_PER_WORD - p))
            };
            self.pending_nodes = p + take - NODES_PER_WORD;
            Some(joined)
        } else {
            self.pending = joined;
            self.pending_nodes = p + take;
            None
        }
    }

    /// The last, partly filled word (`None` if the nodes so far fill whole words), leaving the packer empty.
    pub(crate) fn flush(&mut self) -> Option<u64> {
        let last = (self.pending_nodes > 0).then_some(self.pending);
        *self = Self::default();
        last
    }
}

/// The level being written.
#[derive(Debug, Default)]
struct LevelWriter {
    nodes: u64,
    full: u64,
    partial: u64,
    packer: WordPacker,
    words: u64,
    samples: Vec<u64>,
    hasher: crc32fast::Hasher,
}

impl<W: Write> KtreeWriter<W> {
    /// Starts a file for a `K = k` tree in a level-`level` universe, writing the header.
    ///
    /// # Errors
    /// `InvalidInput` for `k` or `level` out of range; any I/O error.
    pub fn new(mut out: W, k: usize, level: u32) -> std::io::Result<Self> {
        if !(1..=MAX_K).contains(&k) || level > max_level(k) {
            return Err(invalid(format!(
                "K = {k}, L = {level} is not a valid universe"
            )));
        }
        out.write_all(&header_bytes(k, level))?;
        Ok(Self {
            out,
            k,
            level,
            written: HEADER_BYTES as u64,
            finished: Vec::new(),
            current: LevelWriter::default(),
            buffer: Vec::with_capacity(1 << 16),
        })
    }

    /// Appends one node to the current level.
    ///
    /// # Errors
    /// Any I/O error.
    pub fn push(&mut self, state: NodeState) -> std::io::Result<()> {
        self.append_words(&[state as u64], 1)
    }

    /// Appends a whole [`PackedStates`] (for instance a level of a tree, or of a subtree) to the current
    /// level.
    ///
    /// # Errors
    /// Any I/O error.
    pub fn append_states(&mut self, states: &PackedStates) -> std::io::Result<()> {
        self.append_words(states.words(), states.len() as u64)
    }

    /// Appends `nodes` nodes packed in `words` (the first node in the low bits of `words[0]`) to the current
    /// level, shifted to follow the nodes already appended.
    ///
    /// # Errors
    /// `InvalidInput` if `words` holds fewer than `nodes` nodes or a node has the unused code `11`; any I/O
    /// error.
    pub fn append_words(&mut self, words: &[u64], nodes: u64) -> std::io::Result<()> {
        let needed = words_of(nodes);
        if (words.len() as u64) < needed {
            return Err(invalid(format!(
                "{} words cannot hold {nodes} nodes",
                words.len()
            )));
        }
        let mut remaining = nodes;
        for &word in &words[..needed as usize] {
            let take = remaining.min(NODES_PER_WORD);
            let word = word & slots_mask(take);
            if (word >> 1) & word & LOW_BITS != 0 {
                return Err(invalid(format!(
                    "a node of level {} has the unused code 11",
                    self.finished.len()
                )));
            }
            if let Some(whole) = self.current.packer.push(word, take) {
                self.emit(whole)?;
            }
            remaining -= take;
        }
        self.current.nodes += nodes;
        Ok(())
    }

    /// Writes one complete word of the current level.
    fn emit(&mut self, word: u64) -> std::io::Result<()> {
        let level = &mut self.current;
        if level.words % WORDS_PER_SAMPLE == 0 {
            level.samples.push(level.partial);
        }
        level.words += 1;
        level.full += u64::from(full_mask(word).count_ones());
        level.partial += u64::from(partial_mask(word).count_ones());
        self.buffer.extend_from_slice(&word.to_le_bytes());
        if self.buffer.len() >= 1 << 16 {
            self.flush_buffer()?;
        }
        Ok(())
    }

    fn flush_buffer(&mut self) -> std::io::Result<()> {
        self.current.hasher.update(&self.buffer);
        self.out.write_all(&self.buffer)?;
        self.written += self.buffer.len() as u64;
        self.buffer.clear();
        Ok(())
    }

    /// Closes the current level: the next append starts the level below.
    ///
    /// # Errors
    /// `InvalidInput` if the level is empty, the root level is not one node, the level's size is not `2^K`
    /// times the partial nodes of the level above, or the tree would be deeper than the universe; any I/O
    /// error.
    pub fn end_level(&mut self) -> std::io::Result<()> {
        let depth = self.finished.len();
        let nodes = self.current.nodes;
        let expected = match self.finished.last() {
            None => 1,
            Some(above) => above.partial << self.k,
        };
        if nodes != expected || depth > self.level as usize {
            return Err(invalid(format!(
                "level {depth} has {nodes} nodes, but the levels above call for {expected} (universe level {})",
                self.level
            )));
        }
        if let Some(word) = self.current.packer.flush() {
            self.emit(word)?;
        }
        let samples = std::mem::take(&mut self.current.samples);
        for s in samples {
            self.buffer.extend_from_slice(&s.to_le_bytes());
        }
        self.flush_buffer()?;
        let level = std::mem::take(&mut self.current);
        let section_bytes = 8 * (level.words + samples_of(level.words));
        self.finished.push(Section {
            offset: self.written - section_bytes,
            nodes,
            full: level.full,
            partial: level.partial,
            crc: level.hasher.finalize(),
        });
        Ok(())
    }

    /// The node counts of the levels closed so far (`level` = depth), as the file's directory will hold them.
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.finished
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

    /// Closes the last level if nodes were appended to it, writes the directory, and returns the output.
    ///
    /// # Errors
    /// `InvalidInput` if no level was written or the last level has partial nodes; any I/O error.
    pub fn finish(mut self) -> std::io::Result<W> {
        if self.current.nodes > 0 {
            self.end_level()?;
        }
        match self.finished.last() {
            None => return Err(invalid("no level was written".into())),
            Some(last) if last.partial > 0 => {
                return Err(invalid(format!(
                    "the last level ({}) has {} partial nodes without children",
                    self.finished.len() - 1,
                    last.partial
                )))
            }
            Some(_) => {}
        }
        let depth = self.finished.len();
        let mut tail = Vec::with_capacity(depth * ENTRY_BYTES + TAIL_BYTES);
        for s in &self.finished {
            for v in [s.nodes, s.full, s.partial] {
                tail.extend_from_slice(&v.to_le_bytes());
            }
            tail.extend_from_slice(&s.crc.to_le_bytes());
            tail.extend_from_slice(&0u32.to_le_bytes());
        }
        let len = self.written + tail.len() as u64 + TAIL_BYTES as u64;
        tail.extend_from_slice(&len.to_le_bytes());
        tail.extend_from_slice(&(depth as u32).to_le_bytes());
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&header_bytes(self.k, self.level));
        hasher.update(&tail);
        tail.extend_from_slice(&hasher.finalize().to_le_bytes());
        self.out.write_all(&tail)?;
        self.out.flush()?;
        Ok(self.out)
    }
}

/// Writes a tree as a `.ktree` version 2 file.
///
/// ```
/// use ktree::{io, KTree};
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
/// let mut bytes = Vec::new();
/// io::write_ktree_v2(&mut bytes, &tree).unwrap();
/// assert_eq!(io::read_ktree::<2>(&bytes, "mem").unwrap(), tree);
/// ```
///
/// # Errors
/// Any I/O error.
pub fn write_ktree_v2<const K: usize>(out: impl Write, tree: &KTree<K>) -> std::io::Result<()> {
    let mut w = KtreeWriter::new(out, K, tree.level())?;
    for d in 0..tree.depth_count() {
        w.append_states(tree.level_states(d))?;
        w.end_level()?;
    }
    w.finish().map(drop)
}

/// Writes a `.ktree` version 2 file atomically (temporary file, then rename).
///
/// # Errors
/// Any I/O error, naming the path.
pub fn write_ktree_v2_file<const K: usize>(path: &Path, tree: &KTree<K>) -> std::io::Result<()> {
    super::write_atomic_with(path, |w| write_ktree_v2(w, tree))
}

/// The shape of a version 2 file: its header and directory, checked.
#[derive(Debug, Clone)]
struct Layout {
    k: usize,
    level: u32,
    sections: Vec<Section>,
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
}

impl Layout {
    /// Reads and checks the header and directory. `head` is the file's first 16 bytes, `len` its length,
    /// and `tail(n)` returns its last `n` bytes (`n ≤ len`).
    fn parse(
        file: &str,
        head: &[u8],
        len: u64,
        mut tail: impl FnMut(usize) -> Result<Vec<u8>, KtreeFileError>,
    ) -> Result<Self, KtreeFileError> {
        let fail = |offset: u64, kind| KtreeFileError {
            file: file.to_string(),
            offset,
            kind,
        };
        let header_error =
            |offset: u64, message: String| fail(offset, KtreeFileErrorKind::Header(message));
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
        if head[10..16].iter().any(|&b| b != 0) {
            return Err(header_error(10, "reserved bytes are not 0".into()));
        }
        let end = tail(TAIL_BYTES)?;
        let tail_at = len - TAIL_BYTES as u64;
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
        let directory = tail(directory_bytes as usize + TAIL_BYTES)?;
        let stored = u32_at(&directory, directory.len() - 4);
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&head[..HEADER_BYTES]);
        hasher.update(&directory[..directory.len() - 4]);
        let computed = hasher.finalize();
        if stored != computed {
            return Err(fail(
                len - 4,
                KtreeFileErrorKind::Checksum { stored, computed },
            ));
        }
        let mut sections = Vec::with_capacity(depth as usize);
        let mut offset = HEADER_BYTES as u64;
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
        Ok(Self { k, level, sections })
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.sections
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

    /// Checks every section; `window(offset, len, f)` calls `f` with the file's bytes `offset … offset +
    /// len` (`len ≤ WINDOW_BYTES`, a multiple of 8).
    fn check_sections(
        &self,
        file: &str,
        mut window: impl FnMut(
            u64,
            usize,
            &mut dyn FnMut(&[u8]) -> Result<(), KtreeFileError>,
        ) -> Result<(), KtreeFileError>,
    ) -> Result<(), KtreeFileError> {
        for (depth, section) in self.sections.iter().enumerate() {
            let samples_len = (section.bytes() - 8 * section.words()) as usize;
            let mut samples = Vec::with_capacity(samples_len / 8);
            let mut copy_samples = |bytes: &[u8]| {
                samples.extend(
                    bytes
                        .chunks_exact(8)
                        .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes"))),
                );
                Ok(())
            };
            // The samples are ⌈W/64⌉ words: at most 1/64 of the section, read in windows too.
            let mut at = 0;
            while at < samples_len {
                let n = (samples_len - at).min(WINDOW_BYTES);
                window(section.samples_offset() + at as u64, n, &mut copy_samples)?;
                at += n;
            }
            let mut scan = SectionScan::new(file, self.k, depth, *section, samples);
            let words_len = 8 * section.words();
            let mut at = 0u64;
            while at < words_len {
                let n = (words_len - at).min(WINDOW_BYTES as u64) as usize;
                window(section.offset + at, n, &mut |bytes| scan.words(bytes))?;
                at += n as u64;
            }
            scan.finish()?;
        }
        Ok(())
    }
}

/// The running check of one section's words.
struct SectionScan<'a> {
    file: &'a str,
    k: usize,
    depth: usize,
    section: Section,
    samples: Vec<u64>,
    hasher: crc32fast::Hasher,
    word: u64,
    full: u64,
    partial: u64,
}

impl<'a> SectionScan<'a> {
    fn new(file: &'a str, k: usize, depth: usize, section: Section, samples: Vec<u64>) -> Self {
        Self {
            file,
            k,
            depth,
            section,
            samples,
            hasher: crc32fast::Hasher::new(),
            word: 0,
            full: 0,
            partial: 0,
        }
    }

    fn fail(&self, offset: u64, message: String) -> KtreeFileError {
        KtreeFileError {
            file: self.file.to_string(),
            offset,
            kind: KtreeFileErrorKind::Tree(message),
        }
    }

    /// Scans the next words of the section (a multiple of 8 bytes).
    fn words(&mut self, bytes: &[u8]) -> Result<(), KtreeFileError> {
        self.hasher.update(bytes);
        let group_bits = 2u32 << self.k;
        let group_mask = if group_bits == 64 {
            u64::MAX
        } else {
            (1u64 << group_bits) - 1
        };
        let nodes = self.section.nodes;
        for chunk in bytes.chunks_exact(8) {
            let word = u64::from_le_bytes(chunk.try_into().expect("8 bytes"));
            let at = self.section.offset + 8 * self.word;
            let first = self.word * NODES_PER_WORD;
            let here = (nodes - first).min(NODES_PER_WORD);
            if self.word % WORDS_PER_SAMPLE == 0 {
                let sample = self.samples[(self.word / WORDS_PER_SAMPLE) as usize];
                if sample != self.partial {
                    return Err(self.fail(
                        self.section.samples_offset() + self.word / WORDS_PER_SAMPLE * 8,
                        format!(
                            "rank sample of level {} is {sample}, the nodes give {}",
                            self.depth, self.partial
                        ),
                    ));
                }
            }
            if (word >> 1) & word & LOW_BITS != 0 {
                return Err(self.fail(
                    at,
                    format!("a node of level {} has the unused code 11", self.depth),
                ));
            }
            if word & !slots_mask(here) != 0 {
                return Err(self.fail(
                    at,
                    format!(
                        "padding bits after the last node of level {} are not 0",
                        self.depth
                    ),
                ));
            }
            if self.depth > 0 {
                // Levels below the root hold whole groups of 2^K siblings, aligned in the word.
                let full_group = LOW_BITS & group_mask;
                for g in 0..(here >> self.k) as u32 {
                    let group = word >> (g * group_bits) & group_mask;
                    if group == 0 || group == full_group {
                        let node = first + u64::from(g << self.k);
                        return Err(self.fail(
                            at,
                            format!(
                                "not reduced: the {} siblings from node {node} of level {} are all {}",
                                1u32 << self.k,
                                self.depth,
                                if group == 0 { "empty" } else { "full" }
                            ),
                        ));
                    }
                }
            }
            self.full += u64::from(full_mask(word).count_ones());
            self.partial += u64::from(partial_mask(word).count_ones());
            self.word += 1;
        }
        Ok(())
    }

    fn finish(mut self) -> Result<(), KtreeFileError> {
        for s in &self.samples {
            self.hasher.update(&s.to_le_bytes());
        }
        let computed = std::mem::take(&mut self.hasher).finalize();
        if computed != self.section.crc {
            return Err(KtreeFileError {
                file: self.file.to_string(),
                offset: self.section.offset,
                kind: KtreeFileErrorKind::SectionChecksum {
                    level: self.depth,
                    stored: self.section.crc,
                    computed,
                },
            });
        }
        if (self.full, self.partial) != (self.section.full, self.section.partial) {
            return Err(self.fail(
                self.section.offset,
                format!(
                    "level {}: the directory records {} full and {} partial nodes, the section holds {} and {}",
                    self.depth, self.section.full, self.section.partial, self.full, self.partial
                ),
            ));
        }
        Ok(())
    }
}

fn layout_of_bytes(bytes: &[u8], file: &str) -> Result<Layout, KtreeFileError> {
    let len = bytes.len() as u64;
    Layout::parse(file, &bytes[..bytes.len().min(HEADER_BYTES)], len, |n| {
        Ok(bytes[bytes.len() - n..].to_vec())
    })
}

fn check_bytes(layout: &Layout, bytes: &[u8], file: &str) -> Result<(), KtreeFileError> {
    layout.check_sections(file, |offset, len, f| {
        f(&bytes[offset as usize..offset as usize + len])
    })
}

/// Reads a version 2 file's bytes into a tree in memory (called by [`read_ktree_any`](super::read_ktree_any)).
pub(super) fn read_v2_any(bytes: &[u8], file: &str) -> Result<AnyTree, KtreeFileError> {
    let layout = layout_of_bytes(bytes, file)?;
    check_bytes(&layout, bytes, file)?;
    let levels: Vec<PackedStates> = layout
        .sections
        .iter()
        .map(|s| {
            let start = s.offset as usize;
            let words = bytes[start..start + 8 * s.words() as usize]
                .chunks_exact(8)
                .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect();
            PackedStates::from_words(words, s.nodes as usize).expect("sections checked above")
        })
        .collect();
    fn assemble<const K: usize>(level: u32, levels: Vec<PackedStates>) -> KTree<K> {
        KTree::from_levels(Universe::new(level).expect("level checked"), levels)
    }
    let tree = match layout.k {
        1 => AnyTree::K1(assemble::<1>(layout.level, levels)),
        2 => AnyTree::K2(assemble::<2>(layout.level, levels)),
        3 => AnyTree::K3(assemble::<3>(layout.level, levels)),
        _ => AnyTree::K4(assemble::<4>(layout.level, levels)),
    };
    let check = crate::with_dim!(&tree, AnyTree, t => t.check());
    check.map_err(|e| KtreeFileError {
        file: file.to_string(),
        offset: HEADER_BYTES as u64,
        kind: KtreeFileErrorKind::Tree(e.to_string()),
    })?;
    Ok(tree)
}

/// Where a view's bytes are.
#[derive(Debug)]
enum Backing {
    /// A file, mapped whole.
    Map(FileMap),
    /// Bytes in memory.
    Bytes(Vec<u8>),
}

/// A read-only view of a `.ktree` version 2 file through a memory map: statistics, point queries and leaf
/// iteration without loading the levels into memory.
///
/// Opening checks the whole file (the checks listed with the layout in the README) by scanning it through
/// windows of 1 MiB that are unmapped after use, holding besides only one level's rank samples (1/256 of
/// the level); queries then read only the pages they touch.
///
/// ```
/// use ktree::{io, KTree};
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// io::write_ktree_v2_file(&path, &tree).unwrap();
/// let view = io::KtreeView::open(&path).unwrap();
/// assert_eq!(view.counts(), tree.counts());
/// assert!(view.contains([0u32, 0]).unwrap() && !view.contains([1u32, 0]).unwrap());
/// ```
#[derive(Debug)]
pub struct KtreeView {
    name: String,
    backing: Backing,
    layout: Layout,
}

impl KtreeView {
    /// Opens and checks a version 2 file.
    ///
    /// # Errors
    /// [`KtreeFileError`] naming the file and byte offset of the first problem
    /// ([`KtreeFileErrorKind::Version`] for a version 1 file: read those with
    /// [`read_ktree_file`](super::read_ktree_file)).
    pub fn open(path: &Path) -> Result<Self, KtreeFileError> {
        let name = path.display().to_string();
        let io_error = |offset: u64, e: std::io::Error| KtreeFileError {
            file: name.clone(),
            offset,
            kind: KtreeFileErrorKind::Io(e.to_string()),
        };
        let file = File::open(path).map_err(|e| io_error(0, e))?;
        let len = file.metadata().map_err(|e| io_error(0, e))?.len();
        let len_usize = usize::try_from(len).map_err(|_| {
            io_error(
                0,
                std::io::Error::other("the file is larger than the address space"),
            )
        })?;
        let head =
            read_at(&file, 0, (len as usize).min(HEADER_BYTES)).map_err(|e| io_error(0, e))?;
        let layout = Layout::parse(&name, &head, len, |n| {
            read_at(&file, len - n as u64, n).map_err(|e| io_error(len - n as u64, e))
        })?;
        layout.check_sections(&name, |offset, n, f| {
            let window = FileMap::map(&file, offset, n).map_err(|e| io_error(offset, e))?;
            f(window.bytes())
        })?;
        let map = FileMap::map(&file, 0, len_usize).map_err(|e| io_error(0, e))?;
        Ok(Self {
            name,
            backing: Backing::Map(map),
            layout,
        })
    }

    /// A view of a version 2 file's bytes held in memory (`name` is used in errors).
    ///
    /// # Errors
    /// As [`KtreeView::open`].
    pub fn from_bytes(bytes: Vec<u8>, name: &str) -> Result<Self, KtreeFileError> {
        let layout = layout_of_bytes(&bytes, name)?;
        check_bytes(&layout, &bytes, name)?;
        Ok(Self {
            name: name.to_string(),
            backing: Backing::Bytes(bytes),
            layout,
        })
    }

    fn bytes(&self) -> &[u8] {
        match &self.backing {
            Backing::Map(map) => map.bytes(),
            Backing::Bytes(b) => b,
        }
    }

    /// Whether the view reads through a memory map (rather than bytes in memory).
    pub fn is_mapped(&self) -> bool {
        matches!(self.backing, Backing::Map(_))
    }

    /// The dimension `K`.
    pub fn k(&self) -> usize {
        self.layout.k
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        self.layout.level
    }

    /// The number of stored levels.
    pub fn depth_count(&self) -> usize {
        self.layout.sections.len()
    }

    /// Node counts per level, from the root down (read from the checked directory).
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.layout.counts_per_level()
    }

    /// Total node counts (`level` holds the universe level), as [`KTree::counts`].
    pub fn counts(&self) -> LevelCounts {
        LevelCounts::total(self.level(), &self.counts_per_level())
    }

    /// The total number of nodes.
    pub fn node_count(&self) -> u64 {
        self.layout.sections.iter().map(|s| s.nodes).sum()
    }

    /// Bytes needed at Meagher's 2 bits a node.
    pub fn bytes_at_two_bits(&self) -> u64 {
        self.node_count().div_ceil(4)
    }

    fn word(&self, section: &Section, j: u64) -> u64 {
        u64_at(self.bytes(), (section.offset + 8 * j) as usize)
    }

    /// The state of node `index` at `depth`, or `None` if there is no such node.
    pub fn state(&self, depth: usize, index: u64) -> Option<NodeState> {
        let s = self.layout.sections.get(depth)?;
        if index >= s.nodes {
            return None;
        }
        let code = self.word(s, index / NODES_PER_WORD) >> (2 * (index % NODES_PER_WORD)) & 3;
        NodeState::from_code(code as u8)
    }

    /// Word `j` of the node states of level `depth` (`j` below the level's word count).
    pub(crate) fn level_word(&self, depth: usize, j: u64) -> u64 {
        self.word(&self.layout.sections[depth], j)
    }

    /// The number of nodes of level `depth` (0 below the last level).
    pub(crate) fn level_nodes(&self, depth: usize) -> u64 {
        self.layout.sections.get(depth).map_or(0, |s| s.nodes)
    }

    /// The name given when the view was opened (the file's path).
    pub(crate) fn name(&self) -> &str {
        &self.name
    }

    /// The error for a node that is not what the checks at opening found: the file was changed since.
    pub(crate) fn changed(&self, depth: usize, index: u64) -> KtreeFileError {
        let section = &self.layout.sections[depth.min(self.layout.sections.len() - 1)];
        KtreeFileError {
            file: self.name.clone(),
            offset: section.offset + 8 * (index / NODES_PER_WORD),
            kind: KtreeFileErrorKind::Tree(format!(
                "node {index} of level {depth} is missing or has the code 11: the file was changed after it was opened"
            )),
        }
    }

    /// The state of a node the tree's shape says exists, or the error of a file changed since opening.
    pub(crate) fn checked_state(
        &self,
        depth: usize,
        index: u64,
    ) -> Result<NodeState, KtreeFileError> {
        self.state(depth, index)
            .ok_or_else(|| self.changed(depth, index))
    }

    /// The number of partial nodes before node `index` of level `depth` (`index` < the level's size).
    pub(crate) fn partial_rank(&self, depth: usize, index: u64) -> u64 {
        let s = &self.layout.sections[depth];
        let word = index / NODES_PER_WORD;
        let block = word / WORDS_PER_SAMPLE;
        let mut rank = u64_at(self.bytes(), (s.samples_offset() + 8 * block) as usize);
        for j in block * WORDS_PER_SAMPLE..word {
            rank = rank.saturating_add(u64::from(partial_mask(self.word(s, j)).count_ones()));
        }
        let slot = index % NODES_PER_WORD;
        rank.saturating_add(u64::from(
            (partial_mask(self.word(s, word)) & slots_mask(slot)).count_ones(),
        ))
    }

    /// The universe, if the file's `K` is `K`.
    pub(crate) fn universe<const K: usize>(&self) -> Result<Universe<K>, KtreeFileError> {
        self.dimension::<K>()
    }

    fn dimension<const K: usize>(&self) -> Result<Universe<K>, KtreeFileError> {
        if K != self.k() {
            return Err(KtreeFileError {
                file: self.name.clone(),
                offset: 8,
                kind: KtreeFileErrorKind::Dimension {
                    expected: K,
                    found: self.k(),
                },
            });
        }
        Ok(Universe::new(self.level()).expect("level checked when opened"))
    }

    /// Whether the voxel `point` is inside the object (`O(L)` node reads, each rank at most 64 word
    /// pop-counts). Points outside the universe are outside the object.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn contains<const K: usize>(&self, point: [u32; K]) -> Result<bool, KtreeFileError> {
        let universe = self.dimension::<K>()?;
        if universe.check_point(point).is_err() {
            return Ok(false);
        }
        let mut index = 0u64;
        for depth in 0..self.depth_count() {
            match self.checked_state(depth, index)? {
                NodeState::Empty => return Ok(false),
                NodeState::Full => return Ok(true),
                NodeState::Partial if depth + 1 >= self.depth_count() => {
                    return Err(self.changed(depth, index))
                }
                NodeState::Partial => {
                    let bit = self.level() - 1 - depth as u32;
                    let code = point
                        .iter()
                        .enumerate()
                        .fold(0u64, |c, (axis, &x)| c | u64::from(x >> bit & 1) << axis);
                    // Saturating: a rank sample changed underneath must not overflow (the node is then
                    // missing, an error).
                    index = self
                        .partial_rank(depth, index)
                        .saturating_mul(1 << K)
                        .saturating_add(code);
                }
            }
        }
        Ok(false)
    }

    /// Visits every leaf (empty and full) in Morton (depth-first) order, as [`KTree::for_each_leaf`].
    /// Needs no rank: in depth-first order the partial nodes of each level are met in level order, so the
    /// children of the next one are the next `2^K` nodes of the level below.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn for_each_leaf<const K: usize>(
        &self,
        mut visit: impl FnMut(Cell<K>, NodeState),
    ) -> Result<(), KtreeFileError> {
        let universe = self.dimension::<K>()?;
        let mut next_child = vec![0u64; self.depth_count() + 1];
        let mut stack = vec![(universe.root(), 0u64)];
        while let Some((cell, index)) = stack.pop() {
            let depth = cell.level as usize;
            match self.checked_state(depth, index)? {
                NodeState::Partial if depth + 1 >= self.depth_count() => {
                    return Err(self.changed(depth, index))
                }
                NodeState::Partial => {
                    let first = next_child[depth + 1];
                    next_child[depth + 1] += 1 << K;
                    for code in (0..1usize << K).rev() {
                        stack.push((cell.child(code), first + code as u64));
                    }
                }
                state => visit(cell, state),
            }
        }
        Ok(())
    }

    /// Visits the full leaves in Morton order: the object's linear tree.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn for_each_full_cell<const K: usize>(
        &self,
        mut visit: impl FnMut(Cell<K>),
    ) -> Result<(), KtreeFileError> {
        self.for_each_leaf::<K>(|cell, state| {
            if state == NodeState::Full {
                visit(cell)
            }
        })
    }

    /// Loads the tree into memory.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn to_tree<const K: usize>(&self) -> Result<KTree<K>, KtreeFileError> {
        let universe = self.dimension::<K>()?;
        let levels = self
            .layout
            .sections
            .iter()
            .enumerate()
            .map(|(depth, s)| {
                let words = (0..s.words()).map(|j| self.word(s, j)).collect();
                PackedStates::from_words(words, s.nodes as usize)
                    .map_err(|_| self.changed(depth, 0))
            })
            .collect::<Result<_, _>>()?;
        let tree = KTree::from_levels(universe, levels);
        tree.check().map_err(|e| KtreeFileError {
            file: self.name.clone(),
            offset: HEADER_BYTES as u64,
            kind: KtreeFileErrorKind::Tree(e.to_string()),
        })?;
        Ok(tree)
    }
}

/// Reads `n` bytes of `file` at `offset`.
fn read_at(file: &File, offset: u64, n: usize) -> std::io::Result<Vec<u8>> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = file;
    f.seek(SeekFrom::Start(offset))?;
    let mut buf = vec![0u8; n];
    f.read_exact(&mut buf)?;
    Ok(buf)
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
            read_at(&f, 0, len)
        })
        .map_err(|e| KtreeFileError {
            file: name.clone(),
            offset: 0,
            kind: KtreeFileErrorKind::Io(e.to_string()),
        })?;
    if head.len() < 8 || &head[..6] != MAGIC {
        return Err(KtreeFileError {
            file: name,
            offset: 0,
            kind: KtreeFileErrorKind::BadMagic,
        });
    }
    Ok(u16::from_le_bytes([head[6], head[7]]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ball_rays;
    use crate::stacking::stack;

    fn sample() -> (KTree<3>, Vec<u8>) {
        let tree = stack(&ball_rays::<3>(4, [10, 12, 14], 9).unwrap());
        let mut bytes = Vec::new();
        write_ktree_v2(&mut bytes, &tree).unwrap();
        (tree, bytes)
    }

    #[test]
    fn round_trip_view_and_pieces_agree() {
        let (tree, bytes) = sample();
        assert_eq!(bytes.len() % 8, 0);
        let back = read_v2_any(&bytes, "s").unwrap().into_dim::<3>().unwrap();
        assert_eq!(back, tree);
        let view = KtreeView::from_bytes(bytes.clone(), "s").unwrap();
        assert_eq!(view.counts_per_level(), tree.counts_per_level());
        assert_eq!(view.to_tree::<3>().unwrap(), tree);
        for x in (0..16).step_by(3) {
            for y in 0..16 {
                for z in (0..16).step_by(2) {
                    assert_eq!(view.contains([x, y, z]).unwrap(), tree.contains([x, y, z]));
                }
            }
        }
        let mut leaves = Vec::new();
        view.for_each_leaf::<3>(|c, s| leaves.push((c, s))).unwrap();
        assert_eq!(leaves, tree.leaves().collect::<Vec<_>>());
        // Each level in odd-sized pieces: the shifted appends give the same bytes.
        let mut pieces = Vec::new();
        let mut w = KtreeWriter::new(&mut pieces, 3, tree.level()).unwrap();
        for d in 0..tree.depth_count() {
            let level = tree.level_states(d);
            let mut i = 0;
            let mut size = 1;
            while i < level.len() {
                let n = size.min(level.len() - i);
                let mut piece = PackedStates::new();
                (i..i + n).for_each(|j| piece.push(level.get(j)));
                piece.finish();
                w.append_states(&piece).unwrap();
                i += n;
                size = size % 45 + 7;
            }
            w.end_level().unwrap();
        }
        w.finish().unwrap();
        assert_eq!(pieces, bytes);
    }

    #[test]
    fn bad_section_checksum_names_level_and_offset() {
        let (tree, mut bytes) = sample();
        let view = KtreeView::from_bytes(bytes.clone(), "s").unwrap();
        let last = view.depth_count() - 1;
        let offset = view.layout.sections[last].offset;
        // Swap two different 2-bit codes inside the last section: counts stay equal, the CRC does not.
        let at = offset as usize;
        let word = u64_at(&bytes, at);
        let swapped = (0..32)
            .flat_map(|i| (0..32).map(move |j| (i, j)))
            .find_map(|(i, j)| {
                let (a, b) = (word >> (2 * i) & 3, word >> (2 * j) & 3);
                (a != b).then(|| word ^ (a ^ b) << (2 * i) ^ (a ^ b) << (2 * j))
            })
            .unwrap();
        bytes[at..at + 8].copy_from_slice(&swapped.to_le_bytes());
        let e = read_v2_any(&bytes, "s").unwrap_err();
        assert_eq!(e.offset, offset);
        assert!(
            matches!(e.kind, KtreeFileErrorKind::SectionChecksum { level, .. } if level == last),
            "{e}"
        );
        assert!(e.to_string().contains(&format!("level {last}")), "{e}");
        let _ = tree;
    }

    #[test]
    fn a_file_changed_underneath_a_view_gives_errors_not_panics() {
        use std::io::{Seek, SeekFrom, Write as _};
        let (tree, bytes) = sample();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.ktree");
        std::fs::write(&path, &bytes).unwrap();
        let view = KtreeView::open(&path).unwrap();
        assert!(view.is_mapped());
        assert_eq!(view.to_tree::<3>().unwrap(), tree);
        // Overwrite every section in place with code 11: the map shows the new bytes.
        let directory_at = view
            .layout
            .sections
            .last()
            .map(|s| s.offset + s.bytes())
            .unwrap();
        let mut f = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
        f.seek(SeekFrom::Start(HEADER_BYTES as u64)).unwrap();
        f.write_all(&vec![0xFF; directory_at as usize - HEADER_BYTES])
            .unwrap();
        f.sync_all().unwrap();
        assert!(view.contains([10u32, 12, 14]).is_err());
        assert!(view.for_each_leaf::<3>(|_, _| {}).is_err());
        assert!(view.to_tree::<3>().is_err());
        assert!(KtreeView::open(&path).is_err(), "reopening checks again");
    }

    #[test]
    fn writer_rejects_a_broken_shape() {
        let mut w = KtreeWriter::new(Vec::new(), 2, 2).unwrap();
        w.push(NodeState::Partial).unwrap();
        w.end_level().unwrap();
        w.append_words(&[0b10], 3).unwrap();
        assert!(w.end_level().is_err(), "3 children of one partial node");
        let mut w = KtreeWriter::new(Vec::new(), 2, 2).unwrap();
        w.push(NodeState::Partial).unwrap();
        assert!(w.finish().is_err(), "a partial leaf");
        assert!(KtreeWriter::new(Vec::new(), 2, 2)
            .unwrap()
            .append_words(&[0b11], 1)
            .is_err());
    }
}
