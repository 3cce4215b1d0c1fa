//! The ray text reader on arbitrary bytes: an error or a ray set, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = ktree::io::read_rays(data, "fuzz");
});
