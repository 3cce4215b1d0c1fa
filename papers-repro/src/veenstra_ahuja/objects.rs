//! The objects of Veenstra & Ahuja's Figs. 5–11, built with the library: exact quadrics, boxes and
//! half-spaces of `ktree::solid` in the unit-cube frame (voxel centres tested), combined by CSG on rays
//! (`RaySet::intersection`, …) or by tree Booleans (`ktree::ops`). Only the torus, a quartic, keeps a
//! private inside test.

use ktree::ops;
use ktree::rays::{Ray, RaySet};
use ktree::solid::{BoxSolid, Frame, Quadric, Rational, Sample};
use ktree::stacking::paper::stack;
use ktree::tree::Octree;

/// A figure's object: its name, the paper's figure number and how to build it at a level.
pub struct Shape {
    /// File-name part, e.g. `cylinder`.
    pub name: &'static str,
    /// The paper's figure number.
    pub figure: u32,
    /// What it is, for the tables.
    pub description: &'static str,
    /// The builder: the object's octree at a level.
    pub build: fn(u32) -> Result<Octree, String>,
}

/// `num / den` as an exact rational.
fn q(num: i64, den: i64) -> Rational {
    Rational::new(num, den).expect("non-zero denominator")
}

fn text<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// The voxels whose centres lie in the quadric, in the unit-cube frame.
fn quadric_rays(
    quadric: Result<Quadric<3>, ktree::solid::SolidError>,
    level: u32,
) -> Result<RaySet<3>, String> {
    quadric
        .map_err(text)?
        .to_rays(level, Sample::Centre, false)
        .map_err(text)
}

/// The voxels whose centres lie in the closed box `[lo, hi]` of the unit cube.
fn box_rays(lo: [Rational; 3], hi: [Rational; 3], level: u32) -> Result<RaySet<3>, String> {
    BoxSolid::new(lo, hi, Frame::UnitCube)
        .map_err(text)?
        .to_rays(level, Sample::Centre, false)
        .map_err(text)
}

/// The intersection of closed half-spaces `n · p ≤ d` (`n` and `d` integers over the unit cube).
fn polytope_rays(planes: &[([i64; 3], Rational)], level: u32) -> Result<RaySet<3>, String> {
    let mut rays = box_rays([q(0, 1); 3], [q(1, 1); 3], level)?;
    for &(n, d) in planes {
        let h = quadric_rays(
            Quadric::half_space(n.map(Rational::int), d, Frame::UnitCube),
            level,
        )?;
        rays = rays.intersection(&h).map_err(text)?;
    }
    Ok(rays)
}

/// The part of `rays` with 0.1 ≤ z ≤ 0.9 (CSG on rays with a slab), as a tree.
fn upright(rays: &RaySet<3>, level: u32) -> Result<Octree, String> {
    let slab = box_rays(
        [q(0, 1), q(0, 1), q(1, 10)],
        [q(1, 1), q(1, 1), q(9, 10)],
        level,
    )?;
    Ok(stack(&rays.intersection(&slab).map_err(text)?))
}

/// Cylinder x² + y² ≤ 0.4² around the vertical axis through the centre, 0.1 ≤ z ≤ 0.9.
fn cylinder(level: u32) -> Result<Octree, String> {
    let tube = quadric_rays(
        Quadric::cylinder(2, [q(1, 2), q(1, 2), q(0, 1)], q(2, 5), Frame::UnitCube),
        level,
    )?;
    upright(&tube, level)
}

/// Cone with apex at z = 0.9 on the vertical axis and radius 0.42 at z = 0.1 (one nappe, cut at z = 0.1).
fn cone(level: u32) -> Result<Octree, String> {
    let nappes = quadric_rays(
        Quadric::cone(
            2,
            [q(1, 2), q(1, 2), q(9, 10)],
            q(21, 50),
            q(4, 5),
            Frame::UnitCube,
        ),
        level,
    )?;
    upright(&nappes, level)
}

fn sphere_quadric() -> Result<Quadric<3>, ktree::solid::SolidError> {
    Quadric::ball([q(1, 2); 3], q(9, 20), Frame::UnitCube)
}

/// Ball of radius 0.45 at the centre.
fn sphere(level: u32) -> Result<Octree, String> {
    Ok(stack(&quadric_rays(sphere_quadric(), level)?))
}

/// Square pyramid: base 0.84 × 0.84 at z = 0.1 centred on the vertical axis, apex at z = 0.88; its four
/// sides |x − ½| ≤ 0.42 (0.88 − z) / 0.78 (likewise y), times 5000 / 6, and z ≥ 0.1, are half-spaces.
fn pyramid(level: u32) -> Result<Octree, String> {
    let planes = [
        ([650, 0, 350], q(633, 1)),
        ([-650, 0, 350], q(-17, 1)),
        ([0, 650, 350], q(633, 1)),
        ([0, -650, 350], q(-17, 1)),
        ([0, 0, -1], q(-1, 10)),
    ];
    Ok(stack(&polytope_rays(&planes, level)?))
}

/// Self-occluding: a torus lying in the x-y plane (major radius 0.3, minor 0.11; a quartic, so a private
/// inside test), crossed by a bar (a box) through its hole; united as trees.
fn self_occluding(level: u32) -> Result<Octree, String> {
    let ring = stack(&rays_of(level, |p| {
        let (x, y, z) = (p[0] - 0.5, p[1] - 0.5, p[2] - 0.5);
        ((x * x + y * y).sqrt() - 0.3).powi(2) + z * z <= 0.11 * 0.11
    })?);
    let bar = stack(&box_rays(
        [q(11, 25), q(1, 25), q(11, 25)],
        [q(14, 25), q(24, 25), q(14, 25)],
        level,
    )?);
    ops::union(&ring, &bar).map_err(text)
}

/// Octahedron |x − ½| + |y − ½| + |z − ½| ≤ 0.46: eight half-spaces s · p ≤ 0.46 + ½ (s₀ + s₁ + s₂).
fn diamond(level: u32) -> Result<Octree, String> {
    let mut planes = Vec::new();
    for signs in 0..8 {
        let n = [0, 1, 2].map(|i| if signs >> i & 1 == 0 { 1 } else { -1 });
        let d = q(46 + 50 * (n[0] + n[1] + n[2]), 100);
        planes.push((n, d));
    }
    Ok(stack(&polytope_rays(&planes, level)?))
}

/// The coffee cup's three silhouettes, 16 × 16 pixels, top row first. Front: looking along y (x across,
/// z up) — the body and a ring handle; side: looking along x (y across, z up) — the body; top: looking
/// down z (x across, y up) — a disc and the handle's bar.
const CUP_FRONT: [&str; 16] = [
    "................",
    "................",
    "..#########.....",
    "..############..",
    "..#########..#..",
    "..#########..#..",
    "..#########..#..",
    "..############..",
    "..#########.....",
    "..#########.....",
    "...#######......",
    "...#######......",
    "....#####.......",
    "................",
    "................",
    "................",
];
const CUP_SIDE: [&str; 16] = [
    "................",
    "................",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "...#######......",
    "...#######......",
    "....#####.......",
    "................",
    "................",
    "................",
];
const CUP_TOP: [&str; 16] = [
    "................",
    "................",
    "................",
    "................",
    "................",
    "....#####.......",
    "...#######......",
    "..#########.....",
    "..############..",
    "..############..",
    "..############..",
    "..#########.....",
    "...#######......",
    "....#####.......",
    "................",
    "................",
];

/// The silhouette `image` extruded along `along` (0 = x, 1 = y, 2 = z): `across` and `up` are the axes of
/// the image's columns and rows (row 0 at the top). Each row's runs of `#` become boxes of the unit cube,
/// united by CSG on rays.
fn extruded(image: &[&str; 16], across: usize, up: usize, level: u32) -> Result<Octree, String> {
    let mut rays = RaySet::from_rays(level, Vec::new()).map_err(text)?;
    for (row, line) in image.iter().enumerate() {
        let bytes = line.as_bytes();
        let mut col = 0;
        while col < 16 {
            if bytes[col] != b'#' {
                col += 1;
                continue;
            }
            let first = col;
            while col < 16 && bytes[col] == b'#' {
                col += 1;
            }
            let (mut lo, mut hi) = ([q(0, 1); 3], [q(1, 1); 3]);
            lo[across] = q(first as i64, 16);
            hi[across] = q(col as i64, 16);
            let v = 15 - row as i64;
            lo[up] = q(v, 16);
            hi[up] = q(v + 1, 16);
            rays = rays.union(&box_rays(lo, hi, level)?).map_err(text)?;
        }
    }
    Ok(stack(&rays))
}

/// The cup: the intersection (tree Booleans) of the three silhouettes extruded along their viewing
/// directions.
fn coffee_cup(level: u32) -> Result<Octree, String> {
    let front = extruded(&CUP_FRONT, 0, 2, level)?;
    let side = extruded(&CUP_SIDE, 1, 2, level)?;
    let top = extruded(&CUP_TOP, 0, 1, level)?;
    let body = ops::intersection(&front, &side).map_err(text)?;
    ops::intersection(&body, &top).map_err(text)
}

/// The shapes of Figs. 5–11 in figure order.
pub fn shapes() -> Vec<Shape> {
    vec![
        Shape {
            name: "cylinder",
            figure: 5,
            description: "cylinder (radius 0.4 U, height 0.8 U)",
            build: cylinder,
        },
        Shape {
            name: "cone",
            figure: 6,
            description: "cone (base radius 0.42 U, height 0.8 U)",
            build: cone,
        },
        Shape {
            name: "sphere",
            figure: 7,
            description: "sphere (radius 0.45 U)",
            build: sphere,
        },
        Shape {
            name: "pyramid",
            figure: 8,
            description: "square pyramid (base 0.84 U, height 0.78 U)",
            build: pyramid,
        },
        Shape {
            name: "coffee_cup",
            figure: 9,
            description: "coffee cup: three 16×16 silhouettes extruded and intersected",
            build: coffee_cup,
        },
        Shape {
            name: "self_occluding",
            figure: 10,
            description: "torus crossed by a bar through its hole (self-occluding)",
            build: self_occluding,
        },
        Shape {
            name: "diamond",
            figure: 11,
            description: "octahedron |x|+|y|+|z| ≤ 0.46 U: a diamond silhouette from every face",
            build: diamond,
        },
    ]
}

/// The octree of a shape at `level`.
pub fn shape_tree(shape: &Shape, level: u32) -> Result<Octree, String> {
    let tree = (shape.build)(level)?;
    tree.assert_well_formed();
    Ok(tree)
}

/// The rays of an inside test on the unit cube (`p` a voxel centre scaled to `[0, 1]^3`): each column's
/// voxels whose centres are inside, as runs. Only for shapes the solids module has no exact form for.
fn rays_of(level: u32, inside: impl Fn([f64; 3]) -> bool) -> Result<RaySet<3>, String> {
    let side = 1u32 << level;
    let unit = |v: u32| (f64::from(v) + 0.5) / f64::from(side);
    let mut runs = Vec::new();
    for x in 0..side {
        for y in 0..side {
            let mut start: Option<u32> = None;
            for z in 0..=side {
                let is_in = z < side && inside([unit(x), unit(y), unit(z)]);
                match (is_in, start) {
                    (true, None) => start = Some(z),
                    (false, Some(z1)) => {
                        runs.push(Ray::new([x, y, z1], z));
                        start = None;
                    }
                    _ => {}
                }
            }
        }
    }
    RaySet::from_rays(level, runs).map_err(text)
}

/// The sphere with its exact surface normals carried by the rays (the quadric's gradient), for smooth
/// shading.
pub fn sphere_with_normals(level: u32) -> Result<(RaySet<3>, Octree), String> {
    let rays = sphere_quadric()
        .map_err(text)?
        .to_rays(level, Sample::Centre, true)
        .map_err(text)?;
    let tree = stack(&rays);
    Ok((rays, tree))
}

/// A 4-D object: a ball of radius U/5 moving along x from U/4 to 3U/4 (and rising along z) while time,
/// the fourth axis, goes from 0 to U. In unit coordinates `(x, y, z, t)` it is the quadric
/// `(x − ¼ − ½t)² + (y − ½)² + (z − 0.35 − 0.3t)² ≤ 0.2²` (a slanted cylinder in 4-D), whose rays run along
/// time: each voxel's run is when the ball covers it.
pub fn moving_ball(level: u32) -> Result<RaySet<4>, String> {
    // The three linear forms times 20, over (x, y, z, t, 1); the radius² times 400 is 16.
    let forms: [[i128; 5]; 3] = [[20, 0, 0, -10, -5], [0, 20, 0, 0, -10], [0, 0, 20, -6, -7]];
    let mut m = vec![vec![0i128; 5]; 5];
    for l in &forms {
        for i in 0..5 {
            for j in 0..5 {
                m[i][j] += l[i] * l[j];
            }
        }
    }
    m[4][4] -= 16;
    Quadric::<4>::from_matrix(&m, Frame::UnitCube)
        .map_err(text)?
        .to_rays(level, Sample::Centre, false)
        .map_err(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shapes as floating-point inside tests at voxel centres on the unit cube (the reference the
    /// library-built objects must match voxel for voxel).
    fn reference(name: &str, p: [f64; 3]) -> bool {
        let (x, y, z) = (p[0] - 0.5, p[1] - 0.5, p[2] - 0.5);
        match name {
            "cylinder" => x * x + y * y <= 0.16 && (0.1..=0.9).contains(&p[2]),
            "cone" => {
                let r = 0.42 * (0.9 - p[2]) / 0.8;
                p[2] >= 0.1 && r > 0.0 && x * x + y * y <= r * r
            }
            "sphere" => x * x + y * y + z * z <= 0.45 * 0.45,
            "pyramid" => {
                let half = 0.42 * (0.88 - p[2]) / 0.78;
                p[2] >= 0.1 && x.abs() <= half && y.abs() <= half
            }
            "self_occluding" => {
                ((x * x + y * y).sqrt() - 0.3).powi(2) + z * z <= 0.11 * 0.11
                    || (x.abs() <= 0.06 && z.abs() <= 0.06 && y.abs() <= 0.46)
            }
            "diamond" => x.abs() + y.abs() + z.abs() <= 0.46,
            "coffee_cup" => {
                let pixel = |image: &[&str; 16], across: f64, up: f64| {
                    let col = ((across * 16.0).floor() as usize).min(15);
                    let row = 15 - ((up * 16.0).floor() as usize).min(15);
                    image[row].as_bytes()[col] == b'#'
                };
                pixel(&CUP_FRONT, p[0], p[2])
                    && pixel(&CUP_SIDE, p[1], p[2])
                    && pixel(&CUP_TOP, p[0], p[1])
            }
            _ => panic!("unknown shape {name}"),
        }
    }

    #[test]
    fn library_objects_match_the_inside_tests() {
        for level in [4, 5] {
            let side = 1usize << level;
            let unit = |v: usize| (v as f64 + 0.5) / side as f64;
            for shape in shapes() {
                let dense = shape_tree(&shape, level).unwrap().to_dense().unwrap();
                let mut inside = 0;
                for z in 0..side {
                    for y in 0..side {
                        for x in 0..side {
                            let want = reference(shape.name, [unit(x), unit(y), unit(z)]);
                            let got = dense[x + side * (y + side * z)];
                            assert_eq!(
                                got, want,
                                "{} at L = {level}, voxel {x},{y},{z}",
                                shape.name
                            );
                            inside += usize::from(got);
                        }
                    }
                }
                assert!(inside > 0, "{} is empty at L = {level}", shape.name);
            }
        }
    }

    #[test]
    fn moving_ball_matches_its_definition() {
        let level = 3;
        let side = 1u32 << level;
        let u = f64::from(side);
        let rays = moving_ball(level).unwrap();
        let mut count = 0u128;
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    for t in 0..side {
                        let s = (f64::from(t) + 0.5) / u;
                        let c = [u * (0.25 + 0.5 * s), u * 0.5, u * (0.35 + 0.3 * s)];
                        let d: f64 = [x, y, z]
                            .iter()
                            .zip(c)
                            .map(|(&v, c)| (f64::from(v) + 0.5 - c).powi(2))
                            .sum();
                        count += u128::from(d <= (u / 5.0).powi(2));
                    }
                }
            }
        }
        assert!(count > 0);
        assert_eq!(rays.voxel_count(), count);
    }
}
