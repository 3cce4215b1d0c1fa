//! The voxels a ray crosses between a sensor and a point, as OctoMap's key traversal crosses them
//! (Amanatides & Woo's 3-D DDA in OctoMap's `computeRayKeys`), in any dimension, with the same `f32` and
//! `f64` steps so that floating-point ties fall the same way.

use super::grid::MapGrid;
use crate::space::{morton_decode, morton_encode, spread_bits};

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
    visit_morton_ray(grid, origin, end, |code| visit(morton_decode(code)))
}

/// [`visit_key_ray`] handing each voxel's Morton key (of the map's universe) instead of its keys: the
/// traversal steps the Morton key itself, an axis's bits at a time, so no key is encoded on the way.
///
/// ```
/// use ktree::map::{visit_key_ray, visit_morton_ray, MapGrid};
/// use ktree::space::morton_encode;
/// let grid = MapGrid::new(0.1).unwrap();
/// let (a, b) = ([0.03f32, -0.41, 0.25], [-1.7f32, 0.9, 0.33]);
/// let (mut keys, mut codes) = (Vec::new(), Vec::new());
/// visit_key_ray(&grid, a, b, |k| keys.push(morton_encode(k)));
/// visit_morton_ray(&grid, a, b, |c| codes.push(c));
/// assert_eq!(codes, keys);
/// assert_eq!(codes.len(), 31);
/// ```
#[inline]
pub fn visit_morton_ray<const K: usize>(
    grid: &MapGrid,
    origin: [f32; K],
    end: [f32; K],
    mut visit: impl FnMut(u64),
) -> bool {
    match MortonWalk::start(grid, origin, end) {
        None => false,
        Some(None) => true,
        Some(Some((first, mut walk))) => {
            visit(first);
            while let Some(code) = walk.next_voxel() {
                visit(code);
            }
            true
        }
    }
}

/// A ray's traversal stepped one voxel at a time ([`next_voxel`](Self::next_voxel)): the state of
/// [`visit_morton_ray`]. (Stepping two or four rays in turn, so that the processor might overlap their
/// steps, was measured slower: the walks' states no longer stay in registers. Eight rays stepped in the
/// lanes of vectors are faster: [`super::ray_lanes`].)
/// Its fields are read by [`super::ray_lanes`], which steps eight (or four) such walks side by side.
#[derive(Debug, Clone, Copy)]
pub(super) struct MortonWalk<const K: usize> {
    pub(super) code: u64,
    pub(super) code_end: u64,
    pub(super) length: f64,
    /// The axis stepped next.
    dim: usize,
    pub(super) t_max: [f64; K],
    pub(super) t_delta: [f64; K],
    mask: [u64; K],
    pub(super) carry: [u64; K],
    pub(super) add: [u64; K],
}

/// The bits of axis `i`'s key in a Morton key of the map's universe: the same for every ray.
#[inline]
pub(super) fn axis_bits<const K: usize>(i: usize) -> u64 {
    spread_bits::<K>(u32::from(u16::MAX)) << i
}

/// What the traversals of rays from one origin share: the origin, its voxel and the borders of that
/// voxel (OctoMap rounds the half step to `f32`), computed once for a scan's rays.
#[derive(Debug, Clone, Copy)]
pub(super) struct RayOrigin<const K: usize> {
    origin: [f32; K],
    key: [u32; K],
    code: u64,
    /// The origin's voxel's border along each axis, below (`[0]`) and above (`[1]`).
    borders: [[f64; 2]; K],
}

impl<const K: usize> RayOrigin<K> {
    /// The rays' common start, or `None` if `origin` is outside the map (every ray then leaves it).
    #[inline]
    pub(super) fn new(grid: &MapGrid, origin: [f32; K]) -> Option<Self> {
        let key = grid.keys(origin)?;
        let half = f64::from((grid.resolution() * 0.5) as f32);
        let borders = std::array::from_fn(|i| {
            let centre = grid.centre(key[i]);
            [centre - half, centre + half]
        });
        Some(Self {
            origin,
            key,
            code: morton_encode(key),
            borders,
        })
    }
}

impl<const K: usize> MortonWalk<K> {
    /// The traversal of the ray from `origin` to `end`: `None` if either point is outside the map,
    /// `Some(None)` if both are in one voxel (nothing is crossed), else the origin's voxel and the walk
    /// on from it.
    #[inline]
    fn start(grid: &MapGrid, origin: [f32; K], end: [f32; K]) -> Option<Option<(u64, Self)>> {
        Self::start_from(grid, &RayOrigin::new(grid, origin)?, end)
    }

    /// [`start`](Self::start) from an origin's shared parts.
    #[inline]
    pub(super) fn start_from(
        grid: &MapGrid,
        from: &RayOrigin<K>,
        end: [f32; K],
    ) -> Option<Option<(u64, Self)>> {
        let (origin, key_origin) = (from.origin, from.key);
        let key_end = grid.keys(end)?;
        if key_origin == key_end {
            return Some(None);
        }
        let code = from.code;
        let code_end = morton_encode(key_end);
        let mut direction = difference(origin, end);
        let length = norm(direction) as f32;
        for d in &mut direction {
            *d /= length;
        }
        let resolution = grid.resolution();
        let mut t_max = [f64::MAX; K];
        let mut t_delta = [f64::MAX; K];
        // A step along axis i: the axis's bits of the Morton key (mask[i]) counted up or down by one,
        // wrapping at 16 bits as OctoMap's 16-bit keys wrap. Counting up fills the other axes' bits with
        // ones (carry[i] = !mask[i]) so the carry runs through them; counting down clears them
        // (carry[i] = 0).
        let mut mask = [0u64; K];
        let mut carry = [0u64; K];
        let mut add = [0u64; K];
        for i in 0..K {
            mask[i] = axis_bits::<K>(i);
            let up = if direction[i] > 0.0 {
                true
            } else if direction[i] < 0.0 {
                false
            } else {
                continue;
            };
            (carry[i], add[i]) = if up { (!mask[i], 1) } else { (0, u64::MAX) };
            // The voxel's border in the ray's direction.
            let border = from.borders[i][usize::from(up)];
            t_max[i] = (border - f64::from(origin[i])) / f64::from(direction[i]);
            t_delta[i] = resolution / f64::from(direction[i]).abs();
        }
        let (dim, _) = nearest(&t_max);
        let walk = Self {
            code,
            code_end,
            length: f64::from(length),
            dim,
            t_max,
            t_delta,
            mask,
            carry,
            add,
        };
        Some(Some((code, walk)))
    }

    /// The next voxel the ray crosses, or `None` at its end (the end's voxel is not crossed).
    #[inline]
    fn next_voxel(&mut self) -> Option<u64> {
        let dim = self.dim;
        let stepped = ((self.code & self.mask[dim]) | self.carry[dim]).wrapping_add(self.add[dim])
            & self.mask[dim];
        self.code = stepped | (self.code & !self.mask[dim]);
        for (i, (t, delta)) in self.t_max.iter_mut().zip(self.t_delta).enumerate() {
            *t += std::hint::select_unpredictable(i == dim, delta, 0.0);
        }
        if self.code == self.code_end {
            return None;
        }
        let reached;
        (self.dim, reached) = nearest(&self.t_max);
        // Past the end point's distance without meeting its voxel (rounding): stop.
        if reached > self.length {
            return None;
        }
        Some(self.code)
    }
}

/// The axis of the smallest `t_max` and that time, ties going to the later axis (OctoMap's comparisons).
/// Chosen without branches, the `K` times kept in registers: which axis comes next is what the processor
/// cannot predict.
#[inline]
fn nearest<const K: usize>(t_max: &[f64; K]) -> (usize, f64) {
    let (mut dim, mut best) = (0, t_max[0]);
    for (i, &t) in t_max.iter().enumerate().skip(1) {
        let nearer = t <= best;
        dim = std::hint::select_unpredictable(nearer, i, dim);
        best = std::hint::select_unpredictable(nearer, t, best);
    }
    (dim, best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The traversal stepping keys one axis at a time, as OctoMap's `computeRayKeys` steps them.
    fn stepping_keys<const K: usize>(
        grid: &MapGrid,
        origin: [f32; K],
        end: [f32; K],
    ) -> Option<Vec<[u32; K]>> {
        let (key_origin, key_end) = (grid.keys(origin)?, grid.keys(end)?);
        let mut out = Vec::new();
        if key_origin == key_end {
            return Some(out);
        }
        out.push(key_origin);
        let mut direction = difference(origin, end);
        let length = norm(direction) as f32;
        for d in &mut direction {
            *d /= length;
        }
        let res = grid.resolution();
        let (mut step, mut t_max, mut t_delta) = ([0i32; K], [f64::MAX; K], [f64::MAX; K]);
        for i in 0..K {
            step[i] = if direction[i] > 0.0 {
                1
            } else if direction[i] < 0.0 {
                -1
            } else {
                0
            };
            if step[i] != 0 {
                let border =
                    grid.centre(key_origin[i]) + f64::from((f64::from(step[i]) * res * 0.5) as f32);
                t_max[i] = (border - f64::from(origin[i])) / f64::from(direction[i]);
                t_delta[i] = res / f64::from(direction[i]).abs();
            }
        }
        let mut key = key_origin;
        loop {
            let mut dim = 0;
            for i in 1..K {
                if t_max[i] <= t_max[dim] {
                    dim = i;
                }
            }
            key[dim] = (key[dim] as i32 + step[dim]) as u32 & 0xffff;
            t_max[dim] += t_delta[dim];
            if key == key_end || t_max.iter().copied().fold(f64::MAX, f64::min) > f64::from(length)
            {
                break;
            }
            out.push(key);
        }
        Some(out)
    }

    fn same_as_stepping_keys<const K: usize>(
        a: [f32; K],
        b: [f32; K],
        res: f64,
    ) -> Result<(), TestCaseError> {
        let grid = MapGrid::new(res).unwrap();
        let mut keys = Vec::new();
        let inside = key_ray(&grid, a, b, &mut keys);
        let expected = stepping_keys(&grid, a, b);
        prop_assert_eq!(inside, expected.is_some());
        prop_assert_eq!(keys, expected.unwrap_or_default());
        Ok(())
    }

    /// Coordinates near the middle of the map and near its edges (where keys are 0 or 65 535).
    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![-20.0f32..20.0, 3270.0f32..3276.8, -3276.8f32..-3270.0]
    }

    proptest! {
        #[test]
        fn morton_steps_are_key_steps_k1(a in [coord()], b in [coord()], res in 0.1f64..0.7) {
            same_as_stepping_keys(a, b, res)?;
        }

        #[test]
        fn morton_steps_are_key_steps_k2(a in [coord(), coord()], b in [coord(), coord()], res in 0.1f64..0.7) {
            same_as_stepping_keys(a, b, res)?;
        }

        #[test]
        fn morton_steps_are_key_steps_k3(a in [coord(), coord(), coord()], b in [coord(), coord(), coord()], res in 0.1f64..0.7) {
            same_as_stepping_keys(a, b, res)?;
        }

        #[test]
        fn morton_steps_are_key_steps_k4(a in [coord(), coord(), coord(), coord()], b in [coord(), coord(), coord(), coord()], res in 0.1f64..0.7) {
            same_as_stepping_keys(a, b, res)?;
        }
    }
}
