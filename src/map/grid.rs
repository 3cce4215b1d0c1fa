//! Where a map's voxels are in the world: OctoMap's keys. A map of resolution `r` has `2^16` voxels a side;
//! voxel key `k` along an axis covers world coordinates `[(k − 2^15)·r, (k − 2^15 + 1)·r)`, so the world's
//! origin is the corner between the keys `2^15 − 1` and `2^15`. A key is also the voxel's coordinate in the
//! map's tree (a universe of level [`MAP_LEVEL`]).

/// The level of a map's universe: 16, OctoMap's tree depth.
pub const MAP_LEVEL: u32 = 16;

/// The key of the voxel just above the world's origin along each axis (OctoMap's `tree_max_val`).
pub const CENTRE_KEY: u32 = 1 << (MAP_LEVEL - 1);

/// A map's voxel size and the conversion between world coordinates and keys, computed as OctoMap computes
/// them (so that the same points fall in the same voxels).
///
/// ```
/// use ktree::map::MapGrid;
/// let grid = MapGrid::new(0.1).unwrap();
/// assert_eq!(grid.key(0.05), Some(32768));
/// assert_eq!(grid.key(-0.05), Some(32767));
/// assert_eq!(grid.key(1e9), None); // beyond the map's 2^16 voxels
/// assert!((grid.centre(32768) - 0.05).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapGrid {
    resolution: f64,
    factor: f64,
}

impl MapGrid {
    /// The grid of voxels of side `resolution` (metres, or the points' unit).
    ///
    /// # Errors
    /// A message if the resolution is not a positive finite number.
    pub fn new(resolution: f64) -> Result<Self, String> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(format!(
                "a map's resolution must be a positive number, not {resolution}"
            ));
        }
        Ok(Self {
            resolution,
            factor: 1.0 / resolution,
        })
    }

    /// The side of a voxel.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// The key of the voxel holding world coordinate `c` along an axis (OctoMap's `coordToKeyChecked`),
    /// or `None` outside the map's `2^16` voxels.
    #[inline]
    pub fn key(&self, c: f64) -> Option<u32> {
        let scaled = self.factor * c;
        let centre = f64::from(CENTRE_KEY);
        // The floor of `scaled` is in [−centre, centre) exactly when `scaled` is (the bounds are whole).
        if !(scaled >= -centre && scaled < centre) {
            return None;
        }
        // The floor by truncation, one less below zero unless whole (`f64::floor` is a library call on
        // processors without SSE4.1).
        let truncated = scaled as i64;
        let floor = truncated - i64::from(truncated as f64 > scaled);
        Some((floor + i64::from(CENTRE_KEY)) as u32)
    }

    /// The keys of a point, or `None` if any coordinate is outside the map.
    #[inline]
    pub fn keys<const K: usize>(&self, point: [f32; K]) -> Option<[u32; K]> {
        let mut out = [0u32; K];
        for (o, &c) in out.iter_mut().zip(&point) {
            *o = self.key(f64::from(c))?;
        }
        Some(out)
    }

    /// The world coordinate of the centre of key `k` along an axis (OctoMap's `keyToCoord`).
    #[inline]
    pub fn centre(&self, k: u32) -> f64 {
        (f64::from(k as i32 - CENTRE_KEY as i32) + 0.5) * self.resolution
    }

    /// The world coordinate of the lower corner of the map (the voxel of key 0).
    pub fn corner(&self) -> f64 {
        -f64::from(CENTRE_KEY) * self.resolution
    }

    /// The map's world frame: voxels of its resolution, key 0 at its [corner](Self::corner) on every
    /// axis (what a `.ktree` map file keeps).
    ///
    /// ```
    /// use ktree::map::MapGrid;
    /// let grid = MapGrid::new(0.25).unwrap();
    /// assert_eq!(grid.world_frame().origin, [-8192.0; 3]);
    /// assert_eq!(MapGrid::from_world_frame(&grid.world_frame()), Some(grid));
    /// ```
    pub fn world_frame(&self) -> crate::space::WorldFrame {
        crate::space::WorldFrame {
            voxel_size: self.resolution,
            origin: [self.corner(); 3],
        }
    }

    /// The grid whose world frame is `frame`, or `None` if `frame` is not a map's (its origin is not the
    /// corner of a map of its voxel size).
    pub fn from_world_frame(frame: &crate::space::WorldFrame) -> Option<Self> {
        let grid = Self::new(frame.voxel_size).ok()?;
        (grid.world_frame() == *frame).then_some(grid)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// OctoMap's `coordToKeyChecked`: the floor of the scaled coordinate, checked against the map.
    fn key_by_floor(grid: &MapGrid, c: f64) -> Option<u32> {
        let scaled = (grid.factor * c).floor();
        let centre = f64::from(CENTRE_KEY);
        (scaled >= -centre && scaled < centre)
            .then(|| (scaled as i64 + i64::from(CENTRE_KEY)) as u32)
    }

    proptest! {
        /// Keys of coordinates anywhere, on voxel borders (whole multiples of the resolution, negative
        /// ones included) and near the map's edges.
        #[test]
        fn key_is_the_floor_of_the_scaled_coordinate(
            res in prop_oneof![Just(0.1f64), Just(0.05), Just(1.0), 0.01f64..2.0],
            c in prop_oneof![-5000.0f64..5000.0, (-70_000i32..70_000).prop_map(f64::from), -1e-9f64..1e-9],
            whole in any::<bool>(),
        ) {
            let grid = MapGrid::new(res).unwrap();
            let c = if whole { (c / res).round() * res } else { c };
            prop_assert_eq!(grid.key(c), key_by_floor(&grid, c));
            prop_assert_eq!(grid.key(-c), key_by_floor(&grid, -c));
        }
    }

    #[test]
    fn coordinates_that_are_not_numbers_have_no_key() {
        let grid = MapGrid::new(0.1).unwrap();
        for c in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300] {
            assert_eq!(grid.key(c), None);
        }
        assert_eq!(grid.key(-0.0), Some(CENTRE_KEY));
        assert_eq!(grid.key(-1e-12), Some(CENTRE_KEY - 1));
    }
}
