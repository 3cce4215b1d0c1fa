//! The OpenVDB `.vdb` readers on arbitrary bytes: they never panic, and whatever they accept is a
//! well-formed tree (the binary reader's voxels, the typed reader's values).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(placed) = ktree::io::read_vdb(data, "fuzz", None, None) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
    }
    if let Ok(placed) = ktree::io::read_vdb_values(data, "fuzz", None, None) {
        ktree::with_valued!(&placed.tree, t => t.assert_well_formed());
    }
});
