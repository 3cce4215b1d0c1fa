//! NIfTI volumes with values, checked by nibabel (Debian's `python3-nibabel`) both ways: trees written by
//! `ktree convert TREE OUT.nii[.gz]` read by nibabel voxel for voxel (labels, a float window, a tree without
//! values; data type, shape and affine), and volumes written by nibabel (labels stored as int16 with a
//! scale, floats) read by `ktree voxelize --labels` / `--window` to the trees their samples make.

mod common;

use std::path::Path;
use std::process::Command;

use common::{data_dir, ktree, run, tools};
use ktree::io::ktree::v3::read_valued_ktree;
use ktree::value::Value;
use ktree::KTree;

/// Reads a NIfTI file with nibabel: its data type name, shape, affine (12 numbers) and samples as
/// float64, x fastest.
fn nibabel_read(python: &Path, nii: &Path) -> (String, Vec<usize>, Vec<f64>, Vec<f64>) {
    let samples = nii.with_extension("samples");
    let script = r#"
import sys, json, numpy as np, nibabel as nib
img = nib.load(sys.argv[1])
data = np.asanyarray(img.dataobj)
if data.dtype.names:  # RGB24: a structured array of R, G, B
    data = np.stack([data[n] for n in data.dtype.names], axis=-1).astype(np.float64)
    data = (data[..., 0] * 65536 + data[..., 1] * 256 + data[..., 2])
dt = 'rgb24' if img.get_data_dtype().names else str(img.get_data_dtype())
np.asarray(data, dtype='<f8').ravel(order='F').tofile(sys.argv[2])
print(json.dumps({"dtype": dt, "shape": list(img.shape), "affine": img.affine[:3].ravel().tolist()}))
"#;
    let out = Command::new(python)
        .args(["-c", script])
        .arg(nii)
        .arg(&samples)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "nibabel: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let dtype = field(&text, "dtype").trim_matches('"').to_string();
    let shape = numbers(&field(&text, "shape"))
        .into_iter()
        .map(|v| v as usize)
        .collect();
    let affine = numbers(&field(&text, "affine"));
    let bytes = std::fs::read(&samples).unwrap();
    let values = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    (dtype, shape, affine, values)
}

/// The text of key `key` in a one-line JSON object of strings and arrays of numbers.
fn field(json: &str, key: &str) -> String {
    let start = json.find(&format!("\"{key}\": ")).unwrap() + key.len() + 4;
    let rest = &json[start..];
    let end = if rest.starts_with('[') {
        rest.find(']').unwrap() + 1
    } else {
        rest.find([',', '}']).unwrap()
    };
    rest[..end].to_string()
}

fn numbers(list: &str) -> Vec<f64> {
    list.trim_matches(['[', ']'])
        .split(',')
        .map(|t| t.trim().parse().unwrap())
        .collect()
}

fn read_tree<V: Value>(path: &Path) -> KTree<3, V> {
    read_valued_ktree::<3, V>(&std::fs::read(path).unwrap(), "tree").unwrap()
}

/// The tree's samples as a NIfTI of its universe holds them (x fastest, 0 where empty).
fn expected<V: Value>(tree: &KTree<3, V>, sample: impl Fn(V) -> f64) -> Vec<f64> {
    tree.to_dense_values()
        .unwrap()
        .into_iter()
        .map(|v| v.map_or(0.0, &sample))
        .collect()
}

#[test]
fn trees_written_as_nifti_read_by_nibabel_voxel_for_voxel() {
    let Some(python) = tools::require_python_module("nibabel", "install Debian's python3-nibabel")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let s = |n: &str| p(n).to_str().unwrap().to_string();
    let classes = data_dir().join("volumes/skull_classes.json");
    let grey = data_dir().join("volumes/skull_grey.json");

    // Labels (uint8), gzip-compressed, placed in the world.
    run(&[
        "voxelize",
        classes.to_str().unwrap(),
        "--labels",
        "--out",
        &s("c.ktree"),
    ]);
    run(&[
        "convert",
        &s("c.ktree"),
        &s("c.nii.gz"),
        "--voxel-size",
        "0.5",
        "--origin",
        "-3,2,10",
    ]);
    let (dtype, shape, affine, values) = nibabel_read(&python, &p("c.nii.gz"));
    let tree = read_tree::<u8>(&p("c.ktree"));
    assert_eq!(dtype, "uint8");
    assert_eq!(shape, vec![64, 64, 64]);
    // Voxel (i, j, k)'s centre at origin + 0.5 · (i + ½, …).
    assert_eq!(
        affine,
        vec![0.5, 0.0, 0.0, -2.75, 0.0, 0.5, 0.0, 2.25, 0.0, 0.0, 0.5, 10.25]
    );
    assert_eq!(values, expected(&tree, f64::from));
    // The classes the data file's JSON counts, seen by nibabel.
    let count = |c: f64| values.iter().filter(|&&v| v == c).count();
    assert_eq!(
        [0.0, 1.0, 2.0, 3.0, 4.0].map(count),
        [195_318, 32_726, 11_610, 17_996, 4_494]
    );

    // A float window.
    run(&[
        "voxelize",
        grey.to_str().unwrap(),
        "--window",
        "20000:45000",
        "--out",
        &s("w.ktree"),
    ]);
    run(&["convert", &s("w.ktree"), &s("w.nii")]);
    let (dtype, shape, _, values) = nibabel_read(&python, &p("w.nii"));
    assert_eq!((dtype.as_str(), shape), ("float32", vec![64, 64, 64]));
    let tree = read_tree::<f32>(&p("w.ktree"));
    assert_eq!(values, expected(&tree, f64::from));
    assert!(values.iter().any(|&v| v > 40_000.0) && values.iter().all(|&v| v <= 45_000.0));

    // A tree without values: 0/1 as uint8.
    run(&[
        "voxelize",
        grey.to_str().unwrap(),
        "--threshold",
        "29000",
        "--out",
        &s("b.ktree"),
    ]);
    run(&["convert", &s("b.ktree"), &s("b.nii")]);
    let (dtype, _, _, values) = nibabel_read(&python, &p("b.nii"));
    assert_eq!(dtype, "uint8");
    assert_eq!(values.iter().filter(|&&v| v == 1.0).count(), 22_490);
    assert!(values.iter().all(|&v| v == 0.0 || v == 1.0));

    // Colours, written by the library (no command makes a colour tree from a volume).
    let mut dense = vec![None; 8 * 8 * 8];
    for (i, d) in dense.iter_mut().enumerate() {
        if i % 3 != 0 {
            *d = Some([(i % 256) as u8, (i * 7 % 256) as u8, 200]);
        }
    }
    let rgb = KTree::<3, [u8; 3]>::from_dense_values(3, &dense).unwrap();
    ktree::io::write_nifti_file(&p("rgb.nii"), &rgb, &Default::default()).unwrap();
    let (dtype, shape, _, values) = nibabel_read(&python, &p("rgb.nii"));
    assert_eq!(shape, vec![8, 8, 8]);
    assert_eq!(dtype, "rgb24");
    let packed = |[r, g, b]: [u8; 3]| f64::from(r) * 65536.0 + f64::from(g) * 256.0 + f64::from(b);
    assert_eq!(values, expected(&rgb, packed));
}

#[test]
fn nifti_written_by_nibabel_read_as_labels_and_windows() {
    let Some(python) = tools::require_python_module("nibabel", "install Debian's python3-nibabel")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let s = |n: &str| p(n).to_str().unwrap().to_string();
    // Labels stored as int16 with scl_slope 2 (the labels are twice the stored numbers), and a float
    // volume; both 20 × 12 × 9, written by nibabel with its own affine.
    let script = r#"
import sys, numpy as np, nibabel as nib
rng = np.random.default_rng(7)
labels = rng.integers(0, 4, size=(20, 12, 9)).astype(np.int16)
labels[5:15, 2:10, 1:8] = 3
img = nib.Nifti1Image(labels, np.diag([0.8, 0.8, 1.5, 1.0]))
img.header.set_slope_inter(2.0, 0.0)
nib.save(img, sys.argv[1] + '/l.nii.gz')
dens = rng.normal(100.0, 40.0, size=(20, 12, 9)).astype(np.float32)
nib.save(nib.Nifti1Image(dens, np.eye(4)), sys.argv[1] + '/d.nii')
(labels.astype('<f8') * 2).ravel(order='F').tofile(sys.argv[1] + '/l.samples')
dens.astype('<f8').ravel(order='F').tofile(sys.argv[1] + '/d.samples')
"#;
    let out = Command::new(&python)
        .args(["-c", script])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let samples = |n: &str| -> Vec<f64> {
        std::fs::read(p(n))
            .unwrap()
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let at = |i: usize| [i % 20, i / 20 % 12, i / 240].map(|c| c as u32);

    run(&[
        "voxelize",
        &s("l.nii.gz"),
        "--labels",
        "--out",
        &s("l.ktree"),
    ]);
    let labels = read_tree::<u8>(&p("l.ktree"));
    let want = samples("l.samples");
    assert!(want.contains(&6.0));
    for (i, &v) in want.iter().enumerate() {
        let got = labels.value_at(at(i));
        assert_eq!(got, (v != 0.0).then_some(v as u8), "voxel {:?}", at(i));
    }

    run(&[
        "voxelize",
        &s("d.nii"),
        "--window",
        "90:150.5",
        "--out",
        &s("d.ktree"),
    ]);
    let dens = read_tree::<f32>(&p("d.ktree"));
    let want = samples("d.samples");
    let mut kept = 0;
    for (i, &v) in want.iter().enumerate() {
        let inside = (90.0..=150.5).contains(&v);
        kept += usize::from(inside);
        assert_eq!(
            dens.value_at(at(i)),
            inside.then_some(v as f32),
            "voxel {:?}",
            at(i)
        );
    }
    assert!(kept > 100);
    // Round trip: the tree back to NIfTI and into a tree again is the same file.
    run(&["convert", &s("l.ktree"), &s("l2.nii")]);
    run(&[
        "voxelize",
        &s("l2.nii"),
        "--labels",
        "--out",
        &s("l2.ktree"),
    ]);
    assert_eq!(
        std::fs::read(p("l.ktree")).unwrap(),
        std::fs::read(p("l2.ktree")).unwrap()
    );
}

#[test]
fn what_nifti_cannot_hold_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let classes = data_dir().join("volumes/skull_classes.json");
    run(&[
        "voxelize",
        classes.to_str().unwrap(),
        "--labels",
        "--out",
        &s("c.ktree"),
    ]);
    // Values go only where they can be kept.
    let (ok, _, err) = ktree(&["convert", &s("c.ktree"), &s("c.binvox")]);
    assert!(
        !ok && err.contains("c.binvox") && err.contains("NIfTI"),
        "{err}"
    );
    // A quadtree is not a NIfTI volume.
    let quad = KTree::<2, u8>::from_dense_values(1, &[Some(1), None, Some(2), None]).unwrap();
    ktree::io::ktree::v3::write_valued_ktree_file(dir.path().join("q.ktree").as_path(), &quad)
        .unwrap();
    let (ok, _, err) = ktree(&["convert", &s("q.ktree"), &s("q.nii")]);
    assert!(!ok && err.contains("K = 3"), "{err}");
    // --window wants two ordered numbers.
    let (ok, _, err) = ktree(&[
        "voxelize",
        classes.to_str().unwrap(),
        "--window",
        "5:2",
        "--out",
        &s("w.ktree"),
    ]);
    assert!(!ok && err.contains("5:2"), "{err}");
    assert!(!dir.path().join("w.ktree").exists());
}
