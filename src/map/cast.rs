//! Ray casts on a map, as OctoMap's `castRay`: from the voxel of the origin along a direction, voxel by
//! voxel (its DDA, its `f32` and `f64` steps), until an occupied voxel (a hit), an unknown one (unless
//! unknown voxels are passed through), the maximum range or the map's edge.

use super::{MapView, OccupancyMap, VoxelState};
use crate::map::traverse::norm;
use crate::tree::storage::infallible;
use crate::tree::valued::ValueCursor;
use crate::tree::ValueStorage;

/// How a ray cast ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CastEnd {
    /// The ray entered an occupied voxel (its keys).
    Occupied([u32; 3]),
    /// The ray entered an unknown voxel and unknown voxels stop rays (its keys).
    Unknown([u32; 3]),
    /// The ray went beyond the maximum range (the keys of the first voxel beyond it).
    Range([u32; 3]),
    /// The ray left the map (the keys of the last voxel inside it, where OctoMap's `castRay` puts its
    /// `end`), or its origin is outside the map or its direction is zero (`None`: OctoMap leaves `end` as
    /// it was).
    Outside(Option<[u32; 3]>),
}

impl OccupancyMap<3> {
    /// Casts a ray from `origin` along `direction` (any length): OctoMap's `castRay(origin, direction,
    /// end, ignore_unknown, max_range)` — a hit is [`CastEnd::Occupied`] (OctoMap returns true), the
    /// others are OctoMap's false with its `end` at the voxel given. `max_range` ≤ 0 means none.
    ///
    /// ```
    /// use ktree::map::{CastEnd, OccupancyMap};
    /// let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    /// map.insert(&[[2.05, 0.05, 0.05]], [0.05, 0.05, 0.05], None).unwrap();
    /// let key = map.grid().keys([2.05f32, 0.05, 0.05]).unwrap();
    /// assert_eq!(map.cast_ray([0.05, 0.05, 0.05], [1.0, 0.0, 0.0], false, -1.0), CastEnd::Occupied(key));
    /// // Sideways the first voxel is unknown.
    /// assert!(matches!(map.cast_ray([0.05, 0.05, 0.05], [0.0, 1.0, 0.0], false, -1.0), CastEnd::Unknown(_)));
    /// ```
    pub fn cast_ray(
        &self,
        origin: [f32; 3],
        direction: [f32; 3],
        ignore_unknown: bool,
        max_range: f64,
    ) -> CastEnd {
        infallible(
            self.view()
                .cast_ray(origin, direction, ignore_unknown, max_range),
        )
    }
}

impl<S: ValueStorage<3, Value = f32>> MapView<'_, 3, S> {
    /// [`OccupancyMap::cast_ray`] on the map's log-odds in any storage.
    ///
    /// # Errors
    /// The storage's first read error.
    pub fn cast_ray(
        &self,
        origin: [f32; 3],
        direction: [f32; 3],
        ignore_unknown: bool,
        max_range: f64,
    ) -> Result<CastEnd, S::Error> {
        let grid = *self.grid();
        let Some(mut key) = grid.keys(origin) else {
            return Ok(CastEnd::Outside(None));
        };
        // The leaf the ray is in (its cell: the keys' bits above `leaf.0`) and its state: looked up again
        // only when the ray leaves it, from the deepest node the two leaves share.
        let mut cursor = ValueCursor::new(self.log_odds());
        let mut look = |k: [u32; 3]| -> Result<_, S::Error> {
            let (log_side, v) = cursor.leaf_at(k)?.unwrap_or((0, None));
            Ok((log_side, k.map(|c| c >> log_side), self.state_of(v)))
        };
        let mut leaf = look(key)?;
        let mut state = |k: [u32; 3]| -> Result<VoxelState, S::Error> {
            if k.map(|c| c >> leaf.0) != leaf.1 {
                leaf = look(k)?;
            }
            Ok(leaf.2)
        };
        match state(key)? {
            VoxelState::Occupied => return Ok(CastEnd::Occupied(key)),
            VoxelState::Unknown if !ignore_unknown => return Ok(CastEnd::Unknown(key)),
            _ => {}
        }
        // OctoMap's normalized(): the norm in f64, the division in f32.
        let len = norm(direction);
        let mut d = direction;
        if len > 0.0 {
            for c in &mut d {
                *c /= len as f32;
            }
        }
        let resolution = grid.resolution();
        let mut step = [0i32; 3];
        let mut t_max = [f64::MAX; 3];
        let mut t_delta = [f64::MAX; 3];
        for i in 0..3 {
            if d[i] > 0.0 {
                step[i] = 1;
            } else if d[i] < 0.0 {
                step[i] = -1;
            }
            if step[i] != 0 {
                let border = grid.centre(key[i]) + f64::from(step[i]) * resolution * 0.5;
                t_max[i] = (border - f64::from(origin[i])) / f64::from(d[i]);
                t_delta[i] = resolution / f64::from(d[i]).abs();
            }
        }
        if step == [0; 3] {
            return Ok(CastEnd::Outside(None));
        }
        let range_sq = max_range * max_range;
        let last = (1u32 << super::MAP_LEVEL) - 1;
        // The key at which a step along each axis would leave the map (none for an axis not stepped).
        let edge = step.map(|s| match s {
            -1 => 0,
            1 => last,
            _ => u32::MAX,
        });
        loop {
            // The axis of the smallest t_max, ties going to the later axis, chosen and stepped without
            // branches (which axis comes next is what the processor cannot predict).
            let (mut dim, mut best) = (0, t_max[0]);
            for (i, &t) in t_max.iter().enumerate().skip(1) {
                let nearer = t <= best;
                dim = std::hint::select_unpredictable(nearer, i, dim);
                best = std::hint::select_unpredictable(nearer, t, best);
            }
            if key[dim] == edge[dim] {
                return Ok(CastEnd::Outside(Some(key)));
            }
            key[dim] = key[dim].wrapping_add_signed(step[dim]);
            for (i, (t, delta)) in t_max.iter_mut().zip(t_delta).enumerate() {
                *t += std::hint::select_unpredictable(i == dim, delta, 0.0);
            }
            if max_range > 0.0 {
                // OctoMap: the voxel's centre as a float point, its squared distance summed in f64.
                let mut sq = 0.0f64;
                for j in 0..3 {
                    let e = grid.centre(key[j]) as f32 - origin[j];
                    sq += f64::from(e * e);
                }
                if sq > range_sq {
                    return Ok(CastEnd::Range(key));
                }
            }
            match state(key)? {
                VoxelState::Occupied => return Ok(CastEnd::Occupied(key)),
                VoxelState::Unknown if !ignore_unknown => return Ok(CastEnd::Unknown(key)),
                _ => {}
            }
        }
    }
}
