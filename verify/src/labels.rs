//! Random valued objects for the valued trees' property tests: boxes and voxels painted in order with values
//! from a small palette (so that equal values meet and merge, and different ones mix), as a dense array of
//! `Option<V>` that is the reference itself.

use std::fmt;

use ktree::tree::{Rgb, Value};
use ktree::Universe;
use proptest::prelude::*;

use crate::objects::max_level;

/// Four values of a type to paint with: close and far, and for `f32` both zeros (two values).
pub trait Palette: Value {
    /// The palette.
    const PALETTE: [Self; 4];
}

impl Palette for u8 {
    const PALETTE: [u8; 4] = [1, 2, 3, 255];
}
impl Palette for u16 {
    const PALETTE: [u16; 4] = [0, 7, 300, 65535];
}
impl Palette for u32 {
    const PALETTE: [u32; 4] = [1, 2, 70_000, u32::MAX];
}
impl Palette for i8 {
    const PALETTE: [i8; 4] = [-128, -1, 0, 127];
}
impl Palette for f32 {
    const PALETTE: [f32; 4] = [0.0, -0.0, 1.5, -7.25];
}
impl Palette for Rgb {
    const PALETTE: [Rgb; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 0, 1]];
}

/// A valued object: boxes `[lo, hi)` and voxels painted in order, each with a palette index (a later
/// paint covers an earlier one); `None` paint erases.
#[derive(Clone)]
pub struct Painted<const K: usize> {
    /// The universe's level.
    pub level: u32,
    /// Boxes and their paint (a palette index, or `None` to erase).
    pub boxes: Vec<([u32; K], [u32; K], Option<usize>)>,
    /// Voxels and their paint.
    pub voxels: Vec<([u32; K], Option<usize>)>,
}

impl<const K: usize> fmt::Debug for Painted<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "K={K} L={} boxes [lo,hi),paint={:?} voxels={:?}",
            self.level, self.boxes, self.voxels
        )
    }
}

impl<const K: usize> Painted<K> {
    /// The universe of the object's level.
    pub fn universe(&self) -> Universe<K> {
        Universe::new(self.level).unwrap()
    }

    /// The dense array of palette indices, in [`Universe::dense_index`] order.
    pub fn indices(&self) -> Vec<Option<usize>> {
        let u = self.universe();
        let mut d = vec![None; u.voxels() as usize];
        for (lo, hi, paint) in &self.boxes {
            for (i, cell) in d.iter_mut().enumerate() {
                let p = u.dense_point(i);
                if (0..K).all(|a| p[a] >= lo[a] && p[a] < hi[a]) {
                    *cell = *paint;
                }
            }
        }
        for (p, paint) in &self.voxels {
            d[u.dense_index(*p)] = *paint;
        }
        d
    }

    /// The dense array of values: the reference.
    pub fn dense<V: Palette>(&self) -> Vec<Option<V>> {
        self.indices()
            .into_iter()
            .map(|i| i.map(|i| V::PALETTE[i]))
            .collect()
    }
}

/// Valued objects in a universe of level `level`: up to 5 painted boxes and 12 painted voxels.
pub fn painted_at<const K: usize>(level: u32) -> impl Strategy<Value = Painted<K>> {
    let side = 1u32 << level;
    let paint = prop_oneof![1 => Just(None), 6 => (0..4usize).prop_map(Some)];
    let bx = (
        prop::array::uniform::<_, K>((0..side, 1..=side)),
        paint.clone(),
    )
        .prop_map(move |(b, paint)| {
            let lo: [u32; K] = std::array::from_fn(|i| b[i].0);
            let hi: [u32; K] = std::array::from_fn(|i| (b[i].0 + b[i].1).min(side));
            (lo, hi, paint)
        });
    (
        prop::collection::vec(bx, 0..6),
        prop::collection::vec((prop::array::uniform::<_, K>(0..side), paint), 0..13),
    )
        .prop_map(move |(boxes, voxels)| Painted {
            level,
            boxes,
            voxels,
        })
}

/// Valued objects at any level up to [`max_level`] for `K`.
pub fn painted<const K: usize>() -> impl Strategy<Value = Painted<K>> {
    (0..=max_level(K)).prop_flat_map(painted_at::<K>)
}
