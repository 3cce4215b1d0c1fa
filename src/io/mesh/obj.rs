//! Wavefront OBJ, read by `tobj` (faces triangulated as fans, points and lines ignored, every group and
//! object of the file in one mesh).

use super::Parts;
use crate::io::geometry_file::Fault;

/// The vertices and triangles of an OBJ file.
pub(super) fn read(bytes: &[u8]) -> Result<Parts, Fault> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are not read (a mesh is its shape).
    let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| Fault::whole(format!("OBJ: {e}")))?;
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for model in models {
        let base = vertices.len() as u32;
        let p = &model.mesh.positions;
        vertices.extend(
            p.chunks_exact(3)
                .map(|c| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])]),
        );
        triangles.extend(
            model
                .mesh
                .indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    Ok((vertices, triangles))
}
