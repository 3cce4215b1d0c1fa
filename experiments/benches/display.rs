//! Criterion benchmarks of display: the front-to-back raster renderer against the painter's order and the
//! brute-force z-buffer
//! (balls at L = 6 … 8, 256 × 256), and line drawings with the pairwise and the bucketed hidden-line
//! methods (balls at L = 4 … 6). Each benchmark first checks that the fast result equals the reference.
//!
//! `cargo bench --bench display`; the recorded figures come from
//! `cargo run --release --example perf -- display` into results/performance/display.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ktree::display::{
    default_camera, line_drawing, render, render_back_to_front, render_zbuffer, HiddenLineMethod,
    RenderOptions, ISO_TOWARD_EYE,
};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::Octree;

fn ball(level: u32) -> Octree {
    let u = 1i64 << level;
    stack(&ball_rays::<3>(level, [u, u, u], u).expect("level in range"))
}

fn raster(c: &mut Criterion) {
    let mut group = c.benchmark_group("render-ball-256");
    group.sample_size(10);
    for level in 6..=8u32 {
        let tree = ball(level);
        let camera = default_camera(&tree, ISO_TOWARD_EYE, None, 256, 256).expect("camera");
        let options = RenderOptions {
            width: 256,
            height: 256,
            depth: true,
            ..Default::default()
        };
        let fast = render(&tree, &camera, &options).expect("render");
        let reference = render_zbuffer(&tree, &camera, &options).expect("render");
        assert_eq!(
            fast.stats.painted, reference.stats.painted,
            "raster and z-buffer disagree"
        );
        group.throughput(Throughput::Elements(tree.node_count()));
        group.bench_with_input(BenchmarkId::new("front-to-back", level), &tree, |b, t| {
            b.iter(|| render(t, &camera, &options).expect("render"))
        });
        let painter = render_back_to_front(&tree, &camera, &options).expect("render");
        assert_eq!(
            fast.stats.painted, painter.stats.painted,
            "raster and painter disagree"
        );
        group.bench_with_input(BenchmarkId::new("back-to-front", level), &tree, |b, t| {
            b.iter(|| render_back_to_front(t, &camera, &options).expect("render"))
        });
        group.bench_with_input(BenchmarkId::new("z-buffer", level), &tree, |b, t| {
            b.iter(|| render_zbuffer(t, &camera, &options).expect("render"))
        });
    }
    group.finish();
}

fn lines(c: &mut Criterion) {
    let mut group = c.benchmark_group("lines-ball");
    group.sample_size(10);
    for level in 4..=6u32 {
        let tree = ball(level);
        let fast = line_drawing(&tree, ISO_TOWARD_EYE, HiddenLineMethod::Bucketed).expect("draw");
        let slow = line_drawing(&tree, ISO_TOWARD_EYE, HiddenLineMethod::Pairwise).expect("draw");
        assert_eq!(
            fast.lines, slow.lines,
            "bucketed and pairwise drawings differ"
        );
        group.throughput(Throughput::Elements(tree.node_count()));
        for (name, method) in [
            ("bucketed", HiddenLineMethod::Bucketed),
            ("pairwise", HiddenLineMethod::Pairwise),
        ] {
            group.bench_with_input(BenchmarkId::new(name, level), &tree, |b, t| {
                b.iter(|| line_drawing(t, ISO_TOWARD_EYE, method).expect("draw"))
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    // Criterion's plots need a font registered with plotters (ab_glyph); without one it panics. The
    // numbers are what matters here.
    config = Criterion::default().without_plots();
    targets = raster, lines
}
criterion_main!(benches);
