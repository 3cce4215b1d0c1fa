//! Rays integrated one at a time, as OctoMap's `insertRay` integrates them: each ray's misses and its
//! hit update the map before the next ray is seen, so a voxel crossed by several rays of a batch is updated
//! once for each (a scan's update, [`OccupancyMap::insert`], updates each voxel once a scan, hits winning).

use std::collections::HashMap;

use super::traverse::{clipped_end, difference, norm, visit_key_ray};
use super::{tree_from_leaves, OccupancyMap, MAP_LEVEL};
use crate::space::morton_encode;

impl<const K: usize> OccupancyMap<K> {
    /// Integrates one ray from `origin` to `end` (world coordinates), as OctoMap's `insertRay(origin, end,
    /// maxrange)`: the voxels the ray crosses before `end`'s voxel take a miss, then `end`'s voxel a hit.
    /// A ray longer than `max_range` is cut there and its end is no hit (`None`: no limit, OctoMap's
    /// `maxrange` ≤ 0). Returns `false`, changing nothing, when the ray (cut or not) leaves the map.
    ///
    /// For many rays, [`insert_rays`](Self::insert_rays) gives the same map at once.
    ///
    /// ```
    /// use ktree::map::{OccupancyMap, VoxelState};
    /// let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    /// // Two rays ending in one voxel: it takes two hits (a scan would give it one).
    /// for _ in 0..2 {
    ///     assert!(map.insert_ray([0.05, 0.05, 0.05], [0.55, 0.05, 0.05], None).unwrap());
    /// }
    /// let hit = map.log_odds().value_at(map.grid().keys([0.55f32, 0.05, 0.05]).unwrap());
    /// assert_eq!(hit, Some(map.model().update(map.model().update(0.0, true), true)));
    /// assert_eq!(map.states(&[[0.25, 0.05, 0.05]]), [VoxelState::Free]);
    /// // A ray to a point beyond the map changes nothing.
    /// assert!(!map.insert_ray([0.05, 0.05, 0.05], [1e6, 0.0, 0.0], None).unwrap());
    /// ```
    ///
    /// # Errors
    /// A message for a coordinate that is not finite or a maximum range that is negative or not a number.
    pub fn insert_ray(
        &mut self,
        origin: [f32; K],
        end: [f32; K],
        max_range: Option<f64>,
    ) -> Result<bool, String> {
        Ok(self.insert_rays(origin, &[end], max_range)? == 0)
    }

    /// Integrates the rays from `origin` to each of `ends` in turn, each as [`insert_ray`](Self::insert_ray)
    /// integrates it, and updates the map's tree once. Returns the number of rays that left the map
    /// (OctoMap's `insertRay` returns `false` for them and changes nothing).
    ///
    /// ```
    /// use ktree::map::OccupancyMap;
    /// let mut one_by_one = OccupancyMap::<2>::new(0.1).unwrap();
    /// let mut at_once = one_by_one.clone();
    /// let ends = [[1.05, 0.35], [0.05, 0.95], [1.05, 0.35], [-0.5, -0.5]];
    /// for end in ends {
    ///     one_by_one.insert_ray([0.05, 0.05], end, Some(1.0)).unwrap();
    /// }
    /// assert_eq!(at_once.insert_rays([0.05, 0.05], &ends, Some(1.0)).unwrap(), 0);
    /// assert_eq!(at_once, one_by_one);
    /// ```
    ///
    /// # Errors
    /// A message for a coordinate that is not finite or a maximum range that is negative or not a number;
    /// the map is then unchanged.
    pub fn insert_rays(
        &mut self,
        origin: [f32; K],
        ends: &[[f32; K]],
        max_range: Option<f64>,
    ) -> Result<usize, String> {
        super::check_rays(
            ends,
            origin,
            max_range,
            "the end of ray {i}",
            "the rays' origin",
        )?;
        let grid = *self.grid();
        let model = *self.model();
        let tree = &self.log_odds;
        // The log-odds of every voxel the rays update (each starting from the map's), by Morton key.
        let mut updated: HashMap<u64, f32> = HashMap::new();
        let mut update = |key: [u32; K], hit: bool| {
            let l = updated
                .entry(morton_encode(key))
                .or_insert_with(|| tree.value_at(key).unwrap_or(0.0));
            *l = model.update(*l, hit);
        };
        let mut outside = 0;
        for &end in ends {
            let cut = max_range.filter(|&m| norm(difference(origin, end)) > m);
            let stop = cut.map_or(end, |m| clipped_end(origin, end, m));
            // The misses first (the ray's voxels are distinct and exclude the end's), then the hit.
            let inside = visit_key_ray(&grid, origin, stop, |k| update(k, false));
            if !inside {
                outside += 1;
            } else if cut.is_none() {
                let key = grid.keys(end).expect("a ray inside the map ends inside it");
                update(key, true);
            }
        }
        if updated.is_empty() {
            return Ok(outside);
        }
        let mut leaves: Vec<(u64, u32, f32)> =
            updated.into_iter().map(|(k, l)| (k, 0, l)).collect();
        leaves.sort_unstable_by_key(|l| l.0);
        // Never fails: the log-odds are numbers, the leaves distinct voxels of the map's level.
        let changes = tree_from_leaves::<K, f32>(MAP_LEVEL, &leaves).map_err(|e| e.to_string())?;
        self.log_odds = self.log_odds.overlay(&changes).map_err(|e| e.to_string())?;
        Ok(outside)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn point<const K: usize>() -> impl Strategy<Value = [f32; K]> {
        prop::array::uniform(-3.0f32..3.0)
    }

    /// A one-ray insertion is a one-point scan (a single ray updates each of its voxels once), on a map
    /// that already holds a scan.
    fn one_ray_is_a_one_point_scan<const K: usize>(
        scan: &[[f32; K]],
        origin: [f32; K],
        end: [f32; K],
        res: f64,
        range: Option<f64>,
    ) -> Result<(), TestCaseError> {
        let mut a = OccupancyMap::<K>::new(res).unwrap();
        a.insert(scan, origin, None).unwrap();
        let mut b = a.clone();
        prop_assert!(a.insert_ray(origin, end, range).unwrap());
        b.insert(&[end], origin, range).unwrap();
        prop_assert_eq!(a, b);
        Ok(())
    }

    /// Rays at once are the same rays one by one, repeats (several updates of a voxel) and rays leaving
    /// the map among them.
    fn at_once_is_one_by_one<const K: usize>(
        ends: &[[f32; K]],
        origin: [f32; K],
        res: f64,
        range: Option<f64>,
    ) -> Result<(), TestCaseError> {
        let mut ends = ends.to_vec();
        ends.extend_from_within(..ends.len() / 2);
        ends.push([1e6; K]);
        let mut one = OccupancyMap::<K>::new(res).unwrap();
        let outside: usize = ends
            .iter()
            .map(|&e| usize::from(!one.insert_ray(origin, e, range).unwrap()))
            .sum();
        let mut all = OccupancyMap::<K>::new(res).unwrap();
        prop_assert_eq!(all.insert_rays(origin, &ends, range).unwrap(), outside);
        prop_assert_eq!(outside, usize::from(range.is_none()));
        prop_assert_eq!(all, one);
        Ok(())
    }

    proptest! {
        #[test]
        fn one_ray_is_a_one_point_scan_k2(scan in prop::collection::vec(point::<2>(), 0..20), o in point::<2>(), e in point::<2>(), res in 0.1f64..0.7, range in prop::option::of(0.0f64..4.0)) {
            one_ray_is_a_one_point_scan(&scan, o, e, res, range)?;
        }

        #[test]
        fn one_ray_is_a_one_point_scan_k3(scan in prop::collection::vec(point::<3>(), 0..20), o in point::<3>(), e in point::<3>(), res in 0.1f64..0.7, range in prop::option::of(0.0f64..4.0)) {
            one_ray_is_a_one_point_scan(&scan, o, e, res, range)?;
        }

        #[test]
        fn at_once_is_one_by_one_k2(ends in prop::collection::vec(point::<2>(), 0..30), o in point::<2>(), res in 0.1f64..0.7, range in prop::option::of(0.5f64..4.0)) {
            at_once_is_one_by_one(&ends, o, res, range)?;
        }

        #[test]
        fn at_once_is_one_by_one_k3(ends in prop::collection::vec(point::<3>(), 0..30), o in point::<3>(), res in 0.1f64..0.7, range in prop::option::of(0.5f64..4.0)) {
            at_once_is_one_by_one(&ends, o, res, range)?;
        }
    }

    #[test]
    fn bad_rays_are_errors_and_change_nothing() {
        let mut map = OccupancyMap::<3>::new(0.1).unwrap();
        let before = map.clone();
        let o = [0.0f32; 3];
        assert!(map
            .insert_rays(o, &[[1.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0]], None)
            .unwrap_err()
            .contains("ray 1"));
        assert!(map
            .insert_ray([f32::INFINITY, 0.0, 0.0], [1.0, 0.0, 0.0], None)
            .unwrap_err()
            .contains("origin"));
        assert!(map
            .insert_ray(o, [1.0, 0.0, 0.0], Some(-1.0))
            .unwrap_err()
            .contains("maximum range"));
        assert!(map
            .insert_ray(o, [1.0, 0.0, 0.0], Some(f64::NAN))
            .unwrap_err()
            .contains("maximum range"));
        assert_eq!(map, before);
        assert_eq!(map.insert_rays(o, &[], None), Ok(0));
    }
}
