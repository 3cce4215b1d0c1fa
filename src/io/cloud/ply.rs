//! PLY point clouds: the `x`, `y`, `z` of the `vertex` element, and its `red`, `green`, `blue`,
//! `intensity` and `label` or `class` when it has them.

use super::{channel, class, finite, Points};
use crate::io::geometry_file::Fault;
use crate::io::location::Place;
use crate::io::ply::PlyProperty;
use crate::io::ply::{read_body, PlyHeader};
use crate::io::scalar::Scalar;
use crate::solid::cloud::PointAttributes;

/// The vertices of a PLY file without faces.
pub(super) fn read(bytes: &[u8]) -> Result<Points, Fault> {
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
    let kind = |j: usize| match &element.properties[j] {
        PlyProperty::Scalar { kind, .. } => *kind,
        PlyProperty::List { item, .. } => *item,
    };
    let rgb: Option<[(usize, Scalar); 3]> = match (
        element.scalar("red"),
        element.scalar("green"),
        element.scalar("blue"),
    ) {
        (Some(r), Some(g), Some(b)) => Some([r, g, b].map(|j| (j, kind(j)))),
        _ => None,
    };
    let intensity = element.scalar("intensity");
    let label = element.scalar("label").or_else(|| element.scalar("class"));
    // The header's counts are checked against the body's bytes.
    let n = element.count as usize;
    let mut points = Vec::with_capacity(n);
    let mut attributes = PointAttributes {
        colours: rgb.map(|_| Vec::with_capacity(n)),
        intensities: intensity.map(|_| Vec::with_capacity(n)),
        classes: label.map(|_| Vec::with_capacity(n)),
    };
    read_body(bytes, &header, vertex, |e, i, entry, place| {
        if e == vertex {
            let p = xyz.map(|j| entry.scalar(j));
            points.push(finite(p, |why| {
                fault(place, format!("PLY vertex {i} {why}"))
            })?);
            if let (Some(rgb), Some(colours)) = (rgb, &mut attributes.colours) {
                colours.push(rgb.map(|(j, kind)| channel(kind, entry.scalar(j))));
            }
            if let (Some(j), Some(intensities)) = (intensity, &mut attributes.intensities) {
                intensities.push(entry.scalar(j) as f32);
            }
            if let (Some(j), Some(classes)) = (label, &mut attributes.classes) {
                classes.push(
                    class(entry.scalar(j))
                        .map_err(|why| fault(place, format!("PLY vertex {i} {why}")))?,
                );
            }
        }
        Ok(())
    })?;
    Ok((points, attributes))
}

/// A fault at a place of the body.
fn fault(place: Place, message: String) -> Fault {
    Fault { place, message }
}
