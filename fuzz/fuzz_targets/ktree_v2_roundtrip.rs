//! Round trips of `.ktree` version 2: an arbitrary tree (K = 1…4, any level) written in version 2 reads
//! back as the same tree from bytes, as a view and as a memory-mapped view, and its version 1 file holds
//! the same tree; then any file (version 1 or 2) that reads is written in version 2 and read back unchanged.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_ktree_any, KtreeView};
use ktree::{AnyTree};
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
struct Input {
    k: u8,
    level: u8,
    shape: Vec<u8>,
    /// Any bytes, read as a `.ktree` file.
    file: Vec<u8>,
}

/// The tree of a view of dimension `K`, compared with `tree`.
fn view_gives<const K: usize>(view: &KtreeView, tree: &AnyTree) -> bool {
    let loaded = view.to_tree::<K>().map(AnyTree::from);
    loaded.as_ref() == Ok(tree) && view.counts() == tree.counts()
}

fn check_views(bytes: &[u8], tree: &AnyTree) {
    let in_memory = KtreeView::from_bytes(bytes.to_vec(), "written").expect("a written file opens");
    let mapped = ktree_fuzz::open_mapped(bytes).expect("a written file maps");
    for view in [in_memory, mapped] {
        let same = match view.k() {
            1 => view_gives::<1>(&view, tree),
            2 => view_gives::<2>(&view, tree),
            3 => view_gives::<3>(&view, tree),
            _ => view_gives::<4>(&view, tree),
        };
        assert!(same, "a view of a written file gives another tree");
    }
}

fuzz_target!(|input: Input| {
    let tree = ktree_fuzz::arbitrary_any_tree(input.k, input.level, &input.shape);
    let bytes = ktree_fuzz::ktree_v2_bytes(&tree);
    assert_eq!(bytes.len() % 8, 0, "a version 2 file is whole words");
    assert_eq!(read_ktree_any(&bytes, "written").as_ref(), Ok(&tree));
    check_views(&bytes, &tree);
    let v1 = ktree_fuzz::ktree_bytes(&tree);
    assert_eq!(read_ktree_any(&v1, "version 1").as_ref(), Ok(&tree));

    if let Ok(read) = read_ktree_any(&input.file, "fuzz") {
        ktree_fuzz::check_tree(&read);
        let again = ktree_fuzz::ktree_v2_bytes(&read);
        assert_eq!(read_ktree_any(&again, "rewritten").as_ref(), Ok(&read));
        check_views(&again, &read);
        let version = u16::from_le_bytes([input.file[6], input.file[7]]);
        if version == ktree::io::VERSION {
            assert_eq!(
                again, input.file,
                "an accepted version 2 file is not what its tree writes"
            );
        }
    }
});
