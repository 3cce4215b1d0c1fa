//! The front-to-back raster renderer against a brute-force z-buffer of all full leaves: the same visible
//! leaf at every pixel (up to exact depth ties), orthographic and perspective, on random trees.
// Geometry over axes reads clearest with indices.
#![allow(clippy::needless_range_loop)]

use ktree_verify::cases;

use cases::ray_sets;
use ktree::display::{
    default_camera, render, render_back_to_front, render_zbuffer, Camera, DisplayError, Projection,
    RenderOptions,
};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::{Ray, RaySet};
use proptest::prelude::*;

fn toward() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(prop_oneof![-1.0..-0.1f64, 0.1..1.0f64])
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]

    #[test]
    fn raster_equals_zbuffer(
        case in ray_sets::<3>(),
        dir in toward(),
        perspective in prop::option::of(20.0..70.0f64),
        zoom in 0.5..1.5f64,
    ) {
        let tree = stack(&case.rays);
        tree.assert_well_formed();
        let (w, h) = (40, 32);
        let mut camera = default_camera(&tree, dir, perspective, w, h).unwrap();
        if let Projection::Orthographic { height } = camera.projection {
            camera.projection = Projection::Orthographic { height: height * zoom };
        }
        let options = RenderOptions { width: w, height: h, depth: true, cells: true, ..Default::default() };
        let fast = render(&tree, &camera, &options).unwrap();
        let reference = render_zbuffer(&tree, &camera, &options).unwrap();
        let (fc, rc) = (fast.cells.as_ref().unwrap(), reference.cells.as_ref().unwrap());
        let (fd, rd) = (fast.depth.as_ref().unwrap(), reference.depth.as_ref().unwrap());
        for p in 0..(w * h) as usize {
            match (fc[p], rc[p]) {
                (None, None) => {}
                (Some(a), Some(b)) if a == b => {
                    prop_assert_eq!(fd[p], rd[p]);
                    prop_assert_eq!(&fast.rgb[3 * p..3 * p + 3], &reference.rgb[3 * p..3 * p + 3]);
                }
                (Some(a), Some(b)) => prop_assert!(
                    (fd[p] - rd[p]).abs() <= 1e-5 * rd[p].abs().max(1.0),
                    "pixel {}: raster sees {:?} at {}, z-buffer {:?} at {}", p, a, fd[p], b, rd[p]
                ),
                (a, b) => prop_assert!(false, "pixel {}: raster {:?}, z-buffer {:?}", p, a, b),
            }
        }
        prop_assert_eq!(fast.stats.painted, reference.stats.painted);
        // The painter's order (back to front, later leaves overwrite) gives the same leaves.
        let painter = render_back_to_front(&tree, &camera, &options).unwrap();
        let pc = painter.cells.as_ref().unwrap();
        let pd = painter.depth.as_ref().unwrap();
        for p in 0..(w * h) as usize {
            match (pc[p], rc[p]) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    prop_assert!(
                        a == b || (pd[p] - rd[p]).abs() <= 1e-5 * rd[p].abs().max(1.0),
                        "pixel {}: painter sees {:?} at {}, z-buffer {:?} at {}", p, a, pd[p], b, rd[p]
                    );
                    if a == b {
                        // The same leaf through the same pixel: the same face, shaded alike.
                        prop_assert_eq!(&painter.rgb[3 * p..3 * p + 3], &reference.rgb[3 * p..3 * p + 3]);
                    }
                }
                (a, b) => prop_assert!(false, "pixel {}: painter {:?}, z-buffer {:?}", p, a, b),
            }
        }
    }
}

#[test]
fn a_ball_fills_a_disc_and_is_shaded_like_a_sphere() {
    // A level-6 ball of radius 30 seen along −z: the painted area is the disc's, within 3 %.
    let tree = stack(&ball_rays::<3>(6, [64, 64, 64], 60).unwrap());
    let camera = Camera {
        eye: [32.0, 32.0, 200.0],
        target: [32.0, 32.0, 32.0],
        up: [0.0, 1.0, 0.0],
        projection: Projection::Orthographic { height: 64.0 },
    };
    let options = RenderOptions {
        width: 256,
        height: 256,
        ..Default::default()
    };
    let image = render(&tree, &camera, &options).unwrap();
    let disc = std::f64::consts::PI * (30.0f64 * 4.0).powi(2);
    let ratio = image.stats.painted as f64 / disc;
    assert!(
        (ratio - 1.0).abs() < 0.03,
        "painted {} pixels, disc {disc:.0}",
        image.stats.painted
    );
    // Culling works: far fewer leaves drawn than the ball has.
    assert!(image.stats.leaves_drawn < tree.full_cells().count() as u64);

    // With exact sphere normals carried by the rays, the shading is smooth: many grey levels, and the
    // brightest pixel is up and to the left of the centre (the light comes from there).
    let rays = sphere_rays_with_normals(6, 30.0);
    let tree2 = stack(&rays);
    assert_eq!(tree2, tree);
    let smooth = render(
        &tree2,
        &camera,
        &RenderOptions {
            normals: Some(&rays),
            ..options
        },
    )
    .unwrap();
    let flat_levels = distinct_colours(&image.rgb);
    let smooth_levels = distinct_colours(&smooth.rgb);
    assert!(
        smooth_levels > 10 * flat_levels,
        "{smooth_levels} vs {flat_levels} colours"
    );
    let (mut best, mut at) = (0u32, (0, 0));
    for y in 0..256 {
        for x in 0..256 {
            let i = 3 * (y * 256 + x);
            let v: u32 = smooth.rgb[i..i + 3].iter().map(|&c| u32::from(c)).sum();
            if smooth.rgb[i..i + 3] != [255, 255, 255] && v > best {
                best = v;
                at = (x, y);
            }
        }
    }
    assert!(at.0 < 128 && at.1 < 128, "brightest pixel at {at:?}");
}

fn distinct_colours(rgb: &[u8]) -> usize {
    let mut set: Vec<[u8; 3]> = rgb.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    set.sort_unstable();
    set.dedup();
    set.len()
}

/// The same voxels as `ball_rays(level, [64, 64, 64], 2·radius)`, with the sphere's normals at run ends.
fn sphere_rays_with_normals(level: u32, radius: f64) -> RaySet<3> {
    let side = 1u32 << level;
    let c = f64::from(side) / 2.0;
    let mut rays = Vec::new();
    for x in 0..side {
        for y in 0..side {
            let (dx, dy) = (f64::from(x) + 0.5 - c, f64::from(y) + 0.5 - c);
            let zs: Vec<u32> = (0..side)
                .filter(|&z| {
                    let dz = f64::from(z) + 0.5 - c;
                    dx * dx + dy * dy + dz * dz <= radius * radius
                })
                .collect();
            if let (Some(&z1), Some(&z2)) = (zs.first(), zs.last()) {
                let n = |z: f64| {
                    let v = [dx as f32, dy as f32, (z - c) as f32];
                    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-6);
                    v.map(|a| a / l)
                };
                rays.push((
                    Ray::new([x, y, z1], z2 + 1),
                    [n(f64::from(z1)), n(f64::from(z2) + 1.0)],
                ));
            }
        }
    }
    RaySet::from_rays_with_normals(level, rays).unwrap()
}

#[test]
fn bad_sizes_and_cameras_are_errors() {
    let tree = stack(&ball_rays::<3>(3, [8, 8, 8], 6).unwrap());
    let camera = default_camera(&tree, [1.0, 1.0, 1.0], None, 8, 8).unwrap();
    let zero = RenderOptions {
        width: 0,
        height: 8,
        ..Default::default()
    };
    assert!(matches!(
        render(&tree, &camera, &zero),
        Err(DisplayError::BadSize { .. })
    ));
    let flat = Camera {
        eye: [1.0, 1.0, 1.0],
        target: [1.0, 1.0, 1.0],
        ..camera
    };
    assert!(matches!(
        render(&tree, &flat, &RenderOptions::default()),
        Err(DisplayError::BadCamera(_))
    ));
    let up = Camera {
        eye: [0.0, 0.0, 10.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 0.0, 1.0],
        ..camera
    };
    assert!(up.check().is_err());
    assert!(default_camera(&tree, [0.0, 0.0, 0.0], None, 8, 8).is_err());
    assert!(default_camera(&tree, [1.0, 0.0, 0.0], Some(190.0), 8, 8).is_err());
}
