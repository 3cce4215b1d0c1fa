//! Structure-aware meshes: an OBJ file written from arbitrary vertices (any finite or non-finite value,
//! including huge and tiny ones) and faces (indices in or out of range, negative ones), so the parser
//! accepts many and the voxelizer sees degenerate, open, self-intersecting and extreme geometry.
#![no_main]
use std::fmt::Write;

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
struct Input {
    vertices: Vec<[f32; 3]>,
    faces: Vec<Vec<i8>>,
}

fuzz_target!(|input: Input| {
    let mut obj = String::new();
    for v in &input.vertices {
        let _ = writeln!(obj, "v {} {} {}", v[0], v[1], v[2]);
    }
    for f in &input.faces {
        obj.push('f');
        for i in f {
            let _ = write!(obj, " {i}");
        }
        obj.push('\n');
    }
    ktree_fuzz::check_mesh(obj.as_bytes(), "obj");
});
