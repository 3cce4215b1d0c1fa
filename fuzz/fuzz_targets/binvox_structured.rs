//! Structure-aware binvox: the file of an arbitrary octree (levels 0…5, any `translate` and `scale`), then
//! edits of its header lines (`dim`, `translate`, `scale`, `data` lines replaced, inserted, removed,
//! repeated or exchanged, with any numbers) and of its run-length pairs (bytes flipped or set, pairs
//! removed or repeated, a cut or added tail), read with or without a placement. The untouched file is the
//! tree; an edited one is rejected, or is a well-formed tree that holds exactly the voxels its runs set.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_binvox, write_binvox, GridMeta};
use ktree_fuzz::{BodyEdit, HeaderEdit, TextHeaderFile};
use libfuzzer_sys::fuzz_target;

const KEYWORDS: [&str; 5] = ["#binvox", "dim", "translate", "scale", "data"];

#[derive(Debug, Arbitrary)]
struct Input {
    level: u8,
    shape: Vec<u8>,
    voxel_size: f64,
    origin: [f64; 3],
    header_edits: Vec<HeaderEdit>,
    body_edits: Vec<BodyEdit>,
    offset: Option<[i64; 3]>,
    read_level: Option<u8>,
}

/// The voxels a binvox file sets, decoded the simplest way (`D` and the runs), for files the reader
/// accepted.
fn decode(bytes: &[u8]) -> (u64, Vec<bool>) {
    let mut at = 0;
    let mut dim = None;
    loop {
        let len = bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .expect("a header line");
        let line = std::str::from_utf8(&bytes[at..at + len]).expect("text");
        at += len + 1;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["dim", d, ..] => dim = Some(d.parse::<f64>().expect("a number") as u64),
            ["data"] => break,
            _ => {}
        }
    }
    let voxels = bytes[at..]
        .chunks_exact(2)
        .flat_map(|pair| std::iter::repeat_n(pair[0] == 1, usize::from(pair[1])))
        .collect();
    (dim.expect("a dim line"), voxels)
}

fuzz_target!(|input: Input| {
    let level = u32::from(input.level) % 6;
    let tree = ktree_fuzz::arbitrary_tree::<3>(level, &input.shape);
    let meta = GridMeta {
        voxel_size: input.voxel_size,
        origin: input.origin,
    };
    let mut bytes = Vec::new();
    write_binvox(&mut bytes, &tree, &meta).expect("writing to memory");
    let valid_meta = meta.origin.iter().all(|o| o.is_finite())
        && (meta.voxel_size * f64::from(1u32 << level)).is_finite()
        && meta.voxel_size * f64::from(1u32 << level) > 0.0;
    let read = read_binvox(&bytes, "valid", None, None);
    if valid_meta {
        assert_eq!(read.map(|p| p.tree).as_ref(), Ok(&tree));
    }
    let mut file = TextHeaderFile::split(&bytes);
    for edit in &input.header_edits {
        file.edit_header(edit, &KEYWORDS);
    }
    for edit in &input.body_edits {
        ktree_fuzz::edit_body(&mut file.body, edit, 2);
    }
    let bytes = file.to_bytes();
    let level = input.read_level.map(u32::from);
    if let Ok(placed) = read_binvox(&bytes, "edited", input.offset, level) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
        if input.offset.is_none() && level.is_none() {
            let (d, voxels) = decode(&bytes);
            assert_eq!(voxels.len() as u64, d * d * d);
            if d <= 32 {
                let t = &placed.tree;
                assert!(1u64 << t.level() >= d && (t.level() == 0 || 1u64 << (t.level() - 1) < d));
                assert_eq!(
                    t.voxel_count(),
                    voxels.iter().filter(|&&v| v).count() as u128
                );
                for (i, &v) in voxels.iter().enumerate() {
                    let i = i as u64;
                    let (x, z, y) = (i / (d * d), i / d % d, i % d);
                    assert_eq!(t.contains([x as u32, y as u32, z as u32]), v, "voxel {i}");
                }
            }
        }
    }
});
