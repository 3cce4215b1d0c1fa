//! Criterion benchmarks of the operations on octrees of voxel-centre spheres, L = 6 … 10: the Booleans and
//! a rotation by reordering (throughput in input nodes), translation and an arbitrary rotation by overlays
//! (up to L = 9). Before timing, each operation's result is checked against an independent route to the
//! same object (a benchmark of a wrong answer is worthless): the Booleans against the dense reference
//! where it fits (L ≤ 7) and against the laws `A ∩ B = ¬(¬A ∪ ¬B)` above; the quarter turn against the
//! affine rotation by 90°; translation there and back against the part that stays inside.
//!
//! `cargo bench --bench ops`; the recorded figures come from `cargo run --release --example perf -- ops`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ktree::ops::{self, Affine, AxisMap, BoolOp};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::KTree;

fn spheres(level: u32) -> (KTree<3>, KTree<3>) {
    let u = 1i64 << level;
    (
        stack(&ball_rays::<3>(level, [u + 1, u + 1, u + 1], u - 2).expect("level")),
        stack(&ball_rays::<3>(level, [u + u / 4, u, u - u / 8], u * 3 / 4).expect("level")),
    )
}

fn check(a: &KTree<3>, b: &KTree<3>) {
    for op in BoolOp::ALL {
        let out = ops::boolean(a, b, op).unwrap();
        out.assert_well_formed();
        if a.level() <= 7 {
            let (da, db) = (a.to_dense().unwrap(), b.to_dense().unwrap());
            let expect: Vec<bool> = da.iter().zip(&db).map(|(&x, &y)| op.apply(x, y)).collect();
            assert_eq!(out.to_dense().unwrap(), expect, "{op:?}");
        }
    }
    let law = ops::complement(&ops::union(&ops::complement(a), &ops::complement(b)).unwrap());
    assert_eq!(ops::intersection(a, b).unwrap(), law);
    let q = AxisMap::<3>::quarter_turn(0, 1).unwrap();
    let m = Affine::rotation_about(0, 1, 90.0, Affine::<3>::universe_centre(a.level())).unwrap();
    assert_eq!(
        ops::rotate_axes(a, &q).unwrap(),
        ops::transform(a, &m).unwrap()
    );
    // Translating there and back keeps exactly the part that stays inside the universe.
    let there_and_back = |t: &KTree<3>| {
        ops::translate(&ops::translate(t, [3, -5, 7]).unwrap(), [-3, 5, -7]).unwrap()
    };
    let stays = there_and_back(&KTree::full(b.level()).unwrap());
    assert_eq!(there_and_back(b), ops::intersection(b, &stays).unwrap());
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("ops-sphere");
    group.sample_size(10);
    for level in 6..=10u32 {
        let (a, b) = spheres(level);
        if level <= 9 {
            check(&a, &b);
        }
        group.throughput(Throughput::Elements(a.node_count() + b.node_count()));
        for op in BoolOp::ALL {
            group.bench_with_input(
                BenchmarkId::new(op.name(), level),
                &(&a, &b),
                |bn, (a, b)| bn.iter(|| ops::boolean(*a, *b, op).unwrap()),
            );
        }
        group.throughput(Throughput::Elements(a.node_count()));
        let q = AxisMap::<3>::quarter_turn(0, 1).unwrap();
        group.bench_with_input(BenchmarkId::new("rotate90", level), &a, |bn, a| {
            bn.iter(|| ops::rotate_axes(a, &q).unwrap())
        });
        if level <= 9 {
            group.bench_with_input(BenchmarkId::new("translate", level), &a, |bn, a| {
                bn.iter(|| ops::translate(a, [3, -5, 7]).unwrap())
            });
            let m =
                Affine::rotation_about(0, 1, 30.0, Affine::<3>::universe_centre(level)).unwrap();
            group.bench_with_input(BenchmarkId::new("rotate30", level), &a, |bn, a| {
                bn.iter(|| ops::transform(a, &m).unwrap())
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = ops_benches;
    // Criterion's own plots need a registered font (plotters' ab_glyph backend); the figures that matter
    // are in results/performance/ops.md.
    config = Criterion::default().without_plots();
    targets = benches
}
criterion_main!(ops_benches);
