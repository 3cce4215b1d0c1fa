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

use std::collections::HashMap;

use crate::radix;
use crate::tree::storage::TreeStorage;

use super::section::{section, Pieces, Slab};

use super::{
    face_index, link_parts, others, part_of, pinched, vertex_of, Merge, Rect, SurfaceMesh,
};

/// The boundary of `tree` as a closed, outward-oriented triangle mesh, its planes merged as `merge` says.
pub(super) fn sweep<T: TreeStorage<3>>(tree: &T, merge: Merge) -> Result<SurfaceMesh, T::Error> {
    let mut sweep = Sweep::new(tree.level(), merge);
    for_each_section(tree, |x, _, below, slab| {
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
    for_each_section(tree, |x, next, below, slab| {
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
/// one before `x`.
fn for_each_section<T: TreeStorage<3>>(
    tree: &T,
    mut step: impl FnMut(u32, u32, &Slab, &Slab),
) -> Result<(), T::Error> {
    let side = 1u32 << tree.level();
    let (mut below, mut slab) = (Slab::default(), Slab::default());
    let mut x = 0;
    loop {
        let next = if x < side {
            section(tree, x, &mut slab)?.min(side)
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

/// A T-junction kept for a rectangle's edge: its coordinate along the edge, its point's occupancy and the
/// vertex, and the next stop of the same edge (a list in a shared store; [`NONE`] ends it).
#[derive(Debug, Clone, Copy)]
struct Stop {
    along: u32,
    mask: u8,
    vertex: u32,
    next: u32,
}

/// The end of a list of [`Stop`]s.
const NONE: u32 = u32::MAX;

/// What a carried rectangle keeps from the step that opened it: its corners there (vertex and
/// occupancy, by corner number) and, by edge number, the stops of its edges met so far.
#[derive(Debug, Clone, Copy)]
struct Birth {
    corners: [(u32, u8); 4],
    edges: [u32; 4],
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

/// A lattice point of the step (`x = X`) at rectangles' corners.
#[derive(Debug, Clone, Copy)]
struct Point {
    y: u32,
    z: u32,
    /// The occupancy of the eight voxels around the point (bit `o`: octant `o`).
    mask: u8,
    /// The vertex of its first link part; the others follow in order of part.
    first_vertex: u32,
    /// The link parts of all corners here (bit set).
    parts: u8,
    /// By direction, the link parts of the corners here whose rectangle has an edge along it.
    on_lines: [u8; 3],
}

impl Point {
    /// The point's stop on an edge along `d` whose rectangle's unit face just past it is `face`, if its
    /// sheet there has a corner with an edge along `d`.
    fn stop(&self, d: usize, face: usize, along: u32) -> Option<Stop> {
        let part = link_parts()[self.mask as usize][face];
        debug_assert!(part < 4, "a rectangle's edge past a non-boundary face");
        (part < 8 && self.on_lines[d] >> part & 1 == 1).then(|| Stop {
            along,
            mask: self.mask,
            vertex: vertex_of(self.first_vertex, self.parts, part),
            next: NONE,
        })
    }
}

/// For edge `k` of a rectangle in a plane of axis `a` (from corner `k` to corner `k + 1`): its direction,
/// the other axis of the plane, the rectangle's side of the edge on that axis, and the rectangle's unit
/// face just past a point inside the edge (on the upper side along the direction).
fn edge_of(a: usize, k: usize) -> (usize, usize, usize, usize) {
    let (b, c) = others(a);
    let (d, e) = if k.is_multiple_of(2) { (b, c) } else { (c, b) };
    let e_side = usize::from(k == 0 || k == 3);
    let quadrant = if d == b {
        1 | e_side << 1
    } else {
        e_side | 1 << 1
    };
    (d, e, e_side, face_index(a, quadrant))
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

    /// The step's lattice points: the corners at `x` sorted and joined, each point's occupancy read from
    /// the two slabs' bands around it, its vertices made; and each corner's vertex.
    fn make_points(&mut self, x: u32, below: &Slab, slab: &Slab) {
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
                part_of(mask, rect.a, super::CORNER_QUADRANTS[slot as usize % 4])
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

    /// The stops strictly inside an edge along `d` (1 or 2) in the plane of the step, between the points
    /// `from` and `to`, in order along `d`, into `out`.
    fn stops_in_plane(&self, d: usize, face: usize, from: u32, to: u32, out: &mut Vec<Stop>) {
        out.clear();
        let place = |p: u32| {
            if d == 2 {
                p
            } else {
                self.place_by_z[p as usize]
            }
        };
        let (j0, j1) = (place(from), place(to));
        for j in j0.min(j1) + 1..j0.max(j1) {
            let point = if d == 2 {
                &self.points[j as usize]
            } else {
                &self.points[self.by_z[j as usize].1 as usize]
            };
            let along = if d == 2 { point.z } else { point.y };
            out.extend(point.stop(d, face, along));
        }
    }

    /// The stops at `x` of the edges along `x` of the open rectangles that go on past it.
    fn stops_along_x(&mut self, x: u32) {
        for axis in 0..2 {
            let a = axis + 1;
            // The edges along x: of a plane y = Y, edges 1 (at z = hi) and 3 (at lo); of a plane z = Z,
            // edges 0 (at y = lo) and 2 (at hi).
            let along_x: [(usize, bool); 2] = if a == 1 {
                [(1, true), (3, false)]
            } else {
                [(0, false), (2, true)]
            };
            let mut line = LineFinder::default();
            for o in &self.open[axis] {
                if o.start >= x {
                    continue;
                }
                let coord = o.plane >> 1;
                for (k, at_hi) in along_x {
                    let across = if at_hi { o.hi } else { o.lo };
                    // The line's (y, z).
                    let (y, z) = if a == 1 {
                        (coord, across)
                    } else {
                        (across, coord)
                    };
                    let Some(point) = line.find(self, a, y, z) else {
                        continue;
                    };
                    let (_, _, _, face) = edge_of(a, k);
                    if let Some(stop) = self.points[point as usize].stop(0, face, x) {
                        let birth = &mut self.births[o.id as usize];
                        let head = &mut birth.edges[k];
                        *head = push_stop(&mut self.stops, &mut self.free_stops, stop, *head);
                    }
                }
            }
        }
    }

    /// The triangles of the rectangles complete at the step; what the opened ones keep.
    fn finish_rects(&mut self) {
        for i in 0..self.rects.len() {
            let step_rect = self.rects[i];
            let rect = step_rect.rect;
            let here = |k: usize| {
                let (vertex, mask, _) = self.corners[4 * i + k];
                (vertex, mask)
            };
            let here_point = |k: usize| self.corners[4 * i + k].2;
            match step_rect.kind {
                Kind::Opened(id) => {
                    let mut birth = self.births[id as usize];
                    for &k in step_rect.corners_here() {
                        birth.corners[k] = here(k);
                    }
                    // The edge at x: edge 0 of a plane y = Y, edge 3 of a plane z = Z.
                    let k = if rect.a == 1 { 0 } else { 3 };
                    let mut stops = std::mem::take(&mut self.edge[0]);
                    let (d, _, _, face) = edge_of(rect.a, k);
                    let (from, to) = (here_point(k), here_point((k + 1) % 4));
                    // In order along the line, as the lists keep them.
                    self.stops_in_plane(d, face, from, to, &mut stops);
                    for &stop in &stops {
                        birth.edges[k] =
                            push_stop(&mut self.stops, &mut self.free_stops, stop, birth.edges[k]);
                    }
                    self.edge[0] = stops;
                    self.births[id as usize] = birth;
                }
                Kind::Whole => {
                    let corners = std::array::from_fn(here);
                    let mut edges = std::mem::take(&mut self.edge);
                    for (k, stops) in edges.iter_mut().enumerate() {
                        self.in_plane_edge(i, k, stops);
                    }
                    self.emit(&step_rect, corners, &edges);
                    self.edge = edges;
                }
                Kind::Closed(id) => {
                    let birth = self.births[id as usize];
                    let mut corners = birth.corners;
                    for &k in step_rect.corners_here() {
                        corners[k] = here(k);
                    }
                    let mut edges = std::mem::take(&mut self.edge);
                    // The edge at x: edge 2 of a plane y = Y, edge 1 of a plane z = Z; the others kept.
                    let at_x = if rect.a == 1 { 2 } else { 1 };
                    for (k, stops) in edges.iter_mut().enumerate() {
                        if k == at_x {
                            self.in_plane_edge(i, k, stops);
                        } else {
                            stops.clear();
                            self.take_stops(birth.edges[k], stops);
                            // Kept in the order met (ascending along the edge's line); in order along
                            // the edge from corner k.
                            let (d, ..) = edge_of(rect.a, k);
                            let points = &step_rect.points;
                            if points[(k + 1) % 4][d] < points[k][d] {
                                stops.reverse();
                            }
                        }
                    }
                    self.emit(&step_rect, corners, &edges);
                    self.edge = edges;
                    self.free_births.push(id);
                }
            }
        }
    }

    /// The stops of edge `k` of step rectangle `i`, an edge in the plane of the step, in order from
    /// corner `k`.
    fn in_plane_edge(&self, i: usize, k: usize, out: &mut Vec<Stop>) {
        let rect = &self.rects[i].rect;
        let (d, _, _, face) = edge_of(rect.a, k);
        debug_assert!(d != 0);
        let from = self.corners[4 * i + k].2;
        let to = self.corners[4 * i + (k + 1) % 4].2;
        self.stops_in_plane(d, face, from, to, out);
        let points = &self.rects[i].points;
        if points[(k + 1) % 4][d] < points[k][d] {
            out.reverse();
        }
    }

    /// Moves the stops of a list (pushed in order along its line, so read backwards) into `out` in order
    /// along the line, freeing the list.
    fn take_stops(&mut self, mut head: u32, out: &mut Vec<Stop>) {
        while head != NONE {
            let stop = self.stops[head as usize];
            out.push(stop);
            self.stops[head as usize].next = self.free_stops;
            self.free_stops = head;
            head = stop.next;
        }
        out.reverse();
    }

    /// The triangles of a rectangle, given its corners (vertex, occupancy) and the stops of each edge in
    /// order from its first corner.
    fn emit(&mut self, step_rect: &StepRect, corners: [(u32, u8); 4], edges: &[Vec<Stop>; 4]) {
        let (rect, points) = (&step_rect.rect, &step_rect.points);
        let (b, c) = others(rect.a);
        let mut ring = std::mem::take(&mut self.ring);
        ring.clear();
        for k in 0..4 {
            let p = points[k];
            let next = (k + 1) % 4;
            ring.push(corners[k].0);
            let (d, e, e_side, _) = edge_of(rect.a, k);
            // The full octant the rectangle bounds, as bits on the axes across the line.
            let full_side = usize::from(!rect.upper);
            let octant = (full_side << rect.a | e_side << e) as u8;
            // Along the edge: each stop, then the next corner, as (coordinate along d, occupancy, vertex).
            let ends = edges[k]
                .iter()
                .map(|s| (s.along, s.mask, Some(s.vertex)))
                .chain(std::iter::once((points[next][d], corners[next].1, None)));
            let mut prev = (p[d], corners[k].1);
            for (at, mask, vertex) in ends {
                let lower = if prev.0 < at { prev.1 } else { mask };
                if pinched(lower, d) {
                    let mut m = p.map(|x| 2 * u64::from(x));
                    m[d] = u64::from(prev.0) + u64::from(at);
                    let vertices = &mut self.mesh.vertices;
                    let id = *self.midpoints.entry((m, 16 + octant)).or_insert_with(|| {
                        vertices.push(m.map(|x| x as f64 / 2.0));
                        (vertices.len() - 1) as u32
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
        let triangles = &mut self.mesh.triangles;
        if ring.len() == 4 {
            triangles.push([ring[0], ring[1], ring[2]]);
            triangles.push([ring[0], ring[2], ring[3]]);
        } else {
            let [b0, b1, c0, c1] = rect.r;
            let mut centre = [0u64; 3];
            centre[rect.a] = 2 * u64::from(rect.coord);
            centre[b] = u64::from(b0) + u64::from(b1);
            centre[c] = u64::from(c0) + u64::from(c1);
            self.mesh.vertices.push(centre.map(|x| x as f64 / 2.0));
            let centre = (self.mesh.vertices.len() - 1) as u32;
            for j in 0..ring.len() {
                triangles.push([centre, ring[j], ring[(j + 1) % ring.len()]]);
            }
        }
        self.ring = ring;
    }
}

/// Pushes `stop` in front of the list `head` in `store` (reusing a freed entry), returning the new head.
fn push_stop(store: &mut Vec<Stop>, free: &mut u32, stop: Stop, head: u32) -> u32 {
    let stop = Stop { next: head, ..stop };
    if *free != NONE {
        let at = *free;
        *free = store[at as usize].next;
        store[at as usize] = stop;
        at
    } else {
        store.push(stop);
        (store.len() - 1) as u32
    }
}

/// Finds step points on lines along `x`, for open rectangles met in order of `(plane, lo)`: the points
/// of the plane's coordinate are found by a cursor that only moves on (the planes come in order), then
/// searched.
#[derive(Debug, Default)]
struct LineFinder {
    /// The coordinate whose points are `range`, and where the cursor is.
    coord: Option<u32>,
    range: (usize, usize),
    cursor: usize,
}

impl LineFinder {
    /// The step point at `(y, z)`, for an open rectangle of a plane of axis `a` (1: `y = Y`, points by
    /// `(y, z)`; 2: `z = Z`, points by `(z, y)`).
    fn find(&mut self, sweep: &Sweep, a: usize, y: u32, z: u32) -> Option<u32> {
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

/// The stretches along a line where exactly one of two sets of runs is full, in order, as `(z0, z1,
/// whether it is the first)`.
fn xor_runs(first: &[(u32, u32)], second: &[(u32, u32)], out: &mut Vec<(u32, u32, bool)>) {
    out.clear();
    let end_at = |runs: &[(u32, u32)], k: usize| {
        runs.get(k / 2)
            .map_or(u32::MAX, |r| if k.is_multiple_of(2) { r.0 } else { r.1 })
    };
    let (mut i, mut j) = (0, 0);
    let (mut in_first, mut in_second) = (false, false);
    let mut from = 0;
    loop {
        let (zi, zj) = (end_at(first, i), end_at(second, j));
        let z = zi.min(zj);
        if z == u32::MAX {
            break;
        }
        if in_first != in_second && z > from {
            out.push((from, z, in_first));
        }
        if zi == z {
            in_first = !in_first;
            i += 1;
        }
        if zj == z {
            in_second = !in_second;
            j += 1;
        }
        from = z;
    }
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
