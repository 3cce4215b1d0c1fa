//! Point clouds: every format written here (PLY ASCII and binary, PCD ASCII and binary, XYZ, CSV, LAS, LAZ)
//! reads back the points written, and the voxels equal numpy's `floor((p − origin) / s)` computed by brute
//! force (a set of floored keys, counted for the minimum points), for random clouds; malformed files are
//! errors naming the file and the line or byte.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use ktree::io::{read_cloud, read_cloud_bytes};
use ktree::solid::cloud::CloudVoxelizer;
use ktree::{KTree, Universe};
use proptest::prelude::*;

/// The voxels of `points` by brute force: `floor((p − origin) / s)` per point, counted; those with at least
/// `min` points; and the smallest level holding them (`None`: a negative index).
fn reference(
    points: &[[f64; 3]],
    s: f64,
    origin: [f64; 3],
    min: u64,
) -> (BTreeMap<[i64; 3], u64>, u32) {
    let mut counts = BTreeMap::new();
    for p in points {
        let key: [i64; 3] = std::array::from_fn(|a| ((p[a] - origin[a]) / s).floor() as i64);
        *counts.entry(key).or_insert(0u64) += 1;
    }
    let top = counts.keys().flatten().copied().max().unwrap_or(0);
    let level = (0..).find(|&l| top < 1i64 << l).unwrap();
    counts.retain(|_, c| *c >= min);
    (counts, level)
}

/// The tree of a set of voxels, through `KTree::from_cells` (not the cloud's path).
fn tree_of(voxels: &BTreeMap<[i64; 3], u64>, level: u32) -> KTree<3> {
    let u = Universe::<3>::new(level).unwrap();
    let cells: Vec<_> = voxels
        .keys()
        .map(|k| u.cell(k.map(|c| c as u32), level).unwrap())
        .collect();
    KTree::from_cells(u, &cells).unwrap()
}

fn minimum(points: &[[f64; 3]]) -> [f64; 3] {
    points.iter().fold([f64::INFINITY; 3], |m, p| {
        std::array::from_fn(|a| m[a].min(p[a]))
    })
}

// ---- Writers of each format (small and plain, for the tests) ----

fn ply_ascii(points: &[[f64; 3]]) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\ncomment made by a test\nelement vertex {}\nproperty double x\nproperty double y\nproperty uchar red\nproperty double z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
        points.len()
    );
    for p in points {
        writeln!(s, "{} {} 7 {}", p[0], p[1], p[2]).unwrap();
    }
    s.into_bytes()
}

fn ply_binary(points: &[[f64; 3]], big: bool) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_{}_endian 1.0\nelement vertex {}\nproperty float64 x\nproperty float64 y\nproperty float64 z\nproperty list uchar int extra\nend_header\n",
        if big { "big" } else { "little" },
        points.len()
    )
    .into_bytes();
    for p in points {
        for c in p {
            b.extend(if big {
                c.to_be_bytes()
            } else {
                c.to_le_bytes()
            });
        }
        b.push(1);
        b.extend(if big {
            5i32.to_be_bytes()
        } else {
            5i32.to_le_bytes()
        });
    }
    b
}

fn pcd_header(points: &[[f64; 3]], data: &str) -> String {
    format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 8 8 8 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n",
        n = points.len()
    )
}

fn pcd_ascii(points: &[[f64; 3]]) -> Vec<u8> {
    let mut s = pcd_header(points, "ascii");
    for p in points {
        writeln!(s, "{} {} {} 4278190080", p[0], p[1], p[2]).unwrap();
    }
    s.into_bytes()
}

fn pcd_binary(points: &[[f64; 3]]) -> Vec<u8> {
    let mut b = pcd_header(points, "binary").into_bytes();
    for p in points {
        for c in p {
            b.extend(c.to_le_bytes());
        }
        b.extend(7u32.to_le_bytes());
    }
    b
}

/// PCD `DATA binary_compressed` as PCL writes it: the fields column by column (the padding field `_` not
/// stored), compressed by [`lzf`].
fn pcd_compressed(points: &[[f64; 3]]) -> Vec<u8> {
    let n = points.len();
    let mut b = format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z _ rgb\nSIZE 8 8 8 1 4\nTYPE F F F U U\nCOUNT 1 1 1 4 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary_compressed\n"
    )
    .into_bytes();
    let mut columns = Vec::new();
    for a in 0..3 {
        for p in points {
            columns.extend(p[a].to_le_bytes());
        }
    }
    for i in 0..n {
        columns.extend((i as u32 % 3).to_le_bytes());
    }
    let data = lzf(&columns);
    b.extend((data.len() as u32).to_le_bytes());
    b.extend((columns.len() as u32).to_le_bytes());
    b.extend(data);
    b
}

/// A plain LZF compressor (liblzf's format: literal runs of at most 32 bytes, back references of 3 to 264
/// bytes at most 8192 back), greedy over the last position of each 3 bytes.
fn lzf(data: &[u8]) -> Vec<u8> {
    fn flush(out: &mut Vec<u8>, literal: &mut Vec<u8>) {
        for run in literal.chunks(32) {
            out.push((run.len() - 1) as u8);
            out.extend(run);
        }
        literal.clear();
    }
    let mut out = Vec::new();
    let mut literal = Vec::new();
    let mut last: std::collections::HashMap<[u8; 3], usize> = std::collections::HashMap::new();
    let mut i = 0;
    while i < data.len() {
        let key = (i + 3 <= data.len()).then(|| [data[i], data[i + 1], data[i + 2]]);
        let found = key
            .and_then(|k| last.get(&k).copied())
            .filter(|&j| i - j <= 8192);
        if let Some(k) = key {
            last.insert(k, i);
        }
        let Some(j) = found else {
            literal.push(data[i]);
            i += 1;
            continue;
        };
        let mut len = 3;
        while i + len < data.len() && len < 264 && data[j + len] == data[i + len] {
            len += 1;
        }
        flush(&mut out, &mut literal);
        let (back, n) = (i - j - 1, len - 2);
        if n < 7 {
            out.push(((n as u8) << 5) | (back >> 8) as u8);
        } else {
            out.push((7 << 5) | (back >> 8) as u8);
            out.push((n - 7) as u8);
        }
        out.push((back & 0xff) as u8);
        i += len;
    }
    flush(&mut out, &mut literal);
    out
}

fn xyz(points: &[[f64; 3]]) -> Vec<u8> {
    let mut s = String::from("# x y z intensity\n\n");
    for p in points {
        writeln!(s, "{}\t{} {}  0.5", p[0], p[1], p[2]).unwrap();
    }
    s.into_bytes()
}

fn csv(points: &[[f64; 3]]) -> Vec<u8> {
    let mut s = String::from("x,y,z,label\n");
    for p in points {
        writeln!(s, "{},{},{},ground", p[0], p[1], p[2]).unwrap();
    }
    s.into_bytes()
}

/// LAS (or LAZ when `compressed`) with a scale of 1/1024, so that the points written on that grid read back
/// exactly.
fn las(points: &[[f64; 3]], compressed: bool) -> Vec<u8> {
    let mut b = las::Builder::from((1, 2));
    let t = las::Transform {
        scale: 1.0 / 1024.0,
        offset: 0.0,
    };
    b.transforms = las::Vector { x: t, y: t, z: t };
    b.point_format.is_compressed = compressed;
    write_las(b, points)
}

/// LAS 1.4 (the version with extended records) of `points`, uncompressed, with `extended` as its
/// extended records' data.
fn las_1_4(points: &[[f64; 3]], extended: &[Vec<u8>]) -> Vec<u8> {
    let mut b = las::Builder::from((1, 4));
    b.point_format = las::point::Format::new(6).unwrap();
    b.evlrs = extended
        .iter()
        .map(|data| las::Vlr {
            user_id: "ktree".into(),
            record_id: 1,
            description: "test".into(),
            data: data.clone(),
        })
        .collect();
    write_las(b, points)
}

/// LAZ 1.4 of `points` (point format 6, compressed in layered chunks), with a scale of 1/1024.
fn laz_1_4(points: &[[f64; 3]]) -> Vec<u8> {
    let mut b = las::Builder::from((1, 4));
    b.point_format = las::point::Format::new(6).unwrap();
    b.point_format.is_compressed = true;
    let t = las::Transform {
        scale: 1.0 / 1024.0,
        offset: 0.0,
    };
    b.transforms = las::Vector { x: t, y: t, z: t };
    write_las(b, points)
}

/// The file `b` describes, holding `points`.
fn write_las(b: las::Builder, points: &[[f64; 3]]) -> Vec<u8> {
    let gps_time = b.point_format.has_gps_time.then_some(0.0);
    let mut w =
        las::Writer::new(std::io::Cursor::new(Vec::new()), b.into_header().unwrap()).unwrap();
    for p in points {
        w.write_point(las::Point {
            x: p[0],
            y: p[1],
            z: p[2],
            gps_time,
            ..Default::default()
        })
        .unwrap();
    }
    w.into_inner().unwrap().into_inner()
}

/// Every format: (extension, bytes).
fn all_formats(points: &[[f64; 3]]) -> Vec<(&'static str, Vec<u8>)> {
    vec![
        ("ply", ply_ascii(points)),
        ("ply", ply_binary(points, false)),
        ("ply", ply_binary(points, true)),
        ("pcd", pcd_ascii(points)),
        ("pcd", pcd_binary(points)),
        ("pcd", pcd_compressed(points)),
        ("xyz", xyz(points)),
        ("csv", csv(points)),
        ("las", las(points, false)),
        ("laz", las(points, true)),
    ]
}

/// Random clouds of up to `n` points on a grid of 1/1024 (so LAS holds them exactly), within ±`r`.
fn cloud(n: usize, r: i32) -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec(
        prop::array::uniform3(-r * 1024..r * 1024).prop_map(|p| p.map(|c| f64::from(c) / 1024.0)),
        1..n,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn every_format_reads_back_the_points(points in cloud(60, 40)) {
        for (ext, bytes) in all_formats(&points) {
            let read = read_cloud_bytes(&bytes, ext, Path::new("t")).unwrap();
            prop_assert_eq!(read.points(), &points[..], "{}", ext);
        }
    }

    #[test]
    fn voxels_equal_the_floored_keys(
        points in cloud(300, 30),
        s in prop::sample::select(vec![0.1, 0.25, 0.7, 1.0, 3.0, 9.5]),
        min in 1u64..4,
        given in prop::option::of(prop::array::uniform3(-40i32..-30).prop_map(|o| o.map(f64::from))),
    ) {
        let origin = given.unwrap_or_else(|| minimum(&points));
        let (want, level) = reference(&points, s, origin, min);
        let mut v = CloudVoxelizer::new(s).unwrap().min_points(min);
        if let Some(o) = given {
            v = v.origin(o);
        }
        let got = v.voxelize(&points).unwrap();
        prop_assert_eq!(got.origin, origin);
        prop_assert_eq!(got.rays.level(), level);
        let tree = KTree::from_rays(&got.rays);
        tree.assert_well_formed();
        prop_assert_eq!(&tree, &tree_of(&want, level));
        if min == 1 {
            prop_assert_eq!(KTree::from_points(&points, s, given, None).unwrap(), tree);
        }
    }

    #[test]
    fn a_level_given_crops_or_fails(points in cloud(200, 30), level in 0u32..6, crop: bool) {
        let origin = [-8.0, -8.0, -8.0];
        let (mut want, _) = reference(&points, 1.0, origin, 1);
        let side = 1i64 << level;
        let outside: u64 = want
            .iter()
            .filter(|(k, _)| k.iter().any(|&c| c < 0 || c >= side))
            .map(|(_, c)| c)
            .sum();
        want.retain(|k, _| k.iter().all(|&c| c >= 0 && c < side));
        let got = CloudVoxelizer::new(1.0).unwrap().origin(origin).level(level).crop(crop).voxelize(&points);
        match got {
            Ok(v) => {
                prop_assert!(crop || outside == 0);
                prop_assert_eq!(v.cropped, outside);
                prop_assert_eq!(KTree::from_rays(&v.rays), tree_of(&want, level));
            }
            Err(e) => {
                prop_assert!(!crop && outside > 0);
                let text = e.to_string();
                prop_assert!(text.starts_with(&format!("{outside} points lie outside")), "{}", text);
            }
        }
    }
}

/// The voxels of every format's file equal the reference, through the file.
#[test]
fn files_of_every_format_voxelize_as_the_reference() {
    let points: Vec<[f64; 3]> = (0..500)
        .map(|i| {
            let t = f64::from(i) * 0.37;
            [t.sin() * 5.0, t.cos() * 5.0, t * 0.1].map(|c| (c * 1024.0).round() / 1024.0)
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let (want, level) = reference(&points, 0.5, minimum(&points), 2);
    for (i, (ext, bytes)) in all_formats(&points).into_iter().enumerate() {
        let path = dir.path().join(format!("c{i}.{ext}"));
        std::fs::write(&path, bytes).unwrap();
        assert!(ktree::io::is_cloud_file(&path).unwrap());
        let cloud = read_cloud(&path).unwrap();
        let v = CloudVoxelizer::new(0.5)
            .unwrap()
            .min_points(2)
            .voxelize(cloud.points())
            .unwrap();
        assert_eq!(KTree::from_rays(&v.rays), tree_of(&want, level), "{ext}");
    }
}

/// A malformed file is an error naming the file once and the line (text) or byte (binary), in one line.
#[test]
fn malformed_files_name_the_line_or_byte() {
    let p = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
    let mut bad_pcd_binary = pcd_binary(&p);
    bad_pcd_binary.truncate(bad_pcd_binary.len() - 3);
    let mut bad_ply_binary = ply_binary(&p, false);
    bad_ply_binary.truncate(bad_ply_binary.len() - 30);
    let mut nan_ply_binary = ply_binary(&p, false);
    let at = nan_ply_binary.len() - 29 + 8; // y of the second vertex (records of 29 bytes)
    nan_ply_binary[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    let mut huge_las = las(&p, false);
    huge_las[107..111].copy_from_slice(&u32::MAX.to_le_bytes()); // legacy point count
                                                                 // A LAS 1.4 file whose one extended record declares 2^54 bytes of data.
    let mut huge_evlr = las_1_4(&p, &[]);
    let start = huge_evlr.len() as u64;
    huge_evlr[235..243].copy_from_slice(&start.to_le_bytes());
    huge_evlr[243..247].copy_from_slice(&1u32.to_le_bytes());
    let mut record = vec![0u8; 60];
    record[20..28].copy_from_slice(&(1u64 << 54).to_le_bytes());
    huge_evlr.extend_from_slice(&record);
    let huge_evlr_error = format!(
        ": byte {start}: LAS: the extended variable-length record there declares 18014398509481984 bytes"
    );
    // binary_compressed: the sizes after the header, then the LZF data.
    let compressed = pcd_compressed(&p);
    let end = b"DATA binary_compressed\n";
    let body = compressed
        .windows(end.len())
        .position(|w| w == end)
        .unwrap()
        + end.len();
    let mut cut_compressed = compressed.clone();
    cut_compressed.truncate(cut_compressed.len() - 1);
    let mut wrong_size = compressed.clone();
    wrong_size[body + 4..body + 8].copy_from_slice(&61u32.to_le_bytes());
    let mut far_back = compressed.clone();
    far_back[body + 8..body + 12].copy_from_slice(&[0, 7, 0x20, 9]); // 1 literal byte, then 10 bytes back
    let data = compressed.len() - body - 8;
    let cut_error = format!(
        ": byte {body}: PCD: {data} bytes of compressed data declared but the file has {} after the sizes",
        data - 1
    );
    let wrong_size_error = format!(
        ": byte {}: PCD: 2 points of 28 bytes need 56 bytes, but the uncompressed size is 61",
        body + 4
    );
    let far_back_error = format!(
        ": byte {}: PCD: LZF: a reference 10 bytes back, but only 1 bytes are decompressed",
        body + 10
    );
    let mut short_header = las(&p, false);
    short_header[94..96].copy_from_slice(&100u16.to_le_bytes());
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("las", huge_evlr, &huge_evlr_error),
        ("las", short_header, ": byte 94: LAS: a header of 100 bytes, but LAS 1.2's takes 227"),
        ("xyz", b"1 2 3\n4 five 6\n".to_vec(), ":2: 'five' is not a number"),
        ("xyz", b"x y z\n1 2 3\n".to_vec(), ":1: 'x' is not a number"),
        ("xyz", b"1 2 3\n\n1 2\n".to_vec(), ":3: expected 3 numbers x y z, found 2"),
        ("xyz", b"1 2 3\n1 nan 2\n".to_vec(), ":2: the point has a coordinate that is not finite"),
        ("csv", b"x,y,z\n1,2,3\n4,5,inf\n".to_vec(), ":3: the point has a coordinate that is not finite"),
        ("csv", b"x,y,z\n1,2,3\nx,y,z\n".to_vec(), ":3: 'x' is not a number"),
        ("ply", ply_ascii(&p)[..150].to_vec(), ": the PLY header has no end line"),
        (
            "ply",
            String::from_utf8(ply_ascii(&p)).unwrap().replace("4 5 7 6", "4 5 7 nan").into_bytes(),
            ":13: PLY vertex 1 has a coordinate that is not finite",
        ),
        (
            "ply",
            String::from_utf8(ply_ascii(&p)).unwrap().replace("4 5 7 6", "4 5").into_bytes(),
            ":13: vertex 1 has too few values",
        ),
        (
            "ply",
            bad_ply_binary,
            ": byte 151: the PLY header declares 2 'vertex' entries, which take at least 50 bytes, but only 28 bytes follow it",
        ),
        ("ply", nan_ply_binary, ": byte 180: PLY vertex 1 has a coordinate that is not finite"),
        (
            "ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec(),
            ": the PLY file has 1 faces: it is a mesh",
        ),
        (
            "ply",
            b"ply\nformat binary_little_endian 1.0\nelement junk 99999999999\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec(),
            ":8: PLY element 'junk' has 99999999999 entries but no property",
        ),
        ("pcd", bad_pcd_binary, ": byte 174: PCD: 2 points of 28 bytes need 56 bytes but the file has 53"),
        (
            "pcd",
            String::from_utf8(pcd_ascii(&p)).unwrap().replace("4 5 6 ", "4 5 ").into_bytes(),
            ":13: expected 4 values, found 3",
        ),
        (
            "pcd",
            String::from_utf8(pcd_ascii(&p)).unwrap().replace("4 5 6 ", "4 -inf 6 ").into_bytes(),
            ":13: point 1 has a coordinate that is not finite",
        ),
        (
            "pcd",
            String::from_utf8(pcd_ascii(&p)).unwrap().replace("POINTS 2", "POINTS 99999999999").into_bytes(),
            ": byte 183: PCD: 99999999999 points declared but only",
        ),
        ("pcd", cut_compressed, &cut_error),
        ("pcd", wrong_size, &wrong_size_error),
        ("pcd", far_back, &far_back_error),
        ("las", huge_las, ": byte 107: LAS: the header declares 4294967295 points"),
        ("las", b"LASF".to_vec(), ": byte 0: LAS header"),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (i, (ext, bytes, want)) in cases.into_iter().enumerate() {
        let path = dir.path().join(format!("bad{i}.{ext}"));
        std::fs::write(&path, &bytes).unwrap();
        let e = read_cloud(&path).unwrap_err().to_string();
        let name = path.display().to_string();
        let rest = e
            .strip_prefix(&name)
            .unwrap_or_else(|| panic!("case {i}: {e}"));
        assert!(rest.starts_with(want), "case {i}: {e} (wanted: {want})");
        assert!(
            !rest.contains(&format!("bad{i}.{ext}")),
            "the file named twice: {e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }
}

/// A LAS or LAZ file whose point count was raised is refused, naming the byte, before any point beyond
/// the data is decoded: uncompressed, against the point data; compressed, against the chunk table and
/// each chunk's own bytes (LAS 1.2 with chunks of points, LAS 1.4 with chunks of layers); in LAS 1.4 the
/// two counts of the header must agree.
#[test]
fn a_point_count_the_data_cannot_hold_is_refused() {
    let p: Vec<[f64; 3]> = (0..300)
        .map(|i| [f64::from(i), 2.0, f64::from(i % 7)])
        .collect();
    let raised = |mut bytes: Vec<u8>, at: std::ops::Range<usize>, by: u64| {
        let mut n = [0u8; 8];
        n[..at.len()].copy_from_slice(&bytes[at.clone()]);
        let count = u64::from_le_bytes(n) + by;
        bytes[at.clone()].copy_from_slice(&count.to_le_bytes()[..at.len()]);
        bytes
    };
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("las", raised(las(&p, false), 107..111, 1), ": byte 107: LAS: the header declares 301 points of 20 bytes (6020 bytes), but the point data"),
        ("laz", raised(las(&p, true), 107..111, 1), "LAZ chunk 0: its"),
        ("laz", raised(las(&p, true), 107..111, 2), "bytes end after 300 of the 302 points the header and the chunk table give it"),
        ("laz", raised(raised(laz_1_4(&p), 107..111, 1), 247..255, 1), "LAZ chunk 0: the chunk says it holds 300 points, the header and the chunk table give it 301"),
        ("las", raised(las_1_4(&p, &[]), 107..111, 5), ": byte 107: LAS: the legacy point count 305 disagrees with the point count 300 at byte 247"),
    ];
    for (i, (ext, bytes, want)) in cases.into_iter().enumerate() {
        let e = read_cloud_bytes(&bytes, ext, Path::new("raised"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("raised: byte "), "case {i}: {e}");
        assert!(e.contains(want), "case {i}: {e} (wanted: {want})");
    }
    // As written, every one reads.
    for bytes in [las(&p, false), las(&p, true), laz_1_4(&p), las_1_4(&p, &[])] {
        assert_eq!(
            read_cloud_bytes(&bytes, "las", Path::new("t"))
                .unwrap()
                .points(),
            &p[..]
        );
    }
}

/// laspy's COPC file (LAS 1.4, LASzip layered chunks of variable size) reads; with its point counts
/// raised (the legacy one alone, or both), it is refused naming the byte: once this made the LASzip
/// decoder read past the last chunk and ask for 3.7 GB.
#[test]
fn a_copc_file_with_a_raised_count_is_refused() {
    let file =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/clouds/simple.copc.laz"))
            .unwrap();
    let cloud = read_cloud_bytes(&file, "laz", Path::new("simple.copc.laz")).unwrap();
    assert_eq!(cloud.len(), 1065);
    let mut legacy = file.clone();
    legacy[107..111].copy_from_slice(&1066u32.to_le_bytes());
    let e = read_cloud_bytes(&legacy, "laz", Path::new("c.laz"))
        .unwrap_err()
        .to_string();
    assert_eq!(e, "c.laz: byte 107: LAS: the legacy point count 1066 disagrees with the point count 1065 at byte 247");
    let mut both = legacy.clone();
    both[247..255].copy_from_slice(&1066u64.to_le_bytes());
    let e = read_cloud_bytes(&both, "laz", Path::new("c.laz"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(
            "c.laz: byte 107: LAZ: the header declares 1066 points, but the chunk table (byte "
        ),
        "{e}"
    );
    assert!(e.ends_with(") gives its chunks 1065"), "{e}");
}

/// PCL's own `binary_compressed` file reads the points PCL reads from it (PCL's conversion of it to
/// `binary`, kept beside it).
#[test]
fn pcl_compressed_file_reads_as_pcl_reads_it() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/clouds");
    let compressed = read_cloud(&dir.join("pcl_brisk_keypoints_gt.pcd")).unwrap();
    let binary = read_cloud(&dir.join("pcl_brisk_keypoints_gt_binary.pcd")).unwrap();
    assert_eq!(compressed.len(), 1860);
    assert_eq!(compressed, binary);
}

/// PCD points whose x, y and z are all NaN (PCL's pixels without a measurement) are skipped, in each
/// kind of data; a point with one NaN coordinate is an error.
#[test]
fn pcd_points_without_a_measurement_are_skipped() {
    let p = [[1.0, 2.0, 3.0], [f64::NAN; 3], [4.0, 5.0, 6.0]];
    for (i, bytes) in [pcd_ascii(&p), pcd_binary(&p), pcd_compressed(&p)]
        .into_iter()
        .enumerate()
    {
        let read = read_cloud_bytes(&bytes, "pcd", Path::new("t")).unwrap();
        assert_eq!(read.points(), &[p[0], p[2]], "{i}");
    }
    let half = [[1.0, 2.0, 3.0], [f64::NAN, 0.0, 0.0]];
    for bytes in [pcd_ascii(&half), pcd_binary(&half), pcd_compressed(&half)] {
        let e = read_cloud_bytes(&bytes, "pcd", Path::new("t"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("point 1 has a coordinate that is not finite"),
            "{e}"
        );
    }
}

#[test]
fn las_1_4_with_extended_records_reads() {
    let p = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
    for extended in [
        vec![],
        vec![vec![7u8; 100]],
        vec![vec![1u8; 3], vec![2u8; 70_000]],
    ] {
        let bytes = las_1_4(&p, &extended);
        let cloud = read_cloud_bytes(&bytes, "las", Path::new("x.las")).unwrap();
        assert_eq!(
            cloud.points(),
            &p[..],
            "{} extended records",
            extended.len()
        );
    }
}

#[test]
fn nan_points_and_bad_voxel_sizes_are_errors() {
    for s in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(CloudVoxelizer::new(s).is_err());
    }
    let e = KTree::from_points(&[[0.0; 3], [1.0, f64::NAN, 0.0]], 1.0, None, None).unwrap_err();
    assert!(e.to_string().contains("point 1"), "{e}");
    // Below a given origin, without a level: an error naming the point.
    let e =
        KTree::from_points(&[[0.0; 3], [-1.0, 0.0, 0.0]], 1.0, Some([0.0; 3]), None).unwrap_err();
    assert!(e.to_string().contains("point 1"), "{e}");
    // Too wide for the largest universe.
    assert!(KTree::from_points(&[[0.0; 3], [1e9, 0.0, 0.0]], 1e-3, None, None).is_err());
    // An empty cloud is the empty universe of level 0.
    let t = KTree::from_points(&[], 1.0, None, None).unwrap();
    assert_eq!((t.level(), t.voxel_count()), (0, 0));
}
