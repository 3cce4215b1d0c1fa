//! Small closed meshes for the tests: boxes and octahedra, outward oriented.
//!
//! ```
//! use ktree_verify::meshes::{cube, octahedron};
//! assert_eq!(cube([0.0; 3], [1.0; 3]).open_edges(), 0);
//! assert_eq!(octahedron([0.0; 3], 1.0).open_edges(), 0);
//! ```

use ktree::solid::mesh::TriangleMesh;

/// The triangles of a box whose corner `i` is at `(i & 1, i >> 1 & 1, i >> 2 & 1)`, counter-clockwise
/// seen from outside.
pub const CUBE: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3],
    [4, 5, 6],
    [5, 7, 6],
    [0, 1, 4],
    [1, 5, 4],
    [2, 6, 3],
    [3, 6, 7],
    [0, 4, 2],
    [2, 4, 6],
    [1, 3, 5],
    [3, 7, 5],
];

/// The corners of the box `[lo, hi]`, corner `i` at the `hi` side along axis `a` where bit `a` of `i` is set.
pub fn cube_corners(lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| [0, 1, 2].map(|a| if i >> a & 1 == 1 { hi[a] } else { lo[a] }))
        .collect()
}

/// The box `[lo, hi]`, outward oriented.
///
/// # Panics
/// For a box that is not a valid mesh (a coordinate not finite).
pub fn cube(lo: [f64; 3], hi: [f64; 3]) -> TriangleMesh {
    TriangleMesh::new(cube_corners(lo, hi), CUBE.to_vec()).expect("a box is a valid mesh")
}

/// The octahedron |x − c| + |y − c| + |z − c| ≤ r, outward oriented.
///
/// # Panics
/// For an octahedron that is not a valid mesh (a coordinate not finite).
pub fn octahedron(c: [f64; 3], r: f64) -> TriangleMesh {
    let mut vertices = Vec::new();
    for a in 0..3 {
        for s in [-1.0, 1.0] {
            let mut v = c;
            v[a] += s * r;
            vertices.push(v);
        }
    }
    // Vertices: 0 −x, 1 +x, 2 −y, 3 +y, 4 −z, 5 +z.
    let mut triangles = Vec::new();
    for (x, sx) in [(0u32, -1.0), (1, 1.0)] {
        for (y, sy) in [(2u32, -1.0), (3, 1.0)] {
            for (z, sz) in [(4u32, -1.0), (5, 1.0)] {
                // Counter-clockwise seen from outside iff the triple product of (x, y, z) is positive.
                if sx * sy * sz > 0.0 {
                    triangles.push([x, y, z]);
                } else {
                    triangles.push([x, z, y]);
                }
            }
        }
    }
    TriangleMesh::new(vertices, triangles).expect("an octahedron is a valid mesh")
}
