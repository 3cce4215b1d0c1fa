//! The binvox reader on arbitrary bytes: it never panics, and whatever it accepts is a well-formed tree.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(placed) = ktree::io::read_binvox(data, "fuzz", None, None) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
    }
});
