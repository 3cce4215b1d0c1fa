//! Inputs that once made ktree panic, hang or allocate without bound, found by the fuzz targets in `fuzz/`
//! and the no-panic property tests; each is now a clear error (or a correct result).

use std::path::Path;

use ktree::io::{read_mesh_bytes, GeometryFileErrorKind};
use ktree::rays::ball_rays;

fn ply_error(bytes: &[u8]) -> String {
    match read_mesh_bytes(bytes, "ply", Path::new("case.ply")).map_err(|e| e.kind) {
        Err(GeometryFileErrorKind::Malformed(what)) => what,
        other => panic!("expected a parse error, got {other:?}"),
    }
}

/// `mesh_ply`: a version number beyond `u64` made the PLY parser panic (it unwraps the number's parse).
#[test]
fn ply_version_beyond_u64_is_an_error() {
    let crash = b"ply\nformat ascii 22222222222222222222222221.0\nelement verte}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}}x 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\xfaend_heaty gl 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    assert!(ply_error(crash).contains("number too large"));
    let count = b"ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nproperty float x\nend_header\n";
    assert!(ply_error(count).contains("number too large"));
}

/// An element without properties made the PLY parser push empty elements as many times as declared (a
/// hang and unbounded memory for a 60-byte file); more elements than bytes did the same more slowly.
#[test]
fn ply_counts_are_checked_against_the_input() {
    let empty =
        b"ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\nend_header\n";
    assert!(ply_error(empty).contains("no property"));
    let many = b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty uchar x\nend_header\n\x01";
    assert!(ply_error(many).contains("only 1 bytes follow"));
    assert!(ply_error(b"ply\nformat ascii 1.0\n").contains("no end_header"));
}

/// `no_panic`: a ball whose doubled centre and radius are near `i64::MIN`/`MAX` overflowed while clipping
/// its column range and its runs; the bounds are now computed without overflow. Checked voxel by voxel
/// against the definition `Σ (2c_i + 1 − centre2_i)² ≤ radius2²` (empty for a negative radius).
#[test]
fn ball_with_extreme_centre_and_radius_matches_the_definition() {
    let extremes = [i64::MIN, i64::MIN + 1, -1, 0, 7, i64::MAX - 1, i64::MAX];
    for &cx in &extremes {
        for &cy in &extremes {
            for &r in &extremes {
                let rays = ball_rays::<2>(3, [cx, cy], r).unwrap();
                let expected = (0..8i128)
                    .flat_map(|x| (0..8i128).map(move |y| (x, y)))
                    .filter(|&(x, y)| {
                        let dx = 2 * x + 1 - i128::from(cx);
                        let dy = 2 * y + 1 - i128::from(cy);
                        // A negative radius is an empty ball. Compared as u128: the squares of i64
                        // differences do not fit i128 together.
                        r >= 0
                            && (dx * dx) as u128 + (dy * dy) as u128
                                <= (i128::from(r) * i128::from(r)) as u128
                    })
                    .count();
                assert_eq!(
                    rays.voxel_count(),
                    expected as u128,
                    "centre ({cx}, {cy}), radius {r}"
                );
            }
        }
    }
}

/// A small box far from the origin in a level-31 quadtree: its central second moments are the box's own,
/// `V·w²/12` per axis (they used to cancel to a negative number when summed about the origin).
#[test]
fn central_moments_of_a_small_far_box_are_exact() {
    let (lo, hi) = ([6_030_483u32, 499_419_628], [6_030_496u32, 499_419_638]);
    let rays = ktree::RaySet::<2>::from_rays(
        31,
        (lo[0]..hi[0]).map(|x| ktree::Ray::new([x, lo[1]], hi[1])),
    )
    .unwrap();
    let m = ktree::ops::mass_properties(&ktree::stacking::paper::stack(&rays)).unwrap();
    let v = m.volume as f64;
    for axis in 0..2 {
        let w = f64::from(hi[axis] - lo[axis]);
        let want = v * w * w / 12.0;
        let got = m.central_moments[axis][axis];
        assert!(
            (got - want).abs() <= 1e-6 * want,
            "axis {axis}: {got} vs {want}"
        );
        let centre = f64::from(lo[axis]) + w / 2.0;
        assert!((m.centroid[axis] - centre).abs() < 1e-6);
    }
    assert!(m.central_moments[0][1].abs() <= 1e-6 * v);
}

/// `binvox_structured`: `write_binvox` wrote `translate` and `scale` in plain digits, 301 of them for
/// `1e300`, and its own reader rejects header lines longer than 256 bytes; the numbers now take an exponent
/// where the digits would be long, and read back exactly.
#[test]
fn binvox_with_huge_or_tiny_metadata_reads_back() {
    use ktree::io::{read_binvox, write_binvox, GridMeta};
    let tree =
        ktree::KTree::<3>::from_dense(1, &[true, false, false, true, false, true, true, false])
            .unwrap();
    for meta in [
        GridMeta {
            voxel_size: 1e-300,
            origin: [1e300, -1.5e-300, f64::MAX],
        },
        GridMeta {
            voxel_size: 1e300,
            origin: [-f64::MAX, 5e-324, 0.1],
        },
    ] {
        let mut bytes = Vec::new();
        write_binvox(&mut bytes, &tree, &meta).unwrap();
        let back = read_binvox(&bytes, "meta.binvox", None, None).unwrap();
        assert_eq!(back.tree, tree);
        assert_eq!(back.meta.origin, meta.origin);
        assert_eq!(back.meta.voxel_size, meta.voxel_size * 2.0 / 2.0);
    }
}

/// `octomap_bt_structured`: a `.bt` file of 90 bytes — a free voxel at key x = 1 and an occupied cube of
/// side 2^14 — read at offset 32767 on x (once the default placement: minus the smallest index) puts the
/// cube off its alignment, and its octree would have billions of nodes (the reader ran out of memory). Grid
/// readers stop at 2^20 + 2^5 nodes a byte of the file with a placement error; the default offset is now a
/// multiple of the largest aligned cell's side (32768 here), where the file reads as one cube.
#[test]
fn bt_cube_off_its_alignment_is_a_placement_error_not_unbounded_memory() {
    use ktree::io::{read_bt, GridFileErrorKind, BT_HEADER};
    let mut file = format!("{BT_HEADER}\nid OcTree\nsize 18\nres 1\ndata\n").into_bytes();
    file.extend_from_slice(&[0b11, 0]); // root: child 0 has children
    file.extend_from_slice(&[0b10_11, 0]); // depth 1: child 0 has children, child 1 (x + 2^14) occupied
    for _ in 2..15 {
        file.extend_from_slice(&[0b11, 0]); // depths 2…14: child 0 has children
    }
    file.extend_from_slice(&[0b01_00, 0]); // depth 15: voxel child 1 (key x = 1) free
    for (level, unknown_full) in [(None, false), (Some(21), true)] {
        let e = read_bt(
            &file,
            "cut.bt",
            Some([32767, 32768, 32768]),
            level,
            unknown_full,
        )
        .unwrap_err();
        assert!(
            matches!(&e.kind, GridFileErrorKind::GridPlacement(m) if m.contains("nodes")),
            "{e}"
        );
    }
    for offset in [None, Some([32768; 3])] {
        let aligned = read_bt(&file, "cut.bt", offset, Some(16), false).unwrap();
        assert_eq!(aligned.placement.offset[0], 32768);
        assert_eq!(aligned.tree.voxel_count(), 1 << 42);
        assert!(aligned.tree.node_count() < 1000);
    }
}

/// Found by fuzzing `.vdb`: a 46 KB grid whose root tiles the offset in its metadata (`ktree_offset`, 35
/// on z) leaves unaligned. The reader stopped at its node bound with a placement error, but the bound (then
/// 2^20 + 2^10 nodes a byte) let it build 48 million nodes first (0.9 s, over libFuzzer's time limit on a
/// loaded machine). The bound is now 2^20 + 2^5 nodes a byte: the same error, after counting at most 2.5
/// million nodes.
#[test]
fn a_vdb_with_unaligned_tiles_stops_at_the_node_bound() {
    use ktree::io::{read_vdb, GridFileErrorKind};
    let file = include_bytes!("../../fuzz/corpus/vdb/misaligned_tiles.vdb");
    let e = read_vdb(file, "tiles.vdb", None, None).unwrap_err();
    let bound = (1u64 << 20) + ((file.len() as u64) << 5);
    assert!(
        matches!(&e.kind, GridFileErrorKind::GridPlacement(m) if m.contains(&format!("more than {bound} nodes"))),
        "{e}"
    );
}

#[test]
fn a_las_extended_record_longer_than_the_file_is_an_error() {
    // LAS 1.4, 399 bytes, whose extended variable-length record declares 2^54 bytes of data: the `las`
    // crate allocated them before reading. The header is wrong in other ways, the first found now being
    // that its two point counts disagree (an extended record alone too long is a case of `cloud.rs`).
    let file = include_bytes!("../../fuzz/corpus/cloud_las/evlr_of_2_54_bytes.las");
    let e = ktree::io::read_cloud_bytes(file, "las", Path::new("evlr.las"))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "evlr.las: byte 107: LAS: the legacy point count 4294967295 disagrees with the point count 23362423134093312 at byte 247"
    );
}

/// The byte offset of the first chunk of a LAZ file (after the 8-byte offset of its chunk table) and its
/// points' record length.
fn first_laz_chunk(file: &[u8]) -> (usize, usize) {
    let start = u32::from_le_bytes(file[96..100].try_into().unwrap()) as usize;
    let record = u16::from_le_bytes(file[105..107].try_into().unwrap()) as usize;
    (start + 8, record)
}

fn laz_error(file: &[u8]) -> String {
    ktree::io::read_cloud_bytes(file, "laz", Path::new("damaged.laz"))
        .unwrap_err()
        .to_string()
}

/// `cloud_las`: a LAZ stream whose first four bytes are `FF FF FF FF` (above any value an arithmetic coder
/// starts with) made the `laz` crate's decoder index past its model's table: a panic. Each kind of
/// stream — a chunk of points after its first, a layer of a LAS 1.4 chunk, the chunk table — is refused.
#[test]
fn a_laz_stream_starting_above_the_coders_range_is_an_error() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/clouds");
    let simple = std::fs::read(data.join("simple.laz")).unwrap();
    assert!(ktree::io::read_cloud_bytes(&simple, "laz", Path::new("simple.laz")).is_ok());

    // LAS 1.2, point format 3: one stream a chunk, after the chunk's first point.
    let (chunk, record) = first_laz_chunk(&simple);
    let mut file = simple.clone();
    file[chunk + record..chunk + record + 4].fill(0xff);
    let e = laz_error(&file);
    assert_eq!(
        e,
        format!("damaged.laz: byte {chunk}: LAZ chunk 0: its stream (byte {record} of the chunk) starts with FF FF FF FF, which no LASzip encoder writes")
    );

    // The chunk table's entries.
    let table = i64::from_le_bytes(simple[chunk - 8..chunk].try_into().unwrap()) as usize;
    let mut file = simple.clone();
    file[table + 8..table + 12].fill(0xff);
    assert!(laz_error(&file).contains("the chunk table's stream starts with FF FF FF FF"));

    // LAS 1.4 (COPC), point format 7: nine layers of the point and one of its colour.
    let copc = std::fs::read(data.join("simple.copc.laz")).unwrap();
    let (chunk, record) = first_laz_chunk(&copc);
    let layers = chunk + record + 4 + 4 * 10;
    let mut file = copc.clone();
    file[layers..layers + 4].fill(0xff);
    let e = laz_error(&file);
    assert!(
        e.contains(&format!(
            "LAZ chunk 0: its layer 0's stream (byte {} of the chunk) starts with FF FF FF FF",
            layers - chunk
        )),
        "{e}"
    );
}
