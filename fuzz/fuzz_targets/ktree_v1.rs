//! The `.ktree` v1 reader on arbitrary bytes; whatever it accepts must round-trip byte for byte.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(tree) = ktree::io::read_ktree_any(data, "fuzz") {
        ktree_fuzz::check_accepted_ktree(data, &tree);
    }
});
