//! The STL reader on ASCII text: the input follows `solid ` so the ASCII parser is the one reached.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut text = b"solid ".to_vec();
    text.extend_from_slice(data);
    ktree_fuzz::check_mesh(&text, "stl");
});
