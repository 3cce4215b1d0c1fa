//! Trees with values end to end: a label volume made in the test (raw + JSON) through `ktree voxelize
//! --labels`, `ktree stats --json` (per-value voxels, boxes, centroids, surface areas against a count over
//! the samples), and `ktree select --value/--range`, whose trees must be byte for byte those of `ktree
//! voxelize --label` and `--threshold` on the same volume (the binary path, independent of the values).

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::{ktree, run};

/// A 5 × 6 × 7 volume of labels 0 (background), 1, 2, 3 and 300 in blobs and stripes.
fn labels() -> ([usize; 3], Vec<u16>) {
    let shape = [5usize, 6, 7];
    let mut v = Vec::new();
    for z in 0..shape[2] {
        for y in 0..shape[1] {
            for x in 0..shape[0] {
                let label = if (x + y) % 4 == 0 && z > 1 {
                    3
                } else if x < 2 && y < 3 {
                    1
                } else if z == 6 {
                    300
                } else if x + z > 7 {
                    2
                } else {
                    0
                };
                v.push(label);
            }
        }
    }
    (shape, v)
}

fn write_volume(dir: &Path, shape: [usize; 3], values: &[u16]) -> std::path::PathBuf {
    let raw: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join("labels.raw"), raw).unwrap();
    let json = dir.join("labels.json");
    std::fs::write(
        &json,
        format!(
            r#"{{"file": "labels.raw", "dtype": "uint16", "endianness": "little", "shape_xyz": [{}, {}, {}]}}"#,
            shape[0], shape[1], shape[2]
        ),
    )
    .unwrap();
    json
}

/// Voxels, box `[lo, hi)` and the sums of the centres of one label, counted on the samples.
type Measured = (u64, [usize; 3], [usize; 3], [f64; 3]);

#[test]
#[allow(clippy::needless_range_loop)] // Loops over the axes index several arrays.
fn a_label_volume_becomes_one_tree_whose_values_select_and_measure_as_the_samples() {
    let dir = tempfile::tempdir().unwrap();
    let (shape, values) = labels();
    let json = write_volume(dir.path(), shape, &values);
    let labels = dir.path().join("labels.ktree");
    let p = |name: &str| dir.path().join(name).display().to_string();
    run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--labels",
        "--out",
        labels.to_str().unwrap(),
    ]);

    // Per-value statistics against the samples.
    let stats: serde_json::Value =
        serde_json::from_str(&run(&["stats", labels.to_str().unwrap(), "--json"])).unwrap();
    assert_eq!(stats["dtype"], "uint16");
    assert_eq!(stats["level"], 3);
    let mut want: BTreeMap<u16, Measured> = BTreeMap::new();
    let mut inside = 0u64;
    for (i, &v) in values.iter().enumerate() {
        if v == 0 {
            continue;
        }
        inside += 1;
        let q = [
            i % shape[0],
            i / shape[0] % shape[1],
            i / (shape[0] * shape[1]),
        ];
        let e = want
            .entry(v)
            .or_insert((0, [usize::MAX; 3], [0; 3], [0.0; 3]));
        e.0 += 1;
        for a in 0..3 {
            e.1[a] = e.1[a].min(q[a]);
            e.2[a] = e.2[a].max(q[a] + 1);
            e.3[a] += q[a] as f64 + 0.5;
        }
    }
    assert_eq!(stats["voxels"], inside);
    let got = stats["values"].as_object().unwrap();
    assert_eq!(got.len(), want.len());
    for (label, (n, lo, hi, sums)) in &want {
        let s = &got[&label.to_string()];
        assert_eq!(s["voxels"], *n, "label {label}");
        assert_eq!(
            s["bounding_box"],
            serde_json::json!([lo, hi]),
            "label {label}"
        );
        for a in 0..3 {
            let c = s["centroid"][a].as_f64().unwrap();
            assert!((c - sums[a] / *n as f64).abs() < 1e-9, "label {label}");
        }
    }

    // select --value 3 is the binary tree of --label 3, byte for byte; --range 2:3 that of the union.
    run(&[
        "select",
        labels.to_str().unwrap(),
        "--value",
        "3",
        "--out",
        &p("three.ktree"),
    ]);
    run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--label",
        "3",
        "--out",
        &p("three_direct.ktree"),
    ]);
    assert_eq!(
        std::fs::read(p("three.ktree")).unwrap(),
        std::fs::read(p("three_direct.ktree")).unwrap()
    );
    run(&[
        "select",
        labels.to_str().unwrap(),
        "--range",
        "1:300",
        "--out",
        &p("all.ktree"),
    ]);
    run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--threshold",
        "1",
        "--out",
        &p("all_direct.ktree"),
    ]);
    assert_eq!(
        std::fs::read(p("all.ktree")).unwrap(),
        std::fs::read(p("all_direct.ktree")).unwrap()
    );
    // The surface area of label 3 is that of its binary tree.
    let three: serde_json::Value =
        serde_json::from_str(&run(&["stats", &p("three.ktree"), "--json", "--measures"])).unwrap();
    assert_eq!(got["3"]["surface_area"], three["surface_area"]);
}

#[test]
fn values_on_the_command_line_fail_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let (shape, values) = labels();
    let json = write_volume(dir.path(), shape, &values);
    run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--labels",
        "--out",
        &p("l.ktree"),
    ]);
    // A value of another type, a range without a colon, a tree without values.
    let (ok, _, err) = ktree(&[
        "select",
        &p("l.ktree"),
        "--value",
        "70000",
        "--out",
        &p("x.ktree"),
    ]);
    assert!(!ok && err.contains("uint16"), "{err}");
    let (ok, _, err) = ktree(&[
        "select",
        &p("l.ktree"),
        "--range",
        "3",
        "--out",
        &p("x.ktree"),
    ]);
    assert!(!ok && err.contains("LO:HI"), "{err}");
    run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--label",
        "3",
        "--out",
        &p("b.ktree"),
    ]);
    let (ok, _, err) = ktree(&[
        "select",
        &p("b.ktree"),
        "--value",
        "3",
        "--out",
        &p("x.ktree"),
    ]);
    assert!(!ok && err.contains("no values"), "{err}");
    // A label that does not fit the type asked for, named with its sample.
    let (ok, _, err) = ktree(&[
        "voxelize",
        json.to_str().unwrap(),
        "--labels",
        "--dtype",
        "uint8",
        "--out",
        &p("u8.ktree"),
    ]);
    assert!(!ok && err.contains("300"), "{err}");
    // A volume of floats is not labels.
    let dir2 = tempfile::tempdir().unwrap();
    let raw: Vec<u8> = [0.5f32, 1.0].iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir2.path().join("f.raw"), raw).unwrap();
    let f = dir2.path().join("f.json");
    std::fs::write(
        &f,
        r#"{"file": "f.raw", "dtype": "float32", "endianness": "little", "shape_xyz": [2, 1, 1]}"#,
    )
    .unwrap();
    let (ok, _, err) = ktree(&[
        "voxelize",
        f.to_str().unwrap(),
        "--labels",
        "--out",
        &p("f.ktree"),
    ]);
    assert!(
        !ok && err.contains("(0, 0, 0)") && err.contains("whole numbers"),
        "{err}"
    );
    // The binary readers name the value type.
    std::fs::write(p("rays.csv"), "0,0,0,1,0,0\n").unwrap();
    let (ok, _, err) = ktree(&["raycast", &p("l.ktree"), "--rays", &p("rays.csv")]);
    assert!(!ok && err.contains("uint16"), "{err}");
}

#[test]
fn queries_of_a_tree_with_values_give_each_points_value() {
    // Values alone are read from the file in place; with distances, the tree is loaded.
    use ktree::io::ktree::v3::write_valued_ktree_file;
    use ktree::KTree;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    // Labels 0..5 in a 8 × 8 × 8 universe (0 empty), colours in a 4 × 4 quadtree.
    let dense: Vec<Option<u16>> = (0..512u16)
        .map(|i| Some(i * 7 % 5).filter(|&v| v > 0))
        .collect();
    let labels = KTree::<3, u16>::from_dense_values(3, &dense).unwrap();
    write_valued_ktree_file(Path::new(&p("labels.ktree")), &labels).unwrap();
    let colours: Vec<Option<[u8; 3]>> = (0..16u8)
        .map(|i| (i % 3 != 0).then_some([i, 2 * i, 255]))
        .collect();
    let painted = KTree::<2, [u8; 3]>::from_dense_values(2, &colours).unwrap();
    write_valued_ktree_file(Path::new(&p("colours.ktree")), &painted).unwrap();
    let points: Vec<[u32; 3]> = (0..40u32).map(|i| [i % 9, i * 3 % 8, i * 5 % 10]).collect();
    let text: String = points
        .iter()
        .map(|q| format!("{},{},{}\n", q[0], q[1], q[2]))
        .collect();
    std::fs::write(p("points.csv"), text).unwrap();
    let out = run(&[
        "query",
        &p("labels.ktree"),
        "--points",
        &p("points.csv"),
        "--json",
    ]);
    let rows: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    assert_eq!(rows.len(), points.len());
    for (row, q) in rows.iter().zip(&points) {
        let want = labels.value_at(*q);
        assert_eq!(row["value"], serde_json::json!(want), "{q:?}");
        assert_eq!(row["inside"], serde_json::json!(want.is_some()), "{q:?}");
    }
    // The text lines end with the value where there is one.
    let out = run(&["query", &p("labels.ktree"), "--points", &p("points.csv")]);
    for (line, q) in out.lines().zip(&points) {
        match labels.value_at(*q) {
            Some(v) => assert!(line.ends_with(&format!("inside value {v}")), "{line}"),
            None => assert!(line.ends_with("outside"), "{line}"),
        }
    }
    // With distances the shape is read too: the same values, 0 inside.
    let out = run(&[
        "query",
        &p("labels.ktree"),
        "--points",
        &p("points.csv"),
        "--distance",
        "--json",
    ]);
    let rows: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    for (row, q) in rows.iter().zip(&points) {
        let want = labels.value_at(*q);
        assert_eq!(row["value"], serde_json::json!(want), "{q:?}");
        if want.is_some() {
            assert_eq!(row["distance"], serde_json::json!(0.0), "{q:?}");
        }
    }
    std::fs::write(p("cells.csv"), "1,0\n2,0\n3,0\n").unwrap();
    let out = run(&[
        "query",
        &p("colours.ktree"),
        "--points",
        &p("cells.csv"),
        "--json",
    ]);
    let rows: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    let values: Vec<_> = rows.iter().map(|r| r["value"].clone()).collect();
    assert_eq!(
        values,
        [
            serde_json::json!([1, 2, 255]),
            serde_json::json!([2, 4, 255]),
            serde_json::Value::Null
        ]
    );
}

#[test]
fn a_tree_with_values_converts_to_vtk_files_whose_cell_data_holds_them() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let (shape, values) = labels();
    let json = write_volume(dir.path(), shape, &values);
    run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--labels",
        "--out",
        &p("l.ktree"),
    ]);
    // The labels (0 … 300) as UInt16 cell data, the active scalars; the voxels placed by the flags.
    let out = run(&["convert", &p("l.ktree"), &p("l.vtu"), "--voxel-size", "0.5"]);
    assert!(out.contains("uint16"), "{out}");
    let vtu = std::fs::read(p("l.vtu")).unwrap();
    let text = String::from_utf8_lossy(&vtu);
    assert!(text.contains(r#"<CellData Scalars="value">"#), "{text}");
    assert!(text.contains(r#"<DataArray type="UInt16" Name="value""#));
    assert!(text.contains(r#"Name="level""#) && text.contains(r#"Name="side""#));
    run(&["convert", &p("l.ktree"), &p("l.htg"), "--origin", "1,2,3"]);
    let htg = std::fs::read_to_string(p("l.htg")).unwrap();
    assert!(htg.contains(r#"<CellData Scalars="value">"#));
    assert!(htg.contains(r#"<DataArray type="UInt16" Name="value""#));
    assert!(htg.contains(r#"RangeMin="1""#));
    // Every label of the volume is a value of the hyper tree grid's vertices.
    let (_, numbers) = htg.split_once(r#"Name="value""#).unwrap();
    let numbers = &numbers[numbers.find('>').unwrap() + 1..numbers.find('<').unwrap()];
    let found: std::collections::BTreeSet<u16> = numbers
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    let labels: std::collections::BTreeSet<u16> = values.iter().copied().collect();
    assert_eq!(found, labels); // 0 at the vertices without a value, and the background's voxels
                               // Another extension names every output a tree with values converts to.
    let (ok, _, err) = ktree(&["convert", &p("l.ktree"), &p("l.ply")]);
    assert!(
        !ok && err.contains(".vtu") && err.contains(".htg") && err.contains(".nii"),
        "{err}"
    );
}

#[test]
fn a_4d_tree_with_values_converts_to_a_time_series() {
    use ktree::io::ktree::v3::write_valued_ktree_file;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    // Label t + 1 on the half x < 2 at each time t of a 4⁴ universe.
    let dense: Vec<Option<u8>> = (0..256u32)
        .map(|i| (i % 4 < 2).then_some(1 + (i / 64) as u8))
        .collect();
    let tree = ktree::KTree::<4, u8>::from_dense_values(2, &dense).unwrap();
    write_valued_ktree_file(Path::new(&p("h.ktree")), &tree).unwrap();
    let out = run(&["convert", &p("h.ktree"), &p("h.pvd"), "--time-axis", "3"]);
    assert!(out.contains("5 files"), "{out}");
    let pvd = std::fs::read_to_string(p("h.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 4);
    for t in 0..4 {
        let text = String::from_utf8_lossy(&std::fs::read(p(&format!("h_{t:04}.vtu"))).unwrap())
            .into_owned();
        assert!(text.contains("<CellData Scalars=\"value\">"), "{text}");
    }
    // Not a 4-D tree: a clear error.
    let three = ktree::KTree::<3, u8>::from_dense_values(1, &[Some(1); 8]).unwrap();
    write_valued_ktree_file(Path::new(&p("t.ktree")), &three).unwrap();
    let (ok, _, err) = ktree(&["convert", &p("t.ktree"), &p("t.pvd"), "--time-axis", "0"]);
    assert!(
        !ok && err.contains("4-D") && err.lines().count() == 1,
        "{err}"
    );
}

#[test]
fn a_tree_with_values_transforms_each_voxel_keeping_its_value() {
    use ktree::io::ktree::v3::{read_valued_ktree, write_valued_ktree_file};
    use ktree::ops::{transform, Affine};
    use ktree::KTree;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let dense: Vec<Option<u16>> = (0..512u16)
        .map(|i| Some(i * 7 % 5 + (i / 64) * 10).filter(|&v| v % 5 > 0))
        .collect();
    let labels = KTree::<3, u16>::from_dense_values(3, &dense).unwrap();
    write_valued_ktree_file(Path::new(&p("labels.ktree")), &labels).unwrap();
    let read = |name: &str| {
        let bytes = std::fs::read(p(name)).unwrap();
        read_valued_ktree::<3, u16>(&bytes, name).unwrap()
    };
    // Exact: a quarter turn about z, x → y, then one voxel along x: (x, y, z) → (8 − y, x, z).
    run(&[
        "transform",
        &p("labels.ktree"),
        "--rotate",
        "z:90",
        "--translate",
        "1,0,0",
        "--out",
        &p("turned.ktree"),
    ]);
    let turned = read("turned.ktree");
    for (i, v) in dense.iter().enumerate() {
        let (x, y, z) = (i as u32 % 8, i as u32 / 8 % 8, i as u32 / 64);
        let to = [8 - y, x, z];
        if to[0] < 8 {
            assert_eq!(turned.value_at(to), *v, "{x} {y} {z}");
        }
    }
    assert_eq!(turned.voxel_count(), turned.shape().voxel_count());
    // One affine pass: the voxels are those of the shape's transform, each with a value it had.
    run(&[
        "transform",
        &p("labels.ktree"),
        "--rotate",
        "z:30",
        "--out",
        &p("tilted.ktree"),
    ]);
    let tilted = read("tilted.ktree");
    let m = Affine::rotation_about(0, 1, 30.0, Affine::<3>::universe_centre(3)).unwrap();
    assert_eq!(tilted.shape(), transform(&labels.shape(), &m).unwrap());
    let had: std::collections::BTreeSet<u16> = dense.iter().flatten().copied().collect();
    assert!(tilted
        .value_leaves()
        .all(|(_, v)| v.is_none_or(|v| had.contains(&v))));
    // Values go to a .ktree only.
    let (ok, _, err) = ktree(&[
        "transform",
        &p("labels.ktree"),
        "--scale",
        "2",
        "--out",
        &p("big.binvox"),
    ]);
    assert!(!ok && err.contains("is written as a .ktree"), "{err}");
}
