//! Round trips of OctoMap `.bt`: an arbitrary octree (levels 0…16) written at any corner OctoMap's keys
//! allow and any resolution reads back, at the offset and level it was written with, as the same tree with
//! the same resolution — with unknown space read as empty or as full (writing marks the whole universe
//! known) — and without a placement as well when no offset is negative (the known region then chooses the
//! same one). Then any file that reads is written at the placement chosen for it, when OctoMap's keys allow
//! that placement, and read back as the same tree.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_bt, write_bt, BT_DEPTH, GridPlacement};
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
struct Input {
    level: u8,
    shape: Vec<u8>,
    corner: [u16; 3],
    res: f64,
    /// Any bytes, read as a `.bt` file.
    file: Vec<u8>,
}

fuzz_target!(|input: Input| {
    let level = u32::from(input.level) % (BT_DEPTH + 1);
    let tree = ktree_fuzz::arbitrary_tree::<3>(level, &input.shape);
    let offset = input
        .corner
        .map(|c| (1i64 << 15) - (i64::from(c) >> level << level));
    let mut bytes = Vec::new();
    match write_bt(&mut bytes, &tree, offset, input.res) {
        Ok(()) => assert!(input.res.is_finite() && input.res > 0.0),
        Err(_) => {
            assert!(
                !(input.res.is_finite() && input.res > 0.0),
                "a valid resolution is refused"
            );
            return;
        }
    }
    for unknown_full in [false, true] {
        let placed = read_bt(&bytes, "written", Some(offset), Some(level), unknown_full)
            .expect("a written file reads");
        assert_eq!(placed.tree, tree);
        assert_eq!(placed.meta.voxel_size, input.res);
    }
    if offset.iter().all(|&o| o >= 0) {
        let placed = read_bt(&bytes, "written", None, None, false).expect("a written file reads");
        assert_eq!(placed.tree, tree);
        assert_eq!(placed.placement, GridPlacement { offset, level });
    }

    if let Ok(placed) = read_bt(&input.file, "fuzz", None, None, false) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
        let p = placed.placement;
        let mut again = Vec::new();
        if write_bt(&mut again, &placed.tree, p.offset, placed.meta.voxel_size).is_ok() {
            let back = read_bt(&again, "rewritten", Some(p.offset), Some(p.level), false)
                .expect("a written file reads back");
            assert_eq!(back.tree, placed.tree);
            assert_eq!(back.meta, placed.meta);
        }
    }
});
