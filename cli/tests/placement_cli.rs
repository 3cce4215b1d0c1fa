//! A grid's place in the world survives `ktree convert`: `.bt` → `.bt`, `.bt` ↔ `.vdb`, and `--origin` with a
//! `.bt` output, each voxel at the same world position after as before (or a clear refusal where the
//! output cannot hold the placement); a `.ktree` keeps it as its world frame; a ray file, which holds
//! none, says so.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use common::ktree;
use ktree::io::{read_tree_placed, write_bt, write_tree, GridMeta, ReadOptions, WriteOptions};
use ktree::{AnyTree, KTree, NodeState};

/// A small lopsided object in a level-3 universe.
fn object() -> KTree<3> {
    let dense: Vec<bool> = (0..512)
        .map(|i| i % 7 == 0 || (100..140).contains(&i))
        .collect();
    KTree::from_dense(3, &dense).unwrap()
}

/// The world positions of a grid file's voxels, in units of its voxel size (each voxel's lower corner),
/// and the voxel size.
fn world_voxels(path: &Path) -> (BTreeSet<[i64; 3]>, f64) {
    let read = read_tree_placed(path, &ReadOptions::default()).unwrap();
    let AnyTree::K3(tree) = read.tree else {
        panic!("not an octree")
    };
    let meta = read.meta.unwrap_or_default();
    let offset = read.placement.map_or([0; 3], |p| p.offset);
    let corner: [f64; 3] = std::array::from_fn(|a| meta.origin[a] / meta.voxel_size);
    for c in corner {
        assert!(
            (c - c.round()).abs() < 1e-9,
            "{}: origin {corner:?}",
            path.display()
        );
    }
    let mut voxels = BTreeSet::new();
    tree.for_each_leaf(|cell, state| {
        if state != NodeState::Full {
            return;
        }
        let (o, s) = (cell.origin(), cell.side() as u32);
        for x in 0..s {
            for y in 0..s {
                for z in 0..s {
                    let v = [o[0] + x, o[1] + y, o[2] + z];
                    voxels.insert(std::array::from_fn(|a| {
                        corner[a].round() as i64 + i64::from(v[a]) - offset[a]
                    }));
                }
            }
        }
    });
    (voxels, meta.voxel_size)
}

/// The full voxels of a tree moved by `shift`.
fn shifted(tree: &KTree<3>, shift: [i64; 3]) -> BTreeSet<[i64; 3]> {
    let mut voxels = BTreeSet::new();
    tree.for_each_leaf(|cell, state| {
        if state == NodeState::Full {
            let (o, n) = (cell.origin(), cell.side() as u32);
            for x in 0..n {
                for y in 0..n {
                    for z in 0..n {
                        let v = [o[0] + x, o[1] + y, o[2] + z];
                        voxels.insert(std::array::from_fn(|a| i64::from(v[a]) + shift[a]));
                    }
                }
            }
        }
    });
    voxels
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_bt_away_from_the_origin_keeps_its_place_through_bt_and_vdb() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    // Grid index = ktree voxel − offset: negative indices on two axes, as a map from a robot's start.
    let mut bytes = Vec::new();
    write_bt(&mut bytes, &object(), [-40, 16, 8], 0.1).unwrap();
    std::fs::write(p("map.bt"), &bytes).unwrap();
    let original = world_voxels(&p("map.bt"));
    assert!(original.0.iter().any(|v| v[1] < 0), "{:?}", original.0);
    for (from, to) in [
        ("map.bt", "same.bt"),
        ("map.bt", "map.vdb"),
        ("map.vdb", "back.bt"),
        ("back.bt", "again.vdb"),
    ] {
        let (ok, _, err) = ktree(&["convert", s(&p(from)), s(&p(to))]);
        assert!(ok, "{from} -> {to}: {err}");
        assert_eq!(world_voxels(&p(to)), original, "{from} -> {to}");
    }
    // A .ktree keeps the placement as its world frame: back to a .bt, each voxel where it was.
    let (ok, _, err) = ktree(&["convert", s(&p("map.bt")), s(&p("map.ktree"))]);
    assert!(ok && err.is_empty(), "{err}");
    let (ok, _, err) = ktree(&["convert", s(&p("map.ktree")), s(&p("again.bt"))]);
    assert!(ok, "{err}");
    assert_eq!(world_voxels(&p("again.bt")), original);
    // A ray file holds none: the conversion says so.
    let (ok, _, err) = ktree(&["convert", s(&p("map.bt")), s(&p("map.rays"))]);
    assert!(ok, "{err}");
    assert!(
        err.contains("note:") && err.contains("no world placement"),
        "{err}"
    );
}

#[test]
fn a_vdb_origin_goes_to_a_bt_when_it_is_whole_voxels_and_is_refused_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    for (origin, whole) in [([0.5, -1.0, 2.25], true), ([0.1, 0.0, 0.0], false)] {
        let meta = GridMeta {
            voxel_size: 0.25,
            origin,
        };
        let options = WriteOptions {
            offset: [3, -5, 0],
            meta: Some(meta),
            ..WriteOptions::default()
        };
        write_tree(&p("o.vdb"), &AnyTree::K3(object()), &options).unwrap();
        let _ = std::fs::remove_file(p("o.bt"));
        let (ok, _, err) = ktree(&["convert", s(&p("o.vdb")), s(&p("o.bt"))]);
        if whole {
            assert!(ok, "{err}");
            let (bt, size) = world_voxels(&p("o.bt"));
            assert_eq!(size, 0.25);
            // In voxels: the origin / size (2, −4, 9) + grid index (ktree voxel − (3, −5, 0)).
            assert_eq!(bt, shifted(&object(), [-1, 1, 9]));
            assert_eq!(bt, world_voxels(&p("o.vdb")).0);
        } else {
            assert!(!ok);
            assert_eq!(err.trim().lines().count(), 1, "{err}");
            assert!(err.contains("o.bt") && err.contains("multiples"), "{err}");
            assert!(!p("o.bt").exists());
        }
    }
}

#[test]
fn origin_is_honoured_or_refused_for_a_bt_output() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let tree = object();
    tree.save(p("t.ktree")).unwrap();
    // Ktree voxel 0 at world (1, −2, 0.5) with voxels of 0.5: grid index = voxel + (2, −4, 1).
    let (ok, _, err) = ktree(&[
        "convert",
        s(&p("t.ktree")),
        s(&p("t.bt")),
        "--voxel-size",
        "0.5",
        "--origin",
        "1,-2,0.5",
    ]);
    assert!(ok, "{err}");
    let (got, size) = world_voxels(&p("t.bt"));
    assert_eq!(size, 0.5);
    assert_eq!(got, shifted(&tree, [2, -4, 1]));
    // An origin between voxels cannot be written to a .bt.
    let (ok, _, err) = ktree(&[
        "convert",
        s(&p("t.ktree")),
        s(&p("u.bt")),
        "--voxel-size",
        "0.5",
        "--origin",
        "0.3,0,0",
    ]);
    assert!(!ok && err.contains("multiples"), "{err}");
    assert!(!p("u.bt").exists());
}
