//! The shape commands: `ktree morph`, `ktree components`, and the measures `ktree stats` and `ktree mass`
//! report, checked against the library; bad input is a clear error.

mod common;

use common::ktree;

use std::path::Path;

use ktree::io::{read_ktree_file, write_ktree_file};
use ktree::rays::ball_rays;
use ktree::shape::Element;
use ktree::{KTree, Ray, RaySet};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn load3(path: &Path) -> KTree<3> {
    read_ktree_file(path).unwrap().into_dim::<3>().unwrap()
}

#[test]
fn morph_agrees_with_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let a = KTree::from_rays(&ball_rays::<3>(5, [26, 32, 32], 60).unwrap());
    let (pa, pb) = (dir.path().join("a.ktree"), dir.path().join("b.ktree"));
    write_ktree_file(&pa, &a).unwrap();
    for (name, shape, element) in [
        ("dilate", "ball", Element::Ball),
        ("erode", "box", Element::Box),
        ("open", "cross", Element::Cross),
        ("close", "ball", Element::Ball),
    ] {
        let (ok, out, err) = ktree(&[
            "morph",
            s(&pa),
            name,
            "--radius",
            "2.5",
            "--shape",
            shape,
            "--out",
            s(&pb),
        ]);
        assert!(ok, "{name}: {err}");
        assert!(out.contains("voxels"), "{out}");
        let expect = match name {
            "dilate" => a.dilate(2.5, element),
            "erode" => a.erode(2.5, element),
            "open" => a.opening(2.5, element),
            _ => a.closing(2.5, element),
        }
        .unwrap();
        assert_eq!(load3(&pb), expect, "{name}");
    }
    // The shape defaults to the ball.
    let (ok, _, err) = ktree(&["morph", s(&pa), "dilate", "--radius", "1", "--out", s(&pb)]);
    assert!(ok, "{err}");
    assert_eq!(load3(&pb), a.dilate(1.0, Element::Ball).unwrap());
    // Bad input.
    let (ok, _, err) = ktree(&["morph", s(&pa), "dilate", "--radius", "-1", "--out", s(&pb)]);
    assert!(!ok && err.contains("--radius"), "{err}");
    let (ok, _, err) = ktree(&[
        "morph",
        s(&pa),
        "dilate",
        "--radius",
        "1",
        "--shape",
        "star",
        "--out",
        s(&pb),
    ]);
    assert!(!ok && err.contains("star"), "{err}");
    let missing = dir.path().join("missing.ktree");
    let (ok, _, err) = ktree(&[
        "morph",
        s(&missing),
        "erode",
        "--radius",
        "1",
        "--out",
        s(&pb),
    ]);
    assert!(!ok && err.contains("missing.ktree"), "{err}");
}

#[test]
fn components_and_measures() {
    let dir = tempfile::tempdir().unwrap();
    // Two voxel blocks touching at a corner plus a far voxel, in 2-D.
    let rays = RaySet::<2>::from_rays(
        3,
        [
            Ray::new([0, 0], 2),
            Ray::new([1, 0], 2),
            Ray::new([2, 2], 3),
            Ray::new([6, 6], 7),
        ],
    )
    .unwrap();
    let tree = KTree::from_rays(&rays);
    let pa = dir.path().join("a.ktree");
    write_ktree_file(&pa, &tree).unwrap();
    let (ok, out, err) = ktree(&["components", s(&pa), "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["count"], 3);
    assert_eq!(v["sizes"], serde_json::json!([4, 1, 1]));
    let out_dir = dir.path().join("parts");
    let (ok, out, err) = ktree(&[
        "components",
        s(&pa),
        "--connectivity",
        "2",
        "--out-dir",
        s(&out_dir),
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["count"], 2);
    let parts = tree.components(2).unwrap();
    for (i, part) in parts.iter().enumerate() {
        let file = out_dir.join(format!("component-{}.ktree", i + 1));
        assert_eq!(v["files"][i], s(&file));
        let back = read_ktree_file(&file).unwrap().into_dim::<2>().unwrap();
        assert_eq!(back, part.tree);
    }
    let (ok, out, _) = ktree(&["components", s(&pa)]);
    assert!(ok && out.starts_with("3 components"), "{out}");
    let (ok, _, err) = ktree(&["components", s(&pa), "--connectivity", "3"]);
    assert!(
        !ok && err.contains("a.ktree") && err.contains("connectivity"),
        "{err}"
    );

    // stats and mass report the surface area and the Euler number, in text and JSON.
    for (command, format) in [("stats", "2"), ("stats", "1"), ("mass", "2"), ("mass", "1")] {
        let pf = dir.path().join(format!("f{format}.ktree"));
        let (ok, _, err) = ktree(&[
            "op",
            "not",
            s(&pa),
            "--out",
            s(&pf),
            "--format-version",
            format,
        ]);
        assert!(ok, "{err}");
        let complement = ktree::ops::complement(&tree);
        // `stats` measures when asked; `mass` always does.
        let mut args = vec![command, s(&pf)];
        if command == "stats" {
            args.push("--measures");
        }
        let (ok, out, err) = ktree(&[&args[..], &["--json"]].concat());
        assert!(ok, "{command}: {err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(
            v["surface_area"],
            complement.surface_area() as u64,
            "{command}"
        );
        assert_eq!(
            v["euler_number"],
            complement.euler_number(2).unwrap(),
            "{command}"
        );
        let (ok, out, _) = ktree(&args);
        assert!(
            ok && out.contains(&format!("{} faces", complement.surface_area())),
            "{out}"
        );
    }
    // A 4-D tree has a surface area and no Euler number key.
    let p4 = dir.path().join("t4.ktree");
    write_ktree_file(&p4, &KTree::<4>::full(1).unwrap()).unwrap();
    let (ok, out, err) = ktree(&["stats", s(&p4), "--json", "--measures"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["surface_area"], 2 * 4 * 8);
    assert!(v.get("euler_number").is_none());
    assert_eq!(v["nodes"], 1, "the counts are still there");
}
