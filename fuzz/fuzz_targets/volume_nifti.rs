//! The NIfTI-1 reader on arbitrary bytes (plain, or gzip when the input starts with the gzip magic).
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(v) = ktree::solid::volume::Volume::from_nifti_bytes(data, Path::new("fuzz")) {
        ktree_fuzz::check_volume(&v);
    }
});
