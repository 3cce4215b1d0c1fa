//! Where a tree's voxels are in the world (the world frame a `.ktree` keeps) survives the commands that
//! write trees: `op` (streamed from the files' maps, or in memory), `transform` and `convert` keep it and
//! the notes; `convert` writes a grid's placement into the `.ktree` and places meshes and grids by it; a
//! Boolean of trees kept in different frames is refused, the output untouched.

mod common;

use std::path::Path;

use common::{ktree, run};
use ktree::io::{read_ktree_file_framed, write_ktree_file_framed, write_ktree_v1, Notes};
use ktree::space::WorldFrame;
use ktree::{AnyTree, KTree};

const FRAME: WorldFrame = WorldFrame {
    voxel_size: 0.25,
    origin: [1.0, -3.5, 0.75],
};

/// Two overlapping octrees of level 3.
fn pair() -> (KTree<3>, KTree<3>) {
    let a: Vec<bool> = (0..512).map(|i| i % 7 == 0 || i < 100).collect();
    let b: Vec<bool> = (0..512).map(|i| i % 5 == 0 || i > 400).collect();
    (
        KTree::from_dense(3, &a).unwrap(),
        KTree::from_dense(3, &b).unwrap(),
    )
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn notes(text: &str) -> Notes {
    Notes::from([("source".to_string(), text.to_string())])
}

/// The tree, frame and notes of a `.ktree` file.
fn framed(path: &Path) -> (AnyTree, Option<WorldFrame>, Notes) {
    read_ktree_file_framed(path).unwrap()
}

#[test]
fn op_keeps_the_frame_the_inputs_share_streamed_and_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let (a, b) = pair();
    write_ktree_file_framed(&p("a.ktree"), &a, Some(&FRAME), &notes("a")).unwrap();
    write_ktree_file_framed(&p("b.ktree"), &b, None, &Notes::new()).unwrap();
    // Streamed from the maps (both version 2): the frame of the one that keeps one, its notes.
    for (op, want) in [
        ("union", ktree::ops::union(&a, &b).unwrap()),
        ("diff", ktree::ops::difference(&a, &b).unwrap()),
    ] {
        let out = p(&format!("{op}.ktree"));
        run(&[
            "op",
            op,
            s(&p("a.ktree")),
            s(&p("b.ktree")),
            "--out",
            s(&out),
        ]);
        assert_eq!(
            framed(&out),
            (AnyTree::K3(want), Some(FRAME), notes("a")),
            "{op}"
        );
    }
    run(&["op", "not", s(&p("a.ktree")), "--out", s(&p("not.ktree"))]);
    assert_eq!(
        framed(&p("not.ktree")),
        (
            AnyTree::K3(ktree::ops::complement(&a)),
            Some(FRAME),
            notes("a")
        )
    );
    // In memory (the second a version 1 file): the same.
    let mut v1 = Vec::new();
    write_ktree_v1(&mut v1, &b).unwrap();
    std::fs::write(p("b1.ktree"), v1).unwrap();
    run(&[
        "op",
        "xor",
        s(&p("b1.ktree")),
        s(&p("a.ktree")),
        "--out",
        s(&p("x.ktree")),
    ]);
    assert_eq!(
        framed(&p("x.ktree")),
        (
            AnyTree::K3(ktree::ops::symmetric_difference(&b, &a).unwrap()),
            Some(FRAME),
            notes("a")
        )
    );
    // Trees without frames give a tree without one, byte for byte the file of before.
    write_ktree_file_framed(&p("a0.ktree"), &a, None, &Notes::new()).unwrap();
    run(&[
        "op",
        "union",
        s(&p("a0.ktree")),
        s(&p("b.ktree")),
        "--out",
        s(&p("u0.ktree")),
    ]);
    let plain = p("plain.ktree");
    ktree::io::write_ktree_file(&plain, &ktree::ops::union(&a, &b).unwrap()).unwrap();
    assert_eq!(
        std::fs::read(p("u0.ktree")).unwrap(),
        std::fs::read(plain).unwrap()
    );
}

#[test]
fn a_boolean_of_trees_in_different_frames_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let (a, b) = pair();
    let other = WorldFrame {
        voxel_size: 0.5,
        ..FRAME
    };
    write_ktree_file_framed(&p("a.ktree"), &a, Some(&FRAME), &Notes::new()).unwrap();
    write_ktree_file_framed(&p("b.ktree"), &b, Some(&other), &Notes::new()).unwrap();
    std::fs::write(p("out.ktree"), b"before").unwrap();
    let (pa, pb, out) = (p("a.ktree"), p("b.ktree"), p("out.ktree"));
    // Streamed, and in memory (a version 1 output).
    for extra in [&[][..], &["--format-version", "1"][..]] {
        let mut args = vec!["op", "union", s(&pa), s(&pb), "--out", s(&out)];
        args.extend_from_slice(extra);
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{extra:?}");
        assert!(
            err.contains("a.ktree") && err.contains("b.ktree") && err.contains("frame"),
            "{err}"
        );
        assert_eq!(std::fs::read(p("out.ktree")).unwrap(), b"before");
    }
}

#[test]
fn a_version_1_output_says_it_keeps_no_frame() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let (a, _) = pair();
    write_ktree_file_framed(&p("a.ktree"), &a, Some(&FRAME), &Notes::new()).unwrap();
    let (ok, _, err) = ktree(&[
        "op",
        "not",
        s(&p("a.ktree")),
        "--out",
        s(&p("n.ktree")),
        "--format-version",
        "1",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("note:") && err.contains("no world frame"),
        "{err}"
    );
    assert_eq!(framed(&p("n.ktree")).1, None);
}

#[test]
fn transform_keeps_the_frame_and_the_notes() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let (a, _) = pair();
    write_ktree_file_framed(&p("a.ktree"), &a, Some(&FRAME), &notes("scan")).unwrap();
    run(&[
        "transform",
        s(&p("a.ktree")),
        "--translate",
        "1,0,2",
        "--out",
        s(&p("t.ktree")),
    ]);
    let (moved, frame, kept) = framed(&p("t.ktree"));
    assert_eq!((frame, kept), (Some(FRAME), notes("scan")));
    let AnyTree::K3(moved) = moved else {
        panic!("not an octree")
    };
    assert_eq!(moved.voxel_count(), {
        // The voxels that stay inside the universe.
        let mut n = 0;
        for z in 0..8u32 {
            for y in 0..8u32 {
                for x in 0..8u32 {
                    if a.contains([x, y, z]) && x + 1 < 8 && z + 2 < 8 {
                        n += 1;
                    }
                }
            }
        }
        n
    });
}

/// The smallest vertex coordinate of an `.obj` along each axis.
fn lowest_vertex(obj: &Path) -> [f64; 3] {
    let mut low = [f64::INFINITY; 3];
    for line in std::fs::read_to_string(obj).unwrap().lines() {
        if let Some(rest) = line.strip_prefix("v ") {
            for (l, c) in low.iter_mut().zip(rest.split_whitespace()) {
                *l = l.min(c.parse::<f64>().unwrap());
            }
        }
    }
    low
}

#[test]
fn convert_keeps_a_grids_placement_in_the_ktree_and_places_meshes_by_it() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    // One voxel at (2, 1, 3) of a level-2 tree.
    let dense: Vec<bool> = (0..64).map(|i| i == 2 + 4 + 3 * 16).collect();
    let one = KTree::<3>::from_dense(2, &dense).unwrap();
    write_ktree_file_framed(&p("one.ktree"), &one, Some(&FRAME), &notes("one")).unwrap();
    // Its mesh is in the world: the voxel's lower corner at origin + size · (2, 1, 3).
    run(&["convert", s(&p("one.ktree")), s(&p("one.obj"))]);
    let low = lowest_vertex(&p("one.obj"));
    let want = FRAME.corner_of([2, 1, 3]);
    for a in 0..3 {
        assert!((low[a] - want[a]).abs() < 1e-9, "{low:?} against {want:?}");
    }
    // To a grid with a placement and back: each voxel in the same world place.
    run(&["convert", s(&p("one.ktree")), s(&p("one.vdb"))]);
    run(&["convert", s(&p("one.vdb")), s(&p("back.ktree"))]);
    let (tree, frame, _) = framed(&p("back.ktree"));
    let frame = frame.expect("the grid's placement kept");
    let AnyTree::K3(tree) = tree else {
        panic!("not an octree")
    };
    let cells: Vec<[u32; 3]> = tree.full_cells().map(|c| c.origin()).collect();
    assert_eq!(cells.len(), 1);
    let at = frame.corner_of(cells[0].map(i64::from));
    for a in 0..3 {
        assert!((at[a] - want[a]).abs() < 1e-9, "{at:?} against {want:?}");
    }
    assert_eq!(frame.voxel_size, FRAME.voxel_size);
    // A .ktree to a .ktree keeps the frame and the notes, a unit frame at the origin too.
    run(&["convert", s(&p("one.ktree")), s(&p("copy.ktree"))]);
    assert_eq!(
        framed(&p("copy.ktree")),
        (AnyTree::K3(one.clone()), Some(FRAME), notes("one"))
    );
    let unit = WorldFrame::default();
    write_ktree_file_framed(&p("unit.ktree"), &one, Some(&unit), &Notes::new()).unwrap();
    run(&["convert", s(&p("unit.ktree")), s(&p("unit-copy.ktree"))]);
    assert_eq!(framed(&p("unit-copy.ktree")).1, Some(unit));
}

#[test]
fn voxelize_keeps_where_a_clouds_and_a_placed_meshs_voxels_are() {
    use ktree::io::ktree::v3::read_any_ktree_framed;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    // A cloud: voxel (0, 0, 0) has its lower corner at the points' minimum corner.
    std::fs::write(p("c.xyz"), "1.5 -2 0.25\n2.5 -1 0.75\n1.6 -2 0.3\n").unwrap();
    run(&[
        "voxelize",
        s(&p("c.xyz")),
        "--voxel-size",
        "0.5",
        "--out",
        s(&p("c.ktree")),
    ]);
    let cloud = WorldFrame {
        voxel_size: 0.5,
        origin: [1.5, -2.0, 0.25],
    };
    assert_eq!(framed(&p("c.ktree")).1, Some(cloud));
    run(&[
        "voxelize",
        s(&p("c.xyz")),
        "--voxel-size",
        "0.5",
        "--value",
        "count",
        "--out",
        s(&p("n.ktree")),
    ]);
    let bytes = std::fs::read(p("n.ktree")).unwrap();
    assert_eq!(read_any_ktree_framed(&bytes, "n").unwrap().1, Some(cloud));
    // A mesh placed by --transform s,t (voxel = s·v + t): voxels of 1/s, voxel 0 at −t/s.
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n\
                f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
    std::fs::write(p("cube.obj"), cube).unwrap();
    run(&[
        "voxelize",
        s(&p("cube.obj")),
        "--level",
        "3",
        "--transform",
        "4,2,2,2",
        "--out",
        s(&p("cube.ktree")),
    ]);
    let (tree, frame, _) = framed(&p("cube.ktree"));
    assert_eq!(
        frame,
        Some(WorldFrame {
            voxel_size: 0.25,
            origin: [-0.5; 3],
        })
    );
    let AnyTree::K3(tree) = tree else {
        panic!("not an octree")
    };
    assert_eq!(tree.voxel_count(), 64);
    // Its mesh is the unit cube again, in the world.
    run(&["convert", s(&p("cube.ktree")), s(&p("cube-out.obj"))]);
    assert_eq!(lowest_vertex(&p("cube-out.obj")), [0.0; 3]);
    // Fitted into the universe, a mesh keeps no frame.
    run(&[
        "voxelize",
        s(&p("cube.obj")),
        "--level",
        "3",
        "--fit",
        "--out",
        s(&p("fit.ktree")),
    ]);
    assert_eq!(framed(&p("fit.ktree")).1, None);
}

#[test]
fn stats_gives_the_world_frame_a_file_keeps() {
    use ktree::io::ktree::v3::write_valued_ktree_file_noted;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let (a, _) = pair();
    write_ktree_file_framed(&p("a.ktree"), &a, Some(&FRAME), &Notes::new()).unwrap();
    write_ktree_file_framed(&p("plain.ktree"), &a, None, &Notes::new()).unwrap();
    let labels: Vec<Option<u8>> = (0..64).map(|i| (i % 3 != 0).then_some(1)).collect();
    let valued = KTree::<3, u8>::from_dense_values(2, &labels).unwrap();
    write_valued_ktree_file_noted(&p("v.ktree"), &valued, Some(&FRAME), &Notes::new()).unwrap();
    for file in ["a.ktree", "v.ktree"] {
        let json: serde_json::Value =
            serde_json::from_str(&run(&["stats", s(&p(file)), "--json"])).unwrap();
        assert_eq!(json["world_frame"]["voxel_size"], 0.25, "{file}");
        assert_eq!(
            json["world_frame"]["origin"],
            serde_json::json!([1.0, -3.5, 0.75]),
            "{file}"
        );
        let text = run(&["stats", s(&p(file))]);
        assert!(
            text.contains("voxels of 0.25, voxel 0 at [1.0, -3.5, 0.75]"),
            "{text}"
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&run(&["stats", s(&p("plain.ktree")), "--json"])).unwrap();
    assert!(json.get("world_frame").is_none(), "{json}");
}
