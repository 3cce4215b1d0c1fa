//! Hidden-line removal for line drawings: each segment is clipped against the projections of the graphics
//! nodes that come before its owner in the front-to-back list — exactly those that can be in front of it.
//!
//! * [`HiddenLineMethod::Pairwise`] is the paper's method (V7): every segment is tested against *every*
//!   earlier graphics node, first with Cohen–Sutherland-like bit codes (one bit per half-plane of the
//!   projected hexagon: a segment whose two end codes share a bit is outside), then by clipping. The
//!   cost is quadratic in the number of graphics nodes.
//! * [`HiddenLineMethod::Bucketed`] puts the hexagons into a screen grid once, each bucket keeping its
//!   graphics nodes in front-to-back order; a segment is tested only against the earlier nodes in the
//!   buckets its bounding box meets, each once. Same tests, same answer, a small fraction of the work.
//!
//! Projections are hexagons given by their half-planes `n_k · q ≤ c_k`; the hexagon of a cube of side `s`
//! at origin `o` is the unit cube's hexagon scaled by `s` and moved to the projection of `o`. A segment is
//! hidden where it lies strictly inside (by a tolerance of 10⁻⁹ of the universe's side) — a segment
//! on the border of a hexagon stays visible.
//!
//! ```
//! use ktree::display::{line_drawing, HiddenLineMethod};
//! use ktree::{rays::ball_rays, stacking::stack};
//! let ball = stack(&ball_rays::<3>(4, [16, 16, 16], 20).unwrap());
//! let dir = [0.6, -1.0, 0.8];
//! let pairwise = line_drawing(&ball, dir, HiddenLineMethod::Pairwise).unwrap();
//! let bucketed = line_drawing(&ball, dir, HiddenLineMethod::Bucketed).unwrap();
//! assert_eq!(pairwise.lines, bucketed.lines); // two methods, one drawing
//! ```

use super::lines::{Edge3, LineStats, Piece};
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

/// The projection of the unit cube in a parallel view: its half-planes and bounding box.
#[derive(Debug, Clone)]
pub(crate) struct Hexagon {
    right: [f64; 3],
    up: [f64; 3],
    /// Outward normals of the hull's edges.
    normals: Vec<[f64; 2]>,
    /// `n_k · q ≤ support[k]` for the unit cube at the origin.
    support: Vec<f64>,
    /// Bounding box of the unit cube's projection: `[xmin, ymin, xmax, ymax]`.
    bbox: [f64; 4],
    eps: f64,
}

impl Hexagon {
    pub(crate) fn new(right: [f64; 3], up: [f64; 3], scale: f64) -> Self {
        let mut pts: Vec<[f64; 2]> = (0..8)
            .map(|c| {
                let p = [
                    f64::from(c & 1),
                    f64::from(c >> 1 & 1),
                    f64::from(c >> 2 & 1),
                ];
                [dot3(p, right), dot3(p, up)]
            })
            .collect();
        let hull = convex_hull(&mut pts);
        let mut normals = Vec::new();
        let mut support = Vec::new();
        for i in 0..hull.len() {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            let e = [b[0] - a[0], b[1] - a[1]];
            let len = (e[0] * e[0] + e[1] * e[1]).sqrt();
            if len < 1e-12 {
                continue;
            }
            let n = [e[1] / len, -e[0] / len];
            normals.push(n);
            support.push(n[0] * a[0] + n[1] * a[1]);
        }
        let mut bbox = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in &hull {
            bbox[0] = bbox[0].min(p[0]);
            bbox[1] = bbox[1].min(p[1]);
            bbox[2] = bbox[2].max(p[0]);
            bbox[3] = bbox[3].max(p[1]);
        }
        Self {
            right,
            up,
            normals,
            support,
            bbox,
            eps: 1e-9 * scale.max(1.0),
        }
    }

    fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [dot3(p, self.right), dot3(p, self.up)]
    }
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Counter-clockwise convex hull (Andrew's monotone chain).
fn convex_hull(pts: &mut [[f64; 2]]) -> Vec<[f64; 2]> {
    pts.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 1e-15
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// A graphics node's projection: its half-plane bounds and bounding box.
struct CubeProj {
    c: Vec<f64>,
    bbox: [f64; 4],
}

fn project_cube(hex: &Hexagon, cell: &Cell<3>) -> CubeProj {
    let s = cell.side() as f64;
    let o = hex.project(cell.origin.map(f64::from));
    CubeProj {
        c: hex
            .normals
            .iter()
            .zip(&hex.support)
            .map(|(n, h)| n[0] * o[0] + n[1] * o[1] + s * h)
            .collect(),
        bbox: [
            o[0] + s * hex.bbox[0],
            o[1] + s * hex.bbox[1],
            o[0] + s * hex.bbox[2],
            o[1] + s * hex.bbox[3],
        ],
    }
}

/// The parameter interval `(t0, t1)` of the segment `a → b` strictly inside the cube's hexagon, if any.
#[inline]
fn clip(hex: &Hexagon, cube: &CubeProj, a: [f64; 2], b: [f64; 2]) -> Option<(f64, f64)> {
    let eps = hex.eps;
    // Bit codes: bit k set when an end point is outside (or on) half-plane k.
    let mut fa = [0.0f64; 8];
    let mut fb = [0.0f64; 8];
    let (mut code_a, mut code_b) = (0u8, 0u8);
    for (k, n) in hex.normals.iter().enumerate() {
        fa[k] = n[0] * a[0] + n[1] * a[1] - cube.c[k];
        fb[k] = n[0] * b[0] + n[1] * b[1] - cube.c[k];
        code_a |= u8::from(fa[k] >= -eps) << k;
        code_b |= u8::from(fb[k] >= -eps) << k;
    }
    if code_a & code_b != 0 {
        return None;
    }
    if code_a == 0 && code_b == 0 {
        return Some((0.0, 1.0));
    }
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..hex.normals.len() {
        // Inside: fa + t (fb − fa) < −eps.
        let denom = fb[k] - fa[k];
        let num = -eps - fa[k];
        if denom == 0.0 {
            if num <= 0.0 {
                return None;
            }
        } else if denom > 0.0 {
            t1 = t1.min(num / denom);
        } else {
            t0 = t0.max(num / denom);
        }
    }
    (t1 - t0 > 1e-12).then_some((t0, t1))
}

#[inline]
fn boxes_meet(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3]
}

/// The visible parts of one segment given its hidden parameter intervals.
fn visible_parts(seg: &Piece, hidden: &mut [(f64, f64)], out: &mut Vec<Edge3>) {
    let (u0, u1) = (f64::from(seg.u0), f64::from(seg.u1));
    let len = u1 - u0;
    let mut emit = |t0: f64, t1: f64| {
        if (t1 - t0) * len > 1e-7 {
            out.push(Edge3 {
                axis: seg.axis,
                fixed: seg.fixed,
                u0: u0 + t0 * len,
                u1: if t1 >= 1.0 { u1 } else { u0 + t1 * len },
            });
        }
    };
    hidden.sort_unstable_by(|a, b| a.0.partial_cmp(&b.0).expect("finite"));
    let mut at = 0.0f64;
    for &(h0, h1) in hidden.iter() {
        if h0 > at {
            emit(at, h0);
        }
        at = at.max(h1);
    }
    if at < 1.0 {
        emit(at, 1.0);
    }
}

/// Removes hidden parts of `segments` (owned by graphics nodes of `cubes`, in front-to-back order).
pub(crate) fn remove_hidden(
    cubes: &[Cell<3>],
    segments: &[Piece],
    hex: &Hexagon,
    method: HiddenLineMethod,
    stats: &mut LineStats,
    mut progress: Option<&mut dyn FnMut(u64, u64)>,
) -> Vec<Edge3> {
    let projs: Vec<CubeProj> = cubes.iter().map(|c| project_cube(hex, c)).collect();
    let total = segments.len() as u64;
    let mut out = Vec::new();
    let mut hidden: Vec<(f64, f64)> = Vec::new();
    let mut tests = 0u64;
    let ends = |seg: &Piece| {
        let e = Edge3 {
            axis: seg.axis,
            fixed: seg.fixed,
            u0: f64::from(seg.u0),
            u1: f64::from(seg.u1),
        };
        let a = hex.project(e.point(e.u0));
        let b = hex.project(e.point(e.u1));
        let bbox = [
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[0].max(b[0]),
            a[1].max(b[1]),
        ];
        (a, b, bbox)
    };
    // The pairwise method tests every cube in front of a segment; the bucketed one only the cubes in the
    // screen-grid buckets the segment's box touches. Both keep the same occluders in the same order.
    let grid = (method == HiddenLineMethod::Bucketed).then(|| Grid::new(&projs));
    let mut seen = vec![u32::MAX; if grid.is_some() { projs.len() } else { 0 }];
    for (i, seg) in segments.iter().enumerate() {
        let (a, b, bbox) = ends(seg);
        hidden.clear();
        let mut test = |cube: &CubeProj| {
            tests += 1;
            if let Some(h) = clip(hex, cube, a, b) {
                hidden.push(h);
            }
        };
        match &grid {
            None => projs[..seg.owner as usize].iter().for_each(&mut test),
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
                            let cube = &projs[j as usize];
                            if boxes_meet(&cube.bbox, &bbox) {
                                test(cube);
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
    fn new(projs: &[CubeProj]) -> Self {
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in projs {
            b[0] = b[0].min(p.bbox[0]);
            b[1] = b[1].min(p.bbox[1]);
            b[2] = b[2].max(p.bbox[2]);
            b[3] = b[3].max(p.bbox[3]);
        }
        if projs.is_empty() {
            b = [0.0, 0.0, 1.0, 1.0];
        }
        let (w, h) = ((b[2] - b[0]).max(1e-9), (b[3] - b[1]).max(1e-9));
        // About two graphics nodes per bucket, at most 2^20 buckets.
        let target = (projs.len() as f64 / 2.0).clamp(1.0, (1u64 << 20) as f64);
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
        for (j, p) in projs.iter().enumerate() {
            let (gx0, gy0, gx1, gy1) = grid.range(&p.bbox);
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
