//! The voxels a ray crosses between a sensor and a point, as OctoMap's key traversal crosses them
//! (Amanatides & Woo's 3-D DDA in OctoMap's `computeRayKeys`), in any dimension, with the same `f32` and
//! `f64` steps so that floating-point ties fall the same way.

use super::grid::MapGrid;

/// The Euclidean length of `v` as OctoMap's `Vector3::norm` computes it: the squares summed in `f32`, the
/// root taken in `f64`.
#[inline]
pub fn norm<const K: usize>(v: [f32; K]) -> f64 {
    let mut sum = 0.0f32;
    for c in v {
        sum += c * c;
    }
    f64::from(sum).sqrt()
}

/// `b − a`, coordinate by coordinate in `f32`.
#[inline]
pub fn difference<const K: usize>(a: [f32; K], b: [f32; K]) -> [f32; K] {
    std::array::from_fn(|i| b[i] - a[i])
}

/// The point at distance `range` from `origin` towards `end` (OctoMap's maximum-range end point:
/// `origin + (end − origin).normalized() · (float) range`).
pub fn clipped_end<const K: usize>(origin: [f32; K], end: [f32; K], range: f64) -> [f32; K] {
    let mut d = difference(origin, end);
    let len = norm(d);
    if len > 0.0 {
        for c in &mut d {
            *c /= len as f32;
        }
    }
    std::array::from_fn(|i| origin[i] + d[i] * range as f32)
}

/// Appends to `out` the keys of the voxels the ray from `origin` to `end` crosses, the origin's voxel
/// first and the end's voxel excluded (none if both are in one voxel). Returns `false`, appending
/// nothing, if either point is outside the map (OctoMap's `computeRayKeys` then reports the ray out of
/// bounds).
///
/// ```
/// use ktree::map::{key_ray, MapGrid};
/// let grid = MapGrid::new(1.0).unwrap();
/// let mut keys = Vec::new();
/// assert!(key_ray(&grid, [0.5f32, 0.5], [3.5, 0.5], &mut keys));
/// let c = 32768;
/// assert_eq!(keys, [[c, c], [c + 1, c], [c + 2, c]]);
/// ```
pub fn key_ray<const K: usize>(
    grid: &MapGrid,
    origin: [f32; K],
    end: [f32; K],
    out: &mut Vec<[u32; K]>,
) -> bool {
    visit_key_ray(grid, origin, end, |k| out.push(k))
}

/// [`key_ray`] handing each key to `visit` in order instead of collecting them.
#[inline]
pub fn visit_key_ray<const K: usize>(
    grid: &MapGrid,
    origin: [f32; K],
    end: [f32; K],
    mut visit: impl FnMut([u32; K]),
) -> bool {
    let (Some(key_origin), Some(key_end)) = (grid.keys(origin), grid.keys(end)) else {
        return false;
    };
    if key_origin == key_end {
        return true;
    }
    visit(key_origin);
    let mut direction = difference(origin, end);
    let length = norm(direction) as f32;
    for d in &mut direction {
        *d /= length;
    }
    let resolution = grid.resolution();
    let mut step = [0i32; K];
    let mut t_max = [f64::MAX; K];
    let mut t_delta = [f64::MAX; K];
    for i in 0..K {
        if direction[i] > 0.0 {
            step[i] = 1;
        } else if direction[i] < 0.0 {
            step[i] = -1;
        }
        if step[i] != 0 {
            // The voxel's border in the ray's direction; OctoMap rounds the half step to f32.
            let border = grid.centre(key_origin[i])
                + f64::from((f64::from(step[i]) * resolution * 0.5) as f32);
            t_max[i] = (border - f64::from(origin[i])) / f64::from(direction[i]);
            t_delta[i] = resolution / f64::from(direction[i]).abs();
        }
    }
    // OctoMap's keys are 16-bit and wrap; a key stepped past the map's edge wraps the same way.
    let mut key = key_origin;
    loop {
        // The axis of the smallest t_max, ties going to the later axis (OctoMap's comparisons).
        let mut dim = 0;
        for i in 1..K {
            if t_max[i] <= t_max[dim] {
                dim = i;
            }
        }
        key[dim] = (key[dim] as i32 + step[dim]) as u32 & 0xffff;
        t_max[dim] += t_delta[dim];
        if key == key_end {
            break;
        }
        // Past the end point's distance without meeting its voxel (rounding): stop.
        let reached = t_max.iter().copied().fold(f64::MAX, f64::min);
        if reached > f64::from(length) {
            break;
        }
        visit(key);
    }
    true
}
