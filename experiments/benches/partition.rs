//! Criterion benchmarks of the partitioned build: the voxel-centre sphere (centre U/2, radius (U−1)/2)
//! from its quadric, end to end (rays made slab by slab, cells of depth L − 6 stacked apart), on one thread
//! and on all cores, against whole-set stacking of the same rays. Throughput is in tree nodes. Each
//! benchmark first checks that the partitioned tree equals whole-set stacking's.
//!
//! `cargo bench --bench partition`; the recorded figures (with peak memory, up to L = 13) come from
//! `cargo run --release --example perf -- scale` into results/performance/scale.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
use ktree::stacking::{default_split_depth, paper::stack, Builder};

fn sphere(level: u32) -> Solid<3> {
    let u = 1i64 << level;
    let c = Rational::new(u, 2).unwrap();
    let r = Rational::new(u - 1, 2).unwrap();
    Solid::Quadric(Quadric::ball([c; 3], r, Frame::Voxel).unwrap())
}

fn partitioned(c: &mut Criterion) {
    let mut group = c.benchmark_group("partition-sphere");
    group.sample_size(10);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let all = rayon::ThreadPoolBuilder::new().build().unwrap();
    for level in [8u32, 9, 10] {
        let solid = sphere(level);
        let source = SolidSource::new(&solid, level, Sample::Centre).unwrap();
        let depth = default_split_depth(3, level);
        let whole = stack(&solid.to_rays(level, Sample::Centre, false).unwrap());
        assert_eq!(
            one.install(|| Builder::new(&source).split_depth(depth).build().unwrap()),
            whole
        );
        group.throughput(Throughput::Elements(whole.node_count()));
        group.bench_function(BenchmarkId::new("cells-1-thread", level), |b| {
            b.iter(|| one.install(|| Builder::new(&source).split_depth(depth).build().unwrap()))
        });
        group.bench_function(BenchmarkId::new("cells-all-cores", level), |b| {
            b.iter(|| all.install(|| Builder::new(&source).split_depth(depth).build().unwrap()))
        });
        group.bench_function(BenchmarkId::new("whole-set", level), |b| {
            b.iter(|| stack(&solid.to_rays(level, Sample::Centre, false).unwrap()))
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    // Criterion's plots need a system font that plotters cannot find here; the numbers do not.
    config = Criterion::default().without_plots();
    targets = partitioned
}
criterion_main!(benches);
