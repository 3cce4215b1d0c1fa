//! Valued trees against the dense array of values they were made from, K = 1 … 4 and every value type: the
//! tree is well formed and minimal, gives back every voxel's value (point by point, with the leaf holding
//! it, and densely), its leaves
//! cover the universe, and its shape is the binary tree of the voxels that hold a value.

use ktree::tree::valued::ValueLeaves;
use ktree::tree::{Rgb, Value};
use ktree::KTree;
use ktree_verify::labels::{painted, Painted, Palette};
use proptest::prelude::*;

fn check<const K: usize, V: Palette>(o: &Painted<K>) -> Result<(), TestCaseError> {
    let dense = o.dense::<V>();
    let tree = KTree::<K, V>::from_dense_values(o.level, &dense).unwrap();
    tree.assert_well_formed();
    let back = tree.to_dense_values().unwrap();
    prop_assert!(back.len() == dense.len());
    for (i, (a, b)) in back.iter().zip(&dense).enumerate() {
        prop_assert!(
            a.map(Value::key) == b.map(Value::key),
            "voxel {i}: {a:?} != {b:?}"
        );
        let p = o.universe().dense_point(i);
        prop_assert_eq!(tree.value_at(p).map(Value::key), b.map(Value::key));
        // The leaf holding the voxel: its value there, and the same value on all of its cell.
        let (log_side, v) = tree.leaf_at(p).unwrap();
        prop_assert_eq!(v.map(Value::key), b.map(Value::key));
        let side = 1usize << log_side;
        let corner = p.map(|c| c >> log_side << log_side);
        for j in 0..side.pow(K as u32) {
            let q: [u32; K] =
                std::array::from_fn(|a| corner[a] + (j / side.pow(a as u32) % side) as u32);
            prop_assert_eq!(
                dense[o.universe().dense_index(q)].map(Value::key),
                b.map(Value::key)
            );
        }
    }
    prop_assert_eq!(tree.leaf_at([1u32 << o.level; K]), None);
    // The leaves tile the universe.
    let volume: u128 = ValueLeaves::new(&tree).map(|l| l.unwrap().0.volume()).sum();
    prop_assert_eq!(volume, o.universe().voxels());
    // The shape: the voxels that hold a value.
    let support: Vec<bool> = dense.iter().map(Option::is_some).collect();
    let shape = tree.shape();
    shape.assert_well_formed();
    prop_assert_eq!(&shape, &KTree::<K>::from_dense(o.level, &support).unwrap());
    prop_assert_eq!(tree.voxel_count(), shape.voxel_count());
    // A tree of one value everywhere it is not empty is its shape with that value.
    let one: Vec<Option<V>> = support
        .iter()
        .map(|&b| b.then_some(V::PALETTE[0]))
        .collect();
    let uniform = KTree::<K, V>::from_dense_values(o.level, &one).unwrap();
    prop_assert_eq!(uniform.counts_per_level(), shape.counts_per_level());
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn dense_values_k1(o in painted::<1>()) { check::<1, u8>(&o)?; check::<1, f32>(&o)?; }
    #[test]
    fn dense_values_k2(o in painted::<2>()) { check::<2, u16>(&o)?; check::<2, Rgb>(&o)?; }
    #[test]
    fn dense_values_k3(o in painted::<3>()) { check::<3, u32>(&o)?; check::<3, i8>(&o)?; check::<3, f32>(&o)?; }
    #[test]
    fn dense_values_k4(o in painted::<4>()) { check::<4, u8>(&o)?; check::<4, Rgb>(&o)?; }
}

#[test]
fn two_zeros_are_two_values_and_nan_is_refused() {
    let tree = KTree::<1, f32>::from_dense_values(1, &[Some(0.0), Some(-0.0)]).unwrap();
    assert_eq!(tree.node_count(), 3, "0.0 and -0.0 do not merge");
    let e = KTree::<1, f32>::from_dense_values(1, &[Some(f32::NAN), None]).unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
}

#[test]
fn a_binary_tree_has_no_value_column_and_its_memory_is_unchanged() {
    let tree = KTree::<3>::from_dense(3, &(0..512).map(|i| i % 7 < 3).collect::<Vec<_>>()).unwrap();
    let unit = KTree::<3, ()>::from_dense_values(
        3,
        &(0..512)
            .map(|i| (i % 7 < 3).then_some(()))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    assert_eq!(tree, unit);
    assert_eq!(tree.heap_bytes(), unit.heap_bytes());
}

/// A valued tree through its `.ktree` file (version 3) and back, equal; a binary tree through the same
/// calls is version 2, byte for byte what `write_ktree` writes.
fn file_round_trip<const K: usize, V: Palette>(o: &Painted<K>) -> Result<(), TestCaseError> {
    use ktree::io::ktree::v3::{read_valued_ktree, write_valued_ktree};
    let tree = KTree::<K, V>::from_dense_values(o.level, &o.dense::<V>()).unwrap();
    let mut bytes = Vec::new();
    write_valued_ktree(&mut bytes, &tree).unwrap();
    prop_assert_eq!(bytes.len() % 8, 0);
    prop_assert_eq!(u16::from_le_bytes([bytes[6], bytes[7]]), 3);
    let back = read_valued_ktree::<K, V>(&bytes, "mem").unwrap();
    prop_assert!(back == tree);
    let shape = tree.shape();
    let mut binary = Vec::new();
    write_valued_ktree(&mut binary, &shape).unwrap();
    let mut plain = Vec::new();
    ktree::io::write_ktree(&mut plain, &shape).unwrap();
    prop_assert_eq!(&binary, &plain);
    prop_assert_eq!(read_valued_ktree::<K, ()>(&binary, "mem").unwrap(), shape);
    // Read in place: the values at every voxel (and outside), in a small and in a large batch (through
    // the table of the top levels), and the leaves of a walk, as the tree in memory has them.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.ktree");
    std::fs::write(&path, &bytes).unwrap();
    let mapped = ktree::io::ktree::v3::MappedValuedTree::<K, V>::open(&path).unwrap();
    let u = tree.universe();
    let mut points: Vec<[u32; K]> = (0..u.voxels() as usize).map(|i| u.dense_point(i)).collect();
    points.push([u.side() as u32; K]);
    let key = |v: &Option<V>| v.map(Value::key);
    let want: Vec<_> = points.iter().map(|&p| key(&tree.value_at(p))).collect();
    let got = ktree::query::values_at(&mapped, &points).unwrap();
    prop_assert_eq!(got.iter().map(key).collect::<Vec<_>>(), want.clone());
    let many: Vec<[u32; K]> = points.iter().copied().cycle().take(70_000).collect();
    let got = ktree::query::values_at(&mapped, &many).unwrap();
    for (g, p) in got.iter().zip(&many) {
        prop_assert_eq!(key(g), key(&tree.value_at(*p)));
    }
    let leaves: Vec<_> = ktree::tree::valued::ValueLeaves::new(&mapped)
        .map(|l| l.map(|(c, v)| (c, key(&v))))
        .collect::<Result<_, _>>()
        .unwrap();
    let in_memory: Vec<_> = tree.value_leaves().map(|(c, v)| (c, key(&v))).collect();
    prop_assert_eq!(leaves, in_memory);
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    #[test]
    fn files_k1(o in painted::<1>()) { file_round_trip::<1, u8>(&o)?; file_round_trip::<1, f32>(&o)?; }
    #[test]
    fn files_k2(o in painted::<2>()) { file_round_trip::<2, Rgb>(&o)?; file_round_trip::<2, i8>(&o)?; }
    #[test]
    fn files_k3(o in painted::<3>()) { file_round_trip::<3, u16>(&o)?; file_round_trip::<3, u32>(&o)?; }
    #[test]
    fn files_k4(o in painted::<4>()) { file_round_trip::<4, f32>(&o)?; }
}

#[test]
fn a_damaged_valued_file_is_an_error_at_a_byte_never_a_panic() {
    use ktree::io::ktree::v3::{read_valued_ktree, write_valued_ktree};
    let dense: Vec<Option<u16>> = (0..64u16).map(|i| (i % 5 != 0).then_some(i / 16)).collect();
    let tree = KTree::<2, u16>::from_dense_values(3, &dense).unwrap();
    let mut bytes = Vec::new();
    write_valued_ktree(&mut bytes, &tree).unwrap();
    for at in 0..bytes.len() {
        for bit in [0, 3, 7] {
            let mut bad = bytes.clone();
            bad[at] ^= 1 << bit;
            let e = read_valued_ktree::<2, u16>(&bad, "bad.ktree").unwrap_err();
            assert!(e.to_string().contains("bad.ktree"), "{e}");
        }
    }
    for len in 0..bytes.len() {
        assert!(
            read_valued_ktree::<2, u16>(&bytes[..len], "cut").is_err(),
            "{len}"
        );
    }
    // Mapped: the same checks when the file is opened.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.ktree");
    for at in (0..bytes.len()).step_by(5) {
        let mut bad = bytes.clone();
        bad[at] ^= 0x10;
        std::fs::write(&path, &bad).unwrap();
        let e = ktree::io::ktree::v3::MappedValuedTree::<2, u16>::open(&path).unwrap_err();
        assert!(e.to_string().contains("bad.ktree"), "{e}");
    }
    std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
    assert!(ktree::io::ktree::v3::MappedValuedTree::<2, u16>::open(&path).is_err());
    // Another value type, another K, and the binary readers: clear errors.
    let e = read_valued_ktree::<2, f32>(&bytes, "f")
        .unwrap_err()
        .to_string();
    assert!(e.contains("uint16") && e.contains("float32"), "{e}");
    assert!(read_valued_ktree::<3, u16>(&bytes, "k").is_err());
    let e = ktree::io::read_ktree::<2>(&bytes, "b")
        .unwrap_err()
        .to_string();
    assert!(e.contains("uint16") && e.contains("without values"), "{e}");
}

/// Building from valued runs: the runs of the dense array (maximal stretches of equal values), and the same
/// voxels as one run each (touching runs of one value), give the tree of the dense array, built on one
/// thread or apart below any split depth.
fn from_runs<const K: usize, V: Palette>(o: &Painted<K>) -> Result<(), TestCaseError> {
    use ktree::rays::ValueRuns;
    use ktree::Ray;
    let dense = o.dense::<V>();
    let want = KTree::<K, V>::from_dense_values(o.level, &dense).unwrap();
    let runs = ValueRuns::<K, V>::from_dense(o.level, &dense).unwrap();
    let got = KTree::from_value_runs(&runs);
    got.assert_well_formed();
    prop_assert!(got == want);
    prop_assert_eq!(runs.voxel_count(), want.voxel_count());
    let u = o.universe();
    let voxels = dense.iter().enumerate().filter_map(|(i, v)| {
        let p = u.dense_point(i);
        v.map(|v| (Ray::new(p, p[K - 1] + 1), v))
    });
    let single =
        ValueRuns::<K, V>::from_runs(o.level, voxels.collect::<Vec<_>>().into_iter().rev())
            .unwrap();
    let got = KTree::from_value_runs(&single);
    got.assert_well_formed();
    prop_assert!(got == want);
    // Built out of core at every cell depth, whole and in parts (the runs cut at the slabs): the file of
    // the tree.
    let dir = tempfile::tempdir().unwrap();
    let notes = ktree::io::ktree::Notes::new();
    let mut bytes = Vec::new();
    ktree::io::ktree::v3::write_valued_ktree_noted(&mut bytes, &want, None, &notes).unwrap();
    for depth in 0..=o.level {
        let out = dir.path().join("runs.ktree");
        let report = runs.write_file(&out, None, None, &notes, depth).unwrap();
        prop_assert!(std::fs::read(&out).unwrap() == bytes, "cell depth {depth}");
        prop_assert_eq!(&report.counts_per_level, &want.counts_per_level());
        prop_assert_eq!(report.cell_depth, depth);
        let count = 1u32 << depth;
        for parts in [2u32, 3] {
            let cuts: Vec<std::ops::Range<u32>> = (0..parts)
                .map(|p| count * p / parts..count * (p + 1) / parts)
                .collect();
            let writer = (depth % parts) as usize;
            let built: Vec<_> = cuts
                .iter()
                .map(|c| runs.stack_part_files(depth, c.clone(), &out, None).unwrap())
                .collect();
            write_parts(built, writer, &out, &notes);
            prop_assert!(
                std::fs::read(&out).unwrap() == bytes,
                "cell depth {depth}, {parts} parts"
            );
        }
        std::fs::remove_file(&out).unwrap();
        prop_assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
    // Built apart below every split depth, on one thread and on two: the same tree.
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for split in 0..=o.level + 1 {
            let got = pool.install(|| KTree::from_value_runs_split(&single, split));
            got.assert_well_formed();
            prop_assert!(got == want, "split {split}, {threads} threads");
        }
    }
    // A dense array of plain values with a background: the palette's first value is empty there.
    let background = V::PALETTE[0];
    let plain: Vec<V> = dense.iter().map(|v| v.unwrap_or(background)).collect();
    let emptied: Vec<Option<V>> = plain
        .iter()
        .map(|&v| (!v.same(background)).then_some(v))
        .collect();
    let want = KTree::<K, V>::from_dense_values(o.level, &emptied).unwrap();
    let runs = ValueRuns::<K, V>::from_dense_background(o.level, &plain, background).unwrap();
    let got = KTree::from_value_runs(&runs);
    got.assert_well_formed();
    prop_assert!(got == want);
    // Straight from the dense array, on one thread and on two.
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let got = pool
            .install(|| KTree::<K, V>::from_dense_background(o.level, &plain, background))
            .unwrap();
        got.assert_well_formed();
        prop_assert!(got == want, "from the dense array, {threads} threads");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(48))]
    #[test]
    fn runs_k1(o in painted::<1>()) { from_runs::<1, u8>(&o)?; from_runs::<1, f32>(&o)?; }
    #[test]
    fn runs_k2(o in painted::<2>()) { from_runs::<2, Rgb>(&o)?; from_runs::<2, u16>(&o)?; }
    #[test]
    fn runs_k3(o in painted::<3>()) { from_runs::<3, i8>(&o)?; from_runs::<3, u32>(&o)?; }
    #[test]
    fn runs_k4(o in painted::<4>()) { from_runs::<4, f32>(&o)?; from_runs::<4, u8>(&o)?; }
}

#[test]
fn valued_runs_that_overlap_or_hold_nan_are_errors() {
    use ktree::rays::ValueRuns;
    use ktree::Ray;
    let e = ValueRuns::<2, u8>::from_runs(2, [(Ray::new([1, 0], 3), 1), (Ray::new([1, 2], 4), 2)])
        .unwrap_err();
    assert!(e.to_string().contains("overlaps"), "{e}");
    // Touching runs are fine, in any order.
    assert!(
        ValueRuns::<2, u8>::from_runs(2, [(Ray::new([1, 2], 4), 2), (Ray::new([1, 0], 2), 1)])
            .is_ok()
    );
    let e = ValueRuns::<1, f32>::from_runs(1, [(Ray::new([0], 1), f32::NAN)]).unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    let e = ValueRuns::<1, f32>::from_dense(1, &[None, Some(f32::NAN)]).unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    let e = KTree::<2, f32>::from_dense_background(1, &[0.0, 0.0, 2.0, f32::NAN], 0.0).unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    let e = KTree::<2, f32>::from_dense_background(1, &[0.0; 5], 0.0).unwrap_err();
    assert!(!e.to_string().is_empty());
}

/// The file `out` written by part `writer` of `built`, the others streaming their levels to it in the
/// order their indexes are added (owner 1, 2, …), as ranks do.
fn write_parts<const K: usize, V: ktree::value::Value + Send + Sync>(
    mut built: Vec<ktree::stacking::ValuePart<K, V, ktree::io::SpilledFiles>>,
    writer: usize,
    out: &std::path::Path,
    notes: &ktree::io::ktree::Notes,
) -> ktree::stacking::ValueSlabsReport {
    let mut part = built.remove(writer);
    let mut streams = Vec::new();
    for mut other in built {
        let expected = part.add_part(&other.index_words()).unwrap();
        let mut words = Vec::new();
        let sent = other
            .stream_levels(5, &mut |chunk| {
                words.extend_from_slice(chunk);
                Ok(())
            })
            .unwrap();
        assert_eq!((sent, words.len() as u64), (expected, expected));
        streams.push(words.into_iter());
    }
    part.write::<ktree::rays::RayError>(out, None, notes, &mut |owner, words| {
        for w in words.iter_mut() {
            *w = streams[owner - 1]
                .next()
                .expect("the stream holds the words taken");
        }
        Ok(())
    })
    .unwrap()
}

/// The file of `slabs` built in the parts `cuts` (ranges of slabs), part `writer` writing `out` and the
/// others streaming their levels to it, as ranks do; the slabs' rows are read by `read`.
fn write_in_parts<const K: usize, V: Palette>(
    slabs: &ktree::stacking::ValueSlabs<K, V>,
    cuts: &[std::ops::Range<u32>],
    writer: usize,
    out: &std::path::Path,
    notes: &ktree::io::ktree::Notes,
    read: impl Fn(std::ops::Range<u32>, &mut Vec<V>) -> Result<(), ktree::rays::RayError> + Copy,
) -> ktree::stacking::ValueSlabsReport {
    let built: Vec<_> = cuts
        .iter()
        .map(|c| {
            slabs
                .stack_part_files(c.clone(), out, None, |rows, values: &mut Vec<V>| {
                    // Only the part's own slabs are read.
                    let thickness = slabs.level - slabs.slab_count().trailing_zeros();
                    assert!(c.start << thickness <= rows.start && rows.end <= c.end << thickness);
                    read(rows, values)
                })
                .unwrap()
        })
        .collect();
    write_parts(built, writer, out, notes)
}

/// Building from a box of the dense array read slab by slab along the last axis: for a box of the painted
/// universe (everything outside it emptied) and every slab thickness, the tree of the emptied array; a
/// slab of the wrong length is an error, not a tree.
fn from_slabs<const K: usize, V: Palette>(
    o: &Painted<K>,
    corners: ([u32; K], [u32; K]),
) -> Result<(), TestCaseError> {
    use ktree::rays::RayError;
    let u = o.universe();
    let side = u.side() as u32;
    let region: [std::ops::Range<u32>; K] = std::array::from_fn(|a| {
        let (p, q) = (corners.0[a] % (side + 1), corners.1[a] % (side + 1));
        p.min(q)..p.max(q)
    });
    let background = V::PALETTE[0];
    let plain: Vec<V> = o
        .dense::<V>()
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let p = u.dense_point(i);
            let inside = (0..K).all(|a| region[a].contains(&p[a]));
            v.filter(|_| inside).unwrap_or(background)
        })
        .collect();
    let want = KTree::<K, V>::from_dense_background(o.level, &plain, background).unwrap();
    // The box's values with the last coordinate in `rows`, axis 0 fastest.
    let read = |rows: std::ops::Range<u32>, out: &mut Vec<V>| {
        for (i, &v) in plain.iter().enumerate() {
            let p = u.dense_point(i);
            let inside = (0..K - 1).all(|a| region[a].contains(&p[a]));
            if inside && rows.contains(&p[K - 1]) {
                out.push(v);
            }
        }
        Ok::<_, RayError>(())
    };
    let row = std::mem::size_of::<V>() * region[..K - 1].iter().map(|r| r.len()).product::<usize>();
    let mut slabs_seen = Vec::new();
    for s in 0..=o.level {
        let got = KTree::<K, V>::from_value_slabs(
            o.level,
            region.clone(),
            background,
            row << s,
            |rows, out| {
                slabs_seen.push(rows.clone());
                read(rows, out)
            },
        )
        .unwrap();
        got.assert_well_formed();
        prop_assert!(got == want, "slabs 2^{s} thick, box {region:?}");
        // Written level by level with the cells' subtrees spilled: the file of the tree, and nothing else
        // left in the folder.
        let slabs = ktree::stacking::ValueSlabs {
            level: o.level,
            region: region.clone(),
            background,
            slab_bytes: row << s,
        };
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("slabs.ktree");
        let notes = ktree::io::ktree::Notes::from([("s".to_string(), s.to_string())]);
        let report = slabs.write_file(&out, None, None, &notes, read).unwrap();
        let mut bytes = Vec::new();
        ktree::io::ktree::v3::write_valued_ktree_noted(&mut bytes, &want, None, &notes).unwrap();
        prop_assert!(
            std::fs::read(&out).unwrap() == bytes,
            "file of slabs 2^{s} thick"
        );
        prop_assert_eq!(report.file_bytes, bytes.len() as u64);
        prop_assert_eq!(&report.counts_per_level, &want.counts_per_level());
        prop_assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // Built in parts, as ranks build it: each part reads its own slabs, and any one of them writes.
        let count = slabs.slab_count();
        for parts in 2..=3u32 {
            let cuts: Vec<std::ops::Range<u32>> = (0..parts)
                .map(|p| count * p / parts..count * (p + 1) / parts)
                .collect();
            for writer in 0..parts as usize {
                let out = dir.path().join("parts.ktree");
                let report = write_in_parts(&slabs, &cuts, writer, &out, &notes, read);
                prop_assert!(
                    std::fs::read(&out).unwrap() == bytes,
                    "{parts} parts, part {writer} writing, slabs 2^{s} thick"
                );
                prop_assert_eq!(&report.counts_per_level, &want.counts_per_level());
                prop_assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
                std::fs::remove_file(&out).unwrap();
            }
        }
        // The slabs cover the box's rows once, in order (none of an empty box is read).
        let covered: Vec<u32> = slabs_seen.drain(..).flatten().collect();
        let rows = if region.iter().any(|r| r.is_empty()) {
            0..0
        } else {
            region[K - 1].clone()
        };
        prop_assert_eq!(covered, rows.collect::<Vec<_>>());
    }
    if !region.iter().any(|r| r.is_empty()) {
        let short =
            KTree::<K, V>::from_value_slabs(o.level, region.clone(), background, 0, |rows, out| {
                read(rows, out)?;
                out.pop();
                Ok::<_, RayError>(())
            });
        prop_assert!(
            matches!(short, Err(RayError::SlabLength { .. })),
            "{short:?}"
        );
        let slabs = ktree::stacking::ValueSlabs {
            level: o.level,
            region: region.clone(),
            background,
            slab_bytes: 0,
        };
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("short.ktree");
        let notes = ktree::io::ktree::Notes::new();
        let short = slabs.write_file(&out, None, None, &notes, |rows, out| {
            read(rows, out)?;
            out.pop();
            Ok::<_, RayError>(())
        });
        prop_assert!(
            matches!(
                short,
                Err(ktree::stacking::BuildError::Source(
                    RayError::SlabLength { .. }
                ))
            ),
            "{short:?}"
        );
        prop_assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(48))]
    #[test]
    fn slabs_k1(o in painted::<1>(), c in any::<([u32; 1], [u32; 1])>()) { from_slabs::<1, u8>(&o, c)?; from_slabs::<1, f32>(&o, c)?; }
    #[test]
    fn slabs_k2(o in painted::<2>(), c in any::<([u32; 2], [u32; 2])>()) { from_slabs::<2, Rgb>(&o, c)?; from_slabs::<2, u16>(&o, c)?; }
    #[test]
    fn slabs_k3(o in painted::<3>(), c in any::<([u32; 3], [u32; 3])>()) { from_slabs::<3, i8>(&o, c)?; from_slabs::<3, u32>(&o, c)?; }
    #[test]
    fn slabs_k4(o in painted::<4>(), c in any::<([u32; 4], [u32; 4])>()) { from_slabs::<4, f32>(&o, c)?; from_slabs::<4, u8>(&o, c)?; }
}

#[test]
fn a_box_beyond_the_universe_is_an_error() {
    use ktree::rays::RayError;
    let got =
        KTree::<2, u8>::from_value_slabs(2, [0..5, 0..4], 0, 1 << 20, |_, _| Ok::<_, RayError>(()));
    assert!(matches!(got, Err(RayError::Space(_))), "{got:?}");
}

/// A valued file read in place as a tree without values ([`MappedLeaves`]): the nodes, ranks and blocks
/// of the tree in memory read the same way ([`LeavesOfValues`]), and the same nearest voxels.
fn mapped_leaves<const K: usize>(o: &Painted<K>, points: &[[i64; K]]) -> Result<(), TestCaseError> {
    use ktree::io::ktree::v3::{write_valued_ktree_file, MappedValuedTree};
    use ktree::query::nearest_many_signed;
    use ktree::tree::storage::TreeStorage;
    use ktree::tree::valued::LeavesOfValues;
    let tree = KTree::<K, u8>::from_dense_values(o.level, &o.dense::<u8>()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("values.ktree");
    write_valued_ktree_file(&path, &tree).unwrap();
    let mapped = MappedValuedTree::<K, u8>::open(&path).unwrap();
    let (file, memory) = (mapped.leaves(), LeavesOfValues(&tree));
    prop_assert_eq!(file.counts_per_level(), memory.counts_per_level());
    prop_assert_eq!(file.depth_count(), memory.depth_count());
    prop_assert_eq!(file.root_state().unwrap(), memory.root_state().unwrap());
    for d in 0..memory.depth_count() {
        let len = memory.level_len(d);
        prop_assert_eq!(file.level_len(d), len);
        for i in 0..=len {
            prop_assert_eq!(
                file.partial_rank(d, i).unwrap(),
                memory.partial_rank(d, i).unwrap(),
                "level {}, node {}",
                d,
                i
            );
        }
        for first in (0..len).step_by(1 << K).filter(|_| d > 0) {
            prop_assert_eq!(
                file.block_codes(d, first).unwrap(),
                memory.block_codes(d, first).unwrap()
            );
        }
    }
    prop_assert!(file.partial_rank(0, 2).is_err());
    let side = 1i64 << o.level;
    let points: Vec<[i64; K]> = points
        .iter()
        .map(|p| p.map(|c| c % (side + 2) - 1))
        .collect();
    prop_assert_eq!(
        nearest_many_signed(&file, &points).unwrap(),
        nearest_many_signed(&memory, &points).unwrap()
    );
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(48))]
    #[test]
    fn mapped_leaves_k1(o in painted::<1>(), p in proptest::collection::vec(any::<[u16; 1]>(), 8)) { mapped_leaves::<1>(&o, &p.iter().map(|q| q.map(i64::from)).collect::<Vec<_>>())?; }
    #[test]
    fn mapped_leaves_k2(o in painted::<2>(), p in proptest::collection::vec(any::<[u16; 2]>(), 8)) { mapped_leaves::<2>(&o, &p.iter().map(|q| q.map(i64::from)).collect::<Vec<_>>())?; }
    #[test]
    fn mapped_leaves_k3(o in painted::<3>(), p in proptest::collection::vec(any::<[u16; 3]>(), 8)) { mapped_leaves::<3>(&o, &p.iter().map(|q| q.map(i64::from)).collect::<Vec<_>>())?; }
    #[test]
    fn mapped_leaves_k4(o in painted::<4>(), p in proptest::collection::vec(any::<[u16; 4]>(), 8)) { mapped_leaves::<4>(&o, &p.iter().map(|q| q.map(i64::from)).collect::<Vec<_>>())?; }
}

/// A part's index that is not of another part of the same build is refused, naming why; nothing of it is
/// kept.
#[test]
fn part_indexes_of_other_builds_are_refused() {
    let slabs = ktree::stacking::ValueSlabs {
        level: 4,
        region: [1..15, 2..16, 0..13],
        background: 0u16,
        slab_bytes: 2 * 14 * 14 * 2,
    };
    let read = |rows: std::ops::Range<u32>, out: &mut Vec<u16>| {
        for z in rows {
            out.extend(
                (2..16u32).flat_map(|y| (1..15u32).map(move |x| ((x / 3 + y / 5 + z) % 4) as u16)),
            );
        }
        Ok::<_, ktree::rays::RayError>(())
    };
    assert_eq!(slabs.slab_count(), 8);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.ktree");
    let mut first = slabs.stack_part_files(0..4, &out, None, read).unwrap();
    let second = slabs.stack_part_files(4..8, &out, None, read).unwrap();
    let index = second.index_words();
    let refused = |part: &mut ktree::stacking::ValuePart<3, u16, _>, words: &[u64], why: &str| {
        let e = part.add_part(words).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
        assert!(e.to_string().contains(why), "{e}");
    };
    // Its own slabs again, a truncated index, a state that is none, another level.
    let own = first.index_words();
    refused(&mut first, &own, "slabs another part read");
    refused(&mut first, &index[..index.len() - 1], "length");
    let mut bad = index.clone();
    bad[11] = 7;
    refused(&mut first, &bad, "state");
    let mut bad = index.clone();
    bad[2] = 5;
    refused(&mut first, &bad, "another K, level");
    let mut bad = index.clone();
    bad[0] = 0;
    refused(&mut first, &bad, "not a part index");
    // A cell with children whose subtree it did not spill.
    let mut bad = index.clone();
    let at = 10
        + bad[10..]
            .iter()
            .position(|&w| w == 2 || w == 3)
            .expect("a cell with children");
    bad[at] = 0;
    refused(&mut first, &bad, "spilled cells");
    // The right index is still taken after the wrong ones.
    first.add_part(&index).unwrap();
}

/// A volume read slab by slab from a later plane on skips the planes before it (as a rank reading its own
/// slabs does), and refuses planes already read.
#[test]
fn volume_slabs_skip_to_the_planes_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let samples: Vec<u8> = (0..4 * 3 * 10u32).map(|i| (i * 7 % 5) as u8).collect();
    std::fs::write(dir.path().join("v.raw"), &samples).unwrap();
    let json = dir.path().join("v.json");
    std::fs::write(
        &json,
        r#"{"file": "v.raw", "dtype": "uint8", "shape_xyz": [4, 3, 10]}"#,
    )
    .unwrap();
    // Placed at z = 2: universe planes 5 and 6 are the file's planes 3 and 4.
    let mut slabs = ktree::solid::volume_file::label_slabs::<u8>(&json, 4, [0, 0, 2]).unwrap();
    assert_eq!(slabs.region, [0..4, 0..3, 2..12]);
    let plane = |z: usize| samples[12 * z..12 * (z + 1)].to_vec();
    let mut got = Vec::new();
    slabs.read(5..7, &mut got).unwrap();
    assert_eq!(got, [plane(3), plane(4)].concat());
    got.clear();
    slabs.read(7..8, &mut got).unwrap();
    assert_eq!(got, plane(5));
    let e = slabs.read(4..5, &mut got).unwrap_err();
    assert!(e.to_string().contains("already read"), "{e}");
}
