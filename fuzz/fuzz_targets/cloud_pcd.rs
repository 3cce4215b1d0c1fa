//! The PCD reader (ASCII, binary and binary_compressed) on arbitrary bytes; accepted clouds are voxelized in a small universe.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ktree_fuzz::check_cloud(data, "pcd"));
