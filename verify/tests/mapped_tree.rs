//! A `.ktree` version 2 file walked through its memory map ([`MappedTree`]) gives what the tree in memory
//! gives: the same leaves in K = 1 … 4, the same view-order walk and the same rendered image.

use ktree::display::{default_camera, render, RenderOptions, ISO_TOWARD_EYE};
use ktree::io::{write_ktree, KtreeView, MappedTree};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::tree::cursor::TryLeaves;
use ktree::tree::storage::TreeStorage;
use ktree::KTree;
use ktree_verify::objects::object;
use proptest::prelude::*;

fn view_of<const K: usize>(tree: &KTree<K>) -> KtreeView {
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    KtreeView::from_bytes(bytes, "mem").unwrap()
}

fn check_leaves<const K: usize>(tree: &KTree<K>) -> Result<(), TestCaseError> {
    let view = view_of(tree);
    let mapped = MappedTree::<K>::new(&view).unwrap();
    let leaves: Vec<_> = TryLeaves::new(&mapped).collect::<Result<_, _>>().unwrap();
    prop_assert_eq!(leaves, tree.leaves().collect::<Vec<_>>());
    prop_assert_eq!(mapped.depth_count(), tree.depth_count());
    prop_assert_eq!(mapped.counts_per_level(), tree.counts_per_level());
    prop_assert_eq!(TreeStorage::voxel_count(&mapped), tree.voxel_count());
    // The rank of every node, the level's end included, as the tree in memory counts it.
    for depth in 0..tree.depth_count() {
        let len = tree.level_states(depth).len();
        prop_assert_eq!(mapped.level_len(depth), len);
        for index in 0..=len {
            prop_assert_eq!(
                mapped.partial_rank(depth, index).unwrap(),
                tree.level_states(depth).partial_rank(index)
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn mapped_leaves_k1(o in object::<1>()) { check_leaves(&o.tree())?; }
    #[test]
    fn mapped_leaves_k2(o in object::<2>()) { check_leaves(&o.tree())?; }
    #[test]
    fn mapped_leaves_k3(o in object::<3>()) { check_leaves(&o.tree())?; }
    #[test]
    fn mapped_leaves_k4(o in object::<4>()) { check_leaves(&o.tree())?; }
}

/// Levels of many words and rank samples; the image, depth and statistics are those of the tree in memory.
#[test]
fn mapped_render_is_the_in_memory_render() {
    let tree = stack(&ball_rays::<3>(8, [120, 128, 140], 100).unwrap());
    let view = view_of(&tree);
    let mapped = MappedTree::<3>::new(&view).unwrap();
    let camera = default_camera(&tree, ISO_TOWARD_EYE, Some(40.0), 160, 120).unwrap();
    assert_eq!(
        default_camera(&mapped, ISO_TOWARD_EYE, Some(40.0), 160, 120).unwrap(),
        camera
    );
    let options = RenderOptions {
        width: 160,
        height: 120,
        depth: true,
        ..Default::default()
    };
    let (a, b) = (
        render(&tree, &camera, &options).unwrap(),
        render(&mapped, &camera, &options).unwrap(),
    );
    assert!(a.stats.painted > 5000);
    assert_eq!(a.rgb, b.rgb);
    assert_eq!(a.depth, b.depth);
    assert_eq!(a.stats, b.stats);
}

#[test]
fn a_file_of_another_dimension_is_an_error() {
    let view = view_of(&KTree::<2>::full(3).unwrap());
    let e = MappedTree::<3>::new(&view).unwrap_err();
    assert!(e.to_string().contains("mem"), "{e}");
}
