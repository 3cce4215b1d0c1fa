//! Line drawings of octrees with hidden lines removed (Veenstra & Ahuja, V1–V8), in parallel projection
//! from any direction.
//!
//! 1. The full leaves are listed front to back ([`super::order`], V2); a leaf whose six faces all touch
//!    full voxels is skipped (V5). The others are the "graphics nodes" (at most one per full leaf, V8).
//! 2. For each of a leaf's twelve edges, the three cells around the edge (two across its faces, one
//!    diagonal) are read along the edge through the pointer-free neighbour search of
//!    [`super::neighbours`]. A point of the edge is a line of the drawing when the four cells around it
//!    are not "flat": one full (convex edge), three full (concave), or two diagonal. Two full side by side
//!    is a *crack* between coplanar faces and is not drawn (V3). A point is kept only if the cell towards
//!    the viewer is empty (else the object itself hides it there).
//! 3. Pieces of the same lattice line from different leaves are merged, each part keeping the earliest
//!    leaf that produced it as owner.
//! 4. Hidden parts are removed by clipping each piece against the projections (hexagons) of the graphics
//!    nodes *before its owner* in the front-to-back list: [`super::hidden`] has the paper's pairwise method
//!    and a faster bucketed one; both give the same result.
//! 5. Touching collinear visible pieces are joined into long lines ("dots" removed, V4).
//!
//! **Exact views, ties broken symbolically.** The drawing is of the requested direction exactly: the
//! projection ([`LineDrawing::right`], [`LineDrawing::up`]) is that of the requested direction, normalised.
//! Every visibility decision (which leaf's edge faces the viewer, the front-to-back order, which part of a
//! segment a graphics node hides) is exact integer arithmetic on the lattice coordinates and on the
//! direction's components as integers in units of 2⁻⁵⁰ of the largest one. Where the direction is
//! degenerate for the lattice (an axis view, a diagonal such as (1, −1, 0) or (1, 1, 1), where lattice lines
//! project onto one another and points fall exactly on outlines), the decision is the one for the view
//! whose direction into the scene has its magnitudes grown by an infinitesimal `(ε, ε², ε⁴)` on the three
//! axes, a zero component counting as positive (simulation of simplicity: the first non-zero coefficient
//! of a predicate's polynomial in `ε` decides it, and none is identically zero). So:
//!
//! * a sightline that runs along a seam between two full cells is hidden by one of them: no hidden edge
//!   leaks through the outlines of a wall, whatever the direction;
//! * a hidden part that shrinks to a point in the tilted view hides nothing, and a visible part is drawn
//!   only when its exact length is positive;
//! * the edges of a face seen exactly edge-on are drawn, as they are in every nearby tilted view: seen
//!   from `+z`, a box shows its top face's four edges, the bottom edges of its `−x` and `−y` faces (drawn on
//!   top of the top face's) and three vertical edges (drawn as points).
//!
//! ```
//! use ktree::display::{line_drawing, HiddenLineMethod};
//! use ktree::KTree;
//! // A single voxel seen from a general direction: a hexagon outline and three inner edges.
//! let mut dense = vec![false; 8];
//! dense[0] = true;
//! let voxel = KTree::<3>::from_dense(1, &dense).unwrap();
//! let d = line_drawing(&voxel, [1.0, -0.8, 0.6], HiddenLineMethod::Bucketed).unwrap();
//! assert_eq!(d.lines.len(), 9);
//! // Seen along a diagonal: the same nine edges, drawn in the exact diagonal view.
//! let d = line_drawing(&voxel, [1.0, 1.0, 1.0], HiddenLineMethod::Bucketed).unwrap();
//! assert_eq!(d.lines.len(), 9);
//! assert_eq!(d.view_dir[0], d.view_dir[1]);
//! ```

use super::camera::v3;
use super::error::DisplayError;
use super::hidden::{remove_hidden, HiddenLineMethod, ScreenBoxes};
use super::neighbours::{shifted, Neighbours};
use super::order::{try_ordered_full_cells, Order, Viewer};
use super::sightline::ExactView;
use crate::space::Cell;
use crate::tree::storage::TreeStorage;

/// A piece of a lattice line: along `axis`, at coordinates `fixed` on the two other axes (in increasing
/// axis order), from `u0` to `u1` along `axis` (voxel units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge3 {
    /// The axis the line runs along.
    pub axis: u8,
    /// The line's coordinates on the other two axes, lower axis first.
    pub fixed: [u32; 2],
    /// Start along `axis`.
    pub u0: f64,
    /// End along `axis` (`u0 < u1`).
    pub u1: f64,
}

impl Edge3 {
    /// The other two axes, lower first.
    pub fn other_axes(&self) -> [usize; 2] {
        other_axes(self.axis as usize)
    }

    /// The 3-D point at `u` along the line.
    pub fn point(&self, u: f64) -> [f64; 3] {
        let [b, c] = self.other_axes();
        let mut p = [0.0; 3];
        p[self.axis as usize] = u;
        p[b] = f64::from(self.fixed[0]);
        p[c] = f64::from(self.fixed[1]);
        p
    }

    /// The line's key (axis, fixed coordinates).
    pub(crate) fn key(&self) -> (u8, [u32; 2]) {
        (self.axis, self.fixed)
    }
}

pub(crate) fn other_axes(axis: usize) -> [usize; 2] {
    match axis {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

/// Counters of one line drawing (the paper's quantities and ours).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LineStats {
    /// Nodes in the tree.
    pub nodes: u64,
    /// Full leaves.
    pub full_leaves: u64,
    /// Full leaves skipped as surrounded on all six faces (V5).
    pub surrounded: u64,
    /// Graphics nodes: full leaves kept, one per leaf at most (V8).
    pub graphics_nodes: u64,
    /// Edge pieces produced by the leaves before merging.
    pub edge_pieces: u64,
    /// Pieces after merging duplicates along each lattice line (the input of hidden-line removal).
    pub segments: u64,
    /// Segment–hexagon tests made by hidden-line removal.
    pub pair_tests: u64,
    /// Visible pieces after hidden-line removal.
    pub visible_pieces: u64,
    /// Lines drawn after joining touching collinear pieces (V4).
    pub lines: u64,
}

/// A line drawing: the visible edges in 3-D and the parallel projection that draws them.
#[derive(Debug, Clone)]
pub struct LineDrawing {
    /// The view direction (into the scene, unit): the requested one, normalised.
    pub view_dir: [f64; 3],
    /// Screen right, in world coordinates.
    pub right: [f64; 3],
    /// Screen up, in world coordinates.
    pub up: [f64; 3],
    /// The visible lines, sorted by line then start.
    pub lines: Vec<Edge3>,
    /// Counters.
    pub stats: LineStats,
}

impl LineDrawing {
    /// The 2-D drawing coordinates (x right, y up) of a world point.
    pub fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [v3::dot(p, self.right), v3::dot(p, self.up)]
    }

    /// The drawn lines as 2-D segments `[x0, y0, x1, y1]` (y up).
    pub fn segments_2d(&self) -> Vec<[f64; 4]> {
        self.lines
            .iter()
            .map(|e| {
                let a = self.project(e.point(e.u0));
                let b = self.project(e.point(e.u1));
                [a[0], a[1], b[0], b[1]]
            })
            .collect()
    }

    /// The 2-D bounding box `(xmin, ymin, xmax, ymax)` of the lines, `None` when there are none.
    pub fn bounds_2d(&self) -> Option<[f64; 4]> {
        let segs = self.segments_2d();
        if segs.is_empty() {
            return None;
        }
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for s in segs {
            b[0] = b[0].min(s[0]).min(s[2]);
            b[1] = b[1].min(s[1]).min(s[3]);
            b[2] = b[2].max(s[0]).max(s[2]);
            b[3] = b[3].max(s[1]).max(s[3]);
        }
        Some(b)
    }
}

/// One edge piece before merging: line key, `[u0, u1)` in voxel units, owner (graphics node index).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piece {
    pub axis: u8,
    pub fixed: [u32; 2],
    pub u0: u32,
    pub u1: u32,
    pub owner: u32,
}

/// The graphics nodes (non-surrounded full leaves in front-to-back order) and their edge pieces.
pub(crate) fn extract<T: TreeStorage<3>>(
    tree: &T,
    view: &ExactView,
    stats: &mut LineStats,
) -> Result<(Vec<Cell<3>>, Vec<Piece>), T::Error> {
    let side_u = tree.universe().side();
    let mut cubes = Vec::new();
    let mut pieces = Vec::new();
    let mut near = Neighbours::new(tree)?;
    let order = Viewer::Direction(view.signs());
    for cell in try_ordered_full_cells(tree, order, Order::FrontToBack)? {
        stats.full_leaves += 1;
        if near.is_surrounded(&cell)? {
            stats.surrounded += 1;
            continue;
        }
        let owner = cubes.len() as u32;
        cubes.push(cell);
        let s = cell.side() as u32;
        for axis in 0..3 {
            let [b, c] = other_axes(axis);
            for sb in [false, true] {
                for sc in [false, true] {
                    // Towards the viewer across the edge's faces? (the viewer is on the upper side of
                    // axis b when the tilted direction into the scene decreases along it)
                    let vb = sb != view.increasing(b);
                    let vc = sc != view.increasing(c);
                    if !vb && !vc {
                        continue; // the viewer's quadrant is this full leaf
                    }
                    let n1 = shifted(&cell, &[(b, sb)], side_u);
                    let n2 = shifted(&cell, &[(c, sc)], side_u);
                    let dg = shifted(&cell, &[(b, sb), (c, sc)], side_u);
                    let mut occ = |r: &Option<Cell<3>>, b_side: bool, c_side: bool| {
                        near.edge_occupancy(r.as_ref(), s, axis, (b, b_side), (c, c_side))
                    };
                    // Query the viewer's quadrant first: if it is all full, nothing here shows.
                    let (viewer_q, which) = match (vb, vc) {
                        (true, false) => (occ(&n1, !sb, sc)?, 1),
                        (false, true) => (occ(&n2, sb, !sc)?, 2),
                        _ => (occ(&dg, !sb, !sc)?, 3),
                    };
                    if viewer_q.iter().all(|r| r.2) {
                        continue;
                    }
                    let o1 = if which == 1 {
                        viewer_q.clone()
                    } else {
                        occ(&n1, !sb, sc)?
                    };
                    let o2 = if which == 2 {
                        viewer_q.clone()
                    } else {
                        occ(&n2, sb, !sc)?
                    };
                    let od = if which == 3 {
                        viewer_q
                    } else {
                        occ(&dg, !sb, !sc)?
                    };
                    let fixed = [
                        cell.origin[b] + if sb { s } else { 0 },
                        cell.origin[c] + if sc { s } else { 0 },
                    ];
                    let base = cell.origin[axis];
                    let (mut i1, mut i2, mut id) = (0, 0, 0);
                    let mut at = 0u32;
                    let mut open: Option<u32> = None;
                    while at < s {
                        while o1[i1].1 <= at {
                            i1 += 1;
                        }
                        while o2[i2].1 <= at {
                            i2 += 1;
                        }
                        while od[id].1 <= at {
                            id += 1;
                        }
                        let end = o1[i1].1.min(o2[i2].1).min(od[id].1);
                        let (f1, f2, fd) = (o1[i1].2, o2[i2].2, od[id].2);
                        let viewer_full = match which {
                            1 => f1,
                            2 => f2,
                            _ => fd,
                        };
                        let drawable = !viewer_full && ((!f1 && !f2) || (fd && f1 != f2));
                        match (drawable, open) {
                            (true, None) => open = Some(at),
                            (false, Some(start)) => {
                                pieces.push(Piece {
                                    axis: axis as u8,
                                    fixed,
                                    u0: base + start,
                                    u1: base + at,
                                    owner,
                                });
                                open = None;
                            }
                            _ => {}
                        }
                        at = end;
                    }
                    if let Some(start) = open {
                        pieces.push(Piece {
                            axis: axis as u8,
                            fixed,
                            u0: base + start,
                            u1: base + s,
                            owner,
                        });
                    }
                }
            }
        }
    }
    stats.graphics_nodes = cubes.len() as u64;
    stats.edge_pieces = pieces.len() as u64;
    Ok((cubes, pieces))
}

/// Merges pieces of the same lattice line: overlapping parts are kept once, owned by the earliest
/// producer; consecutive parts with the same owner are joined.
pub(crate) fn merge_pieces(mut pieces: Vec<Piece>) -> Vec<Piece> {
    pieces.sort_unstable_by_key(|p| (p.axis, p.fixed, p.u0, p.owner));
    let mut out: Vec<Piece> = Vec::with_capacity(pieces.len());
    let mut i = 0;
    while i < pieces.len() {
        let mut j = i;
        while j < pieces.len()
            && pieces[j].axis == pieces[i].axis
            && pieces[j].fixed == pieces[i].fixed
        {
            j += 1;
        }
        let line = &pieces[i..j];
        if line.len() == 1 {
            out.push(line[0]);
        } else {
            let mut cuts: Vec<u32> = line.iter().flat_map(|p| [p.u0, p.u1]).collect();
            cuts.sort_unstable();
            cuts.dedup();
            for w in cuts.windows(2) {
                let (a, b) = (w[0], w[1]);
                let owner = line
                    .iter()
                    .filter(|p| p.u0 <= a && p.u1 >= b)
                    .map(|p| p.owner)
                    .min();
                if let Some(owner) = owner {
                    match out.last_mut() {
                        Some(last)
                            if last.axis == line[0].axis
                                && last.fixed == line[0].fixed
                                && last.owner == owner
                                && last.u1 == a =>
                        {
                            last.u1 = b
                        }
                        _ => out.push(Piece {
                            u0: a,
                            u1: b,
                            owner,
                            ..line[0]
                        }),
                    }
                }
            }
        }
        i = j;
    }
    out
}

/// Joins touching or overlapping collinear pieces of each lattice line into one (V4).
pub(crate) fn join_lines(mut pieces: Vec<Edge3>) -> Vec<Edge3> {
    pieces.sort_unstable_by(|a, b| {
        a.key()
            .cmp(&b.key())
            .then(a.u0.partial_cmp(&b.u0).expect("finite"))
    });
    let mut out: Vec<Edge3> = Vec::with_capacity(pieces.len());
    for p in pieces {
        match out.last_mut() {
            Some(last) if last.key() == p.key() && p.u0 <= last.u1 => last.u1 = last.u1.max(p.u1),
            _ => out.push(p),
        }
    }
    out
}

/// A line drawing of the object in `tree` seen from direction `toward_eye` (from the object towards the
/// viewer), with cracks, hidden lines and dots removed.
///
/// ```
/// use ktree::display::{line_drawing, HiddenLineMethod};
/// use ktree::KTree;
/// // One 2×2×2 cube in a 4×4×4 universe: a hexagon outline plus three inner edges.
/// let mut dense = vec![false; 64];
/// for z in 0..2 { for y in 0..2 { for x in 0..2 { dense[x + 4 * (y + 4 * z)] = true; } } }
/// let tree = KTree::<3>::from_dense(2, &dense).unwrap();
/// let d = line_drawing(&tree, [1.0, -0.8, 0.6], HiddenLineMethod::Bucketed).unwrap();
/// assert_eq!(d.lines.len(), 9);
/// ```
///
/// # Errors
/// [`DisplayError::BadDirection`] for a zero or non-finite direction; [`DisplayError::Storage`] if a read
/// of the tree fails.
pub fn line_drawing<T: TreeStorage<3>>(
    tree: &T,
    toward_eye: [f64; 3],
    method: HiddenLineMethod,
) -> Result<LineDrawing, DisplayError> {
    draw(tree, toward_eye, method, None)
}

/// As [`line_drawing`], calling `progress` with (segments done, total).
///
/// # Errors
/// As [`line_drawing`].
pub fn line_drawing_with_progress<T: TreeStorage<3>>(
    tree: &T,
    toward_eye: [f64; 3],
    method: HiddenLineMethod,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<LineDrawing, DisplayError> {
    draw(tree, toward_eye, method, Some(progress))
}

fn draw<T: TreeStorage<3>>(
    tree: &T,
    toward_eye: [f64; 3],
    method: HiddenLineMethod,
    progress: Option<&mut dyn FnMut(u64, u64)>,
) -> Result<LineDrawing, DisplayError> {
    let into_scene = toward_eye.map(|x| -x);
    let d =
        v3::normalize(into_scene).ok_or_else(|| DisplayError::BadDirection(toward_eye.to_vec()))?;
    let view = ExactView::new(into_scene);
    let up0 = if d[0].abs() < 1e-3 && d[1].abs() < 1e-3 {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let right = v3::normalize(v3::cross(d, up0)).expect("up not parallel to d");
    let up = v3::cross(right, d);
    let mut stats = LineStats {
        nodes: tree.node_count(),
        ..Default::default()
    };
    let (cubes, pieces) =
        extract(tree, &view, &mut stats).map_err(|e| DisplayError::Storage(e.into()))?;
    let segments = merge_pieces(pieces);
    stats.segments = segments.len() as u64;
    let screen = ScreenBoxes::new(right, up, tree.universe().side() as f64);
    let visible = remove_hidden(
        &cubes, &segments, &view, &screen, method, &mut stats, progress,
    );
    stats.visible_pieces = visible.len() as u64;
    let lines = join_lines(visible);
    stats.lines = lines.len() as u64;
    Ok(LineDrawing {
        view_dir: d,
        right,
        up,
        lines,
        stats,
    })
}
