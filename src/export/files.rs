//! Mesh and outline file writers: PLY (binary little-endian), OBJ, STL (binary), glTF binary (`.glb`),
//! and for outlines PLY edges, OBJ lines and an SVG path.
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
use super::surface::SurfaceMesh;

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
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by ktree\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        mesh.vertices.len(),
        mesh.triangles.len()
    )?;
    for v in &mesh.vertices {
        f32_le(w, v)?;
    }
    for t in &mesh.triangles {
        w.write_all(&[3])?;
        for i in t {
            w.write_all(&(*i as i32).to_le_bytes())?;
        }
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
    let too_big = || {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "the mesh exceeds 4 GiB for .glb",
        )
    };
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
    let bin_len = positions + indices;
    let json = format!(
        concat!(
            r#"{{"asset":{{"version":"2.0","generator":"ktree"}},"scene":0,"scenes":[{{"nodes":[0]}}],"#,
            r#""nodes":[{{"mesh":0,"rotation":[-0.70710678,0,0,0.70710678]}}],"#,
            r#""meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":4}}]}}],"#,
            r#""buffers":[{{"byteLength":{bin}}}],"#,
            r#""bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{pos},"target":34962}},"#,
            r#"{{"buffer":0,"byteOffset":{pos},"byteLength":{ind},"target":34963}}],"#,
            r#""accessors":[{{"bufferView":0,"componentType":5126,"count":{nv},"type":"VEC3","#,
            r#""min":[{l0},{l1},{l2}],"max":[{h0},{h1},{h2}]}},"#,
            r#"{{"bufferView":1,"componentType":5125,"count":{ni},"type":"SCALAR"}}]}}"#
        ),
        bin = bin_len,
        pos = positions,
        ind = indices,
        nv = mesh.vertices.len(),
        ni = mesh.triangles.len() * 3,
        l0 = lo[0],
        l1 = lo[1],
        l2 = lo[2],
        h0 = hi[0],
        h1 = hi[1],
        h2 = hi[2],
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
    for v in &mesh.vertices {
        f32_le(w, v)?;
    }
    for t in &mesh.triangles {
        for i in t {
            w.write_all(&i.to_le_bytes())?;
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
