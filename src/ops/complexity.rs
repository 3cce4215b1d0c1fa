//! Meagher's complexity metric (§5, claim M9): the number of nodes, one value per level, and its
//! normalisations — over placements of the object at sub-cell offsets, and over a set of rotations (or any
//! maps): the node count as a function of the placement, with its minimum, mean and maximum.
// Matrix and per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use super::affine::{transform, Affine};
use super::translate::translate;
use super::OpsError;
use crate::tree::{KTree, LevelCounts, NodeState};

/// The metric itself: node counts per level (from the root), as [`KTree::counts_per_level`] gives.
pub fn complexity<const K: usize>(tree: &KTree<K>) -> Vec<LevelCounts> {
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

/// The bounding box of the object's voxels, `(lo, hi)` inclusive per axis, or `None` if it is empty.
pub fn bounding_box<const K: usize>(tree: &KTree<K>) -> Option<[(u32, u32); K]> {
    let mut bx: Option<[(u32, u32); K]> = None;
    tree.for_each_leaf(|cell, state| {
        if state == NodeState::Full {
            let side = cell.side() as u32;
            let b = bx.get_or_insert([(u32::MAX, 0); K]);
            for i in 0..K {
                b[i].0 = b[i].0.min(cell.origin[i]);
                b[i].1 = b[i].1.max(cell.origin[i] + side - 1);
            }
        }
    });
    bx
}

/// Meagher's first normalisation: the object translated so that it touches the `K` faces of the universe
/// through the origin.
pub fn normalise_to_origin<const K: usize>(tree: &KTree<K>) -> KTree<K> {
    match bounding_box(tree) {
        None => tree.clone(),
        Some(bx) => translate(tree, bx.map(|b| -i64::from(b.0))),
    }
}

/// Node counts over all `2^(K·bits)` translations by offsets in `[0, 2^bits)` per axis of the object first
/// normalised to the origin: Meagher's "minimum (or mean) over placements". Offsets enumerate with axis 0
/// fastest.
///
/// # Errors
/// [`OpsError::TooManyPlacements`] if `2^(K·bits)` exceeds 65 536 placements.
pub fn over_translations<const K: usize>(
    tree: &KTree<K>,
    bits: u32,
) -> Result<Normalised, OpsError> {
    if K as u32 * bits > 16 {
        return Err(OpsError::TooManyPlacements {
            per_axis: 1u64.checked_shl(bits).unwrap_or(u64::MAX),
            k: K,
        });
    }
    let base = normalise_to_origin(tree);
    let voxels = base.voxel_count();
    let n = 1usize << (K as u32 * bits);
    let mut counts = Vec::with_capacity(n);
    let mut clipped = 0;
    for i in 0..n {
        let t: [i64; K] =
            std::array::from_fn(|a| ((i >> (a as u32 * bits)) & ((1 << bits) - 1)) as i64);
        let moved = translate(&base, t);
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
/// [`OpsError::Singular`] for a singular map.
pub fn over_maps<const K: usize>(
    tree: &KTree<K>,
    maps: &[Affine<K>],
) -> Result<Normalised, OpsError> {
    let mut counts = Vec::with_capacity(maps.len());
    for m in maps {
        counts.push(transform(tree, m)?.node_count());
    }
    Ok(Normalised::from_counts(counts, 0))
}
