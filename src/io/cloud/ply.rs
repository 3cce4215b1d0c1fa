//! PLY point clouds: the `x`, `y`, `z` of the `vertex` element.

use super::finite;
use crate::io::geometry_file::Fault;
use crate::io::location::Place;
use crate::io::ply::{read_body, PlyHeader};

/// The vertices of a PLY file without faces.
pub(super) fn read(bytes: &[u8]) -> Result<Vec<[f64; 3]>, Fault> {
    let header = PlyHeader::parse(bytes)?;
    if let Some(e) = header
        .elements
        .iter()
        .find(|e| e.name == "face" && e.count > 0)
    {
        return Err(Fault::whole(format!(
            "the PLY file has {} faces: it is a mesh, not a point cloud",
            e.count
        )));
    }
    let vertex = header
        .element("vertex")
        .ok_or_else(|| Fault::whole("the PLY file has no 'vertex' element"))?;
    let element = &header.elements[vertex];
    let axis = |name: &str| {
        element.scalar(name).ok_or_else(|| {
            Fault::whole(format!(
                "the PLY vertex element has no scalar property '{name}'"
            ))
        })
    };
    let xyz = [axis("x")?, axis("y")?, axis("z")?];
    // The header's counts are checked against the body's bytes.
    let mut points = Vec::with_capacity(element.count as usize);
    read_body(bytes, &header, vertex, |e, i, entry, place| {
        if e == vertex {
            let p = xyz.map(|j| entry.scalar(j));
            points.push(finite(p, |why| {
                fault(place, format!("PLY vertex {i} {why}"))
            })?);
        }
        Ok(())
    })?;
    Ok(points)
}

/// A fault at a place of the body.
fn fault(place: Place, message: String) -> Fault {
    Fault { place, message }
}
