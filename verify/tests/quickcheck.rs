//! The same cross-checks with a second property-testing crate, quickcheck (its own generators and
//! shrinking): stacking equals the dense pyramid on arbitrary small ray sets, and maximal rows tile any run
//! with aligned, unmergeable rows.

use ktree::rays::maximal_rows;
use ktree::{reference::DensePyramid, stacking::paper::stack};
use ktree::{Ray, RaySet};
use quickcheck::{Arbitrary, Gen, QuickCheck};

/// A small ray set of dimension K; shrinks by dropping runs and prints as ray-file lines.
#[derive(Clone, Debug)]
struct SmallRays<const K: usize> {
    level: u32,
    runs: Vec<([u32; K], u32)>,
}

impl<const K: usize> SmallRays<K> {
    fn rays(&self) -> RaySet<K> {
        let side = 1u32 << self.level;
        RaySet::from_rays(
            self.level,
            self.runs.iter().map(|&(mut start, len)| {
                for c in start.iter_mut() {
                    *c %= side;
                }
                let z2 = (start[K - 1] + 1 + len % side).min(side);
                Ray::new(start, z2)
            }),
        )
        .expect("normalised runs are valid")
    }
}

impl<const K: usize> Arbitrary for SmallRays<K> {
    fn arbitrary(g: &mut Gen) -> Self {
        let max_level = if K == 4 { 4 } else { 6 };
        let level = u32::arbitrary(g) % (max_level + 1);
        let n = usize::arbitrary(g) % 24;
        let runs = (0..n)
            .map(|_| {
                (
                    std::array::from_fn(|_| u32::arbitrary(g)),
                    u32::arbitrary(g),
                )
            })
            .collect();
        Self { level, runs }
    }

    fn shrink(&self) -> Box<dyn Iterator<Item = Self>> {
        let level = self.level;
        Box::new(self.runs.shrink().map(move |runs| Self { level, runs }))
    }
}

fn stacking_equals_dense<const K: usize>(case: SmallRays<K>) -> bool {
    let rays = case.rays();
    let tree = stack(&rays);
    tree.check().is_ok() && tree == DensePyramid::from_rays(&rays).expect("small").to_tree()
}

#[test]
fn quickcheck_stacking_equals_dense_pyramid() {
    QuickCheck::new()
        .tests(ktree_verify::quickcheck_tests(200))
        .quickcheck(stacking_equals_dense::<1> as fn(SmallRays<1>) -> bool);
    QuickCheck::new()
        .tests(ktree_verify::quickcheck_tests(200))
        .quickcheck(stacking_equals_dense::<2> as fn(SmallRays<2>) -> bool);
    QuickCheck::new()
        .tests(ktree_verify::quickcheck_tests(200))
        .quickcheck(stacking_equals_dense::<3> as fn(SmallRays<3>) -> bool);
    QuickCheck::new()
        .tests(ktree_verify::quickcheck_tests(100))
        .quickcheck(stacking_equals_dense::<4> as fn(SmallRays<4>) -> bool);
}

#[test]
fn quickcheck_maximal_rows_tile_and_cannot_merge() {
    fn prop(a: u32, b: u32) -> bool {
        let (z1, z2) = (a.min(b) % (1 << 31), a.max(b) % (1 << 31));
        if z1 >= z2 {
            return maximal_rows(z1, z2).next().is_none();
        }
        let rows: Vec<_> = maximal_rows(z1, z2).collect();
        let tiles = rows.windows(2).all(|w| w[0].end() == u64::from(w[1].z))
            && u64::from(rows[0].z) == u64::from(z1)
            && rows.last().map(|r| r.end()) == Some(u64::from(z2));
        let aligned = rows.iter().all(|r| u64::from(r.z) % r.len() == 0);
        let unmergeable = rows
            .windows(2)
            .all(|w| !(w[0].log_len == w[1].log_len && u64::from(w[0].z) % (2 * w[0].len()) == 0));
        let short = rows.len() <= 2 * 31;
        tiles && aligned && unmergeable && short
    }
    QuickCheck::new()
        .tests(ktree_verify::quickcheck_tests(2000))
        .quickcheck(prop as fn(u32, u32) -> bool);
}
