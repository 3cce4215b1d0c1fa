//! The point cloud PLY reader (ASCII and binary, vertices without faces) on arbitrary bytes; accepted clouds are voxelized in a small universe.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ktree_fuzz::check_cloud(data, "ply"));
