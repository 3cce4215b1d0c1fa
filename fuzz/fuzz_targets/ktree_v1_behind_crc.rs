//! The `.ktree` v1 reader behind its checksum: the input's last 4 bytes are replaced by the CRC of the rest,
//! so mutated headers, level sizes, totals and node states reach the structural validation. Whatever is
//! accepted must round-trip byte for byte.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    ktree_fuzz::fix_crc(&mut bytes);
    if let Ok(tree) = ktree::io::read_ktree_any(&bytes, "fuzz") {
        ktree_fuzz::check_accepted_ktree(&bytes, &tree);
    }
});
