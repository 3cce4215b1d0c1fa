//! The operations' command-line interface: `ktree op`, `ktree transform`, `ktree collide`, `ktree mass`
//! on `.ktree` files, checked against the library, and clear errors on bad input.

mod common;

use common::ktree;

use std::path::Path;

use ktree::io::{read_ktree_file, write_ktree_file};
use ktree::ops::{self, Affine, AxisMap};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::KTree;

fn load3(path: &Path) -> KTree<3> {
    read_ktree_file(path).unwrap().into_dim::<3>().unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn op_transform_collide_mass_agree_with_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let a = stack(&ball_rays::<3>(5, [26, 32, 32], 20).unwrap());
    let b = stack(&ball_rays::<3>(5, [40, 32, 32], 18).unwrap());
    let (pa, pb, pc) = (
        dir.path().join("a.ktree"),
        dir.path().join("b.ktree"),
        dir.path().join("c.ktree"),
    );
    write_ktree_file(&pa, &a).unwrap();
    write_ktree_file(&pb, &b).unwrap();

    for (name, op) in [
        ("union", ops::BoolOp::Union),
        ("intersect", ops::BoolOp::Intersection),
        ("diff", ops::BoolOp::Difference),
        ("xor", ops::BoolOp::SymmetricDifference),
    ] {
        let (ok, _, err) = ktree(&["op", name, s(&pa), s(&pb), "--out", s(&pc)]);
        assert!(ok, "{name}: {err}");
        assert_eq!(load3(&pc), ops::boolean(&a, &b, op).unwrap(), "{name}");
    }
    let (ok, _, _) = ktree(&["op", "not", s(&pa), "--out", s(&pc)]);
    assert!(ok);
    assert_eq!(load3(&pc), ops::complement(&a));

    // Exact path: integer translation and quarter turns.
    let (ok, _, err) = ktree(&[
        "transform",
        s(&pa),
        "--rotate",
        "z:90",
        "--translate",
        "1,-2,3",
        "--out",
        s(&pc),
    ]);
    assert!(ok, "{err}");
    let expect = ops::translate(
        &ops::rotate_axes(&a, &AxisMap::quarter_turn(0, 1).unwrap()).unwrap(),
        [1, -2, 3],
    )
    .unwrap();
    assert_eq!(load3(&pc), expect);
    // Affine path: an arbitrary angle.
    let (ok, _, err) = ktree(&["transform", s(&pa), "--rotate", "x:30", "--out", s(&pc)]);
    assert!(ok, "{err}");
    let m = Affine::rotation_about(1, 2, 30.0, Affine::<3>::universe_centre(5)).unwrap();
    assert_eq!(load3(&pc), ops::transform(&a, &m).unwrap());
    // A matrix: translation by (2, 0, 0) in homogeneous form equals the integer translation.
    let (ok, _, err) = ktree(&[
        "transform",
        s(&pa),
        "--matrix",
        "1,0,0,2,0,1,0,0,0,0,1,0,0,0,0,1",
        "--out",
        s(&pc),
    ]);
    assert!(ok, "{err}");
    assert_eq!(load3(&pc), ops::translate(&a, [2, 0, 0]).unwrap());

    // A projective matrix: Meagher's perspective deformation along z.
    let p = ops::Projective::<3>::perspective(5, 2, 40.0).unwrap();
    let text = "40,0,16,0,0,40,16,0,0,0,72,0,0,0,1,40";
    let (ok, _, err) = ktree(&["transform", s(&pa), "--matrix", text, "--out", s(&pc)]);
    assert!(ok, "{err}");
    assert_eq!(load3(&pc), ops::transform_projective(&a, &p).unwrap());

    let (ok, out, _) = ktree(&["collide", s(&pa), s(&pb), "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["collide"], true);
    let overlap = ops::intersection(&a, &b).unwrap();
    assert_eq!(
        v["overlap_voxels"].as_u64().unwrap() as u128,
        overlap.voxel_count()
    );

    let (ok, out, _) = ktree(&["mass", s(&pa), "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["volume"].as_u64().unwrap() as u128, a.voxel_count());
    let (ok, out, _) = ktree(&["mass", s(&pa), "--tolerance", "0.05"]);
    assert!(ok && out.contains("nodes touched"), "{out}");
}

#[test]
fn bad_input_gives_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let p3 = dir.path().join("a3.ktree");
    let p2 = dir.path().join("a2.ktree");
    let p4 = dir.path().join("big.ktree");
    write_ktree_file(&p3, &KTree::<3>::full(3).unwrap()).unwrap();
    write_ktree_file(&p2, &KTree::<2>::full(3).unwrap()).unwrap();
    write_ktree_file(&p4, &KTree::<3>::full(4).unwrap()).unwrap();
    let out = dir.path().join("o.ktree");
    for args in [
        vec!["op", "union", s(&p3), s(&p2), "--out", s(&out)],
        vec!["op", "union", s(&p3), s(&p4), "--out", s(&out)],
        vec!["op", "union", s(&p3), "--out", s(&out)],
        vec![
            "op",
            "union",
            s(&p3),
            "/nonexistent.ktree",
            "--out",
            s(&out),
        ],
        vec!["transform", s(&p3), "--translate", "1,2", "--out", s(&out)],
        vec!["transform", s(&p3), "--rotate", "q:30", "--out", s(&out)],
        vec!["transform", s(&p3), "--matrix", "1,2,3", "--out", s(&out)],
        vec!["transform", s(&p3), "--scale", "-2", "--out", s(&out)],
        vec!["mass", s(&p3), "--tolerance", "-1"],
        vec!["collide", s(&p3), s(&p2)],
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{args:?} should fail");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(err.trim().lines().count() >= 1, "{args:?}");
    }
    assert!(!out.exists(), "no output written on error");
}

#[test]
fn other_dimensions_work_through_the_cli() {
    let dir = tempfile::tempdir().unwrap();
    let a = stack(&ball_rays::<2>(6, [50, 60], 30).unwrap());
    let b = stack(&ball_rays::<2>(6, [70, 60], 24).unwrap());
    let (pa, pb, pc) = (
        dir.path().join("a.ktree"),
        dir.path().join("b.ktree"),
        dir.path().join("c.ktree"),
    );
    write_ktree_file(&pa, &a).unwrap();
    write_ktree_file(&pb, &b).unwrap();
    let load2 = |p: &Path| read_ktree_file(p).unwrap().into_dim::<2>().unwrap();
    let (ok, _, err) = ktree(&["op", "diff", s(&pa), s(&pb), "--out", s(&pc)]);
    assert!(ok, "{err}");
    assert_eq!(load2(&pc), ops::difference(&a, &b).unwrap());
    let (ok, _, err) = ktree(&["transform", s(&pa), "--rotate", "0-1:90", "--out", s(&pc)]);
    assert!(ok, "{err}");
    assert_eq!(
        load2(&pc),
        ops::rotate_axes(&a, &AxisMap::quarter_turn(0, 1).unwrap()).unwrap()
    );
    let (ok, _, err) = ktree(&["transform", s(&pa), "--rotate", "z:30", "--out", s(&pc)]);
    assert!(!ok && err.contains("axis"), "named axes are for 3-D: {err}");
    // A 4-D tree's mass.
    let t4 = stack(&ball_rays::<4>(3, [8, 8, 8, 8], 6).unwrap());
    let p4 = dir.path().join("t4.ktree");
    write_ktree_file(&p4, &t4).unwrap();
    let (ok, out, _) = ktree(&["mass", s(&p4), "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["k"], 4);
    assert_eq!(v["volume"].as_u64().unwrap() as u128, t4.voxel_count());
}
