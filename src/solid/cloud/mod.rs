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

mod reduce;
mod voxelizer;

pub use reduce::{max_intensity, mean_colour, mean_intensity, most_frequent_class};
pub use voxelizer::{CloudValueVoxels, CloudVoxelizer, CloudVoxels};

use super::SolidError;
use crate::value::Rgb;

/// The largest level of a cloud's universe (3 · 21 bits of a voxel key fit a `u64`).
pub const MAX_LEVEL: u32 = 21;

/// A point cloud: finite 3-D points, in file order, and the attributes its file gave them.
///
/// ```
/// use ktree::solid::cloud::{PointAttributes, PointCloud};
/// assert!(PointCloud::new(vec![[0.0, 1.0, 2.0]]).is_ok());
/// assert!(PointCloud::new(vec![[0.0, f64::NAN, 2.0]]).is_err());
/// let classes = PointAttributes { classes: Some(vec![2]), ..Default::default() };
/// let cloud = PointCloud::with_attributes(vec![[0.0, 1.0, 2.0]], classes).unwrap();
/// assert_eq!((cloud.classes(), cloud.colours()), (Some(&[2u8][..]), None));
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointCloud {
    points: Vec<[f64; 3]>,
    attributes: PointAttributes,
}

/// The attributes of a cloud's points, each a column with a value a point, or `None` when the file has
/// none (no memory taken then).
///
/// * colour: 8 bits a channel (a file's 16-bit colours are scaled down by its reader, see
///   [`crate::io::read_cloud`]);
/// * intensity: as the file stores it (LAS: `u16`), as `f32`;
/// * class: a `u8` (LAS classification, a PLY or PCD `label` or `class` field).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointAttributes {
    /// Each point's colour.
    pub colours: Option<Vec<Rgb>>,
    /// Each point's intensity.
    pub intensities: Option<Vec<f32>>,
    /// Each point's class.
    pub classes: Option<Vec<u8>>,
}

impl PointAttributes {
    /// The names of the attributes present (`colour`, `intensity`, `class`), for messages.
    pub fn names(&self) -> Vec<&'static str> {
        [
            ("colour", self.colours.is_some()),
            ("intensity", self.intensities.is_some()),
            ("class", self.classes.is_some()),
        ]
        .into_iter()
        .filter_map(|(name, present)| present.then_some(name))
        .collect()
    }
}

impl PointCloud {
    /// A cloud of `points`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] naming the first point with a NaN or infinite coordinate.
    pub fn new(points: Vec<[f64; 3]>) -> Result<Self, SolidError> {
        Self::with_attributes(points, PointAttributes::default())
    }

    /// A cloud of `points` with `attributes`, each present column a value a point.
    ///
    /// # Errors
    /// As [`PointCloud::new`]; [`SolidError::BadParameter`] for a column of another length than the points.
    pub fn with_attributes(
        points: Vec<[f64; 3]>,
        attributes: PointAttributes,
    ) -> Result<Self, SolidError> {
        check_finite(&points)?;
        let lengths = [
            ("colour", attributes.colours.as_ref().map(Vec::len)),
            ("intensity", attributes.intensities.as_ref().map(Vec::len)),
            ("class", attributes.classes.as_ref().map(Vec::len)),
        ];
        for (name, len) in lengths {
            if let Some(len) = len.filter(|&len| len != points.len()) {
                return Err(SolidError::BadParameter(format!(
                    "{len} values of {name} for {} points",
                    points.len()
                )));
            }
        }
        Ok(Self { points, attributes })
    }

    /// Each point's colour, when the file gave colours.
    pub fn colours(&self) -> Option<&[Rgb]> {
        self.attributes.colours.as_deref()
    }

    /// Each point's intensity, when the file gave intensities.
    pub fn intensities(&self) -> Option<&[f32]> {
        self.attributes.intensities.as_deref()
    }

    /// Each point's class, when the file gave classes.
    pub fn classes(&self) -> Option<&[u8]> {
        self.attributes.classes.as_deref()
    }

    /// All the attributes.
    pub fn attributes(&self) -> &PointAttributes {
        &self.attributes
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
