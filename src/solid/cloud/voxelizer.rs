//! A point cloud's voxels: those holding at least a given number of points.

use super::{bounds, check_finite, MAX_LEVEL};
use crate::rays::{Ray, RaySet};
use crate::solid::SolidError;
use crate::space::max_level;
use crate::tree::KTree;

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
        let mut keys = Vec::with_capacity(points.len());
        let mut outside = 0u64;
        let mut first_outside = None;
        for (i, p) in points.iter().enumerate() {
            let v = index(p);
            if v.iter().all(|&c| (0.0..side).contains(&c)) {
                keys.push(((v[0] as u64) << 42) | ((v[1] as u64) << 21) | (v[2] as u64));
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
        keys.sort_unstable();
        let mask = (1u64 << 21) - 1;
        let mut rays = Vec::new();
        let mut sparse = 0;
        let mut open: Option<(u64, u32, u32)> = None; // column, z1, z2
        for group in keys.chunk_by(|a, b| a == b) {
            if (group.len() as u64) < self.min_points {
                sparse += 1;
                continue;
            }
            let (column, z) = (group[0] >> 21, (group[0] & mask) as u32);
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
            level,
            rays.into_iter()
                .map(|(c, z1, z2)| Ray::new([(c >> 21) as u32, (c & mask) as u32, z1], z2)),
        )?;
        Ok(CloudVoxels {
            rays,
            origin,
            cropped: outside,
            sparse,
        })
    }
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
