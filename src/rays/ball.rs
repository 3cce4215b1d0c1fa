//! A direct ray generator for balls (disks, spheres, hyperspheres) with exact voxel-centre tests — enough
//! for benchmarks and the default object; general quadrics live in the solids module.

use super::{RayError, RaySet};
use crate::space::Universe;

/// The voxels whose centres lie in the closed ball of the given centre and radius, clipped to the universe,
/// as rays. Centre and radius are in *half-voxel units* (doubled coordinates), so that voxel centres
/// `c + ½` are integers and the test `Σ (2c_i + 1 − centre2_i)² ≤ radius2²` is exact integer arithmetic.
///
/// Only columns that meet the ball are visited; each column's run comes from an integer square root.
///
/// ```
/// use ktree::rays::ball_rays;
/// // The ball of radius 4 centred in an 8×8 universe: centre (4, 4), i.e. (8, 8) doubled, radius 8 doubled.
/// let disk = ball_rays::<2>(3, [8, 8], 8).unwrap();
/// assert_eq!(disk.len(), 8);
/// assert_eq!(disk.voxel_count(), 52);
/// ```
///
/// # Errors
/// [`RayError::Space`] for a level beyond [`crate::max_level`].
pub fn ball_rays<const K: usize>(
    level: u32,
    centre2: [i64; K],
    radius2: i64,
) -> Result<RaySet<K>, RayError> {
    let universe = Universe::<K>::new(level)?;
    let side = universe.side() as i64;
    let r2 = i128::from(radius2) * i128::from(radius2);
    let mut columns = Vec::new();
    let mut runs = Vec::new();
    // Column range per axis: voxels c with |2c + 1 − C| ≤ R.
    let range = |c2: i64| -> (i64, i64) {
        // ceil((c2 − R − 1) / 2) ..= floor((c2 + R − 1) / 2), clipped to the universe.
        // Saturating: a bound beyond i64 is clipped to the universe all the same.
        let lo = c2.saturating_sub(radius2).div_euclid(2).max(0);
        let hi = c2
            .saturating_add(radius2)
            .saturating_sub(1)
            .div_euclid(2)
            .min(side - 1);
        (lo, hi)
    };
    let ranges: Vec<(i64, i64)> = centre2.iter().map(|&c| range(c)).collect();
    if ranges.iter().any(|&(lo, hi)| lo > hi) {
        return RaySet::from_rays(level, []);
    }
    let mut col: Vec<i64> = ranges[..K - 1].iter().map(|r| r.0).collect();
    // The squared distance from the centre along each column axis, updated as the column moves.
    let term = |axis: usize, c: i64| (i128::from(2 * c + 1) - i128::from(centre2[axis])).pow(2);
    let mut terms: Vec<i128> = col.iter().enumerate().map(|(a, &c)| term(a, c)).collect();
    let empty = RaySet::<K>::empty(level)?;
    loop {
        let used: i128 = terms.iter().sum();
        if used <= r2 {
            let s = isqrt(r2 - used);
            let cz = i128::from(centre2[K - 1]);
            // |2z + 1 − cz| ≤ s  ⇔  (cz − s − 1)/2 ≤ z ≤ (cz + s − 1)/2 (in i128: no overflow; an
            // arithmetic shift is the floor of a halving)
            let z1 = ((cz - s) >> 1).max(0);
            let z2 = ((cz + s - 1) >> 1).min(i128::from(side) - 1) + 1;
            if z1 < z2 {
                let mut point = [0u32; K];
                for (p, &c) in point.iter_mut().zip(col.iter()) {
                    *p = c as u32;
                }
                columns.push(empty.column_key(point));
                runs.push((z1 as u32, z2 as u32));
            }
        }
        // Next column (last of the K−1 axes fastest, to keep lexicographic order).
        let mut axis = K - 1;
        loop {
            if axis == 0 {
                return Ok(RaySet::from_sorted_parts(universe, columns, runs, None));
            }
            axis -= 1;
            col[axis] += 1;
            if col[axis] <= ranges[axis].1 {
                terms[axis] = term(axis, col[axis]);
                break;
            }
            col[axis] = ranges[axis].0;
            terms[axis] = term(axis, col[axis]);
        }
    }
}

/// The integer square root: the largest `s` with `s² ≤ n`.
pub(crate) fn isqrt(n: i128) -> i128 {
    if n <= 0 {
        return 0;
    }
    if let Ok(small) = u64::try_from(n) {
        return i128::from(isqrt_u64(small));
    }
    let mut s = (n as f64).sqrt() as i128;
    while s * s > n {
        s -= 1;
    }
    while (s + 1) * (s + 1) <= n {
        s += 1;
    }
    s
}

/// `floor(sqrt(n))` in 64-bit arithmetic.
fn isqrt_u64(n: u64) -> u64 {
    let mut s = (n as f64).sqrt() as u64;
    while s.checked_mul(s).is_none_or(|sq| sq > n) {
        s -= 1;
    }
    while (s + 1).checked_mul(s + 1).is_some_and(|sq| sq <= n) {
        s += 1;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isqrt_is_the_floor_of_the_square_root_around_squares() {
        let roots = (0..2000i128)
            .chain((1i128 << 31) - 3..(1 << 31) + 3)
            .chain((1i128 << 32) - 3..(1 << 32) + 3);
        for k in roots.chain((1i128 << 40)..(1 << 40) + 3) {
            for n in [k * k - 1, k * k, k * k + 1] {
                let s = isqrt(n);
                assert!(
                    n < 0 || (s * s <= n && (s + 1) * (s + 1) > n),
                    "isqrt({n}) = {s}"
                );
            }
        }
    }

    fn brute<const K: usize>(level: u32, centre2: [i64; K], radius2: i64) -> u128 {
        let u = Universe::<K>::new(level).unwrap();
        let mut n = 0;
        for i in 0..u.voxels() as usize {
            let p = u.dense_point(i);
            let d: i64 = p
                .iter()
                .zip(centre2.iter())
                .map(|(&c, &c2)| (2 * c as i64 + 1 - c2).pow(2))
                .sum();
            if d <= radius2 * radius2 {
                n += 1;
                let set = ball_rays::<K>(level, centre2, radius2).unwrap();
                assert!(set.contains(p));
            }
        }
        n
    }

    #[test]
    fn ball_matches_voxel_centre_test() {
        for (c, r) in [
            ([8, 8, 8], 8),
            ([0, 0, 0], 13),
            ([3, 17, 9], 6),
            ([-4, 20, 2], 11),
            ([50, 50, 50], 3),
        ] {
            assert_eq!(
                ball_rays::<3>(4, c, r).unwrap().voxel_count(),
                brute::<3>(4, c, r),
                "{c:?} {r}"
            );
        }
        assert_eq!(
            ball_rays::<2>(3, [7, 9], 5).unwrap().voxel_count(),
            brute::<2>(3, [7, 9], 5)
        );
        assert_eq!(
            ball_rays::<1>(3, [7], 5).unwrap().voxel_count(),
            brute::<1>(3, [7], 5)
        );
        assert_eq!(
            ball_rays::<4>(2, [4, 3, 5, 4], 4).unwrap().voxel_count(),
            brute::<4>(2, [4, 3, 5, 4], 4)
        );
    }
}
