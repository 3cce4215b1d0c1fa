//! 4-D trees shown as 3-D frames: the slice of a time-space tree at one position along an axis (time is
//! the last axis by convention) is an octree; a strip of frames at evenly spaced times, rendered with one
//! camera, shows the motion (each leaf in its value's colour for a tree with values: [`time_strip_values`]).
//!
//! ```
//! use ktree::{display::slices::slice_4d, rays::ball_rays, stacking::paper::stack};
//! // A 4-D ball; its slice at the middle of the fourth axis is a 3-D ball.
//! let ball4 = stack(&ball_rays::<4>(3, [8, 8, 8, 8], 8).unwrap());
//! let middle = slice_4d(&ball4, 3, 4).unwrap();
//! assert_eq!(middle.level(), 3);
//! assert!(middle.contains([4, 4, 4]) && !middle.contains([0, 0, 0]));
//! ```

use super::camera::{Bounds, Camera, ISO_TOWARD_EYE};
use super::error::DisplayError;
use super::png::Canvas;
use super::raster::{render, Paint, RenderOptions, Rendered};
use crate::space::Cell;
use crate::tree::storage::TreeStorage;
use crate::tree::valued::{BinaryValues, LeavesOfValues, ValueLeaves, ValueStorage};
use crate::tree::Octree;

/// The octree of the 4-D tree's slice at `position` along `axis` (the remaining axes keep their order).
///
/// ```
/// use ktree::{stacking::paper::stack, rays::ball_rays, display::slices::slice_4d};
/// let ball4 = stack(&ball_rays::<4>(3, [8, 8, 8, 8], 8).unwrap());
/// let middle = slice_4d(&ball4, 3, 4).unwrap();
/// middle.assert_well_formed();
/// assert!(middle.voxel_count() > 0);
/// ```
///
/// # Errors
/// [`DisplayError::SliceOutside`] if `axis > 3` or the position is outside the universe;
/// [`DisplayError::Storage`] if a read of the tree fails.
pub fn slice_4d<T: TreeStorage<4>>(
    tree: &T,
    axis: usize,
    position: u32,
) -> Result<Octree, DisplayError> {
    let side = tree.universe().side();
    if axis > 3 || u64::from(position) >= side {
        return Err(DisplayError::SliceOutside {
            axis,
            position: position.into(),
            side,
        });
    }
    crate::ops::slice::<4, 3, T>(tree, axis, position).map_err(|e| match e {
        crate::ops::OpsError::Storage(e) => DisplayError::Storage(e),
        other => unreachable!("the axis and position were checked: {other}"),
    })
}

/// A strip of `frames` hidden-surface renderings of the 4-D tree's slices at evenly spaced positions along
/// `axis` (the middles of `frames` equal parts of the universe), each `frame_size` pixels square, seen
/// from `ISO_TOWARD_EYE` with one camera framing the whole motion. Returns the strip and the frames with
/// their slice positions (to write as an animated sequence of PNGs). The strip of [`time_strip_values`]
/// in one colour.
///
/// # Errors
/// [`DisplayError::NoFrames`], [`DisplayError::SliceOutside`], [`DisplayError::BadSize`];
/// [`DisplayError::Storage`] if a read of the tree fails.
pub fn time_strip<T: TreeStorage<4>>(
    tree: &T,
    axis: usize,
    frames: usize,
    frame_size: u32,
) -> Result<Strip, DisplayError> {
    let bounds = super::camera::object_bounds(tree).map_err(|e| DisplayError::Storage(e.into()))?;
    let colour = RenderOptions::default().colour;
    strip(
        &BinaryValues(tree),
        bounds,
        (axis, frames, frame_size),
        |()| colour,
    )
}

/// The strip of [`time_strip`] of a 4-D tree with values: each full leaf of a slice drawn (shaded) in
/// `colour` of its value.
///
/// ```
/// use ktree::display::{palette::value_colours, slices::time_strip_values};
/// use ktree::KTree;
/// // Label 1 early on the time axis, label 2 late.
/// let dense: Vec<_> = (0..256).map(|i| Some(if i < 128 { 1u8 } else { 2 })).collect();
/// let t = KTree::<4, u8>::from_dense_values(2, &dense).unwrap();
/// let (strip, frames) = time_strip_values(&t, 3, 2, 32, value_colours(&t)).unwrap();
/// assert_eq!((strip.width, frames.len()), (2 * 36, 2));
/// ```
///
/// # Errors
/// As [`time_strip`].
pub fn time_strip_values<T: ValueStorage<4>>(
    tree: &T,
    axis: usize,
    frames: usize,
    frame_size: u32,
    colour: impl Fn(T::Value) -> [u8; 3],
) -> Result<Strip, DisplayError> {
    let mut bounds: Option<Bounds<4>> = None;
    for leaf in ValueLeaves::new(tree) {
        let (cell, value) = leaf.map_err(|e| DisplayError::Storage(e.into()))?;
        if value.is_none() {
            continue;
        }
        let lo = cell.origin.map(f64::from);
        let hi = lo.map(|o| o + cell.side() as f64);
        bounds = Some(match bounds {
            None => (lo, hi),
            Some((a, b)) => (
                std::array::from_fn(|i| a[i].min(lo[i])),
                std::array::from_fn(|i| b[i].max(hi[i])),
            ),
        });
    }
    strip(tree, bounds, (axis, frames, frame_size), colour)
}

/// A strip and its frames with their slice positions.
pub type Strip = (Canvas, Vec<(u32, Rendered)>);

/// The strip of a tree whose full voxels lie within `bounds` (`None`: none).
fn strip<T: ValueStorage<4>>(
    tree: &T,
    bounds: Option<Bounds<4>>,
    (axis, frames, frame_size): (usize, usize, u32),
    colour: impl Fn(T::Value) -> [u8; 3],
) -> Result<Strip, DisplayError> {
    if frames == 0 {
        return Err(DisplayError::NoFrames);
    }
    if axis > 3 {
        return Err(DisplayError::SliceOutside {
            axis,
            position: 0,
            side: tree.universe().side(),
        });
    }
    let strip_width = u32::try_from(frames)
        .ok()
        .and_then(|f| f.checked_mul(frame_size + 4))
        .ok_or(DisplayError::BadSize {
            width: u32::MAX,
            height: frame_size,
        })?;
    let mut canvas = Canvas::new(strip_width, frame_size, [255, 255, 255])?;
    let side = tree.universe().side();
    let (lo, hi) = bounds.unwrap_or(([0.0; 4], [side as f64; 4]));
    let keep = |v: [f64; 4]| -> [f64; 3] {
        let mut out = [0.0; 3];
        let mut j = 0;
        for (i, &c) in v.iter().enumerate() {
            if i != axis {
                out[j] = c;
                j += 1;
            }
        }
        out
    };
    let camera = Camera::framing(
        keep(lo),
        keep(hi),
        ISO_TOWARD_EYE,
        None,
        frame_size,
        frame_size,
    )?;
    let mut out = Vec::with_capacity(frames);
    for f in 0..frames {
        let position = ((2 * f as u64 + 1) * side / (2 * frames as u64)).min(side - 1) as u32;
        let slice =
            crate::ops::slice_values::<4, 3, T>(tree, axis, position).map_err(|e| match e {
                crate::ops::OpsError::Storage(e) => DisplayError::Storage(e),
                other => unreachable!("the axis and position were checked: {other}"),
            })?;
        let paint = |cell: &Cell<3>| slice.value_at(cell.origin()).map_or([0; 3], &colour);
        let options = RenderOptions {
            width: frame_size,
            height: frame_size,
            paint: Some(Paint(&paint)),
            ..Default::default()
        };
        let image = render(&LeavesOfValues(&slice), &camera, &options)?;
        let x0 = f as u32 * (frame_size + 4);
        for y in 0..frame_size {
            let src = 3 * (y * frame_size) as usize;
            let dst = 3 * (y * strip_width + x0) as usize;
            canvas.rgb[dst..dst + 3 * frame_size as usize]
                .copy_from_slice(&image.rgb[src..src + 3 * frame_size as usize]);
        }
        for y in 0..frame_size {
            for dx in frame_size..frame_size + 4 {
                canvas.blend(i64::from(x0 + dx), i64::from(y), [200, 200, 200], 1.0);
            }
        }
        out.push((position, image));
    }
    Ok((canvas, out))
}
