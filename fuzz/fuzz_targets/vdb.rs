//! The OpenVDB `.vdb` readers on arbitrary bytes: they never panic, and whatever they accept is a
//! well-formed tree (the binary reader's voxels, the typed reader's values).
//!
//! The readers run with their octree bounded to [`MAX_NODES`] (`read_vdb_within`), as a reader of untrusted
//! files would: every path of the default bound (counting the placed octree, refusing it, writing it) is
//! taken, and an execution costs at most about a millisecond. At the default bound (2^20 + 2^5 nodes a byte
//! of the file), the inputs libFuzzer keeps gather at the bound (a tile cut by an offset off its alignment
//! makes nodes in proportion to its surface) and each costs tens of milliseconds here.
#![no_main]
use libfuzzer_sys::fuzz_target;

/// The most nodes a tree read here may have.
const MAX_NODES: u64 = 1 << 16;

fuzz_target!(|data: &[u8]| {
    if let Ok(placed) = ktree::io::read_vdb_within(data, "fuzz", None, None, MAX_NODES) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
    }
    if let Ok(placed) = ktree::io::read_vdb_values_within(data, "fuzz", None, None, MAX_NODES) {
        ktree::with_valued!(&placed.tree, t => t.assert_well_formed());
    }
});
