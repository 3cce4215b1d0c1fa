//! Structure-aware `.ktree` v1: a valid file of an arbitrary tree (K = 1…4, small level, from a dense
//! array), then arbitrary edits — byte flips, a changed level size, a cut or added tail — with the checksum
//! recomputed. The untouched file must read back as the tree; an edited one must be rejected or be exactly
//! the file of the tree it reads as.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_ktree_any};
use ktree::{AnyTree};
use ktree::KTree;
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
enum Edit {
    Xor { at: u16, mask: u8 },
    LevelSize { depth: u8, size: u64 },
    Depth(u32),
    Truncate(u16),
    Append(Vec<u8>),
}

#[derive(Debug, Arbitrary)]
struct Input {
    k: u8,
    level: u8,
    voxels: Vec<u8>,
    edits: Vec<Edit>,
}

fn tree<const K: usize>(level: u32, voxels: &[u8]) -> AnyTree {
    let len = 1usize << (K as u32 * level);
    let dense: Vec<bool> = (0..len)
        .map(|i| voxels.get(i / 8).is_some_and(|b| b >> (i % 8) & 1 == 1))
        .collect();
    AnyTree::from(KTree::<K>::from_dense(level, &dense).expect("a small dense universe"))
}

fuzz_target!(|input: Input| {
    let k = 1 + input.k % 4;
    // At most 2^9 voxels.
    let level = u32::from(input.level) % (9 / u32::from(k) + 1);
    let tree = match k {
        1 => tree::<1>(level, &input.voxels),
        2 => tree::<2>(level, &input.voxels),
        3 => tree::<3>(level, &input.voxels),
        _ => tree::<4>(level, &input.voxels),
    };
    let mut bytes = ktree_fuzz::ktree_bytes(&tree);
    assert_eq!(read_ktree_any(&bytes, "valid").as_ref(), Ok(&tree));
    bytes.truncate(bytes.len() - 4);
    for edit in &input.edits {
        match edit {
            Edit::Xor { at, mask } => {
                if !bytes.is_empty() {
                    let at = usize::from(*at) % bytes.len();
                    bytes[at] ^= mask;
                }
            }
            Edit::LevelSize { depth, size } => {
                let at = 16 + 8 * usize::from(*depth);
                if at + 8 <= bytes.len() {
                    bytes[at..at + 8].copy_from_slice(&size.to_le_bytes());
                }
            }
            Edit::Depth(d) => {
                if bytes.len() >= 16 {
                    bytes[12..16].copy_from_slice(&d.to_le_bytes());
                }
            }
            Edit::Truncate(n) => {
                let keep = bytes.len().saturating_sub(usize::from(*n));
                bytes.truncate(keep);
            }
            Edit::Append(tail) => bytes.extend_from_slice(tail),
        }
    }
    bytes.extend_from_slice(&[0; 4]);
    ktree_fuzz::fix_crc(&mut bytes);
    if let Ok(read) = read_ktree_any(&bytes, "edited") {
        ktree_fuzz::check_accepted_ktree(&bytes, &read);
    }
});
