//! The PLY reader (ASCII and binary PLY) on arbitrary bytes; accepted meshes are voxelized in a small universe.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ktree_fuzz::check_mesh(data, "ply"));
