//! `ktree project` and `ktree slice`: the trees written are the library's (`ops::project`, `ops::slice`) of
//! the same file; a `.png` map has map_server's grey levels where the projection is occupied and free, rows
//! from the largest y down, and its `.yaml` names the image, resolution and origin; bad axes and positions
//! are one-line errors.

mod common;

use common::{data_dir, ktree, run};
use ktree::io::read_ktree_file;
use ktree::ops::{project, slice};
use ktree::KTree;

#[test]
fn projections_slices_and_maps_of_the_skull() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let grey = data_dir().join("volumes/skull_grey.json");
    run(&[
        "voxelize",
        grey.to_str().unwrap(),
        "--threshold",
        "29000",
        "--out",
        &s("skull.ktree"),
    ]);
    let skull =
        KTree::<3>::try_from(read_ktree_file(dir.path().join("skull.ktree").as_path()).unwrap())
            .unwrap();

    run(&[
        "project",
        &s("skull.ktree"),
        "--axis",
        "z",
        "--range",
        "20:40",
        "--out",
        &s("p.ktree"),
    ]);
    let got = KTree::<2>::try_from(read_ktree_file(dir.path().join("p.ktree").as_path()).unwrap())
        .unwrap();
    let want: KTree<2> = project(&skull, 2, 20..41).unwrap();
    assert_eq!(got, want);
    assert!(got.voxel_count() > 0);

    run(&[
        "slice",
        &s("skull.ktree"),
        "--axis",
        "1",
        "--at",
        "31",
        "--out",
        &s("s.ktree"),
    ]);
    let got = KTree::<2>::try_from(read_ktree_file(dir.path().join("s.ktree").as_path()).unwrap())
        .unwrap();
    assert_eq!(got, slice::<3, 2, _>(&skull, 1, 31).unwrap());

    // The map: pixel (x, row) is cell (x, 63 − row); occupied 0, free 254.
    run(&[
        "project",
        &s("skull.ktree"),
        "--axis",
        "z",
        "--range",
        "20:40",
        "--out",
        &s("floor.png"),
        "--voxel-size",
        "0.05",
        "--origin",
        "-1.5,2",
    ]);
    let image = image::open(dir.path().join("floor.png"))
        .unwrap()
        .to_luma8();
    assert_eq!(image.dimensions(), (64, 64));
    for (x, row, p) in image.enumerate_pixels() {
        let occupied = want.contains([x, 63 - row]);
        assert_eq!(p.0[0], if occupied { 0 } else { 254 }, "pixel ({x}, {row})");
    }
    let yaml = std::fs::read_to_string(dir.path().join("floor.yaml")).unwrap();
    for line in [
        "image: floor.png",
        "resolution: 0.05",
        "origin: [-1.5, 2.0, 0.0]",
        "negate: 0",
    ] {
        assert!(yaml.contains(line), "{yaml}");
    }
}

#[test]
fn bad_axes_and_positions_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let grey = data_dir().join("volumes/skull_grey.json");
    run(&[
        "voxelize",
        grey.to_str().unwrap(),
        "--threshold",
        "29000",
        "--out",
        &s("skull.ktree"),
    ]);
    let (ok, _, err) = ktree(&[
        "slice",
        &s("skull.ktree"),
        "--axis",
        "z",
        "--at",
        "64",
        "--out",
        &s("o.ktree"),
    ]);
    assert!(!ok && err.contains("--at 64"), "{err}");
    let (ok, _, err) = ktree(&[
        "project",
        &s("skull.ktree"),
        "--axis",
        "w",
        "--out",
        &s("o.ktree"),
    ]);
    assert!(!ok && err.contains("axis 3"), "{err}");
    let (ok, _, err) = ktree(&[
        "project",
        &s("skull.ktree"),
        "--axis",
        "q",
        "--out",
        &s("o.ktree"),
    ]);
    assert!(!ok && err.contains("'q'"), "{err}");
    let (ok, _, err) = ktree(&[
        "project",
        &s("skull.ktree"),
        "--axis",
        "x",
        "--range",
        "9:3",
        "--out",
        &s("o.ktree"),
    ]);
    assert!(!ok && err.contains("9:3"), "{err}");
    assert!(!dir.path().join("o.ktree").exists());
}

#[test]
fn the_slice_of_a_tree_with_values_keeps_each_voxels_value() {
    use ktree::io::ktree::v3::{read_valued_ktree, write_valued_ktree_file};
    use ktree::ops::slice_values;
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    // Labels 1 … 5 in slabs along z, some voxels empty: an 8³ label volume.
    let dense: Vec<Option<u16>> = (0..512u32)
        .map(|i| {
            let (x, z) = (i % 8, i / 64);
            (x != 3).then_some(1 + (z as u16) % 5)
        })
        .collect();
    let labels = KTree::<3, u16>::from_dense_values(3, &dense).unwrap();
    write_valued_ktree_file(dir.path().join("labels.ktree").as_path(), &labels).unwrap();
    for (axis, name, at) in [(0, "x", 5u32), (2, "z", 6), (1, "1", 0)] {
        let out = s(&format!("s{axis}.ktree"));
        let said = run(&[
            "slice",
            &s("labels.ktree"),
            "--axis",
            name,
            "--at",
            &at.to_string(),
            "--out",
            &out,
        ]);
        assert!(said.contains("uint16"), "{said}");
        let bytes = std::fs::read(&out).unwrap();
        let got: KTree<2, u16> = read_valued_ktree(&bytes, &out).unwrap();
        assert_eq!(got, slice_values::<3, 2, _>(&labels, axis, at).unwrap());
        assert!(got.voxel_count() > 0);
    }
    // Values do not go to a picture.
    let (ok, _, err) = ktree(&[
        "slice",
        &s("labels.ktree"),
        "--axis",
        "z",
        "--at",
        "1",
        "--out",
        &s("s.png"),
    ]);
    assert!(
        !ok && err.contains(".ktree") && err.lines().count() == 1,
        "{err}"
    );
}
