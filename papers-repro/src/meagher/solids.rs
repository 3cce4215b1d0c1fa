//! The reproduction's shapes from the library's exact solids (`ktree::solid`): boxes, balls and finite
//! cylinders, in the voxel frame sampled at voxel centres, stacked into octrees. Finite cylinders are the
//! library's infinite quadric cylinder cut by a box, by CSG on rays (`RaySet::intersection`).

use ktree::rays::RaySet;
use ktree::solid::{BoxSolid, Frame, Quadric, Rational, Sample};
use ktree::stacking::paper::stack;
use ktree::tree::KTree;

fn half(v: i64) -> Rational {
    Rational::new(v, 2).expect("non-zero denominator")
}

fn rays_of_box(level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<RaySet<3>, String> {
    // Centres c + ½ in the closed box [lo, hi − ½]: exactly the voxels lo ≤ c < hi.
    let b = BoxSolid::<3>::new(
        lo.map(|v| Rational::int(i64::from(v))),
        hi.map(|v| half(2 * i64::from(v) - 1)),
        Frame::Voxel,
    )
    .map_err(|e| e.to_string())?;
    b.to_rays(level, Sample::Centre, false)
        .map_err(|e| e.to_string())
}

/// The box `[lo, hi)` (voxels) as an octree.
pub fn cuboid(level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<KTree<3>, String> {
    Ok(stack(&rays_of_box(level, lo, hi)?))
}

/// The closed ball with centre `centre2 / 2` and radius `radius2 / 2` (voxel units; voxel centres tested).
pub fn ball(level: u32, centre2: [i64; 3], radius2: i64) -> Result<KTree<3>, String> {
    let q = Quadric::<3>::ball(centre2.map(half), half(radius2), Frame::Voxel)
        .map_err(|e| e.to_string())?;
    Ok(stack(
        &q.to_rays(level, Sample::Centre, false)
            .map_err(|e| e.to_string())?,
    ))
}

/// The cylinder along `axis` (0, 1, 2) whose voxels have centres within `radius2 / 2` of the axis line
/// through `centre2 / 2` (the coordinate along `axis` is ignored) and whose coordinate along `axis` lies
/// in `[from, to)`.
pub fn cylinder(
    level: u32,
    axis: usize,
    centre2: [i64; 3],
    radius2: i64,
    (from, to): (u32, u32),
) -> Result<KTree<3>, String> {
    let q = Quadric::<3>::cylinder(axis, centre2.map(half), half(radius2), Frame::Voxel)
        .map_err(|e| e.to_string())?;
    let tube = q
        .to_rays(level, Sample::Centre, false)
        .map_err(|e| e.to_string())?;
    let side = 1u32 << level;
    let (mut lo, mut hi) = ([0; 3], [side; 3]);
    lo[axis] = from;
    hi[axis] = to;
    let slab = rays_of_box(level, lo, hi)?;
    Ok(stack(&tube.intersection(&slab).map_err(|e| e.to_string())?))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each voxel of a level-5 universe against the shapes' definitions in doubled integer coordinates.
    #[test]
    fn shapes_match_their_definitions() {
        let level = 5;
        let side = 1i64 << level;
        let centre2 = [33, 30, 31];
        let boxed = cuboid(level, [3, 7, 0], [20, 9, 31]).unwrap();
        let round = ball(level, centre2, 21).unwrap();
        let tubes: Vec<KTree<3>> = (0..3)
            .map(|axis| cylinder(level, axis, centre2, 17, (4, 27)).unwrap())
            .collect();
        let dense = |t: &KTree<3>| t.to_dense().unwrap();
        let (b, r) = (dense(&boxed), dense(&round));
        let t: Vec<Vec<bool>> = tubes.iter().map(dense).collect();
        let off = |c: i64, c2: i64| (2 * c + 1 - c2).pow(2);
        for z in 0..side {
            for y in 0..side {
                for x in 0..side {
                    let p = [x, y, z];
                    let i = (x + side * (y + side * z)) as usize;
                    let in_box =
                        (3..20).contains(&x) && (7..9).contains(&y) && (0..31).contains(&z);
                    assert_eq!(b[i], in_box, "box at {p:?}");
                    let d: i64 = (0..3).map(|a| off(p[a], centre2[a])).sum();
                    assert_eq!(r[i], d <= 21 * 21, "ball at {p:?}");
                    for (axis, tube) in t.iter().enumerate() {
                        let d: i64 = (0..3)
                            .filter(|&a| a != axis)
                            .map(|a| off(p[a], centre2[a]))
                            .sum();
                        let want = d <= 17 * 17 && (4..27).contains(&p[axis]);
                        assert_eq!(tube[i], want, "cylinder along {axis} at {p:?}");
                    }
                }
            }
        }
    }
}
