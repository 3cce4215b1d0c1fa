//! Point clouds to voxels: a [`PointCloud`] (read from PLY, PCD, XYZ/CSV and LAS/LAZ files by
//! [`crate::io::read_cloud`]) and its voxelizer ([`CloudVoxelizer`]).
//!
//! **Voxels.** A point `p` falls in voxel `floor((p − origin) / s)` per axis, computed in `f64` exactly as
//! numpy's `np.floor((p - origin) / s)`; a voxel is full when it holds at least `min_points` points
//! ([`CloudVoxelizer`]). The default origin is the minimum corner of the points' bounding box (so every
//! index is ≥ 0), the default level the smallest whose universe holds every voxel. With a level given,
//! points outside the universe are an error naming how many and the first
//! ([`SolidError::PointsOutside`]), unless [`CloudVoxelizer::crop`] drops them.
//!
//! **Work:** `O(n log n)` for `n` points: the voxel keys are packed in a `u64`, sorted, counted and turned
//! into runs along z, never inserted one by one.
//!
//! ```
//! use ktree::solid::cloud::{CloudVoxelizer, PointCloud};
//! let cloud = PointCloud::new(vec![[0.1, 0.1, 0.1], [0.2, 0.3, 0.1], [1.7, 0.1, 0.1]]).unwrap();
//! let v = CloudVoxelizer::new(0.5).unwrap().voxelize(cloud.points()).unwrap();
//! assert_eq!(v.origin, [0.1, 0.1, 0.1]);
//! assert_eq!(v.rays.voxel_count(), 2); // voxels (0, 0, 0) and (3, 0, 0)
//! assert_eq!(v.rays.level(), 2); // the smallest universe holding x = 3
//! ```

mod voxelizer;

pub use voxelizer::{CloudVoxelizer, CloudVoxels};

use super::SolidError;

/// The largest level of a cloud's universe (3 · 21 bits of a voxel key fit a `u64`).
pub const MAX_LEVEL: u32 = 21;

/// A point cloud: finite 3-D points, in file order.
///
/// ```
/// use ktree::solid::cloud::PointCloud;
/// assert!(PointCloud::new(vec![[0.0, 1.0, 2.0]]).is_ok());
/// assert!(PointCloud::new(vec![[0.0, f64::NAN, 2.0]]).is_err());
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointCloud {
    points: Vec<[f64; 3]>,
}

impl PointCloud {
    /// A cloud of `points`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] naming the first point with a NaN or infinite coordinate.
    pub fn new(points: Vec<[f64; 3]>) -> Result<Self, SolidError> {
        check_finite(&points)?;
        Ok(Self { points })
    }

    /// The points.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there is no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Takes the points out.
    pub fn into_points(self) -> Vec<[f64; 3]> {
        self.points
    }
}

/// `Err` naming the first point with a NaN or infinite coordinate.
fn check_finite(points: &[[f64; 3]]) -> Result<(), SolidError> {
    match points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        Some(i) => Err(SolidError::BadParameter(format!(
            "point {i} has a coordinate that is not finite: {:?}",
            points[i]
        ))),
        None => Ok(()),
    }
}

/// The minimum and maximum corners of `points` (`None` for none).
pub fn bounds(points: &[[f64; 3]]) -> Option<([f64; 3], [f64; 3])> {
    let first = *points.first()?;
    Some(points.iter().fold((first, first), |(lo, hi), p| {
        (
            std::array::from_fn(|a| lo[a].min(p[a])),
            std::array::from_fn(|a| hi[a].max(p[a])),
        )
    }))
}
