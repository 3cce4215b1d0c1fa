//! A 3-D map seen from above: the occupied and the known cells of its slices between two heights,
//! projected onto the other two axes and cut to the known part — the 2-D occupancy grid a navigation stack
//! reads (occupied where any voxel of the column range is occupied, free where one is known and none is
//! occupied, unknown elsewhere).

use super::OccupancyMap;
use crate::ops::{project, translate, zoom};
use crate::query::bounding_box;
use crate::tree::storage::infallible;
use crate::KTree;

/// A map's plane: its occupied and known cells (occupied included), a universe just large enough for the
/// known part, whose cell (0, 0) has its lower corner at `origin` in the world (the two axes other than
/// the one projected along, in order).
#[derive(Debug, Clone, PartialEq)]
pub struct MapPlane {
    /// The occupied cells.
    pub occupied: KTree<2>,
    /// The observed cells, occupied or free.
    pub known: KTree<2>,
    /// The world position of cell (0, 0)'s lower corner.
    pub origin: [f64; 2],
    /// The side of a cell.
    pub resolution: f64,
}

impl OccupancyMap<3> {
    /// The plane of the voxels between world coordinates `lo` and `hi` (both included) along `axis`.
    ///
    /// ```
    /// use ktree::map::OccupancyMap;
    /// let mut map = OccupancyMap::<3>::new(0.5).unwrap();
    /// // A wall at x = 2 m seen from the origin, 1 m up.
    /// let wall: Vec<[f32; 3]> = (0..8).map(|i| [2.1, -1.0 + 0.25 * i as f32, 1.0]).collect();
    /// map.insert(&wall, [0.1, 0.1, 1.0], None).unwrap();
    /// let plane = map.plane(2, 0.5, 1.5).unwrap();
    /// assert_eq!(plane.occupied.voxel_count(), 4); // the wall's four cells along y
    /// assert!(plane.known.voxel_count() > 4);
    /// assert!(map.plane(2, 5.0, 6.0).unwrap().known.voxel_count() == 0); // nothing seen up there
    /// ```
    ///
    /// # Errors
    /// A message for an axis beyond 2 or a range that is not `lo ≤ hi`.
    pub fn plane(&self, axis: usize, lo: f64, hi: f64) -> Result<MapPlane, String> {
        if axis > 2 {
            return Err(format!("a 3-D map has axes 0, 1 and 2, not {axis}"));
        }
        if lo.is_nan() || hi.is_nan() || lo > hi {
            return Err(format!("the range {lo}:{hi} is not LO:HI with LO ≤ HI"));
        }
        let grid = self.grid();
        let side = 1u32 << super::MAP_LEVEL;
        // The map's key of a coordinate, the nearest edge of the map beyond it.
        let key = |c: f64| grid.key(c).unwrap_or(if c < 0.0 { 0 } else { side - 1 });
        let (k0, k1) = (key(lo), key(hi));
        let keys = k0..k1 + 1;
        let occupied: KTree<2> =
            project::<3, 2, _>(&self.occupied(), axis, keys.clone()).map_err(|e| e.to_string())?;
        let known: KTree<2> =
            project::<3, 2, _>(&self.log_odds().shape(), axis, keys).map_err(|e| e.to_string())?;
        let Some((first, end)) = infallible(bounding_box(&known)) else {
            return Ok(MapPlane {
                occupied: KTree::empty(0).expect("level 0"),
                known: KTree::empty(0).expect("level 0"),
                origin: [0.0; 2],
                resolution: grid.resolution(),
            });
        };
        let extent = (0..2).map(|a| end[a] - first[a]).max().unwrap_or(1).max(1);
        let level = u32::BITS - (extent - 1).leading_zeros();
        let path = vec![0usize; (super::MAP_LEVEL - level) as usize];
        let shift = [-(first[0] as i64), -(first[1] as i64)];
        let cut = |t: &KTree<2>| -> Result<KTree<2>, String> {
            zoom(&infallible(translate(t, shift)), &path).map_err(|e| e.to_string())
        };
        Ok(MapPlane {
            occupied: cut(&occupied)?,
            known: cut(&known)?,
            origin: std::array::from_fn(|i| {
                (f64::from(first[i]) - f64::from(super::CENTRE_KEY)) * grid.resolution()
            }),
            resolution: grid.resolution(),
        })
    }
}
