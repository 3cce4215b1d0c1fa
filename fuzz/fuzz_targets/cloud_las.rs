//! The LAS/LAZ reader (the `las` crate's header and the `laz` crate's chunks, behind the checks) on arbitrary bytes; accepted clouds are voxelized in a small universe.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ktree_fuzz::check_cloud(data, "las"));
