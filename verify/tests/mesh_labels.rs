//! Meshes as labels: the tree of several meshes voxelized together (`KTree::from_label_meshes`,
//! `input::voxelize_mesh_labels`) equals, voxel for voxel, a reference painted independently — each mesh
//! voxelized alone by the binary voxelizer in the same placement, its voxels written into a dense array of
//! labels in order (the later mesh wins) — for random boxes, tetrahedra and octahedra, overlapping or
//! not; the tree is minimal (no block of 2^K equal sibling leaves); an OBJ file's groups are labels, one
//! each, equal to voxelizing each group's mesh alone from its own file; bad input is an error naming the
//! file.

use std::collections::HashMap;
use std::path::Path;

use ktree::input::voxelize_mesh_labels;
use ktree::io::ReadOptions;
use ktree::solid::mesh::{label_runs, MeshTransform, Placement, TriangleMesh};
use ktree::{AnyValuedTree, KTree, Universe};
use ktree_verify::meshes::{cube, octahedron, CUBE};
use proptest::prelude::*;

/// The tetrahedron of four corners, outward oriented whatever their order (`None` when flat).
fn tetrahedron(p: [[f64; 3]; 4]) -> Option<TriangleMesh> {
    let mesh =
        TriangleMesh::new(p.to_vec(), vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]).ok()?;
    let volume = mesh.signed_volume();
    if volume.abs() < 1e-6 {
        return None;
    }
    if volume > 0.0 {
        return Some(mesh);
    }
    TriangleMesh::new(p.to_vec(), vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]).ok()
}

/// The reference: each mesh voxelized alone by the binary voxelizer, painted in order into a dense
/// array (the later mesh over the earlier).
fn painted(meshes: &[TriangleMesh], level: u32, placement: &MeshTransform) -> Vec<Option<u8>> {
    let u = Universe::<3>::new(level).unwrap();
    let mut dense = vec![None; u.voxels() as usize];
    for (i, mesh) in meshes.iter().enumerate() {
        let rays = mesh.to_rays(level, placement).unwrap().rays;
        for ray in rays.iter() {
            let c = ray.column();
            for z in ray.z1()..ray.z2 {
                dense[u.dense_index([c[0], c[1], z])] = Some(i as u8 + 1);
            }
        }
    }
    dense
}

/// Fails when some 2^K sibling leaves all hold the same value (or are all empty): the tree would not be
/// minimal.
fn assert_minimal<const K: usize>(tree: &KTree<K, u8>) {
    let mut siblings: HashMap<([u32; K], u32), Vec<Option<u8>>> = HashMap::new();
    for (cell, value) in tree.value_leaves() {
        if cell.log_side() == tree.level() {
            continue; // the root
        }
        let mask = !((2u32 << cell.log_side()) - 1);
        siblings
            .entry((cell.origin().map(|c| c & mask), cell.log_side()))
            .or_default()
            .push(value);
    }
    for ((origin, log_side), values) in siblings {
        assert!(
            values.len() < 1 << K || values.iter().any(|v| *v != values[0]),
            "the {} leaves of side 2^{log_side} under {origin:?} all hold {:?}",
            values.len(),
            values[0]
        );
    }
}

/// Checks the label tree of `meshes` against the painted reference, in the transform `placement` gives
/// them together.
fn check(meshes: &[TriangleMesh], level: u32, placement: Placement) -> Result<(), TestCaseError> {
    let tree = KTree::<3, u8>::from_label_meshes(meshes, level, placement).unwrap();
    tree.assert_well_formed();
    assert_minimal(&tree);
    let transform = placement.transform_all(meshes, level).unwrap();
    let want = painted(meshes, level, &transform);
    let got = tree.to_dense_values().unwrap();
    let u = Universe::<3>::new(level).unwrap();
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        prop_assert_eq!(g, w, "voxel {:?}", u.dense_point(i));
    }
    prop_assert_eq!(tree, KTree::from_dense_values(level, &want).unwrap());
    // The voxels counted for each label on the runs.
    let counted = label_runs::<u8>(meshes, level, &transform).unwrap().voxels;
    for (i, &n) in counted.iter().enumerate() {
        let label = Some(i as u8 + 1);
        prop_assert_eq!(
            n,
            want.iter().filter(|&&v| v == label).count() as u64,
            "label {:?}",
            label
        );
    }
    Ok(())
}

/// A coordinate of a corner, on a quarter-voxel grid of a 16³ universe and a little past it.
fn coordinate() -> impl Strategy<Value = f64> {
    (-4i32..68).prop_map(|q| f64::from(q) / 4.0)
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(coordinate())
}

/// A box, a tetrahedron or an octahedron, in voxel units of a 16³ universe.
fn mesh() -> impl Strategy<Value = TriangleMesh> {
    prop_oneof![
        (point(), point()).prop_filter_map("a flat box", |(a, b)| {
            let lo = [0, 1, 2].map(|k| a[k].min(b[k]));
            let hi = [0, 1, 2].map(|k| a[k].max(b[k]));
            (0..3).all(|k| lo[k] < hi[k]).then(|| cube(lo, hi))
        }),
        prop::array::uniform4(point()).prop_filter_map("a flat tetrahedron", tetrahedron),
        (point(), 1i32..24).prop_map(|(c, r)| octahedron(c, f64::from(r) / 4.0)),
    ]
}

const ID: MeshTransform = MeshTransform {
    scale: 1.0,
    translate: [0.0; 3],
};

proptest! {
    #![proptest_config(ktree_verify::config(48))]
    /// One to five meshes, overlapping as they fall, in voxel units and fitted together.
    #[test]
    fn labels_are_the_meshes_painted_in_order(meshes in prop::collection::vec(mesh(), 1..6), fit in any::<bool>()) {
        let placement = if fit { Placement::Fit } else { Placement::Transform(ID) };
        check(&meshes, 4, placement)?;
    }
}

#[test]
fn overlaps_go_to_the_later_mesh() {
    let a = cube([0.0; 3], [8.0; 3]);
    let b = cube([4.0; 3], [12.0; 3]);
    let inner = cube([5.0; 3], [6.0; 3]);
    for meshes in [
        vec![a.clone(), b.clone()],
        vec![b.clone(), a.clone()],
        vec![a.clone(), inner.clone(), b.clone()],
        vec![a.clone(), b.clone(), inner.clone()],
    ] {
        check(&meshes, 4, Placement::Transform(ID)).unwrap();
    }
    let tree =
        KTree::<3, u8>::from_label_meshes(&[a, b, inner], 4, Placement::Transform(ID)).unwrap();
    assert_eq!(tree.value_at([2, 2, 2]), Some(1));
    assert_eq!(tree.value_at([7, 7, 7]), Some(2));
    assert_eq!(tree.value_at([5, 5, 5]), Some(3));
    assert_eq!(tree.value_at([13, 13, 13]), None);
}

#[test]
fn meshes_fill_the_universe_and_touch_minimally() {
    // Two halves of the universe, then eight octants: touching labels, and one label filling a cell.
    let halves = [
        cube([0.0; 3], [8.0, 16.0, 16.0]),
        cube([8.0, 0.0, 0.0], [16.0; 3]),
    ];
    check(&halves, 4, Placement::Transform(ID)).unwrap();
    let octants: Vec<TriangleMesh> = (0..8)
        .map(|i| {
            let lo = [0, 1, 2].map(|a| if i >> a & 1 == 1 { 8.0 } else { 0.0 });
            cube(lo, lo.map(|c| c + 8.0))
        })
        .collect();
    check(&octants, 4, Placement::Transform(ID)).unwrap();
    let tree = KTree::<3, u8>::from_label_meshes(&octants, 4, Placement::Transform(ID)).unwrap();
    assert_eq!(tree.node_count(), 9); // the root and its eight full octants
                                      // The same mesh twice: the second hides the first entirely.
    let twice = [halves[0].clone(), halves[0].clone()];
    let tree = KTree::<3, u8>::from_label_meshes(&twice, 4, Placement::Transform(ID)).unwrap();
    assert_eq!(tree.value_stats().into_keys().collect::<Vec<_>>(), [2]);
}

#[test]
fn too_many_meshes_for_the_label_type_or_none_are_refused() {
    let meshes: Vec<TriangleMesh> = (0..256)
        .map(|i| cube([f64::from(i % 16); 3], [f64::from(i % 16) + 1.0; 3]))
        .collect();
    assert!(KTree::<3, u8>::from_label_meshes(&meshes, 4, Placement::Transform(ID)).is_err());
    let tree = KTree::<3, u16>::from_label_meshes(&meshes, 4, Placement::Transform(ID)).unwrap();
    // The diagonal unit cubes, each painted by its last copy (labels 241 to 256).
    assert_eq!(
        tree.value_stats().into_keys().collect::<Vec<_>>(),
        (241..=256).collect::<Vec<u16>>()
    );
    assert!(KTree::<3, u8>::from_label_meshes(&[], 4, Placement::Fit).is_err());
}

/// A box's lines of an OBJ file: its corners after `base` vertices, its faces.
fn obj_box(lo: [f64; 3], hi: [f64; 3], base: u32) -> String {
    let mut s = String::new();
    for i in 0..8 {
        let c = [0, 1, 2].map(|a| if i >> a & 1 == 1 { hi[a] } else { lo[a] });
        s += &format!("v {} {} {}\n", c[0], c[1], c[2]);
    }
    for t in CUBE {
        s += &format!(
            "f {} {} {}\n",
            base + t[0] + 1,
            base + t[1] + 1,
            base + t[2] + 1
        );
    }
    s
}

fn level(l: u32) -> ReadOptions {
    ReadOptions {
        level: Some(l),
        ..ReadOptions::default()
    }
}

#[test]
fn an_obj_file_s_groups_are_labels_as_each_group_voxelized_alone() {
    let dir = tempfile::tempdir().unwrap();
    let boxes = [
        ("table", [0.0, 0.0, 0.0], [4.0, 3.0, 0.5]),
        ("cup", [1.0, 1.0, 0.25], [1.5, 1.75, 1.5]), // overlaps the table: the cup wins
        ("lamp", [3.0, 0.5, 0.5], [3.5, 1.0, 2.75]),
    ];
    let mut scene = String::new();
    for (i, (name, lo, hi)) in boxes.iter().enumerate() {
        scene += &format!("g {name}\n");
        scene += &obj_box(*lo, *hi, 8 * i as u32);
        std::fs::write(dir.path().join(format!("{name}.obj")), obj_box(*lo, *hi, 0)).unwrap();
    }
    let path = dir.path().join("scene.obj");
    std::fs::write(&path, &scene).unwrap();
    for l in [4, 5] {
        let labels = voxelize_mesh_labels(&[&path], &level(l)).unwrap();
        assert_eq!(labels.names, ["table", "cup", "lamp"]);
        assert!(labels.fitted.is_some());
        let AnyValuedTree::K3U8(tree) = labels.tree else {
            panic!("three labels are u8")
        };
        assert_minimal(&tree);
        // Each group from its own file, in the placement the labels chose, painted in order.
        let placed = ReadOptions {
            mesh_placement: Some(labels.transform),
            ..level(l)
        };
        let u = Universe::<3>::new(l).unwrap();
        let mut want = vec![None; u.voxels() as usize];
        for (i, (name, _, _)) in boxes.iter().enumerate() {
            let alone =
                ktree::input::voxelize(&dir.path().join(format!("{name}.obj")), &placed).unwrap();
            assert!(alone.rays.voxel_count() > 0, "{name} at level {l}");
            for ray in alone.rays.iter() {
                let c = ray.column();
                for z in ray.z1()..ray.z2 {
                    want[u.dense_index([c[0], c[1], z])] = Some(i as u8 + 1);
                }
            }
        }
        assert_eq!(tree.to_dense_values().unwrap(), want, "level {l}");
        for (i, &n) in labels.voxels.iter().enumerate() {
            let label = Some(i as u8 + 1);
            assert_eq!(n, want.iter().filter(|&&v| v == label).count() as u64);
        }
    }
    // Faces before the first group are a group of their own; a file without groups is one label.
    let head = format!(
        "{}g lamp\n{}",
        obj_box([0.0; 3], [1.0; 3], 0),
        obj_box([2.0; 3], [3.0; 3], 8)
    );
    std::fs::write(&path, head).unwrap();
    let labels = voxelize_mesh_labels(&[&path], &level(4)).unwrap();
    assert_eq!(labels.names, ["unnamed_object", "lamp"]);
    std::fs::write(&path, obj_box([0.0; 3], [1.0; 3], 0)).unwrap();
    let labels = voxelize_mesh_labels(&[&path], &level(4)).unwrap();
    assert_eq!(labels.names, [path.display().to_string()]);
}

#[test]
fn several_files_are_one_label_each_in_the_order_given() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.obj");
    let b = dir.path().join("b.stl");
    std::fs::write(&a, obj_box([0.0; 3], [2.0; 3], 0)).unwrap();
    let mut stl = String::from("solid b\n");
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { 3.0 } else { 1.0 }))
        .collect();
    for t in CUBE {
        stl += "facet normal 0 0 0\nouter loop\n";
        for v in t {
            let p = corners[v as usize];
            stl += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        stl += "endloop\nendfacet\n";
    }
    stl += "endsolid b\n";
    std::fs::write(&b, stl).unwrap();
    let placed = ReadOptions {
        mesh_placement: Some(MeshTransform {
            scale: 4.0,
            translate: [1.0; 3],
        }),
        ..level(5)
    };
    let labels = voxelize_mesh_labels(&[&a, &b], &placed).unwrap();
    assert_eq!(
        labels.names,
        [a.display().to_string(), b.display().to_string()]
    );
    assert_eq!(labels.fitted, None);
    let AnyValuedTree::K3U8(tree) = labels.tree else {
        panic!("two labels are u8")
    };
    let meshes = [
        ktree::io::read_mesh(&a).unwrap(),
        ktree::io::read_mesh(&b).unwrap(),
    ];
    let want = painted(&meshes, 5, &placed.mesh_placement.unwrap());
    assert_eq!(tree.to_dense_values().unwrap(), want);
}

#[test]
fn bad_input_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.obj");
    // The second group lacks a face.
    let mut open = obj_box([1.0; 3], [2.0; 3], 8);
    open.truncate(open.trim_end().rfind('\n').unwrap() + 1);
    let scene = format!("g whole\n{}g holed\n{open}", obj_box([0.0; 3], [1.0; 3], 0));
    std::fs::write(&path, scene).unwrap();
    let e = voxelize_mesh_labels(&[&path], &level(4))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scene.obj") && e.contains("'holed'") && e.contains("not closed"),
        "{e}"
    );
    let missing = dir.path().join("missing.obj");
    let e = voxelize_mesh_labels(&[&missing], &level(4))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.obj"), "{e}");
    let e = voxelize_mesh_labels(&[&path, Path::new("x.nii")], &level(4))
        .unwrap_err()
        .to_string();
    assert!(e.contains("scene.obj") || e.contains("x.nii"), "{e}");
    let none: [&Path; 0] = [];
    assert!(voxelize_mesh_labels(&none, &level(4)).is_err());
    let closed = dir.path().join("closed.obj");
    std::fs::write(&closed, obj_box([0.0; 3], [1.0; 3], 0)).unwrap();
    let e = voxelize_mesh_labels(&[&closed], &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("closed.obj") && e.contains("level"), "{e}");
    // A group of faces that name missing vertices.
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\ng a\nf 1 2 3\ng b\nf 1 2 9\n",
    )
    .unwrap();
    let e = voxelize_mesh_labels(&[&path], &level(4))
        .unwrap_err()
        .to_string();
    assert!(e.contains("scene.obj"), "{e}");
}
