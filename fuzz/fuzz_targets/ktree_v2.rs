//! The `.ktree` version 2 reader (the memory-mapped view's checks, on bytes) on arbitrary bytes: it never
//! panics, and a file it accepts converts to a well-formed tree.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(view) = ktree::io::KtreeView::from_bytes(data.to_vec(), "fuzz") {
        let tree = match view.k() {
            1 => view.to_tree::<1>().map(|t| t.check().is_ok()),
            2 => view.to_tree::<2>().map(|t| t.check().is_ok()),
            3 => view.to_tree::<3>().map(|t| t.check().is_ok()),
            _ => view.to_tree::<4>().map(|t| t.check().is_ok()),
        };
        if let Ok(well_formed) = tree {
            assert!(well_formed, "a tree from a reader is well formed");
        }
    }
});
