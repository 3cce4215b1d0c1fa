//! The raw + JSON volume reader on arbitrary bytes: the sidecar is the input up to its first NUL byte, the
//! raw samples the rest.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let (sidecar, raw) = ktree_fuzz::split_at_nul(data);
    if let Ok(v) = ktree::solid::volume::Volume::from_raw_bytes(sidecar, raw, Path::new("fuzz")) {
        ktree_fuzz::check_volume(&v);
    }
});
