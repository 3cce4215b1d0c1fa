//! Round trips of binvox: an arbitrary octree (levels 0…5) written with any `translate` and `scale` reads
//! back as the same tree at offset 0 in its own universe, with the origin and `scale / D` written (a file
//! with a number that is not finite, or a scale that is not positive, is rejected); read with an offset into
//! a universe twice as large, it is the tree moved by that offset. Then any file that reads is written and
//! read back as the same tree and metadata.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_binvox, write_binvox, GridMeta, GridPlacement};
use ktree::{KTree, Universe};
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
struct Input {
    level: u8,
    shape: Vec<u8>,
    voxel_size: f64,
    origin: [f64; 3],
    shift: [u8; 3],
    /// Any bytes, read as a binvox file.
    file: Vec<u8>,
}

fn binvox(tree: &KTree<3>, meta: &GridMeta) -> Vec<u8> {
    let mut bytes = Vec::new();
    write_binvox(&mut bytes, tree, meta).expect("writing to memory");
    bytes
}

fuzz_target!(|input: Input| {
    let level = u32::from(input.level) % 6;
    let tree = ktree_fuzz::arbitrary_tree::<3>(level, &input.shape);
    let meta = GridMeta {
        voxel_size: input.voxel_size,
        origin: input.origin,
    };
    let bytes = binvox(&tree, &meta);
    // The file holds `scale = voxel size · D`; reading divides by `D` again.
    let d = f64::from(1u32 << level);
    let scale = meta.voxel_size * d;
    match read_binvox(&bytes, "written", None, None) {
        Ok(placed) => {
            assert_eq!(placed.tree, tree);
            assert_eq!(
                placed.placement,
                GridPlacement {
                    offset: [0; 3],
                    level
                }
            );
            assert_eq!(
                placed.meta,
                GridMeta {
                    voxel_size: scale / d,
                    origin: meta.origin
                }
            );
        }
        Err(e) => assert!(
            !(scale.is_finite() && scale > 0.0 && meta.origin.iter().all(|o| o.is_finite())),
            "a written file with finite metadata is rejected: {e}"
        ),
    }
    if level <= 4 && scale.is_finite() && scale > 0.0 && meta.origin.iter().all(|o| o.is_finite()) {
        // Moved by `shift` (each axis 0…D) into a universe of level L + 1: checked voxel by voxel.
        let shift = input.shift.map(|s| i64::from(s) % ((1 << level) + 1));
        let placed = read_binvox(&bytes, "moved", Some(shift), Some(level + 1))
            .expect("fits the larger universe");
        let u = Universe::<3>::new(level + 1).expect("a small universe");
        let dense: Vec<bool> = (0..u.dense_len(1 << 15).expect("small"))
            .map(|i| {
                let p = u.dense_point(i);
                let q: [i64; 3] = std::array::from_fn(|a| i64::from(p[a]) - shift[a]);
                q.iter().all(|&c| (0..1 << level).contains(&c))
                    && tree.contains(q.map(|c| c as u32))
            })
            .collect();
        let moved = KTree::<3>::from_dense(level + 1, &dense).expect("a small universe");
        assert_eq!(placed.tree, moved);
    }

    if let Ok(placed) = read_binvox(&input.file, "fuzz", None, None) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
        let d = f64::from(1u32 << placed.tree.level());
        let scale = placed.meta.voxel_size * d;
        // A grid whose side is not a power of two is written larger: its scale may overflow or vanish.
        if scale.is_finite() && scale > 0.0 {
            let again = binvox(&placed.tree, &placed.meta);
            let back =
                read_binvox(&again, "rewritten", None, None).expect("a written file reads back");
            assert_eq!(back.tree, placed.tree);
            assert_eq!(back.placement, placed.placement);
            assert_eq!(
                back.meta,
                GridMeta {
                    voxel_size: scale / d,
                    origin: placed.meta.origin
                }
            );
        }
    }
});
