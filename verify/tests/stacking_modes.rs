//! The other ways of running stacking build the tree of the in-memory stacker, K = 1 … 4: with the
//! dimension-level lists as sequential disk files (same tree, same traffic through every list, never more
//! than three files open, lists sorted in memory or on disk in bounded runs), as a pipeline of one thread
//! per stage, and through a bitmap pyramid (the way the cells of a partitioned build are stacked).

use ktree_verify::cases;

use cases::{ray_sets, Case};
use ktree::stacking::{
    paper::stack, paper::stack_pipelined, paper::stack_with_file_lists, paper::stack_with_stats,
    Builder,
};
use proptest::prelude::*;

fn modes_agree<const K: usize>(case: &Case<K>) -> Result<(), TestCaseError> {
    let rays = &case.rays;
    let (tree, stats) = stack_with_stats(rays);
    let dir = tempfile::tempdir().unwrap();
    // Lists sorted in memory, then on disk in runs of 8 keys (merged two at a time).
    for max_items in [usize::MAX, 8] {
        let (on_disk, disk_stats, files) = stack_with_file_lists(rays, dir.path(), max_items)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(
            files.largest_list <= (max_items as u64).saturating_add(1 << rays.level()),
            "{} keys held with runs of {max_items}",
            files.largest_list
        );
        prop_assert_eq!(disk_stats.rays, stats.rays);
        prop_assert!(
            on_disk == tree,
            "file lists and memory differ node for node"
        );
        prop_assert_eq!(
            &disk_stats.entered,
            &stats.entered,
            "items entering each list"
        );
        prop_assert_eq!(
            &disk_stats.combined,
            &stats.combined,
            "groups combined in each list"
        );
        prop_assert_eq!(&disk_stats.split, &stats.split, "items split in each list");
        prop_assert_eq!(disk_stats.cells, stats.cells);
        prop_assert_eq!(disk_stats.maximal_rows, stats.maximal_rows);
        prop_assert!(
            files.max_open_files <= 3,
            "{} files open at once",
            files.max_open_files
        );
        prop_assert!(
            std::fs::read_dir(dir.path()).unwrap().next().is_none(),
            "list files left behind"
        );
    }
    let pipelined = stack_pipelined(rays);
    prop_assert!(
        pipelined == tree,
        "pipeline and memory differ node for node"
    );
    pipelined
        .check()
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!(stack(rays) == tree);
    prop_assert!(
        Builder::new(rays).split_depth(0).build().unwrap() == tree,
        "bitmap pyramid and stacking differ node for node"
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn modes_agree_k1(case in ray_sets::<1>()) { modes_agree(&case)?; }

    #[test]
    fn modes_agree_k2(case in ray_sets::<2>()) { modes_agree(&case)?; }

    #[test]
    fn modes_agree_k3(case in ray_sets::<3>()) { modes_agree(&case)?; }

    #[test]
    fn modes_agree_k4(case in ray_sets::<4>()) { modes_agree(&case)?; }
}
