//! Slices and projections (`ops::slice`, `ops::project`) against the dense reference, K = 2, 3, 4: the
//! projection along each axis over random ranges is the "any full voxel in the range" of the dense array,
//! the slice its row at one position; the trees are reduced; a mapped file gives the same trees. The
//! extrusion (`ops::extrude`) of a J-tree along a new axis over a range is the dense array held there, and
//! projects back to the tree. The slice of a valued tree (`ops::slice_values`) is the dense array's row of
//! values, and its shape the slice of the tree's shape.

use ktree::ops::{extrude, project, slice, slice_values};
use ktree::tree::{Rgb, Value};
use ktree::KTree;
use ktree_verify::labels::{painted_at, Painted, Palette};
use ktree_verify::objects::{obj_at, Obj};
use proptest::prelude::*;

fn check<const K: usize, const J: usize>(
    o: &Obj<K>,
    axis: usize,
    lo: u32,
    len: u32,
) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let dense = o.dense();
    let u = o.universe();
    let side = u.side() as u32;
    let axis = axis % K;
    let lo = lo % side;
    let hi = (lo + len).min(side + 2); // past the universe's end too: clipped
    let got: KTree<J> = project(&tree, axis, lo..hi).unwrap();
    got.assert_well_formed();
    let plane = ktree::space::Universe::<J>::new(o.level).unwrap();
    let want: Vec<bool> = (0..plane.voxels() as usize)
        .map(|i| {
            let q = plane.dense_point(i);
            (lo..hi.min(side)).any(|c| {
                let p: [u32; K] = std::array::from_fn(|a| match a.cmp(&axis) {
                    std::cmp::Ordering::Less => q[a],
                    std::cmp::Ordering::Equal => c,
                    std::cmp::Ordering::Greater => q[a - 1],
                });
                dense[u.dense_index(p)]
            })
        })
        .collect();
    prop_assert_eq!(got.to_dense().unwrap(), want);
    // The slice at lo is the projection over lo..lo + 1.
    let one: KTree<J> = slice(&tree, axis, lo).unwrap();
    prop_assert_eq!(&one, &project::<K, J, _>(&tree, axis, lo..lo + 1).unwrap());
    Ok(())
}

fn check_extrude<const J: usize, const K: usize>(
    o: &Obj<J>,
    axis: usize,
    lo: u32,
    len: u32,
) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let dense = o.dense();
    let side = o.universe().side() as u32;
    let axis = axis % K;
    let lo = lo % side;
    let hi = lo + len; // past the universe's end too: clipped
    let got: KTree<K> = extrude(&tree, axis, lo..hi).unwrap();
    got.assert_well_formed();
    let u = ktree::space::Universe::<K>::new(o.level).unwrap();
    let want: Vec<bool> = (0..u.voxels() as usize)
        .map(|i| {
            let p = u.dense_point(i);
            let q: [u32; J] = std::array::from_fn(|a| p[if a < axis { a } else { a + 1 }]);
            (lo..hi).contains(&p[axis]) && dense[o.universe().dense_index(q)]
        })
        .collect();
    prop_assert_eq!(got.to_dense().unwrap(), want);
    if lo < hi {
        prop_assert_eq!(project::<K, J, _>(&got, axis, 0..side).unwrap(), tree);
    }
    Ok(())
}

fn check_slice_values<const K: usize, const J: usize, V: Palette>(
    o: &Painted<K>,
    axis: usize,
    at: u32,
) -> Result<(), TestCaseError> {
    let dense = o.dense::<V>();
    let tree = KTree::<K, V>::from_dense_values(o.level, &dense).unwrap();
    let u = o.universe();
    let axis = axis % K;
    let at = at % u.side() as u32;
    let got: KTree<J, V> = slice_values(&tree, axis, at).unwrap();
    got.assert_well_formed();
    let plane = ktree::space::Universe::<J>::new(o.level).unwrap();
    let want: Vec<Option<V>> = (0..plane.voxels() as usize)
        .map(|i| {
            let q = plane.dense_point(i);
            let p: [u32; K] = std::array::from_fn(|a| match a.cmp(&axis) {
                std::cmp::Ordering::Less => q[a],
                std::cmp::Ordering::Equal => at,
                std::cmp::Ordering::Greater => q[a - 1],
            });
            dense[u.dense_index(p)]
        })
        .collect();
    let back = got.to_dense_values().unwrap();
    prop_assert_eq!(
        back.iter().map(|v| v.map(Value::key)).collect::<Vec<_>>(),
        want.iter().map(|v| v.map(Value::key)).collect::<Vec<_>>()
    );
    // Minimal, so equal to the tree built from the row itself; its shape is the shape's slice.
    prop_assert_eq!(
        &got,
        &KTree::<J, V>::from_dense_values(o.level, &want).unwrap()
    );
    prop_assert_eq!(
        got.shape(),
        slice::<K, J, _>(&tree.shape(), axis, at).unwrap()
    );
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn slice_values_k2(o in (0u32..=5).prop_flat_map(painted_at::<2>), axis in 0usize..2, at in 0u32..64) {
        check_slice_values::<2, 1, u8>(&o, axis, at)?;
        check_slice_values::<2, 1, f32>(&o, axis, at)?;
    }
    #[test]
    fn slice_values_k3(o in (0u32..=4).prop_flat_map(painted_at::<3>), axis in 0usize..3, at in 0u32..16) {
        check_slice_values::<3, 2, u16>(&o, axis, at)?;
        check_slice_values::<3, 2, Rgb>(&o, axis, at)?;
    }
    #[test]
    fn slice_values_k4(o in (0u32..=3).prop_flat_map(painted_at::<4>), axis in 0usize..4, at in 0u32..8) {
        check_slice_values::<4, 3, i8>(&o, axis, at)?;
    }
    #[test]
    fn extrude_k1_to_k2(o in (0u32..=5).prop_flat_map(obj_at::<1>), axis in 0usize..2, lo in 0u32..64, len in 0u32..40) {
        check_extrude::<1, 2>(&o, axis, lo, len)?;
    }
    #[test]
    fn extrude_k2_to_k3(o in (0u32..=4).prop_flat_map(obj_at::<2>), axis in 0usize..3, lo in 0u32..16, len in 0u32..20) {
        check_extrude::<2, 3>(&o, axis, lo, len)?;
    }
    #[test]
    fn extrude_k3_to_k4(o in (0u32..=3).prop_flat_map(obj_at::<3>), axis in 0usize..4, lo in 0u32..8, len in 0u32..10) {
        check_extrude::<3, 4>(&o, axis, lo, len)?;
    }
    #[test]
    fn project_k2(o in (0u32..=5).prop_flat_map(obj_at::<2>), axis in 0usize..2, lo in 0u32..64, len in 0u32..40) {
        check::<2, 1>(&o, axis, lo, len)?;
    }
    #[test]
    fn project_k3(o in (0u32..=4).prop_flat_map(obj_at::<3>), axis in 0usize..3, lo in 0u32..16, len in 0u32..20) {
        check::<3, 2>(&o, axis, lo, len)?;
    }
    #[test]
    fn project_k4(o in (0u32..=3).prop_flat_map(obj_at::<4>), axis in 0usize..4, lo in 0u32..8, len in 0u32..10) {
        check::<4, 3>(&o, axis, lo, len)?;
    }
}

#[test]
fn bad_axes_dimensions_and_positions_are_errors() {
    let tree = KTree::<3>::full(2).unwrap();
    assert!(matches!(
        project::<3, 2, _>(&tree, 3, 0..1),
        Err(ktree::ops::OpsError::BadAxis { .. })
    ));
    assert!(matches!(
        project::<3, 1, _>(&tree, 0, 0..1),
        Err(ktree::ops::OpsError::DimensionMismatch(_))
    ));
    let e = slice::<3, 2, _>(&tree, 2, 4).unwrap_err().to_string();
    assert!(e.contains("position 4") && e.contains("axis 2"), "{e}");
    // A full octree's projection is a full quadtree, its empty range an empty one.
    assert_eq!(
        project::<3, 2, _>(&tree, 1, 1..3).unwrap(),
        KTree::<2>::full(2).unwrap()
    );
    assert_eq!(
        project::<3, 2, _>(&tree, 1, 2..2).unwrap(),
        KTree::<2>::empty(2).unwrap()
    );
}

#[test]
fn a_mapped_file_projects_as_the_tree_in_memory() {
    let dense: Vec<bool> = (0..512).map(|i| (i * 37 % 11) < 4).collect();
    let tree = KTree::<3>::from_dense(3, &dense).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.ktree");
    ktree::io::write_ktree_file(&path, &tree).unwrap();
    let mapped = ktree::io::MappedTree::<3>::open(&path).unwrap();
    for axis in 0..3 {
        assert_eq!(
            project::<3, 2, _>(&mapped, axis, 2..6).unwrap(),
            project::<3, 2, _>(&tree, axis, 2..6).unwrap()
        );
    }
}
