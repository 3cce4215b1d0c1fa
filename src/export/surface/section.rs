//! A cross-section of an octree across the first axis, as bands: the full voxels of the plane `x = X`
//! (a slab one voxel thick) as stretches of `y` over which the runs along `z` stay the same.
//!
//! One walk through the nodes the plane crosses, children by `y` then `z`; when a node's four children
//! are done, the bands of its two lower (`z`) quarters are merged with those of the upper ones, half by
//! half along `y`. A cell of side `s` is one band, not `s` columns: the work follows the section's
//! nodes, not its area. The walk also finds where the section next changes: the nearest end along `x` of
//! the leaves it met.

use crate::tree::cursor::{try_walk, ChildOrder, Visitor, Walk};
use crate::tree::storage::TreeStorage;
use crate::tree::{NodeRef, NodeState};

/// Stretches `[y0, y1)` of a slab, each with its runs along `z` (a range of [`Slab::runs`]), in order
/// of `y` and disjoint (touching bands may have the same runs).
#[derive(Debug, Clone, Default)]
pub(super) struct Slab {
    pub(super) bands: Vec<Band>,
    pub(super) runs: Vec<(u32, u32)>,
}

/// A stretch `[y0, y1)` of a slab and its runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Band {
    pub(super) y0: u32,
    pub(super) y1: u32,
    /// Its runs' range in [`Slab::runs`], sorted, disjoint, not touching.
    pub(super) runs: (u32, u32),
}

impl Slab {
    /// The runs of band `band`.
    pub(super) fn runs_of(&self, band: &Band) -> &[(u32, u32)] {
        &self.runs[band.runs.0 as usize..band.runs.1 as usize]
    }

    /// Empties the slab, keeping its memory.
    pub(super) fn clear(&mut self) {
        self.bands.clear();
        self.runs.clear();
    }
}

/// The stretches of `y` over which two slabs' runs both stay the same and one of them has runs, in order:
/// `(y0, y1, runs of the first, runs of the second)` (empty where a slab has no band).
pub(super) struct Pieces<'s> {
    slabs: [&'s Slab; 2],
    at: [usize; 2],
    y: u32,
}

impl<'s> Pieces<'s> {
    pub(super) fn new(first: &'s Slab, second: &'s Slab) -> Self {
        Pieces {
            slabs: [first, second],
            at: [0, 0],
            y: 0,
        }
    }
}

impl<'s> Iterator for Pieces<'s> {
    type Item = (u32, u32, &'s [(u32, u32)], &'s [(u32, u32)]);

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let y = self.y;
            // Each slab's band at or after y, and whether y is inside it.
            let bands: [Option<(&Band, bool)>; 2] = std::array::from_fn(|s| {
                let bands = &self.slabs[s].bands;
                while bands.get(self.at[s]).is_some_and(|b| b.y1 <= y) {
                    self.at[s] += 1;
                }
                bands.get(self.at[s]).map(|b| (b, b.y0 <= y))
            });
            if bands.iter().all(Option::is_none) {
                return None;
            }
            // The stretch ends where a band it is in ends or the next band starts.
            let end = bands
                .iter()
                .flatten()
                .map(|&(b, inside)| if inside { b.y1 } else { b.y0 })
                .min()
                .expect("a band");
            self.y = end;
            let runs = |s: usize| match bands[s] {
                Some((band, true)) => self.slabs[s].runs_of(band),
                _ => &[],
            };
            if bands.iter().flatten().any(|&(_, inside)| inside) {
                return Some((y, end, runs(0), runs(1)));
            }
        }
    }
}

/// The cross-section of `tree` at `x` (below the universe's side) into `slab`; returns the next `x`
/// at which the section may differ.
pub(super) fn section<T: TreeStorage<3>>(
    tree: &T,
    x: u32,
    slab: &mut Slab,
) -> Result<u32, T::Error> {
    slab.clear();
    let mut visitor = Section {
        x,
        next: u32::MAX,
        slab: std::mem::take(slab),
        results: Vec::new(),
        orders: [order(0), order(1)],
    };
    let read = try_walk(tree, &mut visitor);
    *slab = visitor.slab;
    read?;
    debug_assert!(visitor.results.len() <= 1);
    Ok(visitor.next)
}

/// The walk's state: the results of the nodes done whose parent is not, each where its bands start in the
/// slab (the results lie one after another, the last at the end).
struct Section {
    x: u32,
    next: u32,
    slab: Slab,
    /// For each result: its first band and first run.
    results: Vec<(usize, usize)>,
    /// The children a plane of `x` crosses in the lower (0) or upper (1) half of a node, by `y` then `z`.
    orders: [ChildOrder; 2],
}

impl Section {
    /// Merges the bands `a` and `b`, which are over the same stretch of `y` and are below and above a
    /// middle plane of `z`, appending the merged bands (and their runs) to the slab.
    fn merge(&mut self, a: (usize, usize), b: (usize, usize)) {
        let slab = &mut self.slab;
        let (mut i, mut j) = (a.0, b.0);
        let mut y = 0;
        loop {
            while i < a.1 && slab.bands[i].y1 <= y {
                i += 1;
            }
            while j < b.1 && slab.bands[j].y1 <= y {
                j += 1;
            }
            let (first, second) = (
                slab.bands.get(i).filter(|_| i < a.1).copied(),
                slab.bands.get(j).filter(|_| j < b.1).copied(),
            );
            if first.is_none() && second.is_none() {
                break;
            }
            let inside = |band: Option<Band>| band.filter(|band| band.y0 <= y);
            let (in_a, in_b) = (inside(first), inside(second));
            // Where the current stretch ends: the end of a band it is in or the start of the next.
            let boundary = |band: Option<Band>, inside: bool| {
                band.map_or(u32::MAX, |band| if inside { band.y1 } else { band.y0 })
            };
            let end = boundary(first, in_a.is_some()).min(boundary(second, in_b.is_some()));
            if in_a.is_none() && in_b.is_none() {
                y = end;
                continue;
            }
            let start = slab.runs.len();
            for band in [in_a, in_b].into_iter().flatten() {
                for k in band.runs.0..band.runs.1 {
                    let run = slab.runs[k as usize];
                    match slab.runs[start..].last_mut() {
                        Some(last) if last.1 == run.0 => last.1 = run.1,
                        _ => slab.runs.push(run),
                    }
                }
            }
            slab.bands.push(Band {
                y0: y,
                y1: end,
                runs: (start as u32, slab.runs.len() as u32),
            });
            y = end;
        }
    }
}

impl Section {
    /// Appends a copy of the bands and runs from `from` up to `until` (band and run indices).
    fn append_copy(&mut self, from: (usize, usize), until: (usize, usize)) {
        let slab = &mut self.slab;
        let shift = (slab.runs.len() - from.1) as u32;
        slab.runs.extend_from_within(from.1..until.1);
        for k in from.0..until.0 {
            let band = slab.bands[k];
            slab.bands.push(Band {
                runs: (band.runs.0 + shift, band.runs.1 + shift),
                ..band
            });
        }
    }

    /// Moves the bands and runs from `from` up to `until` (band and run indices) down to `to`, the bands'
    /// runs following.
    fn move_down(&mut self, from: (usize, usize), until: (usize, usize), to: (usize, usize)) {
        if from == to {
            return;
        }
        let slab = &mut self.slab;
        slab.bands.copy_within(from.0..until.0, to.0);
        slab.runs.copy_within(from.1..until.1, to.1);
        let shift = (from.1 - to.1) as u32;
        for band in &mut slab.bands[to.0..to.0 + until.0 - from.0] {
            band.runs = (band.runs.0 - shift, band.runs.1 - shift);
        }
    }
}

impl Visitor<3> for Section {
    fn visit(&mut self, node: &NodeRef<3>) -> Walk {
        let cell = node.cell();
        let side = 1u32 << cell.log_side;
        let here = (self.slab.bands.len(), self.slab.runs.len());
        match node.state() {
            NodeState::Partial => return Walk::Descend,
            NodeState::Full => {
                let [_, y, z] = cell.origin;
                self.slab.runs.push((z, z + side));
                self.slab.bands.push(Band {
                    y0: y,
                    y1: y + side,
                    runs: (here.1 as u32, here.1 as u32 + 1),
                });
            }
            NodeState::Empty => {}
        }
        self.next = self.next.min(cell.origin[0] + side);
        self.results.push(here);
        Walk::Skip
    }

    fn leave(&mut self, _node: &NodeRef<3>) {
        // The four children's results, by (y, z): (0, 0), (0, 1), (1, 0), (1, 1), one after another.
        let n = self.results.len();
        let mut starts = [(0, 0); 5];
        starts[..4].copy_from_slice(&self.results[n - 4..]);
        starts[4] = (self.slab.bands.len(), self.slab.runs.len());
        let bands = |k: usize| (starts[k].0, starts[k + 1].0);
        // Each half along y: where one of its two quarters has no bands, the other's are the half's, in
        // place. Where both halves are so, the node's bands are in place; else each half is merged (or
        // copied) after everything and the two moved down over the children's.
        let in_place = |half: usize| {
            let (a, b) = (bands(half), bands(half + 1));
            a.0 == a.1 || b.0 == b.1
        };
        if !(in_place(0) && in_place(2)) {
            let out = starts[4];
            for half in [0, 2] {
                if in_place(half) {
                    self.append_copy(starts[half], starts[half + 2]);
                } else {
                    self.merge(bands(half), bands(half + 1));
                }
            }
            let end = (self.slab.bands.len(), self.slab.runs.len());
            self.move_down(out, end, starts[0]);
            self.slab.bands.truncate(starts[0].0 + end.0 - out.0);
            self.slab.runs.truncate(starts[0].1 + end.1 - out.1);
        }
        self.results.truncate(n - 4);
        self.results.push(starts[0]);
    }

    fn child_order(&self, node: &NodeRef<3>) -> ChildOrder {
        let cell = node.cell();
        let half = cell.log_side - 1;
        let x_bit = (self.x >> half & 1) as usize;
        self.orders[x_bit]
    }
}

/// The children a plane of `x` crosses in the lower (`x_bit` 0) or upper (1) half of a node, by `y`
/// then `z` (child code bit `a`: the upper half on axis `a`).
fn order(x_bit: usize) -> ChildOrder {
    ChildOrder::from_codes([x_bit, x_bit | 4, x_bit | 2, x_bit | 6])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_hold_the_voxels_of_their_plane_until_the_next() {
        let side = 16;
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..40 {
            let tree = super::super::random_blocks(4, &mut state, 6, false);
            let mut slab = Slab::default();
            let mut x = 0;
            while x < side {
                let next = crate::tree::storage::infallible(section(&tree, x, &mut slab));
                assert!(next > x);
                let bands = &slab.bands;
                assert!(bands.windows(2).all(|w| w[0].y1 <= w[1].y0));
                for at in x..next.min(side) {
                    for y in 0..side {
                        for z in 0..side {
                            let band = bands.iter().find(|b| b.y0 <= y && y < b.y1);
                            let full = band.is_some_and(|b| {
                                slab.runs_of(b).iter().any(|r| r.0 <= z && z < r.1)
                            });
                            assert_eq!(full, tree.contains([at, y, z]), "{at} {y} {z}");
                        }
                    }
                }
                x = next;
            }
        }
    }
}
