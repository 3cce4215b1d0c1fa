//! `ktree rays` and `ktree voxelize` from the outside: files written equal the library's result; bad input
//! exits non-zero with a one-line message.

mod common;

use common::ktree;

use ktree::io::{read_ktree_file, read_rays_file};
use ktree::solid::{Frame, Quadric, Rational, Sample};
use ktree::AnyRaySet;

#[test]
fn rays_writes_the_library_result() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball.txt");
    let o = out.to_str().unwrap();
    let (ok, _, err) = ktree(&[
        "rays", "--solid", "ball", "--center", "8,8.5,7", "--radius", "5.25", "--level", "4",
        "--out", o,
    ]);
    assert!(ok, "{err}");
    let c = ["8", "8.5", "7"].map(|x| x.parse::<Rational>().unwrap());
    let want = Quadric::<3>::ball(c, "5.25".parse().unwrap(), Frame::Voxel)
        .unwrap()
        .to_rays(4, Sample::Centre, false)
        .unwrap();
    match read_rays_file(&out).unwrap() {
        AnyRaySet::K3(got) => assert_eq!(got, want),
        _ => panic!("wrong K"),
    }
    // The same as a tree, by extension.
    let tree = dir.path().join("ball.ktree");
    let (ok, _, err) = ktree(&[
        "rays",
        "--center",
        "8,8.5,7",
        "--radius",
        "5.25",
        "--level",
        "4",
        "--out",
        tree.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(
        read_ktree_file(&tree).unwrap().counts().full as usize,
        ktree::stacking::paper::stack(&want).counts().full as usize
    );
}

/// Vectors and numbers beginning with a minus are the values of their flags, given with a space.
#[test]
fn negative_vectors_and_numbers_are_values() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("h.txt");
    let o = out.to_str().unwrap();
    let (ok, _, err) = ktree(&[
        "rays",
        "--solid",
        "half-space",
        "--normal",
        "-1,0,-1/2",
        "--offset",
        "-3",
        "--level",
        "4",
        "--out",
        o,
    ]);
    assert!(ok, "{err}");
    let n = ["-1", "0", "-1/2"].map(|x| x.parse::<Rational>().unwrap());
    let want = Quadric::<3>::half_space(n, "-3".parse().unwrap(), Frame::Voxel)
        .unwrap()
        .to_rays(4, Sample::Centre, false)
        .unwrap();
    match read_rays_file(&out).unwrap() {
        AnyRaySet::K3(got) => {
            assert!(got.voxel_count() > 0);
            assert_eq!(got, want);
        }
        _ => panic!("wrong K"),
    }
}

#[test]
fn bad_input_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("x.txt");
    let o = o.to_str().unwrap();
    for args in [
        vec!["rays", "--solid", "ball", "--level", "4", "--out", o],
        vec![
            "rays", "--solid", "blob", "--radius", "1", "--level", "4", "--out", o,
        ],
        vec![
            "rays", "--radius", "1", "--center", "1,2", "--level", "4", "--out", o,
        ],
        vec!["rays", "--radius", "x", "--level", "4", "--out", o],
        vec!["rays", "--radius", "1", "--level", "40", "--out", o],
        vec![
            "rays", "-k", "5", "--radius", "1", "--level", "4", "--out", o,
        ],
        vec![
            "voxelize",
            "/nonexistent/m.obj",
            "--level",
            "4",
            "--fit",
            "--out",
            o,
        ],
        vec!["voxelize", "m.xyz", "--level", "4", "--out", o],
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{args:?} should fail");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("ktree: "), "{err}");
    }
}

#[test]
fn voxelize_meshes_and_volumes() {
    let data = common::data_dir();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bunny.txt");
    let (ok, stdout, err) = ktree(&[
        "voxelize",
        data.join("meshes/bunny_npm.obj").to_str().unwrap(),
        "--level",
        "5",
        "--fit",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    // --fit prints the transform it chose; feeding it back gives the same rays.
    let t = stdout
        .lines()
        .find_map(|l| l.strip_prefix("--fit chose --transform "))
        .expect("transform printed");
    let out2 = dir.path().join("bunny2.txt");
    let (ok, _, err) = ktree(&[
        "voxelize",
        data.join("meshes/bunny_npm.obj").to_str().unwrap(),
        "--level",
        "5",
        "--transform",
        t,
        "--out",
        out2.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&out2).unwrap());
    let skull = dir.path().join("skull.ktree");
    let (ok, _, err) = ktree(&[
        "voxelize",
        data.join("volumes/skull_grey.json").to_str().unwrap(),
        "--threshold",
        "29000",
        "--out",
        skull.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(read_ktree_file(&skull).unwrap().level(), 6);
}
