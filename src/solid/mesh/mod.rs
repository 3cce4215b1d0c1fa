//! Triangle meshes to rays: a [`TriangleMesh`] (read from OBJ, STL and PLY files by
//! [`crate::io::read_mesh`]), placed in a universe ([`MeshTransform`], [`Placement`]) and voxelized exactly
//! ([`TriangleMesh::to_rays`], or slab by slab by a [`MeshSource`]).
//!
//! **Placement.** A vertex `v` goes to voxel coordinates `s·v + t` ([`MeshTransform`]), computed in `f64` and then
//! rounded to the nearest multiple of 2^−16 voxel; every later step is exact integer arithmetic, so a result
//! is reproducible bit for bit. [`MeshTransform::fit`] scales and centres a mesh into the universe with a one-voxel
//! margin.
//!
//! **Inside rule.** A voxel is inside when its centre is: the column through the centre `(x+½, y+½)` is
//! crossed by the triangles whose projection covers it, each crossing counted `+1` where the triangle faces
//! down (`−z`: the column enters) and `−1` where it faces up, and a centre is inside when the sum of the
//! crossings below it is non-zero (non-zero winding rule; a centre exactly on the surface is inside).
//! **Ties.** Whether a column passing exactly through a vertex or along an edge is covered is decided by
//! simulation of simplicity: the column is treated as moved by an infinitesimal `(ε, ε²)`, which never lies on
//! an edge. Every point of the plane is then covered by the same number of up- and down-facing triangles of a
//! closed mesh, so watertight meshes never leak. Triangles whose projection has zero area are skipped (the
//! moved column never meets them). In effect a centre on the surface is inside where the column crosses the
//! surface there (closed along z), and where the column only touches the surface — a vertical face, a
//! silhouette edge or vertex — the moved column decides: a box `[lo, hi]` covers the centres in
//! `[lo, hi)` across x and y and `[lo, hi]` along z.
//!
//! **Open meshes.** [`TriangleMesh::open_edges`] counts edges not shared by exactly two triangles, on the
//! vertices' positions (a mesh that repeats a vertex per face, as many files do, is closed when its
//! positions close it); the rule above is still applied, column by column, so a hole can make some columns
//! leak (runs to the universe's face) or lose runs. Callers should warn (the CLI does).
//!
//! **Work:** `O(triangles + rays)` plus a radix sort of the crossings: each triangle visits only the columns
//! in its bounding box.
//!
//! **Labels.** [`label_runs`] voxelizes several meshes in one placement into runs of labels (mesh `i` is
//! label `i + 1`, the later mesh winning where they overlap), for a valued tree
//! ([`KTree::from_label_meshes`](crate::KTree::from_label_meshes)).
//!
//! **Slab by slab.** [`MeshSource`] gives the same runs one slab of columns at a time, from the triangles
//! its index lists for the slab, for building trees out of core without holding the whole ray set.
//!
//! ```
//! use ktree::io::read_mesh;
//! use ktree::solid::mesh::MeshTransform;
//! use std::path::Path;
//! let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/bunny_npm.obj");
//! let bunny = read_mesh(&path).unwrap();
//! let placement = MeshTransform::fit(&bunny, 6).unwrap(); // scaled and centred into a 64³ universe
//! let voxels = bunny.to_rays(6, &placement).unwrap();
//! assert_eq!(voxels.open_edges, bunny.open_edges());
//! assert!(voxels.rays.voxel_count() > 1000);
//! ```

mod labels;
mod placement;
mod voxelize;

pub use labels::{label_runs, LabelRuns};
pub use placement::{MeshTransform, Placement};
pub use voxelize::{MeshRays, MeshSource, MAX_LEVEL};

use std::collections::HashMap;

use smallvec::SmallVec;

use super::SolidError;
use crate::radix::radix_sort;

/// A triangle mesh: vertex positions and triangles as vertex indices, checked when made (finite vertices,
/// indices in range, at least one triangle).
///
/// ```
/// use ktree::solid::mesh::TriangleMesh;
/// let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// let tetrahedron = TriangleMesh::new(v.clone(), t).unwrap();
/// assert!((tetrahedron.signed_volume() - 1.0 / 6.0).abs() < 1e-12);
/// assert!(TriangleMesh::new(v, vec![[0, 1, 4]]).is_err()); // no vertex 4
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// A mesh of `vertices` and `triangles` (three indices into `vertices` each, counter-clockwise seen from
    /// outside).
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] when a vertex is not finite, a triangle refers to a missing vertex, or
    /// there is no triangle.
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self, SolidError> {
        let mesh = Self {
            vertices,
            triangles,
        };
        mesh.validate().map_err(SolidError::BadParameter)?;
        Ok(mesh)
    }

    /// The vertex positions.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// The triangles, three indices into [`TriangleMesh::vertices`] each.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    fn validate(&self) -> Result<(), String> {
        let n = self.vertices.len();
        if let Some((i, t)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
        {
            return Err(format!(
                "triangle {i} refers to vertex {t:?} but there are {n} vertices"
            ));
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !v.iter().all(|x| x.is_finite()))
        {
            return Err(format!("vertex {i} is not finite"));
        }
        if self.triangles.is_empty() {
            return Err("no triangle".into());
        }
        Ok(())
    }

    /// The axis-aligned bounding box `(lo, hi)`, `None` without vertices.
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.vertices.first()?;
        Some(self.vertices.iter().fold((first, first), |(lo, hi), v| {
            (
                std::array::from_fn(|a| lo[a].min(v[a])),
                std::array::from_fn(|a| hi[a].max(v[a])),
            )
        }))
    }

    fn corners(&self, t: &[u32; 3]) -> [[f64; 3]; 3] {
        t.map(|i| self.vertices[i as usize])
    }

    /// The signed volume enclosed (positive for outward orientation), by the divergence theorem.
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = self.corners(t);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// The total surface area.
    pub fn surface_area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = self.corners(t);
                let n = cross(sub(b, a), sub(c, a));
                dot(n, n).sqrt() / 2.0
            })
            .sum()
    }

    /// The number of edges not shared by exactly two triangles (an edge from a point to itself is none):
    /// 0 when the triangles close the mesh by their vertex indices; otherwise counted on the vertices'
    /// positions, vertices at the same position being one — the same within [`MERGE_TOLERANCE`] of the
    /// mesh's extent, so that the float noise of an exporter (`−2.7e−16` written for `0`) does not open a
    /// mesh whose every face has its own vertices.
    ///
    /// ```
    /// use ktree::solid::mesh::TriangleMesh;
    /// // Two triangles sharing an edge, each with its own copies of the shared corners.
    /// let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 1e-17], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    /// let square = TriangleMesh::new(v, vec![[0, 1, 2], [3, 5, 4]]).unwrap();
    /// assert_eq!(square.open_edges(), 4); // the diagonal is shared
    /// ```
    ///
    /// # Performance
    /// A radix sort of the edges; the positions are merged (a hash of cells, 8 looked in a vertex) only
    /// for a mesh that its indices leave open.
    pub fn open_edges(&self) -> usize {
        let n = self.vertices.len();
        match open_edges(&self.triangles, n, |v| v) {
            0 => 0,
            _ => {
                let at = self.merged_vertices();
                open_edges(&self.triangles, n, |v| at[v as usize])
            }
        }
    }

    /// For each vertex, the first vertex at its position (within [`MERGE_TOLERANCE`] of the extent, in
    /// every coordinate).
    fn merged_vertices(&self) -> Vec<u32> {
        let Some((lo, hi)) = self.bounds() else {
            return Vec::new();
        };
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        let tolerance = (extent * MERGE_TOLERANCE).max(f64::MIN_POSITIVE);
        // Cells twice the tolerance wide: a position within the tolerance of another lies in its cell or
        // in the neighbour on the near side along each axis, so eight cells are looked in.
        let width = 2.0 * tolerance;
        let mut cells: HashMap<[i64; 3], SmallVec<[u32; 1]>> = HashMap::new();
        let mut first = Vec::with_capacity(self.vertices.len());
        for (i, p) in self.vertices.iter().enumerate() {
            let at = std::array::from_fn::<f64, 3, _>(|a| (p[a] - lo[a]) / width);
            let cell = at.map(|c| c.floor() as i64);
            let near =
                std::array::from_fn::<i64, 3, _>(
                    |a| {
                        if at[a] - at[a].floor() < 0.5 {
                            -1
                        } else {
                            1
                        }
                    },
                );
            let same = |q: u32| {
                let q = self.vertices[q as usize];
                (0..3).all(|a| (q[a] - p[a]).abs() <= tolerance)
            };
            let found = (0..8)
                .filter_map(|corner: usize| {
                    let c = std::array::from_fn(|a| cell[a] + near[a] * ((corner >> a) & 1) as i64);
                    cells.get(&c)?.iter().copied().find(|&q| same(q))
                })
                .min();
            first.push(found.unwrap_or_else(|| {
                cells.entry(cell).or_default().push(i as u32);
                i as u32
            }));
        }
        first
    }
}

/// The edges of `triangles` not used exactly twice, vertex `v` taken as vertex `at(v)` (below
/// `vertices`); an edge from a vertex to itself is none.
fn open_edges(triangles: &[[u32; 3]], vertices: usize, at: impl Fn(u32) -> u32) -> usize {
    // Every edge as one sortable key (lower vertex, higher vertex); equal edges end up side by side.
    let bits = u64::BITS - (vertices as u64).leading_zeros();
    let mut edges: Vec<u64> = triangles
        .iter()
        .flat_map(|t| {
            let at = &at;
            (0..3).filter_map(move |k| {
                let (a, b) = (u64::from(at(t[k])), u64::from(at(t[(k + 1) % 3])));
                (a != b).then(|| a.min(b) << bits | a.max(b))
            })
        })
        .collect();
    radix_sort(&mut edges, 2 * bits, &mut Vec::new());
    edges
        .chunk_by(|a, b| a == b)
        .filter(|uses| uses.len() != 2)
        .count()
}

/// Positions of a mesh closer than this fraction of its extent (its bounding box's largest side), in every
/// coordinate, are one position for [`TriangleMesh::open_edges`]: 2^−40, far below what a voxel resolves at
/// any level ([`MAX_LEVEL`] and 2^−16 of a voxel make 2^−36), far above the noise of `f64` (2^−52).
pub const MERGE_TOLERANCE: f64 = 1.0 / (1u64 << 40) as f64;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::TriangleMesh;
    use std::collections::BTreeMap;

    /// The count of edges not used exactly twice equals a plain tally in a map, on meshes of random
    /// triangles over few vertices (so edges are shared once, twice, or more, and some join a vertex to
    /// itself).
    #[test]
    fn open_edges_equal_a_tally() {
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n) as u32
        };
        for vertices in [3u32, 4, 7, 40, 1000] {
            for triangles in [1usize, 2, 5, 50, 500] {
                let corners = (0..vertices).map(|i| [f64::from(i), 0.0, 0.0]).collect();
                let tris: Vec<[u32; 3]> = (0..triangles)
                    .map(|_| [0; 3].map(|_| next(u64::from(vertices))))
                    .collect();
                let mut tally = BTreeMap::new();
                for t in &tris {
                    for k in 0..3 {
                        let (a, b) = (t[k], t[(k + 1) % 3]);
                        if a != b {
                            *tally.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                        }
                    }
                }
                let want = tally.values().filter(|&&n| n != 2).count();
                let mesh = TriangleMesh::new(corners, tris).unwrap();
                assert_eq!(
                    mesh.open_edges(),
                    want,
                    "{vertices} vertices, {triangles} triangles"
                );
            }
        }
    }
    /// A mesh whose vertices are repeated, each triangle taking either copy of its corners (−0 and +0
    /// copies of 0 alike), has the open edges of the mesh without repeats (none when the copies happen to
    /// close it by their indices).
    #[test]
    fn repeated_vertices_are_one_position() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n) as u32
        };
        for vertices in [3u32, 5, 40] {
            for triangles in [1usize, 4, 60] {
                let corners: Vec<[f64; 3]> =
                    (0..vertices).map(|i| [f64::from(i), 0.0, 1.0]).collect();
                let tris: Vec<[u32; 3]> = (0..triangles)
                    .map(|_| [0; 3].map(|_| next(u64::from(vertices))))
                    .collect();
                let plain = TriangleMesh::new(corners.clone(), tris.clone()).unwrap();
                let copies = corners.iter().map(|p| [p[0], -0.0, p[2]]);
                let doubled: Vec<[f64; 3]> = corners.iter().copied().chain(copies).collect();
                let repeated: Vec<[u32; 3]> = tris
                    .iter()
                    .map(|t| t.map(|v| v + vertices * next(2)))
                    .collect();
                // Closed by its indices, a mesh is closed; otherwise its positions decide.
                let mut uses = BTreeMap::new();
                for t in &repeated {
                    for k in 0..3 {
                        let (a, b): (u32, u32) = (t[k], t[(k + 1) % 3]);
                        if a != b {
                            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                        }
                    }
                }
                let closed = uses.values().all(|&n| n == 2);
                let mesh = TriangleMesh::new(doubled, repeated).unwrap();
                let want = if closed { 0 } else { plain.open_edges() };
                assert_eq!(mesh.open_edges(), want);
            }
        }
    }
}
