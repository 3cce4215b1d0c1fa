//! The OpenVDB reader and writer against each other and against hand-made files.

use super::read::*;
use super::values::Reader;
use super::write::*;
use super::*;
use crate::io::interop::grid::{GridBoxes, GridFileErrorKind, GridMeta};
use crate::rays::ball_rays;
use crate::stacking::paper::stack;
use crate::tree::KTree;

#[test]
fn round_trip_keeps_the_universe_and_tiles_cover_whole_nodes() {
    for (tree, offset) in [
        (
            stack(&ball_rays::<3>(6, [30, 25, 26], 20).unwrap()),
            [5, -300, 0],
        ),
        (
            stack(&ball_rays::<3>(9, [300, 250, 260], 200).unwrap()),
            [0, -512, 128],
        ),
        (KTree::<3>::empty(2).unwrap(), [0; 3]),
    ] {
        let mut bytes = Vec::new();
        write_vdb(&mut bytes, &tree, offset, &GridMeta::default()).unwrap();
        let p = read_vdb(&bytes, "v", None, None).unwrap();
        assert_eq!(p.tree, tree);
        assert_eq!(p.placement.offset, offset);
    }
    // A full level-13 universe at offset 0 is 8 root children of tiles: no leaf at all.
    let mut bytes = Vec::new();
    write_vdb(
        &mut bytes,
        &KTree::<3>::full(13).unwrap(),
        [0; 3],
        &GridMeta::default(),
    )
    .unwrap();
    assert!(bytes.len() < 8 * 50_000, "{} bytes", bytes.len());
}

#[test]
fn a_node_bound_below_the_trees_size_is_refused_and_at_it_the_tree_reads() {
    let ball = stack(&ball_rays::<3>(5, [16, 16, 15], 11).unwrap());
    let labels = KTree::<3, u8>::from_dense_values(
        3,
        &(0..512u16)
            .map(|i| (i % 3 != 0).then_some((i % 7 + 1) as u8))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let (mut binary, mut valued) = (Vec::new(), Vec::new());
    write_vdb(&mut binary, &ball, [0; 3], &GridMeta::default()).unwrap();
    write_vdb_values(&mut valued, &labels, [0; 3], &GridMeta::default()).unwrap();
    let n = ball.node_count();
    assert_eq!(
        read_vdb_within(&binary, "b", None, None, n).unwrap().tree,
        ball
    );
    let e = read_vdb_within(&binary, "b", None, None, n - 1).unwrap_err();
    assert!(
        matches!(&e.kind, GridFileErrorKind::GridPlacement(m) if m.contains("nodes")),
        "{e}"
    );
    let read = read_vdb_values_within(&valued, "v", None, None, 1 << 12).unwrap();
    assert_eq!(read.tree, crate::AnyValuedTree::from(labels.clone()));
    let e = read_vdb_values_within(&valued, "v", None, None, 16).unwrap_err();
    assert!(e.to_string().contains("more than 16"), "{e}");
}

/// A file's header up to its grid count: magic, versions, no file metadata.
fn file_head() -> Vec<u8> {
    let mut b = MAGIC.to_le_bytes().to_vec();
    b.extend_from_slice(&FILE_VERSION.to_le_bytes());
    b.extend_from_slice(&[0; 8]);
    b.push(1);
    b.extend_from_slice(&[b'0'; 36]);
    b.extend_from_slice(&0u32.to_le_bytes());
    b
}

#[test]
fn a_grid_end_before_its_descriptor_is_refused_at_the_first_descriptor() {
    // A header, a grid count of 100 000, and one descriptor of another grid type whose end position
    // points back at the descriptor itself: the scan must stop there, not read it 100 000 times.
    let mut b = file_head();
    b.extend_from_slice(&100_000i32.to_le_bytes());
    let descriptor_at = b.len() as i64;
    for s in ["g", "Tree_vec3i_5_4_3", ""] {
        put_str(&mut b, s);
    }
    let end_field_at = b.len() + 16;
    for p in [0, 0, descriptor_at] {
        b.extend_from_slice(&p.to_le_bytes());
    }
    let e = read_vdb(&b, "loop", None, None).unwrap_err();
    assert!(matches!(e.kind, GridFileErrorKind::Data(_)), "{e}");
    assert_eq!(e.offset(), Some(end_field_at as u64), "{e}");
}

#[test]
fn level_sets_are_passed_over_by_the_value_reader_and_named_by_their_class() {
    // A header, then 3000 descriptors of FloatGrids, each followed by a byte and pointing at one header
    // of 2000 metadata entries and class "level set": reading values, the scan stops reading that header
    // again once twice the file's length has been read, and says why the file is refused.
    let mut b = file_head();
    let count = 3000;
    b.extend_from_slice(&(count as i32).to_le_bytes());
    let descriptor = |grid_at: i64, end_at: i64| {
        let mut d = Vec::new();
        for s in ["g", FLOAT_TREE, ""] {
            put_str(&mut d, s);
        }
        for p in [grid_at, 0, end_at] {
            d.extend_from_slice(&p.to_le_bytes());
        }
        d.push(0);
        d
    };
    let each = descriptor(0, 0).len() as i64;
    let header_at = b.len() as i64 + each * count;
    for i in 0..count {
        let end_at = b.len() as i64 + each;
        assert_eq!(b.len() as i64, header_at - each * (count - i));
        b.extend_from_slice(&descriptor(header_at, end_at));
    }
    b.extend_from_slice(&0u32.to_le_bytes()); // compression
    put_u32(&mut b, 2001);
    for _ in 0..2000 {
        for s in ["a", "b"] {
            put_str(&mut b, s);
        }
        put_u32(&mut b, 0);
    }
    let class_at = b.len() + 4 + 5 + 4 + 6;
    for s in ["class", "string", "level set"] {
        put_str(&mut b, s);
    }
    put_str(&mut b, "TranslationMap");
    b.extend_from_slice(&[0; 24]);
    let e = read_vdb_values(&b, "sdf", None, None).unwrap_err();
    assert!(
        matches!(&e.kind, GridFileErrorKind::Unsupported(m) if m.contains("\"level set\"")),
        "{e}"
    );
    assert_eq!(e.offset(), Some(class_at as u64), "{e}");
}

#[test]
fn a_small_file_claiming_huge_counts_is_refused_before_allocating() {
    let tree = stack(&ball_rays::<3>(4, [8, 8, 8], 5).unwrap());
    let mut bytes = Vec::new();
    write_vdb(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
    // The root child count sits right after the tile count, just before the first node origin.
    let topo = bytes
        .windows(9)
        .position(|w| w == [1, 0, 0, 0, 0, 0, 0, 0, 0])
        .unwrap();
    let mut huge = bytes[..topo + 13].to_vec();
    huge[topo + 9..topo + 13].copy_from_slice(&u32::MAX.to_le_bytes());
    huge.truncate(100.max(huge.len()));
    let e = read_vdb(&huge, "huge", None, None).unwrap_err();
    assert!(matches!(e.kind, GridFileErrorKind::Truncated(_)), "{e}");
    assert!(e.to_string().starts_with("huge: byte "), "{e}");
    let e = read_vdb(b"not a vdb file at all", "x", None, None).unwrap_err();
    assert_eq!(
        (e.offset(), e.to_string().contains("bad magic")),
        (Some(0), true)
    );
}

/// The position of the root child count in a file `write_vdb` wrote: after the buffer count (1), the
/// background (false) and the tile count (0); the first child's origin follows it.
fn root_counts_at(bytes: &[u8]) -> usize {
    bytes
        .windows(9)
        .position(|w| w == [1, 0, 0, 0, 0, 0, 0, 0, 0])
        .unwrap()
        + 9
}

#[test]
fn root_entries_off_the_root_keys_or_met_twice_are_refused() {
    let tree = stack(&ball_rays::<3>(4, [8, 8, 8], 5).unwrap());
    let mut bytes = Vec::new();
    write_vdb(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
    let origin_at = root_counts_at(&bytes) + 4;
    // The child's origin moved one voxel along y: OpenVDB keys its root table by multiples of 4096.
    let mut off = bytes.clone();
    off[origin_at + 4] = 1;
    let e = read_vdb(&off, "off", None, None).unwrap_err();
    assert!(
        matches!(&e.kind, GridFileErrorKind::Data(m) if m.contains("[0, 1, 0] is not a multiple of 4096")),
        "{e}"
    );
    assert_eq!(e.offset(), Some(origin_at as u64), "{e}");
    // An active tile at the child's origin, before it: the child meets a place already taken.
    let tiles_at = origin_at - 8;
    let mut twice = bytes[..tiles_at].to_vec();
    twice.extend_from_slice(&1u32.to_le_bytes());
    twice.extend_from_slice(&bytes[tiles_at + 4..origin_at]);
    twice.extend_from_slice(&[0; 12]);
    twice.extend_from_slice(&[1, 1]);
    twice.extend_from_slice(&bytes[origin_at..]);
    let e = read_vdb(&twice, "twice", None, None).unwrap_err();
    assert!(
        matches!(&e.kind, GridFileErrorKind::Data(m) if m.contains("a second root entry at [0, 0, 0]")),
        "{e}"
    );
    assert_eq!(e.offset(), Some(origin_at as u64 + 14), "{e}");
}

#[test]
fn leaf_masks_become_boxes_of_exactly_their_voxels() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut random = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut masks = vec![[0u64; 8], [u64::MAX; 8], [0x5555_5555_5555_5555; 8]];
    masks.push(std::array::from_fn(
        |x| if x % 3 == 0 { u64::MAX } else { 0 },
    ));
    for _ in 0..200 {
        let sparse = random() % 4;
        masks.push(std::array::from_fn(|_| {
            let w = random();
            (0..sparse).fold(w, |w, _| w & random())
        }));
    }
    let r = Reader {
        bytes: &[],
        at: 0,
        file: "t",
    };
    for mask in &masks {
        let mut boxes = GridBoxes::default();
        add_leaf(&mut boxes, &r, [8, -16, 24], mask).unwrap();
        let mut seen = [false; 512];
        for b in &boxes.inside {
            for x in 0..b.size[0] as i64 {
                for y in 0..b.size[1] as i64 {
                    for z in 0..b.size[2] as i64 {
                        let p = [
                            b.origin[0] + x - 8,
                            b.origin[1] + y + 16,
                            b.origin[2] + z - 24,
                        ];
                        assert!(p.iter().all(|c| (0..8).contains(c)), "{b:?}");
                        let n = (p[0] * 64 + p[1] * 8 + p[2]) as usize;
                        assert!(!seen[n], "voxel {n} twice");
                        seen[n] = true;
                    }
                }
            }
        }
        for (n, &s) in seen.iter().enumerate() {
            assert_eq!(
                s,
                mask[n / 64] >> (n % 64) & 1 == 1,
                "voxel {n} of {mask:x?}"
            );
        }
    }
    // Equal rows and slices are one box: a full leaf is one.
    let mut boxes = GridBoxes::default();
    add_leaf(&mut boxes, &r, [0; 3], &[u64::MAX; 8]).unwrap();
    assert_eq!(boxes.inside.len(), 1);
}

#[test]
fn a_long_transform_name_is_shortened_in_its_message() {
    let tree = stack(&ball_rays::<3>(4, [8, 8, 8], 5).unwrap());
    let mut bytes = Vec::new();
    write_vdb(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
    let name = b"UniformScaleTranslateMap";
    let at = bytes.windows(name.len()).position(|w| w == name).unwrap();
    let long = "M".repeat(10_000);
    let mut bad = bytes[..at - 4].to_vec();
    put_str(&mut bad, &long);
    bad.extend_from_slice(&bytes[at + name.len()..]);
    let e = read_vdb(&bad, "long", None, None).unwrap_err();
    assert!(
        matches!(&e.kind, GridFileErrorKind::Unsupported(m) if m.contains(&format!("{}…", &long[..64]))),
        "{e}"
    );
    assert!(e.to_string().len() < 200, "{e}");
    assert_eq!(e.offset(), Some(at as u64 - 4));
}
