//! The triangles of the rectangles complete at a step: two for a rectangle whose edges have no stop, a fan
//! around its centre for one with stops; a midpoint on each segment where two solids touch along it.

use super::super::{face_index, others, pinched};
use super::junctions::{push_stop, Stop};
use super::{Kind, StepRect, Sweep};

/// For edge `k` of a rectangle in a plane of axis `a` (from corner `k` to corner `k + 1`): its direction,
/// the other axis of the plane, the rectangle's side of the edge on that axis, and the rectangle's unit
/// face just past a point inside the edge (on the upper side along the direction).
pub(super) fn edge_of(a: usize, k: usize) -> (usize, usize, usize, usize) {
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

impl Sweep {
    /// The triangles of the rectangles complete at the step; what the opened ones keep.
    pub(super) fn finish_rects(&mut self) {
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
        if let Some(behind) = &mut self.behind {
            behind.resize(self.mesh.triangles.len(), step_rect.colour);
        }
        self.ring = ring;
    }
}
