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
use crate::solid::cloud::PointCloud;

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
    let points = match format.to_ascii_lowercase().as_str() {
        "ply" => ply::read(bytes),
        "pcd" => pcd::read(bytes),
        "xyz" | "txt" => text::read(bytes, false),
        "csv" => text::read(bytes, true),
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
    PointCloud::new(points).map_err(|e| Fault::whole(e.to_string()).in_file(file))
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
