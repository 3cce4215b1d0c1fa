//! The public constructors take arbitrary input and answer with a value or an error, never a panic: cells,
//! ray sets, meshes, volumes, trees from raw words and levels, trees from cells, and `.ktree` bytes. Whatever
//! they accept is well formed, and the library's operations run on it without panicking.

use ktree::io::{read_ktree_any, write_ktree, write_ktree_v1};
use ktree::solid::mesh::{Placement, TriangleMesh};
use ktree::solid::volume::{Select, Volume};
use ktree::tree::PackedStates;
use ktree::{KTree, Ray, RaySet, Universe};
use ktree_verify::objects::object;
use proptest::prelude::*;

/// Small numbers most of the time, any `u32` sometimes.
fn coordinate() -> impl Strategy<Value = u32> {
    prop_oneof![4 => 0u32..20, 1 => any::<u32>()]
}

/// Levels where the work is small, and levels beyond every limit.
fn level() -> impl Strategy<Value = u32> {
    prop_oneof![4 => 0u32..6, 1 => 21u32..40]
}

/// Finite numbers most of the time, NaN and infinities sometimes.
fn real() -> impl Strategy<Value = f64> {
    prop_oneof![8 => -10.0..10.0f64, 1 => any::<f64>()]
}

/// Runs the read-only operations of a tree; none may panic.
fn exercise<const K: usize>(tree: &KTree<K>) {
    tree.assert_well_formed();
    let full: u128 = tree.full_cells().map(|c| c.volume()).sum();
    assert_eq!(full, tree.voxel_count());
    assert!(tree.leaves().count() as u64 <= tree.node_count());
    let _ = tree.contains([0; K]);
    let _ = tree.contains([u32::MAX; K]);
    let not = !tree;
    not.assert_well_formed();
    let union = (tree | &not).unwrap();
    assert_eq!(union, KTree::full(tree.level()).unwrap());
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    let back = read_ktree_any(&bytes, "tree.ktree")
        .unwrap()
        .into_dim::<K>();
    assert_eq!(back.ok().as_ref(), Some(tree));
}

proptest! {
    #[test]
    fn cells_are_checked(origin in prop::array::uniform3(coordinate()), universe in level(), at in level()) {
        if let Ok(u) = Universe::<3>::new(universe) {
            if let Ok(c) = u.cell(origin, at) {
                prop_assert_eq!(c.universe_level(), universe);
                prop_assert_eq!(c.level(), at);
                prop_assert!(c.origin().iter().all(|&o| u64::from(o) % c.side() == 0));
                prop_assert!(c.origin().iter().all(|&o| u64::from(o) < u.side()));
            }
        }
    }

    #[test]
    fn ray_sets_are_checked(
        level in level(),
        rays in prop::collection::vec((prop::array::uniform3(coordinate()), coordinate()), 0..12),
    ) {
        let rays = rays.into_iter().map(|(start, z2)| Ray::new(start, z2));
        if let Ok(set) = RaySet::<3>::from_rays(level, rays) {
            let tree = KTree::from_rays(&set);
            prop_assert_eq!(tree.voxel_count(), set.voxel_count());
            exercise(&tree);
        }
    }

    #[test]
    fn meshes_are_checked(
        vertices in prop::collection::vec(prop::array::uniform3(real()), 0..8),
        triangles in prop::collection::vec(prop::array::uniform3(prop_oneof![0u32..8, any::<u32>()]), 0..8),
        level in level(),
        scale in real(),
        translate in prop::array::uniform3(real()),
    ) {
        if let Ok(mesh) = TriangleMesh::new(vertices, triangles) {
            let _ = (mesh.bounds(), mesh.signed_volume(), mesh.surface_area(), mesh.open_edges());
            let placements = [Placement::fit(&mesh, level).ok(), Some(Placement { scale, translate })];
            for p in placements.iter().flatten() {
                if let Ok(r) = mesh.to_rays(level, p) {
                    exercise(&KTree::from_rays(&r.rays));
                }
            }
        }
    }

    #[test]
    fn volumes_are_checked(
        shape in prop::array::uniform3(prop_oneof![8 => 0usize..5, 1 => any::<usize>()]),
        samples in prop::collection::vec(real(), 130),
        short in prop_oneof![3 => Just(0usize), 1 => 0usize..3],
        level in level(),
        offset in prop::array::uniform3(coordinate()),
        label in any::<bool>(),
    ) {
        // Mostly as many samples as the shape has voxels, sometimes fewer.
        let n = shape.iter().try_fold(1usize, |p, &s| p.checked_mul(s)).unwrap_or(usize::MAX);
        let values = samples[..n.min(samples.len()).saturating_sub(short)].to_vec();
        if let Ok(volume) = Volume::new(shape, values, [1.0; 3]) {
            let select = if label { Select::Label(1.0) } else { Select::AtLeast(0.0) };
            let _ = volume.fitting_level();
            if let Ok(rays) = volume.to_rays(level, offset, select) {
                prop_assert_eq!(rays.voxel_count(), volume.count(select) as u128);
                exercise(&KTree::from_rays(&rays));
            }
        }
    }

    #[test]
    fn trees_from_raw_words_are_checked(
        level in level(),
        raw in prop::collection::vec((prop::collection::vec(any::<u64>(), 0..3), 0usize..70), 0..4),
    ) {
        let levels: Result<Vec<PackedStates>, _> =
            raw.into_iter().map(|(words, len)| PackedStates::from_words(words, len)).collect();
        if let Ok(levels) = levels {
            if let Ok(tree) = KTree::<2>::from_level_states(level, levels) {
                exercise(&tree);
            }
        }
    }

    #[test]
    fn trees_from_changed_levels_are_checked(obj in object::<2>(), depth in any::<prop::sample::Index>(), bit in any::<prop::sample::Index>()) {
        // A real tree with one bit of one level flipped: sometimes still a tree, mostly not.
        let tree = obj.tree();
        let mut levels: Vec<(Vec<u64>, usize)> = (0..tree.depth_count())
            .map(|d| (tree.level_states(d).words().to_vec(), tree.level_states(d).len()))
            .collect();
        let d = depth.index(levels.len());
        let bits = levels[d].0.len() * 64;
        prop_assume!(bits > 0);
        let b = bit.index(bits);
        levels[d].0[b / 64] ^= 1 << (b % 64);
        let levels: Result<Vec<PackedStates>, _> =
            levels.into_iter().map(|(words, len)| PackedStates::from_words(words, len)).collect();
        if let Ok(levels) = levels {
            if let Ok(changed) = KTree::<2>::from_level_states(obj.level, levels) {
                exercise(&changed);
            }
        }
    }

    #[test]
    fn trees_from_cells_are_checked(
        level in 0u32..5,
        cells in prop::collection::vec((prop::array::uniform2(0u32..16), 0u32..5), 0..12),
    ) {
        let u = Universe::<2>::new(level).unwrap();
        let cells: Vec<_> = cells.into_iter().filter_map(|(o, l)| u.cell(o, l).ok()).collect();
        if let Ok(tree) = KTree::from_cells(u, &cells) {
            let given: u128 = cells.iter().map(|c| c.volume()).sum();
            prop_assert_eq!(tree.voxel_count(), given);
            for c in &cells {
                prop_assert!(tree.contains(c.origin()));
            }
            exercise(&tree);
        }
    }

    #[test]
    fn ktree_bytes_are_checked(bytes in prop::collection::vec(any::<u8>(), 0..120)) {
        if let Ok(tree) = read_ktree_any(&bytes, "any.ktree") {
            ktree::with_dim!(&tree, AnyTree, t => exercise(t));
        }
    }

    #[test]
    fn changed_ktree_files_with_a_fixed_checksum_are_checked(
        obj in object::<3>(),
        at in any::<prop::sample::Index>(),
        value in any::<u8>(),
    ) {
        // Change one byte, then make the checksum agree, so that the structural checks must catch it.
        let mut bytes = Vec::new();
        write_ktree_v1(&mut bytes, &obj.tree()).unwrap();
        let crc_at = bytes.len() - 4;
        bytes[at.index(crc_at)] = value;
        let crc = crc_of(&bytes[..crc_at]);
        bytes[crc_at..].copy_from_slice(&crc.to_le_bytes());
        if let Ok(tree) = read_ktree_any(&bytes, "changed.ktree") {
            ktree::with_dim!(&tree, AnyTree, t => exercise(t));
        }
    }
}

/// CRC-32 (IEEE), bit by bit: the checksum of `.ktree` files.
fn crc_of(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}
