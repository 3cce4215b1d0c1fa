//! Meagher's other order (M7): the painter's algorithm, back to front, every hit pixel painted over.

#[cfg(doc)]
use super::raster::render;

use super::camera::Camera;
use super::error::DisplayError;
use super::order::{try_walk_ordered, Order, Walk};
use super::raster::{background, RenderOptions, RenderStats, Rendered};
use super::screen::{cell_box, viewer, Screen};
use super::shading::{light_for, FaceColours};
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// Meagher's other order (M7): the painter's algorithm. Leaves are visited back to front and every hit
/// pixel is painted, later leaves overwriting earlier ones; no depth is compared and nothing is culled,
/// so it costs a visit of every full leaf. Same picture as [`render`] (face shading; `options.normals` is
/// not used).
///
/// ```
/// use ktree::display::{default_camera, render, render_back_to_front, RenderOptions, ISO_TOWARD_EYE};
/// use ktree::{rays::ball_rays, stacking::paper::stack};
/// let ball = stack(&ball_rays::<3>(4, [16, 16, 16], 24).unwrap());
/// let options = RenderOptions { width: 48, height: 48, ..Default::default() };
/// let camera = default_camera(&ball, ISO_TOWARD_EYE, None, 48, 48).unwrap();
/// let painter = render_back_to_front(&ball, &camera, &options).unwrap();
/// // The same pixels as front to back (the same leaves, up to exact ties in depth).
/// assert_eq!(painter.stats.painted, render(&ball, &camera, &options).unwrap().stats.painted);
/// ```
///
/// # Errors
/// As [`render`].
pub fn render_back_to_front<T: TreeStorage<3>>(
    tree: &T,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Rendered, DisplayError> {
    let screen = Screen::new(camera, options.width, options.height)?;
    let (w, h) = (options.width, options.height);
    let pixels = w as usize * h as usize;
    let mut rgb = background(options);
    let mut depth = options.depth.then(|| vec![f32::INFINITY; pixels]);
    let mut cells = options.cells.then(|| vec![None; pixels]);
    let mut hit_any = vec![false; pixels];
    let faces = FaceColours::new(light_for(camera), options.colour);
    let mut stats = RenderStats::default();
    try_walk_ordered(tree, viewer(camera), Order::BackToFront, |node| {
        stats.nodes_visited += 1;
        if node.state != NodeState::Full {
            return Walk::Descend;
        }
        let Some(r) = screen.rect(&node.cell) else {
            return Walk::Descend;
        };
        stats.leaves_drawn += 1;
        let (lo, hi) = cell_box(&node.cell);
        for y in r.y0..=r.y1 {
            for x in r.x0..=r.x1 {
                stats.pixel_tests += 1;
                if let Some((t, axis, _, d)) = screen.hit(x, y, lo, hi) {
                    let i = y as usize * w as usize + x as usize;
                    rgb[3 * i..3 * i + 3].copy_from_slice(&faces.entered(axis, d));
                    hit_any[i] = true;
                    if let Some(dep) = depth.as_mut() {
                        dep[i] = t as f32;
                    }
                    if let Some(cs) = cells.as_mut() {
                        cs[i] = Some(node.cell);
                    }
                }
            }
        }
        Walk::Descend
    })
    .map_err(|e| DisplayError::Storage(e.into()))?;
    stats.painted = hit_any.iter().filter(|&&b| b).count() as u64;
    Ok(Rendered {
        width: w,
        height: h,
        rgb,
        depth,
        cells,
        stats,
    })
}
