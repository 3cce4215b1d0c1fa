//! Runs that carry values: an object whose voxels hold values, as runs `[z1, z2)` along the last axis, each
//! with one value — a row of a label volume, a scan line of a density. Runs of one column are disjoint;
//! two runs may touch (a label change along the row). The builder stacks them into a minimal valued tree
//! ([`KTree::from_value_runs`](crate::KTree::from_value_runs)).
//!
//! ```
//! use ktree::rays::ValueRuns;
//! use ktree::Ray;
//! // A quadtree row: labels 1 on [0, 2), 2 on [2, 3) in column x = 1.
//! let runs = ValueRuns::<2, u8>::from_runs(2, [(Ray::new([1, 0], 2), 1), (Ray::new([1, 2], 3), 2)]).unwrap();
//! assert_eq!(runs.len(), 2);
//! // Axis 0 fastest: voxel (1, z) is at 1 + 4·z.
//! let mut dense = [None; 16];
//! (dense[1], dense[5], dense[9]) = (Some(1), Some(1), Some(2));
//! assert_eq!(ValueRuns::<2, u8>::from_dense(2, &dense).unwrap(), runs);
//! ```

use super::rayset::check_ray;
use super::{ColumnKeys, Ray, RayError};
use crate::space::{Universe, DENSE_LIMIT};
use crate::value::Value;

/// One run of a [`ValueRuns`]: its column's key ([`ColumnKeys`]), `[z1, z2)` and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValueRun<V> {
    /// The column's key.
    pub column: u64,
    /// Where the run starts (inclusive).
    pub z1: u32,
    /// Where it ends (exclusive).
    pub z2: u32,
    /// What its voxels hold.
    pub value: V,
}

/// Valued runs sorted by column (axis 0 most significant) and by `z1`, disjoint in each column.
#[derive(Debug, Clone, PartialEq)]
pub struct ValueRuns<const K: usize, V> {
    universe: Universe<K>,
    runs: Vec<ValueRun<V>>,
}

impl<const K: usize, V: Value> ValueRuns<K, V> {
    /// The runs of a universe of level `level`, each a ray and its value, in any order.
    ///
    /// # Errors
    /// As [`RaySet::from_rays`](super::RaySet::from_rays) for a run outside the universe or empty;
    /// [`RayError::Overlap`] for two runs of one column that share a voxel; [`RayError::Value`] for a value
    /// no voxel may hold (a NaN).
    pub fn from_runs(
        level: u32,
        runs: impl IntoIterator<Item = (Ray<K>, V)>,
    ) -> Result<Self, RayError> {
        let universe = Universe::<K>::new(level)?;
        let keys = ColumnKeys::<K>::new(level);
        let side = universe.side();
        let mut out: Vec<(ValueRun<V>, usize)> = Vec::new();
        for (index, (ray, value)) in runs.into_iter().enumerate() {
            check_ray(index, &ray, side)?;
            let (z1, z2) = (ray.z1(), ray.z2);
            value
                .check()
                .map_err(|e| RayError::Value { index, error: e })?;
            out.push((
                ValueRun {
                    column: keys.pack(ray.start),
                    z1,
                    z2,
                    value,
                },
                index,
            ));
        }
        out.sort_unstable_by_key(|(r, _)| (r.column, r.z1));
        for pair in out.windows(2) {
            let ((a, _), (b, index)) = (&pair[0], &pair[1]);
            if a.column == b.column && b.z1 < a.z2 {
                return Err(RayError::Overlap {
                    index: *index,
                    z1: b.z1,
                    z2: b.z2,
                });
            }
        }
        Ok(Self {
            universe,
            runs: out.into_iter().map(|(r, _)| r).collect(),
        })
    }

    /// The runs of a dense array of voxels (axis 0 fastest, see [`Universe::dense_index`]): in each
    /// column, each stretch of equal values (bit-equal, [`Value::same`]) one run.
    ///
    /// # Errors
    /// [`RayError::Space`] for a level beyond the largest, a universe beyond
    /// [`DENSE_LIMIT`] voxels or an array of another length; [`RayError::Value`]
    /// for a NaN.
    pub fn from_dense(level: u32, dense: &[Option<V>]) -> Result<Self, RayError> {
        Self::from_dense_by(level, dense.len(), |i| dense[i])
    }

    /// The runs of a dense array of values (axis 0 fastest, see [`Universe::dense_index`]) where
    /// `background` means empty: a numpy or NIfTI volume as it is stored.
    ///
    /// ```
    /// use ktree::rays::ValueRuns;
    /// use ktree::KTree;
    /// // A 2 × 2 quadtree universe: (0,0) = 5, (1,0) = 0, (0,1) = 5, (1,1) = 9; 0 is the background.
    /// let runs = ValueRuns::<2, u16>::from_dense_background(1, &[5, 0, 5, 9], 0).unwrap();
    /// assert_eq!(runs.len(), 2); // column x = 0 is one run of 5s; column x = 1 holds the 9
    /// let tree = KTree::from_value_runs(&runs);
    /// assert_eq!(tree.to_dense_values().unwrap(), [Some(5), None, Some(5), Some(9)]);
    /// ```
    ///
    /// # Errors
    /// As [`ValueRuns::from_dense`].
    pub fn from_dense_background(level: u32, dense: &[V], background: V) -> Result<Self, RayError> {
        let universe = Universe::<K>::new(level)?;
        let len = check_dense_len(universe, dense.len())?;
        let keys = ColumnKeys::<K>::new(level);
        let side = universe.side() as usize;
        let stride = len / side;
        // Row by row of the slowest axis: a voxel equal to the one below it (the same column, one step
        // down the last axis) extends that column's run or its emptiness, so only the voxels that differ
        // from the one below — few in a volume of regions — are looked at further. `start[c]` is where the
        // run open in column c started.
        let mut start = vec![0u32; stride];
        let mut runs = Vec::new();
        let filled = |v: V| (!v.same(background)).then_some(v);
        // Where column c's value changes from `before` (at z − 1) to `now` (at z).
        let mut change = |c: usize, z: usize, before: Option<V>, now: Option<V>| {
            if let Some(value) = before {
                runs.push(ValueRun {
                    column: keys.pack(universe.dense_point(c)),
                    z1: start[c],
                    z2: z as u32,
                    value,
                });
            }
            if let Some(v) = now {
                v.check().map_err(|e| RayError::Value {
                    index: c + z * stride,
                    error: e,
                })?;
                start[c] = z as u32;
            }
            Ok::<(), RayError>(())
        };
        for (c, &v) in dense[..stride].iter().enumerate() {
            if let Some(v) = filled(v) {
                change(c, 0, None, Some(v))?;
            }
        }
        const CHUNK: usize = 16;
        for z in 1..side {
            let below = &dense[(z - 1) * stride..z * stride];
            let row = &dense[z * stride..(z + 1) * stride];
            for (i, (b, r)) in below.chunks(CHUNK).zip(row.chunks(CHUNK)).enumerate() {
                // Compared without stopping early, so that the loop is vectorised.
                if b.iter().zip(r).fold(true, |all, (x, y)| all & x.same(*y)) {
                    continue;
                }
                for (j, (&x, &y)) in b.iter().zip(r).enumerate() {
                    if !x.same(y) {
                        let (before, now) = (filled(x), filled(y));
                        match (before, now) {
                            (Some(_), Some(_)) | (None, Some(_)) | (Some(_), None) => {
                                change(i * CHUNK + j, z, before, now)?;
                            }
                            (None, None) => {}
                        }
                    }
                }
            }
        }
        for (c, &v) in dense[(side - 1) * stride..].iter().enumerate() {
            if let Some(v) = filled(v) {
                change(c, side, Some(v), None)?;
            }
        }
        runs.sort_unstable_by_key(|r| (r.column, r.z1));
        Ok(Self { universe, runs })
    }

    /// The runs of a dense array of `len` voxels whose voxel `i` is `at(i)`. The array is read in its
    /// order (one pass, the runs of every column open at once), then the runs are sorted by column.
    fn from_dense_by(
        level: u32,
        len: usize,
        at: impl Fn(usize) -> Option<V>,
    ) -> Result<Self, RayError> {
        let universe = Universe::<K>::new(level)?;
        check_dense_len(universe, len)?;
        let keys = ColumnKeys::<K>::new(level);
        let side = universe.side() as usize;
        // The last axis is the slowest of the dense order: voxel z of column c is at c + z · side^(K−1).
        let stride = len / side;
        let mut open: Vec<Option<ValueRun<V>>> = vec![None; stride];
        let mut runs = Vec::new();
        for z in 0..=side {
            for (c, current) in open.iter_mut().enumerate() {
                let v = if z < side { at(c + z * stride) } else { None };
                if let Some(v) = v {
                    v.check().map_err(|e| RayError::Value {
                        index: c + z * stride,
                        error: e,
                    })?;
                }
                match (&mut *current, v) {
                    (Some(run), Some(v)) if run.value.same(v) => run.z2 += 1,
                    (None, None) => {}
                    (cur, v) => {
                        if let Some(run) = cur.take() {
                            runs.push(run);
                        }
                        *cur = v.map(|value| ValueRun {
                            column: keys.pack(universe.dense_point(c)),
                            z1: z as u32,
                            z2: z as u32 + 1,
                            value,
                        });
                    }
                }
            }
        }
        runs.sort_unstable_by_key(|r| (r.column, r.z1));
        Ok(Self { universe, runs })
    }

    /// Runs already sorted by column and `z1`, disjoint in each column, of values that pass
    /// [`Value::check`] (a producer that makes them so, as the mesh labels do).
    #[cfg_attr(not(feature = "mesh"), allow(dead_code))]
    pub(crate) fn from_sorted_runs(universe: Universe<K>, runs: Vec<ValueRun<V>>) -> Self {
        debug_assert!(runs
            .windows(2)
            .all(|p| (p[0].column, p[0].z2) <= (p[1].column, p[1].z1)));
        debug_assert!(runs
            .iter()
            .all(|r| r.z1 < r.z2 && u64::from(r.z2) <= universe.side()));
        Self { universe, runs }
    }

    /// The universe.
    pub fn universe(&self) -> Universe<K> {
        self.universe
    }

    /// The runs, by column and `z1`.
    pub fn runs(&self) -> &[ValueRun<V>] {
        &self.runs
    }

    /// The number of runs.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether there is no run.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// The number of voxels that hold a value.
    pub fn voxel_count(&self) -> u128 {
        self.runs.iter().map(|r| u128::from(r.z2 - r.z1)).sum()
    }
}

/// The universe's voxel count, checked to be `len` and to fit a dense array.
pub(crate) fn check_dense_len<const K: usize>(
    universe: Universe<K>,
    len: usize,
) -> Result<usize, RayError> {
    let want = universe.dense_len(DENSE_LIMIT)?;
    if len != want {
        return Err(RayError::Space(
            crate::space::SpaceError::TooLargeForDense {
                voxels: len as u128,
                limit: want as u128,
            },
        ));
    }
    Ok(want)
}
