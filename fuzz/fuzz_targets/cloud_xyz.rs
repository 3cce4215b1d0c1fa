//! The XYZ and CSV text reader on arbitrary bytes, read as XYZ and as CSV; accepted clouds are voxelized in a small universe.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    ktree_fuzz::check_cloud(data, "xyz");
    ktree_fuzz::check_cloud(data, "csv");
});
