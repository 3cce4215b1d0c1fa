//! Booleans streamed from `.ktree` files to a `.ktree` file in bounded memory: byte for byte the file of
//! the in-memory Boolean, in K = 1 … 4, for random objects and for trees large enough to cross many words
//! and rank samples per level.

use std::path::Path;

use ktree::io::{
    self, read_ktree_file, write_ktree, write_ktree_file, BooleanFileError, KtreeView,
    ViewOperation,
};
use ktree::ops::{self, BoolOp};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::AnyTree;
use ktree::KTree;
use ktree_verify::objects::pair;
use proptest::prelude::*;

fn v2_bytes<const K: usize>(tree: &KTree<K>) -> Vec<u8> {
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    bytes
}

/// Every streamed operation on files of `a` and `b` writes the bytes of the in-memory result.
fn check_streamed<const K: usize>(a: &KTree<K>, b: &KTree<K>, dir: &Path) {
    let (pa, pb, out) = (
        dir.join("a.ktree"),
        dir.join("b.ktree"),
        dir.join("c.ktree"),
    );
    write_ktree_file(&pa, a).unwrap();
    write_ktree_file(&pb, b).unwrap();
    for op in BoolOp::ALL {
        let report = io::boolean_files(&pa, &pb, op, &out, None).unwrap();
        let expect = ops::boolean(a, b, op).unwrap();
        assert!(
            std::fs::read(&out).unwrap() == v2_bytes(&expect),
            "{op:?}: streamed file differs from the in-memory result"
        );
        assert_eq!(report.counts_per_level, expect.counts_per_level(), "{op:?}");
    }
    io::complement_file(&pa, &out, None).unwrap();
    assert!(std::fs::read(&out).unwrap() == v2_bytes(&ops::complement(a)));
    // Nothing is left beside the inputs and the output.
    assert_eq!(std::fs::read_dir(dir).unwrap().count(), 3);
}

/// Every operation of [`ViewOperation`] on views of `a` and `b` (the dense arrays `da`, `db`) writes the
/// in-memory result, which is the dense reference's.
fn check_views<const K: usize>(a: &KTree<K>, b: &KTree<K>, da: &[bool], db: &[bool], dir: &Path)
where
    AnyTree: From<KTree<K>>,
{
    let (pa, pb, out) = (
        dir.join("a.ktree"),
        dir.join("b.ktree"),
        dir.join("c.ktree"),
    );
    write_ktree_file(&pa, a).unwrap();
    write_ktree_file(&pb, b).unwrap();
    let (va, vb) = (KtreeView::open(&pa).unwrap(), KtreeView::open(&pb).unwrap());
    let read = |path: &Path| read_ktree_file(path).unwrap();
    for op in BoolOp::ALL {
        io::boolean_views(&va, ViewOperation::Binary(op, &vb), &out, None).unwrap();
        let expect = ops::boolean(a, b, op).unwrap();
        assert_eq!(read(&out), AnyTree::from(expect.clone()), "{op:?}");
        let dense: Vec<bool> = da.iter().zip(db).map(|(&x, &y)| op.apply(x, y)).collect();
        assert_eq!(expect.to_dense().unwrap(), dense, "{op:?}");
    }
    io::boolean_views(&va, ViewOperation::Complement, &out, None).unwrap();
    assert_eq!(read(&out), AnyTree::from(ops::complement(a)));
    let dense: Vec<bool> = da.iter().map(|&x| !x).collect();
    assert_eq!(ops::complement(a).to_dense().unwrap(), dense);
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn view_operations_k1((a, b) in pair::<1>()) {
        check_views(&a.tree(), &b.tree(), &a.dense(), &b.dense(), tempfile::tempdir().unwrap().path());
    }
    #[test]
    fn view_operations_k2((a, b) in pair::<2>()) {
        check_views(&a.tree(), &b.tree(), &a.dense(), &b.dense(), tempfile::tempdir().unwrap().path());
    }
    #[test]
    fn view_operations_k3((a, b) in pair::<3>()) {
        check_views(&a.tree(), &b.tree(), &a.dense(), &b.dense(), tempfile::tempdir().unwrap().path());
    }
    #[test]
    fn view_operations_k4((a, b) in pair::<4>()) {
        check_views(&a.tree(), &b.tree(), &a.dense(), &b.dense(), tempfile::tempdir().unwrap().path());
    }
    #[test]
    fn streamed_booleans_k1((a, b) in pair::<1>()) {
        check_streamed(&a.tree(), &b.tree(), tempfile::tempdir().unwrap().path());
    }
    #[test]
    fn streamed_booleans_k2((a, b) in pair::<2>()) {
        check_streamed(&a.tree(), &b.tree(), tempfile::tempdir().unwrap().path());
    }
    #[test]
    fn streamed_booleans_k3((a, b) in pair::<3>()) {
        check_streamed(&a.tree(), &b.tree(), tempfile::tempdir().unwrap().path());
    }
    #[test]
    fn streamed_booleans_k4((a, b) in pair::<4>()) {
        check_streamed(&a.tree(), &b.tree(), tempfile::tempdir().unwrap().path());
    }
}

/// Overlapping balls whose levels hold many words and rank samples: copies, complements and skips of
/// large subtrees, with positions found again from the samples.
#[test]
fn streamed_booleans_of_large_balls() {
    let dir = tempfile::tempdir().unwrap();
    let a = stack(&ball_rays::<3>(7, [50, 64, 64], 40).unwrap());
    let b = stack(&ball_rays::<3>(7, [80, 60, 70], 35).unwrap());
    assert!(a.level_states(6).len() > 64 * 32);
    check_streamed(&a, &b, dir.path());
    let a = stack(&ball_rays::<2>(11, [900, 1024], 700).unwrap());
    let b = stack(&ball_rays::<2>(11, [1300, 1000], 650).unwrap());
    check_streamed(&a, &b, dir.path());
    // One side empty or full at the root.
    check_streamed(&a, &KTree::<2>::full(11).unwrap(), dir.path());
    check_streamed(&KTree::<2>::empty(11).unwrap(), &b, dir.path());
}

#[test]
fn mismatched_inputs_are_an_error_and_leave_the_target() {
    let dir = tempfile::tempdir().unwrap();
    let (pa, pb, out) = (
        dir.path().join("a.ktree"),
        dir.path().join("b.ktree"),
        dir.path().join("c.ktree"),
    );
    write_ktree_file(&pa, &KTree::<3>::full(3).unwrap()).unwrap();
    write_ktree_file(&pb, &KTree::<3>::full(4).unwrap()).unwrap();
    std::fs::write(&out, b"keep").unwrap();
    let e = io::boolean_files(&pa, &pb, BoolOp::Union, &out, None).unwrap_err();
    assert!(matches!(e, BooleanFileError::Mismatch { .. }), "{e}");
    assert!(e.to_string().contains("L = 4"), "{e}");
    assert_eq!(std::fs::read(&out).unwrap(), b"keep");
    // A damaged input names its file.
    let mut bytes = std::fs::read(&pa).unwrap();
    bytes[20] ^= 1;
    std::fs::write(&pa, &bytes).unwrap();
    let e = io::boolean_files(&pa, &pb, BoolOp::Union, &out, None).unwrap_err();
    assert!(e.to_string().contains("a.ktree"), "{e}");
    assert_eq!(std::fs::read(&out).unwrap(), b"keep");
}

/// A streamed Boolean writes the bytes of the in-memory result written with the world frame its inputs
/// share (or the one that keeps one) and the first one's notes (else the second's); inputs kept in
/// different frames are refused, the target untouched.
#[test]
fn streamed_booleans_keep_the_world_frame_and_refuse_two_frames() {
    use io::{read_ktree_file_framed, write_ktree_file_framed, write_ktree_framed, Notes};
    use ktree::space::WorldFrame;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let a = KTree::<2>::from_dense(2, &[true, true, false, true].repeat(4)).unwrap();
    let b = KTree::<2>::from_dense(2, &[false, true, true, false].repeat(4)).unwrap();
    let frame = WorldFrame {
        voxel_size: 0.1,
        origin: [-2.0, 3.0, 0.0],
    };
    let noted = Notes::from([("source".to_string(), "b".to_string())]);
    write_ktree_file_framed(&p("a.ktree"), &a, None, &Notes::new()).unwrap();
    write_ktree_file_framed(&p("b.ktree"), &b, Some(&frame), &noted).unwrap();
    for op in [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference] {
        io::boolean_files(&p("a.ktree"), &p("b.ktree"), op, &p("c.ktree"), None).unwrap();
        let mut want = Vec::new();
        let result = ops::boolean(&a, &b, op).unwrap();
        write_ktree_framed(&mut want, &result, Some(&frame), &noted).unwrap();
        assert_eq!(std::fs::read(p("c.ktree")).unwrap(), want, "{op:?}");
    }
    io::complement_file(&p("b.ktree"), &p("n.ktree"), None).unwrap();
    let (_, kept, notes) = read_ktree_file_framed(&p("n.ktree")).unwrap();
    assert_eq!((kept, notes), (Some(frame), noted.clone()));
    // Another frame on the first input.
    let moved = WorldFrame {
        origin: [-2.0, 3.0, 0.5],
        ..frame
    };
    write_ktree_file_framed(&p("a.ktree"), &a, Some(&moved), &Notes::new()).unwrap();
    std::fs::write(p("c.ktree"), b"keep").unwrap();
    let e = io::boolean_files(
        &p("a.ktree"),
        &p("b.ktree"),
        BoolOp::Union,
        &p("c.ktree"),
        None,
    )
    .unwrap_err();
    assert!(matches!(e, BooleanFileError::Frames { .. }), "{e}");
    assert!(
        e.to_string().contains("a.ktree") && e.to_string().contains("b.ktree"),
        "{e}"
    );
    assert_eq!(std::fs::read(p("c.ktree")).unwrap(), b"keep");
}
