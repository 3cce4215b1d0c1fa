//! Criterion benchmarks of the questions asked of a map ([`ktree::query`]) on the octree of a ball at
//! L = 10: random and coherent (random-walk) point queries — one at a time, through a cached cursor and in
//! a batch on all threads —, random rays and nearest full voxels, one thread and all threads. Before
//! timing, the answers are checked: the batches against one-at-a-time queries, every ray hit and every
//! nearest voxel against membership, and nearest voxels against brute force over every full voxel of an
//! L = 6 ball (a benchmark of a wrong answer is worthless).
//!
//! `cargo bench --bench queries`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ktree::query::{self, RayCast};
use ktree::rays::ball_rays;
use ktree::KTree;

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn ball(level: u32) -> KTree<3> {
    let u = 1i64 << level;
    KTree::from_rays(&ball_rays::<3>(level, [u + 1, u + 1, u + 1], u - 2).expect("level"))
}

fn random_points(n: usize, side: u64, rng: &mut Rng) -> Vec<[u32; 3]> {
    (0..n)
        .map(|_| std::array::from_fn(|_| rng.below(side) as u32))
        .collect()
}

/// A random walk: each point a neighbour of the last.
fn walk_points(n: usize, side: u64, rng: &mut Rng) -> Vec<[u32; 3]> {
    let mut p = [side as u32 / 2; 3];
    (0..n)
        .map(|_| {
            let a = rng.below(3) as usize;
            p[a] = if rng.below(2) == 0 {
                p[a].saturating_sub(1)
            } else {
                (p[a] + 1).min(side as u32 - 1)
            };
            p
        })
        .collect()
}

fn random_rays(n: usize, side: u64, rng: &mut Rng) -> Vec<RayCast<3>> {
    (0..n)
        .map(|_| {
            let origin = std::array::from_fn(|_| rng.unit() * side as f64);
            let direction = std::array::from_fn(|_| rng.unit() * 2.0 - 1.0);
            RayCast::new(origin, direction, f64::INFINITY).expect("finite")
        })
        .collect()
}

fn benches(c: &mut Criterion) {
    let level = 10;
    let tree = ball(level);
    let side = 1u64 << level;
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let n = 1 << 20;
    let random = random_points(n, side, &mut rng);
    let coherent = walk_points(n, side, &mut rng);
    let rays = random_rays(1 << 14, side, &mut rng);
    let near = random_points(1 << 14, side, &mut rng);

    // The answers, checked before timing.
    for points in [&random, &coherent] {
        let one: Vec<bool> = points.iter().map(|&p| tree.contains(p)).collect();
        assert_eq!(tree.contains_many(points), one);
        let mut cursor = tree.cursor();
        assert!(points
            .iter()
            .zip(&one)
            .all(|(&p, &e)| cursor.contains(p) == Ok(e)));
    }
    let casts = tree.cast_rays(&rays);
    for (r, hit) in rays.iter().zip(&casts) {
        assert_eq!(
            *hit,
            query::cast_ray(&tree, r).unwrap_or_else(|e| match e {})
        );
    }
    for hit in casts.into_iter().flatten() {
        assert!(tree.contains(hit.voxel));
    }
    for (p, n) in near.iter().zip(tree.nearest_many(&near)) {
        let n = n.expect("a full ball");
        assert!(tree.contains(n.voxel));
        assert_eq!(n.squared == 0, tree.contains(*p));
        assert_eq!(Some(n), tree.nearest(*p));
    }
    // Nearest voxels against brute force over every full voxel, on a smaller ball.
    let small = ball(6);
    let full: Vec<[u32; 3]> = (0..1u32 << 18)
        .map(|i| [i & 63, i >> 6 & 63, i >> 12])
        .filter(|&v| small.contains(v))
        .collect();
    let probes = random_points(500, 64, &mut rng);
    for (p, n) in probes.iter().zip(small.nearest_many(&probes)) {
        let expect = full
            .iter()
            .map(|v| {
                let d: u128 = (0..3).map(|a| u128::from(v[a].abs_diff(p[a])).pow(2)).sum();
                (d, ktree::space::morton_encode(*v), *v)
            })
            .min()
            .map(|(d, _, v)| (d, v));
        assert_eq!(n.map(|n| (n.squared, n.voxel)), expect, "from {p:?}");
    }

    let mut group = c.benchmark_group("queries-ball-L10");
    group.sample_size(10);
    for (name, points) in [("random", &random), ("coherent", &coherent)] {
        group.throughput(Throughput::Elements(points.len() as u64));
        group.bench_with_input(BenchmarkId::new("contains", name), points, |b, p| {
            b.iter(|| p.iter().filter(|&&q| tree.contains(q)).count())
        });
        group.bench_with_input(BenchmarkId::new("cursor", name), points, |b, p| {
            b.iter(|| {
                let mut cursor = tree.cursor();
                p.iter()
                    .filter(|&&q| cursor.contains(q) == Ok(true))
                    .count()
            })
        });
        group.bench_with_input(BenchmarkId::new("contains_many", name), points, |b, p| {
            b.iter(|| tree.contains_many(p))
        });
    }
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("cast_ray/one-thread", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| {
                    query::cast_ray(&tree, r)
                        .unwrap_or_else(|e| match e {})
                        .is_some()
                })
                .count()
        })
    });
    group.bench_function("cast_rays/all-threads", |b| {
        b.iter(|| tree.cast_rays(&rays))
    });
    group.throughput(Throughput::Elements(near.len() as u64));
    group.bench_function("nearest/one-thread", |b| {
        b.iter(|| near.iter().filter_map(|&p| tree.nearest(p)).count())
    });
    group.bench_function("nearest_many/all-threads", |b| {
        b.iter(|| tree.nearest_many(&near))
    });
    group.finish();
}

criterion_group! {
    name = query_benches;
    // Criterion's own plots need a registered font (plotters' ab_glyph backend).
    config = Criterion::default().without_plots();
    targets = benches
}
criterion_main!(query_benches);
