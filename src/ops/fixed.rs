//! Arbitrary rotations and affine maps with integer additions and shifts only during the traversal
//! (Meagher §6, claims M5 and M8): the inverse map is rounded once to fixed point, and each target cell's
//! image is derived from its parent's by adding shifted columns — Meagher's "C values after subdivision
//! are the average of two parent values; only an addition followed by a shift is required".
//!
//! The rule differs from [`super::transform`]'s only by the rounding of the matrix: target voxel `q` is
//! full iff source voxel `⌊(H·(2q + 1) + B) / 2^F⌋` is, where `H = round(A⁻¹·2^(F−1))` and
//! `B = round(b⁻¹·2^F)` are integers fixed before the traversal (the only multiplications, like
//! Meagher's set-up of the edge equations). With `F = 32` the matrix entries are exact to 2^−32, far
//! below a voxel at every universe size ktree allows. Cell boxes are exact integer bounds, so the output
//! equals [`FixedAffine::source_voxel`] applied to every voxel centre.

// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use super::output::Memory;
use super::overlay::{resample_incremental_into, IncrementalPreimage};
use super::{Affine, OpsError};
use crate::tree::sink::LevelSink;
use crate::tree::storage::TreeStorage;
use crate::tree::KTree;

/// The inverse of an affine map in fixed point, ready for integer-only traversal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FixedAffine<const K: usize> {
    /// `H[i][j]`: change of source coordinate `i` (units of 2^−F voxels) per half-voxel step of target
    /// coordinate `j`.
    h: [[i128; K]; K],
    /// Source position (units of 2^−F voxels) of the target point 0.
    b: [i128; K],
    /// Fractional bits `F`.
    frac: u32,
}

impl<const K: usize> FixedAffine<K> {
    /// The fixed-point inverse of `m` (source → target) with `frac_bits` fractional bits (8 … 48).
    ///
    /// # Errors
    /// [`OpsError::Singular`] if `m` is singular, [`OpsError::FixedPointOverflow`] if its inverse has
    /// entries too large for fixed point; [`OpsError::BadFractionBits`] for `frac_bits` outside 8 … 48.
    pub fn new(m: &Affine<K>, frac_bits: u32) -> Result<Self, OpsError> {
        if !(8..=48).contains(&frac_bits) {
            return Err(OpsError::BadFractionBits { bits: frac_bits });
        }
        let inv = m.inverse()?;
        let limit = 2f64.powi(60);
        let mut h = [[0i128; K]; K];
        let mut b = [0i128; K];
        for i in 0..K {
            for j in 0..K {
                let v = (inv.a[i][j] * 2f64.powi(frac_bits as i32 - 1)).round();
                if v.abs() > limit {
                    return Err(OpsError::FixedPointOverflow);
                }
                h[i][j] = v as i128;
            }
            let v = (inv.b[i] * 2f64.powi(frac_bits as i32)).round();
            if v.abs() > limit * 2f64.powi(24) {
                return Err(OpsError::FixedPointOverflow);
            }
            b[i] = v as i128;
        }
        Ok(Self {
            h,
            b,
            frac: frac_bits,
        })
    }

    /// The source voxel whose cell holds the (fixed-point) preimage of target voxel `q`'s centre — the rule
    /// [`transform_fixed`] implements exactly. Uses multiplications; the traversal does not.
    pub fn source_voxel(&self, q: [u32; K]) -> [i64; K] {
        std::array::from_fn(|i| {
            let mut p = self.b[i];
            for j in 0..K {
                p += self.h[i][j] * (2 * i128::from(q[j]) + 1);
            }
            clamp(p >> self.frac)
        })
    }
}

fn clamp(v: i128) -> i64 {
    v.clamp(i128::from(i64::MIN / 2), i128::from(i64::MAX / 2)) as i64
}

impl<const K: usize> IncrementalPreimage<K> for FixedAffine<K> {
    /// The fixed-point preimage of the cell's first voxel centre.
    type Ctx = [i128; K];

    fn root(&self) -> [i128; K] {
        // Target centre (½, …, ½) = one half-voxel step on each axis: additions only.
        std::array::from_fn(|i| {
            let mut p = self.b[i];
            for j in 0..K {
                p += self.h[i][j];
            }
            p
        })
    }

    fn child(&self, ctx: &[i128; K], code: usize, log_side: u32) -> [i128; K] {
        // The child's first centre is `side/2` voxels = `side` half-voxels further on the axes in `code`.
        std::array::from_fn(|i| {
            let mut p = ctx[i];
            for j in 0..K {
                if code >> j & 1 == 1 {
                    p += self.h[i][j] << log_side;
                }
            }
            p
        })
    }

    fn voxel(&self, ctx: &[i128; K], _q: [u32; K]) -> [i64; K] {
        ctx.map(|p| clamp(p >> self.frac))
    }

    fn cell_box(&self, ctx: &[i128; K], _origin: [u32; K], side: u64) -> [(i64, i64); K] {
        let log = side.trailing_zeros();
        std::array::from_fn(|i| {
            let (mut lo, mut hi) = (ctx[i], ctx[i]);
            for j in 0..K {
                // From the first to the last centre: 2(side − 1) half-voxel steps.
                let span = (self.h[i][j] << (log + 1)) - (self.h[i][j] << 1);
                if span < 0 {
                    lo += span;
                } else {
                    hi += span;
                }
            }
            (clamp(lo >> self.frac), clamp(hi >> self.frac))
        })
    }
}

/// Applies the affine map `m` (source → target) with the integer-only traversal: the inverse is rounded
/// to `frac_bits`-bit fixed point once, then every cell's image comes from its parent's by additions and
/// shifts. The output equals [`FixedAffine::source_voxel`] at every voxel and is reduced.
///
/// ```
/// use ktree::{stacking::paper::stack, rays::ball_rays, ops::{transform, transform_fixed, Affine}};
/// let ball = stack(&ball_rays::<3>(6, [70, 60, 64], 40).unwrap());
/// let m = Affine::rotation_about(0, 1, 30.0, Affine::<3>::universe_centre(6)).unwrap();
/// let fixed = transform_fixed(&ball, &m, 32).unwrap();
/// assert_eq!(fixed, transform(&ball, &m).unwrap()); // the rounding of the matrix changes nothing here
/// ```
///
/// # Errors
/// As [`FixedAffine::new`]; [`OpsError::Storage`] if a read of `tree` fails.
pub fn transform_fixed<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    m: &Affine<K>,
    frac_bits: u32,
) -> Result<KTree<K>, OpsError> {
    let map = FixedAffine::new(m, frac_bits)?;
    resample_incremental_into::<K, _, _, _, T::Error>(tree, &map, Memory::new(tree.universe()))
        .map_err(OpsError::storage)
}

/// [`transform_fixed`] written to `sink`.
///
/// # Errors
/// As [`transform_fixed`], and the sink's write error.
pub fn transform_fixed_into<const K: usize, T, S, E>(
    tree: &T,
    m: &Affine<K>,
    frac_bits: u32,
    sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<OpsError> + From<T::Error> + From<S::Error>,
{
    let map = FixedAffine::new(m, frac_bits)?;
    resample_incremental_into(tree, &map, sink)
}
