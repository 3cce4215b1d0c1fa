//! PNG output through the `image` crate, written atomically.

use std::path::Path;

use super::error::DisplayError;

fn write_err(path: &Path, e: impl std::fmt::Display) -> DisplayError {
    DisplayError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Encodes RGB bytes (`3 · width · height`, row-major from the top) as PNG.
///
/// # Errors
/// [`DisplayError::BadSize`] if the buffer does not match the size; [`DisplayError::Write`] on an
/// encoding failure.
pub fn encode_rgb_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, DisplayError> {
    super::error::check_size(width, height)?;
    if rgb.len() != 3 * width as usize * height as usize {
        return Err(DisplayError::BadSize { width, height });
    }
    let mut out = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut out);
    image::ImageEncoder::write_image(encoder, rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| write_err(Path::new("<memory>"), e))?;
    Ok(out)
}

/// Writes RGB bytes as a PNG file (atomically).
///
/// # Errors
/// As [`encode_rgb_png`], and [`DisplayError::Write`] for I/O errors.
pub fn write_rgb_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), DisplayError> {
    let bytes = encode_rgb_png(width, height, rgb)?;
    crate::io::write_atomic(path, &bytes).map_err(|e| write_err(path, e))
}

/// Writes grey levels (`width · height` bytes) as a PNG file (atomically).
///
/// # Errors
/// As [`write_rgb_png`].
pub fn write_grey_png(path: &Path, width: u32, height: u32, grey: &[u8]) -> Result<(), DisplayError> {
    let rgb: Vec<u8> = grey.iter().flat_map(|&g| [g, g, g]).collect();
    write_rgb_png(path, width, height, &rgb)
}
