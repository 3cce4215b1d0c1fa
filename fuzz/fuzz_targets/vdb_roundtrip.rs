//! Round trips of OpenVDB: an arbitrary octree (levels 0…12, at any offset up to level 4 and at multiples
//! of 128 above) written with any positive voxel size and any origin reads back as the same tree and
//! placement — from the level and offset the file records, and from the same ones given — with the voxel
//! size written and the origin as the transform's centre of index 0 gives it back. Then any file that
//! reads is written at the placement chosen for it and read back as the same tree, placement and voxel size.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_vdb, write_vdb, GridMeta, GridPlacement};
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
struct Input {
    level: u8,
    shape: Vec<u8>,
    offset: [i32; 3],
    voxel_size: f64,
    origin: [f64; 3],
    /// Any bytes, read as a `.vdb` file.
    file: Vec<u8>,
}

/// The origin a file written with `meta` gives back: it stores the world centre of index 0.
fn stored_origin(meta: &GridMeta) -> [f64; 3] {
    let s = meta.voxel_size;
    meta.origin.map(|o| (o + s / 2.0) - s / 2.0)
}

fuzz_target!(|input: Input| {
    let level = u32::from(input.level) % 13;
    let tree = ktree_fuzz::arbitrary_tree::<3>(level, &input.shape);
    let offset = input.offset.map(|o| {
        if level <= 4 {
            i64::from(o)
        } else {
            i64::from(o) >> 7 << 7
        }
    });
    let meta = GridMeta {
        voxel_size: input.voxel_size,
        origin: input.origin,
    };
    let mut bytes = Vec::new();
    let in_range = offset
        .iter()
        .all(|&o| (1i64 << level) - o <= i64::from(i32::MAX));
    let positive = meta.voxel_size.is_finite() && meta.voxel_size > 0.0;
    match write_vdb(&mut bytes, &tree, offset, &meta) {
        Ok(()) => assert!(in_range && positive),
        Err(_) => {
            assert!(
                !(in_range && positive),
                "a valid offset or voxel size refused"
            );
            return;
        }
    }
    for (given_offset, given_level) in [(None, None), (Some(offset), Some(level))] {
        let placed =
            read_vdb(&bytes, "written", given_offset, given_level).expect("a written file reads");
        assert_eq!(placed.tree, tree);
        assert_eq!(placed.placement, GridPlacement { offset, level });
        assert_eq!(placed.meta.voxel_size, meta.voxel_size);
        let origin = stored_origin(&meta);
        let same = (placed.meta.origin.iter().zip(&origin))
            .all(|(read, stored)| read == stored || read.is_nan() && stored.is_nan());
        assert!(
            same,
            "origin {:?} read back as {:?}",
            meta.origin, placed.meta.origin
        );
    }

    if let Ok(placed) = read_vdb(&input.file, "fuzz", None, None) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
        let p = placed.placement;
        // Writing a full node at an offset that is not a multiple of OpenVDB's node sides writes all its
        // voxels: only small trees are written back at such offsets.
        let aligned = p.offset.iter().all(|&o| o % 128 == 0);
        if aligned || placed.tree.voxel_count() <= 1 << 15 {
            let mut again = Vec::new();
            if write_vdb(&mut again, &placed.tree, p.offset, &placed.meta).is_ok() {
                let back =
                    read_vdb(&again, "rewritten", None, None).expect("a written file reads back");
                assert_eq!(back.tree, placed.tree);
                assert_eq!(back.placement, p);
                assert_eq!(back.meta.voxel_size, placed.meta.voxel_size);
            }
        }
    }
});
