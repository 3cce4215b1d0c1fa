//! Criterion benchmarks of solids to rays: a quadric ball (checked equal to the core's direct generator),
//! meshes from data/ fitted into the universe, and a Boolean difference, at L = 8 … 10.
//!
//! `cargo bench --bench solids`; the recorded figures (with peak memory) come from
//! `cargo run --release --example perf -- solids` into results/performance/solids.md.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ktree::rays::ball_rays;
use ktree::solid::mesh::MeshTransform;
use ktree::solid::{BoxSolid, Frame, Quadric, Rational, Sample};

fn quadrics(c: &mut Criterion) {
    let mut group = c.benchmark_group("quadric-ball");
    group.sample_size(10);
    for level in 8..=10u32 {
        let h = Rational::int(1 << (level - 1));
        let q = Quadric::<3>::ball([h; 3], h, Frame::Voxel).expect("ball");
        let u = 1i64 << level;
        let rays = q.to_rays(level, Sample::Centre, false).expect("rays");
        assert_eq!(rays, ball_rays::<3>(level, [u, u, u], u).expect("rays"));
        group.throughput(Throughput::Elements(rays.len() as u64));
        group.bench_with_input(BenchmarkId::new("to_rays", level), &q, |b, q| {
            b.iter(|| q.to_rays(level, Sample::Centre, false).expect("rays"))
        });
    }
    group.finish();
}

fn meshes(c: &mut Criterion) {
    // The meshes are part of the repository (data/SOURCES.md).
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../data/meshes");
    let mut group = c.benchmark_group("mesh");
    group.sample_size(10);
    for name in ["bunny_npm.obj", "armadillo.obj"] {
        let mesh = ktree::io::read_mesh(&dir.join(name)).expect("mesh");
        let level = 10;
        let p = MeshTransform::fit(&mesh, level).expect("fit");
        group.bench_with_input(BenchmarkId::new(name, level), &mesh, |b, m| {
            b.iter(|| m.to_rays(level, &p).expect("rays"))
        });
    }
    group.finish();
}

fn csg(c: &mut Criterion) {
    let level = 10;
    let q = |x: i64| Rational::int(x);
    let a = BoxSolid::<3>::new([q(128); 3], [q(896); 3], Frame::Voxel)
        .expect("box")
        .to_rays(level, Sample::Centre, false)
        .expect("rays");
    let b = Quadric::<3>::cylinder(0, [q(0), q(512), q(512)], q(256), Frame::Voxel)
        .expect("cylinder")
        .to_rays(level, Sample::Centre, false)
        .expect("rays");
    c.bench_function("csg/box-minus-cylinder/10", |bench| {
        bench.iter(|| a.difference(&b).expect("same level"))
    });
}

criterion_group!(benches, quadrics, meshes, csg);
criterion_main!(benches);
