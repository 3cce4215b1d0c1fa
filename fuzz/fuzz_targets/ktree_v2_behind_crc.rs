//! `.ktree` version 2 behind its checksums: a valid file of an arbitrary tree (K = 1…4, any level), taken
//! apart into header, sections and directory, edited — bytes and words of a section, words dropped or
//! inserted, directory counts, header bytes, levels dropped, duplicated or swapped, the recorded length and
//! level count — and put together again with every section checksum and the directory checksum
//! recomputed, so the edits reach the structural checks. Then a cut or appended tail. Read from bytes, as a
//! view of bytes and as a memory-mapped view: the untouched file is the tree; an edited one is rejected by
//! both views alike (same offset, same kind), or is exactly the file of the tree it reads as.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_ktree_any, KtreeView};
use ktree::{AnyTree};
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
enum Edit {
    /// Flips bits of a byte of a section (its node words or rank samples).
    Xor { level: u8, at: u16, mask: u8 },
    /// Overwrites a word of a section.
    Word { level: u8, at: u16, value: u64 },
    /// Removes a word of a section.
    DropWord { level: u8, at: u16 },
    /// Inserts a word into a section.
    InsertWord { level: u8, at: u16, value: u64 },
    /// Sets a directory field of a level: 0 nodes, 1 full, 2 partial, 3 the reserved `u32`.
    Entry { level: u8, field: u8, value: u64 },
    /// Sets a header byte from 6 on (version, K, L, reserved).
    Header { at: u8, value: u8 },
    /// Removes a level (section and directory entry).
    DropLevel(u8),
    /// Repeats a level right after itself.
    DuplicateLevel(u8),
    /// Exchanges two levels.
    SwapLevels(u8, u8),
    /// A section checksum left as recorded before the edits.
    StaleChecksum(u8),
    /// The recorded file length instead of the true one.
    Length(u64),
    /// The recorded level count instead of the true one.
    Depth(u32),
}

#[derive(Debug, Arbitrary)]
struct Input {
    k: u8,
    level: u8,
    shape: Vec<u8>,
    edits: Vec<Edit>,
    /// Bytes cut from the end of the assembled file (after the checksums are computed).
    cut: u8,
    /// Bytes appended to the assembled file.
    tail: Vec<u8>,
}

/// One level of the file: its section's bytes and its directory entry.
#[derive(Debug, Clone)]
struct Level {
    section: Vec<u8>,
    counts: [u64; 3],
    reserved: u32,
    stale_crc: Option<u32>,
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
}

/// Header, levels and directory of a valid version 2 file.
fn take_apart(bytes: &[u8]) -> ([u8; 16], Vec<Level>) {
    let header: [u8; 16] = bytes[..16].try_into().expect("16 bytes");
    let depth = u32::from_le_bytes(
        bytes[bytes.len() - 8..bytes.len() - 4]
            .try_into()
            .expect("4"),
    );
    let directory = bytes.len() - 16 - 32 * depth as usize;
    let mut at = 16;
    let levels = (0..depth as usize)
        .map(|d| {
            let e = directory + 32 * d;
            let counts = [
                u64_at(bytes, e),
                u64_at(bytes, e + 8),
                u64_at(bytes, e + 16),
            ];
            let words = counts[0].div_ceil(32) as usize;
            let len = 8 * (words + words.div_ceil(64));
            let section = bytes[at..at + len].to_vec();
            at += len;
            Level {
                section,
                counts,
                reserved: 0,
                stale_crc: None,
            }
        })
        .collect();
    assert_eq!(
        at, directory,
        "the sections fill the space before the directory"
    );
    (header, levels)
}

/// The file again, checksums recomputed (except stale ones), with the recorded length and level count
/// given or the true ones.
fn put_together(
    header: &[u8; 16],
    levels: &[Level],
    length: Option<u64>,
    depth: Option<u32>,
) -> Vec<u8> {
    let mut bytes = header.to_vec();
    for l in levels {
        bytes.extend_from_slice(&l.section);
    }
    let directory_at = bytes.len();
    for l in levels {
        for c in l.counts {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
        let crc = l.stale_crc.unwrap_or_else(|| crc32fast::hash(&l.section));
        bytes.extend_from_slice(&crc.to_le_bytes());
        bytes.extend_from_slice(&l.reserved.to_le_bytes());
    }
    let len = bytes.len() as u64 + 16;
    bytes.extend_from_slice(&length.unwrap_or(len).to_le_bytes());
    bytes.extend_from_slice(&depth.unwrap_or(levels.len() as u32).to_le_bytes());
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..16]);
    hasher.update(&bytes[directory_at..]);
    bytes.extend_from_slice(&hasher.finalize().to_le_bytes());
    bytes
}

fn edit(header: &mut [u8; 16], levels: &mut Vec<Level>, e: &Edit) -> (Option<u64>, Option<u32>) {
    let pick =
        |levels: &[Level], l: u8| (!levels.is_empty()).then(|| usize::from(l) % levels.len());
    match *e {
        Edit::Xor { level, at, mask } => {
            if let Some(s) = pick(levels, level).map(|l| &mut levels[l].section) {
                if !s.is_empty() {
                    let at = usize::from(at) % s.len();
                    s[at] ^= mask;
                }
            }
        }
        Edit::Word { level, at, value } => {
            if let Some(s) = pick(levels, level).map(|l| &mut levels[l].section) {
                if !s.is_empty() {
                    let at = 8 * (usize::from(at) % (s.len() / 8));
                    s[at..at + 8].copy_from_slice(&value.to_le_bytes());
                }
            }
        }
        Edit::DropWord { level, at } => {
            if let Some(s) = pick(levels, level).map(|l| &mut levels[l].section) {
                if !s.is_empty() {
                    let at = 8 * (usize::from(at) % (s.len() / 8));
                    s.drain(at..at + 8);
                }
            }
        }
        Edit::InsertWord { level, at, value } => {
            if let Some(s) = pick(levels, level).map(|l| &mut levels[l].section) {
                let at = 8 * (usize::from(at) % (s.len() / 8 + 1));
                s.splice(at..at, value.to_le_bytes());
            }
        }
        Edit::Entry {
            level,
            field,
            value,
        } => {
            if let Some(l) = pick(levels, level).map(|l| &mut levels[l]) {
                match field % 4 {
                    3 => l.reserved = value as u32,
                    f => l.counts[usize::from(f)] = value,
                }
            }
        }
        Edit::Header { at, value } => header[6 + usize::from(at) % 10] = value,
        Edit::DropLevel(l) => {
            if let Some(l) = pick(levels, l) {
                levels.remove(l);
            }
        }
        Edit::DuplicateLevel(l) => {
            if let Some(l) = pick(levels, l) {
                let copy = levels[l].clone();
                levels.insert(l + 1, copy);
            }
        }
        Edit::SwapLevels(a, b) => {
            if let (Some(a), Some(b)) = (pick(levels, a), pick(levels, b)) {
                levels.swap(a, b);
            }
        }
        Edit::StaleChecksum(l) => {
            if let Some(l) = pick(levels, l).map(|l| &mut levels[l]) {
                l.stale_crc.get_or_insert(crc32fast::hash(&l.section));
            }
        }
        Edit::Length(n) => return (Some(n), None),
        Edit::Depth(d) => return (None, Some(d)),
    }
    (None, None)
}

/// Point queries, the leaf walk and loading of a view that opened: errors are fine, panics are not; for a
/// file that read as a tree (`read`) they agree with it, and otherwise loading fails as reading did.
fn query<const K: usize>(view: &KtreeView, read: Option<&AnyTree>) {
    let tree = read.cloned().and_then(|t| t.into_dim::<K>().ok());
    let side = 1u64 << view.level();
    let far = u32::try_from(side - 1).unwrap_or(u32::MAX);
    for p in [[0; K], [far; K], [far / 2 + 1; K]] {
        let inside = view.contains(p);
        if let Some(t) = &tree {
            assert_eq!(inside, Ok(t.contains(p)), "the view disagrees at {p:?}");
        }
    }
    let mut leaves = Vec::new();
    let walked = view.for_each_leaf::<K>(|c, s| leaves.push((c, s)));
    let _ = view.counts();
    let loaded = view.to_tree::<K>();
    match &tree {
        Some(t) => {
            assert_eq!(walked, Ok(()));
            assert_eq!(leaves, t.leaves().collect::<Vec<_>>());
            assert_eq!(loaded.as_ref(), Ok(t));
        }
        None => assert!(loaded.is_err(), "a view loads a tree that reading rejects"),
    }
}

fuzz_target!(|input: Input| {
    let tree = ktree_fuzz::arbitrary_any_tree(input.k, input.level, &input.shape);
    let valid = ktree_fuzz::ktree_v2_bytes(&tree);
    assert_eq!(read_ktree_any(&valid, "valid").as_ref(), Ok(&tree));
    let (mut header, mut levels) = take_apart(&valid);
    assert_eq!(put_together(&header, &levels, None, None), valid);
    let (mut length, mut depth) = (None, None);
    for e in &input.edits {
        let (l, d) = edit(&mut header, &mut levels, e);
        length = l.or(length);
        depth = d.or(depth);
    }
    let mut bytes = put_together(&header, &levels, length, depth);
    bytes.truncate(bytes.len().saturating_sub(usize::from(input.cut)));
    bytes.extend_from_slice(&input.tail);

    let read = read_ktree_any(&bytes, "edited");
    let view = KtreeView::from_bytes(bytes.clone(), "edited");
    let mapped = ktree_fuzz::open_mapped(&bytes);
    match (&view, &mapped) {
        (Ok(v), Ok(m)) => assert_eq!(v.counts_per_level(), m.counts_per_level()),
        (Err(v), Err(m)) => assert_eq!((v.offset(), &v.kind), (m.offset(), &m.kind)),
        _ => panic!("the views of bytes and of a map disagree: {view:?} {mapped:?}"),
    }
    let version = u16::from_le_bytes([
        bytes.get(6).copied().unwrap_or(0),
        bytes.get(7).copied().unwrap_or(0),
    ]);
    if let Ok(tree) = &read {
        if version == 1 {
            ktree_fuzz::check_accepted_ktree(&bytes, tree);
        } else {
            ktree_fuzz::check_accepted_ktree_v2(&bytes, tree);
        }
    }
    for view in [view, mapped].iter().flatten() {
        let read = read.as_ref().ok();
        match view.k() {
            1 => query::<1>(view, read),
            2 => query::<2>(view, read),
            3 => query::<3>(view, read),
            _ => query::<4>(view, read),
        }
    }
});
