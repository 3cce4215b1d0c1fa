//! The boundary of an octree as a closed, outward-oriented triangle mesh.
//!
//! **Faces.** One walk over the tree meets every pair of face-adjacent leaves (as octree dual contouring
//! does: the children across each partial node's inner faces, then the children along each such face, a
//! leaf standing for its own children); a full leaf against an empty one (or the outside of the universe)
//! bounds the object by the face of the smaller. The boundary squares of each axis-aligned plane and orientation are merged into rectangles: a sweep
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
//! **Work:** no face query, and no hash map but for the rare midpoints. The walk above visits each leaf a
//! bounded number of times; the squares are radix-sorted by plane; the rectangles' corners are radix-sorted
//! once by their Morton key into distinct lattice points, and everything the mesh needs of a corner is then
//! worked out point by point in that order and written at the corner's place, so the final pass over the
//! rectangles reads memory in order. Each point's eight voxels are read with one descent from the deepest
//! ancestor shared with the previous point's, the children of the nodes read lately kept at hand; a
//! vertex is a point and a link part, numbered point by point; and the corners inside a rectangle's edge
//! are the points between its two ends along that edge's line: each axis's lines are sorted once with all
//! the edge needs of their points, so that an edge reads a run of memory. Time and peak memory against OpenVDB's
//! `volumeToMesh` in `results/performance/export.md`.
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

use crate::radix;
use std::collections::HashMap;
use std::sync::OnceLock;

use crate::space::Cell;
use crate::tree::cursor::Locator;
use crate::tree::words::partial_mask;
use crate::tree::{KTree, NodeState};

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

/// The occupancy of the eight voxels around lattice point `p` (bit `o`: octant `o`; voxels outside the
/// universe are empty). The eight lie in the smallest aligned cell holding both `p − 1` and `p` on every
/// axis, found with `locator` (from a deep ancestor shared with the previous point's, when points come in
/// Morton order); each voxel's state is then read from that cell down, a few levels for most points.
fn occupancy(
    tree: &KTree<3>,
    locator: &mut Locator<3>,
    recent: &mut RecentChildren,
    p: [u32; 3],
) -> u8 {
    let side = tree.universe().side();
    let level = tree.level();
    // The cell's log side: one more than the most trailing zeros of a coordinate (a coordinate of 0 or the
    // universe's side has voxels outside on one side: its octants there stay empty).
    let inside = |x: u32| x > 0 && u64::from(x) < side;
    let log_side = p
        .iter()
        .filter(|&&x| inside(x))
        .map(|x| x.trailing_zeros() + 1)
        .max()
        .unwrap_or(level)
        .min(level);
    // The block's lowest voxel, kept inside the universe; octants outside are skipped below.
    let low: [u32; 3] = p.map(|x| x.saturating_sub(1));
    let cell = Cell {
        origin: low.map(|x| x >> log_side << log_side),
        level: level - log_side,
        log_side,
    };
    let node = locator.locate(tree, &cell);
    // The octants whose voxels are inside the universe: those below `p` along an axis are out where `p` is
    // at 0 on it, those above where it is at the universe's side.
    let octants = (0..3).fold(0xffu8, |set, a| {
        let x = u64::from(p[a]);
        let below_out = if x == 0 { !UPPER_ON[a] } else { 0 };
        let above_out = if x >= side { UPPER_ON[a] } else { 0 };
        set & !below_out & !above_out
    });
    let depth = node.cell().level() as usize;
    let first = match node.state() {
        NodeState::Partial => tree.first_child(depth, node.index()),
        _ => 0,
    };
    let mut m = 0u8;
    fill(
        tree,
        recent,
        (depth, first, node.state()),
        log_side,
        p,
        octants,
        &mut m,
    );
    m
}

/// Sets in `m` the octants of `octants` (a set of bits) around `p` whose voxel is full, the voxels lying in
/// the node `(depth, index, state)` of log side `log_side`: the octants sharing a child go down together, so
/// each node on the way is stepped into once.
fn fill(
    tree: &KTree<3>,
    recent: &mut RecentChildren,
    (depth, first, state): (usize, usize, NodeState),
    log_side: u32,
    p: [u32; 3],
    octants: u8,
    m: &mut u8,
) {
    match state {
        NodeState::Full => *m |= octants,
        NodeState::Empty => {}
        NodeState::Partial => {
            let bit = log_side - 1;
            // The child code of the voxels below `p` on every axis (octant 0) and above (octant 7); octant
            // `o` takes each axis's bit from the one or the other.
            let child_code =
                |x: [u32; 3]| (0..3).fold(0u8, |code, a| code | ((x[a] >> bit & 1) as u8) << a);
            let below = child_code(p.map(|x| x.wrapping_sub(1)));
            let above = child_code(p);
            let split = below ^ above;
            let children = recent.of(tree, depth, first);
            let mut left = octants;
            while left != 0 {
                let o = left.trailing_zeros() as u8;
                let c = below ^ (split & o);
                // The octants that go into the same child: those agreeing with `o` on the axes that split.
                let same = left & AGREEING[usize::from(split)][usize::from(o)];
                left &= !same;
                let c = usize::from(c);
                match children.state(c) {
                    NodeState::Full => *m |= same,
                    NodeState::Empty => {}
                    NodeState::Partial => fill(
                        tree,
                        recent,
                        (depth + 1, children.first_child(c), NodeState::Partial),
                        bit,
                        p,
                        same,
                        m,
                    ),
                }
            }
        }
    }
}

/// The octants on the upper side of each axis (bit `o` set: octant `o`).
const UPPER_ON: [u8; 3] = [0b1010_1010, 0b1100_1100, 0b1111_0000];

/// For a set of axes `s` (bit `a`: axis `a`) and an octant `o`, the octants agreeing with `o` on those axes.
const AGREEING: [[u8; 8]; 8] = {
    let mut table = [[0u8; 8]; 8];
    let mut s = 0;
    while s < 8 {
        let mut o = 0;
        while o < 8 {
            let mut q = 0;
            while q < 8 {
                if (q ^ o) & s == 0 {
                    table[s][o] |= 1 << q;
                }
                q += 1;
            }
            o += 1;
        }
        s += 1;
    }
    table
};

/// The Morton key of a lattice point (coordinates up to 2^22 − 1; bits interleaved, axis 0 lowest).
fn morton(p: [u32; 3]) -> u128 {
    // The low 21 bits of x spread to every third bit of a u64.
    fn spread(x: u32) -> u64 {
        let mut x = u64::from(x) & 0x1f_ffff;
        x = (x | x << 32) & 0x001f_0000_0000_ffff;
        x = (x | x << 16) & 0x001f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        x = (x | x << 2) & 0x1249_2492_4924_9249;
        x
    }
    let low = spread(p[0]) | spread(p[1]) << 1 | spread(p[2]) << 2;
    let high = (0..3).fold(0u128, |h, a| h | u128::from(p[a] >> 21 & 1) << a);
    u128::from(low) | high << 63
}

/// The lattice point of a Morton key ([`morton`]'s inverse).
fn point_of(key: u128) -> [u32; 3] {
    // Every third bit of a u64 gathered into the low 21 bits.
    fn gather(x: u64) -> u32 {
        let mut x = x & 0x1249_2492_4924_9249;
        x = (x | x >> 2) & 0x10c3_0c30_c30c_30c3;
        x = (x | x >> 4) & 0x100f_00f0_0f00_f00f;
        x = (x | x >> 8) & 0x001f_0000_ff00_00ff;
        x = (x | x >> 16) & 0x001f_0000_0000_ffff;
        x = (x | x >> 32) & 0x1f_ffff;
        x as u32
    }
    let low = key as u64;
    std::array::from_fn(|a| gather(low >> a) | ((key >> (63 + a)) as u32 & 1) << 21)
}

/// A plane of boundary (its axis, its coordinate on that axis, and whether the outward normal points up
/// the axis) as one number ordered as the triple.
fn plane_key(a: usize, coord: u32, upper: bool) -> u64 {
    (a as u64) << 33 | u64::from(coord) << 1 | u64::from(upper)
}

/// A [`plane_key`] packed into `level + 4` bits in the same order (the axis in 2 bits, the coordinate, at
/// most `2^level`, in `level + 1`, the orientation in 1), for radix sorting.
fn packed_plane_key(plane: u64, level: u32) -> u64 {
    (plane >> 33) << (level + 2) | (plane & 0x1_ffff_ffff)
}

/// The eight children of a partial node: their states, read at once, and where the children of the
/// partial ones start, from one rank of the first (the partial children's children are consecutive).
#[derive(Debug, Clone, Copy)]
struct Children {
    /// Child `c`'s state at bits `2c`.
    states: u32,
    /// The index of the first child's first child, were it partial.
    grandchildren: usize,
}

impl Children {
    /// The children of the partial node at `depth` whose first child is `first`.
    #[inline]
    fn of(tree: &KTree<3>, depth: usize, first: usize) -> Children {
        let level = tree.level_states(depth + 1);
        let states = level.block_codes(first, 3);
        let grandchildren = if partial_mask(u64::from(states)) == 0 {
            0
        } else {
            level.partial_rank(first) << 3
        };
        Children {
            states,
            grandchildren,
        }
    }

    /// Child `code`'s state.
    #[inline]
    fn state(&self, code: usize) -> NodeState {
        NodeState::from_bits(self.states >> (2 * code))
    }

    /// The index of partial child `code`'s first child.
    #[inline]
    fn first_child(&self, code: usize) -> usize {
        let before = partial_mask(u64::from(self.states) & ((1 << (2 * code)) - 1));
        self.grandchildren + ((before.count_ones() as usize) << 3)
    }
}

/// The children of the partial nodes read lately, a few at each depth (points in Morton order read
/// the same nodes again and again).
struct RecentChildren {
    /// By depth, then by the first child's index divided by 8, modulo [`RecentChildren::SLOTS`]:
    /// `(first, children)`.
    slots: Vec<[(usize, Children); RecentChildren::SLOTS]>,
}

impl RecentChildren {
    /// Nodes kept at each depth.
    const SLOTS: usize = 8;

    fn new(tree: &KTree<3>) -> Self {
        let none = (
            usize::MAX,
            Children {
                states: 0,
                grandchildren: 0,
            },
        );
        RecentChildren {
            slots: vec![[none; Self::SLOTS]; tree.level() as usize + 1],
        }
    }

    /// As [`Children::of`].
    #[inline]
    fn of(&mut self, tree: &KTree<3>, depth: usize, first: usize) -> Children {
        let slot = &mut self.slots[depth][(first >> 3) % Self::SLOTS];
        if slot.0 != first {
            *slot = (first, Children::of(tree, depth, first));
        }
        slot.1
    }
}

/// A node met by the walk of [`boundary_squares`]: where it is in the tree, its cell and state.
#[derive(Debug, Clone, Copy)]
struct Node {
    depth: usize,
    /// The index of its first child, for a partial node (0 for a leaf).
    first: usize,
    state: NodeState,
    origin: [u32; 3],
    log_side: u32,
}

impl Node {
    /// The root of `tree`.
    fn root(tree: &KTree<3>) -> Node {
        let state = tree.root_state();
        Node {
            depth: 0,
            first: match state {
                NodeState::Partial => tree.first_child(0, 0),
                _ => 0,
            },
            state,
            origin: [0; 3],
            log_side: tree.level(),
        }
    }

    /// The eight children of a partial node, by child code.
    fn children(&self, tree: &KTree<3>) -> [Node; 8] {
        let children = Children::of(tree, self.depth, self.first);
        std::array::from_fn(|code| self.child(&children, code))
    }

    /// The child `code` of a partial node whose children are `children`.
    fn child(&self, children: &Children, code: usize) -> Node {
        let half = 1u32 << (self.log_side - 1);
        let state = children.state(code);
        Node {
            depth: self.depth + 1,
            first: match state {
                NodeState::Partial => children.first_child(code),
                _ => 0,
            },
            state,
            origin: std::array::from_fn(|a| self.origin[a] + (code as u32 >> a & 1) * half),
            log_side: self.log_side - 1,
        }
    }
}

/// The boundary squares of `tree`: `(plane, c, b, side)` with the plane as in [`plane_key`] and `(b, c)`
/// in the plane's axes (see [`others`]), sorted. One walk finds every pair of face-adjacent leaves (as
/// octree dual contouring does): inside a partial node, the pairs of children across its twelve inner
/// faces; across a face between two nodes, the pairs of their children along it, a leaf standing for its
/// own children; the universe's six faces against the empty outside. A pair of a full and an empty leaf
/// bounds the object by the face of the smaller.
fn boundary_squares(tree: &KTree<3>) -> Vec<(u64, u32, u32, u32)> {
    let mut squares = Vec::new();
    let root = Node::root(tree);
    for a in 0..3 {
        across(tree, None, Some(root), a, &mut squares);
        across(tree, Some(root), None, a, &mut squares);
    }
    within(tree, &root, &mut squares);
    // In the order of the tuples (the side never decides: the squares of a plane are disjoint).
    let level = tree.level();
    let key = |&(plane, c, b, _): &(u64, u32, u32, u32)| {
        // The plane (L + 4 bits), then c and b (L bits each).
        let plane = packed_plane_key(plane, level);
        u128::from(plane) << (2 * level) | u128::from(c) << level | u128::from(b)
    };
    radix::sort_by_wide_key(&mut squares, 3 * level + 4, &mut Vec::new(), key);
    squares
}

/// The boundary squares inside `node`.
fn within(tree: &KTree<3>, node: &Node, out: &mut Vec<(u64, u32, u32, u32)>) {
    if node.state != NodeState::Partial {
        return;
    }
    let children = node.children(tree);
    for child in &children {
        within(tree, child, out);
    }
    for a in 0..3 {
        for code in (0..8).filter(|code| code >> a & 1 == 0) {
            across(
                tree,
                Some(children[code]),
                Some(children[code | 1 << a]),
                a,
                out,
            );
        }
    }
}

/// The boundary squares on the face between `lo` and `hi` (`hi` above `lo` along axis `a`; `None` is the
/// empty outside of the universe). The two have the same size, or one is a leaf larger than the other.
fn across(
    tree: &KTree<3>,
    lo: Option<Node>,
    hi: Option<Node>,
    a: usize,
    out: &mut Vec<(u64, u32, u32, u32)>,
) {
    let state = |n: &Option<Node>| n.map_or(NodeState::Empty, |n| n.state);
    let (sl, sh) = (state(&lo), state(&hi));
    if sl == NodeState::Partial || sh == NodeState::Partial {
        // The children along the face; a leaf (or the outside) stands for its own.
        let side = |n: Option<Node>, upper: usize| -> [Option<Node>; 4] {
            match n {
                Some(node) if node.state == NodeState::Partial => {
                    let (b, c) = others(a);
                    let children = Children::of(tree, node.depth, node.first);
                    std::array::from_fn(|q| {
                        Some(node.child(&children, upper << a | (q & 1) << b | (q >> 1) << c))
                    })
                }
                other => [other; 4],
            }
        };
        let (below, above) = (side(lo, 1), side(hi, 0));
        for q in 0..4 {
            across(tree, below[q], above[q], a, out);
        }
        return;
    }
    if sl == sh {
        return;
    }
    // The smaller of the two cells (the same size, or a leaf against the outside, when neither is).
    let cell = match (lo, hi) {
        (Some(l), Some(h)) => {
            if l.log_side <= h.log_side {
                l
            } else {
                h
            }
        }
        (Some(n), None) | (None, Some(n)) => n,
        (None, None) => return,
    };
    let coord = match (lo, hi) {
        (_, Some(h)) => h.origin[a],
        (Some(l), None) => l.origin[a] + (1u32 << l.log_side),
        (None, None) => return,
    };
    let (b, c) = others(a);
    out.push((
        plane_key(a, coord, sl == NodeState::Full),
        cell.origin[c],
        cell.origin[b],
        1u32 << cell.log_side,
    ));
}

/// Disjoint squares `(b, c, side)`, sorted by `(c, b)`, merged into rectangles `[b0, b1, c0, c1]` covering
/// the same region, appended to `out` sorted by `(c0, b0)`: strips across `c` between consecutive square
/// edges, maximal intervals along `b` in each strip, an interval carried on through the following strips
/// while it is the same. The squares across a strip are kept in `b` order (those carried on from the
/// strip below merged with those starting), so no strip is sorted.
fn merge_rectangles(squares: &[[u32; 3]], out: &mut Vec<[u32; 4]>) {
    debug_assert!(squares
        .windows(2)
        .all(|w| (w[0][1], w[0][0]) < (w[1][1], w[1][0])));
    let first = out.len();
    // The squares across the strip, by b; open rectangles `(b0, b1, c0)`, by interval; the strip's intervals.
    let (mut active, mut carried) = (Vec::<[u32; 3]>::new(), Vec::new());
    let (mut open, mut still, mut intervals) =
        (Vec::<(u32, u32, u32)>::new(), Vec::new(), Vec::new());
    let mut next = 0;
    let Some(mut c) = squares.first().map(|s| s[1]) else {
        return;
    };
    loop {
        let start = next;
        while next < squares.len() && squares[next][1] == c {
            next += 1;
        }
        carried.clear();
        carried.extend(active.iter().copied().filter(|s| s[1] + s[2] > c));
        active.clear();
        let (mut i, mut j) = (0, start);
        while i < carried.len() || j < next {
            if j == next || (i < carried.len() && carried[i][0] < squares[j][0]) {
                active.push(carried[i]);
                i += 1;
            } else {
                active.push(squares[j]);
                j += 1;
            }
        }
        intervals.clear();
        for s in &active {
            let (b0, b1) = (s[0], s[0] + s[2]);
            match intervals.last_mut() {
                Some((_, end)) if *end == b0 => *end = b1,
                _ => intervals.push((b0, b1)),
            }
        }
        // Both lists sorted: an open rectangle goes on if its interval is still there, else it ends at c.
        still.clear();
        let mut j = 0;
        for &(b0, b1) in &intervals {
            while j < open.len() && (open[j].0, open[j].1) < (b0, b1) {
                let (x0, x1, c0) = open[j];
                out.push([x0, x1, c0, c]);
                j += 1;
            }
            if j < open.len() && (open[j].0, open[j].1) == (b0, b1) {
                still.push(open[j]);
                j += 1;
            } else {
                still.push((b0, b1, c));
            }
        }
        for &(x0, x1, c0) in &open[j..] {
            out.push([x0, x1, c0, c]);
        }
        std::mem::swap(&mut open, &mut still);
        // The next strip starts where a square across this one ends or the next square begins.
        let ends = active.iter().map(|s| s[1] + s[2]).min();
        c = match (ends, squares.get(next)) {
            (Some(e), Some(s)) => e.min(s[1]),
            (Some(e), None) => e,
            (None, Some(s)) => s[1],
            (None, None) => break,
        };
    }
    out[first..].sort_unstable_by_key(|r| (r[2], r[0]));
}

/// The boundary rectangles of `tree`, by plane (in [`plane_key`] order), each plane's by `(c0, b0)`.
fn boundary_rectangles(tree: &KTree<3>) -> Vec<Rect> {
    let squares = boundary_squares(tree);
    let mut rects = Vec::new();
    let (mut plane, mut merged) = (Vec::new(), Vec::new());
    for group in squares.chunk_by(|x, y| x.0 == y.0) {
        plane.clear();
        plane.extend(group.iter().map(|&(_, c, b, s)| [b, c, s]));
        merged.clear();
        merge_rectangles(&plane, &mut merged);
        let key = group[0].0;
        let (a, coord, upper) = ((key >> 33) as usize, (key >> 1) as u32, key & 1 == 1);
        rects.extend(merged.iter().map(|&r| Rect { a, coord, upper, r }));
    }
    rects
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
        let q = CORNER_QUADRANTS;
        [
            (self.point(b0, c0), q[0]),
            (self.point(b1, c0), q[1]),
            (self.point(b1, c1), q[2]),
            (self.point(b0, c1), q[3]),
        ]
    }
}

/// The quadrant a rectangle covers at each of its corners, counter-clockwise from `(b0, c0)` (see
/// [`Rect::corners`]).
const CORNER_QUADRANTS: [usize; 4] = [0b11, 0b10, 0b00, 0b01];

/// A lattice point at rectangles' corners, as a line along one direction `d` holds it.
#[derive(Debug, Clone, Copy, Default)]
struct LinePoint {
    /// The point's coordinate along `d`.
    along: u32,
    /// The vertex of the point's first link part at a corner; the others follow in order of part.
    first_vertex: u32,
    /// The occupancy of the eight voxels around the point.
    mask: u8,
    /// The link parts (bit set) of the corners here whose rectangle has an edge along `d`.
    on_line: u8,
    /// The link parts of all corners here.
    parts: u8,
}

impl LinePoint {
    /// The vertex of link part `part` (a part of some corner at the point).
    fn vertex(&self, part: u8) -> u32 {
        vertex_of(self.first_vertex, self.parts, part)
    }
}

/// The vertex of link part `part` at a point whose corners have link parts `parts` (bit set) and whose
/// first part's vertex is `first_vertex`: the parts' vertices follow in order of part.
fn vertex_of(first_vertex: u32, parts: u8, part: u8) -> u32 {
    debug_assert!(parts >> part & 1 == 1);
    first_vertex + (parts & ((1u8 << part) - 1)).count_ones()
}

/// A lattice point at rectangles' corners, while the lines are made.
#[derive(Debug, Clone, Copy)]
struct Point {
    at: [u32; 3],
    /// The occupancy of the eight voxels around the point.
    mask: u8,
    /// For each direction `d`, the link parts (bit set) of the corners here whose rectangle has an edge
    /// along `d`.
    on_lines: [u8; 3],
    first_vertex: u32,
}

/// The lattice points at the rectangles' corners, and the vertices made at them.
struct Corners {
    /// For each lattice direction `d`, the points line by line along `d` (sorted by their other two
    /// coordinates, then along `d`).
    lines: [Vec<LinePoint>; 3],
    /// What the mesh needs of corner `k` of rectangle `r`, at `4r + k`.
    corners: Vec<Corner>,
    /// The vertex of each point and corner link part: the points' in Morton order, each point's by part.
    vertices: Vec<[f64; 3]>,
}

/// A rectangle's corner: its point's vertex (of the corner's link part) and occupancy, and the point's
/// places in [`Corners::lines`] along the rectangle's axes `b` and `c`.
#[derive(Debug, Clone, Copy, Default)]
struct Corner {
    vertex: u32,
    positions: [u32; 2],
    mask: u8,
}

impl Corners {
    fn new(tree: &KTree<3>, rects: &[Rect]) -> Self {
        let corner_count = u32::try_from(4 * rects.len())
            .expect("fewer than 2^32 rectangle corners (vertex indices are 32-bit)");
        // Lattice coordinates run from 0 to 2^L: L + 1 bits each.
        let bits = 3 * (tree.level() + 1);
        // Each corner as the Morton key of its point (low 64 bits, high bits), its slot `4r + k` and its
        // rectangle's axis, so that the loops below, in Morton order, read no rectangle (they would come in
        // random order) and write each corner's facts at its slot.
        let mut keyed: Vec<(u64, u32, u8, u8)> = Vec::with_capacity(corner_count as usize);
        for (r, rect) in rects.iter().enumerate() {
            for (k, (p, _)) in rect.corners().into_iter().enumerate() {
                let key = morton(p);
                keyed.push((
                    key as u64,
                    (4 * r + k) as u32,
                    (key >> 64) as u8,
                    rect.a as u8,
                ));
            }
        }
        radix::sort_by_wide_key(&mut keyed, bits, &mut Vec::new(), |&(low, _, high, _)| {
            u128::from(high) << 64 | u128::from(low)
        });
        let same_point = |x: &(u64, u32, u8, u8), y: &(u64, u32, u8, u8)| (x.0, x.2) == (y.0, y.2);
        // The link part of each corner at a point of occupancy `mask`.
        let part = |mask: u8, &(_, slot, _, a): &(u64, u32, u8, u8)| {
            part_of(mask, usize::from(a), CORNER_QUADRANTS[slot as usize % 4])
        };
        let (mut locator, mut recent) = (Locator::new(tree), RecentChildren::new(tree));
        let mut corners = vec![Corner::default(); keyed.len()];
        let mut vertices = Vec::new();
        // The points, in Morton order. The occupancies first, in a pass that reads nothing but the tree.
        let masks: Vec<u8> = keyed
            .chunk_by(same_point)
            .map(|group| {
                let (low, _, high, _) = group[0];
                let at = point_of(u128::from(high) << 64 | u128::from(low));
                occupancy(tree, &mut locator, &mut recent, at)
            })
            .collect();
        let mut points: Vec<Point> = Vec::with_capacity(masks.len());
        for (group, &mask) in keyed.chunk_by(same_point).zip(&masks) {
            let (low, _, high, _) = group[0];
            let at = point_of(u128::from(high) << 64 | u128::from(low));
            let mut on_lines = [0u8; 3];
            for corner in group {
                let (b, c) = others(usize::from(corner.3));
                let bit = 1 << part(mask, corner);
                on_lines[b] |= bit;
                on_lines[c] |= bit;
            }
            let first_vertex = u32::try_from(vertices.len())
                .expect("fewer than 2^32 vertices (indices are 32-bit)");
            let parts = on_lines[0] | on_lines[1] | on_lines[2];
            vertices.extend(std::iter::repeat_n(
                at.map(f64::from),
                parts.count_ones() as usize,
            ));
            for corner in group {
                corners[corner.1 as usize] = Corner {
                    vertex: vertex_of(first_vertex, parts, part(mask, corner)),
                    // The point, until its places in the lines are known.
                    positions: [points.len() as u32, 0],
                    mask,
                };
            }
            points.push(Point {
                at,
                mask,
                on_lines,
                first_vertex,
            });
        }
        drop(masks);
        drop(keyed);
        // The lines along each direction, holding what an edge needs of each point (so that an edge reads
        // a run of memory), and each point's place in them.
        let mut places = vec![[0u32; 3]; points.len()];
        let mut sorted = Vec::with_capacity(points.len());
        let width = bits / 3;
        let lines: [Vec<LinePoint>; 3] = std::array::from_fn(|d| {
            let (x, y) = match d {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            // The point's coordinates across the line, along it, and the point.
            sorted.clear();
            sorted.extend(
                points
                    .iter()
                    .enumerate()
                    .map(|(i, p)| [p.at[x], p.at[y], p.at[d], i as u32]),
            );
            // (A fresh scratch buffer for each sort: it is gone before the line is made, and the peak of
            // memory is here.)
            radix::sort_by_wide_key(&mut sorted, bits, &mut Vec::new(), |p| {
                u128::from(p[0]) << (2 * width) | u128::from(p[1]) << width | u128::from(p[2])
            });
            sorted
                .iter()
                .enumerate()
                .map(|(j, &[.., along, i])| {
                    places[i as usize][d] = j as u32;
                    let p = &points[i as usize];
                    LinePoint {
                        along,
                        first_vertex: p.first_vertex,
                        mask: p.mask,
                        on_line: p.on_lines[d],
                        parts: p.on_lines[0] | p.on_lines[1] | p.on_lines[2],
                    }
                })
                .collect()
        });
        drop(sorted);
        drop(points);
        for (rect, corners) in rects.iter().zip(corners.chunks_exact_mut(4)) {
            let (b, c) = others(rect.a);
            for corner in corners {
                let place = places[corner.positions[0] as usize];
                corner.positions = [place[b], place[c]];
            }
        }
        Self {
            lines,
            corners,
            vertices,
        }
    }
}

/// The link part, at a point of occupancy `mask`, of the unit face `(a, q)`, which must be a boundary face.
fn part_of(mask: u8, a: usize, q: usize) -> u8 {
    let part = link_parts()[mask as usize][face_index(a, q)];
    debug_assert!(part < 4, "a rectangle on a non-boundary face");
    part
}

/// The boundary of `tree` as a closed, outward-oriented triangle mesh in voxel coordinates (see the
/// module's documentation for how it is made crack-free and 2-manifold). Empty for an empty tree.
///
/// # Panics
/// If the mesh would need 2^32 or more vertices or rectangle corners (its indices are 32-bit).
pub fn boundary_mesh(tree: &KTree<3>) -> SurfaceMesh {
    mesh_of(tree, &boundary_rectangles(tree))
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
/// before anything is made).
///
/// # Panics
/// As [`boundary_mesh`].
pub fn smooth_mesh(tree: &KTree<3>, iterations: usize) -> Result<SurfaceMesh, ExportError> {
    let squares = boundary_squares(tree);
    let faces: u128 = squares
        .iter()
        .map(|s| u128::from(s.3) * u128::from(s.3))
        .sum();
    if faces > u128::from(SMOOTH_FACE_LIMIT) {
        return Err(ExportError::TooLarge {
            faces,
            limit: SMOOTH_FACE_LIMIT,
        });
    }
    let mut units = Vec::with_capacity(faces as usize);
    for &(key, c0, b0, side) in &squares {
        let (a, coord, upper) = ((key >> 33) as usize, (key >> 1) as u32, key & 1 == 1);
        for c in c0..c0 + side {
            for b in b0..b0 + side {
                units.push(Rect {
                    a,
                    coord,
                    upper,
                    r: [b, b + 1, c, c + 1],
                });
            }
        }
    }
    let mut mesh = mesh_of(tree, &units);
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

/// The mesh of boundary rectangles `rects` (see [`boundary_mesh`]).
fn mesh_of(tree: &KTree<3>, rects: &[Rect]) -> SurfaceMesh {
    let Corners {
        lines,
        corners,
        vertices,
    } = Corners::new(tree, rects);
    // The corners' vertices, then a centre for some rectangles; two triangles a rectangle at least.
    let mut mesh = SurfaceMesh {
        vertices,
        triangles: Vec::with_capacity(2 * rects.len() + rects.len() / 4),
    };
    // Midpoints of segments where two solids touch, by doubled position and the full octant bounded.
    let mut midpoints: HashMap<([u64; 3], u8), u32> = HashMap::new();
    let mut ring: Vec<u32> = Vec::new();
    let mut stops: Vec<(u32, u8, Option<u32>)> = Vec::new();
    for (rect, corner) in rects.iter().zip(corners.chunks_exact(4)) {
        let (b, c) = others(rect.a);
        let rect_corners = rect.corners();
        ring.clear();
        for k in 0..4 {
            let (p, _) = rect_corners[k];
            let next = (k + 1) % 4;
            ring.push(corner[k].vertex);
            // The edge from p to the next corner: along b for k = 0, 2, along c for k = 1, 3.
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
            // The rectangle's unit face just past each point inside the edge.
            let face = face_index(rect.a, quadrant(1));
            // The corners strictly inside the edge, on the same sheet as the rectangle there.
            stops.clear();
            let (j0, j1) = (corner[k].positions[k % 2], corner[next].positions[k % 2]);
            for point in &lines[d][(j0.min(j1) + 1) as usize..j0.max(j1) as usize] {
                let part = link_parts()[point.mask as usize][face];
                debug_assert!(part < 4, "a rectangle's edge past a non-boundary face");
                if part < 8 && point.on_line >> part & 1 == 1 {
                    stops.push((point.along, point.mask, Some(point.vertex(part))));
                }
            }
            if j1 < j0 {
                stops.reverse();
            }
            // The full octant the rectangle bounds, as bits on the axes across the line.
            let full_side = usize::from(!rect.upper);
            let octant = (full_side << rect.a | e_side << e) as u8;
            // Along the edge: each stop, then the next corner, as (coordinate along d, occupancy, vertex).
            let ends = stops.iter().copied().chain(std::iter::once((
                rect_corners[next].0[d],
                corner[next].mask,
                None,
            )));
            let mut prev = (p[d], corner[k].mask);
            for (at, mask, vertex) in ends {
                let lower = if prev.0 < at { prev.1 } else { mask };
                if pinched(lower, d) {
                    let mut m = p.map(|x| 2 * u64::from(x));
                    m[d] = u64::from(prev.0) + u64::from(at);
                    let id = *midpoints.entry((m, 16 + octant)).or_insert_with(|| {
                        mesh.vertices.push(m.map(|x| x as f64 / 2.0));
                        (mesh.vertices.len() - 1) as u32
                    });
                    ring.push(id);
                }
                ring.extend(vertex);
                prev = (at, mask);
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
    assert!(
        u32::try_from(mesh.vertices.len()).is_ok(),
        "fewer than 2^32 vertices (indices are 32-bit)"
    );
    mesh
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangles_cover_the_squares_once() {
        // An L of three unit squares and a 2 × 2 square beside it.
        let mut squares = vec![[0, 0, 1], [1, 0, 1], [0, 1, 1], [2, 0, 2]];
        squares.sort_unstable_by_key(|s| (s[1], s[0]));
        let mut rects = Vec::new();
        merge_rectangles(&squares, &mut rects);
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

    #[test]
    fn morton_keys_order_points_and_give_them_back() {
        let top = 1u32 << 21;
        for p in [
            [0, 0, 0],
            [1, 2, 3],
            [top, 0, top],
            [top - 1, top, 12345],
            [top, top, top],
        ] {
            assert_eq!(point_of(morton(p)), p);
        }
        // Bits interleaved, axis 0 lowest: the eight corners of a unit cube in child-code order.
        let keys: Vec<u128> = (0..8u32)
            .map(|o| morton([o & 1, o >> 1 & 1, o >> 2]))
            .collect();
        assert_eq!(keys, (0..8).collect::<Vec<u128>>());
        assert!(morton([top, 0, 0]) > morton([top - 1, top - 1, top - 1]));
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
