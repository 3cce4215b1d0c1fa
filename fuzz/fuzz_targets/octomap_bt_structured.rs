//! Structure-aware OctoMap `.bt`: the file of an arbitrary octree (levels 0…16) at any corner OctoMap's
//! keys allow and any resolution, then edits of its header lines (`id`, `size`, `res`, comments, `data`
//! replaced, inserted, removed, repeated or exchanged, with any numbers) and of its nodes (bytes flipped or
//! set, two-byte nodes removed or repeated, a cut or added tail), read with or without a placement and with
//! unknown space as empty or full. The untouched file is the tree; an edited one is rejected or is a
//! well-formed tree.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_bt, write_bt, BT_DEPTH};
use ktree_fuzz::{BodyEdit, HeaderEdit, TextHeaderFile};
use libfuzzer_sys::fuzz_target;

const KEYWORDS: [&str; 7] = [
    "#",
    "# Octomap OcTree binary file",
    "id",
    "size",
    "res",
    "data",
    "id OcTree",
];

#[derive(Debug, Arbitrary)]
struct Input {
    level: u8,
    shape: Vec<u8>,
    corner: [u16; 3],
    res: f64,
    header_edits: Vec<HeaderEdit>,
    body_edits: Vec<BodyEdit>,
    offset: Option<[i64; 3]>,
    read_level: Option<u8>,
    unknown_full: bool,
}

fuzz_target!(|input: Input| {
    let level = u32::from(input.level) % (BT_DEPTH + 1);
    let tree = ktree_fuzz::arbitrary_tree::<3>(level, &input.shape);
    // ktree voxel = OctoMap key − 2^15 + offset: the universe's corner is a multiple of its side.
    let offset = input
        .corner
        .map(|c| (1i64 << 15) - (i64::from(c) >> level << level));
    let res = if input.res.is_finite() && input.res > 0.0 {
        input.res
    } else {
        1.0
    };
    let mut bytes = Vec::new();
    write_bt(&mut bytes, &tree, offset, res).expect("a corner OctoMap's keys allow");
    let placed =
        read_bt(&bytes, "valid", Some(offset), Some(level), false).expect("a written file reads");
    assert_eq!(placed.tree, tree);
    let mut file = TextHeaderFile::split(&bytes);
    for edit in &input.header_edits {
        file.edit_header(edit, &KEYWORDS);
    }
    for edit in &input.body_edits {
        ktree_fuzz::edit_body(&mut file.body, edit, 2);
    }
    let bytes = file.to_bytes();
    let level = input.read_level.map(u32::from);
    if let Ok(placed) = read_bt(&bytes, "edited", input.offset, level, input.unknown_full) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
    }
});
