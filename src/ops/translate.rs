//! Translation by an integer vector with Meagher's overlays (§6 "Translation", claim M3), and by a vector
//! given at a finer level.
//!
//! Each target obel is decided from the source obels of its own level that cover it — exactly `2^K` of
//! them, Meagher's overlay (Fig. 2–3): slot `c` of the overlay is the source cell `base + c` where `base`
//! is the source cell holding the target's preimage corner. If every overlay obel the target meets is
//! empty (or in the void beyond the universe) the target is empty; if all are full it is full; otherwise
//! each of its `2^K` children gets its own overlay, made of children of the parent's overlay obels (or of
//! the same leaves). Parts moved outside the universe are cut off. Integer-only: additions, comparisons,
//! masks and shifts. The output is reduced (children are decided before they are appended), written
//! through any [`LevelSink`] ([`translate_into`]).

use super::output::{collapse, copy_into, Memory};
use crate::tree::sink::LevelSink;
use crate::tree::storage::TreeStorage;
use crate::tree::{KTree, NodeState};

/// One overlay obel: the index of a source node at the target's depth (overlays stay on the target's
/// level), or one of two markers for a leaf standing in for all its descendants.
type Slot = usize;
const EMPTY: Slot = usize::MAX;
const FULL: Slot = usize::MAX - 1;

/// `TERN[m]` = the bits of `m` read as base-3 digits (bit `i` → `3^i`); `TERN[1 << K]` = `3^K`.
const TERN: [usize; 17] = {
    let mut t = [0usize; 17];
    let mut m = 0;
    while m < 17 {
        let (mut v, mut p, mut b) = (0, 1, 0);
        while b < 5 {
            if m >> b & 1 == 1 {
                v += p;
            }
            p *= 3;
            b += 1;
        }
        t[m] = v;
        m += 1;
    }
    t
};

struct Mover<'a, const K: usize, T, S> {
    src: &'a T,
    t: [i64; K],
    level: u32,
    out: S,
}

impl<const K: usize, T: TreeStorage<K>, S: LevelSink> Mover<'_, K, T, S> {
    #[inline(always)]
    fn state(&self, depth: u32, slot: Slot) -> Result<NodeState, T::Error> {
        Ok(match slot {
            EMPTY => NodeState::Empty,
            FULL => NodeState::Full,
            i => self.src.state(depth as usize, i)?,
        })
    }

    /// Decides the target cell at `depth` with origin `origin`, given its overlay.
    fn node<E: From<T::Error> + From<S::Error>>(
        &mut self,
        depth: u32,
        origin: [i64; K],
        overlay: &[Slot; 16],
    ) -> Result<NodeState, E> {
        let log = self.level - depth;
        // Offsets of the target's preimage inside the base cell, per axis.
        let mask = (1i64 << log) - 1;
        let mut meets_upper = 0usize; // bit i: the target reaches into the upper overlay obel on axis i
        for (i, (&o, &t)) in origin.iter().zip(&self.t).enumerate() {
            if (o - t) & mask != 0 {
                meets_upper |= 1 << i;
            }
        }
        let (mut empty, mut full, mut partial) = (false, false, false);
        for (code, &slot) in overlay.iter().enumerate().take(1 << K) {
            if code & !meets_upper != 0 {
                continue;
            }
            match self.state(depth, slot)? {
                NodeState::Empty => empty = true,
                NodeState::Full => full = true,
                NodeState::Partial => partial = true,
            }
        }
        if !(partial || empty && full) {
            return Ok(if full {
                NodeState::Full
            } else {
                NodeState::Empty
            });
        }
        // Each overlay obel resolved once: a leaf, or the index of its first child one level down.
        let mut resolved = [EMPTY; 16];
        for (code, &slot) in overlay.iter().enumerate().take(1 << K) {
            resolved[code] = match self.state(depth, slot)? {
                NodeState::Partial => self.src.first_child(depth as usize, slot)?,
                NodeState::Full => FULL,
                NodeState::Empty => EMPTY,
            };
        }
        let half = 1i64 << (log - 1);
        // X_i: the preimage corner in units of the children's side. All children's overlay obels lie in
        // the 3^K grid of cells X + g (g_i = 0, 1, 2): resolve each grid cell once.
        let x: [i64; K] = std::array::from_fn(|i| (origin[i] - self.t[i]) >> (log - 1));
        let mut grid = [EMPTY; 81];
        for (g, cell_slot) in grid.iter_mut().enumerate().take(TERN[1 << K]) {
            let (mut parent, mut within, mut rest) = (0usize, 0usize, g);
            for (i, &xi) in x.iter().enumerate() {
                let cell = xi + (rest % 3) as i64;
                rest /= 3;
                parent |= (((cell >> 1) - (xi >> 1)) as usize) << i;
                within |= ((cell & 1) as usize) << i;
            }
            *cell_slot = match resolved[parent] {
                leaf @ (EMPTY | FULL) => leaf,
                first => first + within,
            };
        }
        let mut kids = [NodeState::Empty; 16];
        for (c, kid) in kids.iter_mut().enumerate().take(1 << K) {
            let child_origin: [i64; K] =
                std::array::from_fn(|i| origin[i] + ((c >> i) as i64 & 1) * half);
            let mut sub = [EMPTY; 16];
            for (code, slot) in sub.iter_mut().enumerate().take(1 << K) {
                *slot = grid[TERN[c] + TERN[code]];
            }
            *kid = self.node::<E>(depth + 1, child_origin, &sub)?;
        }
        let kids = &kids[..1 << K];
        Ok(match collapse(kids) {
            Some(s) => s,
            None => {
                self.out.push_block(depth as usize + 1, kids)?;
                NodeState::Partial
            }
        })
    }
}

/// Translates the object by `t` voxels (any integer vector, negative allowed); voxels moved out of the
/// universe are lost. The output is reduced. Reads any storage; [`translate_into`] writes to any sink.
///
/// ```
/// use ktree::{KTree, ops::translate};
/// let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
/// assert_eq!(translate(&a, [1]).unwrap().to_dense().unwrap(), [false, true, true, false]);
/// assert_eq!(translate(&a, [-1]).unwrap().to_dense().unwrap(), [true, false, false, false]);
/// ```
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn translate<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    t: [i64; K],
) -> Result<KTree<K>, T::Error> {
    translate_into(tree, t, Memory::new(tree.universe()))
}

/// [`translate`] written to `sink`, for instance a sink that spills each level to its own file.
///
/// ```
/// use ktree::{KTree, ops::{translate, translate_into}};
/// use ktree::tree::sink::MemorySink;
/// let a = KTree::<2>::from_dense(2, &(0..16).map(|i| i % 3 == 0).collect::<Vec<_>>()).unwrap();
/// let sink = MemorySink::new(a.universe());
/// let moved: KTree<2> = translate_into::<2, _, _, std::convert::Infallible>(&a, [1, -1], sink).unwrap();
/// assert_eq!(moved, translate(&a, [1, -1]).unwrap());
/// ```
///
/// # Errors
/// The first read error of `tree` or write error of `sink`.
pub fn translate_into<const K: usize, T, S, E>(
    tree: &T,
    t: [i64; K],
    sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    let side = tree.universe().side() as i64;
    if t.iter().all(|&v| v == 0) {
        return copy_into(tree, sink);
    }
    if t.iter().any(|&v| v.unsigned_abs() >= side as u64) {
        return Ok(sink.finish(NodeState::Empty)?);
    }
    let mut m = Mover {
        src: tree,
        t,
        level: tree.level(),
        out: sink,
    };
    // The root's overlay: the source root sits in the slot whose cell index is 0 on every axis.
    let base: [i64; K] = std::array::from_fn(|i| (-t[i]).div_euclid(side));
    let mut overlay = [EMPTY; 16];
    for (code, slot) in overlay.iter_mut().enumerate().take(1 << K) {
        if (0..K).all(|i| base[i] + ((code >> i) & 1) as i64 == 0) {
            *slot = 0;
        }
    }
    let root = m.node::<E>(0, [0; K], &overlay)?;
    Ok(m.out.finish(root)?)
}

/// The whole-voxel shift used for an offset of `t / 2^sub_level` voxels: the target voxel whose centre,
/// moved back by the offset, lands in a source voxel takes that voxel's state, which is a shift by
/// `t / 2^sub_level` rounded to the nearest integer with halves rounded *down* (towards −∞).
///
/// ```
/// use ktree::ops::fine_shift;
/// assert_eq!(fine_shift(5, 2), 1);   // 1.25 → 1
/// assert_eq!(fine_shift(6, 2), 1);   // 1.5  → 1 (half down)
/// assert_eq!(fine_shift(7, 2), 2);   // 1.75 → 2
/// assert_eq!(fine_shift(-6, 2), -2); // −1.5 → −2 (half down)
/// ```
pub fn fine_shift(t: i64, sub_level: u32) -> i64 {
    // Source voxel of target q: floor(q + ½ − t/2^s) = q + floor((2^s − 2t) / 2^(s+1)).
    let s = 1i128 << sub_level.min(120); // beyond 2^120 every i64 offset rounds to 0 or −1 alike
    let shift = -(s - 2 * i128::from(t)).div_euclid(2 * s);
    shift.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
}

/// Translates by a vector given at a finer level: `t[i] / 2^sub_level` voxels on axis `i`, applied as the
/// whole-voxel shift of [`fine_shift`] (a voxel grid can only move by whole voxels; the rounding rule is
/// that of sampling each target voxel at its centre).
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn translate_fine<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    t: [i64; K],
    sub_level: u32,
) -> Result<KTree<K>, T::Error> {
    translate(tree, t.map(|v| fine_shift(v, sub_level)))
}

/// [`translate_fine`] written to `sink`.
///
/// # Errors
/// The first read error of `tree` or write error of `sink`.
pub fn translate_fine_into<const K: usize, T, S, E>(
    tree: &T,
    t: [i64; K],
    sub_level: u32,
    sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    translate_into(tree, t.map(|v| fine_shift(v, sub_level)), sink)
}
