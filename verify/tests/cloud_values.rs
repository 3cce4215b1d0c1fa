//! Point clouds with values: the readers keep each point's colour, intensity and class (PLY, PCD in its
//! three kinds of data, LAS and LAZ of several point formats, written here with the attributes read back;
//! laspy's `simple.las` against what laspy reads), and the voxelizer with values equals a naive per-voxel
//! reduce (a map from voxel to its points' values) for random clouds, each reduce: its runs exactly those
//! of the reference's dense array, its tree the reference's pyramid.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use ktree::io::read_cloud_bytes;
use ktree::rays::ValueRuns;
use ktree::solid::cloud::{
    max_intensity, mean_colour, mean_intensity, most_frequent_class, CloudVoxelizer, PointCloud,
};
use ktree::value::{Rgb, Value};
use ktree::{KTree, Universe};
use proptest::prelude::*;

// ---- The voxelizer with values against a naive reduce ----

/// The dense array (axis 0 fastest) of a universe of level `level` whose voxel holds `reduce` of the
/// values of its points (origin 0, voxel size `s`), by a map from voxel to values, those with at least
/// `min` points.
fn naive<T: Copy, V: Value>(
    points: &[[f64; 3]],
    values: &[T],
    (s, level, min): (f64, u32, usize),
    reduce: impl Fn(&[T]) -> V,
) -> Vec<Option<V>> {
    let mut voxels: BTreeMap<[u32; 3], Vec<T>> = BTreeMap::new();
    for (p, &v) in points.iter().zip(values) {
        let key = p.map(|c| (c / s).floor() as u32);
        voxels.entry(key).or_default().push(v);
    }
    let u = Universe::<3>::new(level).unwrap();
    let mut dense = vec![None; u.side().pow(3) as usize];
    for (key, v) in voxels {
        if v.len() >= min {
            dense[u.dense_index(key)] = Some(reduce(&v));
        }
    }
    dense
}

/// The naive reducers: written apart from the library's, the plainest way.
fn naive_colour(c: &[Rgb]) -> Rgb {
    std::array::from_fn(|k| {
        let mean = c.iter().map(|p| f64::from(p[k])).sum::<f64>() / c.len() as f64;
        mean.round() as u8
    })
}

fn naive_class(c: &[u8]) -> u8 {
    let mut counts: BTreeMap<u8, usize> = BTreeMap::new();
    for &k in c {
        *counts.entry(k).or_default() += 1;
    }
    let most = *counts.values().max().unwrap();
    // BTreeMap walks the classes in increasing order: the first of the most frequent is the smallest.
    *counts.iter().find(|(_, &n)| n == most).unwrap().0
}

fn naive_mean(c: &[f32]) -> f32 {
    (c.iter().map(|&v| f64::from(v)).sum::<f64>() / c.len() as f64) as f32
}

fn naive_max(c: &[f32]) -> f32 {
    c.iter().copied().reduce(f32::max).unwrap()
}

/// Checks the voxelizer with values against the naive reduce: the runs are those of the dense array
/// (each stretch of a column with equal values one run: exact and as few as possible), the tree is the
/// dense pyramid's.
fn check<T: Copy, V: Value>(
    points: &[[f64; 3]],
    values: &[T],
    (s, level, min): (f64, u32, usize),
    reduce: impl Fn(&[T]) -> V,
    reference: impl Fn(&[T]) -> V,
) -> Result<(), TestCaseError> {
    let v = CloudVoxelizer::new(s)
        .unwrap()
        .origin([0.0; 3])
        .level(level)
        .min_points(min as u64);
    let voxels = v.voxelize_values(points, values, reduce).unwrap();
    let dense = naive(points, values, (s, level, min), reference);
    prop_assert_eq!(&voxels.runs, &ValueRuns::from_dense(level, &dense).unwrap());
    let tree = KTree::from_value_runs(&voxels.runs);
    prop_assert_eq!(tree.to_dense_values().unwrap(), dense.clone());
    prop_assert_eq!(
        tree,
        KTree::<3, V>::from_dense_values(level, &dense).unwrap()
    );
    Ok(())
}

/// A cloud in [0, 8)³ (a universe of level 3 at voxel size 1, or level 4 at 0.5), with few distinct
/// attribute values so that neighbours share values and runs merge.
#[allow(clippy::type_complexity)]
fn cloud() -> impl Strategy<Value = (Vec<[f64; 3]>, Vec<Rgb>, Vec<f32>, Vec<u8>)> {
    (0usize..200).prop_flat_map(|n| {
        (
            prop::collection::vec(prop::array::uniform3(0.0f64..8.0), n),
            prop::collection::vec(
                prop::array::uniform3(prop::sample::select(vec![0u8, 1, 128, 255])),
                n,
            ),
            prop::collection::vec(prop::sample::select(vec![0.0f32, 1.0, 2.5, 1000.0]), n),
            prop::collection::vec(0u8..4, n),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn voxels_with_values_are_the_naive_reduce(
        (points, colours, intensities, classes) in cloud(),
        fine in any::<bool>(),
        min in 1usize..3,
    ) {
        let grid = if fine { (0.5, 4, min) } else { (1.0, 3, min) };
        check(&points, &colours, grid, mean_colour, naive_colour)?;
        check(&points, &intensities, grid, mean_intensity, naive_mean)?;
        check(&points, &intensities, grid, max_intensity, naive_max)?;
        check(&points, &classes, grid, most_frequent_class, naive_class)?;
        let ones = vec![(); points.len()];
        check(&points, &ones, grid, |g: &[()]| g.len() as u32, |g: &[()]| g.len() as u32)?;
    }
}

#[test]
fn ties_go_to_the_smallest_class_and_values_of_another_length_are_refused() {
    assert_eq!(most_frequent_class(&[9, 3, 9, 3]), 3);
    assert_eq!(naive_class(&[9, 3, 9, 3]), 3);
    let v = CloudVoxelizer::new(1.0).unwrap();
    let e = v
        .voxelize_values(&[[0.0; 3]], &[1u8, 2], most_frequent_class)
        .unwrap_err();
    assert!(e.to_string().contains("2 values for 1 points"), "{e}");
}

// ---- The readers keep the attributes ----

/// Points on a grid of 1/8 (exact in every format), colours, intensities and classes.
#[allow(clippy::type_complexity)]
fn sample(n: usize) -> (Vec<[f64; 3]>, Vec<Rgb>, Vec<f32>, Vec<u8>) {
    let points = (0..n)
        .map(|i| [i as f64 / 8.0, (i % 7) as f64, (i * i % 13) as f64 / 8.0])
        .collect();
    let colours = (0..n)
        .map(|i| {
            [
                (i * 37 % 256) as u8,
                (i * 11 % 256) as u8,
                (255 - i % 256) as u8,
            ]
        })
        .collect();
    let intensities = (0..n).map(|i| (i * 101 % 65536) as f32).collect();
    let classes = (0..n).map(|i| (i % 12) as u8).collect();
    (points, colours, intensities, classes)
}

fn assert_attributes(cloud: &PointCloud, colours: &[Rgb], intensities: &[f32], classes: &[u8]) {
    assert_eq!(cloud.colours(), Some(colours));
    assert_eq!(cloud.intensities(), Some(intensities));
    assert_eq!(cloud.classes(), Some(classes));
}

#[test]
fn ply_colours_intensities_and_labels_read() {
    let (points, colours, intensities, classes) = sample(50);
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {}\nproperty double x\nproperty uchar red\nproperty double y\nproperty uchar green\nproperty uchar blue\nproperty double z\nproperty float intensity\nproperty uchar label\nend_header\n",
            points.len()
        )
    };
    let mut ascii = header("ascii");
    let mut binary = header("binary_little_endian").into_bytes();
    for i in 0..points.len() {
        let (p, c) = (points[i], colours[i]);
        writeln!(
            ascii,
            "{} {} {} {} {} {} {} {}",
            p[0], c[0], p[1], c[1], c[2], p[2], intensities[i], classes[i]
        )
        .unwrap();
        binary.extend(p[0].to_le_bytes());
        binary.push(c[0]);
        binary.extend(p[1].to_le_bytes());
        binary.extend([c[1], c[2]]);
        binary.extend(p[2].to_le_bytes());
        binary.extend(intensities[i].to_le_bytes());
        binary.push(classes[i]);
    }
    for bytes in [ascii.into_bytes(), binary] {
        let cloud = read_cloud_bytes(&bytes, "ply", Path::new("c.ply")).unwrap();
        assert_eq!(cloud.points(), &points[..]);
        assert_attributes(&cloud, &colours, &intensities, &classes);
    }
    // Float colours are 0…1, 16-bit ones scaled by 255/65535; a class that is not 0…255 is an error.
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty float red\nproperty float green\nproperty ushort blue\nproperty int class\nend_header\n0 0 0 1.0 0.5 65535 3\n1 1 1 0 2 257 300\n";
    let e = read_cloud_bytes(text.as_bytes(), "ply", Path::new("c.ply")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "c.ply:13: PLY vertex 1 has class 300: expected a whole number 0…255"
    );
    let text = text.replace(" 300\n", " 4\n");
    let cloud = read_cloud_bytes(text.as_bytes(), "ply", Path::new("c.ply")).unwrap();
    assert_eq!(cloud.colours(), Some(&[[255, 128, 255], [0, 255, 1]][..]));
    assert_eq!(cloud.classes(), Some(&[3, 4][..]));
    assert_eq!(cloud.intensities(), None);
}

/// PCL's packed colour: the bits of a float holding 0x00RRGGBB.
fn packed(c: Rgb) -> f32 {
    f32::from_bits(u32::from(c[0]) << 16 | u32::from(c[1]) << 8 | u32::from(c[2]))
}

#[test]
fn pcd_packed_colours_intensities_and_labels_read_in_every_kind_of_data() {
    let (points, colours, intensities, classes) = sample(40);
    let n = points.len();
    let header = |data: &str| {
        format!(
            "VERSION .7\nFIELDS x y z rgb intensity label\nSIZE 4 4 4 4 4 4\nTYPE F F F F F U\nCOUNT 1 1 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nPOINTS {n}\nDATA {data}\n"
        )
    };
    let mut ascii = header("ascii");
    let mut binary = header("binary").into_bytes();
    let mut columns: Vec<Vec<u8>> = vec![Vec::new(); 6];
    for i in 0..n {
        let p = points[i].map(|c| c as f32);
        // PCL writes a float with the digits that give it back: Rust's shortest form does too.
        writeln!(
            ascii,
            "{} {} {} {:e} {} {}",
            p[0],
            p[1],
            p[2],
            packed(colours[i]),
            intensities[i],
            classes[i]
        )
        .unwrap();
        let fields = [
            p[0].to_le_bytes(),
            p[1].to_le_bytes(),
            p[2].to_le_bytes(),
            packed(colours[i]).to_le_bytes(),
            intensities[i].to_le_bytes(),
            u32::from(classes[i]).to_le_bytes(),
        ];
        for (f, bytes) in fields.iter().enumerate() {
            binary.extend(bytes);
            columns[f].extend(bytes);
        }
    }
    // binary_compressed: the columns one after another, as LZF literal runs of at most 32 bytes.
    let raw = columns.concat();
    let mut lzf = Vec::new();
    for chunk in raw.chunks(32) {
        lzf.push(chunk.len() as u8 - 1);
        lzf.extend(chunk);
    }
    let mut compressed = header("binary_compressed").into_bytes();
    compressed.extend((lzf.len() as u32).to_le_bytes());
    compressed.extend((raw.len() as u32).to_le_bytes());
    compressed.extend(lzf);
    for (kind, bytes) in [
        ("ascii", ascii.into_bytes()),
        ("binary", binary),
        ("compressed", compressed),
    ] {
        let cloud = read_cloud_bytes(&bytes, "pcd", Path::new("c.pcd")).unwrap();
        assert_eq!(cloud.points(), &points[..], "{kind}");
        assert_attributes(&cloud, &colours, &intensities, &classes);
    }
}

/// LAS and LAZ written by the `las` crate, point formats with and without colour, legacy and extended.
#[test]
fn las_intensities_classes_and_colours_read_in_every_point_format() {
    let (points, colours, intensities, classes) = sample(60);
    let intensities: Vec<u16> = intensities.iter().map(|&i| i as u16).collect();
    for format in [0u8, 1, 2, 3, 5, 6, 7, 8] {
        for compressed in [false, true] {
            for wide in [false, true] {
                let mut b =
                    las::Builder::from((1, [2, 2, 2, 2, 3, 3, 4, 4, 4][usize::from(format)]));
                b.point_format = las::point::Format::new(format).unwrap();
                b.point_format.is_compressed = compressed;
                let t = las::Transform {
                    scale: 1.0 / 1024.0,
                    offset: 0.0,
                };
                b.transforms = las::Vector { x: t, y: t, z: t };
                let f = b.point_format;
                let mut w =
                    las::Writer::new(std::io::Cursor::new(Vec::new()), b.into_header().unwrap())
                        .unwrap();
                // `wide`: 16-bit colours (the 8 bits in the high byte, a low byte besides); else 8-bit
                // colours stored in 16 bits.
                let stored = |c: u8| {
                    if wide {
                        u16::from(c) << 8 | 0x5a
                    } else {
                        u16::from(c)
                    }
                };
                for i in 0..points.len() {
                    let p = points[i];
                    w.write_point(las::Point {
                        x: p[0],
                        y: p[1],
                        z: p[2],
                        intensity: intensities[i],
                        classification: las::point::Classification::new(classes[i]).unwrap(),
                        gps_time: f.has_gps_time.then_some(0.0),
                        color: f.has_color.then(|| las::Color {
                            red: stored(colours[i][0]),
                            green: stored(colours[i][1]),
                            blue: stored(colours[i][2]),
                        }),
                        nir: f.has_nir.then_some(0),
                        waveform: f.has_waveform.then(Default::default),
                        ..Default::default()
                    })
                    .unwrap();
                }
                let bytes = w.into_inner().unwrap().into_inner();
                let what = format!("format {format}, compressed {compressed}, wide {wide}");
                let ext = if compressed { "laz" } else { "las" };
                let cloud = read_cloud_bytes(&bytes, ext, Path::new("c")).unwrap();
                assert_eq!(cloud.points(), &points[..], "{what}");
                let expected: Vec<f32> = intensities.iter().map(|&i| f32::from(i)).collect();
                assert_eq!(cloud.intensities(), Some(&expected[..]), "{what}");
                assert_eq!(cloud.classes(), Some(&classes[..]), "{what}");
                let colour = f.has_color.then_some(&colours[..]);
                assert_eq!(cloud.colours(), colour, "{what}");
            }
        }
    }
}

/// laspy's `simple.las` (point format 3), its LAZ copy and its COPC copy (point format 7) read as laspy
/// 2.7.0 reads them. The figures were computed with laspy (`pip install laspy[lazrs]`):
/// `l = laspy.read(f)`; `l.red.sum()`, `l.green.sum()`, `l.blue.sum()` (129567, 118582, 134764, every
/// channel below 256: 8-bit colours stored in 16 bits, so kept as they are), `l.intensity.sum()` (81361)
/// and `np.unique(l.classification, return_counts=True)` (class 1: 789 points, class 2: 276).
#[test]
fn laspy_simple_files_read_as_laspy_reads_them() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/clouds");
    for name in ["simple.las", "simple.laz", "simple.copc.laz"] {
        let cloud = ktree::io::read_cloud(&dir.join(name)).unwrap();
        assert_eq!(cloud.len(), 1065, "{name}");
        let colours = cloud.colours().unwrap();
        let sum = |c: usize| colours.iter().map(|p| u64::from(p[c])).sum::<u64>();
        assert_eq!([sum(0), sum(1), sum(2)], [129567, 118582, 134764], "{name}");
        let intensity: f64 = cloud
            .intensities()
            .unwrap()
            .iter()
            .map(|&i| f64::from(i))
            .sum();
        assert_eq!(intensity, 81361.0, "{name}");
        let mut histogram = BTreeMap::new();
        for &c in cloud.classes().unwrap() {
            *histogram.entry(c).or_insert(0) += 1;
        }
        assert_eq!(histogram, BTreeMap::from([(1u8, 789), (2, 276)]), "{name}");
    }
}

#[test]
fn files_without_attributes_have_none() {
    let cloud = read_cloud_bytes(b"0 0 0\n1 1 1\n", "xyz", Path::new("c.xyz")).unwrap();
    assert_eq!(
        (cloud.colours(), cloud.intensities(), cloud.classes()),
        (None, None, None)
    );
    assert!(cloud.attributes().names().is_empty());
}

/// PCL's `colored_cloud.pcd` (a packed `rgb` field, `U 4`, binary) reads the colours PCL writes for it in
/// ASCII (`pcl_convert_pcd_ascii_binary … 0`, kept beside it): unpacked here by hand from the integers PCL
/// printed (`0xAARRGGBB`), and read from the ASCII file by the reader.
#[test]
fn pcl_packed_colours_read_as_pcl_writes_them() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/clouds");
    let binary = ktree::io::read_cloud(&dir.join("pcl_colored_cloud.pcd")).unwrap();
    let ascii_file = dir.join("pcl_colored_cloud_ascii.pcd");
    let ascii = ktree::io::read_cloud(&ascii_file).unwrap();
    let text = std::fs::read_to_string(&ascii_file).unwrap();
    let by_hand: Vec<Rgb> = text
        .lines()
        .skip_while(|l| !l.starts_with("DATA"))
        .skip(1)
        .map(|l| {
            let packed: u32 = l.split(' ').nth(3).unwrap().parse().unwrap();
            [(packed >> 16) as u8, (packed >> 8) as u8, packed as u8]
        })
        .collect();
    assert_eq!(by_hand.len(), 1000);
    assert_eq!(binary.colours(), Some(&by_hand[..]));
    assert_eq!(ascii.colours(), Some(&by_hand[..]));
    // Not all one colour: the comparison says something.
    assert!(by_hand.iter().any(|&c| c != by_hand[0]));
}
