//! The `.ktree` file, version 1: a tree in level order at Meagher's 2 bits a node, in one checksummed body
//! (version 2, with a section per level, is in [`v2`](super::v2)). It is read everywhere and written only by
//! [`write_ktree_v1`], for tests and tools that need old files.
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 6 | magic `KTREE\0` |
//! | 6 | 2 | format version, `u16` little-endian (= 1) |
//! | 8 | 1 | `K` (1…4) |
//! | 9 | 1 | `L` (0…[`crate::max_level`]`(K)`) |
//! | 10 | 2 | reserved, 0 |
//! | 12 | 4 | `D`, the number of stored levels (`u32` LE) |
//! | 16 | 8·D | nodes per level, `u64` LE each |
//! | 16 + 8·D | 24 | full, empty, partial node totals, `u64` LE each |
//! | 40 + 8·D | ⌈N/4⌉ | node states, 2 bits each (`00` empty, `01` full, `10` partial), level order, node `i` in bits `2·(i mod 4)` of byte `i / 4`; unused bits 0 |
//! | end − 4 | 4 | CRC-32 (IEEE) of everything before, `u32` LE |
//!
//! Reading checks the magic, version, K and L, that the level sizes agree with the partial counts above
//! them and with the file's length *before* allocating, the checksum, the totals, and the tree's invariants
//! (reduced, no partial voxels). Any mismatch is an error naming the file and the byte offset.

use std::io::Write;

use super::KtreeView;
use super::{KtreeFileError, KtreeFileErrorKind, MAGIC};
use crate::space::{max_level, Universe, MAX_K};
use crate::tree::words::{slots_mask, WordPacker, NODES_PER_WORD};
use crate::tree::{AnyTree, KTree, NodeState, PackedStates};

/// The format version of this layout.
pub(super) const VERSION: u16 = 1;

/// Writes a tree as a `.ktree` version 1 file: for tests and tools that need files in the old layout.
/// [`write_ktree`](crate::io::write_ktree) writes the current version.
///
/// ```
/// use ktree::{io, KTree};
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
/// let mut bytes = Vec::new();
/// io::write_ktree_v1(&mut bytes, &tree).unwrap();
/// assert_eq!(io::read_ktree::<2>(&bytes, "mem").unwrap(), tree);
/// bytes[20] ^= 1; // corrupt a byte
/// assert!(io::read_ktree::<2>(&bytes, "mem").is_err());
/// ```
///
/// # Errors
/// Any I/O error.
pub fn write_ktree_v1<const K: usize>(mut w: impl Write, tree: &KTree<K>) -> std::io::Result<()> {
    let mut bytes = Vec::with_capacity(64 + tree.bytes_at_two_bits() as usize);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&VERSION.to_le_bytes());
    bytes.push(K as u8);
    bytes.push(tree.level() as u8);
    bytes.extend_from_slice(&[0, 0]);
    bytes.extend_from_slice(&(tree.depth_count() as u32).to_le_bytes());
    for d in 0..tree.depth_count() {
        bytes.extend_from_slice(&(tree.level_states(d).len() as u64).to_le_bytes());
    }
    let c = tree.counts();
    for v in [c.full, c.empty, c.partial] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    // Node states, continuing across levels.
    let mut acc = 0u8;
    let mut n = 0usize;
    for d in 0..tree.depth_count() {
        let level = tree.level_states(d);
        for i in 0..level.len() {
            acc |= (level.get(i) as u8) << (2 * (n % 4));
            n += 1;
            if n.is_multiple_of(4) {
                bytes.push(acc);
                acc = 0;
            }
        }
    }
    if !n.is_multiple_of(4) {
        bytes.push(acc);
    }
    let crc = crc32fast::hash(&bytes);
    bytes.extend_from_slice(&crc.to_le_bytes());
    w.write_all(&bytes)
}

/// Writes the tree of a version 2 file ([`KtreeView`], memory-mapped) as a version 1 file, streamed: word by
/// word, in memory of a few words whatever the tree's size. The bytes are those [`write_ktree_v1`] writes for
/// the same tree, so a tree built out of core can be written in the old layout.
///
/// ```
/// use ktree::io::{write_ktree, write_ktree_v1, write_ktree_v1_view, KtreeView};
/// use ktree::KTree;
/// let tree = KTree::<2>::from_dense(2, &[true, false, true, true, false, false, true, true,
///                                        true, true, true, true, false, true, false, false]).unwrap();
/// let mut v2 = Vec::new();
/// write_ktree(&mut v2, &tree).unwrap();
/// let view = KtreeView::from_bytes(v2, "mem").unwrap();
/// let (mut streamed, mut whole) = (Vec::new(), Vec::new());
/// write_ktree_v1_view(&mut streamed, &view).unwrap();
/// write_ktree_v1(&mut whole, &tree).unwrap();
/// assert_eq!(streamed, whole);
/// ```
///
/// # Errors
/// Any I/O error; [`std::io::ErrorKind::InvalidData`] (with the file and byte offset) if the mapped file
/// was changed after it was opened.
pub fn write_ktree_v1_view(w: impl Write, view: &KtreeView) -> std::io::Result<()> {
    let mut out = Checksummed {
        w,
        crc: crc32fast::Hasher::new(),
    };
    let mut head = Vec::with_capacity(40 + 8 * view.depth_count());
    head.extend_from_slice(MAGIC);
    head.extend_from_slice(&VERSION.to_le_bytes());
    head.push(view.k() as u8);
    head.push(view.level() as u8);
    head.extend_from_slice(&[0, 0]);
    head.extend_from_slice(&(view.depth_count() as u32).to_le_bytes());
    for d in 0..view.depth_count() {
        head.extend_from_slice(&view.level_nodes(d).to_le_bytes());
    }
    let c = view.counts();
    for v in [c.full, c.empty, c.partial] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    out.write(&head)?;
    // The levels continue one another with no padding: each level's words are shifted into place.
    let mut packer = WordPacker::default();
    for d in 0..view.depth_count() {
        let nodes = view.level_nodes(d);
        for j in 0..nodes.div_ceil(NODES_PER_WORD as u64) {
            let word = view
                .level_word(d, j)
                .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))?;
            let n = (nodes - j * NODES_PER_WORD as u64).min(NODES_PER_WORD as u64) as usize;
            if let Some(whole) = packer.push(word & slots_mask(n), n) {
                out.write(&whole.to_le_bytes())?;
            }
        }
    }
    let pending = packer.pending_nodes();
    if let Some(last) = packer.flush() {
        out.write(&last.to_le_bytes()[..pending.div_ceil(4)])?;
    }
    let crc = out.crc.finalize();
    out.w.write_all(&crc.to_le_bytes())
}

/// A writer that keeps the CRC-32 of what went through it.
struct Checksummed<W> {
    w: W,
    crc: crc32fast::Hasher,
}

impl<W: Write> Checksummed<W> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.crc.update(bytes);
        self.w.write_all(bytes)
    }
}

/// Reads a version 1 file's bytes (called by [`read_ktree_any`](crate::io::read_ktree_any) once the magic
/// and version are read).
pub(super) fn read_v1_any(bytes: &[u8], file: &str) -> Result<AnyTree, KtreeFileError> {
    let fail = |offset: usize, kind| KtreeFileError::at_byte(file.to_string(), offset as u64, kind);
    let truncated = |offset: usize| {
        fail(
            offset,
            KtreeFileErrorKind::Length {
                expected: offset as u64 + 1,
                found: bytes.len() as u64,
            },
        )
    };
    let u64_at = |at: usize| -> Result<u64, KtreeFileError> {
        bytes
            .get(at..at + 8)
            .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
            .ok_or_else(|| truncated(at))
    };
    if bytes.len() < 16 {
        return Err(truncated(bytes.len()));
    }
    let k = bytes[8] as usize;
    if !(1..=MAX_K).contains(&k) {
        return Err(fail(
            8,
            KtreeFileErrorKind::Header(format!("K = {k} is not 1 to {MAX_K}")),
        ));
    }
    let level = u32::from(bytes[9]);
    if level > max_level(k) {
        return Err(fail(
            9,
            KtreeFileErrorKind::Header(format!("L = {level} exceeds {} for K = {k}", max_level(k))),
        ));
    }
    if bytes[10] != 0 || bytes[11] != 0 {
        return Err(fail(
            10,
            KtreeFileErrorKind::Header("reserved bytes are not 0".into()),
        ));
    }
    let depth = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes")) as usize;
    if depth == 0 || depth > level as usize + 1 {
        return Err(fail(
            12,
            KtreeFileErrorKind::Header(format!(
                "{depth} levels stored for a level-{level} universe"
            )),
        ));
    }
    let mut sizes = Vec::with_capacity(depth);
    for d in 0..depth {
        sizes.push(u64_at(16 + 8 * d)?);
    }
    let totals_at = 16 + 8 * depth;
    let totals = [
        u64_at(totals_at)?,
        u64_at(totals_at + 8)?,
        u64_at(totals_at + 16)?,
    ];
    let body_at = totals_at + 24;
    // Check the sizes against the file length before allocating anything proportional to them.
    let nodes = sizes.iter().try_fold(0u64, |a, &s| a.checked_add(s));
    let expected = nodes.and_then(|n| n.div_ceil(4).checked_add(body_at as u64 + 4));
    match expected {
        Some(e) if e == bytes.len() as u64 => {}
        Some(e) => {
            return Err(fail(
                bytes.len().min(e as usize),
                KtreeFileErrorKind::Length {
                    expected: e,
                    found: bytes.len() as u64,
                },
            ))
        }
        None => {
            return Err(fail(
                16,
                KtreeFileErrorKind::Header("node counts overflow".into()),
            ))
        }
    }
    let nodes = nodes.expect("checked above") as usize;
    let crc_at = bytes.len() - 4;
    let stored = u32::from_le_bytes(bytes[crc_at..].try_into().expect("4 bytes"));
    let computed = crc32fast::hash(&bytes[..crc_at]);
    if stored != computed {
        return Err(fail(
            crc_at,
            KtreeFileErrorKind::Checksum { stored, computed },
        ));
    }
    // Decode states level by level.
    let body = &bytes[body_at..crc_at];
    let mut levels = Vec::with_capacity(depth);
    let mut n = 0usize;
    let mut counts = [0u64; 3];
    for (d, &size) in sizes.iter().enumerate() {
        let mut level_states = PackedStates::with_capacity(size as usize);
        for _ in 0..size {
            let code = (body[n / 4] >> (2 * (n % 4))) & 3;
            let Some(state) = NodeState::from_code(code) else {
                return Err(fail(
                    body_at + n / 4,
                    KtreeFileErrorKind::Tree(format!(
                        "node {n} (level {d}) has the unused code 11"
                    )),
                ));
            };
            counts[state as usize] += 1;
            level_states.push(state);
            n += 1;
        }
        level_states.finish();
        levels.push(level_states);
    }
    if !nodes.is_multiple_of(4) && body[nodes / 4] >> (2 * (nodes % 4)) != 0 {
        return Err(fail(
            body_at + nodes / 4,
            KtreeFileErrorKind::Tree("padding bits after the last node are not 0".into()),
        ));
    }
    let [full, empty, partial] = [counts[1], counts[0], counts[2]];
    if [full, empty, partial] != totals {
        return Err(fail(
            totals_at,
            KtreeFileErrorKind::Tree(format!(
                "header totals (full, empty, partial) = {totals:?} but the nodes give {:?}",
                [full, empty, partial]
            )),
        ));
    }
    let tree = match k {
        1 => AnyTree::K1(assemble::<1>(level, levels)),
        2 => AnyTree::K2(assemble::<2>(level, levels)),
        3 => AnyTree::K3(assemble::<3>(level, levels)),
        _ => AnyTree::K4(assemble::<4>(level, levels)),
    };
    let check = crate::with_dim!(&tree, AnyTree, t => t.check());
    check.map_err(|e| fail(body_at, KtreeFileErrorKind::Tree(e.to_string())))?;
    Ok(tree)
}

fn assemble<const K: usize>(level: u32, levels: Vec<PackedStates>) -> KTree<K> {
    KTree::from_levels(Universe::new(level).expect("level checked"), levels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::read_ktree;
    use crate::rays::ball_rays;
    use crate::stacking::paper::stack;

    fn sample() -> Vec<u8> {
        let tree = stack(&ball_rays::<3>(4, [10, 12, 14], 9).unwrap());
        let mut bytes = Vec::new();
        write_ktree_v1(&mut bytes, &tree).unwrap();
        bytes
    }

    #[test]
    fn truncation_padding_and_every_single_bit_flip_are_rejected() {
        let bytes = sample();
        assert!(read_ktree::<3>(&bytes, "s").is_ok());
        for cut in [0, 5, 15, 30, bytes.len() - 1] {
            assert!(
                read_ktree::<3>(&bytes[..cut], "s").is_err(),
                "truncated at {cut}"
            );
        }
        let mut padded = bytes.clone();
        padded.push(0);
        assert!(matches!(
            read_ktree::<3>(&padded, "s").unwrap_err().kind,
            KtreeFileErrorKind::Length { .. }
        ));
        for i in 0..bytes.len() {
            for bit in 0..8 {
                let mut bad = bytes.clone();
                bad[i] ^= 1 << bit;
                assert!(
                    read_ktree::<3>(&bad, "s").is_err(),
                    "flip of bit {bit} of byte {i} accepted"
                );
            }
        }
    }

    #[test]
    fn wrong_dimension_and_huge_sizes_are_clear_errors() {
        let bytes = sample();
        let e = read_ktree::<2>(&bytes, "s").unwrap_err();
        assert_eq!(
            e.kind,
            KtreeFileErrorKind::Dimension {
                expected: 2,
                found: 3
            }
        );
        // A header claiming 2^60 nodes is rejected by length before any allocation.
        let mut huge = bytes.clone();
        huge[16 + 8..16 + 16].copy_from_slice(&(1u64 << 60).to_le_bytes());
        assert!(matches!(
            read_ktree::<3>(&huge, "s").unwrap_err().kind,
            KtreeFileErrorKind::Length { .. }
        ));
    }
}
