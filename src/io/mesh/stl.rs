//! STL, binary and ASCII.
//!
//! * Binary: an 80-byte header, a `u32` triangle count, then 50 bytes a triangle (a normal and three
//!   vertices as `f32`, and a 2-byte attribute). A file is binary when its length is what its count says.
//! * ASCII (a file starting with `solid` whose length does not fit the binary layout): one or more
//!   `solid … endsolid` blocks, each of `facet [normal nx ny nz]`, `outer loop`, three or more `vertex x y
//!   z` lines (more make a fan), `endloop`, `endfacet`. Every solid is read, into one mesh.
//!
//! Written here rather than by `stl_io` (used before): its ASCII reader stops at the first solid and names
//! no line, and a binary file whose header starts with `solid ` is taken for ASCII and refused. Equal
//! positions are one vertex (as `stl_io` made them).

use std::collections::HashMap;

use super::Parts;
use crate::io::geometry_file::Fault;

/// The bytes before the first triangle of a binary STL, and a triangle's.
const BINARY_HEADER: usize = 84;
const BINARY_TRIANGLE: usize = 50;

/// The vertices and triangles of an STL file.
pub(super) fn read(bytes: &[u8]) -> Result<Parts, Fault> {
    let binary_count = bytes
        .get(80..84)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64);
    let fits = |n: u64| BINARY_HEADER as u64 + n * BINARY_TRIANGLE as u64 == bytes.len() as u64;
    if binary_count.is_some_and(fits) || !bytes.trim_ascii_start().starts_with(b"solid") {
        binary(bytes, binary_count)
    } else {
        ascii(bytes)
    }
}

/// Positions made into indexed vertices: equal positions (−0 and +0 alike) are one vertex.
#[derive(Default)]
struct Vertices {
    positions: Vec<[f64; 3]>,
    index: HashMap<[u64; 3], u32>,
}

impl Vertices {
    fn index(&mut self, p: [f64; 3]) -> u32 {
        let key = p.map(|c| (c + 0.0).to_bits());
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            (self.positions.len() - 1) as u32
        })
    }
}

fn binary(bytes: &[u8], count: Option<u64>) -> Result<Parts, Fault> {
    let count = count.ok_or_else(|| {
        Fault::whole(format!(
            "a binary STL has an 84-byte header, the file has {} bytes (an ASCII STL starts with 'solid')",
            bytes.len()
        ))
    })?;
    let need = BINARY_HEADER as u64 + count * BINARY_TRIANGLE as u64;
    if need > bytes.len() as u64 {
        return Err(Fault::byte(
            80,
            format!(
                "binary STL: {count} triangles need {need} bytes, the file has {}",
                bytes.len()
            ),
        ));
    }
    let mut vertices = Vertices::default();
    let mut triangles = Vec::with_capacity(count as usize);
    for (i, record) in bytes[BINARY_HEADER..]
        .chunks_exact(BINARY_TRIANGLE)
        .take(count as usize)
        .enumerate()
    {
        let f = |at: usize| {
            f64::from(f32::from_le_bytes([
                record[at],
                record[at + 1],
                record[at + 2],
                record[at + 3],
            ]))
        };
        let mut t = [0u32; 3];
        for (k, slot) in t.iter_mut().enumerate() {
            let p = [f(12 + 12 * k), f(16 + 12 * k), f(20 + 12 * k)];
            if !p.iter().all(|c| c.is_finite()) {
                return Err(Fault::byte(
                    BINARY_HEADER + i * BINARY_TRIANGLE,
                    format!("binary STL: triangle {i} has a vertex that is not finite ({p:?})"),
                ));
            }
            *slot = vertices.index(p);
        }
        triangles.push(t);
    }
    Ok((vertices.positions, triangles))
}

/// Where an ASCII STL reader is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Between solids (or before the first).
    Outside,
    /// Inside a solid, between facets.
    Solid,
    /// After `facet`, before `outer loop`.
    Facet,
    /// Inside `outer loop`, reading vertices.
    Loop,
    /// After `endloop`, before `endfacet`.
    EndLoop,
}

fn ascii(bytes: &[u8]) -> Result<Parts, Fault> {
    let mut vertices = Vertices::default();
    let mut triangles = Vec::new();
    let mut state = State::Outside;
    let mut polygon: Vec<u32> = Vec::new();
    let mut solids = 0;
    let mut last = 0;
    for (n, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let n = n + 1;
        last = n;
        let text = std::str::from_utf8(line).map_err(|_| Fault::line(n, "not UTF-8 text"))?;
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        let Some(&keyword) = words.first() else {
            continue;
        };
        let expected =
            |what: &str| Fault::line(n, format!("expected {what}, found '{}'", text.trim()));
        state = match (state, keyword) {
            (State::Outside, "solid") => {
                solids += 1;
                State::Solid
            }
            (State::Outside, _) => return Err(expected("'solid'")),
            (State::Solid, "facet") => State::Facet,
            (State::Solid, "endsolid") => State::Outside,
            (State::Solid, _) => return Err(expected("'facet' or 'endsolid'")),
            (State::Facet, "outer") if words.get(1) == Some(&"loop") => {
                polygon.clear();
                State::Loop
            }
            (State::Facet, _) => return Err(expected("'outer loop'")),
            (State::Loop, "vertex") => {
                let p = match words[1..] {
                    [x, y, z] => [x, y, z].map(|w| w.parse::<f64>()),
                    _ => return Err(expected("'vertex x y z'")),
                };
                let [Ok(x), Ok(y), Ok(z)] = p else {
                    return Err(expected("'vertex x y z' of three numbers"));
                };
                if ![x, y, z].iter().all(|c| c.is_finite()) {
                    return Err(Fault::line(n, "a vertex coordinate is not finite"));
                }
                polygon.push(vertices.index([x, y, z]));
                State::Loop
            }
            (State::Loop, "endloop") => {
                if polygon.len() < 3 {
                    return Err(Fault::line(
                        n,
                        format!("a facet has {} vertices, fewer than 3", polygon.len()),
                    ));
                }
                for pair in polygon[1..].windows(2) {
                    triangles.push([polygon[0], pair[0], pair[1]]);
                }
                State::EndLoop
            }
            (State::Loop, _) => return Err(expected("'vertex' or 'endloop'")),
            (State::EndLoop, "endfacet") => State::Solid,
            (State::EndLoop, _) => return Err(expected("'endfacet'")),
        };
    }
    if state != State::Outside || solids == 0 {
        return Err(Fault::line(
            last,
            "the ASCII STL ends inside a solid (no 'endsolid')",
        ));
    }
    Ok((vertices.positions, triangles))
}
