//! A point cloud's voxels: those holding at least a given number of points.

use super::{bounds, check_finite, MAX_LEVEL};
use crate::rays::{Ray, RaySet, ValueRuns};
use crate::solid::SolidError;
use crate::space::max_level;
use crate::tree::KTree;
use crate::value::Value;

/// How a cloud becomes voxels: voxel size, origin, level, the points a voxel needs, and what to do with
/// points outside the universe.
///
/// ```
/// use ktree::solid::cloud::CloudVoxelizer;
/// let points = [[0.0, 0.0, 0.0], [0.9, 0.0, 0.0], [5.0, 0.0, 0.0]];
/// let v = CloudVoxelizer::new(1.0).unwrap().origin([0.0; 3]).level(2).min_points(2);
/// assert!(v.voxelize(&points).is_err()); // x = 5 is outside the universe of side 4
/// let r = v.crop(true).voxelize(&points).unwrap();
/// assert_eq!((r.rays.voxel_count(), r.cropped), (1, 1)); // (0, 0, 0) holds two points
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudVoxelizer {
    voxel_size: f64,
    origin: Option<[f64; 3]>,
    level: Option<u32>,
    min_points: u64,
    crop: bool,
}

/// The voxels of a cloud and what was chosen on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudVoxels {
    /// The full voxels.
    pub rays: RaySet<3>,
    /// The origin used (given or the bounding box's minimum corner).
    pub origin: [f64; 3],
    /// Points outside the universe that were dropped ([`CloudVoxelizer::crop`]).
    pub cropped: u64,
    /// Voxels that held at least one point but fewer than the minimum.
    pub sparse: u64,
}

/// The voxels of a cloud with their values ([`CloudVoxelizer::voxelize_values`]) and what was chosen on
/// the way.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudValueVoxels<V> {
    /// The full voxels and their values.
    pub runs: ValueRuns<3, V>,
    /// The origin used (given or the bounding box's minimum corner).
    pub origin: [f64; 3],
    /// Points outside the universe that were dropped ([`CloudVoxelizer::crop`]).
    pub cropped: u64,
    /// Voxels that held at least one point but fewer than the minimum.
    pub sparse: u64,
}

impl CloudVoxelizer {
    /// Voxels of side `voxel_size`, the default origin and level, one point a voxel, no cropping.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] unless `voxel_size` is finite and positive.
    pub fn new(voxel_size: f64) -> Result<Self, SolidError> {
        if !(voxel_size.is_finite() && voxel_size > 0.0) {
            return Err(SolidError::BadParameter(format!(
                "voxel size {voxel_size}: expected a finite number > 0"
            )));
        }
        Ok(Self {
            voxel_size,
            origin: None,
            level: None,
            min_points: 1,
            crop: false,
        })
    }

    /// The edge of a voxel, in the points' units.
    pub fn voxel_size(&self) -> f64 {
        self.voxel_size
    }

    /// The corner of voxel (0, 0, 0) (default: the minimum corner of the points' bounding box).
    pub fn origin(mut self, origin: [f64; 3]) -> Self {
        self.origin = Some(origin);
        self
    }

    /// The universe level (default: the smallest holding every voxel).
    pub fn level(mut self, level: u32) -> Self {
        self.level = Some(level);
        self
    }

    /// The points a voxel must hold to be full (default 1; 0 is taken as 1).
    pub fn min_points(mut self, n: u64) -> Self {
        self.min_points = n.max(1);
        self
    }

    /// Drop points outside the universe instead of failing (default: fail).
    pub fn crop(mut self, crop: bool) -> Self {
        self.crop = crop;
        self
    }

    /// The voxels of `points`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for a NaN or infinite coordinate or origin, or a cloud too large for
    /// [`MAX_LEVEL`]; [`SolidError::PointsOutside`] for points outside the universe of the level given,
    /// unless cropping; [`SolidError::PointBelowOrigin`] for a point below the origin given when no level
    /// is (no universe to crop to).
    pub fn voxelize(&self, points: &[[f64; 3]]) -> Result<CloudVoxels, SolidError> {
        let mut keys = Vec::with_capacity(points.len());
        let placed = self.place(points, |key, _| keys.push(key))?;
        keys.sort_unstable();
        let mut rays = Vec::new();
        let mut sparse = 0;
        let mut open: Option<(u64, u32, u32)> = None; // column, z1, z2
        for group in keys.chunk_by(|a, b| a == b) {
            if (group.len() as u64) < self.min_points {
                sparse += 1;
                continue;
            }
            let (column, z) = (group[0] >> 21, (group[0] & MASK) as u32);
            match &mut open {
                Some((c, _, z2)) if *c == column && *z2 == z => *z2 = z + 1,
                _ => {
                    if let Some(run) = open.replace((column, z, z + 1)) {
                        rays.push(run);
                    }
                }
            }
        }
        rays.extend(open);
        let rays = RaySet::from_rays(
            placed.level,
            rays.into_iter().map(|(c, z1, z2)| ray(c, z1, z2)),
        )?;
        Ok(CloudVoxels {
            rays,
            origin: placed.origin,
            cropped: placed.outside,
            sparse,
        })
    }

    /// The voxels of `points` with values: each full voxel's value is `reduce` of the values `per_point`
    /// gives its points (in file order, never none), e.g. [`mean_colour`](super::mean_colour) of their
    /// colours. The point keys are sorted (with their index, so a voxel's points keep the file's order)
    /// and each column's voxels in a row with the same value ([`Value::same`]) become one run: the runs
    /// are exact and as few as the values allow, and
    /// [`KTree::from_value_runs`](crate::KTree::from_value_runs) stacks them into the minimal tree.
    ///
    /// ```
    /// use ktree::solid::cloud::{most_frequent_class, CloudVoxelizer};
    /// use ktree::KTree;
    /// let points = [[0.5, 0.5, 0.5], [0.6, 0.5, 0.5], [0.7, 0.5, 0.5], [0.5, 0.5, 1.5]];
    /// let classes = [2u8, 6, 6, 6];
    /// let v = CloudVoxelizer::new(1.0).unwrap().origin([0.0; 3]);
    /// let voxels = v.voxelize_values(&points, &classes, most_frequent_class).unwrap();
    /// let tree = KTree::from_value_runs(&voxels.runs);
    /// assert_eq!(tree.value_at([0, 0, 0]), Some(6));
    /// assert_eq!(voxels.runs.len(), 1); // (0, 0, 0) and (0, 0, 1) hold 6: one run
    /// ```
    ///
    /// # Errors
    /// As [`CloudVoxelizer::voxelize`]; [`SolidError::BadParameter`] when `per_point` has another length
    /// than `points` or `reduce` gives a value no voxel may hold (a NaN).
    pub fn voxelize_values<T: Copy, V: Value>(
        &self,
        points: &[[f64; 3]],
        per_point: &[T],
        mut reduce: impl FnMut(&[T]) -> V,
    ) -> Result<CloudValueVoxels<V>, SolidError> {
        if per_point.len() != points.len() {
            return Err(SolidError::BadParameter(format!(
                "{} values for {} points",
                per_point.len(),
                points.len()
            )));
        }
        let mut keys: Vec<(u64, usize)> = Vec::with_capacity(points.len());
        let placed = self.place(points, |key, i| keys.push((key, i)))?;
        keys.sort_unstable();
        let mut runs: Vec<(u64, u32, u32, V)> = Vec::new(); // column, z1, z2, value
        let mut sparse = 0;
        let mut values = Vec::new();
        for group in keys.chunk_by(|a, b| a.0 == b.0) {
            if (group.len() as u64) < self.min_points {
                sparse += 1;
                continue;
            }
            values.clear();
            values.extend(group.iter().map(|&(_, i)| per_point[i]));
            let value = reduce(&values);
            let (column, z) = (group[0].0 >> 21, (group[0].0 & MASK) as u32);
            match runs.last_mut() {
                Some((c, _, z2, v)) if *c == column && *z2 == z && v.same(value) => *z2 = z + 1,
                _ => runs.push((column, z, z + 1, value)),
            }
        }
        let runs = ValueRuns::from_runs(
            placed.level,
            runs.into_iter().map(|(c, z1, z2, v)| (ray(c, z1, z2), v)),
        )?;
        Ok(CloudValueVoxels {
            runs,
            origin: placed.origin,
            cropped: placed.outside,
            sparse,
        })
    }

    /// Places the points: calls `keep(key, i)` for every point `i` inside the universe, its voxel's key
    /// `x << 42 | y << 21 | z`; returns the level, the origin and the points outside.
    fn place(
        &self,
        points: &[[f64; 3]],
        mut keep: impl FnMut(u64, usize),
    ) -> Result<Placed, SolidError> {
        check_finite(points)?;
        let origin = match self.origin {
            Some(o) if o.iter().all(|c| c.is_finite()) => o,
            Some(o) => {
                return Err(SolidError::BadParameter(format!(
                    "origin {o:?}: expected finite coordinates"
                )))
            }
            None => bounds(points).map_or([0.0; 3], |b| b.0),
        };
        let s = self.voxel_size;
        // numpy's floor((p - origin) / s), per axis.
        let index = |p: &[f64; 3]| -> [f64; 3] {
            std::array::from_fn(|a| ((p[a] - origin[a]) / s).floor())
        };
        let level = match self.level {
            Some(l) => {
                crate::Universe::<3>::new(l)?;
                l
            }
            None => {
                let mut top = 0.0f64;
                for (i, p) in points.iter().enumerate() {
                    let v = index(p);
                    if let Some(axis) = (0..3).find(|&a| v[a] < 0.0) {
                        return Err(SolidError::PointBelowOrigin {
                            index: i,
                            point: *p,
                            origin,
                            axis,
                        });
                    }
                    top = top.max(v[0]).max(v[1]).max(v[2]);
                }
                let mut l = 0;
                while l <= MAX_LEVEL && top >= (1u64 << l) as f64 {
                    l += 1;
                }
                if l > MAX_LEVEL.min(max_level(3)) {
                    return Err(SolidError::BadParameter(format!(
                        "the cloud spans voxel index {top} at voxel size {s}: more than a universe of level {MAX_LEVEL} holds; use a larger voxel size"
                    )));
                }
                l
            }
        };
        let side = (1u64 << level) as f64;
        let mut outside = 0u64;
        let mut first_outside = None;
        for (i, p) in points.iter().enumerate() {
            let v = index(p);
            if v.iter().all(|&c| (0.0..side).contains(&c)) {
                keep(
                    ((v[0] as u64) << 42) | ((v[1] as u64) << 21) | (v[2] as u64),
                    i,
                );
            } else {
                outside += 1;
                first_outside.get_or_insert((i, *p, v));
            }
        }
        if let (Some((first, point, voxel)), false) = (first_outside, self.crop) {
            return Err(SolidError::PointsOutside {
                count: outside,
                level,
                first,
                point,
                voxel,
            });
        }
        Ok(Placed {
            level,
            origin,
            outside,
        })
    }
}

/// What placing a cloud's points chose and found.
struct Placed {
    level: u32,
    origin: [f64; 3],
    outside: u64,
}

/// The 21 bits of one axis in a voxel key.
const MASK: u64 = (1 << 21) - 1;

/// The run `[z1, z2)` of the column `column` (`x << 21 | y`).
fn ray(column: u64, z1: u32, z2: u32) -> Ray<3> {
    Ray::new([(column >> 21) as u32, (column & MASK) as u32, z1], z2)
}

impl KTree<3> {
    /// The octree of the voxels holding at least one of `points`: voxel `floor((p − origin) / voxel_size)`,
    /// origin default the points' minimum corner, level default the smallest holding every voxel (see
    /// [`CloudVoxelizer`] for more options).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::from_points(&[[0.5, 0.5, 0.5], [3.5, 0.5, 0.5]], 1.0, Some([0.0; 3]), None).unwrap();
    /// assert_eq!((tree.level(), tree.voxel_count()), (2, 2));
    /// ```
    ///
    /// # Errors
    /// As [`CloudVoxelizer::voxelize`].
    pub fn from_points(
        points: &[[f64; 3]],
        voxel_size: f64,
        origin: Option<[f64; 3]>,
        level: Option<u32>,
    ) -> Result<KTree<3>, SolidError> {
        let mut v = CloudVoxelizer::new(voxel_size)?;
        if let Some(o) = origin {
            v = v.origin(o);
        }
        if let Some(l) = level {
            v = v.level(l);
        }
        Ok(KTree::from_rays(&v.voxelize(points)?.rays))
    }
}
