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
use crate::tree::valued::ValueStorage;

use super::section::{section, value_section, Band, Pieces, Slab};
use super::{Merge, Rect, SurfaceMesh};
use junctions::{Birth, Stop, NONE};
use points::Point;

/// The boundary of `tree` as a closed, outward-oriented triangle mesh, its planes merged as `merge` says.
pub(super) fn sweep<T: TreeStorage<3>>(tree: &T, merge: Merge) -> Result<SurfaceMesh, T::Error> {
    let mut sweep = Sweep::new(tree.level(), merge, None);
    // Unit faces: a step at every x, so that rectangles across the sweep are one voxel long.
    let read = |x: u32, slab: &mut Slab| section(tree, x, slab);
    for_each_section(
        tree.level(),
        merge == Merge::None,
        read,
        |x, _, below, slab| {
            if !(below.bands.is_empty() && slab.bands.is_empty()) {
                sweep.step(x, below, slab, None);
            }
        },
    )?;
    Ok(sweep.finish().0)
}

/// The boundary of the voxels of each colour of a tree with values (`colour_of` numbers its values
/// `0 .. colours`), each a closed, outward-oriented triangle mesh whose rectangles are merged as far
/// as one colour (or nothing) lies behind each, with the colour behind each triangle ([`NOTHING`]: no
/// voxel of a colour): one sweep of the tree's sections, split by colour.
///
/// A colour is swept only while it is in one of the two sections of a step: its sweep starts when the
/// colour appears and ends with the first section without it, its mesh kept (a later appearance, after
/// a gap of at least one section, shares no vertex with it and is appended). So the memory is that of
/// the colours of two sections, not of all colours, and a step visits only the colours it meets.
pub(super) fn sweep_colours<T: ValueStorage<3>>(
    tree: &T,
    colour_of: impl Fn(T::Value) -> u32,
    colours: usize,
) -> Result<Vec<(SurfaceMesh, Vec<u32>)>, T::Error> {
    let level = tree.level();
    let mut meshes: Vec<(SurfaceMesh, Vec<u32>)> = vec![Default::default(); colours];
    let mut sweeping: Vec<Option<Box<ColourSweep>>> = (0..colours).map(|_| None).collect();
    // Sweeps done with, their buffers kept for the next colour to appear.
    let mut spare: Vec<Box<ColourSweep>> = Vec::new();
    // The colours of the section below the step, and of the step's section.
    let (mut below, mut here): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    let read = |x: u32, out: &mut Slab| value_section(tree, x, out, &colour_of);
    for_each_section(level, false, read, |x, _, coloured_below, coloured| {
        here.clear();
        for band in &coloured.bands {
            for (&run, &c) in coloured.runs_of(band).iter().zip(coloured.colours_of(band)) {
                let state = sweeping[c as usize].get_or_insert_with(|| match spare.pop() {
                    Some(mut reused) => {
                        reused.sweep.colour = c;
                        reused
                    }
                    None => ColourSweep::new(level, c),
                });
                if state.slab.bands.is_empty() {
                    here.push(c);
                }
                state.slab.push_run(band, run, c);
            }
        }
        let sections = Some([coloured_below, coloured]);
        // The colours below step once each; one not here is then done until it appears again.
        for &c in &below {
            let slot = &mut sweeping[c as usize];
            let state = slot.as_mut().expect("a colour below is swept");
            state.sweep.step(x, &state.below, &state.slab, sections);
            if state.slab.bands.is_empty() {
                let mut done = slot.take().expect("a colour below is swept");
                append(&mut meshes[c as usize], done.sweep.take_mesh());
                done.below.clear();
                spare.push(done);
            }
        }
        // The colours here step too when they were not below; each section then moves down.
        for &c in &here {
            let state = sweeping[c as usize]
                .as_mut()
                .expect("a colour here is swept");
            if state.below.bands.is_empty() {
                state.sweep.step(x, &state.below, &state.slab, sections);
            }
            std::mem::swap(&mut state.below, &mut state.slab);
            state.slab.clear();
        }
        std::mem::swap(&mut below, &mut here);
    })?;
    debug_assert!(sweeping.iter().all(Option::is_none));
    Ok(meshes)
}

/// The sweep of one colour's voxels and its slabs below and at the step.
struct ColourSweep {
    sweep: Sweep,
    below: Slab,
    slab: Slab,
}

impl ColourSweep {
    fn new(level: u32, colour: u32) -> Box<Self> {
        Box::new(ColourSweep {
            sweep: Sweep::new(level, Merge::Rectangles, Some(colour)),
            below: Slab::default(),
            slab: Slab::default(),
        })
    }
}

/// Appends the mesh `more` (and the colours behind its triangles) to `mesh`; no vertex is shared.
fn append(mesh: &mut (SurfaceMesh, Vec<u32>), more: (SurfaceMesh, Vec<u32>)) {
    if mesh.0.vertices.is_empty() {
        *mesh = more;
        return;
    }
    let offset = mesh.0.vertices.len() as u32;
    let (m, behind) = more;
    mesh.0.vertices.extend(m.vertices);
    assert!(
        u32::try_from(mesh.0.vertices.len()).is_ok(),
        "fewer than 2^32 vertices (indices are 32-bit)"
    );
    mesh.0
        .triangles
        .extend(m.triangles.into_iter().map(|t| t.map(|v| v + offset)));
    mesh.1.extend(behind);
}

/// The number of unit faces on the boundary of `tree`, counted on its cross-sections as [`sweep`] meets
/// them (nothing is made).
pub(super) fn unit_faces<T: TreeStorage<3>>(tree: &T) -> Result<u128, T::Error> {
    let mut xor = Vec::new();
    let mut faces = 0u128;
    let length = |runs: &[(u32, u32)]| runs.iter().map(|r| u128::from(r.1 - r.0)).sum::<u128>();
    let read = |x: u32, slab: &mut Slab| section(tree, x, slab);
    for_each_section(tree.level(), false, read, |x, next, below, slab| {
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

/// Calls `step(x, next, below, slab)` at each `x` where the cross-section of a tree at `level` changes,
/// in order, and at the universe's side (`slab` empty there): `slab` is the section from `x` up to
/// `next`, as `read(x, slab)` reads it (returning where it may next change), `below` the one before `x`.
/// At every `x` when `unit`.
fn for_each_section<E>(
    level: u32,
    unit: bool,
    mut read: impl FnMut(u32, &mut Slab) -> Result<u32, E>,
    mut step: impl FnMut(u32, u32, &Slab, &Slab),
) -> Result<(), E> {
    let side = 1u32 << level;
    let (mut below, mut slab) = (Slab::default(), Slab::default());
    let mut x = 0;
    loop {
        let next = if x < side {
            let next = read(x, &mut slab)?.min(side);
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

/// An interval of a row of a plane's boundary: `(plane, lo, hi, colour)` — its plane (`2 · coordinate +
/// upper`: `upper` when the solid is on the lower side), its stretch `[lo, hi)` and the colour behind it
/// (0 for a binary tree; [`NOTHING`] where no voxel of a colour is).
type Interval = (u32, u32, u32, u32);

/// The colour behind a face with no voxel of a colour behind it.
pub(super) const NOTHING: u32 = u32::MAX;

/// A rectangle of a plane `y = Y` or `z = Z` while the sweep carries it: its plane (`2 · coordinate +
/// upper`), its interval `[lo, hi)` across the sweep and the colour behind it, where it started, and its
/// entry in the stores of [`Sweep::births`].
#[derive(Debug, Clone, Copy)]
struct Open {
    plane: u32,
    lo: u32,
    hi: u32,
    colour: u32,
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
    /// The colour behind it.
    colour: u32,
}

impl StepRect {
    fn new(rect: Rect, kind: Kind, colour: u32) -> Self {
        StepRect {
            rect,
            points: rect.corners(),
            kind,
            colour,
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
    /// The colour of the solid, when the sweep reads coloured sections.
    colour: u32,
    mesh: SurfaceMesh,
    /// The colour behind each triangle made, when the sweep reads coloured sections.
    behind: Option<Vec<u32>>,
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
    row: Vec<Interval>,
    intervals: [Vec<Interval>; 2],
    ends: Vec<Interval>,
    ends_scratch: Vec<Interval>,
    /// The solid's runs of the two slabs' bands, read from coloured sections.
    solid: [Vec<(u32, u32)>; 2],
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
    /// A sweep of a binary tree's sections (`colour` none) or of the voxels of colour `colour` in a
    /// tree's coloured sections.
    fn new(level: u32, merge: Merge, colour: Option<u32>) -> Self {
        Self {
            level,
            merge,
            colour: colour.unwrap_or(0),
            mesh: SurfaceMesh::default(),
            behind: colour.map(|_| Vec::new()),
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
            solid: [Vec::new(), Vec::new()],
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

    /// The mesh made and the colour behind each triangle (none for a binary tree), when the sweep is
    /// done.
    fn finish(mut self) -> (SurfaceMesh, Vec<u32>) {
        assert!(
            u32::try_from(self.mesh.vertices.len()).is_ok(),
            "fewer than 2^32 vertices (indices are 32-bit)"
        );
        self.take_mesh()
    }

    /// The mesh made and the colour behind each triangle, taken out when every rectangle is closed: the
    /// sweep starts again with an empty mesh (for a solid that shares no vertex with the one so far),
    /// keeping its buffers.
    fn take_mesh(&mut self) -> (SurfaceMesh, Vec<u32>) {
        debug_assert!(self.open[0].is_empty() && self.open[1].is_empty());
        self.births.clear();
        self.free_births.clear();
        self.stops.clear();
        self.free_stops = NONE;
        self.midpoints.clear();
        let behind = self.behind.as_mut().map(std::mem::take);
        (std::mem::take(&mut self.mesh), behind.unwrap_or_default())
    }

    /// One step: the slabs `x − 1` (`below`) and `x` (`slab`) of the solid; with `coloured`, the same
    /// slabs' coloured sections, whose colours split the rectangles by what lies behind them.
    fn step(&mut self, x: u32, below: &Slab, slab: &Slab, coloured: Option<[&Slab; 2]>) {
        self.rects.clear();
        match coloured {
            // Only the stretch of y where the colour's voxels are: the rest of the plane has none.
            Some(sections) => {
                let ends = |s: &Slab| {
                    s.bands
                        .first()
                        .map(|b| b.y0)
                        .zip(s.bands.last().map(|b| b.y1))
                };
                let (lo, hi) = [ends(below), ends(slab)]
                    .into_iter()
                    .flatten()
                    .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
                    .expect("a step has voxels of its colour");
                self.plane_x(x, sections, Some((lo, hi)));
            }
            None => self.plane_x(x, [below, slab], None),
        }
        let coloured_slab = coloured.map(|c| c[1]);
        self.intervals_y(slab, coloured_slab);
        self.intervals_z(slab, coloured_slab);
        for axis in 0..2 {
            self.carry_open(axis, x);
        }
        self.make_points(x, below, slab);
        self.stops_along_x(x);
        self.finish_rects();
    }

    /// The rectangles of the plane `x = X`: the stretches where exactly one of the two slabs is full,
    /// merged along `y`. With `coloured`, the stretch `[lo, hi)` of `y` holding the sweep's colour,
    /// `slabs` are the coloured sections and the solid is that colour: the stretches are split where the
    /// colour behind (the other slab's) changes.
    fn plane_x(&mut self, x: u32, slabs: [&Slab; 2], coloured: Option<(u32, u32)>) {
        self.open_x.clear();
        let (from, until) = coloured.unwrap_or((0, u32::MAX));
        let coloured = coloured.is_some();
        // Where the rows carried so far end.
        let mut carried: Option<u32> = None;
        let mut pieces = Pieces::from_y(slabs[0], slabs[1], from);
        while let Some((y, end, bands)) = pieces.next_bands().filter(|p| p.0 < until) {
            if let Some(at) = carried.filter(|&at| at != y) {
                self.row.clear();
                self.carry_x(x, at);
            }
            self.plane_x_row(slabs, bands, coloured);
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

    /// The row of the plane `x = X` over a stretch where the slabs' bands are `bands` (see
    /// [`plane_x`](Self::plane_x)), into `self.row`.
    fn plane_x_row(&mut self, slabs: [&Slab; 2], bands: [Option<&Band>; 2], coloured: bool) {
        let runs = |s: usize| bands[s].map_or(&[][..], |b| slabs[s].runs_of(b));
        if !coloured {
            xor_runs(runs(0), runs(1), &mut self.xor);
            fill_row(&self.xor, self.merge, &mut self.row);
            return;
        }
        let colours = |s: usize| bands[s].map_or(&[][..], |b| slabs[s].colours_of(b));
        for (s, solid) in self.solid.iter_mut().enumerate() {
            solid.clear();
            solid.extend(
                runs(s)
                    .iter()
                    .zip(colours(s))
                    .filter(|(_, &c)| c == self.colour)
                    .map(|(r, _)| *r),
            );
        }
        xor_runs(&self.solid[0], &self.solid[1], &mut self.xor);
        self.row.clear();
        for upper in [false, true] {
            for &(lo, hi, first) in self.xor.iter().filter(|s| s.2 == upper) {
                // The solid below (`first`) faces slab x; else slab x − 1 is behind.
                let behind = usize::from(first);
                let row = &mut self.row;
                colour_stretches(runs(behind), colours(behind), lo, hi, |a, b, c| {
                    row.push((u32::from(first), a, b, c));
                });
            }
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
                r.colour,
            ));
        }
    }

    /// The intervals (along `z`) of the slab's boundary in the planes `y = Y`, by `(plane, lo)`; split by
    /// the colour behind them when the slab's `coloured` section is given.
    fn intervals_y(&mut self, slab: &Slab, coloured: Option<&Slab>) {
        let mut out = std::mem::take(&mut self.intervals[0]);
        out.clear();
        for (k, band) in slab.bands.iter().enumerate() {
            let below = match k.checked_sub(1).map(|p| &slab.bands[p]) {
                Some(p) if p.y1 == band.y0 => slab.runs_of(p),
                _ => &[],
            };
            self.plane_y_row(band.y0, below, slab.runs_of(band), coloured, &mut out);
            if slab.bands.get(k + 1).is_none_or(|n| n.y0 != band.y1) {
                self.plane_y_row(band.y1, slab.runs_of(band), &[], coloured, &mut out);
            }
        }
        self.intervals[0] = out;
    }

    /// The intervals of the plane `y = Y` between the columns `below` (at `Y − 1`) and `above`, split
    /// by the colours of the column behind each when `coloured` is given.
    fn plane_y_row(
        &mut self,
        y: u32,
        below: &[(u32, u32)],
        above: &[(u32, u32)],
        coloured: Option<&Slab>,
        out: &mut Vec<Interval>,
    ) {
        xor_runs(below, above, &mut self.xor);
        let Some(coloured) = coloured else {
            fill_row(&self.xor, self.merge, &mut self.row);
            out.extend(
                self.row
                    .iter()
                    .map(|&(upper, lo, hi, colour)| (2 * y + upper, lo, hi, colour)),
            );
            return;
        };
        for upper in [false, true] {
            for &(lo, hi, first) in self.xor.iter().filter(|s| s.2 == upper) {
                // The solid below faces column y; the solid above, column y − 1.
                let behind = if first { Some(y) } else { y.checked_sub(1) };
                let (runs, colours) = column(coloured, behind);
                colour_stretches(runs, colours, lo, hi, |a, b, c| {
                    out.push((2 * y + u32::from(first), a, b, c));
                });
            }
        }
    }

    /// The intervals (along `y`) of the slab's boundary in the planes `z = Z`, by `(plane, lo)`: the runs'
    /// ends, sorted by plane (stably: the bands come by `y`) and joined where `y` goes on with the same
    /// colour behind (read from the slab's `coloured` section, whose bands are the slab's).
    fn intervals_z(&mut self, slab: &Slab, coloured: Option<&Slab>) {
        self.ends.clear();
        for band in &slab.bands {
            let (runs, colours) = match coloured {
                Some(coloured) => column(coloured, Some(band.y0)),
                None => (&[][..], &[][..]),
            };
            let behind = |z: Option<u32>| coloured.map_or(0, |_| colour_at(runs, colours, z));
            for &(z0, z1) in slab.runs_of(band) {
                self.ends
                    .push((2 * z0, band.y0, band.y1, behind(z0.checked_sub(1))));
                self.ends
                    .push((2 * z1 + 1, band.y0, band.y1, behind(Some(z1))));
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
        for &(plane, y0, y1, colour) in &self.ends {
            match self.merge {
                Merge::Rectangles => match out.last_mut() {
                    Some(last) if last.0 == plane && last.2 == y0 && last.3 == colour => {
                        last.2 = y1
                    }
                    _ => out.push((plane, y0, y1, colour)),
                },
                Merge::None => out.extend((y0..y1).map(|y| (plane, y, y + 1, colour))),
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
                .push(StepRect::new(rect(o, x), Kind::Closed(o.id), o.colour));
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
                .push(StepRect::new(rect(o, x + 1), Kind::Opened(id), o.colour));
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

/// A row's intervals `(upper, lo, hi, 0)` by `(upper, lo)` from the stretches of [`xor_runs`] (`upper`:
/// the first set, the one below, is full), split into unit intervals unless merging.
fn fill_row(xor: &[(u32, u32, bool)], merge: Merge, row: &mut Vec<Interval>) {
    row.clear();
    for upper in [false, true] {
        for &(lo, hi, first) in xor.iter().filter(|s| s.2 == upper) {
            let upper = u32::from(first);
            match merge {
                Merge::Rectangles => row.push((upper, lo, hi, 0)),
                Merge::None => row.extend((lo..hi).map(|z| (upper, z, z + 1, 0))),
            }
        }
    }
}

/// The runs and their colours of column `y` of a coloured section (none for no column).
fn column(coloured: &Slab, y: Option<u32>) -> (&[(u32, u32)], &[u32]) {
    match y.and_then(|y| coloured.band_at(y)) {
        Some(band) => (coloured.runs_of(band), coloured.colours_of(band)),
        None => (&[], &[]),
    }
}

/// The colour at `z` of a column of coloured runs ([`NOTHING`] for no voxel).
fn colour_at(runs: &[(u32, u32)], colours: &[u32], z: Option<u32>) -> u32 {
    let Some(z) = z else {
        return NOTHING;
    };
    let i = runs.partition_point(|r| r.1 <= z);
    match runs.get(i) {
        Some(r) if r.0 <= z => colours[i],
        _ => NOTHING,
    }
}

/// Calls `emit(lo, hi, colour)` for the stretches of `[lo, hi)` in a column of coloured runs over which
/// the colour stays the same ([`NOTHING`] between runs), in order.
fn colour_stretches(
    runs: &[(u32, u32)],
    colours: &[u32],
    lo: u32,
    hi: u32,
    mut emit: impl FnMut(u32, u32, u32),
) {
    let mut at = lo;
    let first = runs.partition_point(|r| r.1 <= lo);
    for (r, &colour) in runs[first..].iter().zip(&colours[first..]) {
        if r.0 >= hi {
            break;
        }
        if r.0 > at {
            emit(at, r.0, NOTHING);
            at = r.0;
        }
        let end = r.1.min(hi);
        emit(at, end, colour);
        at = end;
    }
    if at < hi {
        emit(at, hi, NOTHING);
    }
}

/// Carries open rectangles (`open`, by `(plane, lo)`) across the intervals `now` (the same order) met at
/// `at`: an open rectangle whose interval is met again goes on (when merging), the others are closed
/// (appended to `closed`), and each interval not carried on opens a rectangle started at `at` (its place in
/// the new `open` appended to `opened`).
fn carry(
    open: &mut Vec<Open>,
    now: &[Interval],
    at: u32,
    merge: Merge,
    next: &mut Vec<Open>,
    closed: &mut Vec<Open>,
    opened: &mut Vec<usize>,
) {
    next.clear();
    let mut i = 0;
    for &(plane, lo, hi, colour) in now {
        while i < open.len() && (open[i].plane, open[i].lo) < (plane, lo) {
            closed.push(open[i]);
            i += 1;
        }
        let same = open
            .get(i)
            .is_some_and(|o| (o.plane, o.lo, o.hi, o.colour) == (plane, lo, hi, colour));
        if same && merge == Merge::Rectangles {
            next.push(open[i]);
            i += 1;
        } else {
            opened.push(next.len());
            next.push(Open {
                plane,
                lo,
                hi,
                colour,
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
        let mut lcg = crate::testing::Lcg(0x9E37_79B9_7F4A_7C15);
        for round in 0..30 {
            // Aligned blocks of every size, added and cut out.
            let tree = super::super::random_blocks(4, &mut lcg, 8, true);
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
        let rows: [&[Interval]; 3] = [
            &[(0, 0, 4, 0), (1, 5, 6, 0)],
            &[(0, 0, 4, 0)],
            &[(0, 0, 3, 0)],
        ];
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
