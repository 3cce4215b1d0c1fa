//! Projective maps and Meagher's perspective deformation (§7, the second half of claim M6): instead of
//! dividing by depth when drawing, the object is deformed so that an orthographic projection of the result
//! looks like a perspective view.
//!
//! A projective map is a homogeneous `(K+1)×(K+1)` matrix whose last row is not `0 … 0 1`:
//! `x ↦ (A·x + b) / (p·x + q)`. Target voxel `q` is full iff the source voxel containing the preimage of
//! its centre is. As long as the denominator keeps one sign over the universe, the preimage of a box is
//! inside the convex hull of the preimages of its corners, so the overlay engine's cell boxes stay
//! conservative and single voxels are decided exactly ([`Projective::source_voxel`]). Floating point, like
//! [`super::affine`].

// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use super::output::Memory;
use super::overlay::{resample_into, resample_values, Preimage};
use super::OpsError;
use crate::space::Universe;
use crate::tree::sink::LevelSink;
use crate::tree::storage::TreeStorage;
use crate::tree::valued::ValueStorage;
use crate::tree::KTree;

/// A projective map of a `K`-dimensional universe, as a homogeneous `(K+1)×(K+1)` matrix acting on column
/// vectors `[x; 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Projective<const K: usize> {
    /// Row-major `(K+1)²` entries.
    m: Vec<f64>,
}

impl<const K: usize> Projective<K> {
    /// From a homogeneous matrix in row-major order.
    ///
    /// # Errors
    /// [`OpsError::MatrixSize`] or [`OpsError::NonFiniteEntry`] for a wrong entry count or a non-finite
    /// entry.
    pub fn from_homogeneous(m: &[f64]) -> Result<Self, OpsError> {
        super::affine::check_homogeneous(K, m)?;
        Ok(Self { m: m.to_vec() })
    }

    /// Meagher's perspective deformation for a viewer on the line through the universe's centre parallel to
    /// axis `depth`, at distance `distance` (voxels) in front of the face `x_depth = 0`, looking towards
    /// larger `x_depth`. Across the view axis, coordinates shrink towards the axis by `d / (x_depth + d)`
    /// (Meagher's `Y' = Y·X_s/X`); along it, `x_depth ↦ (U + d)·x_depth / (x_depth + d)`, which keeps the
    /// faces `0` and `U` in place and the map projective (straight lines stay straight).
    ///
    /// # Errors
    /// [`OpsError::BadAxis`] if `depth ≥ K`, [`OpsError::BadDistance`] if `distance` is not positive and
    /// finite.
    pub fn perspective(level: u32, depth: usize, distance: f64) -> Result<Self, OpsError> {
        if depth >= K {
            return Err(OpsError::BadAxis { axis: depth, k: K });
        }
        if !(distance.is_finite() && distance > 0.0) {
            return Err(OpsError::BadDistance { distance });
        }
        let n = K + 1;
        let u = (1u64 << level) as f64;
        let d = distance;
        let mut m = vec![0.0; n * n];
        for i in 0..K {
            if i == depth {
                m[i * n + depth] = u + d;
            } else {
                m[i * n + i] = d;
                m[i * n + depth] = u / 2.0;
            }
        }
        m[K * n + depth] = 1.0;
        m[K * n + K] = d;
        Ok(Self { m })
    }

    /// The homogeneous matrix of an affine map.
    pub fn from_affine(a: &super::Affine<K>) -> Self {
        let n = K + 1;
        let mut m = vec![0.0; n * n];
        for i in 0..K {
            for j in 0..K {
                m[i * n + j] = a.a[i][j];
            }
            m[i * n + K] = a.b[i];
        }
        m[K * n + K] = 1.0;
        Self { m }
    }

    /// `self ∘ first`: apply `first`, then `self` (the matrix product).
    pub fn after(&self, first: &Self) -> Self {
        let n = K + 1;
        let m = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                (0..n).map(|l| self.m[i * n + l] * first.m[l * n + j]).sum()
            })
            .collect();
        Self { m }
    }

    /// Applies the map to a point; `None` where the denominator is zero.
    pub fn apply(&self, x: [f64; K]) -> Option<[f64; K]> {
        let n = K + 1;
        let row =
            |i: usize| self.m[i * n + K] + (0..K).map(|j| self.m[i * n + j] * x[j]).sum::<f64>();
        let w = row(K);
        if w == 0.0 {
            return None;
        }
        Some(std::array::from_fn(|i| row(i) / w))
    }

    /// The inverse map.
    ///
    /// # Errors
    /// [`OpsError::Singular`] if the matrix is singular.
    pub fn inverse(&self) -> Result<Self, OpsError> {
        let n = K + 1;
        let mut a = self.m.clone();
        let mut inv: Vec<f64> = (0..n * n)
            .map(|k| f64::from(u8::from(k / n == k % n)))
            .collect();
        for col in 0..n {
            let pivot = (col..n)
                .max_by(|&x, &y| a[x * n + col].abs().total_cmp(&a[y * n + col].abs()))
                .unwrap_or(col);
            if a[pivot * n + col].abs() < 1e-12 {
                return Err(OpsError::Singular);
            }
            for j in 0..n {
                a.swap(col * n + j, pivot * n + j);
                inv.swap(col * n + j, pivot * n + j);
            }
            let p = a[col * n + col];
            for j in 0..n {
                a[col * n + j] /= p;
                inv[col * n + j] /= p;
            }
            for r in 0..n {
                let f = a[r * n + col];
                if r != col && f != 0.0 {
                    for j in 0..n {
                        a[r * n + j] -= f * a[col * n + j];
                        inv[r * n + j] -= f * inv[col * n + j];
                    }
                }
            }
        }
        Ok(Self { m: inv })
    }

    /// For an *inverse* map: the source voxel containing the image of the centre of target voxel `q`
    /// (`None` if it maps to infinity). This is the rule [`transform_projective`] implements exactly.
    pub fn source_voxel(&self, q: [u32; K]) -> Option<[i64; K]> {
        self.apply(q.map(|c| f64::from(c) + 0.5))
            .map(|x| x.map(|v| v.floor().clamp(-1e15, 1e15) as i64))
    }

    /// The denominator at a point.
    fn w(&self, x: [f64; K]) -> f64 {
        let n = K + 1;
        self.m[K * n + K] + (0..K).map(|j| self.m[K * n + j] * x[j]).sum::<f64>()
    }
}

struct Inverse<const K: usize> {
    map: Projective<K>,
    slack: f64,
}

impl<const K: usize> Preimage<K> for Inverse<K> {
    fn voxel(&self, q: [u32; K]) -> [i64; K] {
        // The denominator is checked positive over the universe, so `None` cannot happen; map it to the void.
        self.map.source_voxel(q).unwrap_or([-1; K])
    }

    fn cell_box(&self, origin: [u32; K], side: u64) -> [(i64, i64); K] {
        let mut lo = [f64::INFINITY; K];
        let mut hi = [f64::NEG_INFINITY; K];
        for corner in 0..1usize << K {
            let c: [f64; K] = std::array::from_fn(|i| {
                f64::from(origin[i])
                    + 0.5
                    + if corner >> i & 1 == 1 {
                        (side - 1) as f64
                    } else {
                        0.0
                    }
            });
            let x = self.map.apply(c).unwrap_or([0.0; K]);
            for i in 0..K {
                lo[i] = lo[i].min(x[i]);
                hi[i] = hi[i].max(x[i]);
            }
        }
        std::array::from_fn(|i| {
            let s = self.slack * (1.0 + lo[i].abs().max(hi[i].abs()));
            (
                (lo[i] - s).floor().clamp(-1e15, 1e15) as i64,
                (hi[i] + s).floor().clamp(-1e15, 1e15) as i64,
            )
        })
    }
}

/// Applies a projective map (source → target) to the object in the same universe; parts mapped outside
/// are cut off. Target voxel `q` is full iff source voxel `m⁻¹`-[`Projective::source_voxel`]`(q)` is.
///
/// ```
/// use ktree::{stacking::paper::stack, rays::ball_rays, ops::{transform_projective, Projective}};
/// let ball = stack(&ball_rays::<3>(6, [64, 64, 64], 40).unwrap());
/// let p = Projective::<3>::perspective(6, 2, 64.0).unwrap();
/// let seen = transform_projective(&ball, &p).unwrap();
/// seen.assert_well_formed();
/// assert!(seen.voxel_count() < ball.voxel_count()); // deformed smaller across, farther parts more
/// ```
///
/// # Errors
/// [`OpsError::Singular`] if the matrix is singular, [`OpsError::ToInfinity`] if its inverse's
/// denominator changes sign (or vanishes) over the universe — the map would send part of it to infinity;
/// [`OpsError::Storage`] if a read of `tree` fails.
pub fn transform_projective<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    m: &Projective<K>,
) -> Result<KTree<K>, OpsError> {
    let map = Inverse::of(m, tree.universe())?;
    resample_into::<K, _, _, _, T::Error>(tree, &map, Memory::new(tree.universe()))
        .map_err(OpsError::storage)
}

/// [`transform_projective`] of a valued tree: each target voxel takes the value of the source voxel its
/// centre maps back into.
///
/// # Errors
/// As [`transform_projective`].
pub fn transform_projective_values<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    m: &Projective<K>,
) -> Result<KTree<K, T::Value>, OpsError> {
    let map = Inverse::of(m, tree.universe())?;
    resample_values(tree, &map).map_err(OpsError::storage)
}

/// [`transform_projective`] written to `sink`.
///
/// # Errors
/// As [`transform_projective`], and the sink's write error.
pub fn transform_projective_into<const K: usize, T, S, E>(
    tree: &T,
    m: &Projective<K>,
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

impl<const K: usize> Inverse<K> {
    /// The preimage of `m` over `universe`, or why `m` cannot map it.
    fn of(m: &Projective<K>, universe: Universe<K>) -> Result<Self, OpsError> {
        let inv = m.inverse()?;
        let u = universe.side() as f64;
        let mut sign = 0.0f64;
        for corner in 0..1usize << K {
            let c: [f64; K] = std::array::from_fn(|i| if corner >> i & 1 == 1 { u } else { 0.0 });
            let w = inv.w(c);
            if w == 0.0 || (sign != 0.0 && w.signum() != sign) {
                return Err(OpsError::ToInfinity);
            }
            sign = w.signum();
        }
        Ok(Self {
            map: inv,
            slack: 1e-9,
        })
    }
}
