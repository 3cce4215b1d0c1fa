//! SVG output: true vector lines, and filled rectangles for quadtree pictures.
//!
//! ```
//! use ktree::display::svg::{bounds_of, lines_svg};
//! let segments = [[0.0, 0.0, 2.0, 1.0], [2.0, 1.0, 3.0, -1.0]];
//! assert_eq!(bounds_of(&segments), [0.0, -1.0, 3.0, 1.0]);
//! let svg = lines_svg(&segments, 120, 80, 1.0);
//! assert!(svg.starts_with("<svg") && svg.contains("<path"));
//! ```

use std::fmt::Write as _;
use std::path::Path;

use super::error::DisplayError;

/// Maps drawing coordinates (y up) into an image of `width × height` with a margin, keeping proportions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    scale: f64,
    dx: f64,
    dy: f64,
    height: f64,
}

impl Fit {
    /// The map that fits `bounds = [xmin, ymin, xmax, ymax]` into the image, centred, with `margin` pixels.
    pub fn new(bounds: [f64; 4], width: u32, height: u32, margin: f64) -> Self {
        let (bw, bh) = (
            (bounds[2] - bounds[0]).max(1e-9),
            (bounds[3] - bounds[1]).max(1e-9),
        );
        let (w, h) = (f64::from(width), f64::from(height));
        let scale = ((w - 2.0 * margin) / bw)
            .min((h - 2.0 * margin) / bh)
            .max(1e-12);
        let dx = (w - bw * scale) / 2.0 - bounds[0] * scale;
        let dy = (h - bh * scale) / 2.0 - bounds[1] * scale;
        Self {
            scale,
            dx,
            dy,
            height: h,
        }
    }

    /// Image coordinates (y down) of a drawing point (y up).
    pub fn map(&self, x: f64, y: f64) -> (f64, f64) {
        (
            x * self.scale + self.dx,
            self.height - (y * self.scale + self.dy),
        )
    }

    /// Drawing units to pixels.
    pub fn scale(&self) -> f64 {
        self.scale
    }
}

/// An SVG document with black line segments `[x0, y0, x1, y1]` (drawing coordinates, y up) fitted into
/// `width × height` on a white background.
///
/// ```
/// let svg = ktree::display::svg::lines_svg(&[[0.0, 0.0, 1.0, 1.0]], 100, 100, 1.0);
/// assert!(svg.starts_with("<svg") && svg.contains("<path"));
/// ```
pub fn lines_svg(segments: &[[f64; 4]], width: u32, height: u32, stroke: f64) -> String {
    let bounds = bounds_of(segments);
    let fit = Fit::new(bounds, width, height, 10.0);
    let mut s = header(width, height);
    let _ = write!(
        s,
        "<path fill=\"none\" stroke=\"black\" stroke-width=\"{stroke}\" stroke-linecap=\"round\" d=\""
    );
    for seg in segments {
        let (x0, y0) = fit.map(seg[0], seg[1]);
        let (x1, y1) = fit.map(seg[2], seg[3]);
        let _ = write!(s, "M{x0:.3} {y0:.3}L{x1:.3} {y1:.3}");
    }
    s.push_str("\"/>\n</svg>\n");
    s
}

/// The bounding box of segments, a unit box when there are none.
pub fn bounds_of(segments: &[[f64; 4]]) -> [f64; 4] {
    if segments.is_empty() {
        return [0.0, 0.0, 1.0, 1.0];
    }
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for s in segments {
        b[0] = b[0].min(s[0]).min(s[2]);
        b[1] = b[1].min(s[1]).min(s[3]);
        b[2] = b[2].max(s[0]).max(s[2]);
        b[3] = b[3].max(s[1]).max(s[3]);
    }
    b
}

/// The opening of an SVG document with a white background.
pub fn header(width: u32, height: u32) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    )
}

/// Writes an SVG document (atomically).
///
/// # Errors
/// [`DisplayError::Write`] on an I/O error.
pub fn write_svg(path: &Path, svg: &str) -> Result<(), DisplayError> {
    crate::fs::write_atomic(path, svg.as_bytes()).map_err(DisplayError::Write)
}
