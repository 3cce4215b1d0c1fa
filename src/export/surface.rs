//! The boundary of an octree as a closed, outward-oriented triangle mesh.
//!
//! **Faces.** Each full leaf asks, for each of its six faces, which leaves lie across it
//! ([`Neighbours::face_leaves`]); the empty ones (and the universe's boundary) are where the surface is.
//! The boundary squares of each axis-aligned plane and orientation are merged into rectangles: a sweep
//! across the plane cuts it into strips, each strip's covered stretch into maximal intervals, and an
//! interval goes on as one rectangle through the following strips while it stays the same.
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
//! **Work:** a face query per full leaf face (`O(L)` lookups each), eight voxel lookups per lattice vertex,
//! and hash maps of the vertices and of the corners on each lattice line, all held at once (about 270 bytes
//! a vertex of the result; `results/performance/export.md`).
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

use std::collections::{BTreeMap, HashMap};
use std::sync::OnceLock;

use crate::display::neighbours::{face_neighbour_cell, Neighbours};
use crate::space::Cell;
use crate::tree::{KTree, NodeState};

use super::Frame;

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
fn others(a: usize) -> (usize, usize) {
    ((a + 1) % 3, (a + 2) % 3)
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

/// Voxel states near lattice points, read through one [`Neighbours`].
struct Lattice<'t> {
    near: Neighbours<'t, 3>,
    side: u64,
    level: u32,
    masks: HashMap<[u32; 3], u8>,
}

impl<'t> Lattice<'t> {
    fn new(tree: &'t KTree<3>) -> Self {
        Self {
            near: Neighbours::new(tree),
            side: tree.universe().side(),
            level: tree.level(),
            masks: HashMap::new(),
        }
    }

    /// Whether the voxel at `v` (possibly outside the universe, which is empty) is full.
    fn full(&mut self, v: [i64; 3]) -> bool {
        if v.iter().any(|&x| x < 0 || x as u64 >= self.side) {
            return false;
        }
        let cell = Cell {
            origin: v.map(|x| x as u32),
            level: self.level,
            log_side: 0,
        };
        self.near.locate(&cell).state() == NodeState::Full
    }

    /// The occupancy of the eight voxels around lattice point `p` (bit `o`: octant `o`).
    fn mask(&mut self, p: [u32; 3]) -> u8 {
        if let Some(&m) = self.masks.get(&p) {
            return m;
        }
        let mut m = 0u8;
        for o in 0..8 {
            let v = std::array::from_fn(|a| i64::from(p[a]) - 1 + (o >> a & 1) as i64);
            if self.full(v) {
                m |= 1 << o;
            }
        }
        self.masks.insert(p, m);
        m
    }

    /// The link part at `p` of the unit face `(a, q)`.
    fn part(&mut self, p: [u32; 3], a: usize, q: usize) -> u8 {
        let m = self.mask(p);
        let part = link_parts()[m as usize][face_index(a, q)];
        debug_assert_ne!(part, u8::MAX, "a rectangle at {p:?} on a non-boundary face");
        part
    }
}

/// A plane of boundary: its axis, its coordinate on that axis, and whether the outward normal points up
/// the axis.
type PlaneKey = (usize, u32, bool);

/// The boundary squares of `tree`, by plane: `(b, c, side)` in the plane's axes (see [`others`]).
fn boundary_squares(tree: &KTree<3>) -> BTreeMap<PlaneKey, Vec<[u32; 3]>> {
    let side = tree.universe().side();
    let mut near = Neighbours::new(tree);
    let mut planes: BTreeMap<PlaneKey, Vec<[u32; 3]>> = BTreeMap::new();
    for cell in tree.full_cells() {
        let s = cell.side() as u32;
        for a in 0..3 {
            let (b, c) = others(a);
            for upper in [false, true] {
                let coord = cell.origin[a] + if upper { s } else { 0 };
                let squares = planes.entry((a, coord, upper)).or_default();
                match face_neighbour_cell(&cell, a, upper, side) {
                    None => squares.push([cell.origin[b], cell.origin[c], s]),
                    Some(n) => near.face_leaves(&n, a, !upper, |leaf, state| {
                        if state == NodeState::Empty {
                            squares.push([leaf.origin[b], leaf.origin[c], leaf.side() as u32]);
                        }
                    }),
                }
            }
        }
    }
    planes.retain(|_, v| !v.is_empty());
    planes
}

/// Disjoint squares `(b, c, side)` merged into rectangles `[b0, b1, c0, c1]` covering the same region:
/// strips across `c` between consecutive square edges, maximal intervals along `b` in each strip, an
/// interval carried on through the following strips while it is the same.
fn merge_rectangles(mut squares: Vec<[u32; 3]>) -> Vec<[u32; 4]> {
    squares.sort_unstable_by_key(|s| (s[1], s[0]));
    let mut cuts: Vec<u32> = squares.iter().flat_map(|s| [s[1], s[1] + s[2]]).collect();
    cuts.sort_unstable();
    cuts.dedup();
    let mut out = Vec::new();
    // Open rectangles: interval (b0, b1) → c0.
    let mut open: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    let mut active: Vec<[u32; 3]> = Vec::new();
    let mut next = 0;
    for w in cuts.windows(2) {
        let c = w[0];
        active.retain(|s| s[1] + s[2] > c);
        while next < squares.len() && squares[next][1] == c {
            active.push(squares[next]);
            next += 1;
        }
        let mut spans: Vec<(u32, u32)> = active.iter().map(|s| (s[0], s[0] + s[2])).collect();
        spans.sort_unstable();
        let mut intervals: Vec<(u32, u32)> = Vec::new();
        for (b0, b1) in spans {
            match intervals.last_mut() {
                Some(last) if last.1 == b0 => last.1 = b1,
                _ => intervals.push((b0, b1)),
            }
        }
        let mut still: BTreeMap<(u32, u32), u32> = BTreeMap::new();
        for iv in intervals {
            let start = open.remove(&iv).unwrap_or(c);
            still.insert(iv, start);
        }
        for ((b0, b1), c0) in std::mem::take(&mut open) {
            out.push([b0, b1, c0, c]);
        }
        open = still;
    }
    let last = cuts.last().copied().unwrap_or(0);
    for ((b0, b1), c0) in open {
        out.push([b0, b1, c0, last]);
    }
    out.sort_unstable_by_key(|r| (r[2], r[0]));
    out
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
    /// The lattice point at `(b, c)` in the rectangle's plane.
    fn point(&self, bv: u32, cv: u32) -> [u32; 3] {
        let (b, c) = others(self.a);
        let mut p = [0; 3];
        p[self.a] = self.coord;
        p[b] = bv;
        p[c] = cv;
        p
    }

    /// The corners counter-clockwise in `(b, c)`, each with the quadrant the rectangle covers there.
    fn corners(&self) -> [([u32; 3], usize); 4] {
        let [b0, b1, c0, c1] = self.r;
        [
            (self.point(b0, c0), 0b11),
            (self.point(b1, c0), 0b10),
            (self.point(b1, c1), 0b00),
            (self.point(b0, c1), 0b01),
        ]
    }
}

/// A line of the lattice: its direction and the point's coordinates on the other two axes (in axis order).
type LineKey = (usize, u32, u32);

fn line_of(d: usize, p: [u32; 3]) -> (LineKey, u32) {
    let rest: Vec<u32> = (0..3).filter(|&x| x != d).map(|x| p[x]).collect();
    ((d, rest[0], rest[1]), p[d])
}

/// The boundary of `tree` as a closed, outward-oriented triangle mesh in voxel coordinates (see the
/// module's documentation for how it is made crack-free and 2-manifold). Empty for an empty tree.
pub fn boundary_mesh(tree: &KTree<3>) -> SurfaceMesh {
    let rects: Vec<Rect> = boundary_squares(tree)
        .into_iter()
        .flat_map(|((a, coord, upper), squares)| {
            merge_rectangles(squares)
                .into_iter()
                .map(move |r| Rect { a, coord, upper, r })
        })
        .collect();
    let mut lattice = Lattice::new(tree);
    // Every corner on the lines of its two edges, with its link part.
    let mut lines: HashMap<LineKey, Vec<(u32, u8)>> = HashMap::new();
    for rect in &rects {
        let (b, c) = others(rect.a);
        for (p, q) in rect.corners() {
            let part = lattice.part(p, rect.a, q);
            for d in [b, c] {
                let (key, t) = line_of(d, p);
                lines.entry(key).or_default().push((t, part));
            }
        }
    }
    for v in lines.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    let mut mesh = SurfaceMesh::default();
    // Vertices by doubled position and tag (link part, or 16 + full octant for a midpoint).
    let mut ids: HashMap<([u64; 3], u8), u32> = HashMap::new();
    let mut vertex = |mesh: &mut SurfaceMesh, doubled: [u64; 3], tag: u8| -> u32 {
        *ids.entry((doubled, tag)).or_insert_with(|| {
            mesh.vertices.push(doubled.map(|x| x as f64 / 2.0));
            (mesh.vertices.len() - 1) as u32
        })
    };
    let double = |p: [u32; 3]| p.map(|x| 2 * u64::from(x));
    let mut ring: Vec<u32> = Vec::new();
    for rect in &rects {
        let (b, c) = others(rect.a);
        let corners = rect.corners();
        ring.clear();
        for k in 0..4 {
            let (p, q) = corners[k];
            let (end, _) = corners[(k + 1) % 4];
            let part = lattice.part(p, rect.a, q);
            ring.push(vertex(&mut mesh, double(p), part));
            // The edge from p to end: along b for k = 0, 2, along c for k = 1, 3.
            let (d, e) = if k % 2 == 0 { (b, c) } else { (c, b) };
            // The rectangle's side of the line along e, as the quadrant bit for e.
            let e_side = match k {
                0 | 3 => 1,
                _ => 0,
            };
            let quadrant = |d_side: usize| {
                if d == b {
                    d_side | e_side << 1
                } else {
                    e_side | d_side << 1
                }
            };
            let (key, t0) = line_of(d, p);
            let t1 = end[d];
            let (lo, hi) = (t0.min(t1), t0.max(t1));
            let mut stops: Vec<(u32, u8)> = Vec::new();
            if let Some(on_line) = lines.get(&key) {
                let from = on_line.partition_point(|&(t, _)| t <= lo);
                for &(t, part) in on_line[from..].iter().take_while(|&&(t, _)| t < hi) {
                    let mut x = p;
                    x[d] = t;
                    if lattice.part(x, rect.a, quadrant(1)) == part {
                        stops.push((t, part));
                    }
                }
            }
            stops.dedup_by_key(|s| s.0);
            if t1 < t0 {
                stops.reverse();
            }
            // The full octant the rectangle bounds, as bits on the axes across the line.
            let full_side = usize::from(!rect.upper);
            let octant = (full_side << rect.a | e_side << e) as u8;
            let mut prev = t0;
            for (t, part) in stops.into_iter().chain(std::iter::once((t1, u8::MAX))) {
                if pinched(&mut lattice, p, d, prev.min(t)) {
                    let mut m = double(p);
                    m[d] = u64::from(prev) + u64::from(t);
                    ring.push(vertex(&mut mesh, m, 16 + octant));
                }
                if part != u8::MAX {
                    let mut x = p;
                    x[d] = t;
                    ring.push(vertex(&mut mesh, double(x), part));
                }
                prev = t;
            }
        }
        if !rect.upper {
            ring.reverse();
        }
        if ring.len() == 4 {
            mesh.triangles.push([ring[0], ring[1], ring[2]]);
            mesh.triangles.push([ring[0], ring[2], ring[3]]);
        } else {
            let [b0, b1, c0, c1] = rect.r;
            let mut centre = [0u64; 3];
            centre[rect.a] = 2 * u64::from(rect.coord);
            centre[b] = u64::from(b0) + u64::from(b1);
            centre[c] = u64::from(c0) + u64::from(c1);
            mesh.vertices.push(centre.map(|x| x as f64 / 2.0));
            let centre = (mesh.vertices.len() - 1) as u32;
            for j in 0..ring.len() {
                mesh.triangles
                    .push([centre, ring[j], ring[(j + 1) % ring.len()]]);
            }
        }
    }
    mesh
}

/// Whether the segment from `lo` of the line along `d` through `p` has two solids touching along it: of
/// the four voxels around the line just past `lo`, exactly two are full and they are diagonal (read from
/// the occupancy around the lattice point at `lo`, so both rectangles along the segment decide alike).
fn pinched(lattice: &mut Lattice<'_>, p: [u32; 3], d: usize, lo: u32) -> bool {
    let mut at = p;
    at[d] = lo;
    let m = lattice.mask(at);
    let (x, y) = match d {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let full = |i: usize| m >> (1 << d | (i & 1) << x | (i >> 1) << y) & 1 == 1;
    let f = [full(0), full(1), full(2), full(3)];
    f == [true, false, false, true] || f == [false, true, true, false]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangles_cover_the_squares_once() {
        // An L of three unit squares and a 2 × 2 square beside it.
        let squares = vec![[0, 0, 1], [1, 0, 1], [0, 1, 1], [2, 0, 2]];
        let rects = merge_rectangles(squares);
        let area: u32 = rects.iter().map(|r| (r[1] - r[0]) * (r[3] - r[2])).sum();
        assert_eq!(area, 7);
        assert!(rects.contains(&[0, 4, 0, 1]), "{rects:?}");
    }

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
}
