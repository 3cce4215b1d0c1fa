//! The boundary of a quadtree as closed polylines.
//!
//! Each full leaf asks which leaves lie across each of its four edges ([`Neighbours::face_leaves`]); the
//! boundary pieces of each lattice line and orientation are merged into maximal segments, and the
//! segments are chained into loops, counter-clockwise around the object (clockwise around its holes).
//! Where two full pixels touch only at a corner, the corner is two vertices, one for each, so every
//! vertex has one segment in and one out and the loops never cross.
//!
//! ```
//! use ktree::export::outline::boundary_loops;
//! use ktree::KTree;
//! // Two pixels touching at a corner: two loops of four vertices.
//! let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
//! let loops = boundary_loops(&tree);
//! assert_eq!(loops.len(), 2);
//! assert!(loops.iter().all(|l| l.len() == 4));
//! ```

use std::collections::{BTreeMap, HashMap};
use std::convert::Infallible;

use crate::display::neighbours::{face_neighbour_cell, Neighbours};
use crate::space::Cell;
use crate::tree::cursor::TryLeaves;
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::NodeState;

/// A closed polyline: its vertices in order (the last joins the first), in pixel coordinates.
pub type Loop = Vec<[f64; 2]>;

/// The signed area of a loop (positive counter-clockwise).
///
/// ```
/// use ktree::export::outline::signed_area;
/// assert_eq!(signed_area(&[[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]), 2.0);
/// ```
pub fn signed_area(l: &[[f64; 2]]) -> f64 {
    (0..l.len())
        .map(|i| {
            let (p, q) = (l[i], l[(i + 1) % l.len()]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        / 2.0
}

/// The boundary of `tree` as closed loops: counter-clockwise around the object, clockwise around holes,
/// each vertex a corner of the outline (collinear pieces merged). Empty for an empty tree. (Any storage:
/// [`try_boundary_loops`].)
pub fn boundary_loops<T: TreeStorage<2, Error = Infallible>>(tree: &T) -> Vec<Loop> {
    infallible(try_boundary_loops(tree))
}

/// [`boundary_loops`] over any storage.
///
/// # Errors
/// The storage's read error.
pub fn try_boundary_loops<T: TreeStorage<2>>(tree: &T) -> Result<Vec<Loop>, T::Error> {
    let side = tree.universe().side();
    let mut near = Neighbours::new(tree)?;
    // Boundary pieces by line: (axis of the normal, coordinate, normal up the axis) → (start, length) along
    // the other axis.
    let mut lines: BTreeMap<(usize, u32, bool), Vec<(u32, u32)>> = BTreeMap::new();
    for leaf in TryLeaves::new(tree) {
        let (cell, state) = leaf?;
        if state != NodeState::Full {
            continue;
        }
        let s = cell.side() as u32;
        for a in 0..2 {
            let b = 1 - a;
            for upper in [false, true] {
                let pieces = lines
                    .entry((a, cell.origin[a] + if upper { s } else { 0 }, upper))
                    .or_default();
                match face_neighbour_cell(&cell, a, upper, side) {
                    None => pieces.push((cell.origin[b], s)),
                    Some(n) => near.face_leaves(&n, a, !upper, |leaf, state| {
                        if state == NodeState::Empty {
                            pieces.push((leaf.origin[b], leaf.side() as u32));
                        }
                    })?,
                }
            }
        }
    }
    let level = tree.level();
    let mut full = |v: [i64; 2]| -> Result<bool, T::Error> {
        if v.iter().any(|&x| x < 0 || x as u64 >= side) {
            return Ok(false);
        }
        let cell = Cell {
            origin: v.map(|x| x as u32),
            level,
            log_side: 0,
        };
        Ok(near.locate(&cell)?.state() == NodeState::Full)
    };
    // A vertex is a lattice point and, where two full pixels touch only there, the quadrant of the full
    // pixel its segments bound (bit i: on the upper side along axis i).
    let mut tag = |p: [u32; 2], quadrant: u8| -> Result<u8, T::Error> {
        let mut f = [false; 4];
        for (q, fq) in f.iter_mut().enumerate() {
            *fq = full([
                i64::from(p[0]) - 1 + (q & 1) as i64,
                i64::from(p[1]) - 1 + (q >> 1) as i64,
            ])?;
        }
        Ok(
            if f == [true, false, false, true] || f == [false, true, true, false] {
                quadrant
            } else {
                u8::MAX
            },
        )
    };
    // Directed segments from vertex to vertex.
    let mut next: HashMap<([u32; 2], u8), ([u32; 2], u8)> = HashMap::new();
    let mut order: Vec<([u32; 2], u8)> = Vec::new();
    for ((a, coord, upper), mut pieces) in lines {
        let b = 1 - a;
        pieces.sort_unstable();
        let mut merged: Vec<(u32, u32)> = Vec::new();
        for (start, len) in pieces {
            match merged.last_mut() {
                Some(last) if last.1 == start => last.1 = start + len,
                _ => merged.push((start, start + len)),
            }
        }
        let full_a = u8::from(!upper) << a;
        for (t0, t1) in merged {
            let at = |t: u32| {
                let mut p = [0; 2];
                p[a] = coord;
                p[b] = t;
                p
            };
            let (p0, p1) = (at(t0), at(t1));
            let v0 = (p0, tag(p0, full_a | 1 << b)?);
            let v1 = (p1, tag(p1, full_a)?);
            // Counter-clockwise: the object on the left. Normal +x runs +y, +y runs −x, −x runs −y, −y runs +x.
            let forward = (a == 0) == upper;
            let (from, to) = if forward { (v0, v1) } else { (v1, v0) };
            next.insert(from, to);
            order.push(from);
        }
    }
    let mut loops = Vec::new();
    for start in order {
        if !next.contains_key(&start) {
            continue;
        }
        let mut l = Vec::new();
        let mut v = start;
        while let Some(w) = next.remove(&v) {
            l.push(v.0.map(f64::from));
            v = w;
        }
        debug_assert_eq!(v, start, "an open boundary chain");
        loops.push(l);
    }
    Ok(loops)
}
