//! The boundary mesh made by one sweep across the first axis, slab by slab (see the parent module).
//!
//! A step `X` looks at the slabs `X − 1` and `X` (cross-sections, as bands of runs along `z`), at each `X`
//! where the tree's cross-section changes:
//! 1. the boundary of the plane `x = X`, merged into rectangles along `y` at once;
//! 2. the intervals of slab `X` in the planes `y = Y` and `z = Z`, which carry the open rectangles of those
//!    planes on, close them (at `x = X`) or open new ones;
//! 3. the step's corners (all of the first kind, the two at `x = X` of each rectangle opened or closed):
//!    sorted into lattice points, each point's eight voxels read from the bands around it, its vertices
//!    made;
//! 4. the T-junctions: of the edges in the plane `x = X` among the step's points, of the open rectangles'
//!    edges along `x` at the step's points on their lines;
//! 5. the triangles of the rectangles complete at `X`.
//!
//! This file holds the driver and the rectangles (1, 2); [`points`] the step's lattice points (3),
//! [`junctions`] the T-junctions (4) and [`triangles`] the triangles (5).

mod junctions;
mod points;
mod triangles;

use std::collections::HashMap;

use crate::radix;
use crate::rays::stretches;
use crate::tree::storage::TreeStorage;

use super::section::{section, Pieces, Slab};
use super::{Merge, Rect, SurfaceMesh};
use junctions::{Birth, Stop, NONE};
use points::Point;

/// The boundary of `tree` as a closed, outward-oriented triangle mesh, its planes merged as `merge` says.
pub(super) fn sweep<T: TreeStorage<3>>(tree: &T, merge: Merge) -> Result<SurfaceMesh, T::Error> {
    let mut sweep = Sweep::new(tree.level(), merge);
    // Unit faces: a step at every x, so that rectangles across the sweep are one voxel long.
    for_each_section(tree, merge == Merge::None, |x, _, below, slab| {
        if !(below.bands.is_empty() && slab.bands.is_empty()) {
            sweep.step(x, below, slab);
        }
    })?;
    debug_assert!(sweep.open[0].is_empty() && sweep.open[1].is_empty());
    assert!(
        u32::try_from(sweep.mesh.vertices.len()).is_ok(),
        "fewer than 2^32 vertices (indices are 32-bit)"
    );
    Ok(sweep.mesh)
}

/// The number of unit faces on the boundary of `tree`, counted on its cross-sections as [`sweep`] meets
/// them (nothing is made).
pub(super) fn unit_faces<T: TreeStorage<3>>(tree: &T) -> Result<u128, T::Error> {
    let mut xor = Vec::new();
    let mut faces = 0u128;
    let length = |runs: &[(u32, u32)]| runs.iter().map(|r| u128::from(r.1 - r.0)).sum::<u128>();
    for_each_section(tree, false, |x, next, below, slab| {
        // The plane x = X.
        for (y, end, lower, upper) in Pieces::new(below, slab) {
            xor_runs(lower, upper, &mut xor);
            let stretch: u128 = xor.iter().map(|s| u128::from(s.1 - s.0)).sum();
            faces += u128::from(end - y) * stretch;
        }
        // The planes y = Y and z = Z through the slab, for each voxel of its thickness.
        let mut across = 0u128;
        for (k, band) in slab.bands.iter().enumerate() {
            let runs = slab.runs_of(band);
            across += 2 * runs.len() as u128 * u128::from(band.y1 - band.y0);
            let before = match k.checked_sub(1).map(|p| &slab.bands[p]) {
                Some(p) if p.y1 == band.y0 => slab.runs_of(p),
                _ => &[],
            };
            xor_runs(before, runs, &mut xor);
            across += xor.iter().map(|s| u128::from(s.1 - s.0)).sum::<u128>();
            if slab.bands.get(k + 1).is_none_or(|n| n.y0 != band.y1) {
                across += length(runs);
            }
        }
        faces += across * u128::from(next - x);
    })?;
    Ok(faces)
}

/// Calls `step(x, next, below, slab)` at each `x` where the cross-section of `tree` changes, in order, and
/// at the universe's side (`slab` empty there): `slab` is the section from `x` up to `next`, `below` the
/// one before `x`. At every `x` when `unit`.
fn for_each_section<T: TreeStorage<3>>(
    tree: &T,
    unit: bool,
    mut step: impl FnMut(u32, u32, &Slab, &Slab),
) -> Result<(), T::Error> {
    let side = 1u32 << tree.level();
    let (mut below, mut slab) = (Slab::default(), Slab::default());
    let mut x = 0;
    loop {
        let next = if x < side {
            let next = section(tree, x, &mut slab)?.min(side);
            if unit {
                next.min(x + 1)
            } else {
                next
            }
        } else {
            slab.clear();
            side
        };
        step(x, next, &below, &slab);
        if x >= side {
            return Ok(());
        }
        std::mem::swap(&mut below, &mut slab);
        x = next;
    }
}

/// A rectangle of a plane `y = Y` or `z = Z` while the sweep carries it: its plane (`2 · coordinate +
/// upper`), its interval `[lo, hi)` across the sweep, where it started, and its entry in the stores of
/// [`Sweep::births`].
#[derive(Debug, Clone, Copy)]
struct Open {
    plane: u32,
    lo: u32,
    hi: u32,
    start: u32,
    id: u32,
}

/// A rectangle that has corners at the step: made whole there (the plane `x = X`), opened or closed.
#[derive(Debug, Clone, Copy)]
struct StepRect {
    rect: Rect,
    /// Its corners ([`Rect::corners`]).
    points: [[u32; 3]; 4],
    kind: Kind,
}

impl StepRect {
    fn new(rect: Rect, kind: Kind) -> Self {
        StepRect {
            rect,
            points: rect.corners(),
            kind,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// In the plane `x = X`: all four corners at the step.
    Whole,
    /// Opened at the step, with its entry in the stores.
    Opened(u32),
    /// Closed at the step, with its entry in the stores.
    Closed(u32),
}

impl StepRect {
    /// The numbers of its corners at the step (`x = X`).
    fn corners_here(&self) -> &'static [usize] {
        match (self.rect.a, self.kind) {
            (0, _) => &[0, 1, 2, 3],
            // A plane y = Y: (b, c) = (z, x), so corners 0 and 1 are at x0, 2 and 3 at x1.
            (1, Kind::Opened(_)) => &[0, 1],
            (1, _) => &[2, 3],
            // A plane z = Z: (b, c) = (x, y), so corners 0 and 3 are at x0, 1 and 2 at x1.
            (_, Kind::Opened(_)) => &[0, 3],
            _ => &[1, 2],
        }
    }
}

/// The sweep's state and buffers.
struct Sweep {
    level: u32,
    merge: Merge,
    mesh: SurfaceMesh,
    /// The open rectangles of the planes `y = Y` (0) and `z = Z` (1), by `(plane, lo)`.
    open: [Vec<Open>; 2],
    births: Vec<Birth>,
    free_births: Vec<u32>,
    stops: Vec<Stop>,
    free_stops: u32,
    /// Midpoints of segments where two solids touch, by doubled position and the full octant bounded.
    midpoints: HashMap<([u64; 3], u8), u32>,
    // Buffers, kept between steps.
    rects: Vec<StepRect>,
    xor: Vec<(u32, u32, bool)>,
    row: Vec<(u32, u32, u32)>,
    intervals: [Vec<(u32, u32, u32)>; 2],
    ends: Vec<(u32, u32, u32)>,
    ends_scratch: Vec<(u32, u32, u32)>,
    next: Vec<Open>,
    closed: Vec<Open>,
    opened: Vec<usize>,
    open_x: Vec<Open>,
    keys: Vec<(u64, u32)>,
    keys_scratch: Vec<(u64, u32)>,
    points: Vec<Point>,
    /// Each corner of the step's rectangles (at `4i + k`): vertex, occupancy and point.
    corners: Vec<(u32, u8, u32)>,
    /// The step's points by `(z, y)`, and each point's place in that order.
    by_z: Vec<(u64, u32)>,
    place_by_z: Vec<u32>,
    edge: [Vec<Stop>; 4],
    ring: Vec<u32>,
}

impl Sweep {
    fn new(level: u32, merge: Merge) -> Self {
        Self {
            level,
            merge,
            mesh: SurfaceMesh::default(),
            open: [Vec::new(), Vec::new()],
            births: Vec::new(),
            free_births: Vec::new(),
            stops: Vec::new(),
            free_stops: NONE,
            midpoints: HashMap::new(),
            rects: Vec::new(),
            xor: Vec::new(),
            row: Vec::new(),
            intervals: [Vec::new(), Vec::new()],
            ends: Vec::new(),
            ends_scratch: Vec::new(),
            next: Vec::new(),
            closed: Vec::new(),
            opened: Vec::new(),
            open_x: Vec::new(),
            keys: Vec::new(),
            keys_scratch: Vec::new(),
            points: Vec::new(),
            corners: Vec::new(),
            by_z: Vec::new(),
            place_by_z: Vec::new(),
            edge: [Vec::new(), Vec::new(), Vec::new(), Vec::new()],
            ring: Vec::new(),
        }
    }

    /// One step: the slabs `x − 1` (`below`) and `x` (`slab`).
    fn step(&mut self, x: u32, below: &Slab, slab: &Slab) {
        self.rects.clear();
        self.plane_x(x, below, slab);
        self.intervals_y(slab);
        self.intervals_z(slab);
        for axis in 0..2 {
            self.carry_open(axis, x);
        }
        self.make_points(x, below, slab);
        self.stops_along_x(x);
        self.finish_rects();
    }

    /// The rectangles of the plane `x = X`: the stretches where exactly one of the two slabs is full,
    /// merged along `y`.
    fn plane_x(&mut self, x: u32, below: &Slab, slab: &Slab) {
        self.open_x.clear();
        // Where the rows carried so far end.
        let mut carried: Option<u32> = None;
        for (y, end, lower, upper) in Pieces::new(below, slab) {
            if let Some(at) = carried.filter(|&at| at != y) {
                self.row.clear();
                self.carry_x(x, at);
            }
            xor_runs(lower, upper, &mut self.xor);
            fill_row(&self.xor, self.merge, &mut self.row);
            match self.merge {
                Merge::Rectangles => self.carry_x(x, y),
                Merge::None => {
                    for row in y..end {
                        self.carry_x(x, row);
                    }
                }
            }
            carried = Some(end);
        }
        if let Some(at) = carried {
            self.row.clear();
            self.carry_x(x, at);
        }
    }

    /// Carries the plane `x = X`'s open rectangles across the row at `y` (`self.row`), making the closed
    /// ones whole.
    fn carry_x(&mut self, x: u32, y: u32) {
        self.closed.clear();
        self.opened.clear();
        carry(
            &mut self.open_x,
            &self.row,
            y,
            self.merge,
            &mut self.next,
            &mut self.closed,
            &mut self.opened,
        );
        for r in &self.closed {
            self.rects.push(StepRect::new(
                Rect {
                    a: 0,
                    coord: x,
                    upper: r.plane == 1,
                    r: [r.start, y, r.lo, r.hi],
                },
                Kind::Whole,
            ));
        }
    }

    /// The intervals (along `z`) of the slab's boundary in the planes `y = Y`, by `(plane, lo)`.
    fn intervals_y(&mut self, slab: &Slab) {
        let mut out = std::mem::take(&mut self.intervals[0]);
        out.clear();
        for (k, band) in slab.bands.iter().enumerate() {
            let below = match k.checked_sub(1).map(|p| &slab.bands[p]) {
                Some(p) if p.y1 == band.y0 => slab.runs_of(p),
                _ => &[],
            };
            self.plane_y_row(band.y0, below, slab.runs_of(band), &mut out);
            if slab.bands.get(k + 1).is_none_or(|n| n.y0 != band.y1) {
                self.plane_y_row(band.y1, slab.runs_of(band), &[], &mut out);
            }
        }
        self.intervals[0] = out;
    }

    /// The intervals of the plane `y = Y` between the columns `below` (at `Y − 1`) and `above`.
    fn plane_y_row(
        &mut self,
        y: u32,
        below: &[(u32, u32)],
        above: &[(u32, u32)],
        out: &mut Vec<(u32, u32, u32)>,
    ) {
        xor_runs(below, above, &mut self.xor);
        fill_row(&self.xor, self.merge, &mut self.row);
        out.extend(
            self.row
                .iter()
                .map(|&(upper, lo, hi)| (2 * y + upper, lo, hi)),
        );
    }

    /// The intervals (along `y`) of the slab's boundary in the planes `z = Z`, by `(plane, lo)`: the runs'
    /// ends, sorted by plane (stably: the bands come by `y`) and joined where `y` goes on.
    fn intervals_z(&mut self, slab: &Slab) {
        self.ends.clear();
        for band in &slab.bands {
            for &(z0, z1) in slab.runs_of(band) {
                self.ends.push((2 * z0, band.y0, band.y1));
                self.ends.push((2 * z1 + 1, band.y0, band.y1));
            }
        }
        radix::sort_by_key(
            &mut self.ends,
            self.level + 2,
            &mut self.ends_scratch,
            |e| u64::from(e.0),
        );
        let out = &mut self.intervals[1];
        out.clear();
        for &(plane, y0, y1) in &self.ends {
            match self.merge {
                Merge::Rectangles => match out.last_mut() {
                    Some(last) if last.0 == plane && last.2 == y0 => last.2 = y1,
                    _ => out.push((plane, y0, y1)),
                },
                Merge::None => out.extend((y0..y1).map(|y| (plane, y, y + 1))),
            }
        }
    }

    /// Carries the open rectangles of the planes `y = Y` (`axis` 0) or `z = Z` (1) across the slab's
    /// intervals at `x`: the closed and opened ones become step rectangles.
    fn carry_open(&mut self, axis: usize, x: u32) {
        self.closed.clear();
        self.opened.clear();
        carry(
            &mut self.open[axis],
            &self.intervals[axis],
            x,
            self.merge,
            &mut self.next,
            &mut self.closed,
            &mut self.opened,
        );
        let a = axis + 1;
        let rect = |o: &Open, end: u32| {
            let (coord, upper) = (o.plane >> 1, o.plane & 1 == 1);
            // A plane y = Y has (b, c) = (z, x); a plane z = Z has (b, c) = (x, y).
            let r = if a == 1 {
                [o.lo, o.hi, o.start, end]
            } else {
                [o.start, end, o.lo, o.hi]
            };
            Rect { a, coord, upper, r }
        };
        for o in &self.closed {
            self.rects
                .push(StepRect::new(rect(o, x), Kind::Closed(o.id)));
        }
        for &at in &self.opened {
            let fresh = Birth {
                corners: [(0, 0); 4],
                edges: [NONE; 4],
            };
            let id = match self.free_births.pop() {
                Some(id) => {
                    self.births[id as usize] = fresh;
                    id
                }
                None => {
                    self.births.push(fresh);
                    (self.births.len() - 1) as u32
                }
            };
            let o = &mut self.open[axis][at];
            o.id = id;
            // Its end is not known yet: x + 1 stands in (only its corners at x are read).
            self.rects
                .push(StepRect::new(rect(o, x + 1), Kind::Opened(id)));
        }
    }
}

/// The stretches along a line where exactly one of two sets of runs is full, in order, as `(z0, z1,
/// whether it is the first)`: the one merge's [`stretches`] where the memberships differ.
fn xor_runs(first: &[(u32, u32)], second: &[(u32, u32)], out: &mut Vec<(u32, u32, bool)>) {
    out.clear();
    out.extend(
        stretches(first, second)
            .filter(|s| s.first != s.second)
            .map(|s| (s.z1, s.z2, s.first)),
    );
}

/// A row's intervals `(upper, lo, hi)` by `(upper, lo)` from the stretches of [`xor_runs`] (`upper`: the
/// first set, the one below, is full), split into unit intervals unless merging.
fn fill_row(xor: &[(u32, u32, bool)], merge: Merge, row: &mut Vec<(u32, u32, u32)>) {
    row.clear();
    for upper in [false, true] {
        for &(lo, hi, first) in xor.iter().filter(|s| s.2 == upper) {
            let upper = u32::from(first);
            match merge {
                Merge::Rectangles => row.push((upper, lo, hi)),
                Merge::None => row.extend((lo..hi).map(|z| (upper, z, z + 1))),
            }
        }
    }
}

/// Carries open rectangles (`open`, by `(plane, lo)`) across the intervals `now` (the same order) met at
/// `at`: an open rectangle whose interval is met again goes on (when merging), the others are closed
/// (appended to `closed`), and each interval not carried on opens a rectangle started at `at` (its place in
/// the new `open` appended to `opened`).
fn carry(
    open: &mut Vec<Open>,
    now: &[(u32, u32, u32)],
    at: u32,
    merge: Merge,
    next: &mut Vec<Open>,
    closed: &mut Vec<Open>,
    opened: &mut Vec<usize>,
) {
    next.clear();
    let mut i = 0;
    for &(plane, lo, hi) in now {
        while i < open.len() && (open[i].plane, open[i].lo) < (plane, lo) {
            closed.push(open[i]);
            i += 1;
        }
        let same = open
            .get(i)
            .is_some_and(|o| (o.plane, o.lo, o.hi) == (plane, lo, hi));
        if same && merge == Merge::Rectangles {
            next.push(open[i]);
            i += 1;
        } else {
            opened.push(next.len());
            next.push(Open {
                plane,
                lo,
                hi,
                start: at,
                id: NONE,
            });
        }
    }
    closed.extend_from_slice(&open[i..]);
    std::mem::swap(open, next);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_faces_are_the_surface_area() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        for round in 0..30 {
            // Aligned blocks of every size, added and cut out.
            let tree = super::super::random_blocks(4, &mut state, 8, true);
            assert_eq!(unit_faces(&tree), Ok(tree.surface_area()), "round {round}");
        }
        // The full universe at the largest level, counted without a run per column.
        let full = crate::KTree::<3>::full(21).unwrap();
        assert_eq!(unit_faces(&full), Ok(6 << 42));
    }

    #[test]
    fn xor_of_runs_is_where_one_is_full() {
        let mut out = Vec::new();
        xor_runs(&[(0, 5), (8, 10)], &[(3, 9)], &mut out);
        assert_eq!(out, vec![(0, 3, true), (5, 8, false), (9, 10, true)]);
        xor_runs(&[], &[(2, 4)], &mut out);
        assert_eq!(out, vec![(2, 4, false)]);
        xor_runs(&[(0, 4)], &[(0, 4)], &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn rectangles_carry_on_while_their_interval_stays() {
        let (mut open, mut next, mut closed, mut opened) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let rows: [&[(u32, u32, u32)]; 3] = [&[(0, 0, 4), (1, 5, 6)], &[(0, 0, 4)], &[(0, 0, 3)]];
        for (y, row) in rows.into_iter().enumerate() {
            carry(
                &mut open,
                row,
                y as u32,
                Merge::Rectangles,
                &mut next,
                &mut closed,
                &mut opened,
            );
        }
        carry(
            &mut open,
            &[],
            3,
            Merge::Rectangles,
            &mut next,
            &mut closed,
            &mut opened,
        );
        let spans: Vec<(u32, u32, u32)> = closed.iter().map(|o| (o.lo, o.hi, o.start)).collect();
        // (5, 6) closes at row 1, (0, 4) at row 2, (0, 3) at the end.
        assert_eq!(spans, vec![(5, 6, 0), (0, 4, 0), (0, 3, 2)]);
        assert_eq!(opened.len(), 3);
    }
}
