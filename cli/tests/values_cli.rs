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

/// The tree of `ktree voxelize --labels` of the volume, `labels.ktree` in `dir`.
fn label_tree(dir: &Path, shape: [usize; 3], values: &[u16]) -> std::path::PathBuf {
    let json = write_volume(dir, shape, values);
    let labels = dir.join("labels.ktree");
    run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--labels",
        "--out",
        labels.to_str().unwrap(),
    ]);
    labels
}

/// Voxels, box `[lo, hi)` and the sums of the centres of one label, counted on the samples.
type Measured = (u64, [usize; 3], [usize; 3], [f64; 3]);

#[test]
#[allow(clippy::needless_range_loop)] // Loops over the axes index several arrays.
fn a_label_volume_becomes_one_tree_whose_values_select_and_measure_as_the_samples() {
    let dir = tempfile::tempdir().unwrap();
    let (shape, values) = labels();
    let labels = label_tree(dir.path(), shape, &values);
    let json = dir.path().join("labels.json");
    let p = |name: &str| dir.path().join(name).display().to_string();

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
    let said = run(&[
        "voxelize",
        json.to_str().unwrap(),
        "--labels",
        "--out",
        &p("l.ktree"),
    ]);
    // The summary counts the samples' labels and labelled voxels.
    let distinct: std::collections::BTreeSet<u16> =
        values.iter().copied().filter(|&v| v > 0).collect();
    let labelled = values.iter().filter(|&&v| v > 0).count();
    let summary = format!(
        "{labelled} voxels labelled with {} labels (uint16)",
        distinct.len()
    );
    assert!(said.contains(&summary), "{said} lacks {summary}");
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
    // Nothing is left of the failed write: neither the file nor its temporary or spill files.
    let hidden: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with('.') || name == "u8.ktree")
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
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
    // Values, distances and nearest voxels are read from the file in place.
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
    // Distances and nearest voxels, read in place too: those of the shape in memory, 0 inside.
    let out = run(&[
        "query",
        &p("labels.ktree"),
        "--points",
        &p("points.csv"),
        "--distance",
        "--nearest",
        "--json",
    ]);
    let rows: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    let signed: Vec<[i64; 3]> = points.iter().map(|q| q.map(i64::from)).collect();
    let near = ktree::query::nearest_many_signed(&labels.shape(), &signed).unwrap();
    for ((row, q), n) in rows.iter().zip(&points).zip(&near) {
        let want = labels.value_at(*q);
        assert_eq!(row["value"], serde_json::json!(want), "{q:?}");
        assert_eq!(
            row["distance"],
            serde_json::json!(n.map(|n| n.distance())),
            "{q:?}"
        );
        assert_eq!(
            row["nearest"],
            serde_json::json!(n.map(|n| n.voxel.to_vec())),
            "{q:?}"
        );
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
    let (ok, _, err) = ktree(&["convert", &p("l.ktree"), &p("l.stl")]);
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

/// A binary little-endian PLY of `ktree convert` of `uint16` labels: its vertices and, per face, its
/// corners, colour, `label`, `label_back` and `back_empty`.
#[allow(clippy::type_complexity)] // The file's own columns.
fn read_label_ply(bytes: &[u8]) -> (Vec<[f32; 3]>, Vec<([u32; 3], [u8; 3], u16, Option<u16>)>) {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let count = |element: &str| -> usize {
        let line = header.lines().find(|l| l.starts_with(element)).unwrap();
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    assert!(header.contains(
        "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty ushort label\n\
         property ushort label_back\nproperty uchar back_empty\nend_header"
    ));
    let (nv, nf) = (count("element vertex"), count("element face"));
    let mut at = end;
    let mut take = |n: usize| {
        at += n;
        &bytes[at - n..at]
    };
    let vertices = (0..nv)
        .map(|_| std::array::from_fn(|_| f32::from_le_bytes(take(4).try_into().unwrap())))
        .collect();
    let faces = (0..nf)
        .map(|_| {
            assert_eq!(take(1), [3]);
            let t = std::array::from_fn(|_| i32::from_le_bytes(take(4).try_into().unwrap()) as u32);
            let colour = take(3).try_into().unwrap();
            let label = u16::from_le_bytes(take(2).try_into().unwrap());
            let back = u16::from_le_bytes(take(2).try_into().unwrap());
            let empty = take(1)[0] == 1;
            (t, colour, label, (!empty).then_some(back))
        })
        .collect();
    assert_eq!(at, bytes.len());
    (vertices, faces)
}

#[test]
fn a_label_volume_becomes_the_surfaces_of_its_labels_with_their_colours() {
    let dir = tempfile::tempdir().unwrap();
    let (shape, values) = labels();
    let labels = label_tree(dir.path(), shape, &values);
    let label = |p: [i64; 3]| -> Option<u16> {
        let inside = (0..3).all(|a| (0..shape[a] as i64).contains(&p[a]));
        let v = inside
            .then(|| values[p[0] as usize + shape[0] * (p[1] as usize + shape[1] * p[2] as usize)]);
        v.filter(|&v| v != 0)
    };
    // The faces between a voxel of each label and its neighbour, counted on the samples.
    let mut faces: BTreeMap<(u16, Option<u16>), f64> = BTreeMap::new();
    let mut voxels: BTreeMap<u16, f64> = BTreeMap::new();
    for z in 0..shape[2] as i64 {
        for y in 0..shape[1] as i64 {
            for x in 0..shape[0] as i64 {
                let Some(v) = label([x, y, z]) else { continue };
                *voxels.entry(v).or_default() += 1.0;
                for a in 0..3 {
                    for step in [-1, 1] {
                        let mut q = [x, y, z];
                        q[a] += step;
                        let w = label(q);
                        if w != Some(v) && w.is_none_or(|w| v < w) {
                            *faces.entry((v, w)).or_default() += 1.0;
                        }
                    }
                }
            }
        }
    }

    let ply = dir.path().join("labels.ply");
    let out = run(&[
        "convert",
        labels.to_str().unwrap(),
        ply.to_str().unwrap(),
        "--voxel-size",
        "0.5",
        "--origin",
        "1,2,3",
    ]);
    assert!(out.contains("the surfaces of 4 uint16 values"), "{out}");
    let (vertices, ply_faces) = read_label_ply(&std::fs::read(&ply).unwrap());
    let mut areas: BTreeMap<(u16, Option<u16>), f64> = BTreeMap::new();
    let mut volumes: BTreeMap<u16, f64> = BTreeMap::new();
    for (t, colour, v, back) in &ply_faces {
        assert_eq!(
            *colour,
            ktree::display::palette::label_colour(u64::from(*v))
        );
        let [a, b, c] = t.map(|i| vertices[i as usize].map(f64::from));
        let (u, w) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        // Areas in voxels (0.5 a side); volumes from each label's faces with their sides.
        *areas.entry((*v, *back)).or_default() +=
            (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0 / 0.25;
        let signed = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))
            / 6.0;
        *volumes.entry(*v).or_default() += signed;
        if let Some(w) = back {
            *volumes.entry(*w).or_default() -= signed;
        }
    }
    assert_eq!(areas.len(), faces.len());
    for (key, n) in &faces {
        assert!(
            (areas[key] - n).abs() < 1e-6,
            "{key:?}: {} against {n}",
            areas[key]
        );
    }
    for (v, n) in &voxels {
        assert!(
            (volumes[v] - n * 0.125).abs() < 1e-6,
            "label {v}: {} against {n}",
            volumes[v]
        );
    }
    // The first vertex is where --origin and --voxel-size place it.
    assert!(vertices
        .iter()
        .all(|p| (0..3).all(|a| p[a] >= [1.0, 2.0, 3.0][a])));

    // OBJ: a group and a material per label, the colours in the .mtl beside it.
    let obj = dir.path().join("labels.obj");
    run(&["convert", labels.to_str().unwrap(), obj.to_str().unwrap()]);
    let text = std::fs::read_to_string(&obj).unwrap();
    assert!(text.contains("mtllib labels.mtl\n"));
    let mtl = std::fs::read_to_string(dir.path().join("labels.mtl")).unwrap();
    for v in voxels.keys() {
        assert!(text.contains(&format!("g label_{v}\nusemtl label_{v}\n")));
        let [r, g, b] =
            ktree::display::palette::label_colour(u64::from(*v)).map(|c| f64::from(c) / 255.0);
        assert!(
            mtl.contains(&format!("newmtl label_{v}\nKd {r} {g} {b}\n")),
            "{mtl}"
        );
    }

    // glTF: a mesh and a material per label.
    let glb = dir.path().join("labels.glb");
    run(&["convert", labels.to_str().unwrap(), glb.to_str().unwrap()]);
    let bytes = std::fs::read(&glb).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let gltf: serde_json::Value = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
    assert_eq!(gltf["materials"].as_array().unwrap().len(), 4);
    assert_eq!(gltf["meshes"][0]["name"], "label_1");

    // STL holds no colours.
    let (ok, _, err) = ktree(&[
        "convert",
        labels.to_str().unwrap(),
        dir.path().join("l.stl").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains(".ply, .obj"), "{err}");
}

#[test]
fn a_tree_with_values_keeps_its_world_frame_through_every_conversion() {
    use ktree::io::ktree::v3::{read_valued_ktree_framed, write_valued_ktree_file_framed};
    use ktree::space::WorldFrame;
    use ktree::KTree;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let dense: Vec<Option<u8>> = (0..64u8).map(|i| (i % 3 != 0).then_some(i % 4)).collect();
    let labels = KTree::<3, u8>::from_dense_values(2, &dense).unwrap();
    let frame = WorldFrame {
        voxel_size: 0.5,
        origin: [1.0, -2.0, 3.0],
    };
    write_valued_ktree_file_framed(Path::new(&p("a.ktree")), &labels, Some(&frame)).unwrap();
    let framed = |name: &str| {
        let bytes = std::fs::read(p(name)).unwrap();
        read_valued_ktree_framed::<3, u8>(&bytes, name).unwrap()
    };
    // .ktree to .ktree, and through OpenVDB and back: the same voxels, values and frame.
    run(&["convert", &p("a.ktree"), &p("b.ktree")]);
    assert_eq!(framed("b.ktree"), (labels.clone(), Some(frame)));
    run(&["convert", &p("a.ktree"), &p("a.vdb")]);
    run(&["convert", &p("a.vdb"), &p("c.ktree")]);
    let (back, kept) = framed("c.ktree");
    assert_eq!(back.to_dense_values().unwrap(), dense);
    let kept = kept.expect("a frame");
    assert_eq!(kept.voxel_size, 0.5);
    for a in 0..3 {
        assert!((kept.origin[a] - frame.origin[a]).abs() < 1e-9, "{kept:?}");
    }
    // NIfTI: the voxel size is pixdim[1..=3] (bytes 80..92 of the header).
    run(&["convert", &p("a.ktree"), &p("a.nii")]);
    let nii = std::fs::read(p("a.nii")).unwrap();
    for a in 0..3 {
        let at = 80 + 4 * a;
        let size = f32::from_le_bytes(nii[at..at + 4].try_into().unwrap());
        assert_eq!(size, 0.5);
    }
    // The typed grid goes to NIfTI, VTK and meshes directly: the same files as from the .ktree.
    for out in ["nii", "vtu", "htg", "ply"] {
        let (direct, through) = (p(&format!("vdb.{out}")), p(&format!("ktree.{out}")));
        run(&["convert", &p("a.vdb"), &direct]);
        run(&["convert", &p("a.ktree"), &through]);
        let same = std::fs::read(&direct).unwrap() == std::fs::read(&through).unwrap();
        assert!(same, "{out}: the grid's file differs from the tree's");
    }
    // Formats that would drop the values write the shape of the grid's active voxels.
    run(&["convert", &p("a.vdb"), &p("shape.binvox")]);
    let (ok, _, err) = ktree(&["convert", &p("a.ktree"), &p("a.bt")]);
    assert!(!ok && err.contains("hold no values"), "{err}");
    // --voxel-size overrides the frame.
    run(&["convert", &p("a.ktree"), &p("d.ktree"), "--voxel-size", "2"]);
    assert_eq!(framed("d.ktree").1.unwrap().voxel_size, 2.0);
}

/// `select` keeps the input's world frame and notes (the labels' names) in the tree it writes, which
/// every reader of trees without values reads, through a map too.
#[test]
fn select_keeps_the_world_frame_and_the_notes() {
    use ::ktree::io::ktree::v3::write_valued_ktree_file_noted;
    use ::ktree::io::{read_ktree_framed, KtreeView, Notes};
    use ::ktree::space::WorldFrame;
    use ::ktree::{AnyTree, KTree};
    let dir = tempfile::tempdir().unwrap();
    let labels: Vec<Option<u8>> = (0..64)
        .map(|i| (i % 3 != 0).then_some((i % 4) as u8))
        .collect();
    let tree = KTree::<3, u8>::from_dense_values(2, &labels).unwrap();
    let frame = WorldFrame {
        voxel_size: 0.25,
        origin: [1.0, -3.5, 0.75],
    };
    let notes = Notes::from([("label.2".to_string(), "kidney".to_string())]);
    let input = dir.path().join("labels.ktree");
    write_valued_ktree_file_noted(&input, &tree, Some(&frame), &notes).unwrap();
    let out = dir.path().join("two.ktree");
    let printed = run(&[
        "select",
        input.to_str().unwrap(),
        "--value",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(printed.contains("kidney"), "{printed}");
    let (selected, kept, kept_notes) =
        read_ktree_framed(&std::fs::read(&out).unwrap(), "two").unwrap();
    assert_eq!(selected, AnyTree::K3(tree.select(2)));
    assert_eq!((kept, kept_notes), (Some(frame), notes.clone()));
    let view = KtreeView::open(&out).unwrap();
    assert_eq!((view.frame(), view.notes()), (Some(frame), &notes));
    // The commands on trees without values read it as any other.
    let stats: serde_json::Value =
        serde_json::from_str(&run(&["stats", out.to_str().unwrap(), "--json"])).unwrap();
    assert_eq!(stats["voxels"], tree.select(2).voxel_count() as u64);
}
