//! Triangle mesh files, read into a [`TriangleMesh`]: OBJ (by `tobj`), STL (ASCII, every solid of the
//! file, and binary) and PLY (the `vertex` element's `x`, `y`, `z` and the `face` element's
//! `vertex_indices`, polygons split into fans of triangles).
//!
//! Errors name the file, and the line (ASCII STL and PLY) or byte offset (binary STL and PLY) where the
//! format's parser can tell it.
//!
//! ```
//! use ktree::io::read_mesh_bytes;
//! let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
//! let mesh = read_mesh_bytes(obj, "obj", "mem.obj".as_ref()).unwrap();
//! assert_eq!(mesh.triangles().len(), 1);
//! let e = read_mesh_bytes(b"f 1 2 9\n", "obj", "bad.obj".as_ref()).unwrap_err();
//! assert!(e.to_string().starts_with("bad.obj: "));
//! ```

mod obj;
mod ply;
mod stl;

use std::path::Path;

use super::geometry_file::{extension, io_error, Fault, GeometryFileError, GeometryFileErrorKind};
use crate::solid::mesh::TriangleMesh;

/// The file extensions [`read_mesh`] knows.
pub const MESH_FORMATS: [&str; 3] = ["obj", "stl", "ply"];

/// Vertex positions and triangles (three indices into the positions each), as a parser makes them.
type Parts = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Reads a mesh, choosing the format by extension: `.obj`, `.stl` (ASCII or binary), `.ply`.
///
/// # Errors
/// [`GeometryFileErrorKind::Io`] when the file cannot be read, [`GeometryFileErrorKind::UnknownFormat`] for
/// another extension, [`GeometryFileErrorKind::Malformed`] naming the line or byte where the parser can.
pub fn read_mesh(path: &Path) -> Result<TriangleMesh, GeometryFileError> {
    let format = extension(path);
    if !MESH_FORMATS.contains(&format.as_str()) {
        return read_mesh_bytes(&[], &format, path);
    }
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    read_mesh_bytes(&bytes, &format, path)
}

/// Parses a mesh held in memory; `format` is the extension without the dot (`obj`, `stl`, `ply`, any
/// case), `file` names the input in errors.
///
/// # Errors
/// As [`read_mesh`].
pub fn read_mesh_bytes(
    bytes: &[u8],
    format: &str,
    file: &Path,
) -> Result<TriangleMesh, GeometryFileError> {
    let (vertices, triangles) = match format.to_ascii_lowercase().as_str() {
        "obj" => obj::read(bytes),
        "stl" => stl::read(bytes),
        "ply" => ply::read(bytes),
        other => {
            return Err(GeometryFileError::at_line(
                file.display().to_string(),
                0,
                GeometryFileErrorKind::UnknownFormat {
                    what: "mesh",
                    extension: other.to_string(),
                    known: ".obj, .stl, .ply".into(),
                },
            ))
        }
    }
    .map_err(|fault| fault.in_file(file))?;
    TriangleMesh::new(vertices, triangles).map_err(|e| Fault::whole(e.to_string()).in_file(file))
}
