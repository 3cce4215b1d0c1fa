//! Small private ray generators for the reproduction's scenes — boxes and cylinders along an axis, with
//! exact voxel-centre tests in doubled (half-voxel) integer coordinates, like [`crate::rays::ball_rays`].
//! They will be replaced by the solids module (general quadrics and CSG on rays, issue 3).

use crate::build::stack;
use crate::rays::{ball_rays, Ray, RaySet};
use crate::tree::KTree;

/// The box `[lo, hi)` (voxels) as an octree.
pub fn cuboid(level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<KTree<3>, String> {
    let mut rays = Vec::new();
    for x in lo[0]..hi[0] {
        for y in lo[1]..hi[1] {
            rays.push(Ray::new([x, y, lo[2]], hi[2]));
        }
    }
    Ok(stack(
        &RaySet::from_rays(level, rays).map_err(|e| e.to_string())?,
    ))
}

/// The ball with centre `centre2` and radius `radius2` in doubled coordinates.
pub fn ball(level: u32, centre2: [i64; 3], radius2: i64) -> Result<KTree<3>, String> {
    Ok(stack(
        &ball_rays::<3>(level, centre2, radius2).map_err(|e| e.to_string())?,
    ))
}

fn isqrt(n: i64) -> i64 {
    if n <= 0 {
        return 0;
    }
    let mut s = (n as f64).sqrt() as i64;
    while s * s > n {
        s -= 1;
    }
    while (s + 1) * (s + 1) <= n {
        s += 1;
    }
    s
}

/// The cylinder along `axis` (0, 1, 2) whose voxels have centres within `radius2` (doubled) of the axis
/// line through `centre2` (doubled; the coordinate along `axis` is ignored) and whose coordinate along
/// `axis` lies in `[from, to)`.
pub fn cylinder(
    level: u32,
    axis: usize,
    centre2: [i64; 3],
    radius2: i64,
    (from, to): (u32, u32),
) -> Result<KTree<3>, String> {
    let side = 1i64 << level;
    let r2 = radius2 * radius2;
    let off = |c: i64, c2: i64| (2 * c + 1 - c2).pow(2);
    let mut rays = Vec::new();
    for x in 0..side {
        for y in 0..side {
            let (z1, z2) = match axis {
                2 => {
                    if off(x, centre2[0]) + off(y, centre2[1]) > r2 {
                        continue;
                    }
                    (i64::from(from), i64::from(to))
                }
                _ => {
                    // The along-axis coordinate is x (axis 0) or y (axis 1); the other is in the disk.
                    let (along, other, oc2) = if axis == 0 {
                        (x, y, centre2[1])
                    } else {
                        (y, x, centre2[0])
                    };
                    if along < i64::from(from) || along >= i64::from(to) {
                        continue;
                    }
                    let used = off(other, oc2);
                    if used > r2 {
                        continue;
                    }
                    let s = isqrt(r2 - used);
                    let cz = centre2[2];
                    (
                        (cz - s).div_euclid(2).max(0),
                        (cz + s - 1).div_euclid(2).min(side - 1) + 1,
                    )
                }
            };
            let (z1, z2) = (z1.max(0), z2.min(side));
            if z1 < z2 {
                rays.push(Ray::new([x as u32, y as u32, z1 as u32], z2 as u32));
            }
        }
    }
    Ok(stack(
        &RaySet::from_rays(level, rays).map_err(|e| e.to_string())?,
    ))
}
