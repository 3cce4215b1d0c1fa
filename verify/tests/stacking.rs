//! Stacking is cross-checked against the two reference builders — naive voxel insertion and the dense
//! pyramid — node for node at every level, for K = 1, 2, 3 and 4; the trees are reduced and their leaves
//! cover exactly the object's voxels. Failures shrink to a small ray file printed in the text format.

use ktree_verify::cases;

use cases::{ray_sets, Case};
use ktree::{
    reference::{DensePyramid, Dim, Fanout, NaiveTree},
    stacking::paper::stack,
};
use ktree::{KTree, NodeState};
use proptest::prelude::*;

/// Checks one case; returns the first disagreement as a sentence.
fn stacking_agrees<const K: usize>(case: &Case<K>) -> Result<(), TestCaseError>
where
    Dim<K>: Fanout,
{
    let rays = &case.rays;
    let stacked = stack(rays);
    stacked
        .check()
        .map_err(|e| TestCaseError::fail(format!("stacked tree malformed: {e}")))?;
    let naive = NaiveTree::from_rays(rays).unwrap().to_tree();
    let dense = DensePyramid::from_rays(rays).unwrap().to_tree();
    prop_assert_eq!(
        stacked.counts_per_level(),
        naive.counts_per_level(),
        "per-level counts: stacking vs naive"
    );
    prop_assert!(stacked == naive, "stacking and naive differ node for node");
    prop_assert!(
        stacked == dense,
        "stacking and dense pyramid differ node for node"
    );
    // Leaves cover exactly the object's voxels.
    let u = rays.universe();
    let mut covered = vec![false; u.dense_len(1 << 24).unwrap()];
    let mut leaf_voxels = 0u128;
    stacked.for_each_leaf(|cell, state| {
        if state == NodeState::Full {
            leaf_voxels += cell.volume();
        }
        let _ = &cell;
    });
    for cell in stacked.full_cells() {
        let side = cell.side() as u32;
        cases::for_each_column(cell.origin(), cell.origin().map(|o| o + side), |mut p| {
            for z in cell.origin()[K - 1]..cell.origin()[K - 1] + side {
                p[K - 1] = z;
                covered[u.dense_index(p)] = true;
            }
        });
    }
    prop_assert_eq!(leaf_voxels, rays.voxel_count());
    for (i, &c) in covered.iter().enumerate() {
        let p = u.dense_point(i);
        prop_assert_eq!(c, rays.contains(p), "voxel {:?}", p);
        prop_assert_eq!(c, stacked.contains(p), "point query at {:?}", p);
    }
    // Dense round trip.
    prop_assert_eq!(
        KTree::<K>::from_dense(u.level(), &covered).unwrap(),
        stacked
    );
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(256))]

    #[test]
    fn stacking_equals_references_k1(case in ray_sets::<1>()) { stacking_agrees(&case)?; }

    #[test]
    fn stacking_equals_references_k2(case in ray_sets::<2>()) { stacking_agrees(&case)?; }

    #[test]
    fn stacking_equals_references_k3(case in ray_sets::<3>()) { stacking_agrees(&case)?; }

    #[test]
    fn stacking_equals_references_k4(case in ray_sets::<4>()) { stacking_agrees(&case)?; }
}

/// Small objects placed anywhere in universes of the largest level for each K: stacking (whose keys fill
/// all 64 bits there) still equals naive insertion, and point queries agree with the rays.
fn extreme_level_agrees<const K: usize>(seed: u64) -> Result<(), TestCaseError>
where
    Dim<K>: Fanout,
{
    let level = ktree::max_level(K);
    let side = 1u64 << level;
    let mut x = seed | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut rays = Vec::new();
    for _ in 0..6 {
        // A few short runs near a random point, sometimes on the universe's far faces.
        let mut start = [0u32; K];
        for c in start.iter_mut() {
            *c = match next() % 3 {
                0 => 0,
                1 => (side - 1 - next() % 3) as u32,
                _ => (next() % side) as u32,
            };
        }
        let z1 = u64::from(start[K - 1]);
        let z2 = (z1 + 1 + next() % 5).min(side);
        rays.push(ktree::Ray::new(start, z2 as u32));
    }
    let set = ktree::RaySet::from_rays(level, rays).unwrap();
    let stacked = stack(&set);
    stacked
        .check()
        .map_err(|e| TestCaseError::fail(format!("malformed: {e}")))?;
    let naive = NaiveTree::from_rays(&set).unwrap().to_tree();
    prop_assert!(
        stacked == naive,
        "stacking and naive differ at level {}",
        level
    );
    prop_assert_eq!(stacked.voxel_count(), set.voxel_count());
    for ray in set.iter() {
        prop_assert!(stacked.contains(ray.start));
        let mut after = ray.start;
        after[K - 1] = ray.z2;
        prop_assert_eq!(stacked.contains(after), set.contains(after));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]

    #[test]
    fn stacking_at_the_largest_levels(seed in any::<u64>()) {
        extreme_level_agrees::<1>(seed)?;
        extreme_level_agrees::<2>(seed)?;
        extreme_level_agrees::<3>(seed)?;
        extreme_level_agrees::<4>(seed)?;
    }
}
