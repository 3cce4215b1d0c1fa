//! Mesh and outline file writers: PLY (binary little-endian), OBJ, STL (binary), glTF binary (`.glb`),
//! the surfaces of a tree's values with their colours as PLY, OBJ (with its `.mtl`) and `.glb`, and for
//! outlines PLY edges, OBJ lines and an SVG path.
//!
//! Each writes to any [`Write`]; [`super::write_mesh`] writes files atomically.
//!
//! ```
//! use ktree::export::{files::write_ply, surface::boundary_mesh};
//! let mesh = boundary_mesh(&ktree::KTree::<3>::full(1).unwrap());
//! let mut bytes = Vec::new();
//! write_ply(&mut bytes, &mesh).unwrap();
//! assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
//! ```

use std::io::{self, Write};

use super::outline::Loop;
use super::surface::{SurfaceMesh, ValueMesh};
use crate::value::{Dtype, Value};

/// Vertex coordinates as 32-bit floats, little-endian.
fn f32_le(w: &mut dyn Write, v: &[f64; 3]) -> io::Result<()> {
    for x in v {
        w.write_all(&(*x as f32).to_le_bytes())?;
    }
    Ok(())
}

/// PLY, binary little-endian: `float` x, y, z per vertex and a `uchar`-counted `int` list per face.
///
/// # Errors
/// The writer's.
pub fn write_ply(w: &mut dyn Write, mesh: &SurfaceMesh) -> io::Result<()> {
    ply_header(w, "", mesh.vertices.len(), mesh.triangles.len(), "")?;
    for v in &mesh.vertices {
        f32_le(w, v)?;
    }
    for t in &mesh.triangles {
        ply_triangle(w, t, 0)?;
    }
    Ok(())
}

/// A PLY header of `vertices` vertices and `faces` faces, each face with its vertex list and the
/// properties `face_properties` (header lines).
fn ply_header(
    w: &mut dyn Write,
    comments: &str,
    vertices: usize,
    faces: usize,
    face_properties: &str,
) -> io::Result<()> {
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by ktree\n{comments}element vertex {vertices}\n\
         property float x\nproperty float y\nproperty float z\nelement face {faces}\n\
         property list uchar int vertex_indices\n{face_properties}end_header\n",
    )
}

/// A PLY face's vertex list: the triangle `t`, its indices shifted by `base`.
fn ply_triangle(w: &mut dyn Write, t: &[u32; 3], base: u32) -> io::Result<()> {
    w.write_all(&[3])?;
    for i in t {
        w.write_all(&((base + i) as i32).to_le_bytes())?;
    }
    Ok(())
}

/// The PLY type of a value type's samples.
fn ply_type(dtype: Option<Dtype>) -> &'static str {
    match dtype {
        Some(Dtype::U16) => "ushort",
        Some(Dtype::U32) => "uint",
        Some(Dtype::I8) => "char",
        Some(Dtype::F32) => "float",
        _ => "uchar",
    }
}

/// The surfaces of a tree's values as PLY, binary little-endian: the surfaces' vertices, then every face
/// once ([`ValueMesh::faces_once`]: a face between two values from the smaller one's surface, oriented
/// outward from it) with the face properties `red`, `green`, `blue` (`uchar`: the colour of the value
/// inside, by `colour`), the value inside and the value behind (`label` and `label_back` for integers in
/// their own type, `value` and `value_back` as `float`; colours are `red`, `green`, `blue` themselves
/// and `red_back`, `green_back`, `blue_back`), and `back_empty` (`uchar`, 1 where nothing is behind; the
/// value behind is then 0). Each value's voxels are bounded by its faces with `label` that value together
/// with its faces with `label_back` that value, turned over. A value with a name of its own
/// ([`ValueMesh::with_names`]) has it in a header comment: `comment 3 liver`.
///
/// ```
/// use ktree::export::{files::write_value_ply, surface::value_boundary_mesh};
/// let mut dense = [None; 8];
/// (dense[0], dense[1]) = (Some(1u8), Some(2));
/// let mesh = value_boundary_mesh(&ktree::KTree::<3, u8>::from_dense_values(1, &dense).unwrap());
/// let mut bytes = Vec::new();
/// write_value_ply(&mut bytes, &mesh, &|_| [255, 0, 0]).unwrap();
/// let text = String::from_utf8_lossy(&bytes);
/// assert!(text.contains("element face 22\n") && text.contains("property uchar label_back\n"));
/// ```
///
/// # Errors
/// The writer's.
pub fn write_value_ply<V: Value>(
    w: &mut dyn Write,
    mesh: &ValueMesh<V>,
    colour: &dyn Fn(V) -> [u8; 3],
) -> io::Result<()> {
    let mut properties =
        String::from("property uchar red\nproperty uchar green\nproperty uchar blue\n");
    if V::DTYPE == Some(Dtype::Rgb) {
        properties +=
            "property uchar red_back\nproperty uchar green_back\nproperty uchar blue_back\n";
    } else {
        let (ty, name) = (
            ply_type(V::DTYPE),
            if V::DTYPE == Some(Dtype::F32) {
                "value"
            } else {
                "label"
            },
        );
        properties += &format!("property {ty} {name}\nproperty {ty} {name}_back\n");
    }
    properties += "property uchar back_empty\n";
    // The values' own names, as comments (PLY has no other place for them).
    let comments: String = mesh
        .surfaces
        .iter()
        .filter(|s| s.label.is_some())
        .map(|s| format!("comment {} {}\n", s.value.text(), s.name()))
        .collect();
    ply_header(
        w,
        &comments,
        mesh.vertex_count(),
        mesh.faces_once().count(),
        &properties,
    )?;
    let mut bases = Vec::with_capacity(mesh.surfaces.len());
    let mut base = 0u32;
    for s in &mesh.surfaces {
        bases.push(base);
        base += s.mesh.vertices.len() as u32;
        for v in &s.mesh.vertices {
            f32_le(w, v)?;
        }
    }
    let zero = vec![0u8; V::DTYPE.map_or(0, Dtype::bytes)];
    let mut bytes = Vec::new();
    for (k, t) in mesh.faces_once() {
        let s = &mesh.surfaces[k];
        ply_triangle(w, &s.mesh.triangles[t], bases[k])?;
        bytes.clear();
        bytes.extend_from_slice(&colour(s.value));
        if V::DTYPE != Some(Dtype::Rgb) {
            s.value.write_le(&mut bytes);
        }
        match s.behind[t] {
            Some(b) => b.write_le(&mut bytes),
            None => bytes.extend_from_slice(&zero),
        }
        bytes.push(u8::from(s.behind[t].is_none()));
        w.write_all(&bytes)?;
    }
    Ok(())
}

/// Wavefront OBJ: `v x y z` lines (shortest round-trip decimals) and `f a b c` lines (1-based).
///
/// # Errors
/// The writer's.
pub fn write_obj(w: &mut dyn Write, mesh: &SurfaceMesh) -> io::Result<()> {
    writeln!(w, "# written by ktree")?;
    for v in &mesh.vertices {
        writeln!(w, "v {} {} {}", v[0], v[1], v[2])?;
    }
    for t in &mesh.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}

/// The surfaces of a tree's values as OBJ: every surface's vertices, then per value a group and material
/// of its name ([`ValueSurface::name`](super::surface::ValueSurface::name): `g label_3`, `usemtl label_3`)
/// with all of its triangles, so each group is a closed surface (a face between two values is in both
/// groups, oriented outward from each); `mtllib mtl` first when given (see [`write_value_mtl`]).
///
/// ```
/// use ktree::export::{files::write_value_obj, surface::value_boundary_mesh};
/// let mesh = value_boundary_mesh(&ktree::KTree::<3, u16>::from_dense_values(1, &[Some(7); 8]).unwrap());
/// let mut bytes = Vec::new();
/// write_value_obj(&mut bytes, &mesh, Some("cube.mtl")).unwrap();
/// let text = String::from_utf8(bytes).unwrap();
/// assert!(text.contains("mtllib cube.mtl\n") && text.contains("g label_7\nusemtl label_7\n"));
/// assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 12);
/// ```
///
/// # Errors
/// The writer's.
pub fn write_value_obj<V: Value>(
    w: &mut dyn Write,
    mesh: &ValueMesh<V>,
    mtl: Option<&str>,
) -> io::Result<()> {
    writeln!(w, "# written by ktree")?;
    if let Some(mtl) = mtl {
        writeln!(w, "mtllib {mtl}")?;
    }
    for v in mesh.surfaces.iter().flat_map(|s| &s.mesh.vertices) {
        writeln!(w, "v {} {} {}", v[0], v[1], v[2])?;
    }
    let mut base = 1;
    for s in &mesh.surfaces {
        let name = s.name();
        writeln!(w, "g {name}\nusemtl {name}")?;
        for t in &s.mesh.triangles {
            writeln!(w, "f {} {} {}", t[0] + base, t[1] + base, t[2] + base)?;
        }
        base += s.mesh.vertices.len() as u32;
    }
    Ok(())
}

/// The materials of [`write_value_obj`]'s groups: per value `newmtl` of its name and `Kd`, its colour by
/// `colour` (0 to 1 per channel).
///
/// ```
/// use ktree::export::{files::write_value_mtl, surface::value_boundary_mesh};
/// let mesh = value_boundary_mesh(&ktree::KTree::<3, u8>::from_dense_values(1, &[Some(2); 8]).unwrap());
/// let mut bytes = Vec::new();
/// write_value_mtl(&mut bytes, &mesh, &|_| [255, 0, 0]).unwrap();
/// assert!(String::from_utf8(bytes).unwrap().contains("newmtl label_2\nKd 1 0 0\n"));
/// ```
///
/// # Errors
/// The writer's.
pub fn write_value_mtl<V: Value>(
    w: &mut dyn Write,
    mesh: &ValueMesh<V>,
    colour: &dyn Fn(V) -> [u8; 3],
) -> io::Result<()> {
    writeln!(w, "# written by ktree")?;
    for s in &mesh.surfaces {
        let [r, g, b] = colour(s.value).map(|c| f64::from(c) / 255.0);
        writeln!(w, "newmtl {}\nKd {r} {g} {b}", s.name())?;
    }
    Ok(())
}

/// Binary STL: an 80-byte header, the triangle count, and per triangle its unit normal and corners.
///
/// # Errors
/// The writer's.
pub fn write_stl(w: &mut dyn Write, mesh: &SurfaceMesh) -> io::Result<()> {
    let mut header = [b' '; 80];
    let text = b"binary STL written by ktree";
    header[..text.len()].copy_from_slice(text);
    w.write_all(&header)?;
    let count = u32::try_from(mesh.triangles.len()).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "too many triangles for binary STL (at most 2^32 − 1)",
        )
    })?;
    w.write_all(&count.to_le_bytes())?;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let n = if len > 0.0 { n.map(|x| x / len) } else { n };
        f32_le(w, &n)?;
        for p in [a, b, c] {
            f32_le(w, &p)?;
        }
        w.write_all(&[0, 0])?;
    }
    Ok(())
}

/// glTF 2.0 binary (`.glb`): one mesh of one indexed triangle primitive (`float` positions, `uint`
/// indices). The data are z-up; the node rotates them a quarter turn about x into glTF's y-up, so that an
/// importer that turns y-up back into z-up (Blender's) shows the original coordinates.
///
/// # Errors
/// The writer's; [`io::ErrorKind::InvalidInput`] past 4 GiB.
pub fn write_glb(w: &mut dyn Write, mesh: &SurfaceMesh) -> io::Result<()> {
    write_glb_parts(w, &[(mesh, None)])
}

/// The surfaces of a tree's values as glTF 2.0 binary (`.glb`), as [`write_glb`] one mesh: per value a
/// mesh and node of its name ([`ValueSurface::name`](super::surface::ValueSurface::name)), all of its
/// triangles (a closed surface: a face between two values is in both) and a material whose
/// `baseColorFactor` is its colour by `colour` (sRGB, given as glTF's linear factors).
///
/// ```
/// use ktree::export::{files::write_value_glb, surface::value_boundary_mesh};
/// let mesh = value_boundary_mesh(&ktree::KTree::<3, u8>::from_dense_values(1, &[Some(1); 8]).unwrap());
/// let mut bytes = Vec::new();
/// write_value_glb(&mut bytes, &mesh, &|_| [255, 255, 255]).unwrap();
/// assert!(bytes.starts_with(b"glTF"));
/// assert!(String::from_utf8_lossy(&bytes).contains(r#""baseColorFactor":[1,1,1,1]"#));
/// ```
///
/// # Errors
/// As [`write_glb`].
pub fn write_value_glb<V: Value>(
    w: &mut dyn Write,
    mesh: &ValueMesh<V>,
    colour: &dyn Fn(V) -> [u8; 3],
) -> io::Result<()> {
    let parts: Vec<_> = mesh
        .surfaces
        .iter()
        .map(|s| (&s.mesh, Some((s.name(), colour(s.value)))))
        .collect();
    write_glb_parts(w, &parts)
}

/// A linear glTF colour factor of an sRGB channel.
fn linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A mesh of a `.glb`, with a name and a colour for its material when given.
type GlbPart<'a> = (&'a SurfaceMesh, Option<(String, [u8; 3])>);

/// A `.glb` of one mesh and node per part, each with a name and a material of that colour when given.
fn write_glb_parts(w: &mut dyn Write, parts: &[GlbPart<'_>]) -> io::Result<()> {
    let too_big = || {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "the mesh exceeds 4 GiB for .glb",
        )
    };
    let (mut nodes, mut meshes, mut materials) = (Vec::new(), Vec::new(), Vec::new());
    let (mut views, mut accessors) = (Vec::new(), Vec::new());
    let mut offset = 0usize;
    for (k, (mesh, named)) in parts.iter().enumerate() {
        let positions = mesh.vertices.len() * 12;
        let indices = mesh.triangles.len() * 12;
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for v in &mesh.vertices {
            for a in 0..3 {
                lo[a] = lo[a].min(v[a] as f32);
                hi[a] = hi[a].max(v[a] as f32);
            }
        }
        if mesh.vertices.is_empty() {
            (lo, hi) = ([0.0; 3], [0.0; 3]);
        }
        let name = named
            .as_ref()
            .map_or(String::new(), |(name, _)| format!(r#""name":"{name}","#));
        let material = named.as_ref().map_or(String::new(), |(name, colour)| {
            let [r, g, b] = colour.map(linear);
            materials.push(format!(
                r#"{{"name":"{name}","pbrMetallicRoughness":{{"baseColorFactor":[{r},{g},{b},1],"metallicFactor":0}}}}"#
            ));
            format!(r#","material":{}"#, materials.len() - 1)
        });
        nodes.push(format!(
            r#"{{{name}"mesh":{k},"rotation":[-0.70710678,0,0,0.70710678]}}"#
        ));
        meshes.push(format!(
            r#"{{{name}"primitives":[{{"attributes":{{"POSITION":{p}}},"indices":{i},"mode":4{material}}}]}}"#,
            p = 2 * k,
            i = 2 * k + 1
        ));
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{positions},"target":34962}}"#
        ));
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{indices},"target":34963}}"#,
            offset + positions
        ));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5126,"count":{},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}}"#,
            2 * k,
            mesh.vertices.len(),
            lo[0],
            lo[1],
            lo[2],
            hi[0],
            hi[1],
            hi[2]
        ));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
            2 * k + 1,
            mesh.triangles.len() * 3
        ));
        offset += positions + indices;
    }
    let bin_len = offset;
    let node_ids: Vec<String> = (0..parts.len()).map(|k| k.to_string()).collect();
    let materials = if materials.is_empty() {
        String::new()
    } else {
        format!(r#","materials":[{}]"#, materials.join(","))
    };
    let json = format!(
        concat!(
            r#"{{"asset":{{"version":"2.0","generator":"ktree"}},"scene":0,"scenes":[{{"nodes":[{}]}}],"#,
            r#""nodes":[{}],"meshes":[{}]{},"buffers":[{{"byteLength":{}}}],"#,
            r#""bufferViews":[{}],"accessors":[{}]}}"#
        ),
        node_ids.join(","),
        nodes.join(","),
        meshes.join(","),
        materials,
        bin_len,
        views.join(","),
        accessors.join(","),
    );
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin_len;
    let total = u32::try_from(total).map_err(|_| too_big())?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(json.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    w.write_all(&(bin_len as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    for (mesh, _) in parts {
        for v in &mesh.vertices {
            f32_le(w, v)?;
        }
        for t in &mesh.triangles {
            for i in t {
                w.write_all(&i.to_le_bytes())?;
            }
        }
    }
    Ok(())
}

/// The vertices of outline loops in world units and their edges (each loop's last vertex joins its first).
fn loop_edges(loops: &[Loop]) -> (Vec<[f64; 2]>, Vec<[u32; 2]>) {
    let mut vertices = Vec::new();
    let mut edges = Vec::new();
    for l in loops {
        let base = vertices.len() as u32;
        vertices.extend_from_slice(l);
        let n = l.len() as u32;
        edges.extend((0..n).map(|i| [base + i, base + (i + 1) % n]));
    }
    (vertices, edges)
}

/// Outline loops as PLY, binary little-endian: vertices (`z` = 0) and an `edge` element of
/// `vertex1`, `vertex2` pairs, each loop in order.
///
/// # Errors
/// The writer's.
pub fn write_ply_edges(w: &mut dyn Write, loops: &[Loop]) -> io::Result<()> {
    let (vertices, edges) = loop_edges(loops);
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by ktree: closed outlines\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement edge {}\n\
         property int vertex1\nproperty int vertex2\nend_header\n",
        vertices.len(),
        edges.len()
    )?;
    for v in &vertices {
        f32_le(w, &[v[0], v[1], 0.0])?;
    }
    for e in &edges {
        for i in e {
            w.write_all(&(*i as i32).to_le_bytes())?;
        }
    }
    Ok(())
}

/// Outline loops as OBJ: `v x y 0` lines and one closed `l` line per loop.
///
/// # Errors
/// The writer's.
pub fn write_obj_lines(w: &mut dyn Write, loops: &[Loop]) -> io::Result<()> {
    writeln!(w, "# written by ktree: closed outlines")?;
    let mut base = 1;
    for l in loops {
        for v in l {
            writeln!(w, "v {} {} 0", v[0], v[1])?;
        }
        let ids: Vec<String> = (0..l.len())
            .chain(std::iter::once(0))
            .map(|i| (base + i).to_string())
            .collect();
        writeln!(w, "l {}", ids.join(" "))?;
        base += l.len();
    }
    Ok(())
}

/// Outline loops as one SVG path (`fill-rule` nonzero: holes run the other way), y up as in the data.
///
/// # Errors
/// The writer's.
pub fn write_svg(w: &mut dyn Write, loops: &[Loop]) -> io::Result<()> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for v in loops.iter().flatten() {
        for a in 0..2 {
            lo[a] = lo[a].min(v[a]);
            hi[a] = hi[a].max(v[a]);
        }
    }
    if loops.is_empty() {
        (lo, hi) = ([0.0; 2], [1.0; 2]);
    }
    let (width, height) = (hi[0] - lo[0], hi[1] - lo[1]);
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="{} {} {width} {height}">"#,
        lo[0], -hi[1]
    )?;
    write!(
        w,
        r#"<path transform="scale(1,-1)" fill="black" fill-rule="nonzero" d=""#
    )?;
    for l in loops {
        for (i, v) in l.iter().enumerate() {
            write!(w, "{}{} {} ", if i == 0 { "M" } else { "L" }, v[0], v[1])?;
        }
        write!(w, "Z ")?;
    }
    writeln!(w, r#""/>"#)?;
    writeln!(w, "</svg>")
}
