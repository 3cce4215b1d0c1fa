//! The builder (Morton-partitioned stacking) is cross-checked, for K = 1 … 4, every split depth and both
//! ways of stacking a cell, against the paper's stacking of the whole set and naive voxel insertion node
//! for node; the cell split of the rays against the rays' own point test; the stacked subtrees of the
//! cells, put together, against stacking the whole set; and the result against the number of threads.

use ktree_verify::cases;

use cases::{ray_sets, Case};
use ktree::reference::{Dim, Fanout, NaiveTree};
use ktree::stacking::{paper::stack, Builder, CellStacking};
use ktree::{Cell, KTree};
use proptest::prelude::*;

fn partitioned_agrees<const K: usize>(case: &Case<K>) -> Result<(), TestCaseError>
where
    Dim<K>: Fanout,
{
    let rays = &case.rays;
    let whole = stack(rays);
    let naive = NaiveTree::from_rays(rays).unwrap().to_tree();
    prop_assert!(whole == naive, "stacking and naive differ");
    for depth in 0..=rays.level() {
        for cells in [CellStacking::Bitmap, CellStacking::Lists] {
            let parted = Builder::new(rays)
                .split_depth(depth)
                .cells(cells)
                .build()
                .unwrap();
            parted
                .check()
                .map_err(|e| TestCaseError::fail(format!("depth {depth}: malformed: {e}")))?;
            prop_assert!(
                parted == whole,
                "split depth {}, cells {:?}: partitioned and whole stacking differ",
                depth,
                cells
            );
        }
    }
    Ok(())
}

/// The cells of depth `depth` in Morton order.
fn cells<const K: usize>(level: u32, depth: u32) -> Vec<Cell<K>> {
    let u = ktree::Universe::<K>::new(level).unwrap();
    let mut cells = vec![u.root()];
    for _ in 0..depth {
        cells = cells
            .iter()
            .flat_map(|c| (0..1usize << K).map(move |code| c.child(code)))
            .collect();
    }
    cells
}

fn split_and_join_agree<const K: usize>(case: &Case<K>, depth: u32) -> Result<(), TestCaseError> {
    let rays = &case.rays;
    let depth = depth.min(rays.level());
    let u = rays.universe();
    let mut moved = Vec::new();
    for cell in cells::<K>(rays.level(), depth) {
        let inner = rays.cell_rays(cell);
        prop_assert_eq!(inner.level(), rays.level() - depth);
        // Every voxel of the cell is in the cell's rays exactly when it is in the rays.
        let mut count = 0u128;
        let side = cell.side() as u32;
        cases::for_each_column([0; K], [side; K], |mut p| {
            for z in 0..side {
                p[K - 1] = z;
                let global: [u32; K] = std::array::from_fn(|a| p[a] + cell.origin()[a]);
                assert_eq!(inner.contains(p), rays.contains(global), "{cell:?} {p:?}");
                count += u128::from(rays.contains(global));
            }
        });
        prop_assert_eq!(inner.voxel_count(), count);
        // The cell's subtree, its full leaves moved to the cell's place.
        for leaf in stack(&inner).full_cells() {
            let origin: [u32; K] = std::array::from_fn(|a| leaf.origin()[a] + cell.origin()[a]);
            moved.push(Cell::new(u, origin, leaf.level() + depth).unwrap());
        }
    }
    prop_assert!(
        KTree::from_cells(u, &moved).unwrap() == stack(rays),
        "the cells' subtrees, joined, differ from stacking at depth {}",
        depth
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn partitioned_equals_stacking_k1(case in ray_sets::<1>()) { partitioned_agrees(&case)?; }
    #[test]
    fn partitioned_equals_stacking_k2(case in ray_sets::<2>()) { partitioned_agrees(&case)?; }
    #[test]
    fn partitioned_equals_stacking_k3(case in ray_sets::<3>()) { partitioned_agrees(&case)?; }
    #[test]
    fn partitioned_equals_stacking_k4(case in ray_sets::<4>()) { partitioned_agrees(&case)?; }

    #[test]
    fn split_and_join_k1(case in ray_sets::<1>(), depth in 0u32..=6) { split_and_join_agree(&case, depth)?; }
    #[test]
    fn split_and_join_k2(case in ray_sets::<2>(), depth in 0u32..=6) { split_and_join_agree(&case, depth)?; }
    #[test]
    fn split_and_join_k3(case in ray_sets::<3>(), depth in 0u32..=3) { split_and_join_agree(&case, depth)?; }
    #[test]
    fn split_and_join_k4(case in ray_sets::<4>(), depth in 0u32..=2) { split_and_join_agree(&case, depth)?; }
}

/// Thread count does not change the tree.
#[test]
fn any_thread_count_gives_the_same_tree() {
    let level = 7;
    let u = 1i64 << level;
    let rays = ktree::rays::ball_rays::<3>(level, [u, u, u], u - 3).unwrap();
    for depth in [1, 3, 5] {
        let a: KTree<3> = Builder::new(&rays)
            .threads(1)
            .split_depth(depth)
            .build()
            .unwrap();
        let b = Builder::new(&rays)
            .threads(3)
            .split_depth(depth)
            .build()
            .unwrap();
        assert_eq!(a, b);
        assert_eq!(a, stack(&rays));
    }
}

/// Small objects in universes of the largest level for each K, split deep.
#[test]
fn extreme_levels_split_anywhere() {
    fn check<const K: usize>() {
        let level = ktree::max_level(K);
        let side = 1u64 << level;
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let rays: Vec<ktree::Ray<K>> = (0..6)
            .map(|_| {
                let start: [u32; K] = std::array::from_fn(|_| (next() % side) as u32);
                let z2 = (u64::from(start[K - 1]) + 1 + next() % 40).min(side);
                ktree::Ray::new(start, z2 as u32)
            })
            .collect();
        let set = ktree::RaySet::from_rays(level, rays).unwrap();
        let whole = stack(&set);
        for depth in [1, level / 2, level - 1, level] {
            assert_eq!(
                Builder::new(&set).split_depth(depth).build().unwrap(),
                whole,
                "K={K} depth {depth}"
            );
        }
    }
    check::<1>();
    check::<2>();
    check::<3>();
    check::<4>();
}

/// Solids produce their rays slab by slab: the partitioned build from a quadric or a box equals stacking
/// its whole ray set, for every split depth.
fn solid_agrees<const K: usize>(
    solid: &ktree::solid::Solid<K>,
    level: u32,
) -> Result<(), TestCaseError> {
    use ktree::solid::{Sample, SolidSource};
    use ktree::stacking::Builder;
    let whole = stack(&solid.to_rays(level, Sample::Centre, false).unwrap());
    let source = SolidSource::new(solid, level, Sample::Centre).unwrap();
    for depth in 0..=level {
        let parted = Builder::new(&source).split_depth(depth).build().unwrap();
        prop_assert!(parted == whole, "solid at split depth {}", depth);
    }
    Ok(())
}

fn rational(n: i64, d: i64) -> ktree::solid::Rational {
    ktree::solid::Rational::new(n, d).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn solids_by_slab_k2(c in prop::array::uniform2(-8i64..72), r in 1i64..60, lo in prop::array::uniform2(-4i64..40), ext in prop::array::uniform2(1i64..40)) {
        use ktree::solid::{BoxSolid, Frame, Quadric, Solid};
        let ball = Quadric::<2>::ball(c.map(|v| rational(v, 2)), rational(r, 2), Frame::Voxel).unwrap();
        solid_agrees(&Solid::Quadric(ball), 5)?;
        let b = BoxSolid::<2>::new(lo.map(|v| rational(v, 1)), [lo[0] + ext[0], lo[1] + ext[1]].map(|v| rational(v, 1)), Frame::Voxel).unwrap();
        solid_agrees(&Solid::Box(b), 5)?;
    }

    #[test]
    fn solids_by_slab_k3(c in prop::array::uniform3(-8i64..72), r in 1i64..60) {
        use ktree::solid::{Frame, Quadric, Solid};
        let ball = Quadric::<3>::ball(c.map(|v| rational(v, 2)), rational(r, 2), Frame::Voxel).unwrap();
        solid_agrees(&Solid::Quadric(ball), 5)?;
    }

    #[test]
    fn solids_by_slab_k1_k4(c in -8i64..40, r in 1i64..30) {
        use ktree::solid::{Frame, Quadric, Solid};
        let ball = Quadric::<1>::ball([rational(c, 2)], rational(r, 2), Frame::Voxel).unwrap();
        solid_agrees(&Solid::Quadric(ball), 4)?;
        let ball = Quadric::<4>::ball([rational(c, 2); 4], rational(r, 2), Frame::Voxel).unwrap();
        solid_agrees(&Solid::Quadric(ball), 3)?;
    }
}
