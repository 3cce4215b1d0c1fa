//! The boundary of an octree as a closed, outward-oriented triangle mesh.
//!
//! **Faces.** The tree is swept across its first axis (`x`): at each `x` where it changes, its
//! cross-section (the slab one voxel thick there) is read as bands, stretches of `y` over
//! which the runs of full voxels along `z` stay the same, one walk through the nodes the plane crosses. A
//! large cell is one band, not a column per voxel, so the work follows the nodes, not the volume. Between
//! two slabs, the stretches where exactly one of them is full are the boundary of the plane `x = X`;
//! between neighbouring bands of a slab, those of a plane `y = Y`; the runs' ends are the boundary of the
//! planes `z = Z`. Each plane and orientation's boundary is merged into rectangles: its maximal intervals
//! in each row, an interval carried on as one rectangle through the following rows while it stays the
//! same (rows along `y` for the planes `x = X`; the slabs themselves for the others, whose rectangles
//! stay open while the sweep passes them).
//!
//! **No cracks.** A rectangle's edge may have other rectangles' corners on it (a T-junction). Every corner
//! is recorded on the two lattice lines of its edges; each rectangle edge then takes into its boundary
//! every corner recorded on its stretch of line that belongs to the same sheet of the surface (below).
//! Two rectangles meeting along an edge so split it at the same points, and every boundary segment is
//! shared by exactly two triangles. A rectangle with no such extra point is two triangles; one with extra
//! points is a fan around its centre.
//!
//! **2-manifold.** Where solids touch only along an edge or at a corner, the surface would pinch. A
//! vertex is a lattice point *and* a sheet: the eight voxels around the point give its link (the unit faces
//! at the point that are boundary faces, linked across each of the six half-axes from the point: the two
//! boundary faces there, or, where four are, the two that bound the same full voxel), and each connected
//! part of the link is its own vertex. A segment of an edge line with four boundary faces around it (two
//! solids touching along it) gets a midpoint per touching solid, so that two sheets sharing both
//! endpoints still have distinct edges. Solids touching along an edge or at a corner are thus separate, as
//! in 6-connectivity: the surface's Euler characteristic is twice the solid's, counted with face-adjacent
//! voxels connected. (One configuration cannot be so: where only two opposite voxels of the eight around
//! a point are empty, a 2-manifold surface is two sheets there, so the six full voxels are joined through
//! the point.)
//!
//! Coordinates are in voxels (the universe's corner at 0); [`SurfaceMesh::placed`] maps them to world
//! units.
//!
//! **Work:** no point query and no global sort. Every corner lies in some plane `x = X`, and the sweep
//! meets it there: the step's corners are radix-sorted into lattice points, whose eight voxels are read
//! from the two slabs' bands around them, and the edges in that plane find their T-junctions among the
//! step's points. The edges along `x`, of rectangles the sweep carries, gather theirs at each step they
//! pass. A rectangle is made into triangles at the step of its last corners, so besides the mesh only two
//! slabs and the open rectangles are held. Time and peak memory against OpenVDB's `volumeToMesh` in
//! `results/performance/export.md`.
//!
//! ```
//! use ktree::export::surface::boundary_mesh;
//! use ktree::KTree;
//! // A 2 × 2 × 2 block of voxels: six faces, each one square of two triangles.
//! let block = KTree::<3>::full(1).unwrap();
//! let mesh = boundary_mesh(&block);
//! assert_eq!((mesh.vertices.len(), mesh.triangles.len()), (8, 12));
//! assert_eq!(mesh.volume(), 8.0);
//! ```

mod section;
mod sweep;
mod values;

pub use values::{try_value_boundary_mesh, value_boundary_mesh, ValueMesh, ValueSurface};

use std::convert::Infallible;
use std::sync::OnceLock;

use crate::tree::storage::{infallible, TreeStorage};
#[cfg(test)]
use crate::tree::KTree;

use super::{ExportError, Frame};

/// A triangle mesh: vertex positions and triangles (indices into the vertices, counter-clockwise seen
/// from outside).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl SurfaceMesh {
    /// The mesh in world units: each vertex `v` goes to `origin + voxel_size · v`.
    ///
    /// ```
    /// use ktree::export::{surface::boundary_mesh, Frame};
    /// let mesh = boundary_mesh(&ktree::KTree::<3>::full(1).unwrap());
    /// let world = mesh.placed(&Frame { voxel_size: 0.5, origin: [1.0, 0.0, 0.0] });
    /// assert_eq!(world.volume(), 1.0);
    /// ```
    pub fn placed(&self, frame: &Frame) -> SurfaceMesh {
        SurfaceMesh {
            vertices: self
                .vertices
                .iter()
                .map(|v| std::array::from_fn(|a| frame.origin[a] + frame.voxel_size * v[a]))
                .collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The enclosed volume by the divergence theorem: the sum of the signed volumes of the tetrahedra
    /// from the origin to each triangle.
    pub fn volume(&self) -> f64 {
        let v = |i: u32| self.vertices[i as usize];
        self.triangles
            .iter()
            .map(|t| {
                let (a, b, c) = (v(t[0]), v(t[1]), v(t[2]));
                a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0])
            })
            .sum::<f64>()
            / 6.0
    }

    /// The vertices' bounding box `(min, max)`, `None` for an empty mesh.
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.vertices.first()?;
        Some(self.vertices.iter().fold((first, first), |(lo, hi), v| {
            (
                std::array::from_fn(|a| lo[a].min(v[a])),
                std::array::from_fn(|a| hi[a].max(v[a])),
            )
        }))
    }
}

/// The other two axes of `a`, in cyclic order (so that `e_b × e_c = e_a`).
#[inline]
fn others(a: usize) -> (usize, usize) {
    [(1, 2), (2, 0), (0, 1)][a]
}

/// Unit face at a lattice point: plane axis `a`, quadrant `q` (bit 0: on the upper side of the point along
/// `b`, bit 1: along `c`). Index `4a + q`.
fn face_index(a: usize, q: usize) -> usize {
    4 * a + q
}

/// The two octants (bit `i` set: on the upper side along axis `i`) on either side of unit face `f`.
fn face_octants(f: usize) -> (usize, usize) {
    let (a, q) = (f / 4, f % 4);
    let (b, c) = others(a);
    let lo = (q & 1) << b | (q >> 1 & 1) << c;
    (lo, lo | 1 << a)
}

/// For each occupancy of the eight voxels around a lattice point (bit `o` set: octant `o` full) and each
/// unit face at the point: which part of the point's link the face is in (`u8::MAX` when not a boundary
/// face).
fn link_parts() -> &'static [[u8; 12]; 256] {
    static TABLE: OnceLock<[[u8; 12]; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut table = [[u8::MAX; 12]; 256];
        for (mask, row) in table.iter_mut().enumerate() {
            let full = |o: usize| mask >> o & 1 == 1;
            let boundary = |f: usize| {
                let (lo, hi) = face_octants(f);
                full(lo) != full(hi)
            };
            let mut parent: [usize; 12] = std::array::from_fn(|i| i);
            fn find(p: &mut [usize; 12], mut i: usize) -> usize {
                while p[i] != i {
                    p[i] = p[p[i]];
                    i = p[i];
                }
                i
            }
            for d in 0..3 {
                for sigma in 0..2usize {
                    // The unit faces containing the half-axis (d, sigma).
                    let faces: Vec<usize> = (0..12)
                        .filter(|&f| {
                            let (a, q) = (f / 4, f % 4);
                            if a == d {
                                return false;
                            }
                            let (b, _) = others(a);
                            let side = if b == d { q & 1 } else { q >> 1 & 1 };
                            side == sigma && boundary(f)
                        })
                        .collect();
                    let pairs: Vec<(usize, usize)> = match faces.len() {
                        2 => vec![(faces[0], faces[1])],
                        4 => {
                            // Pair the faces bounding the same full octant.
                            let mut out = Vec::new();
                            for o in (0..8).filter(|&o| full(o) && (o >> d & 1) == sigma) {
                                let around: Vec<usize> = faces
                                    .iter()
                                    .copied()
                                    .filter(|&f| {
                                        let (lo, hi) = face_octants(f);
                                        lo == o || hi == o
                                    })
                                    .collect();
                                out.push((around[0], around[1]));
                            }
                            out
                        }
                        _ => Vec::new(),
                    };
                    for (x, y) in pairs {
                        let (rx, ry) = (find(&mut parent, x), find(&mut parent, y));
                        parent[rx] = ry;
                    }
                }
            }
            let mut label = [u8::MAX; 12];
            let mut next = 0u8;
            for f in (0..12).filter(|&f| boundary(f)) {
                let r = find(&mut parent, f);
                if label[r] == u8::MAX {
                    label[r] = next;
                    next += 1;
                }
                row[f] = label[r];
            }
        }
        table
    })
}

/// Whether the boundary squares of a plane are merged into rectangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Merge {
    /// Maximal intervals in each row, carried on while they stay the same.
    Rectangles,
    /// Every unit face its own square.
    None,
}

/// A rectangle of boundary in a plane.
#[derive(Debug, Clone, Copy)]
struct Rect {
    a: usize,
    coord: u32,
    upper: bool,
    /// `[b0, b1, c0, c1]`.
    r: [u32; 4],
}

impl Rect {
    /// The corners counter-clockwise in `(b, c)`, from `(b0, c0)`; the rectangle covers quadrant
    /// [`CORNER_QUADRANTS`]`[k]` of corner `k`.
    #[inline]
    fn corners(&self) -> [[u32; 3]; 4] {
        let (b, c) = others(self.a);
        let [b0, b1, c0, c1] = self.r;
        let mut points = [[self.coord; 3]; 4];
        for (p, (bv, cv)) in points
            .iter_mut()
            .zip([(b0, c0), (b1, c0), (b1, c1), (b0, c1)])
        {
            p[b] = bv;
            p[c] = cv;
        }
        points
    }
}

/// The quadrant a rectangle covers at each of its corners, counter-clockwise from `(b0, c0)` (see
/// [`Rect::corners`]).
const CORNER_QUADRANTS: [usize; 4] = [0b11, 0b10, 0b00, 0b01];

/// The vertex of link part `part` at a point whose corners have link parts `parts` (bit set) and whose
/// first part's vertex is `first_vertex`: the parts' vertices follow in order of part.
fn vertex_of(first_vertex: u32, parts: u8, part: u8) -> u32 {
    debug_assert!(parts >> part & 1 == 1);
    first_vertex + (parts & ((1u8 << part) - 1)).count_ones()
}

/// The link part, at a point of occupancy `mask`, of the unit face `(a, q)`, which must be a boundary face.
fn part_of(mask: u8, a: usize, q: usize) -> u8 {
    let part = link_parts()[mask as usize][face_index(a, q)];
    debug_assert!(part < 4, "a rectangle on a non-boundary face");
    part
}

/// The boundary of `tree` as a closed, outward-oriented triangle mesh in voxel coordinates (see the
/// module's documentation for how it is made crack-free and 2-manifold). Empty for an empty tree. (Any
/// storage, a mapped file among them: [`try_boundary_mesh`].)
///
/// # Panics
/// If the mesh would need 2^32 or more vertices or rectangle corners (its indices are 32-bit).
pub fn boundary_mesh<T: TreeStorage<3, Error = Infallible>>(tree: &T) -> SurfaceMesh {
    infallible(try_boundary_mesh(tree))
}

/// [`boundary_mesh`] over any storage: the tree's cross-sections are read as the sweep meets them.
///
/// ```
/// use ktree::export::surface::{boundary_mesh, try_boundary_mesh};
/// use ktree::io::{write_ktree, KtreeView, MappedTree};
/// let block = ktree::KTree::<3>::full(1).unwrap();
/// let mut bytes = Vec::new();
/// write_ktree(&mut bytes, &block).unwrap();
/// let view = KtreeView::from_bytes(bytes, "block.ktree").unwrap();
/// let mapped = MappedTree::<3>::new(&view).unwrap();
/// assert_eq!(try_boundary_mesh(&mapped).unwrap(), boundary_mesh(&block));
/// ```
///
/// # Errors
/// The storage's read error.
///
/// # Panics
/// As [`boundary_mesh`].
pub fn try_boundary_mesh<T: TreeStorage<3>>(tree: &T) -> Result<SurfaceMesh, T::Error> {
    sweep::sweep(tree, Merge::Rectangles)
}

/// A smooth surface over the voxels of `tree`, for display (not for round trips: voxelizing it does not
/// give the tree back): naive surface nets. The boundary is made one unit face at a time (two triangles
/// a face, with the vertices and pinch splits of [`boundary_mesh`], so it is closed and 2-manifold), then
/// relaxed `iterations` times: each vertex moves towards the mean of its neighbours and then away from it
/// a little more (Taubin's λ = 0.5, μ = −0.53, which keeps the volume where plain averaging shrinks it),
/// kept within half a voxel of where it started on every axis (its cell of the dual grid). In voxel coordinates, as
/// [`boundary_mesh`].
///
/// ```
/// use ktree::export::surface::smooth_mesh;
/// let u = 16;
/// let ball = ktree::KTree::from_rays(&ktree::rays::ball_rays::<3>(4, [u, u, u], u).unwrap());
/// let mesh = smooth_mesh(&ball, 10).unwrap();
/// let voxels = ball.voxel_count() as f64;
/// assert!((mesh.volume() - voxels).abs() < 0.01 * voxels);
/// // A unit face at a time: the full universe at L = 21 has far too many.
/// assert!(smooth_mesh(&ktree::KTree::<3>::full(21).unwrap(), 10).is_err());
/// ```
///
/// # Errors
/// [`ExportError::TooLarge`] when the boundary has more than [`SMOOTH_FACE_LIMIT`] unit faces (counted
/// before anything is made); [`ExportError::Storage`] if a read of the tree fails.
///
/// # Panics
/// As [`boundary_mesh`].
pub fn smooth_mesh<T: TreeStorage<3>>(
    tree: &T,
    iterations: usize,
) -> Result<SurfaceMesh, ExportError> {
    let storage = |e: T::Error| ExportError::Storage(e.into());
    let faces = sweep::unit_faces(tree).map_err(storage)?;
    if faces > u128::from(SMOOTH_FACE_LIMIT) {
        return Err(ExportError::TooLarge {
            faces,
            limit: SMOOTH_FACE_LIMIT,
        });
    }
    let mut mesh = sweep::sweep(tree, Merge::None).map_err(storage)?;
    let start = mesh.vertices.clone();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertices.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            neighbours[t[k] as usize].push(t[(k + 1) % 3]);
        }
    }
    // Taubin's two steps, shrinking then inflating, so that the surface keeps its volume.
    for step in (0..iterations).flat_map(|_| [0.5, -0.53]) {
        let now = mesh.vertices.clone();
        for (v, around) in neighbours.iter().enumerate() {
            let n = around.len() as f64;
            mesh.vertices[v] = std::array::from_fn(|a| {
                let mean = around.iter().map(|&w| now[w as usize][a]).sum::<f64>() / n;
                let moved = now[v][a] + step * (mean - now[v][a]);
                moved.clamp(start[v][a] - 0.5, start[v][a] + 0.5)
            });
        }
    }
    Ok(mesh)
}

/// The most unit faces [`smooth_mesh`] makes a surface of (2^26: some 10 GiB of mesh and work space).
pub const SMOOTH_FACE_LIMIT: u64 = 1 << 26;

/// Whether the segment of the line along `d` that starts at the lattice point of occupancy `m` (and goes
/// up `d`) has two solids touching along it: of the four voxels around the line just past the point,
/// exactly two are full and they are diagonal (read at the segment's lower end, so both rectangles along
/// the segment decide alike).
fn pinched(m: u8, d: usize) -> bool {
    let (x, y) = match d {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let full = |i: usize| m >> (1 << d | (i & 1) << x | (i >> 1) << y) & 1 == 1;
    let f = [full(0), full(1), full(2), full(3)];
    f == [true, false, false, true] || f == [false, true, true, false]
}

/// A tree of `blocks` aligned blocks of every size at random places (from `lcg`), at `level` (at most
/// 7), each third one cut out when `cut`.
#[cfg(test)]
fn random_blocks(level: u32, lcg: &mut crate::testing::Lcg, blocks: usize, cut: bool) -> KTree<3> {
    let side = 1usize << level;
    let mut dense = vec![false; side * side * side];
    for block in 0..blocks {
        let state = lcg.next_u64();
        let log_side = (state >> 60) as usize % level as usize;
        let at = [state >> 8, state >> 20, state >> 32]
            .map(|c| ((c as usize % side) >> log_side) << log_side);
        for z in at[2]..at[2] + (1 << log_side) {
            for y in at[1]..at[1] + (1 << log_side) {
                for x in at[0]..at[0] + (1 << log_side) {
                    dense[x + side * (y + side * z)] = !(cut && block % 3 == 2);
                }
            }
        }
    }
    KTree::from_dense(level, &dense).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_link_of_an_edge_contact_has_two_parts() {
        // Octants 0 (−,−,−) and 3 (+,+,−) full: two solids touching along the z half-axis below the point.
        let row = link_parts()[0b0000_1001];
        let parts: std::collections::BTreeSet<u8> =
            row.iter().copied().filter(|&p| p != u8::MAX).collect();
        assert_eq!(parts.len(), 2);
        // One full octant: one part of three faces.
        assert_eq!(link_parts()[1].iter().filter(|&&p| p == 0).count(), 3);
    }

    #[test]
    fn a_link_has_at_most_four_parts() {
        // Each part is a cycle of at least three unit faces: at most four parts of the twelve faces, as
        // many as a point's vertex slots. The checkerboard of four full octants has all four.
        let most = link_parts()
            .iter()
            .flat_map(|row| row.iter().copied().filter(|&p| p != u8::MAX))
            .max();
        assert_eq!(most, Some(3));
        let checkerboard = link_parts()[0b1001_0110];
        assert!(checkerboard.iter().all(|&p| p < 4));
        assert_eq!(checkerboard.iter().max(), Some(&3));
    }
}
