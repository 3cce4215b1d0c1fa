//! Hidden-line removal for line drawings: each segment is clipped against the projections of the graphics
//! nodes that come before its owner in the front-to-back list — exactly those that can be in front of it.
//!
//! * [`HiddenLineMethod::Pairwise`] is the paper's method (V7): every segment is tested against *every*
//!   earlier graphics node. The cost is quadratic in the number of graphics nodes.
//! * [`HiddenLineMethod::Bucketed`] puts the screen boxes of the graphics nodes into a screen grid once,
//!   each bucket keeping its graphics nodes in front-to-back order; a segment is tested only against the
//!   earlier nodes in the buckets its box meets, each once. Same tests, same answer, a small fraction of
//!   the work.
//!
//! The test itself is exact: the part of a segment a cube hides is an open interval with rational ends,
//! computed in integers from the lattice coordinates and the integer view direction, with ties (a
//! segment along the outline of a cube's projection, a sightline through a seam between two cubes)
//! decided by the symbolic tilt of the view described in [`super::lines`]. Screen boxes (in `f64`, grown
//! by 10⁻⁹ of the universe's side) only choose which cubes to test, never the answer.
//!
//! ```
//! use ktree::display::{line_drawing, HiddenLineMethod};
//! use ktree::{rays::ball_rays, stacking::paper::stack};
//! let ball = stack(&ball_rays::<3>(4, [16, 16, 16], 20).unwrap());
//! let dir = [0.6, -1.0, 0.8];
//! let pairwise = line_drawing(&ball, dir, HiddenLineMethod::Pairwise).unwrap();
//! let bucketed = line_drawing(&ball, dir, HiddenLineMethod::Bucketed).unwrap();
//! assert_eq!(pairwise.lines, bucketed.lines); // two methods, one drawing
//! ```

use super::lines::{Edge3, LineStats, Piece};
use super::sightline::{Exact, ExactView};
use crate::space::Cell;

/// Which hidden-line method to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HiddenLineMethod {
    /// The paper's: every segment against every earlier graphics node (quadratic).
    Pairwise,
    /// Ours: against the earlier graphics nodes in the screen buckets the segment meets.
    #[default]
    Bucketed,
}

/// The parallel projection onto the screen, used to find the graphics nodes whose projection may meet a
/// segment (the exact decision is [`ExactView::hidden_part`]'s).
#[derive(Debug, Clone)]
pub(crate) struct ScreenBoxes {
    right: [f64; 3],
    up: [f64; 3],
    /// Bounding box of the unit cube's projection: `[xmin, ymin, xmax, ymax]`.
    unit_box: [f64; 4],
    /// Every box is grown by this margin (10⁻⁹ of the universe's side), far above the rounding of the
    /// projection, so that no cube touching a segment is missed.
    margin: f64,
}

impl ScreenBoxes {
    pub(crate) fn new(right: [f64; 3], up: [f64; 3], scale: f64) -> Self {
        let mut unit_box = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for c in 0..8u32 {
            let p = [
                f64::from(c & 1),
                f64::from(c >> 1 & 1),
                f64::from(c >> 2 & 1),
            ];
            let q = [dot3(p, right), dot3(p, up)];
            unit_box[0] = unit_box[0].min(q[0]);
            unit_box[1] = unit_box[1].min(q[1]);
            unit_box[2] = unit_box[2].max(q[0]);
            unit_box[3] = unit_box[3].max(q[1]);
        }
        Self {
            right,
            up,
            unit_box,
            margin: 1e-9 * scale.max(1.0),
        }
    }

    fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [dot3(p, self.right), dot3(p, self.up)]
    }

    /// The grown screen box of a cube.
    fn of_cube(&self, cell: &Cell<3>) -> [f64; 4] {
        let s = cell.side() as f64;
        let o = self.project(cell.origin.map(f64::from));
        let m = self.margin;
        [
            o[0] + s * self.unit_box[0] - m,
            o[1] + s * self.unit_box[1] - m,
            o[0] + s * self.unit_box[2] + m,
            o[1] + s * self.unit_box[3] + m,
        ]
    }

    /// The grown screen box of a segment.
    fn of_segment(&self, seg: &Piece) -> [f64; 4] {
        let e = Edge3 {
            axis: seg.axis,
            fixed: seg.fixed,
            u0: f64::from(seg.u0),
            u1: f64::from(seg.u1),
        };
        let a = self.project(e.point(e.u0));
        let b = self.project(e.point(e.u1));
        let m = self.margin;
        [
            a[0].min(b[0]) - m,
            a[1].min(b[1]) - m,
            a[0].max(b[0]) + m,
            a[1].max(b[1]) + m,
        ]
    }
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn boxes_meet(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3]
}

/// The visible parts of one segment given its hidden parts (exact, within the segment): the gaps of
/// positive exact length between them.
fn visible_parts(seg: &Piece, hidden: &mut [(Exact, Exact)], out: &mut Vec<Edge3>) {
    let mut emit = |from: Exact, to: Exact| {
        out.push(Edge3 {
            axis: seg.axis,
            fixed: seg.fixed,
            u0: from.to_f64(),
            u1: to.to_f64(),
        });
    };
    hidden.sort_unstable_by_key(|a| a.0);
    let mut at = Exact::int(seg.u0);
    for &(h0, h1) in hidden.iter() {
        if h0 > at {
            emit(at, h0);
        }
        at = at.max(h1);
    }
    let end = Exact::int(seg.u1);
    if at < end {
        emit(at, end);
    }
}

/// Removes hidden parts of `segments` (owned by graphics nodes of `cubes`, in front-to-back order).
pub(crate) fn remove_hidden(
    cubes: &[Cell<3>],
    segments: &[Piece],
    view: &ExactView,
    screen: &ScreenBoxes,
    method: HiddenLineMethod,
    stats: &mut LineStats,
    mut progress: Option<&mut dyn FnMut(u64, u64)>,
) -> Vec<Edge3> {
    let boxes: Vec<[f64; 4]> = cubes.iter().map(|c| screen.of_cube(c)).collect();
    let total = segments.len() as u64;
    let mut out = Vec::new();
    let mut hidden: Vec<(Exact, Exact)> = Vec::new();
    let mut tests = 0u64;
    // The pairwise method tests every cube in front of a segment; the bucketed one only the cubes in the
    // screen-grid buckets the segment's box touches. Both keep the same occluders in the same order.
    let grid = (method == HiddenLineMethod::Bucketed).then(|| Grid::new(&boxes));
    let mut seen = vec![u32::MAX; if grid.is_some() { cubes.len() } else { 0 }];
    for (i, seg) in segments.iter().enumerate() {
        let bbox = screen.of_segment(seg);
        hidden.clear();
        let mut test = |cube: &Cell<3>| {
            tests += 1;
            let axis = usize::from(seg.axis);
            if let Some(h) = view.hidden_part(axis, seg.fixed, (seg.u0, seg.u1), cube) {
                hidden.push(h);
            }
        };
        match &grid {
            None => cubes[..seg.owner as usize].iter().for_each(&mut test),
            Some(grid) => {
                let (gx0, gy0, gx1, gy1) = grid.range(&bbox);
                for gy in gy0..=gy1 {
                    for gx in gx0..=gx1 {
                        for &j in &grid.buckets[gy * grid.nx + gx] {
                            if j >= seg.owner {
                                break;
                            }
                            if seen[j as usize] == i as u32 {
                                continue;
                            }
                            seen[j as usize] = i as u32;
                            if boxes_meet(&boxes[j as usize], &bbox) {
                                test(&cubes[j as usize]);
                            }
                        }
                    }
                }
            }
        }
        visible_parts(seg, &mut hidden, &mut out);
        if i % 4096 == 4095 {
            if let Some(p) = progress.as_mut() {
                p(i as u64 + 1, total);
            }
        }
    }
    if let Some(p) = progress.as_mut() {
        p(total, total);
    }
    stats.pair_tests = tests;
    out
}

/// A uniform screen grid of buckets holding graphics-node indices in increasing (front-to-back) order.
struct Grid {
    x0: f64,
    y0: f64,
    cell: f64,
    nx: usize,
    ny: usize,
    buckets: Vec<Vec<u32>>,
}

impl Grid {
    fn new(boxes: &[[f64; 4]]) -> Self {
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in boxes {
            b[0] = b[0].min(p[0]);
            b[1] = b[1].min(p[1]);
            b[2] = b[2].max(p[2]);
            b[3] = b[3].max(p[3]);
        }
        if boxes.is_empty() {
            b = [0.0, 0.0, 1.0, 1.0];
        }
        let (w, h) = ((b[2] - b[0]).max(1e-9), (b[3] - b[1]).max(1e-9));
        // About two graphics nodes per bucket, at most 2^20 buckets.
        let target = (boxes.len() as f64 / 2.0).clamp(1.0, (1u64 << 20) as f64);
        let cell = (w * h / target).sqrt().max(1e-9);
        let nx = ((w / cell).ceil() as usize).clamp(1, 4096);
        let ny = ((h / cell).ceil() as usize).clamp(1, 4096);
        let mut grid = Self {
            x0: b[0],
            y0: b[1],
            cell,
            nx,
            ny,
            buckets: vec![Vec::new(); nx * ny],
        };
        for (j, p) in boxes.iter().enumerate() {
            let (gx0, gy0, gx1, gy1) = grid.range(p);
            for gy in gy0..=gy1 {
                for gx in gx0..=gx1 {
                    grid.buckets[gy * nx + gx].push(j as u32);
                }
            }
        }
        grid
    }

    /// Inclusive bucket range met by a bounding box (clamped to the grid).
    fn range(&self, bbox: &[f64; 4]) -> (usize, usize, usize, usize) {
        let f =
            |v: f64, o: f64, n: usize| (((v - o) / self.cell).floor().max(0.0) as usize).min(n - 1);
        (
            f(bbox[0], self.x0, self.nx),
            f(bbox[1], self.y0, self.ny),
            f(bbox[2], self.x0, self.nx),
            f(bbox[3], self.y0, self.ny),
        )
    }
}
