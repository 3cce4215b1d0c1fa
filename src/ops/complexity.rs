//! Meagher's complexity metric (§5, claim M9): the number of nodes, one value per level, and its
//! normalisations — over placements of the object at sub-cell offsets, and over a set of rotations (or any
//! maps): the node count as a function of the placement, with its minimum, mean and maximum. Each reads
//! any [`TreeStorage`].

use super::affine::{transform, Affine};
use super::translate::translate;
use super::OpsError;
use crate::query::bounding_box;
use crate::tree::storage::{infallible, TreeStorage};
use crate::tree::{KTree, LevelCounts};

/// The metric itself: node counts per level (from the root), as [`KTree::counts_per_level`] gives.
pub fn complexity<const K: usize, T: TreeStorage<K>>(tree: &T) -> Vec<LevelCounts> {
    tree.counts_per_level()
}

/// Node counts of an object over a family of placements.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Normalised {
    /// For each placement (in the order given or enumerated), the total node count: the metric as a
    /// function of the placement.
    pub counts: Vec<u64>,
    /// The smallest count.
    pub min: u64,
    /// The mean count.
    pub mean: f64,
    /// The largest count.
    pub max: u64,
    /// Placements that lost voxels at the universe's border (their counts describe a clipped object).
    pub clipped: usize,
}

impl Normalised {
    fn from_counts(counts: Vec<u64>, clipped: usize) -> Self {
        let min = counts.iter().copied().min().unwrap_or(0);
        let max = counts.iter().copied().max().unwrap_or(0);
        let mean = if counts.is_empty() {
            0.0
        } else {
            counts.iter().sum::<u64>() as f64 / counts.len() as f64
        };
        Self {
            counts,
            min,
            mean,
            max,
            clipped,
        }
    }
}

/// Meagher's first normalisation: the object translated so that it touches the `K` faces of the universe
/// through the origin (the lower corner of its bounding box, [`bounding_box`], moved to the origin).
///
/// ```
/// use ktree::{KTree, ops::normalise_to_origin};
/// let a = KTree::<1>::from_dense(2, &[false, false, true, false]).unwrap();
/// assert_eq!(normalise_to_origin(&a).unwrap().to_dense().unwrap(), [true, false, false, false]);
/// ```
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn normalise_to_origin<const K: usize, T: TreeStorage<K>>(
    tree: &T,
) -> Result<KTree<K>, T::Error> {
    let lo = bounding_box(tree)?.map_or([0; K], |(lo, _)| lo);
    translate(tree, lo.map(|v| -i64::from(v)))
}

/// Node counts over all `2^(K·bits)` translations by offsets in `[0, 2^bits)` per axis of the object first
/// normalised to the origin: Meagher's "minimum (or mean) over placements". Offsets enumerate with axis 0
/// fastest.
///
/// # Errors
/// [`OpsError::TooManyPlacements`] if `2^(K·bits)` exceeds 65 536 placements; [`OpsError::Storage`] if a
/// read of `tree` fails.
pub fn over_translations<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    bits: u32,
) -> Result<Normalised, OpsError> {
    if K as u32 * bits > 16 {
        return Err(OpsError::TooManyPlacements {
            per_axis: 1u64.checked_shl(bits).unwrap_or(u64::MAX),
            k: K,
        });
    }
    let base = normalise_to_origin(tree).map_err(OpsError::storage)?;
    let voxels = base.voxel_count();
    let n = 1usize << (K as u32 * bits);
    let mut counts = Vec::with_capacity(n);
    let mut clipped = 0;
    for i in 0..n {
        let t: [i64; K] =
            std::array::from_fn(|a| ((i >> (a as u32 * bits)) & ((1 << bits) - 1)) as i64);
        let moved = infallible(translate(&base, t));
        if moved.voxel_count() != voxels {
            clipped += 1;
        }
        counts.push(moved.node_count());
    }
    Ok(Normalised::from_counts(counts, clipped))
}

/// Node counts of an object built afresh at each sub-voxel placement: `build(offset)` is called for every
/// offset in `[0, steps)^K` (axis 0 fastest), in whatever unit the builder uses — e.g. half voxels for
/// [`crate::rays::ball_rays`]'s doubled coordinates, giving Meagher's `2^K` placements with `steps = 2`.
/// Unlike [`over_translations`], this re-digitizes the solid, so it measures the metric's dependence on
/// the object's exact position, not only on whole-voxel shifts.
///
/// # Errors
/// The first error `build` returns; [`OpsError::TooManyPlacements`] beyond 65 536 placements.
pub fn over_placements<const K: usize, E: From<OpsError>>(
    steps: u32,
    mut build: impl FnMut([u32; K]) -> Result<KTree<K>, E>,
) -> Result<Normalised, E> {
    let n = u64::from(steps).pow(K as u32);
    if n > 1 << 16 {
        return Err(OpsError::TooManyPlacements {
            per_axis: steps.into(),
            k: K,
        }
        .into());
    }
    let mut counts = Vec::with_capacity(n as usize);
    for i in 0..n {
        let offset: [u32; K] = std::array::from_fn(|a| {
            ((i / u64::from(steps).pow(a as u32)) % u64::from(steps)) as u32
        });
        counts.push(build(offset)?.node_count());
    }
    Ok(Normalised::from_counts(counts, 0))
}

/// Node counts of the object under each map (e.g. rotations at uniformly spread angles): the other
/// normalisation Meagher proposes.
///
/// # Errors
/// [`OpsError::Singular`] for a singular map; [`OpsError::Storage`] if a read of `tree` fails.
pub fn over_maps<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    maps: &[Affine<K>],
) -> Result<Normalised, OpsError> {
    let mut counts = Vec::with_capacity(maps.len());
    for m in maps {
        counts.push(transform(tree, m)?.node_count());
    }
    Ok(Normalised::from_counts(counts, 0))
}
