//! The grid formats of other tools (binvox, OctoMap `.bt`, OpenVDB `.vdb` as a `BoolGrid` and as a level set):
//! random octrees round-trip through each, and arbitrary or damaged bytes give an error or a tree, never a
//! panic. (The files are checked
//! against the real tools in `cli/tests/interop.rs`.)

use ktree_verify::cases;

use cases::{ray_sets, Case};
use ktree::io::{
    read_binvox, read_bt, read_vdb, write_binvox, write_bt, write_vdb, write_vdb_level_set,
    GridMeta, PlacedTree,
};
use ktree::stacking::paper::stack;
use ktree::KTree;
use proptest::prelude::*;

/// Writes `tree` in each grid format.
fn files(tree: &KTree<3>) -> Vec<(&'static str, Vec<u8>)> {
    let meta = GridMeta::default();
    let mut binvox = Vec::new();
    write_binvox(&mut binvox, tree, &meta).unwrap();
    let mut bt = Vec::new();
    write_bt(&mut bt, tree, [0; 3], 1.0).unwrap();
    let mut vdb = Vec::new();
    write_vdb(&mut vdb, tree, [0; 3], &meta).unwrap();
    // The narrow band of half-width 3 around the tree's surface, read back as its interior.
    let mut level_set = Vec::new();
    write_vdb_level_set(&mut level_set, tree, 3.0, 0.5).unwrap();
    vec![
        ("binvox", binvox),
        ("bt", bt),
        ("vdb", vdb),
        ("vdb level set", level_set),
    ]
}

/// Reads bytes as the named format with the placement the writer used.
fn read(format: &str, bytes: &[u8], level: u32) -> Option<PlacedTree> {
    let (offset, level) = (Some([0; 3]), Some(level));
    match format {
        "binvox" => read_binvox(bytes, "f", offset, level).ok(),
        "bt" => read_bt(bytes, "f", offset, level, false).ok(),
        _ => read_vdb(bytes, "f", offset, level).ok(),
    }
}

proptest! {
    #[test]
    fn octrees_round_trip_through_every_grid_format(case in ray_sets::<3>()) {
        let Case { rays, .. } = case;
        let tree = stack(&rays);
        for (format, bytes) in files(&tree) {
            let back = read(format, &bytes, tree.level());
            prop_assert!(back.is_some(), "{} did not read back", format);
            let back = back.unwrap().tree;
            back.assert_well_formed();
            prop_assert!(back == tree, "{} changed the tree", format);
            if format.starts_with("vdb") {
                // ktree's .vdb files carry their universe: read without a placement, the same tree.
                let unplaced = read_vdb(&bytes, "f", None, None).unwrap();
                prop_assert!(unplaced.tree == tree, "{} without a placement", format);
            }
        }
    }

    #[test]
    fn damaged_files_give_an_error_or_a_tree_never_a_panic(
        case in ray_sets::<3>(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
        cut in any::<prop::sample::Index>(),
    ) {
        let tree = stack(&case.rays);
        for (format, bytes) in files(&tree) {
            let mut bad = bytes.clone();
            for (at, value) in &edits {
                let i = at.index(bad.len());
                bad[i] = *value;
            }
            if let Some(t) = read(format, &bad, tree.level()) {
                t.tree.assert_well_formed();
            }
            let short = &bytes[..cut.index(bytes.len())];
            prop_assert!(read(format, short, tree.level()).is_none(), "{} accepted a truncated file", format);
        }
    }

    #[test]
    fn arbitrary_bytes_give_an_error_or_a_tree_never_a_panic(
        bytes in prop::collection::vec(any::<u8>(), 0..400),
        header in 0usize..4,
    ) {
        // Behind each format's real first line, so that the parsers get past their magic.
        let prefix: &[u8] = match header {
            0 => b"#binvox 1\ndim 4 4 4\ndata\n",
            1 => b"# Octomap OcTree binary file\nid OcTree\nsize 9\nres 1\ndata\n",
            2 => &[0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0, 0xe0, 0, 0, 0],
            _ => b"",
        };
        let input = [prefix, &bytes].concat();
        for format in ["binvox", "bt", "vdb"] {
            if let Some(t) = read(format, &input, 4) {
                t.tree.assert_well_formed();
            }
        }
    }
}
