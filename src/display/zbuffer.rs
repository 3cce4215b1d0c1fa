//! The brute-force reference of the hidden-surface renderer: a z-buffer over every full leaf. The tests
//! and the benchmarks hold [`render`]'s images equal to it.

#[cfg(doc)]
use super::raster::render;

use super::camera::Camera;
use super::error::DisplayError;
use super::raster::{background, RenderOptions, RenderStats, Rendered};
use super::screen::{cell_box, Rect, Screen};
use super::shading::{light_for, shade};
use crate::space::Cell;
use crate::tree::cursor::TryLeaves;
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// The brute-force reference: a z-buffer over *all* full leaves in Morton order, keeping for each pixel the
/// leaf with the smallest entry depth (ties: the first). Shading is by face orientation (`options.normals` is
/// not used). `O(leaves · pixels per leaf)`; for tests and small trees.
///
/// ```
/// use ktree::display::{default_camera, render, render_zbuffer, RenderOptions, ISO_TOWARD_EYE};
/// use ktree::{rays::ball_rays, stacking::paper::stack};
/// let ball = stack(&ball_rays::<3>(4, [16, 16, 16], 24).unwrap());
/// let options = RenderOptions { width: 48, height: 48, ..Default::default() };
/// let camera = default_camera(&ball, ISO_TOWARD_EYE, None, 48, 48).unwrap();
/// let reference = render_zbuffer(&ball, &camera, &options).unwrap();
/// assert_eq!(reference.stats.painted, render(&ball, &camera, &options).unwrap().stats.painted);
/// ```
///
/// # Errors
/// As [`render`].
pub fn render_zbuffer<T: TreeStorage<3>>(
    tree: &T,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Rendered, DisplayError> {
    let screen = Screen::new(camera, options.width, options.height)?;
    let (w, h) = (options.width, options.height);
    let pixels = w as usize * h as usize;
    let mut rgb = background(options);
    let mut depth = vec![f64::INFINITY; pixels];
    let mut cells = vec![None; pixels];
    let light = light_for(camera);
    let mut stats = RenderStats::default();
    for leaf in TryLeaves::new(tree) {
        let (cell, state) = leaf.map_err(|e| DisplayError::Storage(e.into()))?;
        stats.nodes_visited += 1;
        if state != NodeState::Full {
            continue;
        }
        // The reference's own rectangle: all 8 corners through the public projection (independent of
        // the renderer's incremental one); a corner behind the eye means the whole screen.
        let Some(r) = reference_rect(camera, &cell, w, h) else {
            continue;
        };
        stats.leaves_drawn += 1;
        let (lo, hi) = cell_box(&cell);
        for y in r.y0..=r.y1 {
            for x in r.x0..=r.x1 {
                stats.pixel_tests += 1;
                if let Some((t, axis, _, d)) = screen.hit(x, y, lo, hi) {
                    let i = y as usize * w as usize + x as usize;
                    if t < depth[i] {
                        depth[i] = t;
                        cells[i] = Some(cell);
                        let mut n = [0.0; 3];
                        n[axis] = if d[axis] > 0.0 { -1.0 } else { 1.0 };
                        rgb[3 * i..3 * i + 3].copy_from_slice(&shade(n, light, options.colour));
                    }
                }
            }
        }
    }
    stats.painted = cells.iter().filter(|c| c.is_some()).count() as u64;
    Ok(Rendered {
        width: w,
        height: h,
        rgb,
        depth: Some(depth.iter().map(|&d| d as f32).collect()),
        cells: Some(cells),
        stats,
    })
}

/// The pixels whose centres may see `cell`, from its 8 corners projected by [`Camera::project`].
fn reference_rect(camera: &Camera, cell: &Cell<3>, w: u32, h: u32) -> Option<Rect> {
    let (lo, hi) = cell_box(cell);
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for c in 0..8 {
        let p = [
            if c & 1 == 0 { lo[0] } else { hi[0] },
            if c & 2 == 0 { lo[1] } else { hi[1] },
            if c & 4 == 0 { lo[2] } else { hi[2] },
        ];
        match camera.project(p, w, h) {
            Some((x, y, _)) => {
                xmin = xmin.min(x);
                xmax = xmax.max(x);
                ymin = ymin.min(y);
                ymax = ymax.max(y);
            }
            None => {
                return Some(Rect {
                    x0: 0,
                    x1: w - 1,
                    y0: 0,
                    y1: h - 1,
                })
            }
        }
    }
    let x0 = (xmin - 0.5 - 1e-6).ceil().max(0.0);
    let x1 = (xmax - 0.5 + 1e-6).floor().min(f64::from(w) - 1.0);
    let y0 = (ymin - 0.5 - 1e-6).ceil().max(0.0);
    let y1 = (ymax - 0.5 + 1e-6).floor().min(f64::from(h) - 1.0);
    (x0 <= x1 && y0 <= y1).then_some(Rect {
        x0: x0 as u32,
        x1: x1 as u32,
        y0: y0 as u32,
        y1: y1 as u32,
    })
}
