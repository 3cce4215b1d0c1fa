//! A build split into balanced slabs of columns (as the ranks of a distributed run do it) and joined by
//! union equals whole-set stacking and naive insertion node for node, for K = 1 … 4 and 1 … 5 parts; the
//! slabs cover the universe in order and hold every run exactly once.

use ktree_verify::cases;

use cases::{ray_sets, Case};
use ktree::reference::{Dim, Fanout, NaiveTree};
use ktree::stacking::{balanced_slabs, join_parts, slab_rays, stack};
use proptest::prelude::*;

fn parts_agree<const K: usize>(case: &Case<K>, parts: usize) -> Result<(), TestCaseError>
where
    Dim<K>: Fanout,
{
    let rays = &case.rays;
    let whole = stack(rays);
    let naive = NaiveTree::from_rays(rays).unwrap().to_tree();
    prop_assert!(whole == naive, "stacking and naive differ");
    let slabs = balanced_slabs(rays, parts);
    prop_assert_eq!(slabs.len(), parts);
    prop_assert_eq!(slabs[0].start, 0);
    prop_assert_eq!(u64::from(slabs[parts - 1].end), rays.universe().side());
    for w in slabs.windows(2) {
        prop_assert_eq!(w[0].end, w[1].start, "slabs are contiguous");
    }
    let pieces: Vec<_> = slabs.iter().map(|x| slab_rays(rays, x.clone())).collect();
    let runs: usize = pieces.iter().map(|p| p.len()).sum();
    prop_assert_eq!(runs, rays.len(), "every run in exactly one slab");
    let mut trees = pieces.iter().map(stack);
    let first = trees.next().unwrap();
    let joined = join_parts(first, trees).unwrap();
    joined.assert_well_formed();
    prop_assert!(joined == whole, "{} parts: joined and whole differ", parts);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn parts_k1(case in ray_sets::<1>(), parts in 1usize..=5) { parts_agree(&case, parts)?; }
    #[test]
    fn parts_k2(case in ray_sets::<2>(), parts in 1usize..=5) { parts_agree(&case, parts)?; }
    #[test]
    fn parts_k3(case in ray_sets::<3>(), parts in 1usize..=5) { parts_agree(&case, parts)?; }
    #[test]
    fn parts_k4(case in ray_sets::<4>(), parts in 1usize..=5) { parts_agree(&case, parts)?; }
}
