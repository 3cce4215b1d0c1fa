//! `ktree voxelize CLOUD --voxel-size S --value rgb|intensity|class|count [--reduce mean|max]` from the
//! outside: the valued tree written holds, in each voxel, the value worked out here by hand from its
//! points (a small PLY), and on laspy's `simple.las` the per-voxel reduce by brute force of the points
//! and attributes read; a file without the attribute asked for, or an output that is not a `.ktree`, is
//! a one-line error naming the file and what it has.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::{data_dir, ktree};
use ktree::io::ktree::v3::read_valued_ktree_file;
use ktree::value::{Rgb, Value};
use ktree::KTree;

/// Five points in three voxels of side 1 (origin 0): (0,0,0) holds three, (1,0,0) one, (0,0,1) one.
const PLY: &str = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty float intensity\nproperty uchar label\nend_header\n\
0.1 0.1 0.1 10 0 255 1 7\n\
0.2 0.2 0.2 20 0 255 2 3\n\
0.3 0.3 0.3 31 1 0 6 3\n\
1.5 0.5 0.5 0 0 0 9 7\n\
0.5 0.5 1.5 1 2 3 4 2\n";

fn voxelize<V: Value>(input: &str, value: &[&str], out: &Path) -> KTree<3, V> {
    let mut args = vec!["voxelize", input, "--voxel-size", "1", "--origin", "0,0,0"];
    args.extend(value);
    args.extend(["--out", out.to_str().unwrap()]);
    let (ok, stdout, stderr) = ktree(&args);
    assert!(ok, "{stdout}{stderr}");
    read_valued_ktree_file::<3, V>(out).unwrap()
}

/// The values of the three voxels of [`PLY`].
fn at<V: Value>(t: &KTree<3, V>) -> [Option<V>; 3] {
    [[0, 0, 0], [1, 0, 0], [0, 0, 1]].map(|v| t.value_at(v))
}

#[test]
fn each_value_of_a_small_ply_is_its_voxels_reduce() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("c.ply");
    std::fs::write(&input, PLY).unwrap();
    let input = input.to_str().unwrap();
    let out = dir.path().join("c.ktree");

    let rgb = voxelize::<Rgb>(input, &["--value", "rgb"], &out);
    // (10 + 20 + 31) / 3 = 20.33, (0 + 0 + 1) / 3 = 0.33, (255 + 255 + 0) / 3 = 170.
    assert_eq!(
        at(&rgb),
        [Some([20, 0, 170]), Some([0, 0, 0]), Some([1, 2, 3])]
    );
    assert_eq!(rgb.voxel_count(), 3);

    let mean = voxelize::<f32>(input, &["--value", "intensity"], &out);
    assert_eq!(at(&mean), [Some(3.0), Some(9.0), Some(4.0)]);
    let max = voxelize::<f32>(input, &["--value", "intensity", "--reduce", "max"], &out);
    assert_eq!(at(&max), [Some(6.0), Some(9.0), Some(4.0)]);

    let class = voxelize::<u8>(input, &["--value", "class"], &out);
    assert_eq!(at(&class), [Some(3), Some(7), Some(2)]);

    let count = voxelize::<u32>(input, &["--value", "count"], &out);
    assert_eq!(at(&count), [Some(3), Some(1), Some(1)]);
    // With --min-points 2 the voxels of one point are empty.
    let two = voxelize::<u32>(input, &["--value", "count", "--min-points", "2"], &out);
    assert_eq!(at(&two), [Some(3), None, None]);

    let (ok, stdout, _) = ktree(&["stats", out.to_str().unwrap(), "--json"]);
    assert!(ok);
    assert!(stdout.contains("\"voxels\": 1,"), "{stdout}");
}

/// laspy's `simple.las`, each voxel of side 10: the most frequent class and the point count equal a brute
/// force over the points and classes read.
#[test]
fn simple_las_classes_and_counts_are_their_voxels_reduce() {
    let input = data_dir().join("clouds/simple.las");
    let cloud = ktree::io::read_cloud(&input).unwrap();
    let origin = cloud.points().iter().fold([f64::INFINITY; 3], |m, p| {
        std::array::from_fn(|a| m[a].min(p[a]))
    });
    let mut voxels: BTreeMap<[u32; 3], Vec<u8>> = BTreeMap::new();
    for (p, &c) in cloud.points().iter().zip(cloud.classes().unwrap()) {
        let key = std::array::from_fn(|a| ((p[a] - origin[a]) / 10.0).floor() as u32);
        voxels.entry(key).or_default().push(c);
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.ktree");
    let run = |value: &str| {
        let (ok, stdout, stderr) = ktree(&[
            "voxelize",
            input.to_str().unwrap(),
            "--voxel-size",
            "10",
            "--value",
            value,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{stdout}{stderr}");
    };
    run("class");
    let classes = read_valued_ktree_file::<3, u8>(&out).unwrap();
    run("count");
    let counts = read_valued_ktree_file::<3, u32>(&out).unwrap();
    assert_eq!(classes.voxel_count(), voxels.len() as u128);
    for (key, c) in &voxels {
        let ones = c.iter().filter(|&&k| k == 1).count();
        let most = if ones >= c.len() - ones { 1 } else { 2 };
        assert_eq!(classes.value_at(*key), Some(most), "{key:?}");
        assert_eq!(counts.value_at(*key), Some(c.len() as u32), "{key:?}");
    }
}

#[test]
fn a_missing_attribute_or_a_plain_output_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let pcd = data_dir().join("clouds/pcl_brisk_keypoints_gt.pcd");
    let out = dir.path().join("c.ktree");
    let (ok, _, stderr) = ktree(&[
        "voxelize",
        pcd.to_str().unwrap(),
        "--voxel-size",
        "1",
        "--value",
        "rgb",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert_eq!(
        stderr.trim(),
        format!(
            "ktree: {}: --value rgb: the file has no colour (it has points only)",
            pcd.display()
        )
    );
    let ply = dir.path().join("c.ply");
    // The PLY without its labels: the header's last property and each point's last value.
    let unlabelled: String = PLY
        .replace("property uchar label\n", "")
        .lines()
        .map(|l| match l.starts_with(|c: char| c.is_ascii_digit()) {
            true => format!("{}\n", l.rsplit_once(' ').unwrap().0),
            false => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&ply, unlabelled).unwrap();
    let (ok, _, stderr) = ktree(&[
        "voxelize",
        ply.to_str().unwrap(),
        "--voxel-size",
        "1",
        "--value",
        "class",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert_eq!(
        stderr.trim(),
        format!(
            "ktree: {}: --value class: the file has no class (it has colour, intensity per point)",
            ply.display()
        )
    );
    let (ok, _, stderr) = ktree(&[
        "voxelize",
        ply.to_str().unwrap(),
        "--voxel-size",
        "1",
        "--value",
        "rgb",
        "--out",
        dir.path().join("c.rays").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(stderr.contains("the output must be a .ktree"), "{stderr}");
    assert!(!out.exists());
}
