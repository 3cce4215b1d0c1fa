//! Hidden-surface display: front-to-back traversal order and the raster renderer against a brute-force
//! z-buffer of all full leaves.

use ktree::display::*;
use ktree::{build::stack, rays::ball_rays};
use std::path::Path;

#[test]
#[ignore = "writes pictures to /tmp for a look"]
fn scratch_pictures() {
    let level: u32 = std::env::var("L")
        .ok()
        .map(|s| s.parse().unwrap())
        .unwrap_or(6);
    let size: u32 = 300;
    let u = 1i64 << level;
    let rays = ball_rays::<3>(level, [u, u, u], u).unwrap();
    let tree = stack(&rays);
    let cam = default_camera(&tree, ISO_TOWARD_EYE, None, size, size).unwrap();
    let t = std::time::Instant::now();
    let img = render(
        &tree,
        &cam,
        &RenderOptions {
            width: size,
            height: size,
            depth: true,
            ..Default::default()
        },
        None,
        None,
    )
    .unwrap();
    eprintln!(
        "nodes {} render {:?} {:?}",
        tree.node_count(),
        t.elapsed(),
        img.stats
    );
    png::write_rgb_png(Path::new("/tmp/sphere.png"), size, size, &img.rgb).unwrap();
    png::write_grey_png(
        Path::new("/tmp/sphere_depth.png"),
        size,
        size,
        &img.depth_grey().unwrap(),
    )
    .unwrap();
    let cam = default_camera(&tree, ISO_TOWARD_EYE, Some(40.0), size, size).unwrap();
    let img = render(
        &tree,
        &cam,
        &RenderOptions {
            width: size,
            height: size,
            ..Default::default()
        },
        None,
        None,
    )
    .unwrap();
    png::write_rgb_png(Path::new("/tmp/sphere_persp.png"), size, size, &img.rgb).unwrap();
}

#[test]
#[ignore = "writes pictures to /tmp for a look"]
fn scratch_lines() {
    let level: u32 = std::env::var("L")
        .ok()
        .map(|s| s.parse().unwrap())
        .unwrap_or(5);
    let u = 1i64 << level;
    let rays = ball_rays::<3>(level, [u, u, u], u).unwrap();
    let tree = stack(&rays);
    for method in [HiddenLineMethod::Bucketed, HiddenLineMethod::Pairwise] {
        let t = std::time::Instant::now();
        let d = line_drawing(&tree, ISO_TOWARD_EYE, method, None).unwrap();
        eprintln!("{method:?} {:?} {:?}", t.elapsed(), d.stats);
        let segs = d.segments_2d();
        svg::write_svg(
            Path::new("/tmp/lines.svg"),
            &svg::lines_svg(&segs, 600, 600, 1.0),
        )
        .unwrap();
        png::lines_canvas(&segs, 600, 600)
            .unwrap()
            .write_png(Path::new("/tmp/lines.png"))
            .unwrap();
    }
}
