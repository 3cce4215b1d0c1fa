//! Arbitrary rotations and any affine map — a homogeneous `(K+1)×(K+1)` matrix, so any concatenation of
//! translations, scalings, rotations and shears in one pass (Meagher §6 "Concatenated geometric
//! operations", claims M5 and M6) — by overlays on the target obel.
//!
//! Target voxel `q` is full iff the source voxel containing `M⁻¹(q + ½)` (its centre mapped back) is full.
//! The engine ([`super::overlay`]) decides whole target cells from the source obels meeting the box that
//! bounds the mapped-back centres, and single voxels exactly, so the result equals the brute-force map of
//! every voxel centre ([`Affine::source_voxel`]).
//!
//! **Integer-only or not (M8).** Booleans, complement, child reordering ([`super::rotate_axes`]),
//! translation, scaling by powers of two and by rational factors, interference and mass use only integer
//! arithmetic (mass also multiplies, to sum moments exactly). This module uses floating point (`f64`): an
//! arbitrary angle's cosine is irrational, so the matrix cannot be held exactly in integers; cell boxes
//! are widened by a bound on the rounding error and single voxels are decided by the very function the
//! reference uses, so decisions stay exact with respect to that function. For Meagher's integer-only
//! version — the inverse rounded once to fixed point, then only additions and shifts while descending —
//! see [`super::transform_fixed`].
//!
//! ```
//! use ktree::ops::{rotate_axes, transform, Affine, AxisMap};
//! use ktree::{rays::ball_rays, stacking::paper::stack};
//! let ball = stack(&ball_rays::<2>(4, [12, 16], 10).unwrap());
//! // A quarter turn about the universe's centre, by an affine map and by reordering children: the same tree.
//! let m = Affine::rotation_about(0, 1, 90.0, Affine::<2>::universe_centre(4)).unwrap();
//! let turned = transform(&ball, &m).unwrap();
//! assert_eq!(turned, rotate_axes(&ball, &AxisMap::quarter_turn(0, 1).unwrap()).unwrap());
//! assert_eq!(turned.voxel_count(), ball.voxel_count());
//! ```

// Matrix and per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use super::output::Memory;
use super::overlay::{resample_into, resample_values, Preimage};
use super::OpsError;
use crate::space::Universe;
use crate::tree::sink::LevelSink;
use crate::tree::storage::TreeStorage;
use crate::tree::valued::ValueStorage;
use crate::tree::KTree;

/// An affine map `x ↦ A·x + b` of continuous coordinates (voxel units, origin at the universe's corner).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine<const K: usize> {
    /// The linear part, `a[i][j]` = row `i`, column `j`.
    pub a: [[f64; K]; K],
    /// The translation.
    pub b: [f64; K],
}

impl<const K: usize> Affine<K> {
    /// The identity.
    pub fn identity() -> Self {
        Self {
            a: std::array::from_fn(|i| std::array::from_fn(|j| f64::from(u8::from(i == j)))),
            b: [0.0; K],
        }
    }

    /// The translation by `t`.
    pub fn translation(t: [f64; K]) -> Self {
        Self {
            b: t,
            ..Self::identity()
        }
    }

    /// The uniform scaling by `s` about the point `centre`.
    pub fn scaling_about(s: f64, centre: [f64; K]) -> Self {
        let mut m = Self::identity();
        for i in 0..K {
            m.a[i][i] = s;
            m.b[i] = centre[i] * (1.0 - s);
        }
        m
    }

    /// The rotation by `degrees` in the plane of axes `from` → `to` (positive turns `from` towards `to`)
    /// about the point `centre`. For `K = 3`, `(0, 1)` is about z, `(1, 2)` about x, `(2, 0)` about y.
    ///
    /// # Errors
    /// [`OpsError::BadAxisPair`] if an axis is `≥ K` or the two are equal.
    pub fn rotation_about(
        from: usize,
        to: usize,
        degrees: f64,
        centre: [f64; K],
    ) -> Result<Self, OpsError> {
        if from >= K || to >= K || from == to {
            return Err(OpsError::BadAxisPair { from, to, k: K });
        }
        let (s, c) = degrees.to_radians().sin_cos();
        let mut r = Self::identity();
        r.a[from][from] = c;
        r.a[from][to] = -s;
        r.a[to][from] = s;
        r.a[to][to] = c;
        let to_origin = Self::translation(centre.map(|v| -v));
        let back = Self::translation(centre);
        Ok(back.after(&r.after(&to_origin)))
    }

    /// The centre of a universe of level `level`: `(U/2, …, U/2)`.
    pub fn universe_centre(level: u32) -> [f64; K] {
        [(1u64 << level) as f64 / 2.0; K]
    }

    /// `self ∘ first`: apply `first`, then `self` (matrix product `self · first`).
    pub fn after(&self, first: &Self) -> Self {
        let mut out = Self::identity();
        for i in 0..K {
            for j in 0..K {
                out.a[i][j] = (0..K).map(|k| self.a[i][k] * first.a[k][j]).sum();
            }
            out.b[i] = self.b[i] + (0..K).map(|k| self.a[i][k] * first.b[k]).sum::<f64>();
        }
        out
    }

    /// From a homogeneous `(K+1)×(K+1)` matrix in row-major order acting on column vectors `[x; 1]`
    /// (Meagher writes row vectors times the transpose; same map).
    ///
    /// # Errors
    /// [`OpsError::MatrixSize`], [`OpsError::NonFiniteEntry`] or [`OpsError::NotAffine`] for a wrong entry
    /// count, a non-finite entry or a last row other than
    /// `0 … 0 1` (perspective maps are not affine).
    pub fn from_homogeneous(m: &[f64]) -> Result<Self, OpsError> {
        check_homogeneous(K, m)?;
        let n = K + 1;
        let last = &m[K * n..];
        if last[..K].iter().any(|&v| v != 0.0) || last[K] != 1.0 {
            return Err(OpsError::NotAffine {
                last_row: last.to_vec(),
            });
        }
        Ok(Self {
            a: std::array::from_fn(|i| std::array::from_fn(|j| m[i * n + j])),
            b: std::array::from_fn(|i| m[i * n + K]),
        })
    }

    /// The inverse map.
    ///
    /// # Errors
    /// [`OpsError::Singular`] if the linear part is singular (or nearly: a pivot below 1e-12).
    pub fn inverse(&self) -> Result<Self, OpsError> {
        // Gauss–Jordan with partial pivoting on [A | I].
        let mut a = self.a;
        let mut inv = Self::identity().a;
        for col in 0..K {
            let pivot = (col..K)
                .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
                .unwrap_or(col);
            if a[pivot][col].abs() < 1e-12 {
                return Err(OpsError::Singular);
            }
            a.swap(col, pivot);
            inv.swap(col, pivot);
            let p = a[col][col];
            for j in 0..K {
                a[col][j] /= p;
                inv[col][j] /= p;
            }
            for r in 0..K {
                if r != col {
                    let f = a[r][col];
                    if f != 0.0 {
                        for j in 0..K {
                            a[r][j] -= f * a[col][j];
                            inv[r][j] -= f * inv[col][j];
                        }
                    }
                }
            }
        }
        let b = std::array::from_fn(|i| -(0..K).map(|j| inv[i][j] * self.b[j]).sum::<f64>());
        Ok(Self { a: inv, b })
    }

    /// Applies the map to a point.
    pub fn apply(&self, x: [f64; K]) -> [f64; K] {
        std::array::from_fn(|i| {
            let mut v = self.b[i];
            for j in 0..K {
                v += self.a[i][j] * x[j];
            }
            v
        })
    }

    /// For an *inverse* map: the source voxel containing the image of the centre of target voxel `q`,
    /// `floor(self.apply(q + ½))`. This is the rule [`transform`] implements exactly.
    pub fn source_voxel(&self, q: [u32; K]) -> [i64; K] {
        self.apply(q.map(|c| f64::from(c) + 0.5))
            .map(|v| v.floor().clamp(-1e15, 1e15) as i64)
    }
}

/// The inverse map as a preimage for the overlay engine, with a rounding allowance per axis.
struct Inverse<const K: usize> {
    map: Affine<K>,
    slack: [f64; K],
}

impl<const K: usize> Preimage<K> for Inverse<K> {
    fn voxel(&self, q: [u32; K]) -> [i64; K] {
        self.map.source_voxel(q)
    }

    fn cell_box(&self, origin: [u32; K], side: u64) -> [(i64, i64); K] {
        std::array::from_fn(|i| {
            let (mut lo, mut hi) = (self.map.b[i], self.map.b[i]);
            for j in 0..K {
                let c0 = f64::from(origin[j]) + 0.5;
                let c1 = c0 + (side - 1) as f64;
                let (x, y) = (self.map.a[i][j] * c0, self.map.a[i][j] * c1);
                lo += x.min(y);
                hi += x.max(y);
            }
            let lo = (lo - self.slack[i]).floor().clamp(-1e15, 1e15) as i64;
            let hi = (hi + self.slack[i]).floor().clamp(-1e15, 1e15) as i64;
            (lo, hi)
        })
    }
}

impl<const K: usize> Inverse<K> {
    /// The preimage of `m` over `universe`: its inverse, cell boxes widened by a bound on the rounding.
    fn of(m: &Affine<K>, universe: Universe<K>) -> Result<Self, OpsError> {
        let inv = m.inverse()?;
        let side = universe.side() as f64;
        let slack = std::array::from_fn(|i| {
            let magnitude =
                inv.b[i].abs() + (0..K).map(|j| inv.a[i][j].abs()).sum::<f64>() * (side + 1.0);
            1e-9 + 64.0 * f64::EPSILON * magnitude
        });
        Ok(Self { map: inv, slack })
    }
}

/// Applies the affine map `m` (source → target coordinates) to the object, in the same universe; parts
/// mapped outside are cut off. Target voxel `q` is full iff source voxel `m⁻¹`-[`Affine::source_voxel`]`(q)`
/// is. The output is reduced.
///
/// ```
/// use ktree::{KTree, ops::{transform, Affine}};
/// let a = KTree::<2>::from_dense(1, &[true, false, false, false]).unwrap();
/// // A half turn about the universe centre moves voxel (0, 0) to (1, 1).
/// let m = Affine::rotation_about(0, 1, 180.0, Affine::<2>::universe_centre(1)).unwrap();
/// assert_eq!(transform(&a, &m).unwrap().to_dense().unwrap(), [false, false, false, true]);
/// ```
///
/// # Errors
/// [`OpsError::Singular`] if `m` is singular; [`OpsError::Storage`] if a read of `tree` fails.
pub fn transform<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    m: &Affine<K>,
) -> Result<KTree<K>, OpsError> {
    let map = Inverse::of(m, tree.universe())?;
    resample_into::<K, _, _, _, T::Error>(tree, &map, Memory::new(tree.universe()))
        .map_err(OpsError::storage)
}

/// [`transform`] of a valued tree: target voxel `q` takes the value of source voxel
/// `m⁻¹`-[`Affine::source_voxel`]`(q)` — a label volume turned or sheared, each voxel keeping its label
/// (nearest-neighbour resampling: values are never blended).
///
/// ```
/// use ktree::{KTree, ops::{transform_values, Affine}};
/// let a = KTree::<2, u8>::from_dense_values(1, &[Some(1), Some(2), None, None]).unwrap();
/// let m = Affine::rotation_about(0, 1, 180.0, Affine::<2>::universe_centre(1)).unwrap();
/// assert_eq!(transform_values(&a, &m).unwrap().to_dense_values().unwrap(), [None, None, Some(2), Some(1)]);
/// ```
///
/// # Errors
/// As [`transform`].
pub fn transform_values<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    m: &Affine<K>,
) -> Result<KTree<K, T::Value>, OpsError> {
    let map = Inverse::of(m, tree.universe())?;
    resample_values(tree, &map).map_err(OpsError::storage)
}

/// [`transform`] written to `sink`.
///
/// # Errors
/// As [`transform`], and the sink's write error.
pub fn transform_into<const K: usize, T, S, E>(
    tree: &T,
    m: &Affine<K>,
    sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<OpsError> + From<T::Error> + From<S::Error>,
{
    let map = Inverse::of(m, tree.universe())?;
    resample_into(tree, &map, sink)
}

/// Checks that `m` holds the `(k+1)²` finite entries of a homogeneous matrix.
pub(crate) fn check_homogeneous(k: usize, m: &[f64]) -> Result<(), OpsError> {
    let n = k + 1;
    if m.len() != n * n {
        return Err(OpsError::MatrixSize { given: m.len(), n });
    }
    if m.iter().any(|v| !v.is_finite()) {
        return Err(OpsError::NonFiniteEntry);
    }
    Ok(())
}
