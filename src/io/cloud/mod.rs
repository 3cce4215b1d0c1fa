//! Point cloud files, read into a [`PointCloud`]: PLY (vertices, no faces), PCD, XYZ/CSV text and LAS/LAZ.
//!
//! * `.ply`: ASCII and binary (little and big endian) PLY whose `vertex` element has `x`, `y`, `z`
//!   properties of any scalar type; other elements and properties are skipped. A PLY with faces is a mesh
//!   ([`is_cloud_file`]).
//! * `.pcd`: PCL's format, `DATA ascii`, `binary` and `binary_compressed` (LZF, PCL's default for large
//!   clouds), fields `x`, `y`, `z` of any `TYPE`/`SIZE`, other fields skipped; points whose `x`, `y`, `z`
//!   are all NaN (PCL's pixels without a measurement in organized clouds) skipped.
//! * `.xyz`, `.csv`, `.txt`: three numbers a line (separated by spaces, tabs, commas or semicolons), extra
//!   columns ignored, `#` comments and blank lines skipped; a `.csv` may start with a header line.
//! * `.las`, `.laz`: ASPRS LAS 1.0–1.4, compressed or not, coordinates scaled and offset as the header says
//!   (the header read by the `las` crate, compressed points decoded chunk by chunk by the `laz` crate).
//!
//! **Attributes.** Besides the points, the readers keep the attributes a file gives them
//! ([`PointCloud::colours`], [`PointCloud::intensities`], [`PointCloud::classes`]); a file without one has
//! none (`None`, no memory):
//! * colour: PLY `red`, `green`, `blue` (8-bit types as they are, 16-bit ones scaled by 255/65535, 32-bit
//!   integers by 255/(2³²−1), floats taken as 0…1 and scaled by 255; rounded, clamped to 0…255); PCD's
//!   packed `rgb` or `rgba` field (PCL's `0x00RRGGBB` in the bits of a `F 4` or a `U 4`/`I 4`); LAS RGB
//!   (point formats 2, 3, 5, 7, 8, 10), 16 bits a channel: as laspy reads them, then to 8 bits by the high
//!   byte — unless every channel of every point of the file is below 256, which is 8-bit colour stored in
//!   16 bits (as in laspy's `simple.las`) and kept as it is;
//! * intensity: PLY and PCD `intensity`, LAS intensity (`u16`), as `f32`;
//! * class: PLY and PCD `label` or `class` (a whole number 0…255, else an error naming the point), LAS
//!   classification (point formats 0–5: its low 5 bits; 6–10: the byte).
//!
//! Errors name the file and the line (text) or byte offset (binary) of the first fault. Counts from headers
//! are checked against the bytes that must hold what they count before anything is allocated for them: a
//! LAS file's points against its point data, a LAZ file's against its chunk table, each chunk decoded from
//! its own bytes only. A NaN or infinite coordinate is an error naming its line or point (but for PCD's
//! points without a measurement).
//!
//! ```
//! use ktree::io::read_cloud_bytes;
//! use ktree::solid::cloud::CloudVoxelizer;
//! let text = b"# x y z\n0.1 0.1 0.1\n0.2 0.3 0.1 255\n1.7 0.1 0.1\n";
//! let cloud = read_cloud_bytes(text, "xyz", "mem.xyz".as_ref()).unwrap();
//! assert_eq!(cloud.len(), 3);
//! let v = CloudVoxelizer::new(0.5).unwrap().voxelize(cloud.points()).unwrap();
//! assert_eq!(v.rays.voxel_count(), 2); // voxels (0, 0, 0) and (3, 0, 0)
//! ```

mod las;
mod lzf;
mod pcd;
mod ply;
mod text;

use std::io::Read;
use std::path::Path;

use super::geometry_file::{extension, io_error, Fault, GeometryFileError, GeometryFileErrorKind};
use super::scalar::Scalar;
use crate::solid::cloud::{PointAttributes, PointCloud};
use crate::value::Rgb;

/// What a parser reads: the points and their attributes.
type Points = (Vec<[f64; 3]>, PointAttributes);

/// The file extensions [`read_cloud`] knows.
pub const CLOUD_FORMATS: [&str; 7] = ["ply", "pcd", "xyz", "csv", "txt", "las", "laz"];

/// Reads a point cloud, choosing the format by extension (see the [module docs](self)).
///
/// # Errors
/// [`GeometryFileErrorKind::Io`] when the file cannot be read, [`GeometryFileErrorKind::UnknownFormat`] for
/// another extension, [`GeometryFileErrorKind::Malformed`] naming the line or byte of the first fault.
pub fn read_cloud(path: &Path) -> Result<PointCloud, GeometryFileError> {
    let format = extension(path);
    if !CLOUD_FORMATS.contains(&format.as_str()) {
        return read_cloud_bytes(&[], &format, path);
    }
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    read_cloud_bytes(&bytes, &format, path)
}

/// Parses a point cloud held in memory; `format` is the extension without the dot (any case), `file` names
/// the input in errors.
///
/// # Errors
/// As [`read_cloud`].
pub fn read_cloud_bytes(
    bytes: &[u8],
    format: &str,
    file: &Path,
) -> Result<PointCloud, GeometryFileError> {
    let (points, attributes) = match format.to_ascii_lowercase().as_str() {
        "ply" => ply::read(bytes),
        "pcd" => pcd::read(bytes),
        "xyz" | "txt" => text::read(bytes, false).map(|p| (p, PointAttributes::default())),
        "csv" => text::read(bytes, true).map(|p| (p, PointAttributes::default())),
        "las" | "laz" => las::read(bytes),
        other => {
            return Err(GeometryFileError::at_line(
                file.display().to_string(),
                0,
                GeometryFileErrorKind::UnknownFormat {
                    what: "point cloud",
                    extension: other.to_string(),
                    known: ".ply, .pcd, .xyz, .csv, .txt, .las, .laz".into(),
                },
            ))
        }
    }
    .map_err(|fault| fault.in_file(file))?;
    // Every parser has refused a coordinate that is not finite already, naming its line or byte.
    PointCloud::with_attributes(points, attributes)
        .map_err(|e| Fault::whole(e.to_string()).in_file(file))
}

/// Whether a file is read as a point cloud by [`read_cloud`]: `.pcd`, `.xyz`, `.csv`, `.txt`, `.las`,
/// `.laz`, or a `.ply` whose header declares no face (with faces it is a mesh).
///
/// ```
/// use ktree::io::is_cloud_file;
/// let dir = tempfile::tempdir().unwrap();
/// let ply = dir.path().join("m.ply");
/// std::fs::write(&ply, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n").unwrap();
/// assert!(!is_cloud_file(&ply).unwrap()); // a mesh
/// std::fs::write(&ply, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n").unwrap();
/// assert!(is_cloud_file(&ply).unwrap());
/// std::fs::write(&ply, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float\nend_header\n").unwrap();
/// assert_eq!(is_cloud_file(&ply).unwrap_err().line(), Some(4)); // neither: a broken header
/// ```
///
/// # Errors
/// [`GeometryFileErrorKind::Io`] when a PLY file cannot be read, [`GeometryFileErrorKind::Malformed`]
/// naming the line of a PLY header's first fault.
pub fn is_cloud_file(path: &Path) -> Result<bool, GeometryFileError> {
    let format = extension(path);
    if format != "ply" {
        return Ok(CLOUD_FORMATS.contains(&format.as_str()));
    }
    // A header is short: 64 KiB holds any sensible one.
    let mut head = Vec::new();
    std::fs::File::open(path)
        .and_then(|file| file.take(1 << 16).read_to_end(&mut head))
        .map_err(|e| io_error(path, e))?;
    super::ply::ply_has_faces(&head)
        .map(|faces| !faces)
        .map_err(|fault| fault.in_file(path))
}

/// The point, or `fault`'s error when it has a coordinate that is not finite.
fn finite(p: [f64; 3], fault: impl FnOnce(String) -> Fault) -> Result<[f64; 3], Fault> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(p)
    } else {
        Err(fault(format!(
            "has a coordinate that is not finite ({} {} {})",
            p[0], p[1], p[2]
        )))
    }
}

/// A colour channel of a PLY property of type `kind` to 8 bits (see the [module docs](self)).
fn channel(kind: Scalar, v: f64) -> u8 {
    let scaled = match kind {
        Scalar::U8 | Scalar::I8 => v,
        Scalar::U16 | Scalar::I16 => v * 255.0 / 65535.0,
        Scalar::F32 | Scalar::F64 => v * 255.0,
        _ => v * 255.0 / f64::from(u32::MAX),
    };
    // `as` saturates, and takes NaN to 0.
    scaled.round().clamp(0.0, 255.0) as u8
}

/// PCL's packed colour `0x00RRGGBB` (the alpha of `rgba` in the high byte is dropped).
fn unpack(bits: u32) -> Rgb {
    [(bits >> 16) as u8, (bits >> 8) as u8, bits as u8]
}

/// A class: a whole number 0…255, or the reason why not.
fn class(v: f64) -> Result<u8, String> {
    if v.fract() == 0.0 && (0.0..=255.0).contains(&v) {
        Ok(v as u8)
    } else {
        Err(format!("has class {v}: expected a whole number 0…255"))
    }
}
