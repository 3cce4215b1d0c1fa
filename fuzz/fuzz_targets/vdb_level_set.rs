//! The OpenVDB `.vdb` reader on level sets and compressed value buffers: arbitrary bytes (seeded with level
//! sets written by OpenVDB — Blosc, half floats, a `DoubleGrid`, active-mask compression only — and a
//! zlib-compressed `BoolGrid`; ktree's own level sets hold every value of a 32³ node, 128 KiB, and are
//! checked by `verify/tests/interop_files.rs` instead) never panic, whatever is accepted is a well-formed
//! tree, and an accepted small tree written as a level set reads back the same.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(placed) = ktree::io::read_vdb(data, "fuzz", None, None) {
        let tree = placed.tree;
        tree.check().expect("a tree from a reader is well formed");
        if tree.level() <= 5 {
            let mut bytes = Vec::new();
            ktree::io::write_vdb_level_set(&mut bytes, &tree, 2.0, 1.0)
                .expect("a small tree is written as a level set");
            let back = ktree::io::read_vdb(&bytes, "fuzz", None, None)
                .expect("ktree reads the level sets it writes");
            assert!(back.tree == tree, "a level set read back as another tree");
        }
    }
});
