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
use crate::tree::valued::{ValueNode, ValueState, ValueStorage};
use crate::tree::{NodeRef, NodeState};

/// Stretches `[y0, y1)` of a slab, each with its runs along `z` (a range of [`Slab::runs`]), in order
/// of `y` and disjoint (touching bands may have the same runs).
#[derive(Debug, Clone, Default)]
pub(super) struct Slab {
    pub(super) bands: Vec<Band>,
    pub(super) runs: Vec<(u32, u32)>,
    /// Each run's colour: its value's number, in a section of a tree with values (none in a binary
    /// tree's).
    pub(super) colours: Vec<u32>,
}

/// A stretch `[y0, y1)` of a slab and its runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Band {
    pub(super) y0: u32,
    pub(super) y1: u32,
    /// Its runs' range in [`Slab::runs`], sorted, disjoint, not touching unless their colours differ.
    pub(super) runs: (u32, u32),
}

impl Slab {
    /// The runs of band `band`.
    pub(super) fn runs_of(&self, band: &Band) -> &[(u32, u32)] {
        &self.runs[band.runs.0 as usize..band.runs.1 as usize]
    }

    /// The colours of the runs of band `band`.
    pub(super) fn colours_of(&self, band: &Band) -> &[u32] {
        &self.colours[band.runs.0 as usize..band.runs.1 as usize]
    }

    /// The band holding column `y`, if any.
    pub(super) fn band_at(&self, y: u32) -> Option<&Band> {
        let i = self.bands.partition_point(|b| b.y1 <= y);
        self.bands.get(i).filter(|b| b.y0 <= y)
    }

    /// Empties the slab, keeping its memory.
    pub(super) fn clear(&mut self) {
        self.bands.clear();
        self.runs.clear();
        self.colours.clear();
    }

    /// Appends a band `[y0, y1)` with runs `runs`, of colour `colour` in a coloured section.
    fn push_band(&mut self, y0: u32, y1: u32, runs: &[(u32, u32)], colour: Option<u32>) {
        let start = self.runs.len() as u32;
        self.runs.extend_from_slice(runs);
        if let Some(colour) = colour {
            self.colours.extend(std::iter::repeat_n(colour, runs.len()));
        }
        self.bands.push(Band {
            y0,
            y1,
            runs: (start, self.runs.len() as u32),
        });
    }

    /// Appends run `run` of colour `colour` over the stretch of band `band` of another slab (a coloured
    /// section being split into each colour's own slab, its bands in order): to this slab's last band
    /// when that one covers the same stretch, else as a band of its own.
    pub(super) fn push_run(&mut self, band: &Band, run: (u32, u32), colour: u32) {
        match self.bands.last_mut() {
            Some(last) if last.y0 == band.y0 => {
                self.runs.push(run);
                self.colours.push(colour);
                last.runs.1 += 1;
            }
            _ => self.push_band(band.y0, band.y1, &[run], Some(colour)),
        }
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
        Self::from_y(first, second, 0)
    }

    /// The stretches from `y` on (the first one cut at `y`).
    pub(super) fn from_y(first: &'s Slab, second: &'s Slab, y: u32) -> Self {
        let slabs = [first, second];
        Pieces {
            slabs,
            at: slabs.map(|s| s.bands.partition_point(|b| b.y1 <= y)),
            y,
        }
    }
}

impl<'s> Iterator for Pieces<'s> {
    type Item = (u32, u32, &'s [(u32, u32)], &'s [(u32, u32)]);

    fn next(&mut self) -> Option<Self::Item> {
        let (y, end, bands) = self.next_bands()?;
        let runs = |s: usize| bands[s].map_or(&[][..], |band| self.slabs[s].runs_of(band));
        Some((y, end, runs(0), runs(1)))
    }
}

impl<'s> Pieces<'s> {
    /// The next stretch as `(y0, y1, the band of each slab there)`.
    pub(super) fn next_bands(&mut self) -> Option<(u32, u32, [Option<&'s Band>; 2])> {
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
            let inside = |s: usize| bands[s].filter(|b| b.1).map(|b| b.0);
            if bands.iter().flatten().any(|&(_, inside)| inside) {
                return Some((y, end, [inside(0), inside(1)]));
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
    Section::read(x, false, slab, |section| {
        try_walk(tree, section).map(|_| ())
    })
}

/// The cross-section at `x` of a tree with values into `slab`, each run coloured by `colour_of` its
/// value (touching runs of different colours kept apart); returns the next `x` at which the section may
/// differ.
pub(super) fn value_section<T: ValueStorage<3>>(
    tree: &T,
    x: u32,
    slab: &mut Slab,
    colour_of: &impl Fn(T::Value) -> u32,
) -> Result<u32, T::Error> {
    Section::read(x, true, slab, |section| {
        section.descend_values(tree, tree.root()?, colour_of)
    })
}

/// The walk's state: the results of the nodes done whose parent is not, each where its bands start in the
/// slab (the results lie one after another, the last at the end).
struct Section {
    x: u32,
    /// Whether the runs have colours (the section of a tree with values).
    coloured: bool,
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
                    let colour = self.coloured.then(|| slab.colours[k as usize]);
                    match slab.runs[start..].last_mut() {
                        Some(last) if last.1 == run.0 && slab.colours.last() == colour.as_ref() => {
                            last.1 = run.1;
                        }
                        _ => {
                            slab.runs.push(run);
                            slab.colours.extend(colour);
                        }
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
        if self.coloured {
            slab.colours.extend_from_within(from.1..until.1);
        }
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
        if self.coloured {
            slab.colours.copy_within(from.1..until.1, to.1);
        }
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
        match node.state() {
            NodeState::Partial => return Walk::Descend,
            NodeState::Full => self.leaf(cell.origin, side, Some(0)),
            NodeState::Empty => self.leaf(cell.origin, side, None),
        }
        Walk::Skip
    }

    fn leave(&mut self, _node: &NodeRef<3>) {
        self.join_quarters();
    }

    fn child_order(&self, node: &NodeRef<3>) -> ChildOrder {
        let cell = node.cell();
        let half = cell.log_side - 1;
        let x_bit = (self.x >> half & 1) as usize;
        self.orders[x_bit]
    }
}

impl Section {
    /// The section at `x` into `slab` (its memory reused), as the walk `walk` reads it; returns the next
    /// `x` at which the section may differ.
    fn read<E>(
        x: u32,
        coloured: bool,
        slab: &mut Slab,
        walk: impl FnOnce(&mut Section) -> Result<(), E>,
    ) -> Result<u32, E> {
        slab.clear();
        let mut section = Section {
            x,
            coloured,
            next: u32::MAX,
            slab: std::mem::take(slab),
            results: Vec::new(),
            orders: [order(0), order(1)],
        };
        let read = walk(&mut section);
        *slab = section.slab;
        read?;
        debug_assert!(section.results.len() <= 1);
        Ok(section.next)
    }

    /// Walks the node `node` of a tree with values and its children the plane crosses (by `y` then `z`).
    fn descend_values<T: ValueStorage<3>>(
        &mut self,
        tree: &T,
        node: ValueNode<3, T::Value>,
        colour_of: &impl Fn(T::Value) -> u32,
    ) -> Result<(), T::Error> {
        let cell = node.cell;
        let side = 1u32 << cell.log_side;
        match node.state {
            ValueState::Full(v) => self.leaf(cell.origin, side, Some(colour_of(v))),
            ValueState::Empty => self.leaf(cell.origin, side, None),
            ValueState::Partial | ValueState::Mixed => {
                let depth = cell.level as usize;
                let first = tree.children(depth, node.index)?;
                let codes = tree.codes(depth + 1, first)?;
                let x_bit = (self.x >> (cell.log_side - 1) & 1) as usize;
                for code in [x_bit, x_bit | 4, x_bit | 2, x_bit | 6] {
                    let index = first + code;
                    let child = ValueNode {
                        index,
                        cell: cell.child(code),
                        state: tree.decode(depth + 1, index, codes >> (2 * code))?,
                    };
                    self.descend_values(tree, child, colour_of)?;
                }
                self.join_quarters();
            }
        }
        Ok(())
    }

    /// A leaf the plane crosses, at `origin` with side `side`: its band and run when it is full (`full`:
    /// its colour), and where the section next changes.
    fn leaf(&mut self, origin: [u32; 3], side: u32, full: Option<u32>) {
        let here = (self.slab.bands.len(), self.slab.runs.len());
        if let Some(colour) = full {
            let [_, y, z] = origin;
            let colour = self.coloured.then_some(colour);
            self.slab.push_band(y, y + side, &[(z, z + side)], colour);
        }
        self.next = self.next.min(origin[0] + side);
        self.results.push(here);
    }

    /// The bands of a node whose four children the plane crosses are done: joins them into the node's.
    fn join_quarters(&mut self) {
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
            if self.coloured {
                self.slab.colours.truncate(starts[0].1 + end.1 - out.1);
            }
        }
        self.results.truncate(n - 4);
        self.results.push(starts[0]);
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
        let mut lcg = crate::testing::Lcg(0x2545_F491_4F6C_DD1D);
        for _ in 0..40 {
            let tree = super::super::random_blocks(4, &mut lcg, 6, false);
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

    #[test]
    fn value_sections_hold_each_voxels_colour_until_the_next() {
        let side = 16usize;
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..40 {
            // Aligned blocks of every size, each of a value 1 to 4 or emptied.
            let mut dense = vec![None; side * side * side];
            for _ in 0..8 {
                let log = (random() % 4) as usize;
                let value = (random() % 5) as u8;
                let at: [usize; 3] =
                    std::array::from_fn(|_| ((random() as usize % side) >> log) << log);
                for z in at[2]..at[2] + (1 << log) {
                    for y in at[1]..at[1] + (1 << log) {
                        for x in at[0]..at[0] + (1 << log) {
                            dense[x + side * (y + side * z)] = (value > 0).then_some(value);
                        }
                    }
                }
            }
            let tree = crate::KTree::<3, u8>::from_dense_values(4, &dense).unwrap();
            // Colour c for value c + 1.
            let colour_of = |v: u8| u32::from(v) - 1;
            let mut slab = Slab::default();
            let mut x = 0;
            while x < side as u32 {
                let next = crate::tree::storage::infallible(value_section(
                    &tree, x, &mut slab, &colour_of,
                ));
                assert!(next > x);
                for band in &slab.bands {
                    let runs = slab.runs_of(band);
                    assert!(runs.windows(2).all(|w| w[0].1 <= w[1].0));
                    // Touching runs have different colours.
                    let colours = slab.colours_of(band);
                    assert!((1..runs.len())
                        .all(|i| runs[i - 1].1 < runs[i].0 || colours[i - 1] != colours[i]));
                }
                for at in x..next.min(side as u32) {
                    for y in 0..side as u32 {
                        for z in 0..side as u32 {
                            let colour = slab.band_at(y).and_then(|b| {
                                let runs = slab.runs_of(b);
                                let i = runs.iter().position(|r| r.0 <= z && z < r.1)?;
                                Some(slab.colours_of(b)[i])
                            });
                            let voxel = (at as usize) + side * (y as usize + side * z as usize);
                            assert_eq!(colour, dense[voxel].map(colour_of), "{at} {y} {z}");
                        }
                    }
                }
                x = next;
            }
        }
    }
}
