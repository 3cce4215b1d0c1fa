//! `.ktree` version 2, K = 1 … 4: a round trip gives back the tree node for node, through the bytes and
//! through a memory map (counts, point queries at every voxel, leaves in Morton order); a level written in
//! arbitrary pieces gives the same bytes; version 1 streamed from the map is the version 1 writer's bytes; every single-bit flip and every truncation of a small file is
//! rejected; version 1 files are still read.

use ktree_verify::cases;

use cases::{ray_sets, Case};
use ktree::io::{
    read_ktree, read_ktree_any, read_ktree_file, write_ktree, write_ktree_file, write_ktree_v1,
    write_ktree_v1_view, KtreeFileErrorKind, KtreeView, KtreeWriter,
};
use ktree::stacking::paper::stack;
use ktree::tree::PackedStates;
use ktree::KTree;
use proptest::prelude::*;

fn v2_bytes<const K: usize>(tree: &KTree<K>) -> Vec<u8> {
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    bytes
}

fn round_trips<const K: usize>(case: &Case<K>, cuts: &[usize]) -> Result<(), TestCaseError> {
    let tree = stack(&case.rays);
    let bytes = v2_bytes(&tree);
    prop_assert_eq!(bytes.len() % 8, 0, "sections and file are word-aligned");
    let back = read_ktree::<K>(&bytes, "mem").map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!(back == tree, "tree changed through a v2 round trip");
    // Through a file and its memory map.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.ktree");
    write_ktree_file(&path, &tree).unwrap();
    prop_assert_eq!(std::fs::read(&path).unwrap(), bytes.clone());
    let view = KtreeView::open(&path).map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!(view.is_mapped());
    prop_assert_eq!(view.counts_per_level(), tree.counts_per_level());
    prop_assert_eq!(view.counts(), tree.counts());
    let from_file = read_ktree_file(&path)
        .map_err(|e| TestCaseError::fail(e.to_string()))?
        .into_dim::<K>()
        .ok()
        .unwrap();
    prop_assert!(from_file == tree);
    prop_assert!(view.to_tree::<K>().unwrap() == tree);
    let u = tree.universe();
    for i in 0..u.dense_len(1 << 18).unwrap() {
        let p = u.dense_point(i);
        prop_assert_eq!(view.contains(p).unwrap(), tree.contains(p), "point {:?}", p);
    }
    let mut leaves = Vec::new();
    view.for_each_leaf::<K>(|c, s| leaves.push((c, s))).unwrap();
    prop_assert_eq!(leaves, tree.leaves().collect::<Vec<_>>());
    // Version 1 streamed from the map: the bytes the in-memory version 1 writer gives.
    let (mut streamed, mut whole) = (Vec::new(), Vec::new());
    write_ktree_v1_view(&mut streamed, &view).unwrap();
    write_ktree_v1(&mut whole, &tree).unwrap();
    prop_assert_eq!(streamed, whole, "version 1 streamed from a version 2 map");
    // Pieces of arbitrary sizes, joined by shifting, give the same file.
    let mut pieces = Vec::new();
    let mut w = KtreeWriter::new(&mut pieces, K, tree.level()).unwrap();
    for d in 0..tree.depth_count() {
        let level = tree.level_states(d);
        let mut i = 0;
        let mut c = 0;
        while i < level.len() {
            let n = (1 + cuts[c % cuts.len()] % 70).min(level.len() - i);
            c += 1;
            let mut words = vec![0u64; n.div_ceil(32)];
            for (k, j) in (i..i + n).enumerate() {
                words[k / 32] |= (level.get(j) as u64) << (2 * (k % 32));
            }
            let piece = PackedStates::from_words(words, n).unwrap();
            w.append_states(&piece).unwrap();
            i += n;
        }
        w.end_level().unwrap();
    }
    w.finish().unwrap();
    prop_assert_eq!(pieces, bytes.clone(), "pieces joined differently");
    // Version 1 of the same tree still reads back.
    let mut v1 = Vec::new();
    write_ktree_v1(&mut v1, &tree).unwrap();
    prop_assert!(read_ktree::<K>(&v1, "v1").unwrap() == tree);
    // A few truncations and a padding: errors naming an offset inside or at the end of the file.
    for &cut in cuts {
        let at = cut % bytes.len();
        let e = read_ktree_any(&bytes[..at], "cut");
        prop_assert!(e.is_err(), "truncation at {} accepted", at);
    }
    let mut padded = bytes.clone();
    padded.extend_from_slice(&[0; 8]);
    prop_assert!(read_ktree_any(&padded, "pad").is_err());
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn v2_round_trip_k1(case in ray_sets::<1>(), cuts in prop::collection::vec(any::<usize>(), 1..6)) { round_trips(&case, &cuts)?; }

    #[test]
    fn v2_round_trip_k2(case in ray_sets::<2>(), cuts in prop::collection::vec(any::<usize>(), 1..6)) { round_trips(&case, &cuts)?; }

    #[test]
    fn v2_round_trip_k3(case in ray_sets::<3>(), cuts in prop::collection::vec(any::<usize>(), 1..6)) { round_trips(&case, &cuts)?; }

    #[test]
    fn v2_round_trip_k4(case in ray_sets::<4>(), cuts in prop::collection::vec(any::<usize>(), 1..6)) { round_trips(&case, &cuts)?; }
}

/// A small tree of each dimension: every single-bit flip and every truncation of its file is rejected,
/// through the bytes and (for a sample) through a memory map.
fn every_flip_and_cut<const K: usize>(level: u32) {
    let side = 1u32 << level;
    let dense: Vec<bool> = (0..side.pow(K as u32))
        .map(|i| (i * 7 + i / 3) % 5 < 2)
        .collect();
    let tree = KTree::<K>::from_dense(level, &dense).unwrap();
    let bytes = v2_bytes(&tree);
    assert!(tree.depth_count() >= 2);
    let dir = tempfile::tempdir().unwrap();
    for i in 0..bytes.len() {
        for bit in 0..8 {
            let mut bad = bytes.clone();
            bad[i] ^= 1 << bit;
            let e = read_ktree_any(&bad, "flip");
            assert!(
                e.is_err(),
                "K = {K}: flip of bit {bit} of byte {i} accepted"
            );
            if bit == 0 && i % 5 == 0 {
                let path = dir.path().join("flip.ktree");
                std::fs::write(&path, &bad).unwrap();
                assert!(
                    KtreeView::open(&path).is_err(),
                    "K = {K}: mapped flip at {i}"
                );
            }
        }
    }
    for cut in 0..bytes.len() {
        let e = read_ktree_any(&bytes[..cut], "cut").unwrap_err();
        assert!(
            e.offset().is_some_and(|o| o <= bytes.len() as u64),
            "offset beyond the file"
        );
        assert!(KtreeView::from_bytes(bytes[..cut].to_vec(), "cut").is_err());
    }
}

#[test]
fn every_single_bit_flip_and_truncation_is_rejected() {
    every_flip_and_cut::<1>(5);
    every_flip_and_cut::<2>(3);
    every_flip_and_cut::<3>(2);
    every_flip_and_cut::<4>(2);
}

#[test]
fn a_bad_section_names_its_level_and_offset() {
    let tree = KTree::<2>::from_dense(
        3,
        &(0..64)
            .map(|i| (i % 8 < 4 && i / 8 < 4) || i == 5 + 8 * 6)
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let bytes = v2_bytes(&tree);
    // The root section is the word at byte 16 followed by its rank sample at 24; level 1 starts at 32.
    let mut bad = bytes.clone();
    bad[24] ^= 0x80; // the rank sample's high bit: the CRC of section 0 is the first check to fail
    let e = read_ktree_any(&bad, "f.ktree").unwrap_err();
    assert_eq!(e.offset(), Some(24), "{e}");
    let mut bad = bytes.clone();
    // Swap two different nodes of level 1: the counts stay, the section's checksum does not.
    let w = u64::from_le_bytes(bad[32..40].try_into().unwrap());
    let j = (1..4)
        .find(|&j| w >> (2 * j) & 3 != w & 3)
        .expect("level 1 is not uniform");
    let diff = (w ^ w >> (2 * j)) & 3;
    let swapped = w ^ diff ^ diff << (2 * j);
    bad[32..40].copy_from_slice(&swapped.to_le_bytes());
    let e = read_ktree_any(&bad, "f.ktree").unwrap_err();
    assert_eq!(e.offset(), Some(32), "{e}");
    assert!(
        matches!(e.kind, KtreeFileErrorKind::SectionChecksum { level: 1, .. }),
        "{e}"
    );
    assert!(e
        .to_string()
        .starts_with("f.ktree: byte 32: checksum mismatch in the section of level 1"));
}
