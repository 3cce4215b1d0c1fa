//! 2-D quadtrees as pictures: full cells filled (in their values' colours for a tree with values), every
//! leaf's boundary drawn, so the decomposition shows.
//!
//! ```
//! use ktree::{display::plane::quadtree_svg, rays::ball_rays, stacking::paper::stack};
//! let disk = stack(&ball_rays::<2>(4, [16, 16], 20).unwrap());
//! let svg = quadtree_svg(&disk, 256);
//! assert!(svg.starts_with("<svg") && svg.contains("<rect"));
//! ```

use std::convert::Infallible;
use std::fmt::Write as _;

use super::error::DisplayError;
use super::png::Canvas;
use crate::tree::cursor::TryLeaves;
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::valued::{BinaryValues, ValueLeaves, ValueStorage};
use crate::tree::NodeState;

/// Colours of a quadtree picture.
const FILL: [u8; 3] = [70, 110, 170];
const EMPTY: [u8; 3] = [255, 255, 255];
const GRID: [u8; 3] = [150, 150, 150];

/// A `size × size` raster picture of a quadtree: axis 0 to the right, axis 1 up; full leaves filled,
/// leaf boundaries drawn in grey (boundaries of cells smaller than 3 pixels are left out so that fine
/// detail stays readable). The picture of [`values_canvas`] in one colour.
///
/// ```
/// use ktree::{stacking::paper::stack, rays::ball_rays, display::plane::quadtree_canvas};
/// let disk = stack(&ball_rays::<2>(5, [32, 32], 26).unwrap());
/// let canvas = quadtree_canvas(&disk, 128).unwrap();
/// assert_eq!(canvas.rgb.len(), 3 * 128 * 128);
/// ```
///
/// # Errors
/// [`DisplayError::BadSize`] for a zero or too large size; [`DisplayError::Storage`] if a read of the tree
/// fails.
pub fn quadtree_canvas<T: TreeStorage<2>>(tree: &T, size: u32) -> Result<Canvas, DisplayError> {
    values_canvas(&BinaryValues(tree), size, |()| FILL)
}

/// A `size × size` raster picture of a quadtree with values: each full leaf filled with `colour` of its
/// value, empty leaves left white, leaf boundaries drawn as in [`quadtree_canvas`] (a binary tree is the
/// case of one colour, through [`BinaryValues`]).
///
/// ```
/// use ktree::display::{palette::value_colours, plane::values_canvas};
/// use ktree::KTree;
/// // Labels 1 and 2 on the left half, nothing on the right.
/// let t = KTree::<2, u8>::from_dense_values(1, &[Some(1), None, Some(2), None]).unwrap();
/// let colour = value_colours(&t);
/// let canvas = values_canvas(&t, 4, &colour).unwrap();
/// let pixel = |x: usize, y: usize| &canvas.rgb[3 * (4 * y + x)..3 * (4 * y + x) + 3];
/// assert_eq!(pixel(0, 3), colour(1)); // axis 1 points up: voxel (0, 0) is at the bottom left
/// assert_eq!(pixel(0, 0), colour(2));
/// assert_eq!(pixel(3, 0), [255, 255, 255]);
/// ```
///
/// # Errors
/// [`DisplayError::BadSize`] for a zero or too large size; [`DisplayError::Storage`] if a read of the tree
/// fails.
pub fn values_canvas<T: ValueStorage<2>>(
    tree: &T,
    size: u32,
    colour: impl Fn(T::Value) -> [u8; 3],
) -> Result<Canvas, DisplayError> {
    let mut canvas = Canvas::new(size, size, EMPTY)?;
    let scale = f64::from(size) / tree.universe().side() as f64;
    let px = |v: f64| (v * scale).round() as i64;
    let h = i64::from(size);
    let mut outlines = Vec::new();
    for leaf in ValueLeaves::new(tree) {
        let (cell, value) = leaf.map_err(|e| DisplayError::Storage(e.into()))?;
        let (x0, y0) = (f64::from(cell.origin[0]), f64::from(cell.origin[1]));
        let s = cell.side() as f64;
        let (a, b, c, d) = (px(x0), h - px(y0 + s), px(x0 + s), h - px(y0));
        if let Some(v) = value {
            canvas.fill_rect(a, b, c, d, colour(v));
        }
        if s * scale >= 3.0 {
            outlines.push((a, b, c, d));
        }
    }
    for (a, b, c, d) in outlines {
        for x in a..c.min(h) {
            canvas.blend(x, b, GRID, 1.0);
            canvas.blend(x, d - 1, GRID, 1.0);
        }
        for y in b..d.min(h) {
            canvas.blend(a, y, GRID, 1.0);
            canvas.blend(c - 1, y, GRID, 1.0);
        }
    }
    Ok(canvas)
}

/// The same picture as SVG: one rectangle per leaf (full filled), `size` pixels square. (Any storage:
/// [`try_quadtree_svg`].)
pub fn quadtree_svg<T: TreeStorage<2, Error = Infallible>>(tree: &T, size: u32) -> String {
    infallible(try_quadtree_svg(tree, size))
}

/// [`quadtree_svg`] over any storage.
///
/// # Errors
/// The storage's read error.
pub fn try_quadtree_svg<T: TreeStorage<2>>(tree: &T, size: u32) -> Result<String, T::Error> {
    let mut s = super::svg::header(size, size);
    let scale = f64::from(size) / tree.universe().side() as f64;
    let h = f64::from(size);
    for leaf in TryLeaves::new(tree) {
        let (cell, state) = leaf?;
        let side = cell.side() as f64 * scale;
        let x = f64::from(cell.origin[0]) * scale;
        let y = h - f64::from(cell.origin[1]) * scale - side;
        let fill = if state == NodeState::Full {
            "rgb(70,110,170)"
        } else {
            "none"
        };
        let _ = writeln!(
            s,
            "<rect x=\"{x:.3}\" y=\"{y:.3}\" width=\"{side:.3}\" height=\"{side:.3}\" fill=\"{fill}\" \
             stroke=\"rgb(150,150,150)\" stroke-width=\"0.5\"/>"
        );
    }
    s.push_str("</svg>\n");
    Ok(s)
}
