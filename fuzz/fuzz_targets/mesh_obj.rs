//! The OBJ reader on arbitrary bytes; accepted meshes are voxelized in a small universe.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ktree_fuzz::check_mesh(data, "obj"));
