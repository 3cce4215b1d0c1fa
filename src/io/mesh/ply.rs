//! PLY meshes: the `vertex` element's `x`, `y`, `z` and the `face` element's vertex index lists, through
//! the PLY reader point clouds share.

use super::Parts;
use crate::io::geometry_file::Fault;
use crate::io::ply::{read_body, PlyHeader};

/// The vertices and triangles of a PLY file; a face of `n` vertices is the fan of `n − 2` triangles
/// around its first.
pub(super) fn read(bytes: &[u8]) -> Result<Parts, Fault> {
    let header = PlyHeader::parse(bytes)?;
    let vertex = header
        .element("vertex")
        .ok_or_else(|| Fault::whole("the PLY file has no 'vertex' element"))?;
    let face = header
        .element("face")
        .ok_or_else(|| Fault::whole("the PLY file has no 'face' element"))?;
    let axis = |name: &str| {
        header.elements[vertex].scalar(name).ok_or_else(|| {
            Fault::whole(format!(
                "the PLY vertex element has no scalar property '{name}'"
            ))
        })
    };
    let xyz = [axis("x")?, axis("y")?, axis("z")?];
    let indices = header.elements[face]
        .list(&["vertex_indices", "vertex_index"])
        .ok_or_else(|| {
            Fault::whole("the PLY face element has no list property 'vertex_indices'")
        })?;
    // The header's counts are checked against the body's bytes.
    let mut vertices = Vec::with_capacity(header.elements[vertex].count as usize);
    let mut triangles = Vec::new();
    read_body(bytes, &header, vertex.max(face), |e, i, entry, place| {
        if e == vertex {
            vertices.push(xyz.map(|j| entry.scalar(j)));
        } else if e == face {
            let list = entry.list(indices);
            if list.len() < 3 {
                return Err(Fault {
                    place,
                    message: format!("PLY face {i} has {} vertices, fewer than 3", list.len()),
                });
            }
            let index = |v: f64| -> Result<u32, Fault> {
                if v >= 0.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0 {
                    Ok(v as u32)
                } else {
                    Err(Fault {
                        place,
                        message: format!("PLY face {i}: '{v}' is not a vertex index"),
                    })
                }
            };
            let first = index(list[0])?;
            for pair in list[1..].windows(2) {
                triangles.push([first, index(pair[0])?, index(pair[1])?]);
            }
        }
        Ok(())
    })?;
    Ok((vertices, triangles))
}
