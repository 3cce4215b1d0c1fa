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

/// Reads an OBJ file's groups (`g`) and objects (`o`) as separate meshes, each with its name, in the order
/// they first appear: the faces before any `g` or `o` line are the first (named `unnamed_object`) when
/// there are some; groups of one name are one mesh; a group without triangles is left out. A file without
/// groups is one mesh.
///
/// ```
/// use ktree::io::read_obj_groups_bytes;
/// let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng base\nf 1 3 2\ng side\nf 1 2 4\nf 1 4 3\ng base\nf 2 3 4\n";
/// let groups = read_obj_groups_bytes(obj, "mem.obj".as_ref()).unwrap();
/// let names: Vec<&str> = groups.iter().map(|(n, _)| n.as_str()).collect();
/// assert_eq!(names, ["base", "side"]);
/// assert_eq!((groups[0].1.triangles().len(), groups[1].1.triangles().len()), (2, 2));
/// ```
///
/// # Errors
/// As [`read_mesh`]; a group whose mesh is not valid ([`TriangleMesh::new`]) is named in the message.
pub fn read_obj_groups(path: &Path) -> Result<Vec<(String, TriangleMesh)>, GeometryFileError> {
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    read_obj_groups_bytes(&bytes, path)
}

/// Parses an OBJ file held in memory into its groups and objects, as [`read_obj_groups`] does; `file`
/// names the input in errors.
///
/// # Errors
/// As [`read_obj_groups`].
pub fn read_obj_groups_bytes(
    bytes: &[u8],
    file: &Path,
) -> Result<Vec<(String, TriangleMesh)>, GeometryFileError> {
    let groups = obj::read_groups(bytes).map_err(|fault| fault.in_file(file))?;
    if groups.is_empty() {
        return Err(Fault::whole("no triangle").in_file(file));
    }
    groups
        .into_iter()
        .map(|(name, (vertices, triangles))| {
            TriangleMesh::new(vertices, triangles)
                .map(|mesh| (name.clone(), mesh))
                .map_err(|e| Fault::whole(format!("group '{name}': {e}")).in_file(file))
        })
        .collect()
}
