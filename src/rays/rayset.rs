//! `RaySet<K>`: an object as sorted, disjoint runs along the last axis, one list per column.

use super::ColumnKeys;
use crate::space::{DimCheck, SpaceError, Universe};
use thiserror::Error;

/// A surface normal at a run's end, one component per axis (not necessarily of unit length).
pub type Normal<const K: usize> = [f32; K];

/// One run of a ray set: the column is given by the first `K − 1` coordinates of `start`; the run enters the
/// object at `z1 = start[K−1]` and leaves it at `z2`, covering the voxels `z1 ≤ z < z2` (half-open).
///
/// ```
/// use ktree::Ray;
/// let ray = Ray::new([1, 1, 17], 93); // Akman & Franklin's Fig. 3 ray: 76 voxels, z = 17..=92
/// assert_eq!((ray.z1(), ray.z2, ray.len()), (17, 93, 76));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Ray<const K: usize> {
    /// The first voxel of the run: the column's `K − 1` coordinates, then `z1`.
    pub start: [u32; K],
    /// One past the last voxel along the last axis.
    pub z2: u32,
}

impl<const K: usize> Ray<K> {
    /// The run from `start` (column coordinates, then `z1`) to `z2` (exclusive).
    pub fn new(start: [u32; K], z2: u32) -> Self {
        Self { start, z2 }
    }

    /// Where the run enters the object.
    pub fn z1(&self) -> u32 {
        self.start[K - 1]
    }

    /// The column: `start` with the last coordinate set to 0.
    pub fn column(&self) -> [u32; K] {
        let mut c = self.start;
        c[K - 1] = 0;
        c
    }

    /// The number of voxels covered (`z2 − z1`, 0 for an invalid run).
    pub fn len(&self) -> u64 {
        u64::from(self.z2.saturating_sub(self.z1()))
    }

    /// Whether the run covers no voxel (`z2 ≤ z1`: such a run is rejected by [`RaySet::from_rays`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Errors when building a ray set.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum RayError {
    /// The universe level is not allowed.
    #[error(transparent)]
    Space(#[from] SpaceError),
    /// A column coordinate lies outside `[0, U)`.
    #[error("ray {index}: column coordinate {value} on axis {axis} is outside [0, {side})")]
    ColumnOutside {
        /// The 0-based position of the ray in the input.
        index: usize,
        /// The axis.
        axis: usize,
        /// The coordinate.
        value: u32,
        /// The universe's side.
        side: u64,
    },
    /// `z1` or `z2` lies outside `[0, U]`.
    #[error("ray {index}: run [{z1}, {z2}) reaches outside [0, {side}]")]
    RunOutside {
        /// The 0-based position of the ray in the input.
        index: usize,
        /// Start.
        z1: u32,
        /// End.
        z2: u32,
        /// The universe's side.
        side: u64,
    },
    /// `z1 ≥ z2`: a run must cover at least one voxel.
    #[error("ray {index}: run [{z1}, {z2}) is empty or reversed (need z1 < z2)")]
    EmptyRun {
        /// The 0-based position of the ray in the input.
        index: usize,
        /// Start.
        z1: u32,
        /// End.
        z2: u32,
    },
    /// Two valued runs of one column share a voxel (each voxel holds at most one value).
    #[error("run {index}: [{z1}, {z2}) overlaps another run of its column")]
    Overlap {
        /// The 0-based position of the run in the input.
        index: usize,
        /// Start.
        z1: u32,
        /// End.
        z2: u32,
    },
    /// A slab of a dense volume read slab by slab holds another number of values than its box has voxels.
    #[error("the slab from {first} along the last axis holds {got} values, but its box has {expected} voxels")]
    SlabLength {
        /// The slab's first coordinate along the last axis.
        first: u32,
        /// The voxels of the slab's box.
        expected: usize,
        /// The values given.
        got: usize,
    },
    /// A run's value is one no voxel may hold.
    #[error("run {index}: {error}")]
    Value {
        /// The 0-based position of the run (or of the voxel, in a dense array) in the input.
        index: usize,
        /// Why the value is refused.
        error: crate::value::ValueError,
    },
    /// The normals given do not match the rays one for one.
    #[error("{rays} rays but {normals} pairs of normals")]
    NormalCount {
        /// Number of rays.
        rays: usize,
        /// Number of normal pairs.
        normals: usize,
    },
}

/// Checks the `index`-th run of an input against a universe of side `side`: its column inside, `z1 < z2`,
/// both ends in `[0, side]`.
pub(crate) fn check_ray<const K: usize>(
    index: usize,
    ray: &Ray<K>,
    side: u64,
) -> Result<(), RayError> {
    for (axis, &value) in ray.start[..K - 1].iter().enumerate() {
        if u64::from(value) >= side {
            return Err(RayError::ColumnOutside {
                index,
                axis,
                value,
                side,
            });
        }
    }
    let (z1, z2) = (ray.z1(), ray.z2);
    if u64::from(z1) > side || u64::from(z2) > side {
        return Err(RayError::RunOutside {
            index,
            z1,
            z2,
            side,
        });
    }
    if z1 >= z2 {
        return Err(RayError::EmptyRun { index, z1, z2 });
    }
    Ok(())
}

/// An object as rays: for each column (the first `K − 1` coordinates), sorted, disjoint, non-touching
/// half-open runs `[z1, z2)` along the last axis, optionally with a surface normal at each end.
///
/// Building a set validates every run (inside the universe, `z1 < z2`); runs of one column that overlap or
/// touch are merged into one (the merged run keeps the first run's entry normal and the last run's exit
/// normal). Columns are kept in lexicographic order with axis 0 most significant, runs by `z1`.
///
/// ```
/// use ktree::{RaySet, Ray};
/// let rays = RaySet::<2>::from_rays(3, [Ray::new([1, 0], 4), Ray::new([1, 3], 6), Ray::new([0, 2], 3)]).unwrap();
/// assert_eq!(rays.len(), 2); // [0,4) and [3,6) in column 1 merged into [0,6)
/// assert_eq!(rays.voxel_count(), 7);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RaySet<const K: usize> {
    universe: Universe<K>,
    /// Column key of each run (see [`RaySet::column_key`]), non-decreasing.
    columns: Vec<u64>,
    /// `(z1, z2)` of each run.
    runs: Vec<(u32, u32)>,
    /// Normals at `(z1, z2)` of each run, when the set carries them.
    normals: Option<Vec<[Normal<K>; 2]>>,
}

impl<const K: usize> RaySet<K> {
    /// The empty set in a universe of level `level`.
    ///
    /// # Errors
    /// [`RayError::Space`] if the level is too large for `K`.
    pub fn empty(level: u32) -> Result<Self, RayError> {
        let () = DimCheck::<K>::OK;
        Ok(Self {
            universe: Universe::new(level)?,
            columns: Vec::new(),
            runs: Vec::new(),
            normals: None,
        })
    }

    /// The ray set of the whole universe: one run `[0, U)` per column.
    ///
    /// # Errors
    /// [`RayError::Space`] if the level is too large, or if the universe has more than 2^32 columns.
    pub fn full(level: u32) -> Result<Self, RayError> {
        let mut set = Self::empty(level)?;
        let columns = 1u64 << (level as usize * (K - 1));
        if columns > 1 << 32 {
            return Err(RayError::Space(SpaceError::TooLargeForDense {
                voxels: columns.into(),
                limit: 1 << 32,
            }));
        }
        let side = set.universe.side() as u32;
        set.columns = (0..columns).collect();
        set.runs = vec![(0, side); columns as usize];
        Ok(set)
    }

    /// Builds a set from runs in any order; validates them and merges overlapping or touching runs.
    ///
    /// # Errors
    /// [`RayError::Space`] for a bad level; [`RayError::ColumnOutside`], [`RayError::RunOutside`] and
    /// [`RayError::EmptyRun`] name the first bad run by its position in `rays`.
    pub fn from_rays(level: u32, rays: impl IntoIterator<Item = Ray<K>>) -> Result<Self, RayError> {
        Self::build(level, rays.into_iter().map(|r| (r, None)))
    }

    /// Like [`RaySet::from_rays`], with a pair of normals (at `z1`, at `z2`) for each run.
    ///
    /// # Errors
    /// As [`RaySet::from_rays`].
    pub fn from_rays_with_normals(
        level: u32,
        rays: impl IntoIterator<Item = (Ray<K>, [Normal<K>; 2])>,
    ) -> Result<Self, RayError> {
        Self::build(level, rays.into_iter().map(|(r, n)| (r, Some(n))))
    }

    fn build(
        level: u32,
        rays: impl Iterator<Item = (Ray<K>, Option<[Normal<K>; 2]>)>,
    ) -> Result<Self, RayError> {
        let mut set = Self::empty(level)?;
        let side = set.universe.side();
        let mut entries: Vec<(u64, u32, u32, Option<[Normal<K>; 2]>)> = Vec::new();
        let mut with_normals = None;
        for (index, (ray, normals)) in rays.enumerate() {
            check_ray(index, &ray, side)?;
            let (z1, z2) = (ray.z1(), ray.z2);
            if *with_normals.get_or_insert(normals.is_some()) != normals.is_some() {
                return Err(RayError::NormalCount {
                    rays: index + 1,
                    normals: index,
                });
            }
            entries.push((set.column_key(ray.start), z1, z2, normals));
        }
        // Sort by column, then z1. Stable sorts are not needed: equal (column, z1) runs are merged anyway.
        entries.sort_unstable_by_key(|e| (e.0, e.1, e.2));
        let keep_normals = with_normals == Some(true);
        let mut normals_out = Vec::new();
        for (column, z1, z2, normals) in entries {
            let last = set.runs.len();
            if last > 0 && set.columns[last - 1] == column && z1 <= set.runs[last - 1].1 {
                // Overlapping or touching the previous run of the same column: extend it.
                if z2 > set.runs[last - 1].1 {
                    set.runs[last - 1].1 = z2;
                    if let Some(n) = normals {
                        let prev: &mut [Normal<K>; 2] = &mut normals_out[last - 1];
                        prev[1] = n[1];
                    }
                }
                continue;
            }
            set.columns.push(column);
            set.runs.push((z1, z2));
            if let Some(n) = normals {
                normals_out.push(n);
            }
        }
        if keep_normals {
            set.normals = Some(normals_out);
        }
        Ok(set)
    }

    /// The universe.
    pub fn universe(&self) -> Universe<K> {
        self.universe
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        self.universe.level()
    }

    /// The number of runs (rays).
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether the set has no run.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Whether the runs carry normals.
    pub fn has_normals(&self) -> bool {
        self.normals.is_some()
    }

    /// The total number of voxels covered.
    pub fn voxel_count(&self) -> u128 {
        self.runs.iter().map(|&(z1, z2)| u128::from(z2 - z1)).sum()
    }

    /// The `i`-th run in sorted order.
    pub fn ray(&self, i: usize) -> Ray<K> {
        let mut start = self.column_of_key(self.columns[i]);
        start[K - 1] = self.runs[i].0;
        Ray {
            start,
            z2: self.runs[i].1,
        }
    }

    /// The normals (at `z1`, at `z2`) of the `i`-th run, if the set carries normals.
    pub fn normals(&self, i: usize) -> Option<[Normal<K>; 2]> {
        self.normals.as_ref().map(|n| n[i])
    }

    /// All runs in sorted order (column, then `z1`).
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Ray<K>> + '_ {
        (0..self.len()).map(move |i| self.ray(i))
    }

    /// The column keys of the runs, one per run, non-decreasing (see [`RaySet::column_key`]).
    pub fn column_keys(&self) -> &[u64] {
        &self.columns
    }

    /// The `(z1, z2)` of the runs, in sorted order.
    pub fn runs(&self) -> &[(u32, u32)] {
        &self.runs
    }

    /// The key of a column: its `K − 1` coordinates packed with axis 0 most significant, `L` bits each
    /// (the last coordinate of `point` is ignored; [`ColumnKeys::pack`]). Keys sort columns
    /// lexicographically.
    pub fn column_key(&self, point: [u32; K]) -> u64 {
        self.keys().pack(point)
    }

    /// How this set's column keys pack a column ([`ColumnKeys`] of its level).
    pub fn keys(&self) -> ColumnKeys<K> {
        ColumnKeys::new(self.level())
    }

    /// The column of a key (last coordinate 0): the inverse of [`RaySet::column_key`].
    pub fn column_of_key(&self, key: u64) -> [u32; K] {
        Self::column_of_key_at(self.level(), key)
    }

    /// [`RaySet::column_of_key`] in a universe of level `level`.
    pub fn column_of_key_at(level: u32, key: u64) -> [u32; K] {
        ColumnKeys::<K>::new(level).unpack(key)
    }

    /// The runs of one column, as a slice of `(z1, z2)`, found by binary search.
    pub fn column_runs(&self, column: [u32; K]) -> &[(u32, u32)] {
        let key = self.column_key(column);
        let lo = self.columns.partition_point(|&c| c < key);
        let hi = self.columns.partition_point(|&c| c <= key);
        &self.runs[lo..hi]
    }

    /// Whether the voxel `point` is covered by a run.
    pub fn contains(&self, point: [u32; K]) -> bool {
        let z = point[K - 1];
        let runs = self.column_runs(point);
        let i = runs.partition_point(|&(_, z2)| z2 <= z);
        i < runs.len() && runs[i].0 <= z
    }

    /// Groups of consecutive runs that share a column: `(column key, index range)` in order.
    pub fn column_groups(&self) -> ColumnGroups<'_> {
        ColumnGroups {
            columns: &self.columns,
            at: 0,
        }
    }

    /// The column keys and runs, taken apart (normals dropped).
    pub(crate) fn into_parts(self) -> (Vec<u64>, Vec<(u32, u32)>) {
        (self.columns, self.runs)
    }

    /// Builds a set directly from sorted, validated parts. Used by crate code that generates runs in order.
    pub(crate) fn from_sorted_parts(
        universe: Universe<K>,
        columns: Vec<u64>,
        runs: Vec<(u32, u32)>,
        normals: Option<Vec<[Normal<K>; 2]>>,
    ) -> Self {
        debug_assert_eq!(columns.len(), runs.len());
        Self {
            universe,
            columns,
            runs,
            normals,
        }
    }
}

/// Iterator over runs grouped by column, see [`RaySet::column_groups`].
#[derive(Debug, Clone)]
pub struct ColumnGroups<'a> {
    columns: &'a [u64],
    at: usize,
}

impl Iterator for ColumnGroups<'_> {
    type Item = (u64, std::ops::Range<usize>);

    fn next(&mut self) -> Option<Self::Item> {
        let start = self.at;
        let key = *self.columns.get(start)?;
        let mut end = start + 1;
        while end < self.columns.len() && self.columns[end] == key {
            end += 1;
        }
        self.at = end;
        Some((key, start..end))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_and_touching_runs_merge() {
        let set = RaySet::<3>::from_rays(
            4,
            [
                Ray::new([2, 3, 5], 8),
                Ray::new([2, 3, 0], 2),
                Ray::new([2, 3, 2], 3),
                Ray::new([2, 3, 6], 10),
                Ray::new([0, 0, 0], 1),
            ],
        )
        .unwrap();
        let runs: Vec<Ray<3>> = set.iter().collect();
        assert_eq!(
            runs,
            [
                Ray::new([0, 0, 0], 1),
                Ray::new([2, 3, 0], 3),
                Ray::new([2, 3, 5], 10)
            ]
        );
        assert!(set.contains([2, 3, 9]) && !set.contains([2, 3, 4]) && !set.contains([2, 3, 10]));
    }

    #[test]
    fn bad_runs_are_errors() {
        let e = RaySet::<2>::from_rays(3, [Ray::new([0, 3], 3)]).unwrap_err();
        assert!(matches!(e, RayError::EmptyRun { index: 0, .. }));
        let e = RaySet::<2>::from_rays(3, [Ray::new([0, 0], 1), Ray::new([0, 3], 9)]).unwrap_err();
        assert!(matches!(e, RayError::RunOutside { index: 1, .. }));
        let e = RaySet::<2>::from_rays(3, [Ray::new([8, 0], 1)]).unwrap_err();
        assert!(matches!(e, RayError::ColumnOutside { axis: 0, .. }));
        assert!(RaySet::<2>::from_rays(32, []).is_err());
        // z2 = U is allowed: the run reaches the universe's face.
        assert!(RaySet::<2>::from_rays(3, [Ray::new([7, 0], 8)]).is_ok());
    }

    #[test]
    fn normals_travel_with_merged_runs() {
        let a = [[0.0, -1.0], [0.0, 1.0]];
        let b = [[0.0, -0.5], [0.0, 0.5]];
        let set = RaySet::<2>::from_rays_with_normals(
            3,
            [(Ray::new([1, 4], 6), b), (Ray::new([1, 0], 4), a)],
        )
        .unwrap();
        assert_eq!(set.len(), 1);
        assert_eq!(set.normals(0), Some([a[0], b[1]]));
    }

    #[test]
    fn full_universe_has_one_run_per_column() {
        let set = RaySet::<3>::full(2).unwrap();
        assert_eq!(set.len(), 16);
        assert_eq!(set.voxel_count(), 64);
        assert_eq!(set.ray(5).start, [1, 1, 0]);
    }
}
