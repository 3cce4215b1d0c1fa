//! The T-junctions: every corner of a rectangle that lies inside another rectangle's edge, on the same
//! sheet of the surface, is a stop of that edge. The edges in the plane `x = X` find theirs among the
//! step's points; the edges along `x` of the rectangles the sweep carries gather theirs at each step they
//! pass, in lists kept in one store.

use super::super::{link_parts, vertex_of};
use super::points::{LineFinder, Point};
use super::triangles::edge_of;
use super::Sweep;

/// A T-junction kept for a rectangle's edge: its coordinate along the edge, its point's occupancy and the
/// vertex, and the next stop of the same edge (a list in a shared store; [`NONE`] ends it).
#[derive(Debug, Clone, Copy)]
pub(super) struct Stop {
    pub(super) along: u32,
    pub(super) mask: u8,
    pub(super) vertex: u32,
    pub(super) next: u32,
}

/// The end of a list of [`Stop`]s.
pub(super) const NONE: u32 = u32::MAX;

/// What a carried rectangle keeps from the step that opened it: its corners there (vertex and
/// occupancy, by corner number) and, by edge number, the stops of its edges met so far.
#[derive(Debug, Clone, Copy)]
pub(super) struct Birth {
    pub(super) corners: [(u32, u8); 4],
    pub(super) edges: [u32; 4],
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

impl Sweep {
    /// The stops strictly inside an edge along `d` (1 or 2) in the plane of the step, between the points
    /// `from` and `to`, in order along `d`, into `out`.
    pub(super) fn stops_in_plane(
        &self,
        d: usize,
        face: usize,
        from: u32,
        to: u32,
        out: &mut Vec<Stop>,
    ) {
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
    pub(super) fn stops_along_x(&mut self, x: u32) {
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

    /// The stops of edge `k` of step rectangle `i`, an edge in the plane of the step, in order from
    /// corner `k`.
    pub(super) fn in_plane_edge(&self, i: usize, k: usize, out: &mut Vec<Stop>) {
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
    pub(super) fn take_stops(&mut self, mut head: u32, out: &mut Vec<Stop>) {
        while head != NONE {
            let stop = self.stops[head as usize];
            out.push(stop);
            self.stops[head as usize].next = self.free_stops;
            self.free_stops = head;
            head = stop.next;
        }
        out.reverse();
    }
}

/// Pushes `stop` in front of the list `head` in `store` (reusing a freed entry), returning the new head.
pub(super) fn push_stop(store: &mut Vec<Stop>, free: &mut u32, stop: Stop, head: u32) -> u32 {
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
