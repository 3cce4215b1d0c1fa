//! The display module's error type.

use thiserror::Error;

/// Errors from rendering, drawing and writing images.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DisplayError {
    /// The image size is zero or too large. Use a width and height from 1 to [`MAX_IMAGE_SIDE`], at most
    /// [`MAX_PIXELS`] pixels in all.
    #[error("image size {width}x{height} is not allowed (each side 1..={max}, at most {pixels} pixels)", max = MAX_IMAGE_SIDE, pixels = MAX_PIXELS)]
    BadSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// The camera is degenerate: its eye equals its target, its up vector is parallel to the view
    /// direction, or a parameter is not finite or out of range.
    #[error("bad camera: {0}")]
    BadCamera(CameraProblem),
    /// A view direction is zero or not finite.
    #[error("bad view direction {0:?}: it must be a finite, non-zero vector")]
    BadDirection(Vec<f64>),
    /// A slice position lies outside the universe.
    #[error("slice at {position} on axis {axis} is outside the universe [0, {side})")]
    SliceOutside {
        /// The axis sliced.
        axis: usize,
        /// The position asked for.
        position: u64,
        /// The universe's side.
        side: u64,
    },
    /// A frame count of zero was asked for.
    #[error("at least one frame is needed")]
    NoFrames,
    /// Writing an image file failed.
    #[error(transparent)]
    Write(#[from] crate::fs::FileOpError),
    /// Reading the tree failed (a file read in place was changed after it was opened).
    #[error(transparent)]
    Storage(#[from] crate::tree::StorageError),
    /// Encoding an image failed.
    #[cfg(feature = "png")]
    #[error("cannot encode the image")]
    Encode(#[source] image::ImageError),
}

/// What is wrong with a camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum CameraProblem {
    /// The eye, target or up vector has an infinite or NaN coordinate.
    #[error("eye, target and up must be finite")]
    NotFinite,
    /// An orthographic camera's height is not positive and finite.
    #[error("orthographic height must be positive")]
    BadHeight,
    /// A perspective camera's field of view is outside (0°, 180°).
    #[error("field of view must be between 0 and 180 degrees")]
    BadFieldOfView,
    /// The eye and the target are the same point.
    #[error("eye and target coincide")]
    EyeAtTarget,
    /// The up vector is zero.
    #[error("up is zero")]
    ZeroUp,
    /// The up vector is parallel to the view direction.
    #[error("up is parallel to the view direction")]
    UpAlongView,
}

/// The largest image side accepted, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// The largest number of pixels in one image (2^26: about 200 MB of RGB).
pub const MAX_PIXELS: u64 = 1 << 26;

/// Checks an image size.
///
/// # Errors
/// [`DisplayError::BadSize`] when a side is 0 or exceeds [`MAX_IMAGE_SIDE`], or the image has more than
/// [`MAX_PIXELS`] pixels.
pub fn check_size(width: u32, height: u32) -> Result<(), DisplayError> {
    if width == 0
        || height == 0
        || width > MAX_IMAGE_SIDE
        || height > MAX_IMAGE_SIDE
        || u64::from(width) * u64::from(height) > MAX_PIXELS
    {
        return Err(DisplayError::BadSize { width, height });
    }
    Ok(())
}
