//! The step's lattice points: the corners of the step's rectangles at `x = X`, sorted and joined into
//! points, each point's eight voxels read from the bands of the two slabs around it, its vertices made
//! (one for each part of its link); and the search for the points on the lines of the open rectangles' edges.

use super::super::section::Slab;
use super::super::{others, part_of, vertex_of, CORNER_QUADRANTS};
use super::Sweep;
use crate::radix;

/// A lattice point of the step (`x = X`) at rectangles' corners.
#[derive(Debug, Clone, Copy)]
pub(super) struct Point {
    pub(super) y: u32,
    pub(super) z: u32,
    /// The occupancy of the eight voxels around the point (bit `o`: octant `o`).
    pub(super) mask: u8,
    /// The vertex of its first link part; the others follow in order of part.
    pub(super) first_vertex: u32,
    /// The link parts of all corners here (bit set).
    pub(super) parts: u8,
    /// By direction, the link parts of the corners here whose rectangle has an edge along it.
    pub(super) on_lines: [u8; 3],
}

impl Sweep {
    /// The step's lattice points: the corners at `x` sorted and joined, each point's occupancy read from
    /// the two slabs' bands around it, its vertices made; and each corner's vertex.
    pub(super) fn make_points(&mut self, x: u32, below: &Slab, slab: &Slab) {
        let width = self.level + 1;
        self.keys.clear();
        for (i, step_rect) in self.rects.iter().enumerate() {
            for &k in step_rect.corners_here() {
                let p = step_rect.points[k];
                debug_assert_eq!(p[0], x);
                self.keys.push((
                    u64::from(p[1]) << width | u64::from(p[2]),
                    (4 * i + k) as u32,
                ));
            }
        }
        radix::sort_by_key(&mut self.keys, 2 * width, &mut self.keys_scratch, |k| k.0);
        self.points.clear();
        self.corners.clear();
        self.corners.resize(4 * self.rects.len(), (0, 0, 0));
        let mut around = Around::default();
        let mut start = 0;
        while start < self.keys.len() {
            let key = self.keys[start].0;
            let end = start
                + self.keys[start..]
                    .iter()
                    .position(|k| k.0 != key)
                    .unwrap_or(self.keys.len() - start);
            let (y, z) = ((key >> width) as u32, (key & ((1 << width) - 1)) as u32);
            let mask = around.mask(below, slab, y, z);
            let part = |slot: u32| {
                let rect = &self.rects[slot as usize / 4].rect;
                part_of(mask, rect.a, CORNER_QUADRANTS[slot as usize % 4])
            };
            let mut on_lines = [0u8; 3];
            for &(_, slot) in &self.keys[start..end] {
                let (b, c) = others(self.rects[slot as usize / 4].rect.a);
                let bit = 1 << part(slot);
                on_lines[b] |= bit;
                on_lines[c] |= bit;
            }
            let parts = on_lines[0] | on_lines[1] | on_lines[2];
            let first_vertex = self.mesh.vertices.len() as u32;
            let at = [f64::from(x), f64::from(y), f64::from(z)];
            self.mesh
                .vertices
                .extend(std::iter::repeat_n(at, parts.count_ones() as usize));
            let index = self.points.len() as u32;
            for &(_, slot) in &self.keys[start..end] {
                self.corners[slot as usize] =
                    (vertex_of(first_vertex, parts, part(slot)), mask, index);
            }
            self.points.push(Point {
                y,
                z,
                mask,
                first_vertex,
                parts,
                on_lines,
            });
            start = end;
        }
        // The points by (z, y), for the lines along y.
        self.by_z.clear();
        self.by_z.extend(
            self.points
                .iter()
                .enumerate()
                .map(|(i, p)| (u64::from(p.z) << width | u64::from(p.y), i as u32)),
        );
        radix::sort_by_key(&mut self.by_z, 2 * width, &mut self.keys_scratch, |k| k.0);
        self.place_by_z.clear();
        self.place_by_z.resize(self.points.len(), 0);
        for (j, &(_, i)) in self.by_z.iter().enumerate() {
            self.place_by_z[i as usize] = j as u32;
        }
    }
}

/// Finds step points on lines along `x`, for open rectangles met in order of `(plane, lo)`: the points
/// of the plane's coordinate are found by a cursor that only moves on (the planes come in order), then
/// searched.
#[derive(Debug, Default)]
pub(super) struct LineFinder {
    /// The coordinate whose points are `range`, and where the cursor is.
    coord: Option<u32>,
    range: (usize, usize),
    cursor: usize,
}

impl LineFinder {
    /// The step point at `(y, z)`, for an open rectangle of a plane of axis `a` (1: `y = Y`, points by
    /// `(y, z)`; 2: `z = Z`, points by `(z, y)`).
    pub(super) fn find(&mut self, sweep: &Sweep, a: usize, y: u32, z: u32) -> Option<u32> {
        let (major, minor) = if a == 1 { (y, z) } else { (z, y) };
        let n = sweep.points.len();
        let point = |j: usize| {
            if a == 1 {
                j
            } else {
                sweep.by_z[j].1 as usize
            }
        };
        let keys = |j: usize| {
            let p = &sweep.points[point(j)];
            if a == 1 {
                (p.y, p.z)
            } else {
                (p.z, p.y)
            }
        };
        if self.coord != Some(major) {
            while self.cursor < n && keys(self.cursor).0 < major {
                self.cursor += 1;
            }
            let mut end = self.cursor;
            while end < n && keys(end).0 == major {
                end += 1;
            }
            self.coord = Some(major);
            self.range = (self.cursor, end);
        }
        let (mut lo, mut hi) = self.range;
        while lo < hi {
            let mid = (lo + hi) / 2;
            match keys(mid).1.cmp(&minor) {
                std::cmp::Ordering::Less => lo = mid + 1,
                std::cmp::Ordering::Greater => hi = mid,
                std::cmp::Ordering::Equal => return Some(point(mid) as u32),
            }
        }
        None
    }
}

/// The occupancy of the eight voxels around the step's points, from the columns `(x − 1 | x, y − 1 | y)`,
/// found by cursors that only move on (the points come by `y`).
#[derive(Debug, Default)]
struct Around {
    /// Cursors into the slabs below and at `x`, for `y − 1` and `y`.
    cursors: [usize; 4],
}

impl Around {
    fn mask(&mut self, below: &Slab, slab: &Slab, y: u32, z: u32) -> u8 {
        let mut mask = 0u8;
        // Octant bit 0: x side, bit 1: y side, bit 2: z side.
        for (i, (slab, y_side)) in [(below, 0), (below, 1), (slab, 0), (slab, 1)]
            .into_iter()
            .enumerate()
        {
            let Some(want) = (y + y_side).checked_sub(1) else {
                continue;
            };
            let cursor = &mut self.cursors[i];
            while slab.bands.get(*cursor).is_some_and(|b| b.y1 <= want) {
                *cursor += 1;
            }
            let Some(band) = slab.bands.get(*cursor).filter(|b| b.y0 <= want) else {
                continue;
            };
            let (lower, upper) = full_around(slab.runs_of(band), z);
            let x_side = i / 2;
            let octant = x_side | (y_side as usize) << 1;
            mask |= u8::from(lower) << octant | u8::from(upper) << (octant | 4);
        }
        mask
    }
}

/// Whether voxels `z − 1` and `z` of a column with runs `runs` (sorted, disjoint, not touching) are full.
fn full_around(runs: &[(u32, u32)], z: u32) -> (bool, bool) {
    // The first run ending at or after z: the only one that may hold z − 1 or z.
    let i = runs.partition_point(|r| r.1 < z);
    match runs.get(i) {
        Some(&(a, b)) => (a < z, a <= z && z < b),
        None => (false, false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voxels_either_side_of_a_lattice_point() {
        let runs = [(2, 4), (6, 7)];
        let got: Vec<(bool, bool)> = (0..9).map(|z| full_around(&runs, z)).collect();
        let dense = |z: i64| {
            runs.iter()
                .any(|r| i64::from(r.0) <= z && z < i64::from(r.1))
        };
        let want: Vec<(bool, bool)> = (0..9).map(|z| (dense(z - 1), dense(z))).collect();
        assert_eq!(got, want);
    }
}
