//! PNG output through the `image` crate, written atomically.
//!
//! ```
//! use ktree::display::png::{encode_rgb_png, Canvas};
//! let mut canvas = Canvas::new(8, 4, [255, 255, 255]).unwrap();
//! canvas.fill_rect(0, 0, 4, 4, [0, 0, 0]);
//! let png = encode_rgb_png(8, 4, &canvas.rgb).unwrap();
//! assert_eq!(&png[1..4], b"PNG");
//! ```

#[cfg(feature = "png")]
use std::path::Path;

use super::error::DisplayError;

#[cfg(feature = "png")]
/// Encodes RGB bytes (`3 · width · height`, row-major from the top) as PNG.
///
/// # Errors
/// [`DisplayError::BadSize`] if the buffer does not match the size; [`DisplayError::Encode`] on an
/// encoding failure.
pub fn encode_rgb_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, DisplayError> {
    super::error::check_size(width, height)?;
    if rgb.len() != 3 * width as usize * height as usize {
        return Err(DisplayError::BadSize { width, height });
    }
    let mut out = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut out);
    image::ImageEncoder::write_image(encoder, rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(DisplayError::Encode)?;
    Ok(out)
}

#[cfg(feature = "png")]
/// Writes RGB bytes as a PNG file (atomically).
///
/// # Errors
/// As [`encode_rgb_png`], and [`DisplayError::Write`] for I/O errors.
pub fn write_rgb_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), DisplayError> {
    let bytes = encode_rgb_png(width, height, rgb)?;
    crate::fs::write_atomic(path, &bytes).map_err(DisplayError::Write)
}

#[cfg(feature = "png")]
/// Writes grey levels (`width · height` bytes) as a PNG file (atomically).
///
/// # Errors
/// As [`write_rgb_png`].
pub fn write_grey_png(
    path: &Path,
    width: u32,
    height: u32,
    grey: &[u8],
) -> Result<(), DisplayError> {
    let rgb: Vec<u8> = grey.iter().flat_map(|&g| [g, g, g]).collect();
    write_rgb_png(path, width, height, &rgb)
}

/// An RGB canvas for drawing anti-aliased lines and filled rectangles, then saving as PNG.
#[derive(Debug, Clone)]
pub struct Canvas {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// RGB bytes, row-major from the top.
    pub rgb: Vec<u8>,
}

impl Canvas {
    /// A canvas filled with `background`.
    ///
    /// # Errors
    /// [`DisplayError::BadSize`].
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Result<Self, DisplayError> {
        super::error::check_size(width, height)?;
        let n = width as usize * height as usize;
        let mut rgb = Vec::with_capacity(3 * n);
        for _ in 0..n {
            rgb.extend_from_slice(&background);
        }
        Ok(Self { width, height, rgb })
    }

    /// Blends `colour` into pixel `(x, y)` with opacity `a` (ignored outside the canvas).
    #[inline]
    pub fn blend(&mut self, x: i64, y: i64, colour: [u8; 3], a: f64) {
        if x < 0 || y < 0 || x >= i64::from(self.width) || y >= i64::from(self.height) {
            return;
        }
        let i = 3 * (y as usize * self.width as usize + x as usize);
        let a = a.clamp(0.0, 1.0);
        for (dst, &c) in self.rgb[i..i + 3].iter_mut().zip(&colour) {
            let old = f64::from(*dst);
            *dst = (old + (f64::from(c) - old) * a).round() as u8;
        }
    }

    /// Fills the pixel rectangle `[x0, x1) × [y0, y1)` (clipped).
    pub fn fill_rect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, colour: [u8; 3]) {
        for y in y0.max(0)..y1.min(i64::from(self.height)) {
            for x in x0.max(0)..x1.min(i64::from(self.width)) {
                let i = 3 * (y as usize * self.width as usize + x as usize);
                self.rgb[i..i + 3].copy_from_slice(&colour);
            }
        }
    }

    /// Draws an anti-aliased line (Wu's algorithm) between image points (pixel centres at `i + ½`).
    pub fn line(&mut self, (x0, y0): (f64, f64), (x1, y1): (f64, f64), colour: [u8; 3]) {
        let (mut x0, mut y0, mut x1, mut y1) = (x0 - 0.5, y0 - 0.5, x1 - 0.5, y1 - 0.5);
        let steep = (y1 - y0).abs() > (x1 - x0).abs();
        if steep {
            std::mem::swap(&mut x0, &mut y0);
            std::mem::swap(&mut x1, &mut y1);
        }
        if x0 > x1 {
            std::mem::swap(&mut x0, &mut x1);
            std::mem::swap(&mut y0, &mut y1);
        }
        let dx = x1 - x0;
        let gradient = if dx.abs() < 1e-12 {
            0.0
        } else {
            (y1 - y0) / dx
        };
        let mut plot = |x: i64, y: i64, a: f64| {
            if steep {
                self.blend(y, x, colour, a)
            } else {
                self.blend(x, y, colour, a)
            }
        };
        let xs = x0.round() as i64;
        let xe = x1.round() as i64;
        for x in xs..=xe {
            // Coverage of the end pixels by the part of the segment inside them.
            let lo = (x as f64 - 0.5).max(x0);
            let hi = (x as f64 + 0.5).min(x1);
            let w = if xs == xe {
                (x1 - x0).max(0.3)
            } else {
                (hi - lo).clamp(0.0, 1.0)
            };
            let y = y0 + gradient * (x as f64 - x0);
            let yf = y.floor();
            let frac = y - yf;
            plot(x, yf as i64, (1.0 - frac) * w);
            plot(x, yf as i64 + 1, frac * w);
        }
    }

    #[cfg(feature = "png")]
    /// Writes the canvas as a PNG file (atomically).
    ///
    /// # Errors
    /// As [`write_rgb_png`].
    pub fn write_png(&self, path: &Path) -> Result<(), DisplayError> {
        write_rgb_png(path, self.width, self.height, &self.rgb)
    }
}

/// Draws line segments `[x0, y0, x1, y1]` (drawing coordinates, y up) fitted into a white
/// `width × height` canvas, in black.
///
/// # Errors
/// [`DisplayError::BadSize`].
pub fn lines_canvas(
    segments: &[[f64; 4]],
    width: u32,
    height: u32,
) -> Result<Canvas, DisplayError> {
    let fit = super::svg::Fit::new(super::svg::bounds_of(segments), width, height, 10.0);
    let mut canvas = Canvas::new(width, height, [255, 255, 255])?;
    for s in segments {
        canvas.line(fit.map(s[0], s[1]), fit.map(s[2], s[3]), [0, 0, 0]);
    }
    Ok(canvas)
}
