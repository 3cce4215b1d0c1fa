//! Wavefront OBJ, read by `tobj` (faces triangulated as fans, points and lines ignored): every group and
//! object of the file in one mesh ([`read`]), or each apart ([`read_groups`]).

use super::Parts;
use crate::io::geometry_file::Fault;

/// The vertices and triangles of an OBJ file.
pub(super) fn read(bytes: &[u8]) -> Result<Parts, Fault> {
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for (_, parts) in models(bytes)? {
        append(&mut vertices, &mut triangles, parts);
    }
    Ok((vertices, triangles))
}

/// The vertices and triangles of each group (`g`) or object (`o`) of an OBJ file, with its name, in the
/// order they first appear: a `g` or `o` line starts the next one; the faces before any are the first,
/// named `unnamed_object`, when there are some; groups of one name are one (their faces joined); a group
/// without triangles (points or lines only) is none.
pub(super) fn read_groups(bytes: &[u8]) -> Result<Vec<(String, Parts)>, Fault> {
    let mut groups: Vec<(String, Parts)> = Vec::new();
    for (name, parts) in models(bytes)? {
        if parts.1.is_empty() {
            continue;
        }
        match groups.iter_mut().find(|(n, _)| *n == name) {
            Some((_, (v, t))) => append(v, t, parts),
            None => groups.push((name, parts)),
        }
    }
    Ok(groups)
}

/// Appends a part's vertices and triangles, its indices moved past the vertices already there.
fn append(vertices: &mut Vec<[f64; 3]>, triangles: &mut Vec<[u32; 3]>, (v, t): Parts) {
    let base = vertices.len() as u32;
    vertices.extend(v);
    triangles.extend(t.into_iter().map(|t| t.map(|i| base + i)));
}

/// tobj's models (one per group or object, in file order), each with its name and its own vertices.
fn models(bytes: &[u8]) -> Result<Vec<(String, Parts)>, Fault> {
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
    Ok(models
        .into_iter()
        .map(|model| {
            let vertices = model
                .mesh
                .positions
                .chunks_exact(3)
                .map(|c| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])])
                .collect();
            let triangles = model
                .mesh
                .indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect();
            (model.name, (vertices, triangles))
        })
        .collect())
}
