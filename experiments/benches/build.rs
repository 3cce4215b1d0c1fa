//! Criterion benchmarks of building octrees from voxel-centre spheres of radius U/2: stacking vs naive
//! voxel insertion (up to L = 8) vs the dense pyramid (up to L = 9). Each benchmark first checks that its
//! builder's tree equals stacking's: a benchmark of a wrong answer is worthless.
//!
//! `cargo bench --bench build`; the recorded figures (with peak memory) come from
//! `cargo run --release --example perf -- build` into results/performance/build.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ktree::rays::ball_rays;
use ktree::{
    reference::{DensePyramid, NaiveTree},
    stacking::paper::stack,
};

fn builders(c: &mut Criterion) {
    let mut group = c.benchmark_group("build-sphere");
    group.sample_size(10);
    for level in 6..=10u32 {
        let u = 1i64 << level;
        let rays = ball_rays::<3>(level, [u, u, u], u).expect("level in range");
        let reference = stack(&rays);
        group.throughput(Throughput::Elements(rays.len() as u64));
        group.bench_with_input(BenchmarkId::new("stacking", level), &rays, |b, r| {
            b.iter(|| stack(r))
        });
        if level <= 8 {
            assert_eq!(NaiveTree::from_rays(&rays).unwrap().to_tree(), reference);
            group.bench_with_input(BenchmarkId::new("naive", level), &rays, |b, r| {
                b.iter(|| NaiveTree::from_rays(r).unwrap().to_tree())
            });
        }
        if level <= 9 {
            assert_eq!(DensePyramid::from_rays(&rays).unwrap().to_tree(), reference);
            group.bench_with_input(BenchmarkId::new("dense", level), &rays, |b, r| {
                b.iter(|| DensePyramid::from_rays(r).unwrap().to_tree())
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    // Criterion's plots need a system font that plotters cannot find here; the numbers do not.
    config = Criterion::default().without_plots();
    targets = builders
}
criterion_main!(benches);
